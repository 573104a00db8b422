"""``lowerlimb batch`` on hostile input: one line naming the problem and the fix, exit 2, nothing written."""

from __future__ import annotations

from pathlib import Path

import pytest
import simcache

from lowerlimb.batch.dask_cluster import check_scheduler_address
from lowerlimb.cli import main
from lowerlimb.errors import InputError


def _one_trial(root: Path) -> Path:
    """A manifest of one simulated single-leg trial ``data/walk.csv``; returns the manifest."""
    (root / "data").mkdir(parents=True, exist_ok=True)
    simcache.cached_simulation("walk", 12.0, seed=0).trial.to_csv(root / "data" / "walk.csv")
    manifest = root / "m.csv"
    manifest.write_text("trial,side\ndata/walk.csv,left\n")
    return manifest


@pytest.mark.parametrize(
    "address", ["notanaddress", "tcp://localhost", "tcp://127.0.0.1:abc", "", "http://h:1"]
)
def test_a_malformed_scheduler_address_is_refused_before_anything_is_written(tmp_path, capsys, address):
    """It was an internal error (ValueError: missing port number…), exit 1, with empty study tables."""
    manifest = _one_trial(tmp_path)
    out = tmp_path / "o"
    assert main(["batch", str(manifest), "--out", str(out), "--scheduler", address, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err == f"lowerlimb: error: --scheduler needs an address tcp://HOST:PORT, got {address!r}\n"
    assert not out.exists()


@pytest.mark.parametrize(
    "address", ["tcp://127.0.0.1:8786", "localhost:8786", "tcp://[::1]:8786", "inproc://10.0.0.1/42/1"]
)
def test_well_formed_scheduler_addresses_pass_the_check(address):
    check_scheduler_address(address)
    with pytest.raises(InputError, match="tcp://HOST:PORT"):
        check_scheduler_address(address.replace("8786", "0") if "8786" in address else "inproc://")


def test_dask_workers_get_absolute_paths(tmp_path, monkeypatch):
    """A Dask worker runs in its own cwd: relative trial paths were "not found", a relative --out
    wrote the trials under the worker's cwd while batch.csv said ok."""
    distributed = pytest.importorskip("distributed")
    import batch_workers

    from lowerlimb.batch import run_study

    _one_trial(tmp_path)
    (tmp_path / "m.csv").write_text("trial,side,calibration\ndata/walk.csv,left,old/calibration.json\n")
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "calibration.json").write_text("{}")
    monkeypatch.chdir(tmp_path)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False) as cluster:
        result = run_study(
            "m.csv", "o", scheduler=cluster.scheduler_address, worker=batch_workers.reports_paths
        )
    (outcome,) = result.outcomes
    expected = [tmp_path / "data" / "walk.csv", tmp_path / "old" / "calibration.json", tmp_path / "o"]
    assert outcome.reason.split("|") == [str(p) for p in expected]


def test_earlier_result_folders_in_a_study_folder_hold_no_trial(tmp_path, capsys):
    """``batch data --out data/res_v2`` took res_v1's angles.csv… (and a calibrate folder's) as trials."""
    from lowerlimb.batch import read_study
    from lowerlimb.batch.manifest import RESULT_MARKERS
    from lowerlimb.batch.record import MARKER

    assert MARKER in RESULT_MARKERS
    data = tmp_path / "data"
    _one_trial(tmp_path)
    argv = ["--workers", "1", "--quiet", "--outputs", "calibration,angles,positions"]
    assert main(["batch", str(data), "--out", str(data / "res_v1"), *argv]) == 0
    cal = data / "s1" / "cal"  # a calibrate result beside a subject's trials
    cal.mkdir(parents=True)
    (cal / "calibration.json").write_text("{}")
    (cal / "angles.csv").write_text("time\n0\n")
    capsys.readouterr()
    assert [t.label for t in read_study(data)] == ["walk.csv"]
    assert main(["batch", str(data), "--out", str(data / "res_v2"), *argv]) == 0
    assert "1 of 1 trials done" in capsys.readouterr().err
    # a folder of results alone is named as such
    assert main(["batch", str(data / "res_v1"), "--out", str(tmp_path / "o"), *argv]) == 2
    err = capsys.readouterr().err
    assert "no trial found outside result folders (walk); give the folder of the trial CSVs" in err
    assert not (tmp_path / "o").exists()


def test_a_rerun_redoes_a_trial_whose_outputs_were_damaged(tmp_path):
    """A re-run checked only that the files were there: garbage in calibration.json and a truncated
    calibrated.urdf were kept as done."""
    import json

    from lowerlimb.batch import BatchParams, run_study
    from lowerlimb.batch.record import MARKER

    manifest = _one_trial(tmp_path)
    out = tmp_path / "o"
    params = BatchParams(workers=1, outputs=frozenset({"calibration", "angles", "urdf"}))
    assert run_study(manifest, out, params).processed == 1
    folder = out / "data__walk"
    record = json.loads((folder / MARKER).read_text())
    assert set(record["files"]) == {"calibration.json", "angles.csv", "angles.units.json", "calibrated.urdf"}
    size, digest = record["files"]["calibration.json"]
    assert size == (folder / "calibration.json").stat().st_size and len(digest) == 64
    assert run_study(manifest, out, params).processed == 0

    (folder / "calibration.json").write_text("garbage")
    assert run_study(manifest, out, params).processed == 1
    json.loads((folder / "calibration.json").read_text())
    urdf = folder / "calibrated.urdf"
    urdf.write_bytes(urdf.read_bytes()[:100])
    assert run_study(manifest, out, params).processed == 1
    assert urdf.read_text().rstrip().endswith("</robot>")
    # same size, other bytes
    angles = folder / "angles.csv"
    text = angles.read_text()
    angles.write_text(text[:-2] + ("0" if text[-2] != "0" else "1") + text[-1])
    assert run_study(manifest, out, params).processed == 1
    assert run_study(manifest, out, params).processed == 0
    # a record without the files' hashes (written before they were kept) cannot vouch for them
    record = json.loads((folder / MARKER).read_text())
    del record["files"]
    (folder / MARKER).write_text(json.dumps(record))
    assert run_study(manifest, out, params).processed == 1


def _header_only(path: Path, sensors: tuple[str, ...]) -> None:
    """A trial CSV of one row whose header names ``sensors`` (enough for the manifest's checks)."""
    names = [f"{s}_{q}_{a}" for s in sensors for q in ("acc", "gyr") for a in "xyz"]
    path.write_text("time," + ",".join(names) + "\n0.0," + ",".join("0" for _ in names) + "\n")


def test_side_both_is_for_two_leg_trials_and_left_right_for_one_leg(tmp_path, capsys):
    """batch.csv writes side 'both' for a two-leg trial but the manifest refused it; a 'left' given
    for a two-leg trial was silently ignored."""
    from lowerlimb.batch import ManifestError, read_study
    from lowerlimb.conventions import SENSORS
    from lowerlimb.io.recording import TWO_LEG_SENSORS

    _header_only(tmp_path / "two.csv", TWO_LEG_SENSORS)
    _header_only(tmp_path / "one.csv", SENSORS)
    manifest = tmp_path / "m.csv"
    manifest.write_text("trial,side\ntwo.csv,both\none.csv,right\n")
    assert [t.side for t in read_study(manifest)] == ["both", "right"]
    manifest.write_text("trial,side\ntwo.csv,\none.csv,\n")
    assert [t.side for t in read_study(manifest)] == ["both", "left"]
    for rows, message in [
        (
            "trial,side\none.csv,left\ntwo.csv,left\n",
            "m.csv, row 2: side 'left', but two.csv is a two-leg trial (pelvis, left_*, right_* sensors) "
            "and both legs are calibrated; write both or leave the side empty",
        ),
        (
            "trial,side\none.csv,both\n",
            "m.csv, row 1: side 'both', but one.csv has one leg's sensors; write left or right "
            "(or leave it empty)",
        ),
    ]:
        manifest.write_text(rows)
        with pytest.raises(ManifestError):
            read_study(manifest)
        assert main(["batch", str(manifest), "--out", str(tmp_path / "o"), "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.endswith(f"{message}\n") and err.count("\n") == 1
        assert not (tmp_path / "o").exists()


def test_batch_failures_say_to_set_the_manifest_side_not_a_side_option(tmp_path):
    """batch has no --side, but its reasons said "rerun with --side right" / "pass --side left or
    another calibration"."""
    from lowerlimb.batch import BatchParams, run_study

    manifest = _one_trial(tmp_path)  # a simulated left leg
    params = BatchParams(workers=1, outputs=frozenset({"calibration"}))
    assert not run_study(manifest, tmp_path / "o", params).failed
    manifest.write_text("trial,side\ndata/walk.csv,right\n")
    (wrong,) = run_study(manifest, tmp_path / "o2", params).outcomes
    assert wrong.status == "failed" and "--side" not in wrong.reason
    assert "this looks like a left leg, not right" in wrong.reason
    assert "set the trial's side column to left in a manifest" in wrong.reason
    assert "run 'lowerlimb calibrate data/walk.csv --no-side-check' on it alone" in wrong.reason
    cal = tmp_path / "o" / "data__walk" / "calibration.json"
    manifest.write_text(f"trial,side,calibration\ndata/walk.csv,right,{cal}\n")
    (reuse,) = run_study(manifest, tmp_path / "o3", params).outcomes
    assert reuse.reason == (
        f"{cal} is of the left leg but the trial is the right leg; set the trial's side column to left "
        "in the manifest, or give another calibration"
    )


def test_a_manifest_side_against_the_prefixed_columns_is_refused(tmp_path, capsys):
    """It failed in the worker saying "drop --side (or pass --side left)"."""
    _header_only(tmp_path / "t.csv", ("pelvis", "left_thigh", "left_shank", "left_foot"))
    manifest = tmp_path / "m.csv"
    manifest.write_text("trial,side\nt.csv,right\n")
    assert main(["batch", str(manifest), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert capsys.readouterr().err.endswith(
        "m.csv, row 1: side 'right', but t.csv names the left leg's sensors (left_thigh, left_shank, "
        "left_foot); write left or leave the side empty\n"
    )
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("trial;side\ndata/walk.csv;left\n", "the manifest is separated by ';'; save it comma-separated"),
        ("trial\tside\ndata/walk.csv\tleft\n", "the manifest is separated by tabs; save it comma-separated"),
        (
            "trial,side\ndata/walk.csv,left\ndata/missing.csv,left\ndata/gone.csv,left\n",
            "row 2: trial file data/missing.csv not found (looked for {base}/data/missing.csv) (and 1 more "
            "missing); fix the manifest's paths, relative to its folder",
        ),
        (
            "trial,calibration\ndata/walk.csv,cal/calibration.json\n",
            "row 1: calibration cal/calibration.json not found (looked for {base}/cal/calibration.json); "
            "fix the manifest's paths, relative to its folder",
        ),
        (
            "trial\ndata\n",
            "row 1: trial file data is a folder (looked for {base}/data); fix the manifest's paths",
        ),
        (
            "trial\ndata/walk.csv\ndata__walk.csv\n",
            "row 2: 'data/walk.csv' and 'data__walk.csv' map to the same output folder 'data__walk'; "
            "rename one of the two files",
        ),
    ],
)
def test_a_bad_manifest_is_refused_before_any_work(tmp_path, capsys, text, message):
    """Another separator said "no 'trial' column (columns: trial;side)"; a missing file failed its
    trial (exit 1) while saying "fix the manifest's path"; two names of one folder said "list each
    trial once"."""
    manifest = _one_trial(tmp_path)
    (tmp_path / "data__walk.csv").write_bytes((tmp_path / "data" / "walk.csv").read_bytes())
    manifest.write_text(text)
    out = tmp_path / "o"
    assert main(["batch", str(manifest), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"lowerlimb: error: {manifest}") and err.count("\n") == 1
    assert message.format(base=tmp_path) in err
    assert not out.exists()


def test_batch_passes_the_check_flags_its_failure_reasons_name(tmp_path, capsys):
    """A trial refused as swapped says "pass --no-order-check": batch takes that flag too."""
    import numpy as np

    from lowerlimb.io.trial import ImuTrial

    t = simcache.cached_simulation("walk", 20.0, seed=0).trial
    acc, gyr = dict(t.acc), dict(t.gyr)
    for d in (acc, gyr):
        d["thigh"], d["shank"] = d["shank"], d["thigh"]
    (tmp_path / "data").mkdir()
    ImuTrial(t.time_s, acc, gyr, None, side="left").to_csv(tmp_path / "data" / "swapped.csv")
    manifest = tmp_path / "m.csv"
    manifest.write_text("trial,side\ndata/swapped.csv,left\n")
    assert main(["batch", str(manifest), "--out", str(tmp_path / "o1"), "--quiet", "--workers", "1"]) == 1
    assert "--no-order-check" in capsys.readouterr().err
    args = ["batch", str(manifest), "--out", str(tmp_path / "o2"), "--quiet", "--workers", "1"]
    assert main([*args, "--no-order-check", "--no-report"]) == 0
    assert np.isfinite(
        np.loadtxt(tmp_path / "o2" / "data__swapped" / "angles.csv", delimiter=",", skiprows=1)
    ).all()
