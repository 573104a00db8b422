"""``lowerlimb view DIR``: the calibrated leg of a trial, animated in meshcat.

``DIR`` is an output directory of ``lowerlimb calibrate``; the view needs its
``calibrated.urdf`` (the leg) and ``angles.csv`` (the motion, degrees). The
scene is the one of the report (:mod:`lowerlimb.viz.scene`): segments, IMUs with
their axes, joint centres and the knee axis, animated with meshcat's
Animation so that the page has play/pause, a time slider and a speed control
(*Open Controls → Animations*).

:func:`build_animation` fills any meshcat visualizer (by default a
:class:`~lowerlimb.viz.scene.CommandRecorder`, no server) and is what the tests
use; :func:`serve` starts meshcat's server, and :func:`run_view` (the
command) serves until Ctrl-C.
"""

from __future__ import annotations

import os
import subprocess
import time
import warnings
import webbrowser
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..conventions import ANGLE_COLUMNS, FloatArray
from ..errors import InputError
from ..io.tables import read_table
from ..model.leg_model import LegModel
from .scene import DEFAULT_FPS, CommandRecorder, LegScene, draw_leg, live_visualizer

if TYPE_CHECKING:
    import meshcat

#: Files of a calibration directory that the view reads.
URDF_NAME = "calibrated.urdf"
ANGLES_NAME = "angles.csv"


@dataclass
class ViewData:
    """What the view shows, read from a calibration directory.

    Attributes:
        model: the calibrated leg (from ``calibrated.urdf``).
        time_s: (N,) sample times, s.
        angles_rad: (N, 9) ISB joint angles, rad (``angles.csv`` holds degrees).
    """

    model: LegModel
    time_s: FloatArray
    angles_rad: FloatArray


@dataclass
class LegAnimation:
    """A leg drawn and animated in a meshcat visualizer.

    Attributes:
        data: the directory's leg and angles.
        visualizer: the meshcat visualizer the scene was sent to.
        scene: what was drawn (frame times, segment poses, meshcat Animation).
        recorder: the recorder holding the commands when no live visualizer was given.
    """

    data: ViewData
    visualizer: meshcat.Visualizer
    scene: LegScene
    recorder: CommandRecorder | None = None


@dataclass
class ViewSession:
    """A running meshcat server showing a leg; :meth:`close` stops the server.

    Attributes:
        url: address of the meshcat page.
        animation: the leg drawn in it.
        server: the meshcat server process started for this session (``None``
            when connected to an existing server).
    """

    url: str
    animation: LegAnimation
    server: subprocess.Popen[bytes] | None = field(default=None, repr=False)

    def close(self) -> None:
        """Stop the meshcat server this session started (no-op otherwise)."""
        _stop(self.server)
        self.server = None


def load_view_data(directory: str | os.PathLike[str]) -> ViewData:
    """Read ``calibrated.urdf`` and ``angles.csv`` (degrees → rad) from a calibration directory.

    Args:
        directory: output directory of ``lowerlimb calibrate``.

    Returns:
        The leg and its motion.

    Raises:
        InputError: when the directory or one of the two files is missing or
            unreadable; the message names the file and the fix.
    """
    d = Path(directory)
    hint = "give the output directory of 'lowerlimb calibrate TRIAL.csv --out DIR'"
    if not d.is_dir():
        raise InputError(f"{d} is not a directory; {hint}")
    urdf, angles_csv = d / URDF_NAME, d / ANGLES_NAME
    for f in (urdf, angles_csv):
        if not f.is_file():
            raise InputError(f"{f} is missing; {hint}")
    try:
        model = LegModel.from_urdf(urdf)
    except InputError:
        raise
    except Exception as e:  # a parser's own error: unreadable or malformed XML
        raise InputError(
            f"cannot read {urdf} as a lowerlimb leg URDF ({type(e).__name__}: {e}); "
            f"write it again with 'lowerlimb calibrate'"
        ) from e
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # numpy's "input contained no data"
            table = read_table(angles_csv, ANGLE_COLUMNS)
    except ValueError as e:
        raise InputError(f"cannot read {angles_csv}: {e}") from e
    if table.size == 0:
        raise InputError(f"{angles_csv} has no data rows; write it again with 'lowerlimb calibrate'")
    if table.shape[1] != len(ANGLE_COLUMNS):
        raise InputError(
            f"{angles_csv} has {table.shape[1]} values per row, expected {len(ANGLE_COLUMNS)} "
            f"({', '.join(ANGLE_COLUMNS)})"
        )
    if not np.all(np.isfinite(table)):
        row = int(np.argwhere(~np.isfinite(table))[0, 0]) + 1
        raise InputError(f"{angles_csv} has a NaN or infinite value at data row {row}")
    time_s = table[:, 0]
    if np.any(np.diff(time_s) <= 0):
        raise InputError(f"the time column of {angles_csv} is not strictly increasing")
    return ViewData(model, time_s, np.deg2rad(table[:, 1:]))


def build_animation(
    directory: str | os.PathLike[str],
    vis: meshcat.Visualizer | None = None,
    *,
    fps: float = DEFAULT_FPS,
) -> LegAnimation:
    """Draw the directory's calibrated leg in ``vis`` and animate it over ``angles.csv``.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        vis: a meshcat visualizer; by default a :class:`CommandRecorder`'s
            (no server is started, nothing blocks).
        fps: animation frame rate, Hz.

    Returns:
        The drawn animation.

    Raises:
        InputError: see :func:`load_view_data`.
    """
    data = load_view_data(directory)
    recorder = None
    if vis is None:
        recorder = CommandRecorder()
        vis = recorder.visualizer()
    scene = draw_leg(vis, data.model, data.time_s, data.angles_rad, fps=fps)
    return LegAnimation(data, vis, scene, recorder)


def serve(
    directory: str | os.PathLike[str],
    *,
    zmq_url: str | None = None,
    open_browser: bool = False,
    fps: float = DEFAULT_FPS,
) -> ViewSession:
    """Start a meshcat server (or connect to ``zmq_url``) and show the animated leg; returns at once.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        zmq_url: an already running meshcat server; by default one is started.
        open_browser: open the page in the default web browser.
        fps: animation frame rate, Hz.

    Returns:
        The session; call :meth:`ViewSession.close` to stop the server.

    Raises:
        InputError: see :func:`load_view_data` (checked before any server starts).
    """
    load_view_data(directory)  # fail before starting a server
    vis = live_visualizer(zmq_url)
    server = getattr(vis.window, "server_proc", None)
    try:
        animation = build_animation(directory, vis, fps=fps)
    except BaseException:
        _stop(server)
        raise
    session = ViewSession(url=str(vis.url()), animation=animation, server=server)
    if open_browser:
        webbrowser.open(session.url, new=2)
    return session


def run_view(directory: str | os.PathLike[str], *, open_browser: bool = False) -> None:
    """``lowerlimb view DIR``: serve the animated leg and print its URL until Ctrl-C.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        open_browser: also open the page in the default web browser.

    Raises:
        InputError: when the directory lacks ``calibrated.urdf`` or ``angles.csv``.
    """
    session = serve(directory, open_browser=open_browser)
    try:
        scene = session.animation.scene
        print(
            f"lowerlimb: showing {directory} ({len(scene.frame_time_s)} frames, "
            f"{scene.frame_time_s[-1]:.1f} s) at {session.url}",
            flush=True,
        )
        print("lowerlimb: open that address in a browser; press Ctrl-C to stop", flush=True)
        while session.server is None or session.server.poll() is None:
            time.sleep(0.5)
    except KeyboardInterrupt:
        print("lowerlimb: stopped", flush=True)
    finally:
        session.close()


def _stop(process: subprocess.Popen[bytes] | None) -> None:
    """Terminate a server process we started, and reap it."""
    if process is None or process.poll() is not None:
        return
    process.terminate()
    try:
        process.wait(timeout=5)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
