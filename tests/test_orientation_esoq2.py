import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lowerlimb.conventions import quat_conjugate, quat_normalize, quat_rotate
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.orientation import davenport_q_method, esoq2, quest
from lowerlimb.orientation.esoq2 import attitude_profile, lambda_max


def _same(p, q):
    """Distance between two unit quaternions up to sign."""
    return min(np.abs(p - q).max(), np.abs(p + q).max())


def _random_problem(rng, n, noise, kind="random"):
    q = quat_normalize(rng.normal(size=4))
    if kind == "near180":
        q = quat_normalize(np.array([1e-9 * rng.normal(), *rng.normal(size=3)]))
    elif kind == "near0":
        q = quat_normalize(np.array([1.0, *(1e-7 * rng.normal(size=3))]))
    r = rng.normal(size=(n, 3))
    r /= np.linalg.norm(r, axis=1)[:, None]
    b = quat_rotate(quat_conjugate(q), r) + noise * rng.normal(size=(n, 3))
    w = rng.uniform(0.1, 1.0, n)
    return q, b, r, w


@pytest.mark.parametrize("kind", ["random", "near180", "near0"])
@pytest.mark.parametrize("noise", [0.0, 0.1])
def test_esoq2_and_quest_equal_q_method(kind, noise):
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(2, 7))
        _, b, r, w = _random_problem(rng, n, noise, kind)
        q_ref = davenport_q_method(b, r, w)
        assert _same(esoq2(b, r, w), q_ref) < 1e-6
        assert _same(quest(b, r, w), q_ref) < 1e-6


def test_noise_free_pairs_recover_the_rotation():
    rng = np.random.default_rng(3)
    for _ in range(100):
        q, b, r, w = _random_problem(rng, 2, 0.0)
        for method in (esoq2, quest, davenport_q_method):
            assert _same(method(b, r, w), q) < 1e-9
            # sensor -> earth: R(q) maps the measured b onto the reference r
            np.testing.assert_allclose(quat_rotate(method(b, r, w), b), r, atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=4, max_size=4),
    st.lists(st.floats(-1, 1), min_size=12, max_size=12),
    st.lists(st.floats(0.05, 1), min_size=4, max_size=4),
)
def test_esoq2_property(qv, rv, wv):
    q = np.array(qv)
    r = np.array(rv).reshape(4, 3)
    if np.linalg.norm(q) < 1e-3 or np.any(np.linalg.norm(r, axis=1) < 1e-3):
        return
    r = r / np.linalg.norm(r, axis=1)[:, None]
    # the attitude must be observable: at least two clearly non-parallel vectors
    if np.linalg.svd(r, compute_uv=False)[1] < 1e-3:
        return
    b = quat_rotate(quat_conjugate(quat_normalize(q)), r)
    assert _same(esoq2(b, r, wv), davenport_q_method(b, r, wv)) < 1e-6


def test_lambda_max_closed_form_two_pairs_and_newton():
    rng = np.random.default_rng(11)
    for n in (2, 3, 5):
        for _ in range(50):
            _, b, r, w = _random_problem(rng, n, 0.2)
            b = b / np.linalg.norm(b, axis=1)[:, None]
            B, _ = attitude_profile(b, r, w, False)
            sigma = np.trace(B)
            S = B + B.T
            z = np.array([B[1, 2] - B[2, 1], B[2, 0] - B[0, 2], B[0, 1] - B[1, 0]])
            K = np.block([[S - sigma * np.eye(3), z[:, None]], [z[None, :], np.array([[sigma]])]])
            assert lambda_max(B, n, w.sum()) == pytest.approx(np.linalg.eigvalsh(K)[-1], abs=1e-10)


def test_bad_pairs_raise():
    with pytest.raises(ShapeError, match=r"\(n, 3\)"):
        esoq2(np.zeros((2, 2)), np.zeros((2, 2)))
    with pytest.raises(ShapeError, match="at least 2"):
        esoq2(np.ones((1, 3)), np.ones((1, 3)))
    with pytest.raises(InputError, match="non-zero"):
        esoq2(np.array([[0.0, 0, 0], [0, 1, 0]]), np.eye(3)[:2])
    with pytest.raises(InputError, match="weights"):
        esoq2(np.eye(3)[:2], np.eye(3)[:2], [-1.0, 1.0])
