"""Nadaraya–Watson kernel regression on one and two angles (M2, M3)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lowerlimb.errors import InputError, ShapeError
from lowerlimb.s2j import KernelRegression, KernelRegressionParams, fit_kernel_regression


def _f1(x: np.ndarray) -> np.ndarray:
    """A smooth S2J-like function of one angle, m."""
    return np.stack([0.02 * np.sin(2 * x), 0.01 * x**2, -0.03 * np.cos(x)], axis=1)


def _f2(x: np.ndarray) -> np.ndarray:
    """A smooth function of two angles, m."""
    return np.stack([0.02 * np.sin(2 * x[:, 0]) + 0.01 * x[:, 1], 0.01 * x[:, 0] * x[:, 1]], axis=1)


def _flexion(duration_s: float = 120.0, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration_s, 0.01)
    x = 0.8 + 0.8 * np.sin(2 * np.pi * 0.4 * t) + 0.05 * rng.normal(size=t.size)
    return t, x


def _rms_mm(a: np.ndarray, b: np.ndarray) -> float:
    return 1e3 * float(np.sqrt(np.mean((a - b) ** 2)))


def test_one_angle_recovers_smooth_function() -> None:
    rng = np.random.default_rng(0)
    _, x = _flexion()
    reg = fit_kernel_regression(x, _f1(x) + 0.001 * rng.normal(size=(x.size, 3)))
    lo, hi = np.quantile(x, [0.05, 0.95])
    xq = np.linspace(lo, hi, 500)
    # 1 mm measurement noise; the estimate is within 0.5 mm inside the range
    assert np.abs(reg.predict(xq) - _f1(xq)).max() < 0.5e-3
    # within 1 mm nearer the edges, where Nadaraya–Watson's boundary bias grows
    lo, hi = np.quantile(x, [0.01, 0.99])
    xq = np.linspace(lo, hi, 500)
    assert np.abs(reg.predict(xq) - _f1(xq)).max() < 1.0e-3
    assert _rms_mm(reg.predict(x), _f1(x)) < 0.5
    assert reg.n_inputs == 1 and reg.n_outputs == 3
    assert 0.5 < 1e3 * reg.cv_rms < 1.5


def test_clamps_outside_training_range() -> None:
    _, x = _flexion(30.0)
    reg = fit_kernel_regression(x, _f1(x))
    edge_lo, edge_hi = reg.predict(np.array([x.min(), x.max()]))
    out = reg.predict(np.array([x.min() - 1.0, x.max() + 5.0]))
    np.testing.assert_allclose(out[0], edge_lo)
    np.testing.assert_allclose(out[1], edge_hi)


def test_two_angles_recover_smooth_surface() -> None:
    rng = np.random.default_rng(2)
    t, x = _flexion()
    x2 = np.stack([x, 0.3 * np.sin(2 * np.pi * 0.13 * t) + 0.2 * x], axis=1)
    reg = fit_kernel_regression(x2, _f2(x2) + 0.001 * rng.normal(size=(t.size, 2)))
    assert reg.n_inputs == 2
    assert _rms_mm(reg.predict(x2), _f2(x2)) < 0.7
    # a combination never seen in training gets a finite, bounded answer
    far = reg.predict(np.array([[x.min(), x2[:, 1].max()]]))
    assert np.all(np.isfinite(far)) and np.abs(far).max() < np.abs(_f2(x2)).max() + 1e-3


def test_bandwidth_grows_with_noise() -> None:
    rng = np.random.default_rng(3)
    _, x = _flexion(60.0)
    quiet = fit_kernel_regression(x, _f1(x) + 1e-4 * rng.normal(size=(x.size, 3)))
    noisy = fit_kernel_regression(x, _f1(x) + 2e-2 * rng.normal(size=(x.size, 3)))
    assert noisy.bandwidth[0] > quiet.bandwidth[0]


def test_fixed_bandwidth_and_constant_input() -> None:
    _, x = _flexion(10.0)
    reg = fit_kernel_regression(x, _f1(x), KernelRegressionParams(bandwidth=(0.1,)))
    assert reg.bandwidth[0] == pytest.approx(0.1)
    x2 = np.stack([x, np.zeros_like(x)], axis=1)  # an input that never moves
    reg2 = fit_kernel_regression(x2, _f1(x))
    assert reg2.grid_size[1] == 1
    np.testing.assert_allclose(reg2.predict(np.stack([x, x], 1)), reg.predict(x), atol=5e-3)


def test_json_round_trip() -> None:
    t, x = _flexion(60.0)
    x2 = np.stack([x, np.cos(t)], axis=1)
    reg = fit_kernel_regression(x2, np.hstack([_f1(x), _f2(x2)]))
    text = json.dumps(reg.to_dict())
    assert len(text) < 60_000  # a small sidecar
    back = KernelRegression.from_dict(json.loads(text))
    np.testing.assert_allclose(back.predict(x2), reg.predict(x2), atol=1e-6)


def test_bad_input_raises() -> None:
    x = np.linspace(0.0, 1.0, 100)
    with pytest.raises(InputError, match="one or two inputs"):
        fit_kernel_regression(np.stack([x, x, x], 1), x)
    with pytest.raises(InputError, match="at least 10 training samples"):
        fit_kernel_regression(x[:5], x[:5])
    with pytest.raises(ShapeError, match="N = 100 samples"):
        fit_kernel_regression(x, x[:50])
    with pytest.raises(InputError, match="NaN"):
        fit_kernel_regression(np.where(x > 0.5, np.nan, x), x)
    with pytest.raises(InputError, match="bandwidth must hold 1 positive"):
        fit_kernel_regression(x, x, KernelRegressionParams(bandwidth=(-1.0,)))
    reg = fit_kernel_regression(x, x)
    with pytest.raises(ShapeError, match=r"\(N, 1\)"):
        reg.predict(np.zeros((3, 2)))
    with pytest.raises(InputError, match="KernelRegression.to_dict"):
        KernelRegression.from_dict({"format": "something else"})
    rec = reg.to_dict()
    del rec["nodes"]
    with pytest.raises(InputError, match="malformed"):
        KernelRegression.from_dict(rec)
