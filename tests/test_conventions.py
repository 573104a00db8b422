import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from lowerlimb import conventions as cv
from lowerlimb.model.leg_model import LegModel

finite = st.floats(-10, 10, allow_nan=False)
quats = arrays(np.float64, 4, elements=finite).filter(lambda q: np.linalg.norm(q) > 1e-3)


@given(quats)
def test_matrix_quaternion_round_trip(q):
    q = cv.quat_normalize(q)
    R = cv.quat_to_matrix(q)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    q2 = cv.quat_from_matrix(R)
    assert np.isclose(abs(np.dot(q, q2)), 1.0, atol=1e-12)


@given(quats, quats, arrays(np.float64, 3, elements=finite))
def test_product_composes_rotations(p, q, v):
    p, q = cv.quat_normalize(p), cv.quat_normalize(q)
    lhs = cv.quat_rotate(cv.quat_multiply(p, q), v)
    rhs = cv.quat_to_matrix(p) @ cv.quat_to_matrix(q) @ v
    assert np.allclose(lhs, rhs, atol=1e-9)


@given(arrays(np.float64, 3, elements=st.floats(-3, 3)))
def test_rotvec_round_trip(rv):
    q = cv.quat_from_rotvec(rv)
    assert np.isclose(np.linalg.norm(q), 1.0)
    assert np.allclose(
        cv.quat_to_matrix(cv.quat_from_rotvec(cv.quat_to_rotvec(q))),
        cv.quat_to_matrix(q),
        atol=1e-9,
    )


def test_quaternion_is_w_first_and_sensor_to_earth():
    # 90° about z: sensor x maps to earth y (east -> north)
    q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    assert np.allclose(cv.quat_rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0])


def test_gravity_is_enu_down():
    assert np.allclose(cv.GRAVITY_ENU, [0.0, 0.0, -9.81])


@settings(max_examples=300)
@given(st.floats(-3.1, 3.1), st.floats(-1.5, 1.5), st.floats(-3.1, 3.1))
def test_euler_zxy_round_trip(z, x, y):
    R = cv.matrix_from_euler_zxy(z, x, y)
    assert np.allclose(cv.euler_zxy_from_matrix(R), [z, x, y], atol=1e-7)


@pytest.mark.parametrize("x", [np.pi / 2, -np.pi / 2])
def test_euler_zxy_gimbal_branches(x):
    R = cv.matrix_from_euler_zxy(0.7, x, -0.3)
    z2, x2, y2 = cv.euler_zxy_from_matrix(R)
    assert np.isclose(x2, x, atol=1e-6)
    assert y2 == 0.0
    assert np.allclose(cv.matrix_from_euler_zxy(z2, x2, y2), R, atol=1e-9)


def test_euler_is_z_then_x_then_y():
    R = cv.rot_z(0.3) @ cv.rot_x(0.2) @ cv.rot_y(0.1)
    assert np.allclose(cv.matrix_from_euler_zxy(0.3, 0.2, 0.1), R)


@pytest.mark.parametrize("side", ["left", "right"])
@pytest.mark.parametrize("joint", ["hip", "knee", "ankle"])
def test_joint_angle_round_trip(side, joint):
    a = np.array([0.4, -0.2, 0.3])
    R = cv.matrix_from_joint_angles(a, joint, side)
    assert np.allclose(cv.joint_angles_from_matrix(R, joint, side), a)


def _distal_point(model: LegModel, angles: np.ndarray, frame: str, point_in_frame: np.ndarray) -> np.ndarray:
    pose = model.frame_poses(model.configuration(angles), [frame])[frame]
    return pose.rotation @ point_in_frame + pose.translation


@pytest.mark.parametrize("side", ["left", "right"])
def test_clinical_signs_on_the_model(side):
    """Positive angles move the segments the clinical way, on both sides (pelvis frame = world)."""
    m = LegModel.from_template(side)
    medial = -1.0 if side == "right" else 1.0  # z points right
    zero = np.zeros(9)
    knee0 = _distal_point(m, zero, "shank", np.zeros(3))
    ankle0 = _distal_point(m, zero, "foot", np.zeros(3))
    toe0 = _distal_point(m, zero, "foot", np.array([0.15, 0.0, 0.0]))

    def moved(index, value, frame, point):
        a = zero.copy()
        a[index] = value
        return _distal_point(m, a, frame, point)

    # hip flexion: knee moves anterior (+x)
    assert moved(0, 0.3, "shank", np.zeros(3))[0] > knee0[0] + 0.05
    # hip adduction: knee moves medially
    assert medial * (moved(1, 0.2, "shank", np.zeros(3))[2] - knee0[2]) > 0.05
    # hip internal rotation: toes turn medially
    assert medial * (moved(2, 0.3, "foot", np.array([0.15, 0.0, 0.0]))[2] - toe0[2]) > 0.02
    # knee flexion: ankle moves posterior
    assert moved(3, 0.5, "foot", np.zeros(3))[0] < ankle0[0] - 0.1
    # knee adduction (varus): ankle moves medially
    assert medial * (moved(4, 0.1, "foot", np.zeros(3))[2] - ankle0[2]) > 0.02
    # knee internal rotation: toes turn medially
    assert medial * (moved(5, 0.3, "foot", np.array([0.15, 0.0, 0.0]))[2] - toe0[2]) > 0.02
    # ankle dorsiflexion: toes go up
    assert moved(6, 0.3, "foot", np.array([0.15, 0.0, 0.0]))[1] > toe0[1] + 0.02
    # ankle inversion: the sole faces medially, i.e. the foot's up axis tips laterally
    up = moved(7, 0.3, "foot", np.array([0.0, 0.1, 0.0])) - ankle0
    assert -medial * up[2] > 0.01
    # ankle internal rotation: toes turn medially
    assert medial * (moved(8, 0.3, "foot", np.array([0.15, 0.0, 0.0]))[2] - toe0[2]) > 0.02
    # the joint coordinates read back as the same ISB angles through the segment frames
    a = np.array([0.3, 0.1, -0.2, 0.6, 0.05, 0.1, -0.2, 0.15, 0.05])
    poses = m.frame_poses(m.configuration(a), ["pelvis", "thigh", "shank", "foot"])
    for joint, (prox, dist), sl in (
        ("hip", ("pelvis", "thigh"), slice(0, 3)),
        ("knee", ("thigh", "shank"), slice(3, 6)),
        ("ankle", ("shank", "foot"), slice(6, 9)),
    ):
        R = poses[prox].rotation.T @ poses[dist].rotation
        assert np.allclose(cv.joint_angles_from_matrix(R, joint, side), a[sl], atol=1e-9)
