"""Strapdown integration of a gyro (lowerlimb.orientation.strapdown)."""

from __future__ import annotations

import numpy as np

from lowerlimb.conventions import rot_x, rot_z
from lowerlimb.orientation.strapdown import strapdown_matrices, strapdown_quat


def test_constant_rate_turns_by_rate_times_time() -> None:
    gyr = np.tile([0.0, 0.0, 1.0], (101, 1))
    R = strapdown_matrices(gyr, 100.0)
    np.testing.assert_allclose(R[0], np.eye(3), atol=1e-12)
    np.testing.assert_allclose(R[-1], rot_z(1.0), atol=1e-9)  # 100 steps of 0.01 rad


def test_rotations_compose_in_the_sensor_frame() -> None:
    """A turn about x then about the (new) z: R = Rx(a) Rz(b), body-fixed order.

    Each turn is a smooth pulse that is zero at its ends, so no step mixes the two axes.
    """
    pulse = np.sin(np.linspace(0.0, np.pi, 101))
    gyr = np.zeros((201, 3))
    gyr[:101, 0] = 0.5 * pulse
    gyr[100:, 2] = 0.7 * pulse
    a, b = (float(np.sum(0.5 * (v[1:] + v[:-1])) * 0.01) for v in (gyr[:, 0], gyr[:, 2]))
    R = strapdown_matrices(gyr, 100.0)
    np.testing.assert_allclose(R[-1], rot_x(a) @ rot_z(b), atol=1e-9)


def test_attitude_is_at_the_sample_time_not_half_a_sample_late() -> None:
    """ω = A cos t about z turns by A sin t; the rectangle rule lags by A·dt/2 · cos t (≈ 0.015 rad)."""
    t = np.arange(0.0, 3.0, 0.01)
    gyr = np.zeros((t.size, 3))
    gyr[:, 2] = 3.0 * np.cos(t)
    R = strapdown_matrices(gyr, 100.0)
    angle = np.arctan2(R[:, 1, 0], R[:, 0, 0])
    np.testing.assert_allclose(angle, 3.0 * np.sin(t), atol=1e-4)


def test_quaternions_are_unit() -> None:
    rng = np.random.default_rng(1)
    q = strapdown_quat(rng.normal(0.0, 3.0, (500, 3)), 100.0)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
