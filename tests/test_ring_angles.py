"""Real data: RING chain seg3–seg4 hinge angle from IMUs against optical capture.

Skipped when ``ring/`` is not in the data folder (``simcache.data_dir()``).
Same steps as ``benchmarks/ring_angles.py`` (rigid recording, Mahony 6-axis,
estimated hinge axis, heading made consistent with the axis as lowerlimb
does at the knee). Measured there: RMSE 0.18° after removing the constant
offset, correlation 0.99998, axis 0.9° from the nominal y in IMU4; the bounds
below leave a 5x margin for filter retuning.
"""

from __future__ import annotations

import numpy as np
import pytest
from simcache import data_dir

from lowerlimb import estimate_hinge_axis
from lowerlimb.conventions import quat_conjugate, quat_multiply, quat_normalize, quat_rotate
from lowerlimb.orientation import estimate_orientation
from lowerlimb.segments.heading import relative_heading, rotate_about_vertical
from lowerlimb.stillness import initial_still_samples

DATA = data_dir()
RING = DATA / "ring" if DATA is not None else None

pytestmark = [
    pytest.mark.data,
    pytest.mark.skipif(
        RING is None
        or not (RING / "trial1_imu_rigid.csv").is_file()
        or not (RING / "trial1_omc.csv").is_file(),
        reason="RING data (ring/trial1_imu_rigid.csv, trial1_omc.csv) not found",
    ),
]

#: Optical → IMU time offset measured by benchmarks/ring_angles.py (angular-speed cross-correlation).
LAG_S = -0.016
RMSE_BOUND_DEG = 1.0
AXIS_BOUND_DEG = 3.0


def _cols(path, names):
    header = path.read_text().splitlines()[2].split(",")
    idx = [header.index(n) for n in names]
    return np.genfromtxt(path, delimiter=",", skip_header=3, usecols=idx)  # empty cells -> NaN


def _twist(q_p, q_c, ref, axis):
    """Twist angle (rad) of R_pc(ref)ᵀ R_pc(t) about ``axis`` (child frame), unwrapped over finite rows."""
    q_pc = quat_multiply(quat_conjugate(q_p), q_c)
    ok = np.isfinite(q_pc).all(axis=1)
    q_pc[ok] *= np.where(q_pc[ok] @ q_pc[ok][0] < 0, -1.0, 1.0)[:, None]
    q0 = quat_normalize(np.nanmean(q_pc[ref], axis=0))
    q = quat_multiply(quat_conjugate(q0), q_pc)
    ang = np.angle(np.exp(2j * np.arctan2(q[:, 1:] @ axis, q[:, 0])))
    ang[ok] = np.unwrap(ang[ok])
    return ang


def test_rigid_seg3_seg4_hinge_angle_matches_optical():
    rate = 40.0
    imu = _cols(
        RING / "trial1_imu_rigid.csv",
        [f"seg{s}_{k}_{a}" for s in (3, 4) for k in ("acc", "gyr") for a in "xyz"],
    )
    acc3, gyr3, acc4, gyr4 = (imu[:, 3 * i : 3 * i + 3] for i in range(4))
    omc = _cols(RING / "trial1_omc.csv", [f"seg{s}_quat_{a}" for s in (3, 4) for a in "wxyz"])

    j_p, j_c = estimate_hinge_axis(gyr3, gyr4, rate_hz=rate, acc_parent=acc3, acc_child=acc4)
    sign = np.sign(j_p[1] + j_c[1])  # towards the nominal +y (a hinge's sign is arbitrary)
    j_p, j_c = sign * np.asarray(j_p), sign * np.asarray(j_c)
    assert np.degrees(np.arccos(j_c[1])) < AXIS_BOUND_DEG

    q3 = estimate_orientation(gyr3, acc3, rate_hz=rate)
    q4 = estimate_orientation(gyr4, acc4, rate_hz=rate)
    delta = relative_heading(quat_rotate(q3, j_p), quat_rotate(q4, j_c), rate, window_s=4.0)
    q4 = rotate_about_vertical(q4, delta)
    n_still = max(10, initial_still_samples([gyr3, gyr4], [acc3, acc4], rate))
    a_imu = _twist(q3, q4, slice(0, n_still), j_c)

    t_imu = np.arange(len(a_imu)) / rate
    t_omc = np.arange(len(omc)) / 30.0 + LAG_S
    ref = slice(0, int(np.searchsorted(t_omc, t_imu[n_still - 1], side="right")))
    a_omc = _twist(omc[:, :4], omc[:, 4:], ref, np.array([0.0, 1.0, 0.0]))
    a_omc = np.interp(t_imu, t_omc, a_omc, left=np.nan, right=np.nan)  # NaN gaps stay NaN

    ok = np.isfinite(a_omc)
    assert ok.sum() > 0.8 * len(ok)
    d = np.degrees(a_imu[ok] - a_omc[ok])
    rmse = np.sqrt(np.mean((d - d.mean()) ** 2))
    assert np.ptp(np.degrees(a_omc[ok])) > 120  # the hinge really moved (−70° … 91°)
    assert rmse < RMSE_BOUND_DEG
    assert np.corrcoef(a_imu[ok], a_omc[ok])[0, 1] > 0.999
