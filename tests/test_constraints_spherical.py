import casadi as ca
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rigid_pair import rigid_pair
from scipy.spatial.transform import Rotation

from lowerlimb.constraints.spherical import (
    AXIS_GAUGE_MAP,
    SphericalData,
    joint_acceleration,
    kinematic_matrix,
    spherical_axis_gauge_sample_function,
    spherical_casadi,
    spherical_jacobian,
    spherical_jacobian_3d,
    spherical_residual,
    spherical_residual_3d,
    spherical_residual_population,
    spherical_sample_function,
)
from lowerlimb.errors import ShapeError


def _data(p):
    return SphericalData(
        p.acc_parent, p.gyr_parent, p.angacc_parent, p.acc_child, p.gyr_child, p.angacc_child
    )


@pytest.fixture(scope="module")
def pair():
    return rigid_pair("spherical", seed=1, duration_s=10.0)


def _fd(f, x, h=1e-6):
    cols = []
    for i in range(x.size):
        d = np.zeros_like(x)
        d[i] = h
        cols.append((f(x + d) - f(x - d)) / (2 * h))
    return np.stack(cols, axis=-1)


def test_residual_vanishes_at_the_true_centres(pair):
    d = _data(pair)
    x = np.r_[pair.center_parent, pair.center_child]
    # residual of the exact signals is at finite-difference level (< 1 mm/s²) …
    assert np.abs(spherical_residual(x, d)).max() < 1e-3
    # … and large elsewhere: the library sign convention (c = −V) matters
    assert np.abs(spherical_residual(-x, d)).max() > 1.0
    assert np.abs(spherical_residual_3d(x, d, pair.R_parent_child)).max() < 1e-3


def test_joint_acceleration_is_kinematic_matrix_form(pair):
    c = np.array([0.1, -0.2, 0.05])
    K = kinematic_matrix(pair.gyr_parent, pair.angacc_parent)
    g = joint_acceleration(pair.acc_parent, pair.gyr_parent, pair.angacc_parent, c)
    assert np.allclose(g, pair.acc_parent + K @ c)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_jacobian_matches_finite_differences(pair, seed):
    d = _data(pair)
    x = np.random.default_rng(seed).uniform(-0.3, 0.3, 6)
    J = spherical_jacobian(x, d)
    assert J.shape == (d.n_samples, 6)
    assert np.allclose(J, _fd(lambda v: spherical_residual(v, d), x), atol=1e-6, rtol=1e-6)


def test_jacobian_3d_matches_finite_differences(pair):
    d = _data(pair)
    x = np.random.default_rng(3).uniform(-0.3, 0.3, 6)
    J = spherical_jacobian_3d(x, d, pair.R_parent_child)
    fd = _fd(lambda v: spherical_residual_3d(v, d, pair.R_parent_child), x)
    assert np.allclose(J, fd, atol=1e-6)


def test_population_matches_single_evaluations(pair):
    d = _data(pair)
    X = np.random.default_rng(4).uniform(-0.3, 0.3, (7, 6))
    R = spherical_residual_population(X, d)
    assert R.shape == (7, d.n_samples)
    assert np.allclose(R, [spherical_residual(x, d) for x in X], atol=1e-9)


def test_casadi_mapped_residual_matches_numpy(pair):
    d = _data(pair).subsample(10)
    x = np.random.default_rng(5).uniform(-0.3, 0.3, 6)
    F = spherical_casadi(d.n_samples)
    r = np.asarray(F(x, d.data_matrix())).ravel()
    assert np.allclose(r, spherical_residual(x, d), atol=1e-12)
    X = ca.MX.sym("x", 6)
    JF = ca.Function("J", [X], [ca.jacobian(F(X, d.data_matrix()), X)])
    assert np.allclose(np.asarray(JF(x)), spherical_jacobian(x, d), atol=1e-9)


def test_casadi_per_sample_function(pair):
    d = _data(pair).subsample(25)
    x = np.random.default_rng(6).uniform(-0.3, 0.3, 6)
    f = spherical_sample_function()
    assert f is spherical_sample_function()  # cached: solvers reuse what they build
    P = d.data_matrix()
    r = [float(f(x, P[:, k])) for k in range(P.shape[1])]
    assert np.allclose(r, spherical_residual(x, d), atol=1e-12)


def test_axis_gauge_function_matches_rotated_numpy(pair):
    d = _data(pair).subsample(25)
    Qp = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    Qc = Rotation.from_rotvec([-0.4, 0.1, 0.2]).as_matrix()
    rd = d.rotated(Qp, Qc)
    y = np.random.default_rng(7).uniform(-0.2, 0.2, 5)
    g = spherical_axis_gauge_sample_function().map(rd.n_samples)
    r = np.asarray(g(y, rd.data_matrix())).ravel()
    x = AXIS_GAUGE_MAP @ y
    assert np.allclose(r, spherical_residual(x, rd), atol=1e-12)
    # rotating the data and the centres together leaves the residual unchanged
    x_sensor = np.r_[Qp @ x[:3], Qc @ x[3:]]
    assert np.allclose(spherical_residual(x_sensor, d), r, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(
    st.lists(st.floats(-3, 3), min_size=3, max_size=3),
    st.lists(st.floats(-0.3, 0.3), min_size=6, max_size=6),
)
def test_residual_is_invariant_to_the_sensor_frame(rotvec, x):
    """A law: expressing one sensor's data and centre in another frame changes nothing."""
    p = rigid_pair("spherical", seed=3, duration_s=2.0)
    d = _data(p)
    Q = Rotation.from_rotvec(rotvec).as_matrix()
    xv = np.asarray(x)
    r0 = spherical_residual(xv, d)
    r1 = spherical_residual(np.r_[Q.T @ xv[:3], xv[3:]], d.rotated(Q, np.eye(3)))
    assert np.allclose(r0, r1, atol=1e-9)


def test_shape_errors(pair):
    d = _data(pair)
    with pytest.raises(ShapeError, match="6 numbers"):
        spherical_residual(np.zeros(5), d)
    with pytest.raises(ShapeError, match=r"\(P, 6\)"):
        spherical_residual_population(np.zeros(6), d)
    with pytest.raises(ShapeError, match="samples"):
        SphericalData(
            pair.acc_parent,
            pair.gyr_parent[:-1],
            pair.angacc_parent,
            pair.acc_child,
            pair.gyr_child,
            pair.angacc_child,
        )
    with pytest.raises(ShapeError, match=r"R_parent_child"):
        spherical_residual_3d(np.zeros(6), d, np.eye(3))
