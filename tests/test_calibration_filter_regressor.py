"""The regressor prefilter: K = [w]x^2 + [a]x low-passed, not built from a low-passed gyro."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from lowerlimb.calibration.leg import calibrate_leg
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.spherical import (
    SphericalData,
    kinematic_matrix,
    spherical_casadi,
    spherical_residual,
)
from lowerlimb.errors import ShapeError
from lowerlimb.simulation import ImuNoise, simulate_bilateral


def _data(n: int = 50, seed: int = 0, kin: bool = False) -> SphericalData:
    rng = np.random.default_rng(seed)
    v = [rng.normal(size=(n, 3)) for _ in range(6)]
    if not kin:
        return SphericalData(*v)
    kp, kc = rng.normal(size=(n, 3, 3)), rng.normal(size=(n, 3, 3))
    return SphericalData(*v, kin_parent=kp, kin_child=kc)


def test_casadi_and_numpy_residuals_agree_with_and_without_a_given_regressor() -> None:
    x = np.array([0.05, -0.2, 0.01, 0.0, 0.15, -0.03])
    for kin in (False, True):
        d = _data(kin=kin)
        r = np.asarray(spherical_casadi(d.n_samples)(x, d.data_matrix())).ravel()
        assert np.allclose(r, spherical_residual(x, d), atol=1e-6)
    plain = _data()
    assert np.allclose(plain.K_parent, kinematic_matrix(plain.gyr_parent, plain.angacc_parent))


def test_rotating_the_frames_keeps_the_residual_and_slicing_keeps_the_regressor() -> None:
    d = _data(kin=True)
    x = np.array([0.05, -0.2, 0.01, 0.0, 0.15, -0.03])
    qp, _ = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))
    qc, _ = np.linalg.qr(np.random.default_rng(2).normal(size=(3, 3)))
    xr = np.r_[qp.T @ x[:3], qc.T @ x[3:]]
    assert np.allclose(spherical_residual(xr, d.rotated(qp, qc)), spherical_residual(x, d))
    keep = np.arange(d.n_samples) % 3 == 0
    assert np.allclose(d.select(keep).K_child, d.kin_child[keep])
    assert np.allclose(d.subsample(3).K_parent, d.kin_parent[::3])
    with pytest.raises(ShapeError, match="kin_parent"):
        SphericalData(*[d.acc_parent] * 6, kin_parent=np.zeros((3, 3, 3)))


def test_low_cutoff_hip_is_recovered_only_with_the_filtered_regressor() -> None:
    """Noise-free rigid walk filtered at 4 Hz: squaring a low-passed gyro biases the hip
    (17 / 18 cm in the pelvis sensor); low-passing the regressor keeps the relation."""
    sim = simulate_bilateral(20.0, 202, noise=ImuNoise.none())
    trial, truth = sim.trial.leg("left"), sim.truth["legs"]["left"]["joints"]["hip"]
    err = {}
    for on in (False, True):
        opts = CalibrationOptions(filter_regressor=on, cutoff_hz=4.0, anthropometric_prior=False)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            cal = calibrate_leg(trial, options=opts)
        err[on] = np.linalg.norm(
            cal.hip.center_in_parent_sensor - np.asarray(truth["center_in_parent_sensor"])
        )
    assert err[True] < 0.06  # measured 35 mm
    assert err[True] < err[False] / 3  # measured 176 mm without
