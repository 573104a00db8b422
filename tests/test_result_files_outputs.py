"""``check_outputs``: the ``outputs`` of ``process_study`` / ``CalibrateOptions`` given as one string."""

from __future__ import annotations

import pytest

from lowerlimb.errors import InputError
from lowerlimb.io.result_files import check_outputs


def test_one_string_is_a_name_or_a_comma_separated_list_not_its_letters():
    assert check_outputs("angles") == frozenset({"angles"})
    assert check_outputs("calibration, angles") == frozenset({"calibration", "angles"})
    assert check_outputs(["urdf", "s2j"]) == frozenset({"urdf", "s2j"})


def test_unknown_or_no_output_is_refused_naming_the_choices():
    with pytest.raises(InputError, match=r"unknown output 'angle'; choose among calibration, angles"):
        check_outputs("angle")
    with pytest.raises(InputError, match="no output chosen"):
        check_outputs("")
