"""A low-rate trial is interpolated for the joint calibration and the gait events only."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from lowerlimb.calibration.leg import LegCalibration, calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.cli import main
from lowerlimb.errors import InputError
from lowerlimb.gait import GaitEvents, GaitParams, detect_gait_events
from lowerlimb.simulation import simulate_bilateral
from lowerlimb.stillness import StillPeriod
from lowerlimb.upsample import upsample_factor, upsampled, upsampled_still


@pytest.mark.parametrize(
    ("rate", "factor"), [(60.0, 2), (50.0, 2), (51.2, 2), (64.0, 2), (30.0, 4), (100.0, 1), (200.0, 1)]
)
def test_the_factor_is_the_smallest_integer_reaching_the_rate(rate, factor):
    assert upsample_factor(rate, 100.0) == factor
    assert factor * rate >= 100.0 - 1e-9


def test_a_rate_just_under_the_minimum_is_left_alone():
    # timestamps of a 100 Hz recording may say 99.8 Hz: not worth twice the samples
    assert upsample_factor(99.8, 100.0) == 1
    assert upsample_factor(96.0, 100.0) == 1
    assert upsample_factor(94.0, 100.0) == 2


def test_no_minimum_rate_means_no_interpolation():
    assert upsample_factor(20.0, None) == 1
    assert upsampled({"a": np.ones((5, 3))}, 1)["a"].shape == (5, 3)


def test_a_band_limited_signal_is_interpolated_and_a_constant_kept():
    rate, k = 60.0, 2
    t = np.arange(600) / rate

    def signal(t):
        w = 2 * np.pi * t
        return np.column_stack([np.sin(3.0 * w), np.cos(7.0 * w), np.full(t.size, 9.81)])

    y = upsampled({"s": signal(t)}, k)["s"]
    assert y.shape == (1200, 3)
    truth = signal(np.arange(1200) / (rate * k))
    inner = slice(100, 1100)  # the FIR's edges aside
    assert np.max(np.abs(y[inner] - truth[inner])) < 0.01
    assert y[:, 2] == pytest.approx(9.81, abs=1e-9)  # a still start stays still


def test_the_still_start_scales_with_the_samples():
    quiet = np.array([True, True, False, True])
    s = upsampled_still(StillPeriod(3, 60.0, quiet), 2)
    assert s is not None and s.n_samples == 6 and s.rate_hz == 120.0
    assert s.quiet is not None and s.quiet.tolist() == [True, True, True, True, False, False, True, True]
    assert upsampled_still(None, 2) is None


def test_a_bad_minimum_rate_is_refused_by_name():
    for bad in (0.0, -5.0, float("nan"), float("inf")):
        with pytest.raises(InputError, match="min_fit_rate_hz"):
            CalibrationOptions(min_fit_rate_hz=bad)


def test_a_60_hz_walk_places_the_ankle_as_a_100_hz_one():
    """Seven-IMU walk at 60 Hz, 20 s, seed 202: the ankle in the shank sensor was 108 mm off
    fitted on the recorded samples and 14 mm interpolated to 120 Hz (100 Hz walks: 2-15 mm)
    before the ankle pair was low-passed at 12 Hz with impacts (``impact_max_cutoff_hz``);
    now 15 and 8 mm. The calibration reports the recorded rate's still start in seconds
    either way."""
    sim = simulate_bilateral(20.0, 202, rate_hz=60.0)
    leg = sim.trial.leg("left")
    true = np.asarray(sim.truth["legs"]["left"]["joints"]["ankle"]["center_in_parent_sensor"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        interp = calibrate_leg(leg)
        recorded = calibrate_leg(leg, options=CalibrationOptions(min_fit_rate_hz=None))
    err = float(np.linalg.norm(interp.ankle.center_in_parent_sensor - true))
    err_recorded = float(np.linalg.norm(recorded.ankle.center_in_parent_sensor - true))
    assert err < 0.012
    assert err < 0.7 * err_recorded
    assert interp.still_s == pytest.approx(recorded.still_s, abs=0.02)
    assert interp.fit_rate_hz == pytest.approx(120.0) and recorded.fit_rate_hz == pytest.approx(60.0)
    doc = interp.to_dict()
    assert LegCalibration.from_dict(doc).fit_rate_hz == doc["fit_rate_hz"] == interp.fit_rate_hz


def test_the_command_line_says_the_calibration_was_interpolated(tmp_path, capsys):
    trial, out = tmp_path / "w60.csv", tmp_path / "out"
    argv = ["simulate", "--duration", "20", "--seed", "3", "--rate", "60", "--out", str(trial)]
    assert main(argv) == 0
    assert main(["calibrate", str(trial), "--out", str(out)]) == 0
    cal = json.loads((out / "calibration.json").read_text())
    assert cal["fit_rate_hz"] == pytest.approx(120.0, abs=0.01)
    html = (out / "report.html").read_text()
    assert "120 Hz (interpolated from 60 Hz)" in html
    # the outputs keep the recorded samples
    assert len((out / "angles.csv").read_text().splitlines()) == 1 + 20 * 60


def test_gait_events_of_a_60_hz_walk_are_timed_on_interpolated_signals():
    """Seven-IMU walk at 60 Hz, 20 s, seed 206: on the signals interpolated to 120 Hz the
    initial contacts are 7 / 9 ms off median / worst, on the recorded samples 10 / 14 ms
    (toe-offs 2.4 / 4.3 against 3.4 / 6.8 ms). The stationary periods stay on the recorded
    samples."""
    sim = simulate_bilateral(20.0, 206, rate_hz=60.0)
    tr = sim.trial

    def errors_ms(params: GaitParams) -> tuple[dict[str, np.ndarray], GaitEvents]:
        ev = detect_gait_events(
            60.0,
            **{f"{s}_shank_gyr": tr.gyr[f"{s}_shank"] for s in ("left", "right")},
            **{f"{s}_foot_gyr": tr.gyr[f"{s}_foot"] for s in ("left", "right")},
            **{f"{s}_foot_acc": tr.acc[f"{s}_foot"] for s in ("left", "right")},
            params=params,
        )
        errs = {
            name: np.array(
                [
                    1000.0 * float(np.min(np.abs(getattr(getattr(ev, s), name) - t)))
                    for s in ("left", "right")
                    for t in getattr(sim.feet[s].events, name)
                    if t > 3.0
                ]
            )
            for name in ("initial_contact_s", "toe_off_s")
        }
        return errs, ev

    interp, ev = errors_ms(GaitParams())
    recorded, _ = errors_ms(GaitParams(min_event_rate_hz=None))
    assert interp["toe_off_s"].max() < 10.0 and interp["initial_contact_s"].max() < 10.0
    for name in ("initial_contact_s", "toe_off_s"):
        assert np.median(interp[name]) < np.median(recorded[name])
        assert interp[name].max() < recorded[name].max()
    assert ev.left is not None and ev.left.stationary is not None
    assert ev.left.stationary.rate_hz == 60.0 and ev.left.stationary.mask.shape == (tr.n_samples,)
    with pytest.raises(InputError, match="min_event_rate_hz"):
        GaitParams(min_event_rate_hz=0.0)
