"""The knee's relative position along its axis: gauge, prior, the standing axis check, a simulated walk."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest
from simcache import data_dir, real_walk_leg_mapping

from lowerlimb.calibration import calibrate_leg
from lowerlimb.calibration.excitation import ExcitationReport, ExcitationWarning
from lowerlimb.calibration.knee_line import (
    KneeLine,
    axis_mismatch_message,
    knee_line_offset,
    moving_axis_mismatch,
    standing_axis_mismatch,
    with_knee_line,
)
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import (
    HingeAxisCalibration,
    HingeJointCalibration,
    SphericalJointCalibration,
)
from lowerlimb.errors import InputError
from lowerlimb.io.xsens import read_xsens
from lowerlimb.simulation import simulate_bilateral


def _knee(cp, cc, jp=(0.0, 0.0, 1.0), jc=(0.0, 0.0, 1.0)) -> HingeJointCalibration:
    jp, jc = (np.asarray(j, dtype=float) / np.linalg.norm(j) for j in (jp, jc))
    axis = HingeAxisCalibration("knee", "thigh", "shank", jp, jc, rms_residual=0.0)
    rep = ExcitationReport(np.ones(6), 1.0, np.full(6, 1e-4), np.eye(6)[0], 1e-4, 0.1)
    center = SphericalJointCalibration(
        "knee",
        "thigh",
        "shank",
        np.asarray(cp, dtype=float),
        np.asarray(cc, dtype=float),
        rms_residual=0.0,
        excitation=rep,
    )
    return HingeJointCalibration(axis=axis, center=center)


HIP = np.array([0.0, 0.25, 0.03])  # in the thigh sensor: 25 cm up, 3 cm along the axis
ANKLE = np.array([0.0, -0.35, -0.02])  # in the shank sensor


def test_offset_is_gauge_invariant_and_shift_moves_it() -> None:
    k = _knee([0.0, -0.15, 0.01], [0.0, 0.1, 0.04])
    v = knee_line_offset(HIP, k, ANKLE)
    assert v == pytest.approx((-0.02 - 0.04) - (0.03 - 0.01))
    # moving both knee points by the same amount along the axis is the gauge: v is unchanged
    g = _knee([0.0, -0.15, 0.11], [0.0, 0.1, 0.14])
    assert knee_line_offset(HIP, g, ANKLE) == pytest.approx(v)


def test_prior_moves_the_knee_along_its_axis_only() -> None:
    k = _knee([0.0, -0.15, 0.01], [0.0, 0.1, 0.09])
    v = knee_line_offset(HIP, k, ANKLE)
    out, line = with_knee_line(k, HIP, ANKLE, [], mean_m=0.0, std_m=0.04, min_data_std_m=0.04)
    # equal spreads: the posterior lies half way between the data and the prior's mean
    assert line.data_m == pytest.approx(v) and line.posterior_m == pytest.approx(v / 2)
    assert knee_line_offset(HIP, out, ANKLE) == pytest.approx(line.posterior_m)
    d_p = out.center_in_parent_sensor - k.center_in_parent_sensor
    d_c = out.center_in_child_sensor - k.center_in_child_sensor
    # along the axis, by equal and opposite amounts (the gauge, their mean, is kept)
    assert np.allclose(d_p[:2], 0.0) and np.allclose(d_c[:2], 0.0)
    assert d_p[2] == pytest.approx(-d_c[2])
    assert np.allclose(out.axis_in_parent_sensor, k.axis_in_parent_sensor)


def test_probes_widen_the_data_spread_and_the_prior_wins() -> None:
    k = _knee([0.0, -0.15, 0.01], [0.0, 0.1, 0.09])
    far = replace(k, center=replace(k.center, center_in_child_sensor=np.array([0.0, 0.1, 0.29])))
    _, tight = with_knee_line(k, HIP, ANKLE, [], mean_m=0.0, std_m=0.04, min_data_std_m=0.001)
    _, loose = with_knee_line(k, HIP, ANKLE, [far], mean_m=0.0, std_m=0.04, min_data_std_m=0.001)
    assert tight.data_std_m == pytest.approx(0.001)
    assert loose.data_std_m == pytest.approx(0.2)
    assert abs(tight.posterior_m - tight.data_m) < 0.001
    assert abs(loose.posterior_m) < 0.1 * abs(loose.data_m)


def test_an_axis_mismatch_at_standing_keeps_the_data() -> None:
    k = _knee([0.0, -0.15, 0.01], [0.0, 0.1, 0.09])
    kw = {"mean_m": 0.0, "std_m": 0.04, "min_data_std_m": 0.04, "max_mismatch_rad": np.radians(5.0)}
    out, agree = with_knee_line(k, HIP, ANKLE, [], axis_mismatch_rad=np.radians(4.0), **kw)
    assert agree.applied and agree.posterior_m == pytest.approx(agree.data_m / 2)
    out, apart = with_knee_line(k, HIP, ANKLE, [], axis_mismatch_rad=np.radians(-17.0), **kw)
    assert not apart.applied and apart.axis_mismatch_deg == pytest.approx(-17.0)
    assert apart.posterior_m == apart.data_m and out is k
    assert apart.to_dict()["applied"] is False


def test_standing_axis_mismatch_reads_the_elevations() -> None:
    up = np.array([0.0, 1.0, 0.0])
    tilt = np.radians(20.0)
    k = _knee([0, 0, 0], [0, 0, 0], jp=(0.0, np.sin(tilt), np.cos(tilt)), jc=(1.0, 0.0, 1.0))
    assert standing_axis_mismatch(k, 9.81 * up, up) == pytest.approx(tilt)
    # a hinge keeps the axis-gravity angle: any flexion of the shank leaves no mismatch
    c, s = np.cos(0.7), np.sin(0.7)
    up_c = np.array([c * up[0] - s * up[1], s * up[0] + c * up[1], 0.0])
    jc = np.array([c * k.axis_in_parent_sensor[0] - s * k.axis_in_parent_sensor[1], 0.0, 0.0])
    jc[1] = s * k.axis_in_parent_sensor[0] + c * k.axis_in_parent_sensor[1]
    jc[2] = k.axis_in_parent_sensor[2]
    k2 = _knee([0, 0, 0], [0, 0, 0], jp=k.axis_in_parent_sensor, jc=jc)
    assert standing_axis_mismatch(k2, up, up_c) == pytest.approx(0.0, abs=1e-12)


def test_moving_axis_mismatch_reads_the_standing_one_over_a_motion() -> None:
    """A hinge turning the shank about its axis keeps the elevation: the median reads the tilt."""
    from scipy.spatial.transform import Rotation

    rate = 100.0
    q = 0.6 * np.sin(2 * np.pi * 0.9 * np.arange(3000) / rate) - 0.6  # knee flexion, rad
    up = np.array([0.1, 0.98, 0.17]) / np.linalg.norm([0.1, 0.98, 0.17])
    j = np.array([0.3, 0.2, 1.0]) / np.linalg.norm([0.3, 0.2, 1.0])
    acc_thigh = np.tile(9.81 * up, (q.size, 1))
    acc_shank = Rotation.from_rotvec(-q[:, None] * j).apply(9.81 * up)  # gravity in the turning shank
    k = _knee([0, 0, 0], [0, 0, 0], jp=j, jc=j)
    assert moving_axis_mismatch(k, acc_thigh, acc_shank, rate, 1.0) == pytest.approx(0.0, abs=1e-6)
    tilted = Rotation.from_rotvec(np.radians(12.0) * np.cross(j, up) / np.linalg.norm(np.cross(j, up))).apply(
        j
    )
    k2 = _knee([0, 0, 0], [0, 0, 0], jp=tilted, jc=j)
    expected = np.arcsin(tilted @ up) - np.arcsin(j @ up)
    assert abs(expected) > np.radians(10.0), "the tilt must show in the elevation"
    assert moving_axis_mismatch(k2, acc_thigh, acc_shank, rate, 1.0) == pytest.approx(expected, abs=1e-6)
    assert moving_axis_mismatch(k2, acc_thigh, acc_shank, rate, 1.0) == pytest.approx(
        standing_axis_mismatch(k2, acc_thigh[0], acc_shank[0]), abs=1e-6
    )


def test_a_knee_without_its_spread_leaves_v_to_the_prior() -> None:
    k = _knee([0.0, -0.15, 0.01], [0.0, 0.1, 0.09])
    k = replace(k, center=replace(k.center, excitation=None))
    _, line = with_knee_line(k, HIP, ANKLE, [], mean_m=0.0, std_m=0.04, min_data_std_m=0.001)
    assert line.data_std_m == np.inf and line.posterior_m == 0.0


def test_combine_and_record() -> None:
    line = KneeLine.combine(0.1, 0.03, 0.0, 0.04, 2.0)
    w = (1 / 0.03**2) / (1 / 0.03**2 + 1 / 0.04**2)
    assert line.posterior_m == pytest.approx(0.1 * w)
    d = line.to_dict()
    assert d["posterior_m"] == pytest.approx(line.posterior_m) and d["axis_mismatch_deg"] == 2.0


def test_options_are_checked() -> None:
    for name in ("knee_line_std_m", "knee_line_min_data_std_m"):
        with pytest.raises(InputError, match=name):
            CalibrationOptions(**{name: 0.0})
    with pytest.raises(InputError, match="knee_line_probe_factors"):
        CalibrationOptions(knee_line_probe_factors=(1.5, -1.0))


@pytest.fixture(scope="module")
def walk():
    return simulate_bilateral(20.0, 201)


def _true_offset(truth: dict) -> float:
    k = truth["knee"]
    knee = _knee(
        k["center_in_parent_sensor"],
        k["center_in_child_sensor"],
        k["axis_in_parent_sensor"],
        k["axis_in_child_sensor"],
    )
    return knee_line_offset(
        truth["hip"]["center_in_child_sensor"], knee, truth["ankle"]["center_in_parent_sensor"]
    )


@pytest.mark.parametrize("side", ["left", "right"])
def test_simulated_walk_puts_the_ankle_beside_the_hip(walk, side) -> None:
    """The simulated legs have hip, knee and ankle on one line across the axis; the data's
    own estimate is several centimetres off (the prefilter's bias), the posterior is not."""
    truth = walk.truth["legs"][side]["joints"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(walk.trial.leg(side))
    line = cal.priors["knee_line"]
    v = knee_line_offset(cal.hip.center_in_child_sensor, cal.knee, cal.ankle.center_in_parent_sensor)
    assert v == pytest.approx(line["posterior_m"])
    assert abs(line["axis_mismatch_deg"]) < 1.0 and line["applied"]
    assert abs(v - _true_offset(truth)) < 0.025
    assert abs(v - _true_offset(truth)) < abs(line["data_m"] - _true_offset(truth))
    off = calibrate_leg(walk.trial.leg(side), options=CalibrationOptions(knee_line_prior=False))
    assert "knee_line" not in off.priors


def test_mismatch_message_names_the_disagreement_and_a_fix() -> None:
    msg = axis_mismatch_message(-17.4)
    assert "17°" in msg and "soft tissue" in msg and "strap" in msg and "\n" not in msg
    assert "hip flexion" in msg  # the thigh frame leans with the thigh's axis (knee_axis_frames.md)


REAL = data_dir()


@pytest.mark.data
@pytest.mark.skipif(REAL is None or not (REAL / "gait").is_dir(), reason="real-walk data absent")
@pytest.mark.parametrize("side", ["left", "right"])
def test_real_walk_thigh_axis_disagrees_so_the_prior_steps_aside(side) -> None:
    """On the real walk the thigh's knee axis is 17-18 deg off the shank's at standing."""
    assert REAL is not None
    mapping = real_walk_leg_mapping(side)
    trial = read_xsens(REAL / "gait" / "rawimu", mapping, side=side)
    with pytest.warns(ExcitationWarning, match="knee axis from the thigh sensor"):
        cal = calibrate_leg(trial)
    line = cal.priors["knee_line"]
    assert not line["applied"] and abs(line["axis_mismatch_deg"]) > 10.0  # measured 17-18
    assert line["posterior_m"] == line["data_m"]
    assert any("knee axis from the thigh sensor" in w for w in cal.warnings)
