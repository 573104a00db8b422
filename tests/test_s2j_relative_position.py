"""Eq. 2–3 of Lee & Lee 2022 against a directly composed rigid chain."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lowerlimb.conventions import quat_normalize, quat_to_matrix
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.s2j import (
    chain_position,
    reference_relative_position,
    reference_segment_relative_positions,
    relative_position,
    relative_rotation,
    segment_relative_positions,
)

SENSORS = ("pelvis", "thigh", "shank", "foot")


def _random_chain(rng: np.random.Generator, n: int) -> tuple[dict, dict, dict]:
    """Sensor poses and joint centres of a leg whose joints are exact spherical joints."""
    quat = {s: quat_normalize(rng.normal(size=(n, 4))) for s in SENSORS}
    rot = {s: quat_to_matrix(quat[s]) for s in SENSORS}
    # constant S2J vectors, metres
    s2j = {
        "hip": (rng.uniform(-0.2, 0.2, 3), rng.uniform(-0.25, 0.25, 3)),
        "knee": (rng.uniform(-0.3, 0.3, 3), rng.uniform(-0.25, 0.25, 3)),
        "ankle": (rng.uniform(-0.25, 0.25, 3), rng.uniform(-0.1, 0.1, 3)),
    }
    pos = {"pelvis": rng.normal(size=(n, 3))}
    for joint, (prox, dist) in zip(
        s2j, [("pelvis", "thigh"), ("thigh", "shank"), ("shank", "foot")], strict=True
    ):
        centre = pos[prox] + rot[prox] @ s2j[joint][0]
        pos[dist] = centre - rot[dist] @ s2j[joint][1]
    return quat, pos, s2j


def test_segment_positions_match_rigid_chain() -> None:
    rng = np.random.default_rng(0)
    quat, pos, s2j = _random_chain(rng, 200)
    est = segment_relative_positions(s2j, quat)
    ref = reference_segment_relative_positions(pos, quat)
    assert set(est) == {"pelvis_thigh", "thigh_shank", "shank_foot", "pelvis_foot"}
    for name in est:
        np.testing.assert_allclose(est[name], ref[name], atol=1e-12)
    # pelvis_foot is the foot origin in the pelvis sensor frame
    Rp = quat_to_matrix(quat["pelvis"])
    direct = np.einsum("nji,nj->ni", Rp, pos["foot"] - pos["pelvis"])
    np.testing.assert_allclose(est["pelvis_foot"], direct, atol=1e-12)


def test_time_varying_vectors_per_sample() -> None:
    rng = np.random.default_rng(1)
    n = 50
    quat = {s: quat_normalize(rng.normal(size=(n, 4))) for s in ("a", "b")}
    sp = rng.normal(size=(n, 3)) * 0.1
    sd = rng.normal(size=(n, 3)) * 0.1
    R = relative_rotation(quat["a"], quat["b"])
    p = relative_position(sp, sd, R)
    for k in range(n):
        np.testing.assert_allclose(p[k], sp[k] - R[k] @ sd[k], atol=1e-15)


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(-1, 1), min_size=4, max_size=4),
    st.lists(st.floats(-1, 1), min_size=4, max_size=4),
    st.lists(st.floats(-1, 1), min_size=9, max_size=9),
)
def test_chain_equals_homogeneous_composition(q1: list[float], q2: list[float], v: list[float]) -> None:
    qa = np.asarray(q1) + np.array([1.5, 0, 0, 0])
    qb = np.asarray(q2) + np.array([1.5, 0, 0, 0])
    R_PT = quat_to_matrix(qa)
    R_TS = quat_to_matrix(qb)
    a, b, c = np.asarray(v).reshape(3, 3)

    def T(R: np.ndarray, p: np.ndarray) -> np.ndarray:
        out = np.eye(4)
        out[:3, :3] = R
        out[:3, 3] = p
        return out

    composed = T(R_PT, a) @ T(R_TS, b) @ T(np.eye(3), c)
    np.testing.assert_allclose(chain_position(a, b, c, R_PT, R_TS), composed[:3, 3], atol=1e-12)


def test_relative_rotation_maps_distal_to_proximal() -> None:
    rng = np.random.default_rng(2)
    qp, qd = quat_normalize(rng.normal(size=(2, 5, 4)))
    R = relative_rotation(qp, qd)
    v_dist = rng.normal(size=(5, 3))
    v_earth = np.einsum("nij,nj->ni", quat_to_matrix(qd), v_dist)
    v_prox = np.einsum("nji,nj->ni", quat_to_matrix(qp), v_earth)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", R, v_dist), v_prox, atol=1e-12)


def test_bad_shapes_name_the_fix() -> None:
    R = np.tile(np.eye(3), (4, 1, 1))
    with pytest.raises(ShapeError, match=r"shape \(3,\) or \(N, 3\)"):
        relative_position(np.zeros(4), np.zeros(3), R)
    with pytest.raises(ShapeError, match="differ in length"):
        relative_position(np.zeros((5, 3)), np.zeros(3), R)
    with pytest.raises(ShapeError, match="relative_rotation"):
        relative_position(np.zeros(3), np.zeros(3), np.zeros((4, 4)))
    with pytest.raises(InputError, match="NaN"):
        relative_position(np.full(3, np.nan), np.zeros(3), np.eye(3))
    with pytest.raises(ShapeError, match="w, x, y, z"):
        relative_rotation(np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ShapeError, match="same N samples"):
        reference_relative_position(np.zeros((3, 3)), np.tile([1.0, 0, 0, 0], (3, 1)), np.zeros((2, 3)))


def test_missing_sensor_or_joint() -> None:
    rng = np.random.default_rng(3)
    quat, pos, s2j = _random_chain(rng, 5)
    del quat["shank"]
    with pytest.raises(InputError, match="sensor 'shank' is missing"):
        segment_relative_positions(s2j, quat)
    quat, pos, s2j = _random_chain(rng, 5)
    del s2j["knee"]
    with pytest.raises(InputError, match="joint 'knee' are missing"):
        segment_relative_positions(s2j, quat)
    del pos["foot"]
    with pytest.raises(InputError, match="'foot' is missing"):
        reference_segment_relative_positions(pos, quat)
