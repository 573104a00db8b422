"""Both legs of a seven-IMU trial through the single-leg pipeline, side by side on two cores.

The two legs share nothing until the one-pelvis stage, so the right leg runs in a forked
child process while this process runs the left one (:func:`lowerlimb.side_by_side.side_by_side`,
which says when it runs them one after the other instead): a 5-minute simulated two-leg walk's
legs took 5.6 s one after the other and 2.9 s side by side on a 2-core machine
(``benchmarks/results/bilateral_speed.md``). The warnings each leg raised travel as
``(text, category)`` records (:class:`LegWarning`), which pickle whatever the warning's class.
The numbers are the same either way (the pipeline is deterministic and single-threaded).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..side_by_side import side_by_side

__all__ = ["LegWarning", "recorded", "run_two_legs"]


@dataclass(frozen=True)
class LegWarning:
    """A warning one leg raised, kept to be issued again naming the leg.

    Attributes:
        message: its text.
        category: its class.
    """

    message: str
    category: type[Warning]


LegRun = Callable[[str], tuple[Any, list[LegWarning]]]
"""Runs one leg (``"left"`` or ``"right"``): its result and its warnings."""


def recorded(caught: list[warnings.WarningMessage]) -> list[LegWarning]:
    """The caught warnings as :class:`LegWarning` records (picklable, whatever the class)."""
    return [LegWarning(str(w.message), w.category) for w in caught]


def run_two_legs(run: LegRun, parallel: bool = True) -> dict[str, tuple[Any, list[LegWarning]]]:
    """``{"left": run("left"), "right": run("right")}``, the right leg in a child when possible.

    Args:
        run: runs one leg and returns its result and warnings; it must not depend on the
            other leg's result.
        parallel: False runs the legs one after the other in this process.

    Raises:
        Whatever ``run`` raises, from this process: the left leg's first, then the right's.
    """
    left, right = side_by_side(lambda: run("left"), lambda: run("right"), parallel)
    return {"left": left, "right": right}
