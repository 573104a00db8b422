"""Gait-cycle curves and the parameter table with a symmetry index; their section in report.html."""

from __future__ import annotations

import base64
import io

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image
from scipy.signal import find_peaks

from lowerlimb.conventions import ANGLE_COLUMNS
from lowerlimb.errors import ShapeError
from lowerlimb.viz.gait_curves import (
    CYCLE_POINTS,
    MAX_STRIDE_S,
    gait_report_section,
    normalise_strides,
    parameter_table_html,
    plot_gait_cycles,
    symmetry_index_pct,
)
from lowerlimb.viz.report import write_report

NAMES = ANGLE_COLUMNS[1:]


def test_each_stride_is_resampled_from_contact_to_contact():
    t = np.arange(0.0, 10.0, 0.01)
    period = 1.1
    y = np.column_stack([np.sin(2 * np.pi * t / period), t])
    contacts = np.arange(0.3, 10.0, period)
    strides = normalise_strides(t, y, contacts)
    assert strides.shape == (len(contacts) - 1, CYCLE_POINTS, 2)
    phase = np.linspace(0.0, 1.0, CYCLE_POINTS)
    for k, s in enumerate(strides):
        assert np.allclose(s[:, 0], np.sin(2 * np.pi * (0.3 / period + phase)), atol=2e-3)
        assert s[0, 1] == pytest.approx(contacts[k]) and s[-1, 1] == pytest.approx(contacts[k + 1])


def test_strides_with_gaps_or_outside_the_recording_are_left_out():
    t = np.arange(0.0, 10.0, 0.01)
    y = np.sin(t)[:, None].copy()
    y[(t > 2.2) & (t < 2.3)] = np.nan  # inside the stride 2.0 → 3.0
    contacts = [-0.5, 0.5, 1.0, 2.0, 3.0, 7.5, 9.5, 10.5]  # 3.0 → 7.5 is a stop (> 3 s)
    strides = normalise_strides(t, y, contacts)
    assert strides.shape[0] == 3  # 0.5→1.0, 1.0→2.0, 7.5→9.5
    assert normalise_strides(t, y, [1.0]).shape == (0, CYCLE_POINTS, 1)
    with pytest.raises(ShapeError, match="shape"):
        normalise_strides(t, y[:-1], contacts)


def test_symmetry_index_follows_robinson():
    assert symmetry_index_pct(1.0, 1.2) == pytest.approx(200.0 * 0.2 / 2.2)
    assert symmetry_index_pct(1.2, 1.0) == symmetry_index_pct(1.0, 1.2)
    assert symmetry_index_pct(60.0, 60.0) == 0.0
    assert np.isnan(symmetry_index_pct(0.0, 0.0))
    assert np.isnan(symmetry_index_pct(float("nan"), 1.0))


def test_the_table_has_both_sides_and_the_symmetry_index():
    params = {
        "left": {"stride_time_s": {"mean": 1.10, "sd": 0.02}, "stance_pct": {"mean": 60.0, "sd": 1.0}},
        "right": {"stride_time_s": {"mean": 1.12, "sd": 0.03}, "stance_pct": 64.0, "<odd>": 1.0},
    }
    table = parameter_table_html(params, overall={"cadence_steps_per_min": 108.0, "gait_speed_m_s": None})
    assert "stride time (s)" in table and "stance (%)" in table and "cadence (steps/min)" in table
    assert "1.1 ± 0.02" in table and "1.12 ± 0.03" in table
    assert f"{symmetry_index_pct(60.0, 64.0):.1f}" in table  # 6.5
    assert "&lt;odd&gt;" in table and "<odd>" not in table
    assert "gait speed" not in table


def test_a_count_has_no_symmetry_index():
    table = parameter_table_html({"left": {"n_strides": 24}, "right": {"n_strides": 25}})
    row = table[table.index("n strides") :].split("</tr>")[0]
    assert "<td>24</td><td>25</td><td>—</td>" in row


@pytest.fixture(scope="module")
def two_sides(walk_clean):
    """Both sides from the simulated walk: the right leg half a stride behind (the simulator has one leg)."""
    t, angles = walk_clean.trial.time_s, np.rad2deg(walk_clean.angles_rad)
    rate = walk_clean.trial.rate_hz
    peaks, _ = find_peaks(angles[:, 0], distance=int(0.6 * rate))  # hip flexion maxima ≈ initial contact
    stride = int(np.median(np.diff(peaks)))
    right = np.roll(angles, stride // 2, axis=0) + 2.0
    contacts = {"left": t[peaks], "right": t[peaks] + (stride // 2) / rate}
    return t, {"left": angles, "right": right}, contacts


def test_the_curves_are_a_png(two_sides):
    t, angles, contacts = two_sides
    url = plot_gait_cycles(t, angles, contacts, NAMES, toe_off_pct={"left": 60.0, "right": 61.0})
    assert url.startswith("data:image/png;base64,")
    image = Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1])))
    assert image.size[0] > 800
    # the mean of identical strides (shifted by 2 deg on the right) has near-zero SD
    left = normalise_strides(t, angles["left"], contacts["left"])
    right = normalise_strides(t, angles["right"], contacts["right"])
    assert left.shape[0] >= 10 and right.shape[0] >= 10
    assert np.abs(left.mean(axis=0) + 2.0 - right.mean(axis=0)).max() < 1.0


def test_the_section_embeds_in_the_report(tmp_path, walk_clean, two_sides):
    t, angles, contacts = two_sides
    params = {
        "left": {"stance_pct": {"mean": 60.0, "sd": 1.0}},
        "right": {"stance_pct": {"mean": 62.0, "sd": 1.0}},
    }
    section = gait_report_section(t, angles, contacts, NAMES, params)
    assert "id='gait-cycles-plot'" in section and "id='gait-parameters'" in section
    assert "Robinson" in section
    path = tmp_path / "report.html"
    write_report(
        path,
        model=walk_clean.model,
        time_s=t,
        angles_rad=walk_clean.angles_rad,
        positions_m=walk_clean.positions_m,
        calibration=walk_clean.model.calibration_dict("truth"),
        gait_html=section,
    )
    text = path.read_text(encoding="utf-8")
    assert text.index("id='angles-plot'") < text.index("id='gait-cycles'") < text.index("id='positions-plot'")


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_each_stride_reads_only_its_own_samples_and_matches_the_whole_record(seed):
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.005, 0.015, 800))  # uneven sampling
    y = rng.normal(size=(800, 3))
    contacts = np.sort(rng.uniform(t[0] - 0.5, t[-1] + 0.5, 8))
    strides = normalise_strides(t, y, contacts)
    phase = np.linspace(0.0, 1.0, CYCLE_POINTS)
    expected = [
        np.column_stack([np.interp(t0 + phase * (t1 - t0), t, y[:, j]) for j in range(3)])
        for t0, t1 in zip(contacts[:-1], contacts[1:], strict=True)
        if t0 >= t[0] and t1 <= t[-1] and 0.0 < t1 - t0 <= MAX_STRIDE_S
    ]
    assert strides.shape[0] == len(expected)
    for got, want in zip(strides, expected, strict=True):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)
