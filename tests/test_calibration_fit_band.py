"""The fit band: a leg fitted in a band wider than its sensors' coherent one, unless that breaks it."""

from __future__ import annotations

import warnings
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from simcache import cached_simulation, data_dir, real_walk_leg_mapping

import lowerlimb as ll
from lowerlimb.calibration import calibrate_leg
from lowerlimb.calibration.fit_band import (
    NO_CAP_BINDS,
    NO_STANDING_START,
    FitBand,
    implausible_segment,
    segment_lengths_m,
    widened_caps,
)
from lowerlimb.calibration.leg import LegCalibration
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.errors import InputError
from lowerlimb.simulation import simulate_bilateral


def test_only_the_rigid_band_caps_are_widened() -> None:
    o = CalibrationOptions(fit_band_factor=2.0)
    w = widened_caps(o)
    assert w.rigid_band_factor == 2 * o.rigid_band_factor
    assert (w.cutoff_factor, w.cutoff_hz, w.impact_max_cutoff_hz) == (
        o.cutoff_factor,
        o.cutoff_hz,
        o.impact_max_cutoff_hz,
    )


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"fit_band_factor": 0.9}, "fit_band_factor"),
        ({"fit_band_min_ratio": 1.2}, "fit_band_min_ratio"),
        ({"fit_band_max_ratio": 0.9}, "fit_band_max_ratio"),
        ({"fit_band_max_mismatch_deg": 0.0}, "fit_band_max_mismatch_deg"),
    ],
)
def test_bad_fit_band_options_are_refused(kw: dict[str, float], match: str) -> None:
    with pytest.raises(InputError, match=match):
        CalibrationOptions(**kw)


def test_a_segment_far_from_its_anthropometric_length_is_implausible() -> None:
    truth = LegCalibration.from_dict(cached_simulation("walk", 20.0, 0).truth)
    assert implausible_segment(truth, CalibrationOptions()) is None
    thigh, _ = segment_lengths_m(truth)
    # the hip moved to 5 cm from the knee axis line: a 5 cm thigh
    k = truth.knee
    across = np.cross(k.axis_in_parent_sensor, [1.0, 0.0, 0.0])
    across /= np.linalg.norm(across)
    hip = replace(truth.hip, center_in_child_sensor=k.center_in_parent_sensor + 0.05 * across)
    short = replace(truth, hip=hip)
    reason = implausible_segment(short, CalibrationOptions())
    assert reason is not None and "thigh 50 mm" in reason and "shank" not in reason
    assert thigh > 0.3


def test_a_leg_whose_caps_lower_no_cut_off_is_fitted_once() -> None:
    """A one-leg simulated walk: no cap lowers its sensors' own cut-offs, so the widened band
    would give the same fit; the coherent one is the only one made."""
    trial = cached_simulation("walk", 20.0, 0).trial
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(trial)
        edge = calibrate_leg(trial, options=CalibrationOptions(fit_band_factor=1.0))
    assert cal.fit_band == FitBand(1.5, widened=False, reason=NO_CAP_BINDS) and cal.coherent_fit is None
    np.testing.assert_array_equal(cal.hip.center_in_child_sensor, edge.hip.center_in_child_sensor)
    np.testing.assert_array_equal(cal.knee.axis_in_parent_sensor, edge.knee.axis_in_parent_sensor)


@pytest.fixture(scope="module")
def capped_leg() -> tuple[Any, dict[str, Any]]:
    """A seven-IMU walk whose left hip pair the rigid band caps at 3 Hz (seed 205)."""
    sim = simulate_bilateral(60.0, 205)
    return sim.trial.leg("left"), sim.truth["legs"]["left"]


def _lengths_error_mm(cal: LegCalibration, truth: dict[str, Any]) -> np.ndarray:
    j = truth["joints"]
    leg = SimpleNamespace(
        hip=SphericalJointCalibration.from_dict(j["hip"], "hip"),
        knee=HingeJointCalibration.from_dict(j["knee"]),
        ankle=SphericalJointCalibration.from_dict(j["ankle"], "ankle"),
    )
    true = segment_lengths_m(leg)
    return 1000.0 * (np.array(segment_lengths_m(cal)) - np.array(true))


def test_the_widened_band_undoes_the_coherent_bands_short_segments(capped_leg) -> None:
    """Measured (benchmarks/length_variants.py): thigh −79 → −10 mm, shank −26 → −2 mm."""
    trial, truth = capped_leg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        wide = calibrate_leg(trial)
        edge = calibrate_leg(trial, options=CalibrationOptions(fit_band_factor=1.0))
    pairs = ("pelvis-thigh", "shank-foot", "thigh-shank")  # the caps lowered every pair's cut-offs
    assert wide.fit_band == FitBand(1.5, widened=True, capped=pairs)
    assert edge.fit_band == FitBand(capped=pairs)
    assert wide.coherent_fit is not None  # for the clock search: the coherent band's fit, as `edge`
    assert segment_lengths_m(wide.coherent_fit) == pytest.approx(segment_lengths_m(edge), abs=1e-12)
    e_wide, e_edge = _lengths_error_mm(wide, truth), _lengths_error_mm(edge, truth)
    assert np.all(np.abs(e_wide) < 20.0), e_wide
    assert e_edge[0] < -50.0, e_edge  # the coherent band's edge shortens the thigh
    assert LegCalibration.from_dict(wide.to_dict()).fit_band == wide.fit_band


def test_an_implausible_widened_leg_is_refitted_in_the_coherent_band(capped_leg) -> None:
    """Bounds no leg meets make the widened fit implausible: the leg is the coherent band's,
    with one warning naming why, and the widened fit's own warnings are not issued."""
    trial, _ = capped_leg
    strict = CalibrationOptions(fit_band_min_ratio=0.999, fit_band_max_ratio=1.001)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = calibrate_leg(trial, options=strict)
    with warnings.catch_warnings(record=True) as edge_caught:
        warnings.simplefilter("always")
        edge = calibrate_leg(trial, options=replace(strict, fit_band_factor=1.0))
    assert not cal.fit_band.widened and cal.fit_band.reason is not None and "thigh" in cal.fit_band.reason
    np.testing.assert_allclose(cal.hip.center_in_child_sensor, edge.hip.center_in_child_sensor)
    np.testing.assert_allclose(cal.knee.center_in_parent_sensor, edge.knee.center_in_parent_sensor)
    fallback = [w for w in caught if "fitted in a band 1.5× wider" in str(w.message)]
    assert len(fallback) == 1 and fallback[0].message.args[0] in cal.warnings
    others = sorted(str(w.message) for w in caught if w not in fallback)
    assert others == sorted(str(w.message) for w in edge_caught)
    band = {"factor": 1.5, "widened": False, "reason": cal.fit_band.reason}
    band["capped"] = list(cal.fit_band.capped)
    band["uncapped"] = False  # nor is the fit without caps, implausible under such bounds too
    assert cal.to_dict()["fit_band"] == band and cal.fit_band.capped and cal.coherent_fit is None


def test_a_leg_implausible_in_both_capped_bands_is_fitted_without_the_caps() -> None:
    """A shuffling walk with turns about: rotation about the hip makes the pelvis and thigh
    sensors' acceleration norms incoherent though the sensors are rigid; with the turns' segments
    in the coherence (``rigid_band_max_rotation=None``) the caps at the 2 Hz floor left the thigh
    229 mm long, and the leg fell back on de Leva. Fitted without the caps, its segments are the
    truth's; by default the turns are left out of the coherence and the widened band gives them."""
    from lowerlimb.simulation.turns import TurnParams

    sim = simulate_bilateral(30.0, 203, pace="shuffle", turns=TurnParams())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = calibrate_leg(sim.trial.leg("left"))
    assert default.fit_band.widened and not default.fit_band.uncapped
    assert np.all(np.abs(_lengths_error_mm(default, sim.truth["legs"]["left"])) < 15.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cal = calibrate_leg(sim.trial.leg("left"), options=CalibrationOptions(rigid_band_max_rotation=None))
    assert cal.fit_band.uncapped and not cal.fit_band.widened
    assert cal.fit_band.reason is not None and "thigh" in cal.fit_band.reason
    assert np.all(np.abs(_lengths_error_mm(cal, sim.truth["legs"]["left"])) < 15.0)
    said = [w for w in caught if "without the rigid-band caps" in str(w.message)]
    assert len(said) == 1 and said[0].message.args[0] in cal.warnings
    assert LegCalibration.from_dict(cal.to_dict()).fit_band == cal.fit_band


def test_a_trial_without_a_standing_start_reads_its_knee_over_the_motion(capped_leg) -> None:
    """Rigid sensors show over the motion too: the widened band is kept without a standing start,
    and nearer the truth than the coherent band; the old rule (``fit_band_without_standing=False``)
    keeps the coherent band with the reason recorded."""
    trial, truth = capped_leg
    i = int(10.0 * trial.rate_hz)  # mid-walk
    cut = ll.ImuTrial(
        trial.time_s[i:] - trial.time_s[i],
        {k: v[i:] for k, v in trial.acc.items()},
        {k: v[i:] for k, v in trial.gyr.items()},
        None,
        side=trial.side,
    )
    assert cut.still_period().samples(1.0) == 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(cut)
        edge = calibrate_leg(cut, options=CalibrationOptions(fit_band_factor=1.0))
        old = calibrate_leg(cut, options=CalibrationOptions(fit_band_without_standing=False))
    assert cal.fit_band == FitBand(1.5, widened=True, capped=edge.fit_band.capped)
    assert np.abs(_lengths_error_mm(cal, truth)).max() < np.abs(_lengths_error_mm(edge, truth)).max()
    assert old.fit_band == FitBand(1.5, widened=False, reason=NO_STANDING_START, capped=edge.fit_band.capped)
    assert segment_lengths_m(old) == pytest.approx(segment_lengths_m(edge), abs=1e-12)


@pytest.mark.slow
def test_the_clock_search_of_a_widened_leg_still_finds_its_knee_lag() -> None:
    """Sensor clocks σ 10 ms apart (seed 203, left leg: the shank 25 ms behind the thigh): the
    widened fit's knee explained too little of the mismatch for the lag to count (20 %), so
    the clock search fits in the coherent band and the re-timed leg is then widened again."""
    import dataclasses

    from lowerlimb.simulation import Artefacts

    clock = dataclasses.replace(Artefacts(), clock_offset_std_s=0.01, clock_jitter_std_s=0.0005)
    sim = simulate_bilateral(60.0, 203, artefacts=clock)
    assert sim.artefacts is not None
    off = sim.artefacts.clock_offset_s
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = ll.process_trial(sim.trial.leg("left"))
    shift = res.calibration.clock_offsets["shift_s"]
    true_lag = off["left_thigh"] - off["left_shank"]
    assert abs(true_lag) > 0.02  # the case this guards
    assert abs((shift["shank"] - shift["thigh"]) - true_lag) < 0.005
    assert res.calibration.fit_band.widened


DATA = data_dir()


@pytest.mark.data
@pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent")
def test_real_walk_legs_whose_sensors_turn_on_tissue_stay_in_the_coherent_band() -> None:
    """Both real legs' knee axes differ by 17–24° between the thigh and the shank sensor at
    standing: not rigid sensors, so each leg is the coherent band's fit, identical to a
    calibration without the widened band. (Widened, the left knee's axis line passed 70 mm
    from the hip and the right leg's stance width went from 30.7 to 19 cm, Vicon 30.9.)"""
    assert DATA is not None
    raw = DATA / "gait" / "rawimu"
    for side in ("left", "right"):
        trial = ll.read_xsens(raw, real_walk_leg_mapping(side), side=side)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_leg(trial)
            edge = calibrate_leg(trial, options=CalibrationOptions(fit_band_factor=1.0))
        assert not cal.fit_band.widened and "knee axis" in str(cal.fit_band.reason), side
        assert segment_lengths_m(cal) == pytest.approx(segment_lengths_m(edge), abs=1e-9), side
        assert implausible_segment(cal, CalibrationOptions()) is None


@pytest.mark.data
@pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent")
@pytest.mark.parametrize("side", ["left", "right"])
def test_real_walk_legs_without_their_standing_start_stay_in_the_coherent_band(side: str) -> None:
    """Cut where walking begins, the same legs show their loose sensors over the motion."""
    assert DATA is not None
    trial = ll.read_xsens(DATA / "gait" / "rawimu", real_walk_leg_mapping(side), side=side)
    cut = trial.from_sample(1100)
    assert cut.still_period().samples(0.5) == 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(cut)
    assert not cal.fit_band.widened and "over the motion" in str(cal.fit_band.reason), side


def test_a_knee_that_turns_as_it_flexes_is_not_taken_for_loose_sensors() -> None:
    """A real knee is no hinge: its tibia turns inwards as it flexes (about 11° over a stride
    here). On rigid sensors its two knee axis estimates then differ by 3–4° at standing, within
    ``fit_band_max_mismatch_deg``, so the leg is fitted in the widened band; at the earlier 2°
    the coherent band's fit was kept and both segments came out 13–37 mm short."""
    sim = simulate_bilateral(40.0, 202, pace="slow", knee_rotation_per_flexion=0.2)
    truth = sim.truth["legs"]["left"]["joints"]
    true_leg = SimpleNamespace(
        hip=SphericalJointCalibration.from_dict(truth["hip"], "hip"),
        knee=HingeJointCalibration.from_dict(truth["knee"]),
        ankle=SphericalJointCalibration.from_dict(truth["ankle"], "ankle"),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cal = calibrate_leg(sim.trial.leg("left"))
    assert cal.fit_band.widened, cal.fit_band.reason
    error = np.subtract(segment_lengths_m(cal), segment_lengths_m(true_leg))  # type: ignore[arg-type]
    assert np.all(np.abs(error) < 0.02), error
