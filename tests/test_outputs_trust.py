"""Outputs a colleague can trust (issue 10, deliverable 3).

Provenance, residual units, folder permissions, the demo folder, the view, the URDF.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import json
import os
import re
import signal
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lowerlimb import __version__
from lowerlimb.cli import main
from lowerlimb.io.tables import write_angles_csv

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory, walk_clean):
    """One `lowerlimb calibrate` run on a 20 s walk, then one reusing its calibration."""
    import contextlib
    import io

    d = tmp_path_factory.mktemp("trust")
    trial = d / "walk.csv"
    walk_clean.trial.to_csv(trial)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        assert main(["calibrate", str(trial), "--out", str(d / "out"), "--height", "1.8"]) == 0
    reused_err = io.StringIO()
    with contextlib.redirect_stderr(reused_err):
        argv = ["calibrate", str(trial), "--out", str(d / "again")]
        assert main([*argv, "--calibration", str(d / "out" / "calibration.json")]) == 0
    return {"dir": d, "trial": trial, "stderr": err.getvalue(), "reused_stderr": reused_err.getvalue()}


def test_calibration_json_records_its_provenance(calibrated):
    cal = json.loads((calibrated["dir"] / "out" / "calibration.json").read_text())
    prov = cal["provenance"]
    assert set(prov) == {
        "lowerlimb_version",
        "dependencies",
        "input_file",
        "input_sha256",
        "options",
        "calibration_reused_from",
    }
    assert prov["lowerlimb_version"] == __version__
    assert prov["dependencies"]["numpy"] == np.__version__
    assert {"scipy", "casadi", "pinocchio"} <= set(prov["dependencies"])
    assert prov["input_file"] == str(calibrated["trial"])
    assert prov["input_sha256"] == hashlib.sha256(calibrated["trial"].read_bytes()).hexdigest()
    options = prov["options"]
    assert (options["side"], options["filter"], options["method"]) == ("left", "mahony", "casadi")
    assert (options["height"], options["mass"]) == (1.8, 75.0)
    assert (options["clock_sync"], options["centre_form"]) == (True, "norm")
    assert prov["calibration_reused_from"] is None


def test_a_reused_calibration_says_so(calibrated):
    first = calibrated["dir"] / "out" / "calibration.json"
    cal = json.loads((calibrated["dir"] / "again" / "calibration.json").read_text())
    assert cal["provenance"]["calibration_reused_from"] == str(first)
    err = calibrated["reused_stderr"]
    assert f"joint calibration reused from {first}" in err
    calib_lines = [ln for ln in err.splitlines() if "joint calibration" in ln]
    assert calib_lines and not any("0.00 s" in ln or "0.000 s" in ln for ln in calib_lines), calib_lines
    assert "rms residual" not in err  # the earlier trial's residuals are not this trial's
    # nor its clocks: the search ran on the first trial only
    first_cal = json.loads(first.read_text())
    assert set(first_cal["clock_offsets"]) == {"shift_s", "joints", "passes", "rejected", "late_sensor"}
    assert cal["clock_offsets"] == {}


def test_every_printed_residual_has_its_unit(calibrated):
    lines = [ln for ln in calibrated["stderr"].splitlines() if "residual" in ln]
    assert len(lines) == 3
    for line in lines:
        numbers = re.findall(r"residual(?: [\d.e+-]+)", line) + re.findall(r"axis [\d.e+-]+", line)
        assert numbers
        assert re.search(r"residual [\d.e+-]+ m/s²", line), line
    knee = next(ln for ln in lines if "knee" in ln)
    assert re.search(r"axis [\d.e+-]+ rad/s", knee), knee


def test_output_folder_follows_the_umask(calibrated):
    mask = os.umask(0)
    os.umask(mask)
    out = calibrated["dir"] / "out"
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~mask
    assert stat.S_IMODE((out / "angles.csv").stat().st_mode) == 0o666 & ~mask


def test_urdf_is_pretty_printed_without_round_off(calibrated):
    text = (calibrated["dir"] / "out" / "calibrated.urdf").read_text()
    assert text.count("\n") > 50 and "\n  <link" in text
    numbers = re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", " ".join(re.findall(r'="([^"]*)"', text)))
    assert [v for v in numbers if 0 < abs(float(v)) < 1e-12] == []
    assert [v for v in numbers if v.startswith("-") and float(v) == 0] == []


def test_demo_twice_in_the_same_folder(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["demo", "--duration", "10"]) == 0
    assert main(["demo", "--duration", "10"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lowerlimb_demo", "lowerlimb_demo_2"]
    assert (tmp_path / "lowerlimb_demo_2" / "report.html").is_file()
    cal = json.loads((tmp_path / "lowerlimb_demo" / "calibration.json").read_text())
    assert cal["provenance"]["input_file"].endswith("lowerlimb_demo/trial.csv")


def test_demo_folder_is_ignored_by_git():
    for path in ("lowerlimb_demo/report.html", "lowerlimb_demo_2/report.html"):
        proc = subprocess.run(["git", "check-ignore", "-q", path], cwd=ROOT, check=False)
        assert proc.returncode == 0, path


# ---------------------------------------------------------------- lowerlimb view


def _listening(port: int) -> list[str]:
    """Local addresses (hex, as /proc/net/tcp{,6} gives them) listening on ``port``."""
    found = []
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        if not os.path.exists(name):
            continue
        for line in Path(name).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            address, port_hex = local.rsplit(":", 1)
            if state == "0A" and int(port_hex, 16) == port:
                found.append(address)
    return found


@pytest.fixture
def view_dir(tmp_path, walk_clean):
    walk_clean.model.write_urdf(tmp_path / "calibrated.urdf")
    n = 300
    write_angles_csv(tmp_path / "angles.csv", walk_clean.trial.time_s[:n], walk_clean.angles_rad[:n])
    return tmp_path


@pytest.mark.skipif(not os.path.exists("/proc/net/tcp"), reason="reads the listening sockets from /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_view_binds_localhost_and_stops_cleanly(view_dir, sig):
    env = dict(os.environ, PYTHONUNBUFFERED="1", PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(
        [sys.executable, "-X", "dev", "-m", "lowerlimb.cli", "view", str(view_dir)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert proc.stdout is not None
        lines = []
        for line in proc.stdout:
            lines.append(line)
            if line.startswith("lowerlimb: open that address"):
                break
        url = next(ln for ln in lines if "showing" in ln).rsplit(" at ", 1)[1].strip()
        port = int(url.split(":")[2].split("/")[0])
        addresses = _listening(port)
        proc.send_signal(sig)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert url.startswith("http://127.0.0.1:")
    assert sum(url in ln for ln in lines + out.splitlines()) == 1  # the URL printed once
    # bound to 127.0.0.1 only (0100007F in /proc), not 0.0.0.0 / [::]
    assert addresses and set(addresses) == {"0100007F"}, addresses
    assert proc.returncode == 0, err
    assert "Unclosed" not in err and "ResourceWarning" not in err, err
    assert _listening(port) == []  # no orphaned meshcat server keeps the port


def test_the_installed_version_is_the_one_recorded_in_outputs():
    """One version: the package metadata reads ``lowerlimb.__version__`` (a batch re-runs on a change)."""
    assert importlib.metadata.version("lowerlimb") == __version__
