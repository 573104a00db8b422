"""CI turns skips of required tests into failures (tests/required_skips.py, issue 10)."""

from __future__ import annotations

import pytest

pytest_plugins = ["pytester"]

TESTS = """
import pytest

@pytest.mark.data
def test_needs_data():
    pytest.skip("data folder not found")

@pytest.mark.browser
@pytest.mark.skipif(True, reason="chromium not found")
def test_needs_chromium():
    pass

@pytest.mark.urdf
def test_needs_check_urdf():
    pytest.skip("check_urdf not found")

def test_optional():
    pytest.skip("an optional extra is not installed")

@pytest.mark.data
def test_runs():
    assert True
"""


@pytest.fixture
def suite(pytester):
    pytester.makepyfile(test_suite=TESTS)
    return pytester


def test_required_skips_fail_when_required(suite, monkeypatch):
    monkeypatch.setenv("LOWERLIMB_REQUIRE_ALL", "1")
    result = suite.runpytest("-p", "required_skips")
    outcomes = result.parseoutcomes()
    assert outcomes.get("passed") == 1 and outcomes.get("skipped") == 1, outcomes
    assert outcomes.get("failed", 0) + outcomes.get("errors", outcomes.get("error", 0)) == 3, outcomes
    result.stdout.fnmatch_lines(["*required test skipped (LOWERLIMB_REQUIRE_ALL=1; marked data)*"])


def test_required_skips_only_skip_on_a_developer_machine(suite, monkeypatch):
    monkeypatch.delenv("LOWERLIMB_REQUIRE_ALL", raising=False)
    result = suite.runpytest("-p", "required_skips")
    result.assert_outcomes(passed=1, skipped=4)
