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
    """A turn about x then about the (new) z: R = Rx(a) Rz(b), body-fixed order."""
    gyr = np.vstack([np.tile([0.5, 0.0, 0.0], (100, 1)), np.tile([0.0, 0.0, 0.7], (100, 1)), [[0, 0, 0]]])
    R = strapdown_matrices(gyr, 100.0)
    np.testing.assert_allclose(R[-1], rot_x(0.5) @ rot_z(0.7), atol=1e-9)


def test_quaternions_are_unit() -> None:
    rng = np.random.default_rng(1)
    q = strapdown_quat(rng.normal(0.0, 3.0, (500, 3)), 100.0)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
