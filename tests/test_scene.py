from __future__ import annotations

import base64
import re

import numpy as np
import pytest
import umsgpack

from lowerlimb.errors import ShapeError
from lowerlimb.viz.scene import CommandRecorder, draw_leg, resample_angles, standalone_html


def test_resample_angles_interpolates_on_a_regular_grid():
    t = 2.0 + np.linspace(0.0, 3.0, 301)
    a = np.column_stack([np.sin(t + k) for k in range(9)])
    frame_t, frames = resample_angles(t, a, 20.0)
    assert frame_t.shape == (61,) and frames.shape == (61, 9)
    assert np.allclose(np.diff(frame_t), 0.05)
    assert np.allclose(frames, np.column_stack([np.sin(frame_t + 2.0 + k) for k in range(9)]), atol=1e-4)
    capped_t, capped = resample_angles(t, a, 20.0, max_frames=10)
    assert capped.shape == (10, 9) and capped_t[-1] == pytest.approx(3.0)
    one_t, one = resample_angles(t[:1], a[:1], 20.0)
    assert one_t.tolist() == [0.0] and np.array_equal(one, a[:1])


@pytest.mark.parametrize("shape", [(10, 8), (9, 9), (0, 9)])
def test_resample_angles_checks_shapes(shape):
    n = 10 if shape[0] else 0
    with pytest.raises(ShapeError, match=r"expected time \(N,\) and angles \(N, 9\)"):
        resample_angles(np.arange(n, dtype=float), np.zeros(shape), 30.0)


def test_standalone_html_replays_every_command_in_order(walk_clean):
    rec = CommandRecorder()
    scene = draw_leg(
        rec.visualizer(), walk_clean.model, walk_clean.trial.time_s[:50], walk_clean.angles_rad[:50]
    )
    page = standalone_html(rec.messages, title="a <leg>")
    assert "<title>a &lt;leg&gt;</title>" in page
    blobs = re.findall(r'"([A-Za-z0-9+/=]{8,})"', page.split("var commands = [", 1)[1])
    assert [base64.b64decode(b) for b in blobs] == rec.messages
    types = [umsgpack.unpackb(m)["type"] for m in rec.messages]
    assert types[0] == "delete" and types[-1] == "set_animation"
    assert len(scene.paths) == 4 + 4 + 3 + 1  # segments, IMUs, joint centres, knee axis


def test_the_animation_is_meshcats_frame_by_frame_one(walk_clean):
    """segment_animation's keys equal meshcat's ``at_frame(...).set_transform`` (three.js x, y, z, w)."""
    from meshcat.animation import Animation

    rec = CommandRecorder()
    vis = rec.visualizer()
    scene = draw_leg(vis, walk_clean.model, walk_clean.trial.time_s[:200], walk_clean.angles_rad[:200])
    reference = Animation(default_framerate=scene.fps)
    for k in range(len(scene.frame_time_s)):
        with reference.at_frame(vis, k) as frame:
            for seg, T in scene.segment_poses.items():
                frame["leg"][seg].set_transform(T[k])
    ours, theirs = scene.animation.lower(), reference.lower()
    assert [c["path"] for c in ours] == [c["path"] for c in theirs]
    for a, b in zip(ours, theirs, strict=True):
        assert a["clip"]["fps"] == b["clip"]["fps"]
        for ta, tb in zip(a["clip"]["tracks"], b["clip"]["tracks"], strict=True):
            assert (ta["name"], ta["type"]) == (tb["name"], tb["type"])
            assert [key["time"] for key in ta["keys"]] == [key["time"] for key in tb["keys"]]
            va = np.array([key["value"] for key in ta["keys"]])
            assert np.allclose(va, np.array([key["value"] for key in tb["keys"]]), atol=1e-12)


def test_recorded_commands_are_the_bytes_meshcat_would_send(walk_clean):
    """The C packer gives meshcat's umsgpack bytes, numpy geometry (Ext) included."""
    sent = []
    rec = CommandRecorder()
    vis = rec.visualizer()
    vis.window.send = lambda command: sent.append(command)
    draw_leg(vis, walk_clean.model, walk_clean.trial.time_s[:50], walk_clean.angles_rad[:50])
    assert sent
    packed = [umsgpack.packb(c.lower()) for c in sent]
    ours = []
    for c in sent:
        CommandRecorder.send(rec, c)
        ours.append(rec.messages[-1])
    assert ours == packed
    assert any(b"Float32Array" in m for m in ours)  # numpy geometry: umsgpack.Ext → msgpack.ExtType
