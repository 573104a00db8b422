"""The reference-S2J Kalman filter (Lee & Lee 2022, eq. 4–6) on synthetic data with a known answer."""

from __future__ import annotations

import numpy as np
import pytest

from lowerlimb.conventions import matrix_from_euler_zxy
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.s2j import ReferenceKFParams, estimate_reference_s2j

RATE_HZ = 100.0
S_PROX = np.array([-0.17, -0.10, -0.10])
S_DIST = np.array([0.19, 0.0, -0.10])
# a calibration that is 2–2.5 cm off
BIAS_PROX = np.array([0.02, -0.01, 0.015])
BIAS_DIST = np.array([-0.01, 0.02, 0.0])
P_NOISE_M = 5e-4  # optical capture noise


def _motion(duration_s: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, duration_s, 1.0 / RATE_HZ)
    flex = np.sin(2 * np.pi * 0.5 * t) + 0.3 * np.sin(2 * np.pi * 0.13 * t)
    add = 0.3 * np.sin(2 * np.pi * 0.37 * t + 1.0)
    rot = 0.3 * np.sin(2 * np.pi * 0.23 * t + 2.0)
    return t, matrix_from_euler_zxy(flex, add, rot)


def _measure(R: np.ndarray, sp: np.ndarray, sd: np.ndarray, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    p = sp - np.einsum("nij,nj->ni", R, sd)
    return p + P_NOISE_M * rng.normal(size=p.shape)


def _rms_mm(a: np.ndarray, b: np.ndarray) -> float:
    return 1e3 * float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


PARAMS = ReferenceKFParams(constant_noise_m=0.1, position_noise_m=P_NOISE_M, process_noise_m_per_sqrt_s=5e-4)


def test_recovers_constant_vectors_from_biased_calibration() -> None:
    t, R = _motion()
    sp = np.tile(S_PROX, (t.size, 1))
    sd = np.tile(S_DIST, (t.size, 1))
    ref = estimate_reference_s2j(
        R, _measure(R, sp, sd), S_PROX + BIAS_PROX, S_DIST + BIAS_DIST, rate_hz=RATE_HZ, params=PARAMS
    )
    assert _rms_mm(S_PROX + BIAS_PROX, sp) > 20.0
    assert _rms_mm(ref.s_prox_m, sp) < 1.0
    assert _rms_mm(ref.s_dist_m, sd) < 1.0
    # eq. 5 holds to the measurement noise
    assert ref.constraint_rms_m < 2 * np.sqrt(3) * P_NOISE_M
    assert ref.std_m.shape == (t.size, 6)


def test_tracks_slowly_varying_vectors() -> None:
    t, R = _motion()
    drift = np.sin(2 * np.pi * t / 60.0)[:, None]
    sp = S_PROX + 0.02 * drift * np.array([1.0, 0.5, -1.0])
    sd = S_DIST + 0.02 * drift * np.array([-1.0, 1.0, 0.3])
    p_ref = _measure(R, sp, sd)
    smooth = estimate_reference_s2j(R, p_ref, S_PROX, S_DIST, rate_hz=RATE_HZ, params=PARAMS)
    assert _rms_mm(smooth.s_prox_m, sp) < 1.5
    assert _rms_mm(smooth.s_dist_m, sd) < 1.5
    forward = estimate_reference_s2j(
        R,
        p_ref,
        S_PROX,
        S_DIST,
        rate_hz=RATE_HZ,
        params=ReferenceKFParams(
            constant_noise_m=0.1,
            position_noise_m=P_NOISE_M,
            process_noise_m_per_sqrt_s=5e-4,
            smooth=False,
        ),
    )
    # the forward filter lags: worse than the smoother, still far better than the constants
    assert _rms_mm(smooth.s_prox_m, sp) < _rms_mm(forward.s_prox_m, sp) < 8.0


def test_fast_deformation_satisfies_the_reference_position() -> None:
    """Deformation as fast as the motion: only eq. 5 is guaranteed, the split is a prior."""
    t, R = _motion(20.0)
    sp = S_PROX + 0.02 * np.stack([np.sin(t), np.cos(t), 0 * t], 1)
    sd = S_DIST + 0.015 * np.stack([np.cos(3 * t), 0 * t, np.sin(2 * t)], 1)
    p_ref = sp - np.einsum("nij,nj->ni", R, sd)
    ref = estimate_reference_s2j(R, p_ref, S_PROX, S_DIST, rate_hz=RATE_HZ)
    est = ref.s_prox_m - np.einsum("nij,nj->ni", R, ref.s_dist_m)
    assert _rms_mm(est, p_ref) < 0.05
    assert ref.constraint_rms_m < 5e-5


def test_bad_input_raises() -> None:
    _, R = _motion(1.0)
    p = np.zeros((R.shape[0], 3))
    with pytest.raises(ShapeError, match=r"\(N, 3, 3\)"):
        estimate_reference_s2j(R[:, :2], p, S_PROX, S_DIST, rate_hz=RATE_HZ)
    with pytest.raises(ShapeError, match="to match R_pd"):
        estimate_reference_s2j(R, p[:-1], S_PROX, S_DIST, rate_hz=RATE_HZ)
    with pytest.raises(ShapeError, match=r"shape \(3,\)"):
        estimate_reference_s2j(R, p, S_PROX[:2], S_DIST, rate_hz=RATE_HZ)
    with pytest.raises(InputError, match="rate_hz"):
        estimate_reference_s2j(R, p, S_PROX, S_DIST, rate_hz=0.0)
    bad = p.copy()
    bad[3, 1] = np.nan
    with pytest.raises(InputError, match="p_pd_ref_m contains NaN"):
        estimate_reference_s2j(R, bad, S_PROX, S_DIST, rate_hz=RATE_HZ)
    with pytest.raises(InputError, match="at least 2 samples"):
        estimate_reference_s2j(R[:1], p[:1], S_PROX, S_DIST, rate_hz=RATE_HZ)
    with pytest.raises(InputError, match="constant_noise_m must be a positive"):
        ReferenceKFParams(constant_noise_m=0.0)
