"""S2JModel (M1–M3): fit on a synthetic leg with known angle-dependent S2J vectors, predict, JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lowerlimb.conventions import (
    JOINTS,
    matrix_from_joint_angles,
    quat_from_matrix,
    quat_make_continuous,
    rot_x,
    rot_y,
    rot_z,
)
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.s2j import (
    REGRESSION_INPUTS,
    S2JModel,
    constant_s2j_from_calibration,
    reference_segment_relative_positions,
)

RATE_HZ = 100.0
SIDE = "left"
SENSORS = ("pelvis", "thigh", "shank", "foot")
PAIRS = {"hip": ("pelvis", "thigh"), "knee": ("thigh", "shank"), "ankle": ("shank", "foot")}
CONSTANT = {
    "hip": (np.array([-0.168, -0.097, -0.102]), np.array([0.192, -0.006, -0.102])),
    "knee": (np.array([-0.242, 0.008, -0.059]), np.array([0.231, -0.049, -0.093])),
    "ankle": (np.array([-0.182, -0.003, -0.040]), np.array([0.051, 0.015, -0.044])),
}
COL = {"hip_flexion": 0, "hip_adduction": 1, "knee_flexion": 3, "ankle_dorsiflexion": 6}
# true deformation: d s / d angle (m/rad) per joint, side (prox, dist) and M3 input
_GAIN = np.random.default_rng(42).normal(scale=0.012, size=(3, 2, 2, 3))


def true_s2j(angles: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """S2J vectors that deform smoothly (partly quadratically) with the M3 input angles."""
    out = {}
    for j, joint in enumerate(JOINTS):
        x = angles[:, [COL[n] for n in REGRESSION_INPUTS["M3"][joint]]]
        feats = np.stack([x[:, 0] + 0.3 * x[:, 0] ** 2, x[:, 1]], axis=1)
        out[joint] = tuple(CONSTANT[joint][k] + feats @ _GAIN[j, k] for k in range(2))
    return out  # type: ignore[return-value]


def synthetic_trial(seed: int, duration_s: float = 40.0) -> dict[str, object]:
    """Squat-like angles, sensor orientations and positions of a leg with STA.

    The same subject and exercise every trial (amplitudes, sensor mounting and
    deformation fixed); timing and the modulation of each joint vary by seed.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration_s, 1.0 / RATE_HZ)
    c = 0.5 - 0.5 * np.cos(2 * np.pi * t / rng.uniform(2.5, 3.5))
    a = np.zeros((t.size, 9))
    for k, amp_deg in ((0, 90.0), (3, 105.0), (6, 20.0)):
        mod = 1.0 + 0.2 * np.sin(2 * np.pi * rng.uniform(0.05, 0.2) * t + rng.uniform(0, 6.3))
        a[:, k] = np.deg2rad(amp_deg) * c * mod
    for k, amp in ((1, 8.0), (2, 10.0), (4, 2.0), (5, 3.0), (7, 8.0), (8, 6.0)):
        f = rng.uniform(0.15, 0.7)
        a[:, k] = np.deg2rad(amp) * np.sin(2 * np.pi * f * t + rng.uniform(0, 6.3))
    R_seg = {"pelvis": rot_z(0.3 * np.sin(0.2 * t)) @ rot_x(0.1 * np.sin(0.5 * t))}
    for joint, (prox, dist) in PAIRS.items():
        j = JOINTS.index(joint)
        R_seg[dist] = R_seg[prox] @ matrix_from_joint_angles(a[:, 3 * j : 3 * j + 3], joint, SIDE)
    mount_rng = np.random.default_rng(7)  # the same subject and sensor attachment every trial
    mount = {s: rot_z(mount_rng.uniform(-3, 3)) @ rot_y(mount_rng.uniform(-3, 3)) for s in SENSORS}
    R_sensor = {s: R_seg[s] @ mount[s] for s in SENSORS}
    s2j = true_s2j(a)
    pos = {"pelvis": np.stack([0.1 * np.sin(0.3 * t), 0 * t, 0.9 + 0 * t], axis=1)}
    for joint, (prox, dist) in PAIRS.items():
        centre = pos[prox] + np.einsum("nij,nj->ni", R_sensor[prox], s2j[joint][0])
        pos[dist] = centre - np.einsum("nij,nj->ni", R_sensor[dist], s2j[joint][1])
    quat = {s: quat_make_continuous(quat_from_matrix(R_sensor[s])) for s in SENSORS}
    return {"angles": a, "quat": quat, "pos": pos, "s2j": s2j}


@pytest.fixture(scope="module")
def trials() -> tuple[dict[str, object], dict[str, object]]:
    return synthetic_trial(0), synthetic_trial(1)


@pytest.fixture(scope="module")
def models(trials: tuple[dict, dict]) -> dict[str, S2JModel]:
    train, _ = trials
    return {
        m: S2JModel.fit(
            m,
            CONSTANT,
            train["angles"],
            quat_wxyz=train["quat"],
            sensor_pos_m=train["pos"],
            rate_hz=RATE_HZ,
        )
        for m in ("M1", "M2", "M3")
    }


def _rmse_mm(a: np.ndarray, b: np.ndarray) -> float:
    return 1e3 * float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


def test_m3_recovers_relative_positions_on_a_new_trial(
    trials: tuple[dict, dict], models: dict[str, S2JModel]
) -> None:
    _, test = trials
    ref = reference_segment_relative_positions(test["pos"], test["quat"])
    err = {}
    for m, model in models.items():
        est = model.relative_positions(test["angles"], test["quat"])
        err[m] = {k: _rmse_mm(est[k], ref[k]) for k in ref}
    # M1 sees the whole deformation (cm); M3 regresses on exactly the right angles
    assert err["M1"]["pelvis_foot"] > 15.0
    assert err["M3"]["pelvis_foot"] < 0.2 * err["M1"]["pelvis_foot"]
    assert err["M3"]["pelvis_foot"] < 3.0
    assert err["M2"]["pelvis_foot"] < 0.5 * err["M1"]["pelvis_foot"]
    for k in ("pelvis_thigh", "thigh_shank", "shank_foot"):
        assert err["M3"][k] < 2.0


def test_predict_shapes_and_m1_constants(trials: tuple[dict, dict], models: dict[str, S2JModel]) -> None:
    _, test = trials
    n = test["angles"].shape[0]
    for model in models.values():
        out = model.predict(test["angles"])
        assert set(out) == set(JOINTS)
        for sp, sd in out.values():
            assert sp.shape == sd.shape == (n, 3)
    m1 = models["M1"].predict(test["angles"][:3])
    np.testing.assert_array_equal(m1["knee"][1], np.tile(CONSTANT["knee"][1], (3, 1)))
    assert models["M3"].inputs["knee"] == ("knee_flexion", "hip_flexion")
    assert models["M2"].inputs["ankle"] == ("ankle_dorsiflexion",)
    assert models["M3"].metadata["kf_constraint_rms_m"]["hip"] < 1e-4


def test_json_round_trip(trials: tuple[dict, dict], models: dict[str, S2JModel]) -> None:
    _, test = trials
    for model in models.values():
        text = json.dumps(model.to_dict())
        assert len(text) < 150_000
        back = S2JModel.from_dict(json.loads(text))
        assert back.method == model.method
        a, b = model.predict(test["angles"]), back.predict(test["angles"])
        for joint in JOINTS:
            np.testing.assert_allclose(a[joint][0], b[joint][0], atol=1e-6)
            np.testing.assert_allclose(a[joint][1], b[joint][1], atol=1e-6)


def test_constant_from_calibration() -> None:
    joints: dict[str, dict[str, list[float]]] = {
        j: {"center_in_parent_sensor": list(p), "center_in_child_sensor": list(d)}
        for j, (p, d) in CONSTANT.items()
    }
    calib = {"format": "lowerlimb-calibration/1", "joints": joints}
    const = constant_s2j_from_calibration(calib)
    np.testing.assert_array_equal(const["ankle"][0], CONSTANT["ankle"][0])
    del joints["knee"]["center_in_child_sensor"]
    with pytest.raises(InputError, match="re-run `lowerlimb calibrate`"):
        constant_s2j_from_calibration(calib)
    with pytest.raises(InputError, match="no 'joints'"):
        constant_s2j_from_calibration({})


def test_bad_input_raises(trials: tuple[dict, dict], models: dict[str, S2JModel]) -> None:
    train, _ = trials
    angles = train["angles"]
    with pytest.raises(InputError, match=r"unknown S2J method 'M5'.*'M1', 'M2', 'M3'"):
        S2JModel.fit("M5", CONSTANT, angles)
    with pytest.raises(InputError, match=r"look like degrees.*π/180"):
        models["M3"].predict(np.rad2deg(angles))
    with pytest.raises(ShapeError, match=r"\(N, 9\)"):
        models["M3"].predict(angles[:, :6])
    with pytest.raises(InputError, match="pass quat_wxyz, sensor_pos_m and rate_hz"):
        S2JModel.fit("M2", CONSTANT, angles)
    with pytest.raises(InputError, match="joint 'ankle' are missing"):
        S2JModel.fit("M1", {k: v for k, v in CONSTANT.items() if k != "ankle"}, angles)
    with pytest.raises(ShapeError, match=r"shape \(3,\)"):
        S2JModel.fit("M1", {**CONSTANT, "hip": (np.zeros(2), np.zeros(3))}, angles)
    with pytest.raises(InputError, match="S2JModel.to_dict"):
        S2JModel.from_dict({"format": "lowerlimb-calibration/1"})
    with pytest.raises(InputError, match="S2JModel.fit"):
        S2JModel(method="M2", constant=CONSTANT)
    with pytest.raises(ShapeError, match="same samples"):
        S2JModel.fit(
            "M2",
            CONSTANT,
            angles[:-5],
            quat_wxyz=train["quat"],
            sensor_pos_m=train["pos"],
            rate_hz=RATE_HZ,
        )
