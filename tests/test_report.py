from __future__ import annotations

import base64
import io
import re
from html.parser import HTMLParser

import numpy as np
import pytest
import umsgpack
from chromium import orange_mask, screenshot
from PIL import Image

from lowerlimb.errors import InputError, ShapeError
from lowerlimb.viz.report import MAX_ANIMATION_FRAMES, write_report


class _Collect(HTMLParser):
    """Collects the tags of a page with their attributes."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, dict[str, str | None]]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))

    def find(self, tag: str) -> list[dict[str, str | None]]:
        return [a for t, a in self.tags if t == tag]


def parse(text: str) -> _Collect:
    p = _Collect()
    p.feed(text)
    return p


def calibration_of(sim, warnings=()):
    cal = sim.model.calibration_dict("casadi")
    cal["runtime_s"] = 1.25
    cal["warnings"] = list(warnings)
    hip = cal["joints"]["hip"]
    hip.update(
        rms_residual=0.4321,
        rms_residual_unit="m/s^2",
        condition_number=123.4,
        center_std_in_parent_sensor=[0.001, 0.002, 0.003],
        warnings=list(warnings),
    )
    knee = cal["joints"]["knee"]
    knee.update(rms_residual_axis=0.0123, axis_std_deg_in_parent_sensor=0.75)
    return cal


def report(tmp_path, sim, name="report.html", **kw):
    path = tmp_path / name
    args = dict(
        model=sim.model,
        time_s=sim.trial.time_s,
        angles_rad=sim.angles_rad,
        positions_m=sim.positions_m,
        calibration=calibration_of(sim),
    )
    args.update(kw)
    write_report(path, **args)
    return path.read_text(encoding="utf-8")


WARNING = "the hip hardly rotates about <z>; its centre's z is poorly determined"
TITLE = "Subject <7> & knee"


@pytest.fixture(scope="module")
def plain(tmp_path_factory, walk_clean):
    """A report without truth or warnings."""
    return report(tmp_path_factory.mktemp("plain"), walk_clean)


@pytest.fixture(scope="module")
def rich(tmp_path_factory, walk_clean):
    """A report with warnings, truth (estimate = truth + 1 deg, − 2 mm) and an odd title."""
    d = tmp_path_factory.mktemp("rich")
    text = report(
        d,
        walk_clean,
        calibration=calibration_of(walk_clean, warnings=[WARNING]),
        angles_rad=walk_clean.angles_rad + np.deg2rad(1.0),
        positions_m=walk_clean.positions_m - 0.002,
        truth_angles_rad=walk_clean.angles_rad,
        truth_positions_m=walk_clean.positions_m,
        title=TITLE,
    )
    return d / "report.html", text


def iframe_page(text: str) -> str:
    (frame,) = parse(text).find("iframe")
    srcdoc = frame["srcdoc"]
    assert srcdoc is not None
    return srcdoc


def meshcat_commands(page: str) -> list[dict]:
    blobs = re.findall(r'"([A-Za-z0-9+/=]{8,})"', page.split("var commands = [", 1)[1])
    return [umsgpack.unpackb(base64.b64decode(b)) for b in blobs]


def test_report_is_one_offline_file(plain):
    text = plain
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", text)
    assert "<link" not in text and "@import" not in text
    page = iframe_page(text)
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")
    assert "MeshCat.Viewer" in page and "fetch(" not in page.split("var commands", 1)[1]
    images = parse(text).find("img")
    assert {i["id"] for i in images} == {"angles-plot", "positions-plot"}
    for img in images:
        src = img["src"] or ""
        assert src.startswith("data:image/png;base64,")
        with Image.open(io.BytesIO(base64.b64decode(src.split(",", 1)[1]))) as png:
            assert png.width >= 800 and png.height >= 300


def test_scene_animates_the_four_segments_over_the_trial(plain, walk_clean):
    page = iframe_page(plain)
    commands = meshcat_commands(page)
    drawn = {c["path"] for c in commands if c["type"] == "set_object"}
    for node in ("thigh/thigh_visual", "thigh/imu_thigh/imu_thigh_visual", "thigh/knee_axis"):
        assert f"/meshcat/leg/{node}" in drawn
    (anim,) = [c for c in commands if c["type"] == "set_animation"]
    paths = sorted(a["path"] for a in anim["animations"])
    assert paths == sorted(f"/meshcat/leg/{s}" for s in ("pelvis", "thigh", "shank", "foot"))
    duration = walk_clean.trial.time_s[-1] - walk_clean.trial.time_s[0]
    clip = anim["animations"][0]["clip"]
    n_keys = len(clip["tracks"][0]["keys"])
    assert n_keys == int(np.floor(duration * 25.0)) + 1
    assert clip["fps"] == pytest.approx((n_keys - 1) / duration)


def test_calibration_table_in_mm_with_residuals_and_axis(plain, walk_clean):
    text = plain
    cal = calibration_of(walk_clean)
    for joint in ("hip", "knee", "ankle"):
        for key in ("center_in_parent_sensor", "center_in_child_sensor"):
            mm = ", ".join(f"{1000 * x:.1f}" for x in cal["joints"][joint][key])
            assert f"({mm})" in text
    for key in ("axis_in_parent_sensor", "axis_in_child_sensor"):
        axis = ", ".join(f"{x:.3f}" for x in cal["joints"]["knee"][key])
        assert f"({axis})" in text
    assert "± (1.0, 2.0, 3.0)" in text  # hip centre standard deviation, mm
    assert "0.432 m/s^2" in text and "123" in text and "0.0123" in text
    assert "No excitation warnings" in text


def test_warnings_are_listed_once_and_escaped(rich):
    _, text = rich
    assert text.count("the hip hardly rotates about &lt;z&gt;") == 1
    assert "<z>" not in text.split("<iframe", 1)[0]


def test_truth_is_overlaid_and_compared(rich, plain):
    _, text = rich
    assert "RMS error against the truth (deg)" in text
    assert text.count("<td>1.00</td>") == 9
    assert "RMS error against the truth (mm)" in text
    assert text.count("<td>2.0</td>") == 6
    assert "RMS error against the truth" not in plain


def test_title_is_escaped(rich):
    _, text = rich
    assert "<h1>Subject &lt;7&gt; &amp; knee</h1>" in text
    assert "<title>Subject &lt;7&gt; &amp; knee</title>" in text


def test_long_trial_stays_small(tmp_path, walk_noisy):
    text = report(tmp_path, walk_noisy)
    size_mb = len(text.encode("utf-8")) / 1e6
    assert size_mb < 3.0, f"report of a 60 s walk is {size_mb:.1f} MB"
    assert f"{MAX_ANIMATION_FRAMES} frames" in text


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        ({"angles_rad": np.zeros((10, 9))}, ShapeError, "angles_rad must have shape"),
        ({"positions_m": np.zeros((5, 3))}, ShapeError, "positions_m must have shape"),
        ({"time_s": np.zeros((2, 2))}, ShapeError, "time_s must have shape"),
        ({"truth_angles_rad": np.zeros((3, 9))}, ShapeError, "truth_angles_rad must have shape"),
        ({"calibration": {"format": "x"}}, InputError, "pass the calibration.json document"),
    ],
)
def test_bad_arguments(tmp_path, walk_clean, change, error, message):
    with pytest.raises(error, match=message):
        report(tmp_path, walk_clean, **change)
    assert not (tmp_path / "report.html").exists()


@pytest.mark.browser
def test_report_renders_in_headless_chromium(rich, tmp_path):
    path, _ = rich
    rgb = screenshot(path.as_uri(), tmp_path / "report.png", width=1280, height=3200, budget_ms=2500)
    # 3-D scene: the orange IMU boxes are drawn (WebGL works, the leg is in view) ...
    orange = orange_mask(rgb)
    rows, cols = np.nonzero(orange)
    assert orange.sum() > 40, "no IMU box in the 3-D view: blank or failed WebGL canvas"
    assert rows.max() - rows.min() > 150, "the IMUs should span the leg, pelvis to foot"
    # ... on a canvas that is not blank around them
    top, bottom = max(rows.min() - 100, 0), rows.max() + 100
    left, right = max(cols.min() - 200, 0), cols.max() + 200
    grey = rgb[top:bottom, left:right].astype(float).mean(axis=-1)
    assert grey.std() > 8.0
    # plots below the scene: the estimate's blue (#1f77b4) over many rows of both images
    blue = np.all(np.abs(rgb.astype(int) - np.array([31, 119, 180])) <= 40, axis=-1)
    plot_rows = np.count_nonzero(blue[bottom:].sum(axis=1) >= 3)
    assert plot_rows > 700, f"only {plot_rows} rows with plotted curves"


def test_report_says_what_the_clock_search_found(tmp_path, walk_clean):
    cal = calibration_of(walk_clean)
    assert "clock-note" not in report(tmp_path, walk_clean, name="none.html", calibration=cal)
    cal["clock_offsets"] = {"shift_s": {"pelvis": 0.0, "thigh": 0.0, "shank": 0.0, "foot": 0.0}}
    assert "no offset found" in report(tmp_path, walk_clean, name="sync.html", calibration=cal)
    cal["clock_offsets"] = {"shift_s": {"pelvis": 0.0, "thigh": 0.0204, "shank": 0.0, "foot": -0.0071}}
    text = report(tmp_path, walk_clean, name="moved.html", calibration=cal)
    assert "re-timed" in text and "thigh +20.4 ms" in text and "foot -7.1 ms" in text
