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

import csv
import logging
import os
import select
import socket
import subprocess
import sys
import time
import warnings
import webbrowser
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from xml.etree import ElementTree

import numpy as np
from numpy.typing import NDArray

from ..conventions import ANGLE_COLUMNS, SIDES, FloatArray
from ..errors import InputError
from ..io.bilateral_tables import BILATERAL_ANGLE_COLUMNS
from ..model.leg_model import LegModel
from .meshcat_server import DEFAULT_HOST
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
        """Close the connection and stop the meshcat server this session started."""
        _close_visualizer(self.animation.visualizer)
        _stop(self.server)
        self.server = None


def load_view_data(directory: str | os.PathLike[str], side: str | None = None) -> ViewData:
    """Read ``calibrated.urdf`` and ``angles.csv`` (degrees → rad) from a calibration directory.

    A two-leg directory gives one leg: ``calibrated_<side>.urdf`` and that side's nine
    columns of its ``angles.csv``.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        side: the leg of a two-leg directory (default ``"left"``); a one-leg directory's
            leg is its own.

    Returns:
        The leg and its motion.

    Raises:
        InputError: when the directory or one of the two files is missing, or a file is
            damaged (``"DIR/angles.csv is damaged (data row 52 has 1 value, not 10); re-run
            lowerlimb calibrate"``).
    """
    d = Path(directory)
    hint = "give the output directory of 'lowerlimb calibrate TRIAL.csv --out DIR'"
    if not d.is_dir():
        raise InputError(f"{d} is not a directory; {hint}")
    urdf, angles_csv = d / URDF_NAME, d / ANGLES_NAME
    columns, keep = ANGLE_COLUMNS, slice(None)
    if (d / "calibrated_left.urdf").is_file() and (d / "calibrated_right.urdf").is_file():
        side = side or "left"
        if side not in SIDES:
            raise InputError(f"--side {side!r}: a two-leg result has the legs 'left' and 'right'")
        urdf, columns = d / f"calibrated_{side}.urdf", BILATERAL_ANGLE_COLUMNS
        keep = slice(0, 10) if side == "left" else np.r_[0, 10:19]
    for f in (urdf, angles_csv):
        if not f.is_file():
            raise InputError(f"{f} is missing; {hint}")
    model = _read_urdf(urdf)
    if columns == ANGLE_COLUMNS and side is not None and side != model.side:
        raise InputError(
            f"{d} is a one-leg result of the {model.side} leg, so it has no {side} leg to show; drop "
            f"--side {side} (or view a two-leg result, which has both legs)"
        )
    table = _read_angles(angles_csv, columns, keep)
    time_s = table[:, 0]
    return ViewData(model, time_s, np.deg2rad(table[:, 1:]))


def _damaged(path: Path, detail: str) -> InputError:
    """The one-line error of a damaged result file: what is wrong with it, and the fix."""
    return InputError(f"{path} is damaged ({detail}); re-run lowerlimb calibrate")


def _read_urdf(path: Path) -> LegModel:
    """The leg of a ``calibrated*.urdf``; a damaged file is named without the parser's own log lines.

    Raises:
        InputError: not well-formed XML (a truncated file), or not a lowerlimb leg.
    """
    try:
        ElementTree.parse(path)  # strict: yourdfpy would log the error and recover a truncated file
    except ElementTree.ParseError as e:
        raise _damaged(path, f"not well-formed XML: {e}") from None
    logger = logging.getLogger("yourdfpy")
    disabled, logger.disabled = logger.disabled, True
    try:
        return LegModel.from_urdf(path)
    except InputError as e:
        raise _damaged(path, str(e).split(";")[0]) from None
    except Exception as e:  # a parser's own error on XML that is well-formed but not a URDF
        raise _damaged(path, f"not a lowerlimb leg URDF: {type(e).__name__}: {e}") from None
    finally:
        logger.disabled = disabled


def _read_angles(path: Path, columns: tuple[str, ...], keep: slice | NDArray[np.int_]) -> FloatArray:
    """(N, 10) time (s) and one leg's angles (deg): the columns ``keep`` of an ``angles.csv``, checked.

    Raises:
        InputError: naming the damage: the header, a row cut short, an empty or non-numeric
            cell, a NaN, no data rows, or a time that is not strictly increasing.
    """
    try:
        with open(path, encoding="utf-8") as f:
            header = [h.strip() for h in f.readline().split(",")]
    except UnicodeDecodeError:
        raise _damaged(path, "not UTF-8 text") from None
    if tuple(header) != columns:
        shown = ",".join(header)
        raise _damaged(
            path,
            f"its header is {shown[:60] + '…' if len(shown) > 60 else shown!r}, not "
            f"{','.join(columns[:3])},…",
        )
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # numpy's "input contained no data"
            table = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError:
        raise _damaged(path, _first_bad_cell(path, columns)) from None
    if table.size == 0:
        raise _damaged(path, "no data rows")
    if table.shape[1] != len(columns):
        raise _damaged(path, f"its rows have {table.shape[1]} values, not {len(columns)}")
    names = np.array(columns)[keep]
    table = table[:, keep]
    if not np.all(np.isfinite(table)):
        row, col = (int(i) for i in np.argwhere(~np.isfinite(table))[0])
        raise _damaged(path, f"a NaN or infinite value at data row {row + 1}, column '{names[col]}'")
    if np.any(np.diff(table[:, 0]) <= 0):
        row = int(np.flatnonzero(np.diff(table[:, 0]) <= 0)[0]) + 2
        raise _damaged(path, f"the time column is not strictly increasing at data row {row}")
    return table


def _first_bad_cell(path: Path, columns: tuple[str, ...]) -> str:
    """What makes the first unreadable data row of a table unreadable (numpy does not say it clearly)."""
    with open(path, encoding="utf-8", newline="") as f:
        rows = csv.reader(f)
        next(rows, None)
        for i, row in enumerate(rows, start=1):
            if not row:
                continue
            if len(row) != len(columns):
                return f"data row {i} has {len(row)} value{'s' * (len(row) != 1)}, not {len(columns)}"
            for cell, name in zip(row, columns, strict=True):
                try:
                    float(cell)
                except ValueError:
                    what = "is empty" if not cell.strip() else f"holds {cell.strip()[:20]!r}, not a number"
                    return f"data row {i}, column '{name}' {what}"
    return "unreadable numbers"


def build_animation(
    directory: str | os.PathLike[str],
    vis: meshcat.Visualizer | None = None,
    *,
    fps: float = DEFAULT_FPS,
    side: str | None = None,
) -> LegAnimation:
    """Draw the directory's calibrated leg in ``vis`` and animate it over ``angles.csv``.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        vis: a meshcat visualizer; by default a :class:`CommandRecorder`'s
            (no server is started, nothing blocks).
        fps: animation frame rate, Hz.
        side: the leg of a two-leg directory (:func:`load_view_data`).

    Returns:
        The drawn animation.

    Raises:
        InputError: see :func:`load_view_data`.
    """
    data = load_view_data(directory, side)
    recorder = None
    if vis is None:
        recorder = CommandRecorder()
        vis = recorder.visualizer()
    scene = draw_leg(vis, data.model, data.time_s, data.angles_rad, fps=fps)
    return LegAnimation(data, vis, scene, recorder)


def check_host(host: str) -> None:
    """Refuse an address this machine cannot listen on, before any server starts.

    Raises:
        InputError: ``host`` does not resolve, or is not one of this machine's addresses.
    """
    fix = "give one of this machine's addresses, e.g. 127.0.0.1 (the default) or 0.0.0.0 (all)"
    try:
        family, _, _, _, address = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)[0]
    except (OSError, UnicodeError) as e:
        raise InputError(f"--host {host!r} is not an address ({e}); {fix}") from None
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        try:
            probe.bind((address[0], 0))
        except OSError as e:
            raise InputError(f"--host {host!r} cannot be listened on ({e.strerror}); {fix}") from None


def start_server(
    host: str = DEFAULT_HOST, *, timeout_s: float = 60.0
) -> tuple[subprocess.Popen[bytes], str, str]:
    """Start a meshcat server bound to ``host`` (:mod:`lowerlimb.viz.meshcat_server`).

    Returns:
        ``(process, zmq_url, web_url)``.

    Raises:
        RuntimeError: the server exited or printed no URL within ``timeout_s``.
    """
    process = subprocess.Popen(
        [sys.executable, "-u", "-m", "lowerlimb.viz.meshcat_server", "--host", host],
        stdout=subprocess.PIPE,
        bufsize=0,  # unbuffered: select() below must see every line that readline has not read
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        start_new_session=True,  # the terminal's Ctrl-C goes to the view, which stops the server
    )
    urls: dict[str, str] = {}
    deadline = time.monotonic() + timeout_s
    try:
        assert process.stdout is not None
        while len(urls) < 2:
            # wait for a line at most until the deadline (a blocked readline never checks it)
            ready, _, _ = select.select([process.stdout], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                raise RuntimeError("the meshcat server printed no URL")
            line = process.stdout.readline().decode("utf-8", "replace").strip()
            if not line and process.poll() is not None:
                raise RuntimeError(f"the meshcat server exited with status {process.returncode}")
            if "=" in line:
                key, value = line.split("=", 1)
                urls[key] = value
    except BaseException:
        _stop(process)
        raise
    return process, urls["zmq_url"], urls["web_url"]


def _visualizer(zmq_url: str, web_url: str) -> meshcat.Visualizer:
    """A visualizer on a running server, connected once and silently.

    meshcat's own constructor connects twice (leaking a socket) and prints the URL.
    """
    import meshcat
    from meshcat.visualizer import ViewerWindow

    window = ViewerWindow.__new__(ViewerWindow)
    window.server_proc = None
    window.zmq_url = zmq_url
    window.web_url = web_url
    window.connect_zmq()
    return meshcat.Visualizer(window=window)


def _close_visualizer(vis: meshcat.Visualizer | None) -> None:
    socket = getattr(getattr(vis, "window", None), "zmq_socket", None)
    if socket is not None and not socket.closed:
        socket.close(linger=0)


def serve(
    directory: str | os.PathLike[str],
    *,
    zmq_url: str | None = None,
    open_browser: bool = False,
    fps: float = DEFAULT_FPS,
    host: str = DEFAULT_HOST,
    side: str | None = None,
) -> ViewSession:
    """Start a meshcat server (or connect to ``zmq_url``) and show the animated leg; returns at once.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        zmq_url: an already running meshcat server; by default one is started.
        open_browser: open the page in the default web browser.
        fps: animation frame rate, Hz.
        host: address the started server binds to (default: localhost only).
        side: the leg of a two-leg directory (:func:`load_view_data`).

    Returns:
        The session; call :meth:`ViewSession.close` to stop the server.

    Raises:
        InputError: see :func:`load_view_data` and :func:`check_host` (checked before any
            server starts).
    """
    load_view_data(directory, side)  # fail before starting a server
    if zmq_url is None:
        check_host(host)
    server = None
    vis = None
    try:
        if zmq_url is None:
            server, zmq_url, web_url = start_server(host)
            vis = _visualizer(zmq_url, web_url)
        else:
            vis = live_visualizer(zmq_url)
        animation = build_animation(directory, vis, fps=fps, side=side)
    except BaseException:
        _close_visualizer(vis)
        _stop(server)
        raise
    session = ViewSession(url=str(vis.url()), animation=animation, server=server)
    if open_browser:
        webbrowser.open(session.url, new=2)
    return session


def run_view(
    directory: str | os.PathLike[str],
    *,
    open_browser: bool = False,
    host: str = DEFAULT_HOST,
    side: str | None = None,
) -> None:
    """``lowerlimb view DIR``: serve the animated leg and print its URL until Ctrl-C or SIGTERM.

    Args:
        directory: output directory of ``lowerlimb calibrate``.
        open_browser: also open the page in the default web browser.
        host: address the server binds to (default: localhost only).
        side: the leg of a two-leg directory (default left).

    Raises:
        InputError: when the directory lacks ``calibrated.urdf`` or ``angles.csv``.
    """
    session = serve(directory, open_browser=open_browser, host=host, side=side)
    try:
        scene = session.animation.scene
        print(
            f"lowerlimb: showing {directory} ({session.animation.data.model.side} leg, "
            f"{len(scene.frame_time_s)} frames, "
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
    """Terminate a server process we started, reap it and close its pipe."""
    if process is None:
        return
    if process.stdout is not None:
        process.stdout.close()
    if process.poll() is not None:
        return
    process.terminate()
    try:
        process.wait(timeout=5)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
