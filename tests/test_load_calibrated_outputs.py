"""``load_calibrated`` on a folder that ``calibrate --outputs`` wrote without the S2J sidecar."""

from __future__ import annotations

import pytest

from lowerlimb.errors import InputError
from lowerlimb.outputs import load_calibrated


def test_a_urdf_without_its_s2j_sidecar_names_the_outputs_option(tmp_path):
    (tmp_path / "calibrated.urdf").write_text("<robot name='leg'/>")
    with pytest.raises(InputError, match=r"calibrated.urdf but no s2j.json; re-run .* s2j in --outputs"):
        load_calibrated(tmp_path)


def test_a_folder_without_the_urdf_is_not_a_result(tmp_path):
    with pytest.raises(InputError, match="has no calibrated.urdf; give an output directory"):
        load_calibrated(tmp_path)
