"""The method families, one registry each: the API's checks, the CLI's choices and the docs come from here.

This module imports nothing heavy, so that ``lowerlimb --help`` can list the
choices without loading a filter or a solver. The implementations register
against these names: :data:`lowerlimb.orientation.estimate.FILTERS` and
:data:`lowerlimb.calibration.options.METHODS`; ``tests/test_architecture.py``
checks that the registries, the implementations and ``docs/methods.md`` agree.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CALIBRATION_METHODS", "CENTRE_FORMS", "ORIENTATION_FILTERS", "MethodInfo", "describe"]


@dataclass(frozen=True)
class MethodInfo:
    """One method of a family.

    Attributes:
        name: the value of ``method=`` / ``--filter`` / ``--method``.
        summary: one line for ``--help`` and the docs.
    """

    name: str
    summary: str


def _registry(*methods: MethodInfo) -> dict[str, MethodInfo]:
    return {m.name: m for m in methods}


#: Orientation filters of :func:`lowerlimb.estimate_orientation` and ``calibrate --filter``.
ORIENTATION_FILTERS: dict[str, MethodInfo] = _registry(
    MethodInfo("mahony", "Mahony PI complementary filter (Hu et al. 2021 §4.3)"),
    MethodInfo("ftecf", "fuzzy-tuned ESOQ-2 complementary filter (Zhu & Xu 2018)"),
    MethodInfo("madgwick", "Madgwick gradient-descent filter"),
    MethodInfo("quest_kf", "QUEST + Kalman filter (Yun & Bachmann 2006)"),
)

#: Joint-constraint solvers of :func:`lowerlimb.calibrate_leg` and ``calibrate --method``.
CALIBRATION_METHODS: dict[str, MethodInfo] = _registry(
    MethodInfo("casadi", "CasADi Gauss–Newton on the joint-constraint residuals (default)"),
    MethodInfo("gn", "NumPy Gauss–Newton with the analytic Jacobians"),
    MethodInfo("dwpso", "dynamic-weight particle swarm (Hu et al. 2021 §3.2)"),
    MethodInfo("gwo", "grey wolf optimiser (Hu et al. 2021 §3.3)"),
    MethodInfo("dwpso+casadi", "particle swarm, refined by CasADi Gauss–Newton"),
    MethodInfo("gwo+casadi", "grey wolf optimiser, refined by CasADi Gauss–Newton"),
)


#: Forms of the joint constraint that decide the hip and knee centres
#: (:attr:`lowerlimb.calibration.options.CalibrationOptions.centre_form`, ``calibrate --centre-form``):
#: the norm form of Hu et al. 2021 eq. 3 (default) and the 3-D form in gyro-aligned frames
#: (:mod:`lowerlimb.calibration.aligned_form`).
CENTRE_FORMS: tuple[str, ...] = ("norm", "aligned")


def describe(registry: dict[str, MethodInfo]) -> str:
    """``name: summary`` lines of a registry, for ``--help`` and error messages."""
    return "; ".join(f"{m.name}: {m.summary}" for m in registry.values())
