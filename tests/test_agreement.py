import math
import warnings

import numpy as np
import pytest

from lowerlimb.agreement import (
    AgreementParams,
    AlignmentError,
    EmptyReferenceError,
    NoCommonColumnsError,
    NoTimeOverlapError,
    ReferenceTimeUnitError,
    ReferenceUnitError,
    TooLittleTimeOverlapError,
    agreement_statistics,
    cmc_two_waveforms,
    compare_series,
    estimate_time_offset,
    pearson_r,
    plot_bland_altman,
    resample_linear,
)
from lowerlimb.errors import InputError, ShapeError, TimeAxisError

OURS = [1.0, 2.0, 3.0, 4.0, 5.5]
REF = [1.5, 1.5, 3.5, 3.0, 5.0]


def test_bland_altman_matches_hand_computation():
    # d = ours - ref = [-0.5, 0.5, -0.5, 1.0, 0.5]; mean 0.2
    # deviations from the mean: -0.7, 0.3, -0.7, 0.8, 0.3 -> sum of squares 1.8 -> SD = sqrt(1.8 / 4)
    s = agreement_statistics(OURS, REF, quantity="knee_flexion", unit="deg")
    sd = math.sqrt(0.45)
    assert s.n == 5 and s.unit == "deg" and s.quantity == "knee_flexion"
    assert s.bias == pytest.approx(0.2, abs=1e-12)
    assert s.sd_diff == pytest.approx(sd, abs=1e-12)
    assert s.loa_lower == pytest.approx(0.2 - 1.96 * sd, abs=1e-12)
    assert s.loa_upper == pytest.approx(0.2 + 1.96 * sd, abs=1e-12)
    assert s.loa_upper == pytest.approx(1.5148070, abs=1e-6)
    # d^2 = .25 .25 .25 1 .25 -> mean 0.4
    assert s.rmse == pytest.approx(math.sqrt(0.4), abs=1e-12)
    # sum dx dy = 9.55, sum dx^2 = 12.2, sum dy^2 = 8.7
    assert s.pearson_r == pytest.approx(9.55 / math.sqrt(12.2 * 8.7), abs=1e-12)
    assert s.offset_removed == 0.0


def test_cmc_matches_hand_computation():
    # frame means (x+y)/2; within-frame SS = sum(d^2)/2 = 1.0 -> / (F (G-1)) = 1/5
    # grand mean 3.0; total SS = 12.25 + 8.75 = 21 -> / (G F - 1) = 21/9
    assert cmc_two_waveforms(OURS, REF) == pytest.approx(math.sqrt(1 - 0.2 / (21 / 9)), abs=1e-12)
    s = agreement_statistics(OURS, REF, quantity="q", unit="deg")
    assert s.cmc == pytest.approx(0.9561829, abs=1e-6)


def test_cmc_undefined_cases_and_offset_sensitivity():
    assert math.isnan(cmc_two_waveforms([2.0, 2.0, 2.0], [2.0, 2.0, 2.0]))  # no variance at all
    # opposite square waves: within-frame variance exceeds the total -> complex CMC -> NaN
    assert math.isnan(cmc_two_waveforms([0, 1, 0, 1], [1, 0, 1, 0]))
    t = np.linspace(0, 2 * np.pi, 200)
    assert cmc_two_waveforms(np.sin(t), np.sin(t)) == pytest.approx(1.0)
    # an offset leaves r at 1 but lowers the CMC
    assert pearson_r(np.sin(t) + 0.5, np.sin(t)) == pytest.approx(1.0)
    assert cmc_two_waveforms(np.sin(t) + 0.5, np.sin(t)) < 0.95
    assert math.isnan(pearson_r([1.0, 1.0, 1.0], [1.0, 2.0, 3.0]))


def test_remove_offset_and_nan_pairs():
    ours = np.array(OURS + [np.nan, 7.0]) + 10.0
    ref = np.array(REF + [3.0, np.nan])
    s = agreement_statistics(ours, ref, quantity="q", unit="m", remove_offset=True)
    assert s.n == 5
    assert s.offset_removed == pytest.approx(10.2, abs=1e-12)
    assert s.bias == pytest.approx(0.0, abs=1e-12)
    assert s.sd_diff == pytest.approx(math.sqrt(0.45), abs=1e-12)
    assert s.rmse == pytest.approx(math.sqrt(1.8 / 5), abs=1e-12)
    few = agreement_statistics([1.0, np.nan, 3.0], [1.0, 2.0, np.nan], quantity="q", unit="m")
    assert few.n == 1 and math.isnan(few.rmse)
    with pytest.raises(ShapeError):
        agreement_statistics([1.0, 2.0], [1.0], quantity="q", unit="m")


def test_params_change_the_limits():
    s = agreement_statistics(
        OURS, REF, quantity="q", unit="deg", params=AgreementParams(loa_z=2.0, sd_ddof=0)
    )
    sd0 = math.sqrt(1.8 / 5)
    assert s.loa_upper == pytest.approx(0.2 + 2.0 * sd0, abs=1e-12)


def test_resample_linear_does_not_extrapolate_or_bridge_gaps():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    v = np.array([0.0, 10.0, np.nan, 30.0])
    out = resample_linear(t, v, np.array([-0.5, 0.0, 0.5, 1.0, 1.5, 2.5, 3.0, 3.5]))
    assert out[1] == 0.0 and out[2] == 5.0 and out[3] == 10.0 and out[6] == 30.0
    assert np.isnan(out[[0, 4, 5, 7]]).all()


def _signals(t):
    """Two non-periodic gait-like waveforms (deg)."""
    knee = 30 * np.sin(2 * np.pi * 0.9 * t) ** 2 + 8 * np.sin(2 * np.pi * 0.31 * t)
    hip = 20 * np.sin(2 * np.pi * 0.9 * t + 0.7) + 5 * np.cos(2 * np.pi * 0.17 * t)
    return np.column_stack([knee, hip])


def test_known_time_shift_is_recovered():
    t = np.arange(0, 20, 0.01)  # our clock, 100 Hz
    true_offset = 0.237  # reference time stamps lag ours: t_ref = t_true - offset
    t_ref = np.arange(0.5, 19.0, 1 / 120) - true_offset  # 120 Hz reference on its own clock
    ref = _signals(t_ref + true_offset)
    a = estimate_time_offset(t, _signals(t), t_ref, ref)
    assert a.offset_s == pytest.approx(true_offset, abs=0.002)
    assert a.peak_correlation > 0.999 and not a.at_window_edge and a.n_quantities == 2
    assert a.search_window_s == pytest.approx(2.0)
    # and the other direction, with a constant offset between the systems (ignored by r)
    b = estimate_time_offset(t, _signals(t), t_ref + 2 * true_offset, ref + 5.0)
    assert b.offset_s == pytest.approx(-true_offset, abs=0.002)


def _walk(t, variability=0.15):
    """Knee and hip of a walk that repeats each 1.1 s stride, its amplitude varying by stride (deg)."""
    rng = np.random.default_rng(7)
    knots = np.arange(-10, 40, 1.1)
    amp = np.interp(t, knots, 1 + variability * rng.standard_normal(knots.size))
    phase = 2 * np.pi * t / 1.1 + 0.1 * np.sin(2 * np.pi * t / 7.3)
    return np.column_stack([30 * amp * np.sin(phase) ** 2, 20 * amp * np.sin(phase + 0.7)])


@pytest.mark.parametrize("variability", [0.05, 0.15])
def test_an_offset_beyond_the_window_is_called_ambiguous_within_it_is_not(variability):
    t = np.arange(0, 30, 0.01)
    t_true = np.arange(-8, 38, 0.01)
    ref = _walk(t_true, variability)
    for shift in (1.5, -1.5, 0.4):  # within ±2 s: found, and clear even on a very regular walk
        a = estimate_time_offset(t, _walk(t, variability), t_true - shift, ref)
        assert a.offset_s == pytest.approx(shift, abs=0.002)
        assert not a.ambiguous and a.second_peak_correlation is not None
    for shift in (5.0, -5.0, 3.3):  # beyond: the best peak is a wrong stride, almost tied with another
        a = estimate_time_offset(t, _walk(t, variability), t_true - shift, ref)
        assert abs(a.offset_s - shift) > 0.5 and a.ambiguous, a
        assert abs(a.second_peak_offset_s - a.offset_s) >= AgreementParams().min_peak_separation_s


def test_compare_series_warns_once_of_an_ambiguous_offset():
    t = np.arange(0, 30, 0.01)
    t_true = np.arange(-8, 38, 0.01)
    ours = dict(zip(["knee_flexion", "hip_flexion"], _walk(t).T, strict=True))
    ref = dict(zip(["knee_flexion", "hip_flexion"], _walk(t_true).T, strict=True))
    units = dict.fromkeys(ours, "deg")
    with pytest.warns(UserWarning) as caught:
        c = compare_series(t, ours, units, t_true - 5.0, ref, align_time=True)
    assert len(caught) == 1
    text = str(caught[0].message)
    assert "is ambiguous" in text and "outside ±2 s" in text and "align the reference by hand" in text
    assert c.alignment is not None and c.alignment.ambiguous
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        compare_series(t, ours, units, t_true - 1.5, ref, align_time=True)  # no warning


def test_compare_series_aligns_then_scores():
    t = np.arange(0, 20, 0.01)
    true_offset = -0.31
    t_ref = np.arange(0.0, 20.0, 0.01) - true_offset
    rng = np.random.default_rng(3)
    ref_vals = _signals(t_ref + true_offset)
    noise = rng.normal(0, 0.5, t.size)  # on our samples: not smoothed by the resampling
    ours = _signals(t)
    units = {"knee_flexion": "deg", "hip_flexion": "deg", "pelvis_to_foot_x": "m"}
    ours_d = {"knee_flexion": ours[:, 0] + 1.5 + noise, "hip_flexion": ours[:, 1], "pelvis_to_foot_x": t * 0}
    ref_d = {"knee_flexion": ref_vals[:, 0], "hip_flexion": ref_vals[:, 1], "vicon_only": t_ref}
    raw = compare_series(t, ours_d, units, t_ref, ref_d)
    c = compare_series(t, ours_d, units, t_ref, ref_d, align_time=True)
    assert c.time_offset_s == pytest.approx(true_offset, abs=0.005)
    assert [s.quantity for s in c.quantities] == ["knee_flexion", "hip_flexion"]
    assert c.ignored_reference_columns == ("vicon_only",)
    knee = c.quantities[0]
    assert knee.bias == pytest.approx(1.5, abs=0.05)
    assert knee.sd_diff == pytest.approx(np.std(noise, ddof=1), abs=0.01)  # only the added noise is left
    assert raw.quantities[0].rmse > 3 * knee.rmse
    d = compare_series(t, ours_d, units, t_ref, ref_d, align_time=True, remove_offset=True)
    assert d.quantities[0].bias == pytest.approx(0.0, abs=1e-9)
    assert d.quantities[0].offset_removed == pytest.approx(1.5, abs=0.05)
    assert c.series[0].ours.shape == c.series[0].reference.shape == (knee.n,)


def test_compare_series_errors():
    t = np.arange(0, 5, 0.01)
    ours = {"knee_flexion": np.sin(t)}
    units = {"knee_flexion": "deg"}
    with pytest.raises(NoCommonColumnsError, match="hip_flex"):
        compare_series(t, ours, units, t, {"hip_flex": np.sin(t)})
    with pytest.raises(NoTimeOverlapError, match="no overlap"):
        compare_series(t, ours, units, t + 100, {"knee_flexion": np.sin(t)})
    with pytest.raises(EmptyReferenceError, match="knee_flexion"):
        compare_series(t, ours, units, t, {"knee_flexion": np.full(t.size, np.nan)})
    with pytest.raises(AlignmentError):
        compare_series(t, ours, units, t, {"knee_flexion": np.full(t.size, np.nan)}, align_time=True)
    with pytest.raises(TimeAxisError, match="strictly increasing"):
        compare_series(t, ours, units, t[::-1], {"knee_flexion": np.sin(t)})


def test_bland_altman_plot_is_written(tmp_path):
    t = np.arange(0, 5, 0.01)
    units = {"a": "deg", "b": "deg"}
    c = compare_series(t, {"a": np.sin(t), "b": np.cos(t)}, units, t, {"a": np.sin(t) + 0.1, "b": np.cos(t)})
    path = tmp_path / "ba.png"
    plot_bland_altman(path, c.quantities, c.series, title="test")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000


def test_compare_series_refuses_a_reference_clock_in_ms():
    t = np.arange(0, 30, 0.01)
    ours = {"knee_flexion": 30 * np.sin(t)}
    t_ms = 1000 * t  # 0…29990 "s": only its first 4 samples overlap ours
    with pytest.raises(ReferenceTimeUnitError, match=r"like milliseconds.*divide its time column") as e:
        compare_series(t, ours, {"knee_flexion": "deg"}, t_ms, {"knee_flexion": 30 * np.sin(t)})
    assert e.value.median_step == pytest.approx(10.0) and e.value.our_step_s == pytest.approx(0.01)


def test_compare_series_refuses_spans_that_barely_overlap():
    t = np.arange(0, 30, 0.01)
    ours = {"knee_flexion": 30 * np.sin(t)}
    units = {"knee_flexion": "deg"}
    t_ref = t + 29.5  # 0.49 s in common
    with pytest.raises(TooLittleTimeOverlapError, match=r"overlap for only 0\.49 s") as e:
        compare_series(t, ours, units, t_ref, {"knee_flexion": 30 * np.sin(t_ref)})
    assert e.value.overlap_s == pytest.approx(0.49) and e.value.min_fraction == 0.25
    # a short reference inside our span passes
    inner = (t > 10) & (t < 14)
    compare_series(t, ours, units, t[inner], {"knee_flexion": ours["knee_flexion"][inner]})
    # a reference clock 1.8 s late on a 2 s trial overlaps 10 %: refused, unless alignment may shift it
    t2 = t[:200]
    short = {"knee_flexion": _signals(t2)[:, 0]}
    late = {"knee_flexion": _signals(t2)[:, 0]}
    with pytest.raises(TooLittleTimeOverlapError, match="10 % of the shorter"):
        compare_series(t2, short, units, t2 + 1.8, late)
    c = compare_series(t2, short, units, t2 + 1.8, late, align_time=True)
    assert c.time_offset_s == pytest.approx(-1.8, abs=0.005)


def test_compare_series_refuses_radians_and_millimetres_but_not_small_motions():
    t = np.arange(0, 10, 0.01)
    knee_deg = 30 + 30 * np.sin(t)
    foot_m = -0.8 + 0.05 * np.sin(t)
    units = {"knee_flexion": "deg", "hip_internal_rotation": "deg", "pelvis_to_foot_y": "m"}
    ours = {"knee_flexion": knee_deg, "hip_internal_rotation": 2 * np.sin(t), "pelvis_to_foot_y": foot_m}
    with pytest.raises(ReferenceUnitError, match=r"'knee_flexion' spans 1\.05 .*radians.*180/π") as e:
        compare_series(t, ours, units, t, {"knee_flexion": np.deg2rad(knee_deg)})
    assert e.value.column == "knee_flexion" and e.value.guessed_unit == "radians"
    with pytest.raises(ReferenceUnitError, match=r"millimetres.*divide by 1000") as e:
        compare_series(t, ours, units, t, {"pelvis_to_foot_y": 1000 * foot_m})
    assert e.value.unit == "m" and e.value.reference_size == pytest.approx(800, rel=0.02)
    with pytest.raises(ReferenceUnitError, match=r"centimetres.*divide by 100"):
        compare_series(t, ours, units, t, {"pelvis_to_foot_y": 100 * foot_m})
    # a joint that barely moves proves nothing; a reference in deg that disagrees is still compared
    ok = compare_series(
        t,
        ours,
        units,
        t,
        {"hip_internal_rotation": np.deg2rad(2 * np.sin(t)), "knee_flexion": 0.3 * knee_deg},
    )
    assert [s.quantity for s in ok.quantities] == ["knee_flexion", "hip_internal_rotation"]
    # a constant (stuck) reference column is compared, not taken for radians
    stuck = compare_series(t, ours, units, t, {"knee_flexion": np.full(t.size, 0.5)})
    assert stuck.quantities[0].rmse > 10


def test_reference_table_is_checked_when_read(tmp_path):
    from lowerlimb.agreement.files import read_reference_table

    path = tmp_path / "ref.csv"
    path.write_bytes(b"\xef\xbb\xbftime,knee_flexion,note\n0,1,ok\n0.01,2,\xe9t\xe9\n")  # BOM + 37 bytes
    with pytest.raises(InputError, match=r"not UTF-8 text \(byte 0xe9 at offset 40, line 3\)"):
        read_reference_table(path)
    path.write_text("time,knee_flexion,time\n0,1,0\n0.01,2,0.01\n")
    with pytest.raises(InputError, match="'time' 2 times"):
        read_reference_table(path)
    path.write_text("time,knee_flexion\n0,1\nnan,2\n0.02,3\n")
    with pytest.raises(TimeAxisError, match="not a number at data row 2"):
        read_reference_table(path)
    path.write_text("time,knee_flexion,,\n0,1,,\n0.01,2,,\n")  # empty header cells are not duplicates
    assert list(read_reference_table(path).columns) == ["knee_flexion"]
