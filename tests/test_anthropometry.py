"""de Leva (1996) segment parameters checked against the published table (issue 10).

P. de Leva, "Adjustments to Zatsiorsky-Seluyanov's segment inertia parameters",
J. Biomech. 29(9):1223-1230, 1996, Table 4, male columns: mean segment length (mm, for
the 1741 mm reference stature), mass (% of body mass), CoM position (% of the segment
length from the proximal end; the foot from the heel, the lower trunk from the
omphalion) and radii of gyration (% of the segment length) about the sagittal,
transverse and longitudinal axes.

The values below are typed from the paper, not read from the code, so that a CoM
measured from the wrong end or a wrong mass fraction fails here, whatever the
generator writes into the golden URDF.
"""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.model.anthropometry import HEEL_OFFSET_PER_FOOT_LENGTH, segment_inertias

STATURE_M = 1.75
MASS_KG = 75.0
REFERENCE_STATURE_MM = 1741.0

#: de Leva 1996, Table 4, males:
#: segment: (length mm, mass %, CoM % from proximal, r_sagittal %, r_transverse %, r_longitudinal %)
TABLE_4_MALE = {
    "thigh": (422.2, 14.16, 40.95, 32.9, 32.9, 14.9),  # hip joint centre -> knee joint centre
    "shank": (434.0, 4.33, 44.59, 25.5, 24.9, 10.3),  # knee joint centre -> lateral malleolus
    "foot": (258.1, 1.37, 44.15, 25.7, 24.5, 12.4),  # heel -> tip of the longest toe
    "pelvis": (145.7, 11.17, 61.15, 61.5, 55.1, 58.7),  # "lower trunk": omphalion -> hip centres
}


@pytest.fixture(scope="module")
def segments():
    return segment_inertias(STATURE_M, MASS_KG)


def length_m(name: str) -> float:
    return TABLE_4_MALE[name][0] * 1e-3 * STATURE_M / (REFERENCE_STATURE_MM * 1e-3)


@pytest.mark.parametrize("name", list(TABLE_4_MALE))
def test_length_scales_with_stature(segments, name):
    assert segments[name].length_m == pytest.approx(length_m(name), rel=1e-4)


@pytest.mark.parametrize("name", list(TABLE_4_MALE))
def test_mass_is_the_published_fraction_of_body_mass(segments, name):
    assert segments[name].mass_kg == pytest.approx(TABLE_4_MALE[name][1] / 100 * MASS_KG, rel=1e-4)


def test_masses_in_kilograms_for_75_kg():
    """The same numbers worked by hand: 10.62, 3.25, 1.03 and 8.38 kg."""
    s = segment_inertias(STATURE_M, MASS_KG)
    got = [s[k].mass_kg for k in ("thigh", "shank", "foot", "pelvis")]
    np.testing.assert_allclose(got, [10.62, 3.2475, 1.0275, 8.3775], atol=1e-3)


@pytest.mark.parametrize("name", ["thigh", "shank"])
def test_com_of_a_long_segment_lies_below_the_proximal_joint(segments, name):
    """Thigh and shank frames: origin at the proximal joint, the segment along -y."""
    com = segments[name].com_m
    expected = TABLE_4_MALE[name][2] / 100 * length_m(name)
    np.testing.assert_allclose(com, [0.0, -expected, 0.0], atol=1e-6)
    assert -com[1] < 0.5 * length_m(name)  # both CoMs sit in the proximal half


def test_foot_com_is_measured_from_the_heel(segments):
    """Foot frame: origin at the ankle, +x towards the toe; the heel is behind the ankle."""
    length = length_m("foot")
    heel_x = -HEEL_OFFSET_PER_FOOT_LENGTH * length
    com = segments["foot"].com_m
    assert com[0] - heel_x == pytest.approx(TABLE_4_MALE["foot"][2] / 100 * length, abs=1e-6)
    assert com[2] == 0.0


def test_pelvis_com_is_measured_from_the_omphalion(segments):
    """Pelvis frame: origin at the mid-point of the hip centres (the distal end of the
    lower trunk), so the CoM is (1 - 0.6115) of the length above it."""
    length = length_m("pelvis")
    expected_above_hips = (1.0 - TABLE_4_MALE["pelvis"][2] / 100) * length
    np.testing.assert_allclose(segments["pelvis"].com_m, [0.0, expected_above_hips, 0.0], atol=1e-6)


@pytest.mark.parametrize("name", list(TABLE_4_MALE))
def test_inertia_from_the_radii_of_gyration(segments, name):
    """I = m (r L)^2 about each axis. ISB frame: x anterior (sagittal axis), y superior
    (longitudinal), z right (transverse); the foot's long axis is x, so there the
    longitudinal radius belongs to x and the sagittal one to y."""
    _, mass_pct, _, r_sag, r_trans, r_long = TABLE_4_MALE[name]
    mass = mass_pct / 100 * MASS_KG
    radii = (r_long, r_sag, r_trans) if name == "foot" else (r_sag, r_long, r_trans)
    expected = np.diag([mass * (r / 100 * length_m(name)) ** 2 for r in radii])
    np.testing.assert_allclose(segments[name].inertia_kgm2, expected, rtol=1e-4, atol=1e-12)


def test_thigh_inertia_in_kg_m2_for_the_reference_subject():
    """Worked by hand for 1.741 m, 75 kg: m = 10.62 kg, L = 0.4222 m,
    I_sag = m (0.329 L)^2 = 0.2049, I_long = m (0.149 L)^2 = 0.04203 kg m^2."""
    thigh = segment_inertias(1.741, 75.0)["thigh"]
    np.testing.assert_allclose(np.diag(thigh.inertia_kgm2), [0.2049, 0.04203, 0.2049], rtol=1e-3)


def test_every_height_and_mass_the_command_line_accepts_scales_the_model():
    # the CLI and the batch manifest check --height/--mass against InputBounds; a value they let
    # through (2.55 m, 350 kg) used to end as an internal error (exit 1) in the de Leva scaling
    from lowerlimb.io.bounds import INPUT_BOUNDS

    for height in INPUT_BOUNDS.height_m:
        for mass in INPUT_BOUNDS.mass_kg:
            s = segment_inertias(height, mass)
            assert all(np.isfinite(seg.length_m) and seg.length_m > 0 for seg in s.values())
    with pytest.raises(ValueError, match="implausible"):
        segment_inertias(INPUT_BOUNDS.height_m[1] + 0.01, 75.0)
