"""The two-IMU spherical fit's band test (``lowerlimb.calibration.pair_band``).

Rigid sensors keep their own cut-offs even where their acceleration norms make the rigid
band cap them; sensors that move on their segments (simulated tissue with forces of its
own, the real walk's skin-mounted IMUs) keep the cap.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from rigid_pair import rigid_pair
from simcache import data_dir, real_walk_leg_mapping

import lowerlimb as ll
from lowerlimb.calibration import CalibrationOptions, calibrate_spherical_joint
from lowerlimb.calibration._prepare import prepare_pair_bands
from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.pair_band import PairBand
from lowerlimb.calibration.results import SphericalJointCalibration
from lowerlimb.simulation import Artefacts, simulate

OFF = CalibrationOptions(pair_band_test=False)


def _fit(acc_p, gyr_p, acc_c, gyr_c, rate, options=None):  # type: ignore[no-untyped-def]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate_spherical_joint(acc_p, gyr_p, acc_c, gyr_c, rate_hz=rate, options=options)


def _centres(r: SphericalJointCalibration) -> np.ndarray:
    return np.r_[r.center_in_parent_sensor, r.center_in_child_sensor]


def test_rigid_sensors_whose_norms_are_capped_keep_their_own_cut_offs():
    p = rigid_pair(seed=0, duration_s=30.0, still_s=1.0, gyro_noise=0.01, acc_noise=0.05, gyro_bias=0.01)
    args = (p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child, p.rate_hz)
    r = _fit(*args)
    assert r.pair_band is not None, "this pair's norms are capped: the test must run"
    assert not r.pair_band.capped
    assert r.pair_band.full_band_cost > r.pair_band.low_band_gain  # the cap would cost more than it buys
    np.testing.assert_allclose(_centres(r), _centres(_fit(*args, options=OFF)), atol=1e-12)
    err = 1000 * np.linalg.norm(_centres(r) - np.r_[p.center_parent, p.center_child])
    assert err < 3.0


def _own_tissue(seed: int) -> Artefacts:
    """The real-walk profile with each wobbling mass's own force (``sim_signatures.md``: own 3, shared ½)."""
    base = Artefacts.real_walk(seed)
    half = {k: v * 0.5 for k, v in base.tissue_gain.items()}
    own = {"pelvis": 3.0, "thigh": 3.0, "shank": 3.0, "foot": 0.0}
    return dataclasses.replace(base, tissue_random_mps2=own, tissue_gain=half)


def test_sensors_moving_on_their_segments_keep_the_cap_and_land_nearer():
    sim = simulate("mixed", duration_s=40.0, seed=2, artefacts=_own_tissue(2))
    t, truth = sim.trial, sim.truth["joints"]["hip"]
    args = (t.acc["pelvis"], t.gyr["pelvis"], t.acc["thigh"], t.gyr["thigh"], t.rate_hz)
    true = np.r_[truth["center_in_parent_sensor"], truth["center_in_child_sensor"]]
    r, before = _fit(*args), _fit(*args, options=OFF)
    assert r.pair_band is not None and r.pair_band.capped
    err, err_before = (1000 * np.linalg.norm(_centres(x) - true) for x in (r, before))
    assert err < 0.5 * err_before, f"{err:.0f} mm with the cap against {err_before:.0f} mm without"


def test_the_band_test_round_trips_through_calibration_json():
    p = rigid_pair(seed=0, duration_s=30.0, still_s=1.0, gyro_noise=0.01, acc_noise=0.05, gyro_bias=0.01)
    r = _fit(p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child, p.rate_hz)
    d = r.to_dict()
    assert d["pair_band"]["capped"] is False
    back = SphericalJointCalibration.from_dict(d, "joint")
    assert back.pair_band == r.pair_band
    assert isinstance(back.pair_band, PairBand)


DATA = data_dir()


@pytest.mark.data
@pytest.mark.skipif(
    DATA is None or not (DATA / "gait" / "rawimu").is_dir(), reason="real walk (gait/rawimu) not found"
)
@pytest.mark.parametrize("side", ["left", "right"])
def test_the_real_walks_hip_through_the_pair_api_agrees_with_the_leg(side):
    """Without the cap the pair API put the hip 147 / 95 mm from the leg's in the thigh sensor."""
    assert DATA is not None
    trial = ll.read_xsens(DATA / "gait" / "rawimu", real_walk_leg_mapping(side), side=side)
    r = _fit(trial.acc["pelvis"], trial.gyr["pelvis"], trial.acc["thigh"], trial.gyr["thigh"], trial.rate_hz)
    assert r.pair_band is not None and r.pair_band.capped
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        leg = calibrate_leg(trial)
    gap = 1000 * np.linalg.norm(r.center_in_child_sensor - leg.hip.center_in_child_sensor)
    assert gap < 15.0, f"hip in the thigh sensor {gap:.0f} mm from the leg calibration's"


def _line_mm(point: np.ndarray, on: np.ndarray, axis: np.ndarray) -> float:
    d = point - on
    return 1000 * float(np.linalg.norm(d - (d @ axis) * axis))


def test_a_rigid_hinge_keeps_its_own_cut_offs():
    from lowerlimb.calibration import calibrate_hinge_joint

    p = rigid_pair("hinge", seed=0, duration_s=30.0, still_s=1.0, gyro_noise=0.01, acc_noise=0.05)
    args = (p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child)
    bands = prepare_pair_bands(*args, p.rate_hz, CalibrationOptions())
    assert bands.capped is not None and bands.sig.n_still > 0, "the test must be reached"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        h = calibrate_hinge_joint(*args, rate_hz=p.rate_hz)
    assert not any("move on their segments" in str(w.message) for w in caught)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        before = calibrate_hinge_joint(*args, rate_hz=p.rate_hz, options=OFF)
    np.testing.assert_allclose(h.center_in_parent_sensor, before.center_in_parent_sensor, atol=1e-12)
    assert _line_mm(h.center_in_parent_sensor, p.center_parent, p.axis_parent) < 3.0


def test_a_rigid_hinge_without_a_still_start_keeps_its_own_cut_offs():
    """Without a still start the axes' elevations agree over the motion: no refit."""
    from lowerlimb.calibration import calibrate_hinge_joint

    p = rigid_pair("hinge", seed=0, duration_s=30.0, gyro_noise=0.01, acc_noise=0.05)
    args = (p.acc_parent, p.gyr_parent, p.acc_child, p.gyr_child)
    bands = prepare_pair_bands(*args, p.rate_hz, CalibrationOptions())
    assert bands.capped is not None and bands.sig.n_still == 0, "the motion test must be reached"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        h = calibrate_hinge_joint(*args, rate_hz=p.rate_hz)
    assert not any("move on their segments" in str(w.message) for w in caught)
    assert _line_mm(h.center_in_parent_sensor, p.center_parent, p.axis_parent) < 3.0


@pytest.mark.data
@pytest.mark.skipif(
    DATA is None or not (DATA / "gait" / "rawimu").is_dir(), reason="real walk (gait/rawimu) not found"
)
@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("still_start", [True, False])
def test_the_real_walks_knee_through_the_hinge_api_agrees_with_the_leg(side, still_start):
    """Its axis seen from thigh and shank differs by 17 / 22° at rest (and over the walk without
    the standing start): fitted below the cap.

    Without it the centre lay 286 / 155 mm from the leg calibration's axis line in the thigh sensor.
    """
    from lowerlimb.calibration import calibrate_hinge_joint

    assert DATA is not None
    t = ll.read_xsens(DATA / "gait" / "rawimu", real_walk_leg_mapping(side), side=side)
    start = 0 if still_start else 1100  # walking has begun at frame 1120
    pair = [x[start:] for x in (t.acc["thigh"], t.gyr["thigh"], t.acc["shank"], t.gyr["shank"])]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        h = calibrate_hinge_joint(*pair, rate_hz=t.rate_hz)
        knee = calibrate_leg(t).knee
    where = "at rest" if still_start else "over the motion"
    assert any("move on their segments" in str(w.message) and where in str(w.message) for w in caught)
    assert any("move on their segments" in m for m in h.center.warnings)
    for frame in ("parent", "child"):
        gap = _line_mm(
            getattr(h, f"center_in_{frame}_sensor"),
            getattr(knee, f"center_in_{frame}_sensor"),
            getattr(knee, f"axis_in_{frame}_sensor"),
        )
        assert gap < 30.0, f"{side} knee centre in the {frame} sensor {gap:.0f} mm from the leg's axis line"
