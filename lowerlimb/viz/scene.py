"""A meshcat scene of one leg, animated over a trial; shared by ``lowerlimb view`` and the report.

The scene is built from the leg's own URDF (:meth:`LegGeometry.to_robot`), so
what is drawn is what the exported ``calibrated.urdf`` describes: each segment
link becomes a meshcat node ``/meshcat/leg/<segment>`` with its primitive
visuals (box, cylinder, sphere) as children, each IMU link sits under its
segment at the sensor placement with its visual, and three markers are added: the
joint centres (blue spheres), the knee axis (a red rod through the knee
centre) and the axes of every IMU (red/green/blue = x/y/z triads).

Only the four segment nodes move: for each animation frame their world poses
come from Pinocchio forward kinematics of the 9 joint angles, with the pelvis
fixed. meshcat's world is z-up; the pelvis ISB frame (x anterior, y up, z
right) is turned by +90° about x, so anterior is world +x and up is world +z.
The world origin is at mid-leg height, because meshcat's orbit controls
always look at the origin; the grid is lowered to where the foot stands in
the zero posture.

:class:`CommandRecorder` stands in for meshcat's server connection and keeps
the packed commands, so :func:`standalone_html` can write the scene as one
offline HTML page (meshcat's ``main.min.js`` inlined), without starting the
meshcat server.
"""

from __future__ import annotations

import base64
import os
import warnings
from dataclasses import dataclass
from typing import Any

import msgpack
import numpy as np
import umsgpack

from ..conventions import SEGMENTS, SENSORS, FloatArray, quat_from_matrix
from ..errors import ShapeError
from ..model.anthropometry import ankle_height_m
from ..model.geometry import JOINT_SEGMENTS, SENSOR_SEGMENT
from ..model.leg_model import DOF_NAMES, LegModel

with warnings.catch_warnings():
    # meshcat imports its server module, which imports a module pyzmq deprecates
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat
    import meshcat.geometry as mg
    from meshcat.animation import Animation, AnimationClip, AnimationTrack

#: meshcat path (under ``/meshcat``) of the leg.
LEG_PATH = "leg"
#: Maps pelvis ISB coordinates (x anterior, y up, z right) to meshcat's z-up world.
R_WORLD_PELVIS: FloatArray = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
#: Default animation frame rate, Hz.
DEFAULT_FPS = 30.0

_JOINT_CENTRE_RGB = 0x1F5FD6
_KNEE_AXIS_RGB = 0xD62728
_SEGMENT_OPACITY = 0.55
_KNEE_AXIS_LENGTH_M = 0.26
# meshcat (three.js) cylinders lie along y; URDF cylinders along z.
_Y_TO_Z: FloatArray = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


class CommandRecorder:
    """A stand-in for meshcat's ``ViewerWindow`` that keeps the commands instead of sending them.

    Attributes:
        messages: the msgpack-packed commands, in the order they were issued
            (the bytes meshcat's server forwards to the browser).
    """

    def __init__(self) -> None:
        self.messages: list[bytes] = []

    def send(self, command: Any) -> None:
        """Pack and keep one meshcat command (``SetObject``, ``SetTransform``, ...).

        Packed by msgpack's C packer: the same bytes as meshcat's pure-Python
        ``umsgpack`` (tested), 10× faster on an animation's thousands of keys.
        """
        self.messages.append(msgpack.packb(command.lower(), default=_ext))

    def visualizer(self) -> meshcat.Visualizer:
        """A meshcat ``Visualizer`` whose commands this recorder keeps."""
        return meshcat.Visualizer(window=self)


def _ext(obj: Any) -> msgpack.ExtType:
    """The packed numpy arrays of meshcat (``umsgpack.Ext``) as msgpack extension types."""
    if isinstance(obj, umsgpack.Ext):
        return msgpack.ExtType(obj.type, obj.data)
    raise TypeError(f"meshcat command holds an unpackable {type(obj).__name__}")


def live_visualizer(zmq_url: str | None = None) -> meshcat.Visualizer:
    """A meshcat visualizer connected to ``zmq_url``, or to a meshcat server started as a subprocess."""
    return meshcat.Visualizer(zmq_url=zmq_url)


@dataclass
class LegScene:
    """What :func:`draw_leg` put into a meshcat scene.

    Attributes:
        frame_time_s: (F,) times of the animation frames, s from the first sample.
        fps: animation frame rate, Hz.
        segment_poses: ``{segment: (F, 4, 4)}`` world pose of each segment
            frame per animation frame (meshcat world, z up), m.
        paths: meshcat paths of every node drawn (``/meshcat/leg/...``).
        animation: the meshcat animation (``None`` when only one frame).
    """

    frame_time_s: FloatArray
    fps: float
    segment_poses: dict[str, FloatArray]
    paths: list[str]
    animation: Animation | None


def resample_angles(
    time_s: FloatArray, angles_rad: FloatArray, fps: float, max_frames: int | None = None
) -> tuple[FloatArray, FloatArray]:
    """Linearly interpolate joint angles onto a regular animation grid.

    Args:
        time_s: (N,) strictly increasing sample times, s.
        angles_rad: (N, 9) joint angles, rad, angles.csv order.
        fps: wanted frame rate, Hz.
        max_frames: lower the frame rate so that at most this many frames result.

    Returns:
        ``(frame_time_s (F,), frame_angles_rad (F, 9))``, times from 0 s.

    Raises:
        ShapeError: when the arrays do not have shapes (N,) and (N, 9), N ≥ 1.
    """
    t = np.asarray(time_s, dtype=float)
    a = np.asarray(angles_rad, dtype=float)
    if t.ndim != 1 or a.ndim != 2 or a.shape != (t.size, len(DOF_NAMES)) or t.size == 0:
        raise ShapeError(f"expected time (N,) and angles (N, {len(DOF_NAMES)}), got {t.shape} and {a.shape}")
    duration = float(t[-1] - t[0])
    if t.size == 1 or duration <= 0.0:
        return np.zeros(1), a[:1].copy()
    n = int(np.floor(duration * fps)) + 1
    if max_frames is not None and n > max_frames:
        n = max_frames
    frame_t = np.linspace(0.0, duration, n)
    frames = np.column_stack([np.interp(frame_t + t[0], t, a[:, k]) for k in range(a.shape[1])])
    return frame_t, frames


def pelvis_world_pose(model: LegModel) -> tuple[FloatArray, float]:
    """Pose of the pelvis frame in the meshcat world (z up), and the floor height.

    The world origin is at mid-leg height (meshcat's orbit controls turn about
    the origin), the pelvis frame right above it.

    Returns:
        ``(T_world_pelvis (4, 4), floor_z_m)``: the floor is where the foot
        stands in the zero posture, m.
    """
    q0 = model.configuration(np.zeros(len(DOF_NAMES)))
    model.frame_poses(q0, ("foot",))
    ankle_z = float(R_WORLD_PELVIS[2] @ model.joint_center_world("ankle"))
    height = -ankle_z + ankle_height_m(model.geometry.height_m)
    T = np.eye(4)
    T[:3, :3] = R_WORLD_PELVIS
    T[2, 3] = 0.5 * height
    return T, -0.5 * height


def segment_world_poses(
    model: LegModel, frame_angles_rad: FloatArray, T_world_pelvis: FloatArray
) -> dict[str, FloatArray]:
    """World poses ``{segment: (F, 4, 4)}`` of the segment frames for (F, 9) joint angles (rad)."""
    out = {s: np.empty((len(frame_angles_rad), 4, 4)) for s in SEGMENTS}
    for k, angles in enumerate(frame_angles_rad):
        poses = model.frame_poses(model.configuration(angles), SEGMENTS)
        for s in SEGMENTS:
            out[s][k] = T_world_pelvis @ poses[s].homogeneous
    return out


def draw_leg(
    vis: meshcat.Visualizer,
    model: LegModel,
    time_s: FloatArray,
    angles_rad: FloatArray,
    *,
    fps: float = DEFAULT_FPS,
    max_frames: int | None = None,
    play: bool = True,
    loop: bool = True,
    light_background: bool = False,
) -> LegScene:
    """Draw the leg in ``vis`` and animate it over a trial (meshcat Animation with play controls).

    Args:
        vis: a meshcat visualizer (live, or :meth:`CommandRecorder.visualizer`).
        model: the (calibrated) leg.
        time_s: (N,) sample times, s.
        angles_rad: (N, 9) joint angles, rad, angles.csv order.
        fps: animation frame rate, Hz.
        max_frames: cap on the number of animation frames (lowers ``fps``).
        play: start playing when the page loads.
        loop: repeat the animation (otherwise play it once).
        light_background: white-grey background instead of meshcat's sky blue.

    Returns:
        What was drawn (:class:`LegScene`).

    Raises:
        ShapeError: when ``time_s``/``angles_rad`` do not have shapes (N,), (N, 9).
    """
    frame_t, frame_angles = resample_angles(time_s, angles_rad, fps, max_frames)
    eff_fps = fps if len(frame_t) < 2 else (len(frame_t) - 1) / float(frame_t[-1])
    T_root, floor_z = pelvis_world_pose(model)
    poses = segment_world_poses(model, frame_angles, T_root)
    leg = vis[LEG_PATH]
    paths: list[str] = []
    leg.delete()

    if light_background:
        vis["/Background"].set_property("top_color", [1.0, 1.0, 1.0])
        vis["/Background"].set_property("bottom_color", [0.80, 0.83, 0.88])
    robot = model.geometry.to_robot()
    links = {link.name: link for link in robot.links}
    geo = model.geometry
    for seg in SEGMENTS:
        node = leg[seg]
        paths.append(node.path.lower())
        _draw_visuals(node, links.get(seg), opacity=_SEGMENT_OPACITY)
        node.set_transform(poses[seg][0])
    for sensor in SENSORS:
        node = leg[SENSOR_SEGMENT[sensor]][f"imu_{sensor}"]
        paths.append(node.path.lower())
        _draw_visuals(node, links.get(f"imu_{sensor}"), opacity=1.0)
        node["axes"].set_object(mg.triad(0.07))
        node.set_transform(geo.sensor_placements[sensor])
    for joint, (parent, _child) in JOINT_SEGMENTS.items():
        node = leg[parent][f"{joint}_centre"]
        paths.append(node.path.lower())
        node.set_object(mg.Sphere(0.018), mg.MeshLambertMaterial(color=_JOINT_CENTRE_RGB))
        node.set_transform(_translation(geo.joint_origins[joint][:3, 3]))
    T_knee = geo.joint_origins["knee"]
    axis_thigh = T_knee[:3, :3] @ geo.knee_axis_in_thigh
    node = leg["thigh"]["knee_axis"]
    paths.append(node.path.lower())
    node.set_object(mg.Cylinder(_KNEE_AXIS_LENGTH_M, 0.006), mg.MeshLambertMaterial(color=_KNEE_AXIS_RGB))
    node.set_transform(_pose_y_along(axis_thigh, T_knee[:3, 3]))
    vis["/Grid"].set_transform(_translation(np.array([0.0, 0.0, floor_z])))
    vis["/Axes"].set_property("visible", False)
    _aim_camera(vis, model.side, T_root)

    animation: Animation | None = None
    if len(frame_t) > 1:
        animation = segment_animation(vis, poses, eff_fps)
        vis.set_animation(animation, play=play, repetitions=1_000_000 if loop else 1)
    return LegScene(frame_t, eff_fps, poses, paths, animation)


def segment_animation(vis: meshcat.Visualizer, poses: dict[str, FloatArray], fps: float) -> Animation:
    """The meshcat animation of the segment nodes: one position and one quaternion key per frame.

    What ``Animation.at_frame(...).set_transform`` builds frame by frame (three.js
    quaternions ``x, y, z, w`` with ``w >= 0``), with every frame's quaternion at once.

    Args:
        vis: the visualizer the leg is drawn in (its path roots the node paths).
        poses: ``{segment: (F, 4, 4)}`` world poses per animation frame, m.
        fps: animation frame rate, Hz.
    """
    animation = Animation(default_framerate=fps)
    for seg, T in poses.items():
        frames = list(range(len(T)))
        xyzw = quat_from_matrix(T[:, :3, :3])[:, [1, 2, 3, 0]]
        tracks = {
            "position": AnimationTrack("position", "vector3", frames, T[:, :3, 3].tolist()),
            "quaternion": AnimationTrack("quaternion", "quaternion", list(frames), xyzw.tolist()),
        }
        animation.clips[vis.path.append(LEG_PATH).append(seg)] = AnimationClip(tracks, fps=fps)
    return animation


def standalone_html(messages: list[bytes], *, title: str = "lowerlimb leg") -> str:
    """One offline HTML page that replays recorded meshcat commands (meshcat's JS inlined).

    The commands are decoded synchronously in order (meshcat's own
    ``static_html`` uses asynchronous ``fetch`` of data URLs instead).

    Args:
        messages: packed commands from :class:`CommandRecorder`.
        title: page title.

    Returns:
        The HTML text (about 0.9 MB plus the commands).
    """
    js_path = os.path.join(os.path.dirname(meshcat.__file__), "viewer", "dist", "main.min.js")
    with open(js_path, encoding="utf-8") as f:
        main_js = f.read()
    commands = ",\n".join(f'"{base64.b64encode(m).decode("ascii")}"' for m in messages)
    return f"""<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{_escape(title)}</title>
<style>body {{margin: 0;}} #meshcat-pane {{width: 100vw; height: 100vh; overflow: hidden;}}</style>
</head>
<body>
<div id="meshcat-pane"></div>
<script>{main_js}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var commands = [{commands}];
for (var i = 0; i < commands.length; i++) {{
  var s = atob(commands[i]);
  var bytes = new Uint8Array(s.length);
  for (var j = 0; j < s.length; j++) bytes[j] = s.charCodeAt(j);
  viewer.handle_command_bytearray(bytes);
}}
</script>
</body>
</html>
"""


# ---------------------------------------------------------------- helpers


def _draw_visuals(node: meshcat.Visualizer, link: Any, *, opacity: float) -> None:
    """Add a link's URDF primitive visuals (box, cylinder, sphere) as children of ``node``."""
    if link is None:
        return
    for i, visual in enumerate(link.visuals):
        g = visual.geometry
        T = np.eye(4) if visual.origin is None else np.asarray(visual.origin, dtype=float)
        shape: mg.Geometry
        if g.box is not None:
            shape = mg.Box([float(v) for v in g.box.size])
        elif g.cylinder is not None:
            shape = mg.Cylinder(float(g.cylinder.length), float(g.cylinder.radius))
            T = T @ _Y_TO_Z
        elif g.sphere is not None:
            shape = mg.Sphere(float(g.sphere.radius))
        else:  # meshes are not written by lowerlimb
            continue
        rgba = [0.7, 0.7, 0.7, 1.0]
        if visual.material is not None and visual.material.color is not None:
            rgba = [float(v) for v in visual.material.color.rgba]
        child = node[visual.name or f"visual_{i}"]
        child.set_object(shape, mg.MeshLambertMaterial(color=_rgb_int(rgba), opacity=opacity * rgba[3]))
        child.set_transform(T)


def _aim_camera(vis: meshcat.Visualizer, side: str, T_root: FloatArray) -> None:
    """Put the camera in front of and lateral to the leg, looking at the world origin (mid-leg).

    meshcat's orbit controls always look at the world origin; the camera
    position is set in meshcat's y-up "rotated" frame, where
    ``(x, y, z)_rotated = (x, z, -y)_world``.
    """
    lateral = 1.0 if side == "right" else -1.0
    lateral_world = T_root[:3, :3] @ np.array([0.0, 0.0, lateral])
    eye = np.array([0.6, 0.0, 0.25]) + 0.95 * lateral_world
    vis["/Cameras/default/rotated/<object>"].set_property(
        "position", [float(eye[0]), float(eye[2]), float(-eye[1])]
    )


def _translation(p: FloatArray) -> FloatArray:
    T = np.eye(4)
    T[:3, 3] = p
    return T


def _pose_y_along(direction: FloatArray, origin: FloatArray) -> FloatArray:
    """(4, 4) pose whose y axis is ``direction`` (3,) and whose origin is ``origin`` (3,)."""
    y = np.asarray(direction, dtype=float)
    y = y / np.linalg.norm(y)
    helper = np.array([1.0, 0.0, 0.0]) if abs(y[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    x = np.cross(y, helper)
    x /= np.linalg.norm(x)
    z = np.cross(x, y)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, y, z])
    T[:3, 3] = origin
    return T


def _rgb_int(rgba: list[float]) -> int:
    r, g, b = (int(round(255 * min(max(c, 0.0), 1.0))) for c in rgba[:3])
    return (r << 16) + (g << 8) + b


def _escape(text: str) -> str:
    import html

    return html.escape(text, quote=True)
