import io

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

from lowerlimb.conventions import SENSORS
from lowerlimb.model.geometry import LegGeometry
from lowerlimb.model.leg_model import LegModel
from lowerlimb.model.templates import render_template, template_path
from lowerlimb.simulation.placements import random_placements

FRAMES = ["pelvis", "thigh", "shank", "foot"] + [f"imu_{s}" for s in SENSORS]


@pytest.mark.parametrize("side", ["left", "right"])
def test_shipped_templates_match_the_generator(side):
    assert template_path(side).read_text(encoding="utf-8") == render_template(side)


@pytest.mark.parametrize("side", ["left", "right"])
def test_template_loads_in_pinocchio(side):
    model = pin.buildModelFromUrdf(str(template_path(side)), pin.JointModelFreeFlyer())
    assert model.nq == 16 and model.nv == 15
    total = sum(i.mass for i in model.inertias)
    assert 0.25 * 75 < total < 0.35 * 75  # pelvis + one leg ≈ 30 % of body mass


@pytest.mark.parametrize("side", ["left", "right"])
def test_urdf_round_trip_same_kinematics(side, tmp_path):
    rng = np.random.default_rng(4)
    geo = LegGeometry.from_anthropometry(side, 1.68, 62.0)
    model = LegModel(geo)
    for sensor, T in random_placements(geo, rng).items():
        model.set_sensor_placement(sensor, T)
    knee = model.geometry.joint_origins["knee"].copy()
    knee[:3, 3] += [0.01, -0.02, 0.005]
    model.set_joint_origin("knee", knee)
    model.set_knee_axis(np.array([0.05, 0.1, 1.0]))
    path = tmp_path / "leg.urdf"
    model.write_urdf(path)

    back = LegModel.from_urdf(path)
    raw = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    raw_data = raw.createData()
    ydf = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    names = [n for n in ydf.actuated_joint_names]
    assert len(names) == 9
    for _ in range(5):
        angles = rng.uniform(-0.5, 0.5, 9)
        q = model.configuration(angles)
        ref = model.frame_poses(q, FRAMES)
        got = back.frame_poses(q, FRAMES)
        pin.framesForwardKinematics(raw, raw_data, q)
        ydf.update_cfg(dict(zip(model.model.names[2:], angles, strict=True)))
        for f in FRAMES:
            assert np.allclose(ref[f].homogeneous, got[f].homogeneous, atol=1e-9)
            assert np.allclose(ref[f].homogeneous, raw_data.oMf[raw.getFrameId(f)].homogeneous, atol=1e-9)
            T = ydf.get_transform(f, "pelvis")
            assert np.allclose(ref[f].homogeneous, T, atol=1e-9)


def test_sensor_views_match_forward_kinematics():
    """Joint centres in sensor frames agree with the world positions from FK."""
    rng = np.random.default_rng(1)
    geo = LegGeometry.from_anthropometry("right")
    geo.sensor_placements = random_placements(geo, rng)
    m = LegModel(geo)
    q = m.configuration(rng.uniform(-0.4, 0.4, 9))
    poses = m.frame_poses(q, [f"imu_{s}" for s in SENSORS])
    for joint, parent, child in (
        ("hip", "pelvis", "thigh"),
        ("knee", "thigh", "shank"),
        ("ankle", "shank", "foot"),
    ):
        c_world = m.joint_center_world(joint)
        for s in (parent, child):
            P = poses[f"imu_{s}"]
            assert np.allclose(
                P.rotation @ m.joint_center_in_sensor(joint, s) + P.translation, c_world, atol=1e-12
            )
    # the knee axis is one physical direction seen from both sensors (pure flexion)
    angles = np.zeros(9)
    angles[[0, 3]] = [0.4, 0.9]
    pf = m.frame_poses(m.configuration(angles), ["imu_thigh", "imu_shank"])
    a_t = pf["imu_thigh"].rotation @ m.knee_axis_in_sensor("thigh")
    a_s = pf["imu_shank"].rotation @ m.knee_axis_in_sensor("shank")
    assert np.allclose(a_t, a_s, atol=1e-12)
    q0 = m.configuration(np.zeros(9))
    p0 = m.frame_poses(q0, ["imu_thigh", "imu_shank", "thigh"])
    assert np.allclose(
        p0["imu_thigh"].rotation @ m.knee_axis_in_sensor("thigh"), p0["thigh"].rotation @ [0, 0, 1]
    )
    assert np.allclose(p0["imu_shank"].rotation @ m.knee_axis_in_sensor("shank"), [0, 0, 1], atol=1e-12)


def test_from_urdf_string_and_bad_urdf():
    xml = LegGeometry.from_anthropometry("left").to_urdf_string()
    assert LegModel.from_urdf(xml).side == "left"
    from lowerlimb.errors import InputError

    bad = '<robot name="x"><link name="a"/></robot>'
    with pytest.raises(InputError, match="not a lowerlimb leg"):
        LegGeometry.from_urdf(bad)
    assert yourdfpy.URDF.load(io.BytesIO(xml.encode()), build_scene_graph=False, load_meshes=False).validate()
