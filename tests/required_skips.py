"""A pytest plugin: with ``LOWERLIMB_REQUIRE_ALL=1`` a skipped required test fails.

Required are the tests marked ``data`` (the shared real-data folder), ``browser``
(headless Chromium) and ``urdf`` (``check_urdf`` from liburdfdom-tools). On a developer
machine they skip with a reason when their data or tool is missing; CI (``.ci/run``)
sets ``LOWERLIMB_REQUIRE_ALL=1`` so that a missing folder or tool turns the run red
instead of quietly shrinking it.
"""

from __future__ import annotations

import os

import pytest

REQUIRED_MARKERS = ("data", "browser", "urdf")
ENV = "LOWERLIMB_REQUIRE_ALL"


def required_markers(item: pytest.Item) -> list[str]:
    if item.get_closest_marker("optional") is not None:  # an optional extra (e.g. opensim)
        return []
    return [m for m in REQUIRED_MARKERS if item.get_closest_marker(m) is not None]


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "urdf: tests that need check_urdf (Debian package liburdfdom-tools)")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]):  # type: ignore[no-untyped-def]
    outcome = yield
    report = outcome.get_result()
    if not report.skipped or hasattr(report, "wasxfail") or os.environ.get(ENV) != "1":
        return
    markers = required_markers(item)
    if not markers:
        return
    reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else str(report.longrepr)
    report.outcome = "failed"
    report.longrepr = (
        f"required test skipped ({ENV}=1; marked {', '.join(markers)}): {reason}\n"
        "install what it needs or point LOWERLIMB_DATA at the shared data folder"
    )
