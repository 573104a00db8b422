"""``lowerlimb batch`` / ``process_study``: the study contract of docs/formats.md, "Many trials"."""

from __future__ import annotations

import csv
import json
import os
import sys
from pathlib import Path

import pytest
import simcache

from lowerlimb.batch import BatchParams, ManifestError, read_study, record, run_study
from lowerlimb.batch.manifest import StudyTrial
from lowerlimb.batch.record import FAILED_DIR, MARKER, input_hash
from lowerlimb.cli import main
from lowerlimb.cli._common import OUTPUT_NAMES
from lowerlimb.io.result_files import OUTPUT_FILES

sys.path.insert(0, str(Path(__file__).parent))  # the worker processes import batch_workers

FAST = BatchParams(outputs=frozenset({"calibration", "angles", "positions", "s2j", "urdf"}), workers=2)


def _study(root: Path, n_good: int, *, corrupt: bool = True, duration_s: float = 12.0) -> Path:
    """``n_good`` simulated trials in two subject folders, plus one corrupt file; returns the manifest."""
    rows = ["trial,subject,task,side,height_m"]
    for k in range(n_good):
        sim = simcache.cached_simulation("walk", duration_s, seed=k % 3)
        subject = f"s{k % 2 + 1}"
        (root / subject).mkdir(parents=True, exist_ok=True)
        sim.trial.to_csv(root / subject / f"walk_{k}.csv")
        rows.append(f"{subject}/walk_{k}.csv,{subject},walk,left,1.8")
    if corrupt:
        (root / "s2").mkdir(parents=True, exist_ok=True)
        (root / "s2" / "corrupt.csv").write_text("time,pelvis_acc_x\n0.0,abc\n0.01,\n")
        rows.append("s2/corrupt.csv,s2,walk,left,")
    manifest = root / "manifest.csv"
    manifest.write_text("\n".join(rows) + "\n")
    return manifest


def _read_batch_csv(out: Path) -> list[dict[str, str]]:
    with open(out / "batch.csv", newline="") as f:
        return list(csv.DictReader(f))


def _snapshot(out: Path) -> dict[str, float]:
    """Modification times of every trial's files and records (the study tables are rewritten)."""
    return {str(p): p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file() and p.parent != out}


def test_one_corrupt_file_among_ten_finishes_and_a_rerun_does_no_work(tmp_path):
    manifest = _study(tmp_path / "in", 9)
    out = tmp_path / "out"
    result = run_study(manifest, out, BatchParams(workers=2))
    rows = _read_batch_csv(out)
    assert len(rows) == 10 and result.processed == 10
    bad = [r for r in rows if r["status"] == "failed"]
    assert [r["trial"] for r in bad] == ["s2/corrupt.csv"]
    assert "pelvis" in bad[0]["reason"] or "column" in bad[0]["reason"]
    good = [r for r in rows if r["status"] != "failed"]
    assert len(good) == 9
    for r in good:
        folder = out / r["folder"]
        units = {"angles.units.json", "positions.units.json"}
        assert {p.name for p in folder.iterdir()} == set(OUTPUT_FILES.values()) | units | {MARKER}
        assert 400 < float(r["thigh_length_mm"]) < 450 and float(r["knee_flexion_range_deg"]) > 30
        assert 0.0 <= float(r["split_half_max_mm"]) < 30.0  # steady simulated walks: no warning
    assert (out / FAILED_DIR / "s2__corrupt.json").is_file()
    subjects = list(csv.DictReader(open(out / "study_subjects.csv")))
    assert [s["subject"] for s in subjects] == ["s1", "s2"]
    assert sum(int(s["trials"]) for s in subjects) == 9

    before = _snapshot(out)
    again = run_study(manifest, out, BatchParams(workers=2))
    assert again.processed == 0
    assert all(o.skipped for o in again.outcomes)
    assert _snapshot(out) == before
    assert [r["status"] for r in _read_batch_csv(out)] == [r["status"] for r in rows]


def test_cli_exit_status_force_and_changed_input(tmp_path, capsys):
    manifest = _study(tmp_path / "in", 2, corrupt=False)
    out = tmp_path / "out"
    argv = ["batch", str(manifest), "--out", str(out), "--workers", "1", "--quiet", "--no-report"]
    assert main(argv) == 0
    assert "2 of 2 trials done (2 processed now" in capsys.readouterr().err
    assert not (out / "s1__walk_0" / "report.html").exists()
    assert main(argv) == 0
    assert "0 processed now, 2 up to date" in capsys.readouterr().err
    # a changed trial is processed again, the other one is not
    trial = tmp_path / "in" / "s1" / "walk_0.csv"
    trial.write_text(trial.read_text().replace("\n", "\r\n"))
    assert main(argv) == 0
    assert "1 processed now, 1 up to date" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0
    assert "2 processed now" in capsys.readouterr().err
    # a missing trial file is a bad manifest (exit 2): nothing is processed
    with open(manifest, "a") as f:
        f.write("s1/missing.csv,s1,walk,left,\n")
    before = _snapshot(out)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "row 3: trial file s1/missing.csv not found" in err and err.count("\n") == 1
    assert _snapshot(out) == before


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("path,side\na.csv,left\n", "no 'trial' column"),
        ("trial,side\na.csv,up\n", "row 1: side 'up'"),
        ("trial,height_m\na.csv,tall\n", "height_m 'tall'"),
        ("trial\na.csv\na.csv\n", "the same trial twice"),
        ("trial\n", "no trial found"),
        ("trial,height_m\na.csv,175\n", "height_m 175 is outside 0.5–2.6 m; give it in m"),
        ("trial,mass_kg\na.csv,75000\n", "mass_kg 75000 is outside 10–400 kg"),
        ("trial,subject\na.csv,M\xfcller\n", "is not UTF-8 text; save the manifest as UTF-8"),
    ],
)
def test_bad_manifest_is_exit_2(tmp_path, capsys, text, message):
    """A height in cm and a latin-1 manifest were an internal error of the trial, or of the run."""
    manifest = tmp_path / "m.csv"
    manifest.write_bytes(text.encode("latin-1"))
    with pytest.raises(ManifestError, match=message.replace("(", r"\(")):
        read_study(manifest)
    assert main(["batch", str(manifest), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_folder_of_trials_and_leftovers_of_a_killed_run(tmp_path):
    _study(tmp_path / "in", 2, corrupt=False)
    (tmp_path / "in" / "manifest.csv").unlink()
    trials = read_study(tmp_path / "in")
    assert [(t.name, t.subject) for t in trials] == [("s1__walk_0", "s1"), ("s2__walk_1", "s2")]
    out = tmp_path / "out"
    # a killed run leaves a staging folder and, at worst, a folder without its record
    (out / ".s1__walk_0.abc123").mkdir(parents=True)
    (out / "s2__walk_1").mkdir()
    (out / "s2__walk_1" / "angles.csv").write_text("partial")
    result = run_study(tmp_path / "in", out, FAST)
    assert result.processed == 2 and not result.failed
    # an output folder inside the trials' folder holds no trial
    inside = run_study(tmp_path / "in", tmp_path / "in" / "results", FAST)
    assert inside.processed == 2
    assert run_study(tmp_path / "in", tmp_path / "in" / "results", FAST).processed == 0
    assert json.loads((out / "s2__walk_1" / MARKER).read_text())["status"] in ("ok", "warning")
    assert (out / "s2__walk_1" / "angles.csv").read_text().startswith("time,")


def test_a_worker_that_dies_is_retried_once_then_failed(tmp_path):
    import batch_workers

    manifest = _study(tmp_path / "in", 2, corrupt=False)
    killer = tmp_path / "in" / "killer.csv"
    killer.write_bytes((tmp_path / "in" / "s1" / "walk_0.csv").read_bytes())
    with open(manifest, "a") as f:
        f.write("killer.csv,s3,walk,left,\n")
    result = run_study(manifest, tmp_path / "out", FAST, worker=batch_workers.dies_on_killer)
    by_name = {o.name: o for o in result.outcomes}
    assert by_name["killer"].status == "failed" and by_name["killer"].failure == "died"
    assert by_name["killer"].attempts == 2 and "died" in by_name["killer"].reason
    assert by_name["s1__walk_0"].status != "failed" and by_name["s2__walk_1"].status != "failed"
    # a death is not a property of the input: the next run tries it again
    again = run_study(manifest, tmp_path / "out", FAST, worker=batch_workers.dies_on_killer)
    assert again.processed == 1


def test_process_study_on_a_dask_local_cluster(tmp_path):
    pd = pytest.importorskip("pandas")
    distributed = pytest.importorskip("distributed")
    from lowerlimb import process_study

    manifest = _study(tmp_path / "in", 2)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False) as cluster:
        table = process_study(
            manifest, tmp_path / "out", scheduler=cluster.scheduler_address, outputs={"calibration", "angles"}
        )
    assert isinstance(table, pd.DataFrame)
    assert list(table["status"])[:2] != ["failed", "failed"]
    assert table.loc[table["trial"] == "s2/corrupt.csv", "status"].item() == "failed"
    assert {"trial", "status", "reason", "wall_s", "thigh_length_mm"} <= set(table.columns)
    assert (tmp_path / "out" / "s1__walk_0" / "angles.csv").is_file()
    assert not (tmp_path / "out" / "s1__walk_0" / "report.html").exists()


def test_process_study_refuses_unknown_options(tmp_path):
    pytest.importorskip("pandas")
    from lowerlimb import InputError, process_study

    with pytest.raises(InputError, match="unknown option wokers"):
        process_study(tmp_path, tmp_path / "out", wokers=2)


def test_output_names_of_the_cli_are_the_registry():
    assert OUTPUT_NAMES == tuple(OUTPUT_FILES)


def test_calibrate_writes_only_the_chosen_outputs(tmp_path):
    sim = simcache.cached_simulation("walk", 12.0, seed=0)
    sim.trial.to_csv(tmp_path / "t.csv")
    rc = main(
        [
            "calibrate",
            str(tmp_path / "t.csv"),
            "--out",
            str(tmp_path / "o"),
            "--outputs",
            "angles,urdf,report",
            "--no-report",
        ]
    )
    assert rc == 0
    assert sorted(os.listdir(tmp_path / "o")) == ["angles.csv", "angles.units.json", "calibrated.urdf"]
    assert (
        main(["calibrate", str(tmp_path / "t.csv"), "--out", str(tmp_path / "p"), "--outputs", "angels"]) == 2
    )


def test_a_study_mixing_one_leg_and_two_leg_trials(tmp_path):
    from lowerlimb.simulation import simulate_bilateral

    root = tmp_path / "in"
    root.mkdir()
    simcache.cached_simulation("walk", 12.0, seed=0).trial.to_csv(root / "leg.csv")
    simulate_bilateral(20.0, seed=1).trial.to_csv(root / "both.csv")
    rows = "trial,subject,side,calibration\nleg.csv,s1,left,\nboth.csv,s1,both,\n"
    (root / "manifest.csv").write_text(rows)
    out = tmp_path / "out"
    params = BatchParams(workers=1, outputs=frozenset(OUTPUT_FILES) - {"report"})
    result = run_study(root / "manifest.csv", out, params)
    assert result.processed == 2
    by_trial = {r["trial"]: r for r in _read_batch_csv(out)}
    two = by_trial["both.csv"]
    assert two["status"] in ("ok", "warning") and two["side"] == "both"
    assert 380 < float(two["left_thigh_length_mm"]) < 470 and 380 < float(two["right_thigh_length_mm"]) < 470
    assert float(two["left_split_half_max_mm"]) >= 0.0 and float(two["right_split_half_max_mm"]) >= 0.0
    assert float(two["cadence_steps_per_min"]) > 60 and float(two["stride_length_m"]) > 0.5
    assert 0.0 < float(two["step_width_m"]) < 0.4
    folder = {p.name for p in (out / two["folder"]).iterdir()}
    assert {"events.csv", "stationary.csv", "gait.json", "calibrated.urdf", "angles.units.json"} <= folder
    assert "s2j.json" not in folder and "report.html" not in folder
    assert by_trial["leg.csv"]["side"] == "left" and "s2j.json" in {p.name for p in (out / "leg").iterdir()}
    # each calibration.json carries its provenance, as calibrate writes it (it had none in a study)
    for name, side in (("leg", "left"), (two["folder"], "both")):
        prov = json.loads((out / name / "calibration.json").read_text())["provenance"]
        assert prov["options"]["side"] == side and len(prov["input_sha256"]) == 64
        assert prov["input_file"].endswith(f"{'leg' if side == 'left' else 'both'}.csv")
    # up to date on a re-run, although a two-leg folder has no s2j.json
    assert run_study(root / "manifest.csv", out, params).processed == 0
    # calibration reuse does not apply to two legs: that trial fails with one clear reason
    (root / "manifest.csv").write_text(
        rows.replace("both.csv,s1,both,", f"both.csv,s1,both,{out}/leg/calibration.json")
    )
    run_study(root / "manifest.csv", out, params)
    two = {r["trial"]: r for r in _read_batch_csv(out)}["both.csv"]
    assert two["status"] == "failed" and "single-leg option" in two["reason"]


def test_centre_form_reaches_every_trial_and_only_then_the_input_hash(tmp_path):
    assert "centre_form" not in BatchParams().processing_key()  # earlier studies stay up to date
    assert BatchParams(centre_form="aligned").processing_key()["centre_form"] == "aligned"
    # the hip in the pelvis: its new default changed results, so it is always in the hash
    assert BatchParams().processing_key()["hip_in_pelvis_form"] == "aligned"
    assert BatchParams(hip_in_pelvis_form="norm").processing_key() != BatchParams().processing_key()
    # so did the two-pass orientation's
    assert BatchParams().processing_key()["smooth_orientation"] is True
    assert BatchParams(smooth_orientation=False).processing_key() != BatchParams().processing_key()
    manifest = _study(tmp_path / "in", 1, corrupt=False)
    out = tmp_path / "out"
    argv = [
        "batch",
        str(manifest),
        "--out",
        str(out),
        "--workers",
        "1",
        "--quiet",
        "--outputs",
        "calibration",
    ]
    assert main([*argv, "--centre-form", "aligned"]) == 0
    (cal,) = out.rglob("calibration.json")
    assert json.loads(cal.read_text())["joints"]["hip"]["solver"].endswith("+aligned")
    # --causal is another processing: the trial is computed again, not skipped as up to date
    before = _snapshot(out)
    assert main([*argv, "--centre-form", "aligned", "--causal"]) == 0
    assert _snapshot(out)[str(cal)] != before[str(cal)]
    (row,) = _read_batch_csv(out)
    assert row["status"] in ("ok", "warning"), row


def test_a_new_version_redoes_the_study(tmp_path, monkeypatch):
    """The version is in the input hash: results of an earlier release are computed again."""
    trial_file = tmp_path / "t.csv"
    trial_file.write_text("time\n0\n")
    trial = StudyTrial(name="t", path=trial_file, label="t.csv", side="left")
    before = input_hash(trial, BatchParams())
    assert input_hash(trial, BatchParams()) == before
    monkeypatch.setattr(record, "__version__", "99.0.0")
    assert input_hash(trial, BatchParams()) != before


def test_an_out_folder_holding_the_study_is_named(tmp_path, capsys):
    """It said "no trial found": the trials lie under --out, which is never searched."""
    manifest = _study(tmp_path / "in", 1, corrupt=False)
    manifest.unlink()
    study = manifest.parent
    assert main(["batch", str(study), "--out", str(study), "--quiet"]) == 2
    assert "no trial found outside --out" in capsys.readouterr().err


def test_an_unusable_scheduler_leaves_nothing(tmp_path, monkeypatch):
    """An empty batch.csv and study tables were left in --out."""
    import lowerlimb.batch.dask_cluster as dask_cluster
    from lowerlimb.errors import InputError

    def unreachable(*args, **kwargs):
        raise InputError("cannot reach the Dask scheduler tcp://127.0.0.1:1")

    monkeypatch.setattr(dask_cluster, "run_dask", unreachable)
    manifest = _study(tmp_path / "in", 1, corrupt=False)
    with pytest.raises(InputError, match="cannot reach"):
        run_study(manifest, tmp_path / "o", scheduler="tcp://127.0.0.1:1", quiet=True)
    assert not (tmp_path / "o").exists()


def test_trial_folders_follow_the_umask(tmp_path):
    """They were mkdtemp's 0700: other users of a shared study folder could not read them."""
    manifest = _study(tmp_path / "in", 1, corrupt=False)
    old = os.umask(0o022)
    try:
        run_study(manifest, tmp_path / "o", BatchParams(outputs=frozenset({"calibration"})), quiet=True)
    finally:
        os.umask(old)
    folders = [p for p in (tmp_path / "o").iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert folders and all(p.stat().st_mode & 0o777 == 0o755 for p in folders)


def test_a_hidden_trial_name_does_not_share_the_failed_records_folder(tmp_path):
    """A manifest trial '.failed.csv' was written into '.failed', among the failure records."""
    manifest = tmp_path / "m.csv"
    manifest.write_text("trial\n.failed.csv\n")
    (tmp_path / ".failed.csv").write_text("time\n")
    (trial,) = read_study(manifest)
    assert trial.name == "failed" and trial.name != FAILED_DIR
