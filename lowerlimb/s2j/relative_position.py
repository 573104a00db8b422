"""Relative positions of the leg sensors from orientations and S2J vectors (Lee & Lee 2022).

Frames and names follow the paper with segment frame = sensor frame:

- ``s_prox`` (the paper's ``p_s_pJ``): vector from the proximal sensor's origin to
  joint J, in the proximal sensor frame, m — the library's
  ``center_in_parent_sensor``.
- ``s_dist`` (``d_s_dJ``): vector from the distal sensor's origin to joint J, in
  the distal sensor frame, m — ``center_in_child_sensor``.
- ``R_pd``: rotation matrix mapping distal-sensor coordinates to
  proximal-sensor coordinates, ``R_pd = R(q_p)^T R(q_d)`` for sensor
  orientations ``q`` (sensor -> earth).
- ``p_pd``: position of the distal sensor's origin relative to the proximal
  sensor's origin, in the proximal sensor frame, m.

This NumPy module is the reference implementation the Pinocchio forward
kinematics are tested against.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
from numpy.typing import ArrayLike

from lowerlimb.conventions import JOINT_SENSORS, JOINTS, FloatArray, quat_to_matrix
from lowerlimb.errors import InputError, ShapeError

#: Keys of :func:`segment_relative_positions`: (name, proximal sensor, distal sensor).
RELATIVE_POSITIONS: tuple[tuple[str, str, str], ...] = (
    ("pelvis_thigh", "pelvis", "thigh"),
    ("thigh_shank", "thigh", "shank"),
    ("shank_foot", "shank", "foot"),
    ("pelvis_foot", "pelvis", "foot"),
)


def _finite_array(
    name: str, value: ArrayLike, shape_ok: Callable[[FloatArray], bool], message: str
) -> FloatArray:
    """``value`` as a finite float array whose shape passes ``shape_ok``.

    Raises:
        ShapeError: ``message`` (with ``{name}`` and ``{shape}`` filled in) when the shape fails.
        InputError: a NaN or infinite value.
    """
    a = np.asarray(value, dtype=float)
    if not shape_ok(a):
        raise ShapeError(message.format(name=name, shape=a.shape))
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name} contains NaN or infinite values; fill or cut the gaps first")
    return a


def _vectors(name: str, value: ArrayLike) -> FloatArray:
    """Return ``value`` as a float array of shape (3,) or (N, 3), or raise ShapeError."""
    return _finite_array(
        name,
        value,
        lambda a: a.ndim in (1, 2) and a.shape[-1] == 3,
        "{name} must have shape (3,) or (N, 3) (x, y, z in metres), got {shape}; stack the samples as rows",
    )


def _rotations(name: str, value: ArrayLike) -> FloatArray:
    """Return ``value`` as a float array of shape (3, 3) or (N, 3, 3), or raise ShapeError."""
    return _finite_array(
        name,
        value,
        lambda a: a.ndim in (2, 3) and a.shape[-2:] == (3, 3),
        "{name} must be rotation matrices of shape (3, 3) or (N, 3, 3), got {shape}; "
        "convert quaternions with relative_rotation()",
    )


def _quaternions(name: str, value: ArrayLike) -> FloatArray:
    """Return ``value`` as a float array of shape (N, 4), or raise ShapeError."""
    return _finite_array(
        name,
        value,
        lambda a: a.ndim == 2 and a.shape[1] == 4,
        "{name} must be quaternions of shape (N, 4) in w, x, y, z order, got {shape}",
    )


def _check_lengths(
    vectors: Mapping[str, FloatArray], rotations: Mapping[str, FloatArray] | None = None
) -> None:
    """Raise ShapeError when the per-sample (batched) arguments differ in length."""
    lengths = {k: v.shape[0] for k, v in vectors.items() if v.ndim == 2}
    lengths |= {k: v.shape[0] for k, v in (rotations or {}).items() if v.ndim == 3}
    if len(set(lengths.values())) > 1:
        raise ShapeError(f"per-sample arrays differ in length: {lengths}; pass the same samples to each")


def relative_rotation(quat_prox_wxyz: ArrayLike, quat_dist_wxyz: ArrayLike) -> FloatArray:
    """Relative orientation ``R_pd = R(q_p)^T R(q_d)`` (Lee & Lee 2022, §2.1).

    Args:
        quat_prox_wxyz: (N, 4) orientation of the proximal sensor, w, x, y, z,
            sensor -> earth.
        quat_dist_wxyz: (N, 4) orientation of the distal sensor, same convention.

    Returns:
        (N, 3, 3) rotation matrices mapping distal-sensor coordinates to
        proximal-sensor coordinates.

    Raises:
        ShapeError: when the inputs are not (N, 4) arrays of equal length.
        InputError: on NaN or infinite values.
    """
    qp = _quaternions("quat_prox_wxyz", quat_prox_wxyz)
    qd = _quaternions("quat_dist_wxyz", quat_dist_wxyz)
    if qp.shape != qd.shape:
        raise ShapeError(
            f"quat_prox_wxyz {qp.shape} and quat_dist_wxyz {qd.shape} differ in length; "
            f"pass the same samples for both sensors"
        )
    return np.swapaxes(quat_to_matrix(qp), -1, -2) @ quat_to_matrix(qd)


def relative_position(s_prox: ArrayLike, s_dist: ArrayLike, R_pd: ArrayLike) -> FloatArray:
    """Distal sensor position relative to the proximal one, eq. 2: ``p_pd = s_pJ − R_pd s_dJ``.

    Args:
        s_prox: (3,) or (N, 3) vector from the proximal sensor to joint J, in
            the proximal sensor frame, m.
        s_dist: (3,) or (N, 3) vector from the distal sensor to joint J, in the
            distal sensor frame, m.
        R_pd: (3, 3) or (N, 3, 3) rotation mapping distal-sensor coordinates to
            proximal-sensor coordinates.

    Returns:
        (N, 3) (or (3,) when every input is a single sample) position of the
        distal sensor's origin relative to the proximal sensor's origin, in the
        proximal sensor frame, m.

    Raises:
        ShapeError: on wrong shapes or mismatched numbers of samples.
        InputError: on NaN or infinite values.
    """
    sp = _vectors("s_prox", s_prox)
    sd = _vectors("s_dist", s_dist)
    R = _rotations("R_pd", R_pd)
    _check_lengths({"s_prox": sp, "s_dist": sd}, {"R_pd": R})
    return sp - np.einsum("...ij,...j->...i", R, sd)


def chain_position(
    p_PT: ArrayLike, p_TS: ArrayLike, p_SF: ArrayLike, R_PT: ArrayLike, R_TS: ArrayLike
) -> FloatArray:
    """Pelvis-to-foot position, eq. 3: ``p_PF = p_PT + R_PT p_TS + R_PT R_TS p_SF``.

    (The print of eq. 3 is garbled; this is the composition of rigid
    transforms, see docs/methods.md.)

    Args:
        p_PT: (3,) or (N, 3) thigh sensor relative to the pelvis sensor, pelvis frame, m.
        p_TS: (3,) or (N, 3) shank sensor relative to the thigh sensor, thigh frame, m.
        p_SF: (3,) or (N, 3) foot sensor relative to the shank sensor, shank frame, m.
        R_PT: (3, 3) or (N, 3, 3) maps thigh-sensor to pelvis-sensor coordinates.
        R_TS: (3, 3) or (N, 3, 3) maps shank-sensor to thigh-sensor coordinates.

    Returns:
        (N, 3) (or (3,)) foot sensor origin relative to the pelvis sensor
        origin, in the pelvis sensor frame, m.

    Raises:
        ShapeError: on wrong shapes or mismatched numbers of samples.
        InputError: on NaN or infinite values.
    """
    a = _vectors("p_PT", p_PT)
    b = _vectors("p_TS", p_TS)
    c = _vectors("p_SF", p_SF)
    R1 = _rotations("R_PT", R_PT)
    R2 = _rotations("R_TS", R_TS)
    _check_lengths({"p_PT": a, "p_TS": b, "p_SF": c}, {"R_PT": R1, "R_TS": R2})
    b_in_p = np.einsum("...ij,...j->...i", R1, b)
    c_in_p = np.einsum("...ij,...j->...i", R1 @ R2, c)
    return a + b_in_p + c_in_p


def reference_relative_position(
    pos_prox_m: ArrayLike, quat_prox_wxyz: ArrayLike, pos_dist_m: ArrayLike
) -> FloatArray:
    """Reference relative position from measured poses: ``p_pd = R(q_p)^T (x_d − x_p)``.

    This is the optical-capture (or simulated) ``p_pd,ref`` of eq. 5.

    Args:
        pos_prox_m: (N, 3) proximal sensor origin in the earth frame, m.
        quat_prox_wxyz: (N, 4) proximal sensor orientation, w, x, y, z, sensor -> earth.
        pos_dist_m: (N, 3) distal sensor origin in the earth frame, m.

    Returns:
        (N, 3) distal sensor origin relative to the proximal one, in the
        proximal sensor frame, m.

    Raises:
        ShapeError: on wrong shapes or mismatched numbers of samples.
        InputError: on NaN or infinite values.
    """
    xp = _vectors("pos_prox_m", pos_prox_m)
    xd = _vectors("pos_dist_m", pos_dist_m)
    q = _quaternions("quat_prox_wxyz", quat_prox_wxyz)
    if not (xp.shape == xd.shape == (q.shape[0], 3)):
        raise ShapeError(
            f"pos_prox_m {xp.shape}, quat_prox_wxyz {q.shape} and pos_dist_m {xd.shape} "
            f"must hold the same N samples as (N, 3), (N, 4), (N, 3)"
        )
    return np.einsum("nji,nj->ni", quat_to_matrix(q), xd - xp)


def _joint_pair(s2j: Mapping[str, tuple[ArrayLike, ArrayLike]], joint: str) -> tuple[FloatArray, FloatArray]:
    """The (s_prox, s_dist) pair of ``joint`` from an S2J mapping, checked."""
    if joint not in s2j:
        raise InputError(
            f"S2J vectors for joint '{joint}' are missing (got {sorted(s2j)}); "
            f"pass a mapping with keys {list(JOINTS)}"
        )
    pair = s2j[joint]
    if len(pair) != 2:
        raise ShapeError(f"s2j['{joint}'] must be a pair (s_prox, s_dist), got {len(pair)} items")
    return _vectors(f"s2j['{joint}'][0]", pair[0]), _vectors(f"s2j['{joint}'][1]", pair[1])


def segment_relative_positions(
    s2j: Mapping[str, tuple[ArrayLike, ArrayLike]], quat_wxyz: Mapping[str, ArrayLike]
) -> dict[str, FloatArray]:
    """Adjacent and pelvis-to-foot relative positions of the leg sensors (eq. 2 and 3).

    Args:
        s2j: per joint (``"hip"``, ``"knee"``, ``"ankle"``) a pair
            ``(s_prox, s_dist)`` of (3,) or (N, 3) S2J vectors, m, in the parent
            and child sensor frames (:data:`lowerlimb.conventions.JOINT_SENSORS`).
        quat_wxyz: per sensor (``"pelvis"``, ``"thigh"``, ``"shank"``,
            ``"foot"``) the (N, 4) orientation, w, x, y, z, sensor -> earth.

    Returns:
        ``{"pelvis_thigh", "thigh_shank", "shank_foot", "pelvis_foot"}`` ->
        (N, 3) position of the distal sensor relative to the proximal one, m,
        in the proximal sensor frame (``pelvis_foot``: in the pelvis frame).

    Raises:
        InputError: when a joint or sensor is missing, or on NaN values.
        ShapeError: on wrong shapes or mismatched numbers of samples.
    """
    rot: dict[str, FloatArray] = {}
    rel: dict[str, FloatArray] = {}
    for joint in JOINTS:
        parent, child, _ = JOINT_SENSORS[joint]
        for sensor in (parent, child):
            if sensor not in quat_wxyz:
                raise InputError(
                    f"orientation of sensor '{sensor}' is missing (got {sorted(quat_wxyz)}); "
                    f"pass quaternions for pelvis, thigh, shank and foot"
                )
        R = relative_rotation(quat_wxyz[parent], quat_wxyz[child])
        sp, sd = _joint_pair(s2j, joint)
        rot[joint] = R
        rel[joint] = relative_position(sp, sd, R)
    out = {
        "pelvis_thigh": rel["hip"],
        "thigh_shank": rel["knee"],
        "shank_foot": rel["ankle"],
    }
    out["pelvis_foot"] = chain_position(rel["hip"], rel["knee"], rel["ankle"], rot["hip"], rot["knee"])
    return out


def reference_segment_relative_positions(
    sensor_pos_m: Mapping[str, ArrayLike], quat_wxyz: Mapping[str, ArrayLike]
) -> dict[str, FloatArray]:
    """Measured relative positions, with the keys and frames of :func:`segment_relative_positions`.

    Args:
        sensor_pos_m: per sensor the (N, 3) origin in the earth frame, m.
        quat_wxyz: per sensor the (N, 4) orientation, w, x, y, z, sensor -> earth.

    Returns:
        Name -> (N, 3) relative position in the proximal sensor frame, m.

    Raises:
        InputError: when a sensor is missing, or on NaN values.
        ShapeError: on wrong shapes or mismatched numbers of samples.
    """
    out: dict[str, FloatArray] = {}
    for name, prox, dist in RELATIVE_POSITIONS:
        for sensor in (prox, dist):
            if sensor not in sensor_pos_m or sensor not in quat_wxyz:
                raise InputError(
                    f"pose of sensor '{sensor}' is missing; pass positions and quaternions "
                    f"for pelvis, thigh, shank and foot"
                )
        out[name] = reference_relative_position(sensor_pos_m[prox], quat_wxyz[prox], sensor_pos_m[dist])
    return out
