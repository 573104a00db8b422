"""Real data: the BROAD development trials (skipped when ../shared/data is absent)."""

import os
from pathlib import Path

import numpy as np
import pytest

from lowerlimb.conventions import quat_rotate
from lowerlimb.orientation import METHODS, estimate_orientation, orientation_errors

DATA = Path(os.environ.get("LOWERLIMB_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
BROAD = sorted((DATA / "broad").glob("*.mat"))

pytestmark = [
    pytest.mark.data,
    pytest.mark.skipif(not BROAD, reason=f"BROAD trials not found in {DATA / 'broad'}"),
]

#: first samples of each trial used by the fast tests: the still start and ~30 s of motion
SUBSET = 20000


def _load(path):
    import scipy.io as sio

    d = sio.loadmat(path)
    return {
        "gyr": np.ascontiguousarray(d["imu_gyr"], dtype=float),
        "acc": np.ascontiguousarray(d["imu_acc"], dtype=float),
        "mag": np.ascontiguousarray(d["imu_mag"], dtype=float),
        "quat": np.asarray(d["opt_quat"], dtype=float),
        "movement": np.asarray(d["movement"]).reshape(-1).astype(bool),
        "rate_hz": float(np.squeeze(d["sampling_rate"])),
    }


@pytest.fixture(scope="module", params=BROAD, ids=[p.stem for p in BROAD])
def trial(request):
    return _load(request.param)


def test_ground_truth_is_sensor_to_enu(trial):
    """At rest, the specific force rotated by opt_quat points up (+z), the field north (+y)."""
    still = ~trial["movement"] & np.all(np.isfinite(trial["quat"]), axis=1)
    up = quat_rotate(trial["quat"][still], trial["acc"][still]).mean(axis=0)
    assert up[2] > 9.5 and np.hypot(up[0], up[1]) < 0.3
    field = quat_rotate(trial["quat"][still], trial["mag"][still]).mean(axis=0)
    assert abs(np.degrees(np.arctan2(field[0], field[1]))) < 10.0


@pytest.mark.parametrize("method", METHODS)
def test_no_nan_unit_continuous(trial, method):
    sl = slice(0, SUBSET)
    for mag in (trial["mag"][sl], None):
        q = estimate_orientation(
            trial["gyr"][sl], trial["acc"][sl], mag, rate_hz=trial["rate_hz"], method=method
        )
        assert np.all(np.isfinite(q))
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-9)
        assert np.all(np.sum(q[1:] * q[:-1], axis=1) > 0.99)


def test_mahony_accuracy_on_a_whole_trial():
    """02_undisturbed_slow_rotation_B, whole trial: the benchmarked error (1.0°) with margin."""
    path = DATA / "broad" / "02_undisturbed_slow_rotation_B.mat"
    if not path.exists():
        pytest.skip("trial 02 not available")
    t = _load(path)
    q = estimate_orientation(t["gyr"], t["acc"], t["mag"], rate_hz=t["rate_hz"])
    e = orientation_errors(q, t["quat"], t["movement"])
    assert e.total_deg < 2.0
    assert e.inclination_deg < 1.0


#: Whole-trial accuracy of every filter with its default parameters on the 8 BROAD
#: development trials (``benchmarks/results/orientation.md``): measured mean total RMSE,
#: mean inclination RMSE and the largest per-trial total RMSE, degrees; 6D after removing
#: the best constant heading offset, as BROAD scores it.
BROAD_MEASURED_DEG = {
    ("mahony", "9D"): (2.02, 0.91, 3.97),
    ("mahony", "6D"): (2.18, 0.91, 5.20),
    ("ftecf", "9D"): (2.60, 1.16, 4.16),
    ("ftecf", "6D"): (2.35, 1.17, 5.86),
    ("madgwick", "9D"): (2.30, 1.11, 4.10),
    ("madgwick", "6D"): (2.28, 1.00, 5.42),
    ("quest_kf", "9D"): (3.37, 2.12, 6.93),
    ("quest_kf", "6D"): (3.11, 2.28, 7.25),
}
#: the regression bounds sit at 1.5x the measured values
BROAD_MARGIN = 1.5
BROAD_DEVELOPMENT_TRIALS = 8


@pytest.fixture(scope="module")
def all_broad():
    if len(BROAD) != BROAD_DEVELOPMENT_TRIALS:
        pytest.skip(f"{BROAD_DEVELOPMENT_TRIALS} BROAD development trials needed, found {len(BROAD)}")
    return {p.stem: _load(p) for p in BROAD}


@pytest.mark.parametrize(
    ("method", "mode"), list(BROAD_MEASURED_DEG), ids=[f"{m}-{d}" for m, d in BROAD_MEASURED_DEG]
)
def test_every_filter_stays_near_its_broad_accuracy(all_broad, method, mode):
    totals, inclinations = [], []
    for t in all_broad.values():
        mag = t["mag"] if mode == "9D" else None
        q = estimate_orientation(t["gyr"], t["acc"], mag, rate_hz=t["rate_hz"], method=method)
        e = orientation_errors(q, t["quat"], t["movement"], remove_heading_offset=mode == "6D")
        totals.append(e.total_deg)
        inclinations.append(e.inclination_deg)
    mean_total, mean_incl, max_total = BROAD_MEASURED_DEG[(method, mode)]
    got = (float(np.mean(totals)), float(np.mean(inclinations)), float(np.max(totals)))
    assert got[0] < BROAD_MARGIN * mean_total, (got, dict(zip(all_broad, totals, strict=True)))
    assert got[1] < BROAD_MARGIN * mean_incl, (got, dict(zip(all_broad, inclinations, strict=True)))
    assert got[2] < BROAD_MARGIN * max_total, (got, dict(zip(all_broad, totals, strict=True)))
