import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rigid_pair import rigid_pair

from lowerlimb.constraints.hinge import (
    angles_from_axis,
    axis_angles_jacobian,
    axis_from_angles,
    hinge_acc_residual,
    hinge_casadi,
    hinge_jacobian,
    hinge_residual,
    hinge_residual_population,
    hinge_sample_function,
)
from lowerlimb.constraints.spherical import joint_acceleration
from lowerlimb.errors import ShapeError


@pytest.fixture(scope="module")
def pair():
    return rigid_pair("hinge", seed=4, duration_s=10.0)


def _x(p):
    return np.r_[angles_from_axis(p.axis_parent), angles_from_axis(p.axis_child)]


def test_eq5_corrected_last_component_is_sin_phi():
    assert np.allclose(axis_from_angles(np.pi / 2, 0.3), [0, 0, 1], atol=1e-12)
    assert np.allclose(axis_from_angles(0.0, np.pi / 2), [0, 1, 0], atol=1e-12)
    phi, theta = 0.4, -2.0
    assert np.isclose(np.linalg.norm(axis_from_angles(phi, theta)), 1.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 0.1))
def test_angles_round_trip(v):
    u = np.asarray(v) / np.linalg.norm(v)
    assert np.allclose(axis_from_angles(*angles_from_axis(u)), u, atol=1e-12)


def test_angles_round_trip_next_to_the_pole():
    u = np.array([0.0, 1e-8, 1.0]) / np.linalg.norm([0.0, 1e-8, 1.0])
    assert np.allclose(axis_from_angles(*angles_from_axis(u)), u, atol=1e-12)


def test_axis_angles_jacobian_by_finite_differences():
    phi, theta, h = 0.3, 1.1, 1e-6
    fd = np.stack(
        [
            (axis_from_angles(phi + h, theta) - axis_from_angles(phi - h, theta)) / (2 * h),
            (axis_from_angles(phi, theta + h) - axis_from_angles(phi, theta - h)) / (2 * h),
        ],
        axis=1,
    )
    assert np.allclose(axis_angles_jacobian(phi, theta), fd, atol=1e-8)


def test_residual_vanishes_at_the_true_axes_for_every_sign(pair):
    x = _x(pair)
    assert np.abs(hinge_residual(x, pair.gyr_parent, pair.gyr_child)).max() < 1e-6
    # eq. 4/6 do not see the sign of either axis
    flipped = np.r_[angles_from_axis(-pair.axis_parent), angles_from_axis(pair.axis_child)]
    assert np.abs(hinge_residual(flipped, pair.gyr_parent, pair.gyr_child)).max() < 1e-6
    wrong = x + np.array([0.2, 0.0, 0.0, 0.0])
    assert np.abs(hinge_residual(wrong, pair.gyr_parent, pair.gyr_child)).max() > 0.05


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_jacobian_matches_finite_differences(pair, seed):
    x = np.random.default_rng(seed).uniform(-1.2, 1.2, 4)
    J = hinge_jacobian(x, pair.gyr_parent, pair.gyr_child)
    h = 1e-6
    fd = np.stack(
        [
            (
                hinge_residual(x + h * e, pair.gyr_parent, pair.gyr_child)
                - hinge_residual(x - h * e, pair.gyr_parent, pair.gyr_child)
            )
            / (2 * h)
            for e in np.eye(4)
        ],
        axis=1,
    )
    assert np.allclose(J, fd, atol=1e-6)


def test_population_and_casadi_match_numpy(pair):
    X = np.random.default_rng(3).uniform(-1.5, 1.5, (5, 4))
    R = hinge_residual_population(X, pair.gyr_parent, pair.gyr_child)
    assert np.allclose(R, [hinge_residual(x, pair.gyr_parent, pair.gyr_child) for x in X])
    wp, wc = pair.gyr_parent[::10], pair.gyr_child[::10]
    F = hinge_casadi(wp.shape[0])
    P = np.hstack([wp, wc]).T
    x = X[0]
    assert np.allclose(np.asarray(F(x, P)).ravel(), hinge_residual(x, wp, wc), atol=1e-12)
    xs = ca.MX.sym("x", 4)
    JF = ca.Function("J", [xs], [ca.jacobian(F(xs, P), xs)])
    assert np.allclose(np.asarray(JF(x)), hinge_jacobian(x, wp, wc), atol=1e-9)
    assert hinge_sample_function() is hinge_sample_function()


def test_acc_residual_sees_the_sign(pair):
    gp = joint_acceleration(pair.acc_parent, pair.gyr_parent, pair.angacc_parent, pair.center_parent)
    gc = joint_acceleration(pair.acc_child, pair.gyr_child, pair.angacc_child, pair.center_child)
    same = hinge_acc_residual(pair.axis_parent, pair.axis_child, gp, gc)
    opposite = hinge_acc_residual(pair.axis_parent, -pair.axis_child, gp, gc)
    assert np.abs(same).max() < 1e-3
    assert np.abs(opposite).max() > 1.0


def test_shape_errors(pair):
    with pytest.raises(ShapeError, match="phi_P"):
        hinge_residual(np.zeros(3), pair.gyr_parent, pair.gyr_child)
    with pytest.raises(ShapeError, match=r"\(N, 3\)"):
        hinge_jacobian(np.zeros(4), pair.gyr_parent, pair.gyr_child[:-1])
    with pytest.raises(ShapeError, match=r"\(P, 4\)"):
        hinge_residual_population(np.zeros(4), pair.gyr_parent, pair.gyr_child)
