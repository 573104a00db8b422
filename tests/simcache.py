"""Cached simulations and the real-data folder, shared by the tests (import as ``simcache``)."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

from lowerlimb.simulation import Simulation, simulate

_CACHE: dict[tuple[object, ...], Simulation] = {}


def cached_simulation(
    motion: str = "walk", duration_s: float = 20.0, seed: int = 0, **kw: object
) -> Simulation:
    """Simulate once per parameter set per test session."""
    key = (motion, duration_s, seed, tuple(sorted((k, repr(v)) for k, v in kw.items())))
    if key not in _CACHE:
        _CACHE[key] = simulate(motion, duration_s, seed, **kw)  # type: ignore[arg-type]
    return _CACHE[key]


def data_dir() -> Path | None:
    """The shared real-data folder (LOWERLIMB_DATA or ../shared/data beside the checkout)."""
    env = os.environ.get("LOWERLIMB_DATA")
    candidates = [Path(env)] if env else []
    here = Path(__file__).resolve().parents[1]
    candidates += [here.parent / "shared" / "data", here / ".." / "shared" / "data"]
    for c in candidates:
        if c.is_dir():
            return c.resolve()
    return None


def real_walk_leg_mapping(side: str) -> dict[str, str]:
    """``{pelvis, thigh, shank, foot: ID}`` of one leg of the real walk, for ``read_xsens``
    (the IDs of ``benchmarks/_realwalk.py``)."""
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "_realwalk.py"
    spec = importlib.util.spec_from_file_location("_realwalk_ids", path)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return dict(mod.leg_mapping(side))


def true_leg(joints: dict[str, object]) -> object:
    """A simulation truth's ``joints`` (``truth["legs"][side]["joints"]`` or ``truth["joints"]``)
    as the hip/knee/ankle calibrations that :func:`lowerlimb.model.fallback.segment_lengths` reads."""
    from types import SimpleNamespace

    from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration

    return SimpleNamespace(
        hip=SphericalJointCalibration.from_dict(joints["hip"], "hip"),  # type: ignore[arg-type]
        knee=HingeJointCalibration.from_dict(joints["knee"], "knee"),  # type: ignore[arg-type]
        ankle=SphericalJointCalibration.from_dict(joints["ankle"], "ankle"),  # type: ignore[arg-type]
    )
