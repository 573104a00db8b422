"""Headless Chromium screenshots for the browser tests (import as ``chromium``)."""

from __future__ import annotations

import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def find_chromium() -> str:
    """Path of a Chromium executable, or skip the test with the reason."""
    for name in NAMES:
        exe = shutil.which(name)
        if exe:
            return exe
    pytest.skip("headless Chromium not found; install the Debian package 'chromium'")


def screenshot(url: str, out: Path, *, width: int, height: int, budget_ms: int = 5000) -> np.ndarray:
    """Render ``url`` headless (software WebGL) and return the screenshot as (H, W, 3) uint8 RGB.

    ``--enable-unsafe-swiftshader`` opts in to SwiftShader's software WebGL,
    which Chromium no longer falls back to silently; the other flags keep the
    browser off the network and stop it from syncing or updating components.
    """
    from PIL import Image

    exe = find_chromium()
    with tempfile.TemporaryDirectory(prefix="lowerlimb-chromium-") as profile:
        cmd = [
            exe,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--enable-unsafe-swiftshader",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--disable-extensions",
            f"--user-data-dir={profile}",
            f"--screenshot={out}",
            f"--window-size={width},{height}",
            f"--virtual-time-budget={budget_ms}",
            url,
        ]
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
    if result.returncode != 0 or not out.is_file():
        pytest.fail(f"chromium failed ({result.returncode}): {result.stderr[-2000:]}")
    with Image.open(out) as img:
        return np.asarray(img.convert("RGB"))


def colour_mask(rgb: np.ndarray, colour: tuple[int, int, int], tol: int) -> np.ndarray:
    """(H, W) bool: pixels within ``tol`` of ``colour`` in every channel."""
    return np.all(np.abs(rgb.astype(int) - np.array(colour)) <= tol, axis=-1)


def orange_mask(rgb: np.ndarray) -> np.ndarray:
    """(H, W) bool: the IMU boxes' orange (1, 0.5, 0) under any of the scene's lights."""
    r, g, b = (rgb[..., k].astype(int) for k in range(3))
    return (r > 150) & (b < 0.35 * r) & (g > 0.25 * r) & (g < 0.75 * r)
