"""Errors-in-variables correction of the spherical cost and the regressor noise it needs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.calibration._prepare import prepare_pair
from lowerlimb.calibration.joint_center import fit_spherical
from lowerlimb.calibration.noise_correction import capped_noise_information, noise_information
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.angular_acceleration import angular_acceleration
from lowerlimb.constraints.prefilter import lowpass
from lowerlimb.constraints.regressor_noise import filter_noise_gains, white_noise_std
from lowerlimb.constraints.spherical import spherical_residual
from lowerlimb.simulation import ImuNoise


def test_white_noise_std_ignores_slow_sway():
    rng = np.random.default_rng(0)
    t = np.arange(300) / 100.0
    sway = 0.05 * np.sin(2 * np.pi * 0.3 * t)[:, None]
    g = sway + 0.01 * rng.normal(size=(300, 3))
    assert white_noise_std(g) == pytest.approx(0.01, rel=0.1)
    assert white_noise_std(g[:5]) is None


@pytest.mark.parametrize("cutoff", [None, 6.0, 15.0])
def test_filter_gains_match_filtered_white_noise(cutoff):
    rng = np.random.default_rng(1)
    n = rng.normal(size=(200_000, 3))
    f = lowpass(n, 100.0, cutoff)
    a = angular_acceleration(f, 100.0, window_s=0.07, polyorder=4)
    g_w, g_a = filter_noise_gains(100.0, cutoff, 0.07, 4)
    assert np.std(f[1000:-1000]) == pytest.approx(g_w, rel=0.02)
    assert np.std(a[1000:-1000]) == pytest.approx(g_a, rel=0.02)


@pytest.fixture(scope="module")
def ankle():
    sim = cached_simulation("walk", 20.0, 0, noise=ImuNoise.none())
    tr = sim.trial
    opts = CalibrationOptions(prefilter=False)
    _, data = prepare_pair(tr.acc["shank"], tr.gyr["shank"], tr.acc["foot"], tr.gyr["foot"], 100.0, opts)
    t = sim.truth["joints"]["ankle"]
    return data, np.r_[t["center_in_parent_sensor"], t["center_in_child_sensor"]]


def test_q_is_the_expected_noise_part_of_the_cost(ankle):
    """E Σ e² − Σ e₀² = xᵀ Q x for white noise on ω and α (Monte Carlo at the true centres)."""
    data, x = ankle
    s_w, s_a = 0.02, 1.5
    noisy = replace(
        data, gyr_noise_parent=s_w, angacc_noise_parent=s_a, gyr_noise_child=s_w, angacc_noise_child=s_a
    )
    expected = x @ noise_information(x, noisy) @ x
    rng = np.random.default_rng(0)
    e0 = np.sum(spherical_residual(x, data) ** 2)
    excess = []
    for _ in range(10):
        shape = data.gyr_parent.shape
        d = replace(
            data,
            gyr_parent=data.gyr_parent + s_w * rng.normal(size=shape),
            angacc_parent=data.angacc_parent + s_a * rng.normal(size=shape),
            gyr_child=data.gyr_child + s_w * rng.normal(size=shape),
            angacc_child=data.angacc_child + s_a * rng.normal(size=shape),
        )
        excess.append(np.sum(spherical_residual(x, d) ** 2) - e0)
    assert np.mean(excess) == pytest.approx(expected, rel=0.05)


def test_the_cap_limits_every_direction():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(6, 6))
    H = A @ A.T + np.eye(6)
    Q = 2.0 * H  # the noise would claim twice the data's information
    capped, top = capped_noise_information(Q, H, 0.2)
    assert top == pytest.approx(2.0)
    lam = np.linalg.eigvals(np.linalg.solve(H, capped)).real
    assert np.allclose(lam, 0.2)
    same, top = capped_noise_information(0.1 * H, H, 0.2)
    assert top == pytest.approx(0.1) and np.allclose(same, 0.1 * H)


def test_without_noise_levels_the_fit_is_the_plain_one(ankle):
    data, _ = ankle
    on = fit_spherical(data, method="gn", options=CalibrationOptions())
    off = fit_spherical(data, method="gn", options=CalibrationOptions(noise_correction=False))
    assert np.allclose(on.center_in_parent_sensor, off.center_in_parent_sensor)
    assert np.allclose(on.excitation.std, off.excitation.std)
