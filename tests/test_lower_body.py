"""The lower-body URDF: both legs on a z-up base; Pinocchio, yourdfpy, MuJoCo and urdfdom agree."""

from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from scipy.spatial.transform import Rotation

from lowerlimb.model.anthropometry import hip_spacing_m
from lowerlimb.model.geometry import JOINT_LIMITS_RAD, LegGeometry
from lowerlimb.model.joint_limits import EFFORT_NM_PER_KG
from lowerlimb.model.leg_model import DOF_NAMES, LegModel
from lowerlimb.model.lower_body import (
    BASE_LINK,
    IMU_LINKS,
    LOWER_BODY_DOF_NAMES,
    LowerBodyGeometry,
    lower_body_urdf,
)
from lowerlimb.model.trunk import trunk_inertia
from lowerlimb.simulation.placements import random_placements

G = 9.81
SEGMENTS = [f"{side}_{s}" for side in ("left", "right") for s in ("thigh", "shank", "foot")]
FRAMES = ["pelvis", "trunk", *SEGMENTS, *IMU_LINKS.values()]


def calibrated_like(seed: int) -> LowerBodyGeometry:
    """Both legs as a calibration leaves them: random IMUs, moved and turned joint origins, tilted knees."""
    rng = np.random.default_rng(seed)
    height, mass = rng.uniform(1.55, 1.95), rng.uniform(50.0, 95.0)
    body = LowerBodyGeometry.from_anthropometry(height, mass)
    for leg in (body.left, body.right):
        leg.sensor_placements.update(random_placements(leg, rng))
        for joint, T in leg.joint_origins.items():
            T[:3, 3] += rng.uniform(-0.02, 0.02, 3)
            T[:3, :3] = Rotation.from_rotvec(rng.uniform(-0.08, 0.08, 3)).as_matrix() @ T[:3, :3]
            leg.joint_origins[joint] = T
        axis = np.array([0.0, 0.0, 1.0]) + rng.uniform(-0.15, 0.15, 3)
        leg.knee_axis_in_thigh = axis / np.linalg.norm(axis)
    body.right.sensor_placements["pelvis"] = body.left.sensor_placements["pelvis"].copy()
    return body


def random_angles(rng: np.random.Generator) -> np.ndarray:
    """18 angles (rad) inside 80 % of the joint limits, left leg then right leg."""
    out = []
    for _ in ("left", "right"):
        for ranges in JOINT_LIMITS_RAD.values():
            for lo, hi in ranges:
                mid, half = 0.5 * (lo + hi), 0.4 * (hi - lo)
                out.append(rng.uniform(mid - half, mid + half))
    return np.array(out)


@pytest.fixture(params=[21, 22], ids=["seed-21", "seed-22"])
def exported(request, tmp_path):
    body = calibrated_like(request.param)
    path = tmp_path / "calibrated.urdf"
    body.write_urdf(path)
    return body, path, np.random.default_rng(request.param + 100)


def test_standing_under_default_gravity_loads_the_hips_only_through_the_leg_offsets():
    """REP 103 base: Pinocchio's default gravity is right, no phantom hip torque (47 N·m with ISB y-up)."""
    body = LowerBodyGeometry.from_anthropometry(1.75, 75.0)
    model = pin.buildModelFromXML(body.to_urdf_string(), pin.JointModelFreeFlyer())
    data = model.createData()
    assert np.allclose(model.gravity.linear, [0.0, 0.0, -G])
    zero = np.zeros(model.nv)
    tau = pin.rnea(model, data, pin.neutral(model), zero, zero)
    # the whole body weight is on the base
    assert tau[2] == pytest.approx(75.0 * G, rel=1e-3)
    for side, leg in (("left", body.left), ("right", body.right)):
        # straight vertical leg: only the foot's CoM sits ahead of the hip (x is forward in both frames)
        x_ahead = {s: leg.inertias[s].com_m[0] for s in ("thigh", "shank", "foot")}
        expected = G * sum(leg.inertias[s].mass_kg * x for s, x in x_ahead.items())
        flexion = tau[6 + LOWER_BODY_DOF_NAMES.index(f"{side}_hip_flexion")]
        adduction = tau[6 + LOWER_BODY_DOF_NAMES.index(f"{side}_hip_adduction")]
        assert flexion == pytest.approx(expected, abs=1e-6)
        assert abs(flexion) < 1.0
        assert abs(adduction) < 1e-6
    # the single-leg model's ISB y-up root under the same gravity: the phantom torque this fixes
    leg = LegModel.from_template("left", 1.75, 75.0)
    zero = np.zeros(leg.model.nv)
    tau_leg = pin.rnea(leg.model, leg.data, pin.neutral(leg.model), zero, zero)
    assert abs(tau_leg[6 + DOF_NAMES.index("hip_adduction")]) > 40.0


def test_the_hip_centres_are_hip_spacing_apart():
    body = LowerBodyGeometry.from_anthropometry(1.80, 80.0)
    model = pin.buildModelFromXML(body.to_urdf_string())
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    left = data.oMi[model.getJointId("left_hip_flexion")].translation
    right = data.oMi[model.getJointId("right_hip_flexion")].translation
    assert np.linalg.norm(left - right) == pytest.approx(hip_spacing_m(1.80), abs=1e-9)
    # REP 103: the left hip is on +y, the right on −y, both at the base height
    assert left[1] > 0 > right[1]
    assert left[2] == pytest.approx(0.0) and right[2] == pytest.approx(0.0)


def test_clinical_signs_hold_on_both_sides():
    """+flexion swings the knee forward, +adduction swings it towards the midline, on either side."""
    body = LowerBodyGeometry.from_anthropometry()
    model = pin.buildModelFromXML(body.to_urdf_string())
    data = model.createData()
    for side, medial in (("left", -1.0), ("right", 1.0)):
        for dof, direction in (
            ("hip_flexion", np.array([1.0, 0.0, 0.0])),
            ("hip_adduction", medial * np.eye(3)[1]),
        ):
            q = pin.neutral(model)
            q[LOWER_BODY_DOF_NAMES.index(f"{side}_{dof}")] = 0.3
            pin.forwardKinematics(model, data, q)
            knee = data.oMi[model.getJointId(f"{side}_knee_flexion")].translation
            hip = data.oMi[model.getJointId(f"{side}_hip_flexion")].translation
            assert float((knee - hip) @ direction) > 0.1, (side, dof)


def test_the_right_leg_joins_the_left_pelvis_frame_through_the_shared_sensor():
    body = LowerBodyGeometry.from_anthropometry()
    hip_right = body.right.joint_origins["hip"].copy()
    T_lr = np.eye(4)  # the right leg's pelvis frame, as its calibration chose it
    T_lr[:3, :3] = Rotation.from_rotvec([0.05, -0.1, 0.2]).as_matrix()
    T_lr[:3, 3] = [0.01, -0.02, 0.03]
    body.right.sensor_placements["pelvis"] = np.linalg.inv(T_lr) @ body.left.sensor_placements["pelvis"]
    body.right.joint_origins["hip"] = np.linalg.inv(T_lr) @ hip_right
    assert np.allclose(body.hip_origin("right"), hip_right, atol=1e-12)


def test_the_xml_is_pretty_commented_and_limited(tmp_path):
    body = LowerBodyGeometry.from_anthropometry(1.75, 75.0)
    text = lower_body_urdf(body.left, body.right, height_m=1.75, mass_kg=75.0)
    assert text.count("\n") > 300  # one element per line
    values = re.findall(r'="([^"]*)"', text)
    numbers = [v for value in values for v in value.split() if re.fullmatch(r"[-+0-9.eE]+", v)]
    assert numbers
    assert not any(re.search(r"e-(1[0-9]|[2-9][0-9])$", n) for n in numbers), "round-off noise in the XML"
    assert "-0 " not in text and '"-0"' not in text
    for needle in ("REP 103", "de Leva", "49.11 %", "Anderson", "Winter", *IMU_LINKS.values()):
        assert needle in text
    (tmp_path / "lower_body.urdf").write_text(text, encoding="utf-8")
    urdf = yourdfpy.URDF.load(str(tmp_path / "lower_body.urdf"), build_scene_graph=False, load_meshes=False)
    limits = {j.name: j.limit for j in urdf.robot.joints if j.type == "revolute"}
    assert list(limits) == list(LOWER_BODY_DOF_NAMES)
    assert limits["left_hip_flexion"].effort == pytest.approx(EFFORT_NM_PER_KG["hip"][0] * 75.0)
    assert len({lim.effort for lim in limits.values()}) > 3
    assert all(5.0 <= lim.velocity <= 30.0 for lim in limits.values())
    links = {lk.name: lk for lk in urdf.robot.links}
    for name in ("pelvis", "trunk", *SEGMENTS):
        assert links[name].collisions, f"{name} has no collision shape"
    assert links["trunk"].inertial.mass == pytest.approx(trunk_inertia(1.75, 75.0).inertia.mass_kg)
    total = sum(lk.inertial.mass for lk in links.values() if lk.inertial is not None)
    assert total == pytest.approx(75.0, abs=0.01)


def test_pinocchio_and_yourdfpy_agree_on_every_frame(exported):
    body, path, rng = exported
    model = pin.buildModelFromUrdf(str(path))  # fixed base: base_link is the world
    data = model.createData()
    assert [model.names[i] for i in range(1, model.njoints)] == list(LOWER_BODY_DOF_NAMES)
    urdf = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert urdf.base_link == BASE_LINK
    for _ in range(5):
        q = random_angles(rng)
        pin.framesForwardKinematics(model, data, q)
        urdf.update_cfg(dict(zip(LOWER_BODY_DOF_NAMES, q, strict=True)))
        for frame in FRAMES:
            got = data.oMf[model.getFrameId(frame, pin.FrameType.BODY)].homogeneous
            want = np.asarray(urdf.get_transform(frame_to=frame, frame_from=BASE_LINK))
            assert np.abs(got - want).max() < 1e-6, frame


def test_each_leg_moves_as_its_single_leg_model(exported):
    """Renaming and re-rooting keep each leg's kinematics: pelvis→IMU poses equal the single-leg URDF's."""
    body, path, rng = exported
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    q = random_angles(rng)
    pin.framesForwardKinematics(model, data, q)
    T_pelvis = data.oMf[model.getFrameId("pelvis", pin.FrameType.BODY)]
    for k, (side, leg) in enumerate((("left", body.left), ("right", body.right))):
        single = pin.buildModelFromXML(leg.to_urdf_string())
        sdata = single.createData()
        pin.framesForwardKinematics(single, sdata, q[9 * k : 9 * k + 9])
        T_pelvis_side = T_pelvis if side == "left" else T_pelvis * pin.SE3(body.right_pelvis_in_left_pelvis())
        for sensor in ("thigh", "shank", "foot"):
            got = T_pelvis_side.actInv(data.oMf[model.getFrameId(f"imu_{side}_{sensor}", pin.FrameType.BODY)])
            want = sdata.oMf[single.getFrameId(f"imu_{sensor}", pin.FrameType.BODY)]
            assert np.abs(got.homogeneous - want.homogeneous).max() < 1e-9


def test_mujoco_inverse_dynamics_equals_pinocchio_rnea(exported):
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is not installed (pip install mujoco)")
    _, path, rng = exported
    mj = mujoco.MjModel.from_xml_path(str(path))
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # rnea has no contacts either
    assert np.allclose(mj.opt.gravity, [0.0, 0.0, -G])
    data = mujoco.MjData(mj)
    model = pin.buildModelFromUrdf(str(path))  # both: base welded to the world, default gravity
    pdata = model.createData()
    assert np.isclose(sum(mj.body_mass), sum(i.mass for i in model.inertias), rtol=1e-9)
    adr = [int(mj.joint(n).qposadr[0]) for n in LOWER_BODY_DOF_NAMES]
    dof = [int(mj.joint(n).dofadr[0]) for n in LOWER_BODY_DOF_NAMES]
    for _ in range(3):
        q, v, a = random_angles(rng), rng.normal(0.0, 2.0, 18), rng.normal(0.0, 20.0, 18)
        data.qpos[adr], data.qvel[dof], data.qacc[dof] = q, v, a
        mujoco.mj_inverse(mj, data)
        tau = pin.rnea(model, pdata, q, v, a)
        assert np.allclose(data.qfrc_inverse[dof], tau, atol=1e-6 * (1.0 + np.abs(tau).max()))


def test_check_urdf_accepts_it(exported):
    _, path, _ = exported
    exe = shutil.which("check_urdf")
    if exe is None:
        pytest.skip("check_urdf not found; install the Debian package liburdfdom-tools")
    result = subprocess.run([exe, str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout
    assert f"root Link: {BASE_LINK}" in result.stdout


def test_the_legs_must_be_given_left_then_right():
    left = LegGeometry.from_anthropometry("left")
    right = LegGeometry.from_anthropometry("right")
    with pytest.raises(ValueError, match="left leg first"):
        lower_body_urdf(right, left, height_m=1.75, mass_kg=75.0)
