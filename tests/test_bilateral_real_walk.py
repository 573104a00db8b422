"""The two-leg benchmark on the real walk (gait/ in the shared data), bounds ~2-3x the measured errors."""

import importlib.util
from pathlib import Path

import pytest
from simcache import data_dir

DATA = data_dir()
pytestmark = [
    pytest.mark.data,
    pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent"),
]


def _benchmark():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bilateral_gait.py"
    spec = importlib.util.spec_from_file_location("bilateral_gait_benchmark", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_real_walk_two_legs():
    assert DATA is not None
    res = _benchmark().run(DATA)
    assert res["both_legs_calibrate"], res.get("error")
    for side, s in res["legs"].items():
        # measured: left -10/+7 mm, right +30/+0 mm (the same as each leg alone)
        assert abs(s["thigh_err_mm"]) < 70 and abs(s["shank_err_mm"]) < 40, side
    assert res["legs"]["left"]["knee_flexion_rmse_deg"] < 25  # measured 10.6
    assert res["legs"]["right"]["knee_flexion_rmse_deg"] < 12  # measured 4.6
    assert res["legs"]["left"]["hip_flexion_rmse_deg"] < 25  # measured 13.6
    assert res["legs"]["right"]["hip_flexion_rmse_deg"] < 15  # measured 7.5
    assert (
        res["stride_length_err_pct"]["n"] >= 5 and res["stride_length_err_pct"]["median_abs"] < 4.0
    )  # 1.3 %
    # measured 11.9 mm (54 mm with each leg's own pelvis and hip centre)
    assert res["step_width_err_mm"]["n"] >= 3 and res["step_width_err_mm"]["median_abs"] < 40
    # one pelvis: measured +2 mm (the single-leg centres +104 mm: poorly determined vertically)
    assert abs(res["hips"]["spacing_err_mm"]) < 40
    assert res["hips"]["single_leg_spacing_mm"] > res["hips"]["spacing_mm"]
    # the walk's one turn (to the right) against the Vicon pelvis markers: measured 0.04 / 0.03 s
    # at its start / end, 0.1° of its angle (-184°)
    (imu,), (ref,) = res["turns"]["imu"], res["turns"]["vicon"]
    assert imu["direction"] == ref["direction"] == "right" and imu["complete"]
    assert abs(imu["angle_deg"] - ref["angle_deg"]) < 5.0 and abs(abs(imu["angle_deg"]) - 180.0) < 20.0
    assert abs(imu["start_s"] - ref["start_s"]) < 0.2 and abs(imu["end_s"] - ref["end_s"]) < 0.2
    assert imu["steps"] >= 2


def _real_walk_and_swapped():
    """The real walk as a two-leg trial, and the same with its left_* and right_* columns exchanged."""
    from lowerlimb.io import load_xsens
    from lowerlimb.io.bilateral_trial import BilateralTrial

    assert DATA is not None
    mod = _benchmark()
    rec = load_xsens(mod.raw_dir(DATA), mod.IDS)

    def swap(d: dict) -> dict:
        out = {"pelvis": d["pelvis"]}
        for seg in ("thigh", "shank", "foot"):
            out[f"left_{seg}"], out[f"right_{seg}"] = d[f"right_{seg}"], d[f"left_{seg}"]
        return out

    mag = swap(rec.mag) if rec.mag is not None else None
    return (
        BilateralTrial(rec.time_s, rec.acc, rec.gyr, rec.mag),
        BilateralTrial(rec.time_s, swap(rec.acc), swap(rec.gyr), mag),
    )


def test_swapped_legs_of_the_real_walk_are_refused():
    """Exchanging the left_* and right_* columns is caught from the pair of hips (one line, the fix)."""
    import warnings

    from lowerlimb.bilateral import process_bilateral_trial
    from lowerlimb.bilateral.process import BilateralSideError

    trial, swapped = _real_walk_and_swapped()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(BilateralSideError, match="look swapped.*exchange the left_\\* and right_\\*"):
            process_bilateral_trial(swapped)
        process_bilateral_trial(trial)  # as recorded: no error


def test_swapped_looking_hips_are_kept_when_the_pelvis_turn_confirms_the_sides(monkeypatch):
    """The pair verdict hears the pelvis-turn cue: hips that look swapped while both legs' cues
    confirm their labels give a SideEvidenceWarning, not a refusal (the swapped real walk with
    the cue made to confirm the labels it was given)."""
    from lowerlimb.bilateral import process
    from lowerlimb.calibration.plausibility import SideEvidenceWarning

    _, swapped = _real_walk_and_swapped()
    monkeypatch.setattr(process, "_pelvis_turn", lambda leg: -0.3 if leg.trial.side == "left" else 0.3)
    with pytest.warns(SideEvidenceWarning, match="pelvis turns with each leg"):
        process.process_bilateral_trial(swapped)


def test_the_real_walk_cut_mid_stride_calibrates_without_step_width():
    """Cut 0.3 s after walking begins (no standing start): both legs calibrate with one
    standing-start warning, the gyro bias is measured over the walk's standing end (1-2 °/s
    on these sensors), the strides keep their lengths and the step width is null, not the
    94-145 mm error an anchor at the walk's standing end gave (benchmarks/cut_start.py)."""
    import warnings

    import numpy as np

    from lowerlimb.bilateral import UnanchoredFeetWarning, process_bilateral_trial
    from lowerlimb.io.trial import StandingStartWarning

    trial, _ = _real_walk_and_swapped()
    cut = trial.from_sample(1150)  # walking begins at sample 1120
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = process_bilateral_trial(cut)
    assert sum(issubclass(w.category, StandingStartWarning) for w in caught) == 1
    assert sum(issubclass(w.category, UnanchoredFeetWarning) for w in caught) == 1
    strides = res.gait.parameters.strides
    lengths = np.array([s.stride_length_m for s in strides if not s.turning])
    lengths = lengths[np.isfinite(lengths)]
    # Vicon: 1.3-1.5 m on the straight passes; the stopping step at the end is short
    assert np.count_nonzero((lengths > 1.2) & (lengths < 1.8)) >= 5
    assert all(np.isnan(s.step_width_m) for s in strides)
    # no still start: the gyro bias comes from the walk's standing end, and matches the start's
    for side in ("left", "right"):
        end = res.legs[side].calibration.gyro_bias["foot"]
        start = trial.gyr[f"{side}_foot"][200:1000].mean(axis=0)  # the standing start
        assert np.degrees(np.abs(end - start)).max() < 0.3 and np.degrees(np.abs(end)).max() > 0.5
