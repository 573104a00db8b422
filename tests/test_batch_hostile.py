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
