"""The exported URDF loads in Pinocchio, yourdfpy, MuJoCo and urdfdom with the same kinematics.

The reference poses are computed here from the LegGeometry parameters and the
angle conventions alone (not by any URDF loader), so every loader is checked
against what the joint coordinates mean: ISB angles in radians.
"""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy
from scipy.spatial.transform import Rotation

from lowerlimb.conventions import JOINT_AXIS_SIGNS, JOINTS, SENSORS, matrix_from_joint_angles
from lowerlimb.model.geometry import JOINT_LIMITS_RAD, JOINT_SEGMENTS, SENSOR_SEGMENT, LegGeometry
from lowerlimb.model.leg_model import DOF_NAMES, LegModel
from lowerlimb.simulation.placements import random_placements

SEGMENT_LINKS = ["pelvis", "thigh", "shank", "foot"]
IMU_LINKS = [f"imu_{s}" for s in SENSORS]
LINKS = SEGMENT_LINKS + IMU_LINKS
POS_TOL_M = 1e-6
ROT_TOL_RAD = 1e-6


def calibrated_like_model(side: str, seed: int) -> LegModel:
    """A leg as a calibration would leave it: random IMUs, tilted knee axis, moved/turned origins."""
    rng = np.random.default_rng(seed)
    geo = LegGeometry.from_anthropometry(side, rng.uniform(1.55, 1.95), rng.uniform(50.0, 95.0))
    model = LegModel(geo)
    for sensor, T in random_placements(geo, rng).items():
        model.set_sensor_placement(sensor, T)
    for joint in JOINTS:
        T = model.geometry.joint_origins[joint].copy()
        T[:3, 3] += rng.uniform(-0.02, 0.02, 3)
        T[:3, :3] = Rotation.from_rotvec(rng.uniform(-0.08, 0.08, 3)).as_matrix() @ T[:3, :3]
        model.set_joint_origin(joint, T)
    model.set_knee_axis(np.array([0.0, 0.0, 1.0]) + rng.uniform(-0.15, 0.15, 3))
    return model


def random_angles(rng: np.random.Generator) -> np.ndarray:
    """Nine angles (rad) inside 80 % of the URDF joint limits (no MuJoCo limit is active)."""
    out = []
    for joint in JOINTS:
        for lo, hi in JOINT_LIMITS_RAD[joint]:
            mid, half = 0.5 * (lo + hi), 0.4 * (hi - lo)
            out.append(rng.uniform(mid - half, mid + half))
    return np.array(out)


def reference_poses(geo: LegGeometry, angles: np.ndarray) -> dict[str, np.ndarray]:
    """World poses (4x4, pelvis at the origin) from the geometry and the angle conventions only."""
    poses = {"pelvis": np.eye(4)}
    for k, joint in enumerate(JOINTS):
        a = angles[3 * k : 3 * k + 3]
        if joint == "knee":
            s_f, s_a, s_r = JOINT_AXIS_SIGNS[geo.side]["knee"]
            axis = geo.knee_axis_in_thigh / np.linalg.norm(geo.knee_axis_in_thigh)
            R = (
                Rotation.from_rotvec(s_f * a[0] * axis).as_matrix()
                @ Rotation.from_rotvec([s_a * a[1], 0.0, 0.0]).as_matrix()
                @ Rotation.from_rotvec([0.0, s_r * a[2], 0.0]).as_matrix()
            )
        else:
            R = matrix_from_joint_angles(a, joint, geo.side)
        parent, child = JOINT_SEGMENTS[joint]
        J = np.eye(4)
        J[:3, :3] = R
        poses[child] = poses[parent] @ geo.joint_origins[joint] @ J
    for sensor in SENSORS:
        poses[f"imu_{sensor}"] = poses[SENSOR_SEGMENT[sensor]] @ geo.sensor_placements[sensor]
    return poses


def assert_same_pose(got: np.ndarray, want: np.ndarray, what: str) -> None:
    dp = np.linalg.norm(got[:3, 3] - want[:3, 3])
    dr = np.linalg.norm(Rotation.from_matrix(got[:3, :3].T @ want[:3, :3]).as_rotvec())
    assert dp < POS_TOL_M, f"{what}: position differs by {dp:.2e} m"
    assert dr < ROT_TOL_RAD, f"{what}: orientation differs by {dr:.2e} rad"


CASES = [("left", 11), ("right", 12), ("left", 13)]


@pytest.fixture(params=CASES, ids=[f"{s}-{k}" for s, k in CASES])
def exported(request, tmp_path):
    side, seed = request.param
    model = calibrated_like_model(side, seed)
    path = tmp_path / "calibrated.urdf"
    model.write_urdf(path)
    return model, path, np.random.default_rng(seed + 100)


def test_joint_names_are_the_angle_columns(exported):
    _, path, _ = exported
    urdf = yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False)
    revolute = [j.name for j in urdf.robot.joints if j.type == "revolute"]
    assert revolute == list(DOF_NAMES)
    assert {lk.name for lk in urdf.robot.links} >= set(LINKS)


def test_pinocchio_matches_the_conventions(exported):
    model, path, rng = exported
    pm = pin.buildModelFromUrdf(str(path))  # fixed base: the pelvis is the world
    data = pm.createData()
    assert [pm.names[i] for i in range(1, pm.njoints)] == list(DOF_NAMES)
    for _ in range(5):
        angles = random_angles(rng)
        pin.framesForwardKinematics(pm, data, angles)
        want = reference_poses(model.geometry, angles)
        for link in LINKS:
            got = data.oMf[pm.getFrameId(link, pin.FrameType.BODY)].homogeneous
            assert_same_pose(got, want[link], f"pinocchio {link}")


def test_yourdfpy_matches_the_conventions(exported):
    model, path, rng = exported
    urdf = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    assert urdf.base_link == "pelvis"
    for _ in range(5):
        angles = random_angles(rng)
        urdf.update_cfg(dict(zip(DOF_NAMES, angles, strict=True)))
        want = reference_poses(model.geometry, angles)
        for link in LINKS:
            got = urdf.get_transform(frame_to=link, frame_from="pelvis")
            assert_same_pose(np.asarray(got), want[link], f"yourdfpy {link}")


def _load_mujoco(path):
    mujoco = pytest.importorskip("mujoco", reason="MuJoCo is not installed (pip install mujoco)")
    xml = path.read_text(encoding="utf-8")
    # the exported URDF carries the <mujoco><compiler fusestatic="false" .../> extension itself
    assert "fusestatic" in xml
    return mujoco, mujoco.MjModel.from_xml_string(xml)


def test_mujoco_matches_the_conventions(exported):
    model, path, rng = exported
    mujoco, mj = _load_mujoco(path)
    data = mujoco.MjData(mj)
    assert [mj.joint(i).name for i in range(mj.njnt)] == list(DOF_NAMES)
    adr = [int(mj.joint(n).qposadr[0]) for n in DOF_NAMES]
    for _ in range(5):
        angles = random_angles(rng)
        data.qpos[adr] = angles
        mujoco.mj_kinematics(mj, data)
        want = reference_poses(model.geometry, angles)
        for link in LINKS:
            body = mj.body(link)
            got = np.eye(4)
            got[:3, :3] = data.xmat[body.id].reshape(3, 3)
            got[:3, 3] = data.xpos[body.id]
            assert_same_pose(got, want[link], f"mujoco {link}")


def test_mujoco_and_pinocchio_agree_on_inverse_dynamics(exported):
    """The inertias survive the export: same joint torques (fixed pelvis, gravity −z)."""
    _, path, rng = exported
    mujoco, mj = _load_mujoco(path)
    data = mujoco.MjData(mj)
    pm = pin.buildModelFromUrdf(str(path))
    pdata = pm.createData()
    assert np.isclose(sum(mj.body_mass), sum(i.mass for i in pm.inertias), rtol=1e-9)
    adr = [int(mj.joint(n).qposadr[0]) for n in DOF_NAMES]
    dof = [int(mj.joint(n).dofadr[0]) for n in DOF_NAMES]
    for _ in range(3):
        q, v, a = random_angles(rng), rng.normal(0.0, 2.0, 9), rng.normal(0.0, 20.0, 9)
        data.qpos[adr], data.qvel[dof], data.qacc[dof] = q, v, a
        mujoco.mj_inverse(mj, data)
        tau = pin.rnea(pm, pdata, q, v, a)
        assert np.allclose(data.qfrc_inverse[dof], tau, atol=1e-6 * (1.0 + np.abs(tau).max()))


@pytest.mark.urdf
def test_check_urdf_accepts_the_export(exported):
    _, path, _ = exported
    exe = shutil.which("check_urdf")
    if exe is None:
        pytest.skip("check_urdf not found; install the Debian package liburdfdom-tools")
    result = subprocess.run([exe, str(path)], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout
    assert "root Link: pelvis" in result.stdout
