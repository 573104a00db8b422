"""Clock offsets between the sensors of a leg, from the joints (lowerlimb.calibration.clock_sync)."""

from __future__ import annotations

import json
import warnings
from collections import Counter
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from simcache import cached_simulation, data_dir, real_walk_leg_mapping

from lowerlimb.calibration import LegCalibration, calibrate_leg
from lowerlimb.calibration.clock_sync import (
    ClockOffsetWarning,
    JointLag,
    chain_shifts,
    estimate_clock_offsets,
    joint_lag,
    late_sensor,
    retime,
    worse_fits,
)
from lowerlimb.calibration.excitation import ExcitationWarning
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.errors import InputError
from lowerlimb.io.trial import ImuTrial
from lowerlimb.pipeline import process_trial
from lowerlimb.simulation import Artefacts

RATE = 100.0
REAL = data_dir()


def _smooth_noise(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(size=n))
    k = np.exp(-0.5 * (np.arange(-30, 31) / 8.0) ** 2)
    return np.convolve(x - x.mean(), k / k.sum(), mode="same")


def test_lag_of_a_delayed_copy_is_found_to_a_fraction_of_a_sample() -> None:
    t = np.arange(3000) / RATE
    a_p = _smooth_noise(t.size, 1)
    a_c = np.interp(t - 0.017, t, a_p)  # the child's sample at t shows the parent's at t - 17 ms
    found = joint_lag(a_p, a_c, RATE, 0.06)
    assert found.lag_s == pytest.approx(0.017, abs=0.0005)
    assert found.explained > 0.95 and found.split_s < 0.001
    # no lag: nothing to explain
    none = joint_lag(a_p, a_p.copy(), RATE, 0.06)
    assert abs(none.lag_s) < 0.0005 and none.explained < 0.01


def test_halves_that_disagree_show_in_split() -> None:
    t = np.arange(4000) / RATE
    a_p = _smooth_noise(t.size, 2)
    half = t < t[t.size // 2]
    a_c = np.where(half, np.interp(t - 0.02, t, a_p), np.interp(t + 0.02, t, a_p))
    assert joint_lag(a_p, a_c, RATE, 0.06).split_s == pytest.approx(0.04, abs=0.003)


def test_retime_moves_only_the_named_sensors() -> None:
    trial = cached_simulation("walk", 20.0, 0).trial
    moved = retime(trial, {"pelvis": 0.0, "thigh": 0.03, "shank": 0.0, "foot": 0.0})
    assert moved.acc["pelvis"] is trial.acc["pelvis"]
    k = 500
    expect = trial.acc["thigh"][k] + 0.0  # t + 30 ms = 3 samples later at 100 Hz
    assert np.allclose(moved.acc["thigh"][k - 3], expect)
    assert np.allclose(moved.gyr["thigh"][k - 3], trial.gyr["thigh"][k])


def test_chain_adds_only_counted_lags() -> None:
    from lowerlimb.calibration.clock_sync import JointLag

    lags = {
        "hip": JointLag(0.010, 0.6, 0.001, True),
        "knee": JointLag(0.030, 0.1, 0.001, False),
        "ankle": JointLag(-0.004, 0.5, 0.002, True),
    }
    assert chain_shifts(lags) == pytest.approx({"pelvis": 0.0, "thigh": 0.010, "shank": 0.010, "foot": 0.006})


def _offset_walk(seed: int) -> tuple[ImuTrial, dict[str, float], LegCalibration]:
    """A walk whose sensor clocks are offset (only that artefact), the lags, the true joints."""
    sim = cached_simulation("walk", 40.0, seed, artefacts=Artefacts(clock_offset_std_s=0.015, seed=seed))
    assert sim.artefacts is not None
    off = sim.artefacts.clock_offset_s
    # the sample stamped t was taken at t + offset: the child lags the pelvis by off_p - off_c
    lags = {s: off["pelvis"] - off[s] for s in ("thigh", "shank", "foot")}
    return sim.trial, lags, LegCalibration.from_dict(sim.truth)


def test_offset_clocks_are_found_and_the_joints_recover() -> None:
    trial, truth, truth_cal = _offset_walk(7)
    assert max(abs(v) for v in truth.values()) > 0.01  # the draw is worth correcting
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = process_trial(trial, calibration_options=CalibrationOptions(clock_sync=False))
    with pytest.warns(ClockOffsetWarning, match="clocks look offset"):
        synced = process_trial(trial)
    shift = synced.calibration.clock_offsets["shift_s"]
    pairs_before = np.diff([0.0] + [truth[s] for s in ("thigh", "shank", "foot")])
    pairs_after = np.diff([0.0] + [truth[s] - shift[s] for s in ("thigh", "shank", "foot")])
    # knee and ankle pairs re-timed to a few ms; the hip's lag is weakly identifiable in
    # one-leg walking (the pelvis hardly rotates) and may stay
    assert np.max(np.abs(pairs_after[1:])) < 0.005 < np.max(np.abs(pairs_before[1:]))
    assert abs(pairs_after[0]) <= abs(pairs_before[0]) + 0.002
    # the joint centres of the re-timed trial are nearer the truth
    for joint in ("hip", "ankle"):
        for key in ("center_in_parent_sensor", "center_in_child_sensor"):
            t_c = getattr(truth_cal.joints[joint], key)
            err_plain = np.linalg.norm(getattr(plain.calibration.joints[joint], key) - t_c)
            err_sync = np.linalg.norm(getattr(synced.calibration.joints[joint], key) - t_c)
            assert err_sync <= err_plain + 0.002, (joint, key, err_plain, err_sync)


def test_a_retimed_walk_warns_once_of_each_finding() -> None:
    """The clock search calibrates again; only the kept calibration's warnings are issued."""
    sim = cached_simulation("walk", 20.0, 3, artefacts=replace(Artefacts.real_walk(), seed=3))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = process_trial(sim.trial)
    assert any(res.calibration.clock_offsets["shift_s"].values())  # the walk was re-timed
    assert [w.category for w in caught].count(ClockOffsetWarning) == 1
    findings = [str(w.message) for w in caught if issubclass(w.category, ExcitationWarning)]
    assert findings  # the artefacts leave something to warn of
    # each finding once (a replaced calibration's copy differs only in its numbers)
    kinds = Counter(m.split("(")[0] for m in findings)
    assert max(kinds.values()) == 1, kinds
    kept = [m for j in res.calibration.joints.values() for m in j.warnings]
    assert set(findings) <= set(kept)


def test_a_hip_lag_is_found_at_the_norm_forms_pelvis_centre() -> None:
    """The aligned form places the hip in the pelvis sensor, but the lag is sought at the norm form's.

    Seven-IMU simulated walk 201 with clock offsets (σ 10 ms): its right thigh lags the pelvis
    by 24.5 ms. At the aligned centre that lag explained 23 % of the mismatch, was not counted,
    and the hip in the thigh sensor came out 415 mm off.
    """
    from lowerlimb.simulation import simulate_bilateral

    clock = replace(Artefacts(), clock_offset_std_s=0.01, clock_jitter_std_s=0.0005)
    sim = simulate_bilateral(60.0, 201, artefacts=clock)
    assert sim.artefacts is not None
    off = sim.artefacts.clock_offset_s
    lag = off["pelvis"] - off["right_thigh"]
    assert lag > 0.02  # the draw this test is about
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = process_trial(sim.trial.leg("right"))
    cal = res.calibration
    assert cal.hip.norm_center_in_parent_sensor is not None  # the aligned form placed it
    shift = cal.clock_offsets["shift_s"]["thigh"]
    assert abs(lag - shift) < 0.008  # measured 4.6 ms left
    truth = np.asarray(sim.truth["legs"]["right"]["joints"]["hip"]["center_in_child_sensor"])
    err = np.linalg.norm(cal.hip.center_in_child_sensor - truth)
    # measured 94 mm, from the 4.6 ms left (415 mm when the lag was missed)
    assert err < 0.15


def test_a_synchronised_walk_is_not_retimed() -> None:
    sim = cached_simulation("walk", 60.0, 1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = process_trial(sim.trial)
    assert not [w for w in caught if issubclass(w.category, ClockOffsetWarning)]
    rec = res.calibration.clock_offsets
    assert all(v == 0.0 for v in rec["shift_s"].values())
    assert not any(j["counted"] for j in rec["joints"].values())
    # the record survives calibration.json
    again = LegCalibration.from_dict(res.calibration.to_dict())
    assert again.clock_offsets == rec


def test_estimate_on_one_pass_reports_every_joint() -> None:
    trial, _, _ = _offset_walk(7)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(trial)
    off = estimate_clock_offsets(trial, cal, CalibrationOptions())
    assert set(off.joints) == {"hip", "knee", "ankle"} and off.passes == 1
    assert set(off.to_dict()["joints"]["knee"]) == {"lag_s", "explained", "split_s", "counted"}


def _residuals(hip: float, knee_axis: float, ankle: float) -> SimpleNamespace:
    return SimpleNamespace(
        hip=SimpleNamespace(rms_residual=hip),
        knee=SimpleNamespace(axis=SimpleNamespace(rms_residual=knee_axis)),
        ankle=SimpleNamespace(rms_residual=ankle),
    )


def test_only_the_joints_a_step_moves_are_checked_and_together() -> None:
    before = _residuals(0.10, 0.03, 0.10)
    knee_step = {"pelvis": 0.0, "thigh": 0.0, "shank": -0.045, "foot": -0.045}
    # a shuffling walk with turns: a 45 ms knee "lag" on synchronised sensors, axis residual 8×
    assert worse_fits(before, _residuals(0.5, 0.28, 0.5), knee_step, 1.1) == pytest.approx({"knee": 28 / 3})
    # a real offset removed: the residual falls; the hip and ankle were not moved by the step
    assert worse_fits(before, _residuals(0.5, 0.01, 0.5), knee_step, 1.1) == {}
    hip_step = {"pelvis": 0.0, "thigh": 0.01, "shank": 0.01, "foot": 0.01}  # only the hip moves
    assert worse_fits(before, _residuals(0.2, 0.28, 0.5), hip_step, 1.1) == pytest.approx({"hip": 2.0})
    # a shank re-timed moves the knee and the ankle: soft tissue raised the knee's residual
    # 1.2× while the ankle's fell 3× (the simulator's artefacts, a real offset): kept
    shank_step = {"pelvis": 0.0, "thigh": 0.0, "shank": 0.03, "foot": 0.022}
    assert worse_fits(before, _residuals(0.5, 0.036, 0.033), shank_step, 1.1) == {}
    both_worse = worse_fits(before, _residuals(0.5, 0.036, 0.12), shank_step, 1.1)
    assert both_worse == pytest.approx({"knee": 1.2, "ankle": 1.2})


def test_a_retiming_that_makes_a_joint_fit_worse_is_undone(monkeypatch) -> None:
    from lowerlimb.calibration import clock_sync
    from lowerlimb.calibration.clock_sync import JointLag, synchronise

    lags = {
        "hip": JointLag(0.0, 0.0, 0.0, False),
        "knee": JointLag(-0.045, 0.41, 0.0005, True),
        "ankle": JointLag(0.0, 0.0, 0.0, False),
    }
    found = {k: replace(v, counted=False) for k, v in lags.items()}  # the next pass: nothing more
    trial = cached_simulation("walk", 20.0, 0).trial
    first = _residuals(0.1, 0.034, 0.1)
    for retimed_axis, undone in ((0.28, True), (0.012, False)):
        passes = iter([lags, found, found])
        monkeypatch.setattr(clock_sync, "estimate_lags", lambda *_, it=passes: next(it))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            out, cal, offsets = synchronise(
                trial, first, lambda _t, r=retimed_axis: _residuals(0.1, r, 0.1), CalibrationOptions()
            )
        warned = any(issubclass(w.category, ClockOffsetWarning) for w in caught)
        if undone:
            assert out is trial and cal is first and not offsets.applied and not warned
            assert offsets.rejected == pytest.approx({"knee": 0.28 / 0.034})
            assert offsets.to_dict()["rejected"] == offsets.rejected
        else:
            assert offsets.applied and offsets.shift_s["shank"] == -0.045 and warned
            assert cal.knee.axis.rms_residual == 0.012 and offsets.rejected == {}


@pytest.mark.parametrize(
    "bad",
    [
        {"clock_max_residual_growth": 0.9},
        {"clock_min_explained": 0.0},
        {"clock_min_explained": 1.5},
        {"clock_max_offset_s": 0.0},
        {"clock_split_tol_s": -0.001},
        {"clock_passes": 0},
    ],
)
def test_clock_options_are_checked(bad: dict[str, float]) -> None:
    with pytest.raises(InputError, match="clock_"):
        CalibrationOptions(**bad)  # type: ignore[arg-type]


@pytest.mark.skipif(REAL is None or not (REAL / "gait").is_dir(), reason="real-walk data absent")
def test_the_synchronised_real_walk_is_not_retimed() -> None:
    """Xsens MTw share one clock: the spurious hip and knee lags must not count."""
    from lowerlimb.io.xsens import read_xsens

    assert REAL is not None
    trial = read_xsens(REAL / "gait" / "rawimu", real_walk_leg_mapping("right"), side="right")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(trial)
    off = estimate_clock_offsets(trial, cal, CalibrationOptions())
    assert not off.applied
    assert abs(off.joints["ankle"].lag_s) < 0.004  # the one well-determined pair: ~1.5 ms


def test_cli_records_the_clock_search_and_can_skip_it(tmp_path) -> None:
    from lowerlimb.cli import main

    trial = tmp_path / "t.csv"
    assert main(["simulate", "--motion", "walk", "--duration", "20", "--seed", "4", "--out", str(trial)]) == 0
    for flag, out in (([], tmp_path / "on"), (["--no-clock-sync"], tmp_path / "off")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rc = main(["calibrate", str(trial), "--out", str(out), "--outputs", "calibration", *flag])
        assert rc == 0
        rec = json.loads((out / "calibration.json").read_text())["clock_offsets"]
        if flag:
            assert rec == {}
        else:
            assert set(rec) == {"shift_s", "joints", "passes", "rejected", "late_sensor"} and not any(
                rec["shift_s"].values()
            )


def test_a_sensor_late_against_both_neighbours_is_named_from_uncounted_lags() -> None:
    def lags(hip: float, knee: float, ankle: float, explained: float = 0.2) -> dict[str, JointLag]:
        found = (("hip", hip), ("knee", knee), ("ankle", ankle))
        return {j: JointLag(v, explained, 0.02, False) for j, v in found}

    o = CalibrationOptions()
    found = late_sensor(lags(0.002, 0.022, -0.013), o)  # the real walk, right shank 30 ms late
    assert found is not None and found.sensor == "shank" and found.lag_s == pytest.approx(0.0175)
    assert "shank sensor's clock looks 17 ms late" in found.message()
    early = late_sensor(lags(-0.02, 0.015, 0.0), o)
    assert early is not None and early.sensor == "thigh" and early.lag_s < 0
    assert late_sensor(lags(0.034, -0.004, 0.001), o) is None  # soft tissue: one joint alone
    assert late_sensor(lags(0.0, 0.022, 0.013), o) is None  # the shank leads one neighbour, trails the other
    assert late_sensor(lags(0.0, 0.030, -0.010), o) is None  # lags 3x apart
    assert late_sensor(lags(0.0, 0.022, -0.013, explained=0.05), o) is None  # explaining too little
    counted = lags(0.0, 0.022, -0.013)
    counted["knee"] = replace(counted["knee"], counted=True)
    assert late_sensor(counted, o) is None  # a counted lag re-times by itself


@pytest.mark.data
@pytest.mark.skipif(REAL is None or not (REAL / "gait").is_dir(), reason="real-walk data absent")
def test_a_real_shank_30_ms_late_is_retimed_and_keeps_its_lengths() -> None:
    """Neither joint's lag counts alone (explaining 21 and 28 %); together they name the shank."""
    from lowerlimb.calibration.fit_band import segment_lengths_m
    from lowerlimb.io.xsens import read_xsens

    assert REAL is not None
    trial = read_xsens(REAL / "gait" / "rawimu", real_walk_leg_mapping("right"), side="right")
    late = retime(trial, {"shank": -0.03})
    runs = {}
    for name, t, sync in (("recorded", trial, True), ("late", late, False), ("late, searched", late, True)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = process_trial(t, calibration_options=CalibrationOptions(clock_sync=sync))
        runs[name] = r.calibration, [str(w.message) for w in caught]
    base = np.array(segment_lengths_m(runs["recorded"][0]))
    assert np.max(np.abs(np.array(segment_lengths_m(runs["late"][0])) - base)) > 0.025  # what it cost
    cal, said = runs["late, searched"]
    assert cal.clock_offsets["late_sensor"]["shank"] == pytest.approx(0.018, abs=0.004)
    assert cal.clock_offsets["shift_s"]["shank"] > 0.01
    assert np.max(np.abs(np.array(segment_lengths_m(cal)) - base)) < 0.01
    assert any("shank" in m and "re-timed" in m for m in said)
