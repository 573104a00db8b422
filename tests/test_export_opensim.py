"""OpenSim writers: the .mot/.sto read back by the format's header rules, signs checked against the
Rajagopal model's joint definitions, and (when available) read by OpenSim itself."""

import importlib.util
import os
import subprocess
import textwrap
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation
from simcache import data_dir

from lowerlimb.conventions import JOINT_DOF_NAMES, joint_angles_from_matrix, quat_rotate
from lowerlimb.errors import InputError, ShapeError
from lowerlimb.export.opensim import (
    OPENSIM_COORDINATES,
    UNMAPPED_ANGLES,
    opensense_imu_label,
    write_mot,
    write_orientations_sto,
)

ANGLES = [n for j in ("hip", "knee", "ankle") for n in JOINT_DOF_NAMES[j]]


def read_storage(path):
    """Parse an OpenSim Storage/STO file by its header rules: key=value lines up to 'endheader'."""
    lines = open(path).read().splitlines()
    end = lines.index("endheader")
    meta, name = {}, None
    for i, line in enumerate(lines[:end]):
        if "=" in line:
            key, value = line.split("=", 1)
            meta[key] = value
        elif i == 0:
            name = line
        else:
            raise AssertionError(f"header line {line!r} is neither the name nor key=value")
    labels = lines[end + 1].split("\t")
    rows = [r.split("\t") for r in lines[end + 2 :]]
    assert all(len(r) == len(labels) for r in rows)
    return name, meta, labels, rows


def _angles(t):
    return {n: 10 * np.sin(t + k) + k for k, n in enumerate(ANGLES)}


def test_mot_follows_storage_header_rules(tmp_path):
    t = np.arange(0, 3, 0.01)
    angles = _angles(t)
    res = write_mot(tmp_path / "angles.mot", t, angles, "right", name="walk")
    name, meta, labels, rows = read_storage(tmp_path / "angles.mot")
    assert name == "walk"
    assert meta == {"version": "1", "nRows": str(t.size), "nColumns": "7", "inDegrees": "yes"}
    assert labels == [
        "time", "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r",
        "subtalar_angle_r",
    ]  # fmt: skip
    assert len(rows) == int(meta["nRows"]) and len(labels) == int(meta["nColumns"])
    data = np.array(rows, dtype=float)
    np.testing.assert_allclose(data[:, 0], t, atol=1e-9)
    np.testing.assert_allclose(data[:, 4], angles["knee_flexion"], atol=1e-5)
    np.testing.assert_allclose(data[:, 6], angles["ankle_inversion"], atol=1e-5)
    assert res.columns == tuple(labels[1:]) and res.not_written == UNMAPPED_ANGLES


def test_mot_two_legs_and_bad_input(tmp_path):
    t = np.arange(0, 1, 0.01)
    both = {"left_knee_flexion": t, "right_knee_flexion": -t, "left_knee_adduction": t}
    res = write_mot(tmp_path / "a.mot", t, both)
    assert res.columns == ("knee_angle_l", "knee_angle_r") and res.not_written == ("left_knee_adduction",)
    with pytest.raises(InputError, match="not a lowerlimb angle"):
        write_mot(tmp_path / "b.mot", t, {"knee_valgus": t})
    with pytest.raises(InputError, match="none of the given angles has an OpenSim coordinate"):
        write_mot(tmp_path / "b.mot", t, {"knee_adduction": t})
    with pytest.raises(InputError, match="two inputs map to knee_angle_l"):
        write_mot(tmp_path / "b.mot", t, {"knee_flexion": t, "left_knee_flexion": t})
    with pytest.raises(ShapeError):
        write_mot(tmp_path / "b.mot", t, {"knee_flexion": t[:-1]})
    with pytest.raises(InputError, match="strictly increasing"):
        write_mot(tmp_path / "b.mot", t[::-1], {"knee_flexion": t})
    assert not (tmp_path / "b.mot").exists()


def test_orientation_sto_header_labels_and_world_rotation(tmp_path):
    t = np.arange(0, 0.5, 0.01)
    identity = np.tile([1.0, 0, 0, 0], (t.size, 1))
    rng = np.random.default_rng(2)
    rand = rng.normal(size=(t.size, 4))
    quats = {"pelvis": identity, "thigh": rand, "right_foot": 2 * identity}
    res = write_orientations_sto(tmp_path / "o.sto", t, quats, "left")
    name, meta, labels, rows = read_storage(tmp_path / "o.sto")
    assert name is None
    assert meta["DataType"] == "Quaternion" and meta["version"] == "3"
    assert float(meta["DataRate"]) == pytest.approx(100.0)
    assert int(meta["nRows"]) == len(rows) == t.size and int(meta["nColumns"]) == len(labels) == 4
    assert labels == ["time", "pelvis_imu", "femur_l_imu", "calcn_r_imu"] == ["time", *res.columns]
    q_pelvis = np.array([c.split(",") for c in (r[1] for r in rows)], dtype=float)
    # a sensor aligned with ENU: its z (up) is OpenSim's y (up), its y (north) OpenSim's -z, x stays x
    np.testing.assert_allclose(quat_rotate(q_pelvis[0], [0, 0, 1]), [0, 1, 0], atol=1e-8)
    np.testing.assert_allclose(quat_rotate(q_pelvis[0], [0, 1, 0]), [0, 0, -1], atol=1e-8)
    np.testing.assert_allclose(quat_rotate(q_pelvis[0], [1, 0, 0]), [1, 0, 0], atol=1e-8)
    q_foot = np.array([c.split(",") for c in (r[3] for r in rows)], dtype=float)
    np.testing.assert_allclose(q_foot, q_pelvis, atol=1e-8)  # normalised
    write_orientations_sto(tmp_path / "e.sto", t, quats, "left", world="enu")
    _, _, _, erows = read_storage(tmp_path / "e.sto")
    q_thigh = np.array([r[2].split(",") for r in erows], dtype=float)
    np.testing.assert_allclose(q_thigh, rand / np.linalg.norm(rand, axis=1, keepdims=True), atol=1e-8)
    with pytest.raises(InputError, match="not a lowerlimb sensor"):
        write_orientations_sto(tmp_path / "x.sto", t, {"hand": identity})
    with pytest.raises(ShapeError, match=r"\(50, 4\)"):
        write_orientations_sto(tmp_path / "x.sto", t, {"pelvis": identity[:, :3]})
    assert opensense_imu_label("shank", "right") == "tibia_r_imu"


# ------------------------------------------------------------ signs against Rajagopal_2015.osim


def _osim_root():
    d = data_dir()
    path = d / "opensim" / "Rajagopal_2015.osim" if d else None
    if path is None or not path.is_file():
        pytest.skip("shared data (opensim/Rajagopal_2015.osim) not available")
    return ET.parse(path).getroot()


def _vec(text):
    return np.array([float(v) for v in text.split()])


def _joint_rotation(root, joint, coords):
    """R_parentbody_childbody of an OpenSim joint, built from the XML (body-fixed TransformAxis
    sequence for CustomJoint, z-axis rotation for PinJoint; offset frames X-Y-Z body-fixed)."""
    j = root.find(f".//*[@name='{joint}']")
    frames = {f.get("name"): Rotation.from_euler("XYZ", _vec(f.find("orientation").text)).as_matrix()
              for f in j.find("frames")}  # fmt: skip
    P, C = frames[j.find("socket_parent_frame").text], frames[j.find("socket_child_frame").text]
    if j.tag == "PinJoint":
        M = Rotation.from_rotvec([0, 0, coords.get(j.find("coordinates/Coordinate").get("name"), 0.0)])
        return P @ M.as_matrix() @ C.T
    M = np.eye(3)
    for r in ("rotation1", "rotation2", "rotation3"):
        ax = j.find(f"SpatialTransform/TransformAxis[@name='{r}']")
        name = (ax.find("coordinates").text or "").strip()
        q = coords.get(name, 0.0)
        if (lin := ax.find("LinearFunction")) is not None:
            a, b = _vec(lin.find("coefficients").text)
            angle = a * q + b
        else:
            sp = ax.find("SimmSpline")
            angle = float(CubicSpline(_vec(sp.find("x").text), _vec(sp.find("y").text))(q))
        axis = _vec(ax.find("axis").text)
        M = M @ Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle).as_matrix()
    return P @ M @ C.T


@pytest.mark.data
@pytest.mark.parametrize("side", ["left", "right"])
def test_coordinate_signs_match_rajagopal_model(side):
    root = _osim_root()
    s = side[0]
    q = 0.3  # rad, positive coordinate value
    joint_of = {"hip_flexion": "hip", "hip_adduction": "hip", "hip_rotation": "hip",
                "knee_angle": "walker_knee", "ankle_angle": "ankle",
                "subtalar_angle": "subtalar"}  # fmt: skip
    for ours, (stem, sign) in OPENSIM_COORDINATES.items():
        R = _joint_rotation(root, f"{joint_of[stem]}_{s}", {f"{stem}_{s}": q})
        if stem == "subtalar_angle":  # calcaneus in the tibia: ankle (at 0) then subtalar
            R = _joint_rotation(root, f"ankle_{s}", {}) @ R
        joint = ours.split("_")[0]
        ours_rad = dict(zip(JOINT_DOF_NAMES[joint], joint_angles_from_matrix(R, joint, side), strict=True))
        value = sign * ours_rad[ours]
        if joint == "hip":  # same Z-X-Y sequence and signs: exact, other two angles zero
            assert value == pytest.approx(q, abs=1e-9)
            assert sum(abs(v) for k, v in ours_rad.items() if k != ours) < 1e-9
        else:  # oblique axes / coupled rotations: same sign, dominant share
            assert value > 0.7 * q, (ours, ours_rad)
    # unmapped knee rotation: the model couples internal rotation to flexion (our sign: internal +)
    R = _joint_rotation(root, f"walker_knee_{s}", {f"knee_angle_{s}": 0.5})
    assert joint_angles_from_matrix(R, "knee", side)[2] > np.deg2rad(3)


# ------------------------------------------------------------ OpenSim itself (optional)


def _opensim_python():
    if importlib.util.find_spec("opensim") is not None:
        import sys

        return sys.executable
    exe = os.environ.get("LOWERLIMB_OPENSIM_PYTHON")
    if not exe:
        pytest.skip("opensim not installed (set LOWERLIMB_OPENSIM_PYTHON to a python that has it)")
    return exe


def test_opensim_reads_mot_and_quaternion_sto(tmp_path):
    exe = _opensim_python()
    t = np.arange(0, 1, 0.01)
    write_mot(tmp_path / "a.mot", t, _angles(t), "left")
    rng = np.random.default_rng(5)
    quats = {n: rng.normal(size=(t.size, 4)) for n in ("pelvis", "thigh", "shank", "foot")}
    write_orientations_sto(tmp_path / "os.sto", t, quats, world="opensim")
    write_orientations_sto(tmp_path / "enu.sto", t, quats, world="enu")
    script = textwrap.dedent(
        f"""
        import math, opensim as osim
        m = osim.TimeSeriesTable(r"{tmp_path / "a.mot"}")
        print(m.getNumRows(), m.getNumColumns(), m.getTableMetaDataAsString("inDegrees"))
        print(",".join(m.getColumnLabels()))
        print(float(m.getDependentColumn("knee_angle_l").to_numpy()[7]))
        enu = osim.TimeSeriesTableQuaternion(r"{tmp_path / "enu.sto"}")
        ours = osim.TimeSeriesTableQuaternion(r"{tmp_path / "os.sto"}")
        print(ours.getNumRows(), ",".join(ours.getColumnLabels()))
        X, Y, Z = (osim.CoordinateAxis(i) for i in range(3))
        R = osim.Rotation(osim.SpaceRotationSequence, -math.pi / 2, X, 0, Y, 0, Z)
        osim.OpenSenseUtilities.rotateOrientationTable(enu, R)  # OpenSense's own -90 deg about x
        worst = 0.0
        for i in range(enu.getNumRows()):
            for j in range(enu.getNumColumns()):
                a, b = enu.getRowAtIndex(i).getElt(0, j), ours.getRowAtIndex(i).getElt(0, j)
                dot = abs(sum(a.get(k) * b.get(k) for k in range(4)))
                worst = max(worst, abs(1 - dot))
        print(worst)
        """
    )
    out = subprocess.run([exe, "-c", script], capture_output=True, text=True, timeout=300, check=True)
    lines = out.stdout.strip().splitlines()[-5:]
    assert lines[0] == f"{t.size} 6 yes"
    assert (
        lines[1] == "hip_flexion_l,hip_adduction_l,hip_rotation_l,knee_angle_l,ankle_angle_l,subtalar_angle_l"
    )
    assert float(lines[2]) == pytest.approx(_angles(t)["knee_flexion"][7], abs=1e-5)
    assert lines[3] == f"{t.size} pelvis_imu,femur_l_imu,tibia_l_imu,calcn_l_imu"
    assert float(lines[4]) < 1e-9  # our world rotation == OpenSense's sensor_to_opensim_rotations
