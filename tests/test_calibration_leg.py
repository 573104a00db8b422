import json
import warnings

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration import (
    ExcitationWarning,
    HingeJointCalibration,
    LegCalibration,
    calibrate_leg,
)
from lowerlimb.calibration.geometry import angle_between_deg, distance_to_line
from lowerlimb.conventions import SENSORS
from lowerlimb.errors import InputError
from lowerlimb.io.trial import ImuTrial
from lowerlimb.simulation import ImuNoise

REQUIRED = {
    "spherical": {
        "type",
        "parent_sensor",
        "child_sensor",
        "center_in_parent_sensor",
        "center_in_child_sensor",
        "rms_residual",
    },
}
REQUIRED["hinge"] = REQUIRED["spherical"] | {"axis_in_parent_sensor", "axis_in_child_sensor"}


def errors(cal: LegCalibration, truth: dict) -> dict[str, float]:
    """Errors in mm and degrees against the simulator's truth."""
    t = truth["joints"]
    out: dict[str, float] = {}
    for j in ("hip", "ankle"):
        est = cal.joints[j]
        out[f"{j}_parent_mm"] = 1000 * float(
            np.linalg.norm(est.center_in_parent_sensor - t[j]["center_in_parent_sensor"])
        )
        out[f"{j}_child_mm"] = 1000 * float(
            np.linalg.norm(est.center_in_child_sensor - t[j]["center_in_child_sensor"])
        )
    k, tk = cal.knee, t["knee"]
    out["knee_axis_parent_deg"] = angle_between_deg(k.axis_in_parent_sensor, tk["axis_in_parent_sensor"])
    out["knee_axis_child_deg"] = angle_between_deg(k.axis_in_child_sensor, tk["axis_in_child_sensor"])
    for frame in ("parent", "child"):
        out[f"knee_line_{frame}_mm"] = 1000 * distance_to_line(
            getattr(k, f"center_in_{frame}_sensor"),
            tk[f"center_in_{frame}_sensor"],
            tk[f"axis_in_{frame}_sensor"],
        )
    return out


def assert_walking_goals(e: dict[str, float]) -> None:
    assert e["knee_axis_parent_deg"] <= 1.0 and e["knee_axis_child_deg"] <= 1.0, e
    assert e["hip_child_mm"] <= 10.0 and e["ankle_child_mm"] <= 10.0, e
    assert e["hip_parent_mm"] <= 20.0 and e["ankle_parent_mm"] <= 20.0, e
    assert e["knee_line_parent_mm"] <= 10.0 and e["knee_line_child_mm"] <= 10.0, e


#: Regression bounds (issue 10): about 2.5x what the code achieves on the 60 s noisy walk
#: (seed 1; measured: knee axis 0.026/0.018 deg, knee line 0.88/0.18 mm, hip 1.6/2.4 mm,
#: ankle 9.8/1.9 mm, parent/child sensor frame). The goals above stay as they are; these
#: catch a regression long before the goals do (e.g. no gyro-bias removal: knee 0.09 deg).
WALK_REGRESSION = {
    "knee_axis_parent_deg": 0.065,
    "knee_axis_child_deg": 0.045,
    "knee_line_parent_mm": 2.2,
    "knee_line_child_mm": 0.5,
    "hip_parent_mm": 4.0,
    "hip_child_mm": 6.0,
    "ankle_parent_mm": 15.0,
    "ankle_child_mm": 4.8,
}


@pytest.fixture(scope="module")
def walk_cal(walk_noisy):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExcitationWarning)
        return calibrate_leg(walk_noisy.trial)


def test_walking_recovers_the_leg(walk_cal, walk_noisy):
    assert_walking_goals(errors(walk_cal, walk_noisy.truth))
    assert walk_cal.warnings == []
    assert walk_cal.runtime_s > 0  # recorded; its speed is measured in benchmarks/calibration_accuracy.py
    assert walk_cal.still_s >= 1.0
    bias_err = [np.linalg.norm(walk_cal.gyro_bias[s] - walk_noisy.truth["gyr_bias"][s]) for s in SENSORS]
    assert max(bias_err) < 0.006


def test_walking_stays_near_what_the_code_achieves(walk_cal, walk_noisy):
    e = errors(walk_cal, walk_noisy.truth)
    over = {k: (round(e[k], 3), bound) for k, bound in WALK_REGRESSION.items() if e[k] > bound}
    assert not over, f"regression (measured, bound): {over}"


def test_knee_axes_point_right_and_flexion_is_positive(walk_cal, walk_noisy):
    k, tk = walk_cal.knee, walk_noisy.truth["joints"]["knee"]
    # signed comparison: the truth's axes point to the subject's right
    assert angle_between_deg(k.axis_in_parent_sensor, tk["axis_in_parent_sensor"]) < 1.0
    assert angle_between_deg(k.axis_in_child_sensor, tk["axis_in_child_sensor"]) < 1.0
    assert k.axis.acc_sign_correlation > 0.9
    assert k.axis.flexion_sign_margin > 0.3


def test_calibration_json_schema(walk_cal):
    d = walk_cal.to_dict()
    text = json.dumps(d, allow_nan=False)  # strict JSON
    d = json.loads(text)
    assert d["format"] == "lowerlimb-calibration/1"
    assert d["side"] == "left" and d["method"] == "casadi"
    assert set(d["joints"]) == {"hip", "knee", "ankle"}
    for name, (parent, child, kind) in {
        "hip": ("pelvis", "thigh", "spherical"),
        "knee": ("thigh", "shank", "hinge"),
        "ankle": ("shank", "foot", "spherical"),
    }.items():
        j = d["joints"][name]
        assert REQUIRED[kind] <= set(j)
        assert (j["type"], j["parent_sensor"], j["child_sensor"]) == (kind, parent, child)
        for key in REQUIRED[kind] - {"type", "parent_sensor", "child_sensor", "rms_residual"}:
            assert len(j[key]) == 3 and all(isinstance(v, float) for v in j[key])
        assert len(j["center_std_in_parent_sensor"]) == 3
        assert j["condition_number"] > 1
    assert np.isclose(np.linalg.norm(d["joints"]["knee"]["axis_in_parent_sensor"]), 1.0)
    assert d["runtime_s"] == walk_cal.runtime_s


def test_from_dict_round_trip(walk_cal):
    d = json.loads(json.dumps(walk_cal.to_dict()))
    back = LegCalibration.from_dict(d)
    assert back.to_dict() == d
    assert isinstance(back.knee, HingeJointCalibration)
    assert np.allclose(back.knee.axis_in_child_sensor, walk_cal.knee.axis_in_child_sensor)


def test_from_dict_accepts_the_minimal_schema(walk_noisy):
    truth = LegCalibration.from_dict(walk_noisy.truth)
    assert truth.side == "left"
    assert np.allclose(
        truth.hip.center_in_parent_sensor, walk_noisy.truth["joints"]["hip"]["center_in_parent_sensor"]
    )
    with pytest.raises(InputError, match="format"):
        LegCalibration.from_dict({"format": "other"})
    with pytest.raises(InputError, match="joints"):
        LegCalibration.from_dict({"format": "lowerlimb-calibration/1", "side": "left"})


@pytest.mark.parametrize("method", ["gn", "gwo+casadi"])
def test_methods_agree_on_clean_walking(walk_clean, method):
    ref = calibrate_leg(walk_clean.trial)
    other = calibrate_leg(walk_clean.trial, method=method)
    for j in ("hip", "knee", "ankle"):
        assert np.allclose(
            ref.joints[j].center_in_child_sensor, other.joints[j].center_in_child_sensor, atol=1e-3
        )
    assert angle_between_deg(ref.knee.axis_in_parent_sensor, other.knee.axis_in_parent_sensor) < 0.05
    e = errors(ref, walk_clean.truth)
    assert max(e["hip_child_mm"], e["ankle_child_mm"], e["knee_line_child_mm"]) < 5.0
    assert max(e["knee_axis_parent_deg"], e["knee_axis_child_deg"]) < 0.2


def test_right_leg():
    sim = cached_simulation("walk", 30.0, 7, side="right")
    cal = calibrate_leg(sim.trial)
    assert cal.side == "right"
    assert_walking_goals(errors(cal, sim.truth))


def test_a_leg_that_does_not_move_warns_without_nan():
    rng = np.random.default_rng(3)
    n = 1000
    t = np.arange(n) / 100.0
    acc, gyr = {}, {}
    for s in SENSORS:
        g = rng.normal(size=3)
        acc[s] = 9.81 * g / np.linalg.norm(g) + 0.08 * rng.normal(size=(n, 3))
        gyr[s] = 0.01 * rng.normal(size=3) + 0.015 * rng.normal(size=(n, 3))
    trial = ImuTrial(time_s=t, acc=acc, gyr=gyr, side="left")
    with pytest.warns(ExcitationWarning):
        cal = calibrate_leg(trial)
    d = cal.to_dict()
    json.dumps(d, allow_nan=False)
    for j in d["joints"].values():
        assert np.all(np.isfinite(j["center_in_parent_sensor"]))
    assert {w.split(":")[0] for w in cal.warnings} == {"hip", "knee", "ankle"}


def test_trial_errors(walk_clean):
    tr = walk_clean.trial
    broken = ImuTrial(
        time_s=tr.time_s, acc={k: v for k, v in tr.acc.items() if k != "foot"}, gyr=tr.gyr, side="left"
    )
    with pytest.raises(InputError, match="no foot sensor"):
        calibrate_leg(broken)
    with pytest.raises(InputError, match="unknown calibration method"):
        calibrate_leg(tr, method="newton")


@pytest.mark.slow
@pytest.mark.parametrize("seed", [11, 12, 13])
def test_walking_goals_over_seeds(seed):
    sim = cached_simulation("walk", 60.0, seed)
    assert_walking_goals(errors(calibrate_leg(sim.trial), sim.truth))


@pytest.mark.slow
@pytest.mark.parametrize("motion", ["squat", "knee-lift", "sit-to-stand"])
def test_other_motions_are_accurate_or_warn(motion):
    """Knee axis always within 1°; a centre worse than the walking goals must carry a warning."""
    sim = cached_simulation(motion, 60.0, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExcitationWarning)
        cal = calibrate_leg(sim.trial)
    e = errors(cal, sim.truth)
    assert e["knee_axis_parent_deg"] <= 1.0 and e["knee_axis_child_deg"] <= 1.0
    for j, limit in (("hip", 20.0), ("ankle", 20.0)):
        if max(e[f"{j}_parent_mm"], e[f"{j}_child_mm"]) > limit:
            assert cal.joints[j].warnings, (j, e)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [21, 22])
def test_rich_motion_meets_10_mm_in_every_sensor_frame(seed):
    """Knee lifts with hip and ankle circles and a turning pelvis ("mixed"): <= 10 mm everywhere."""
    sim = cached_simulation("mixed", 60.0, seed)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ExcitationWarning)  # well excited: no warning either
        e = errors(calibrate_leg(sim.trial), sim.truth)
    assert max(v for k, v in e.items() if k.endswith("mm")) <= 10.0, e
    assert e["knee_axis_parent_deg"] <= 0.5


def test_noise_free_squat_is_exact():
    sim = cached_simulation("squat", 30.0, 3, noise=ImuNoise.none())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExcitationWarning)
        e = errors(calibrate_leg(sim.trial), sim.truth)
    assert max(v for k, v in e.items() if k.endswith("mm")) < 2.0
    assert max(v for k, v in e.items() if k.endswith("deg")) < 0.2
