"""Sensors exchanged between the legs: ``left_thigh`` data under ``right_thigh`` (or shanks, or feet).

Each leg's own sensor-order check (:mod:`~lowerlimb.calibration.plausibility`) compares
pairings within the leg, and the pair of hips catches two whole legs exchanged; a single
segment's sensors exchanged between the legs passed both. The left leg was then calibrated from
the right thigh, left shank and left foot: the hip centres landed on the wrong sides and the
angles were off by up to 62°, with exit status 0.

The knee tells. A thigh and the shank below it turn against each other about one axis (a hinge,
Hu 2021 eq. 12), a thigh and the other leg's shank do not: the gyro-only hinge fit of the two
knees as given leaves far less than with the thighs (or the shanks) exchanged. Likewise the
ankles for the feet, though less sharply (an ankle is no hinge). Measured (the sum over both legs
of the hinge fit's RMS residual, crossed / as given): simulated seven-IMU walks (seeds 201–206,
normal, slow and shuffling paces, treadmill, turns) knees 8–92, ankles 1.1–4.5; with the
real-walk artefacts knees 1.2–3.2, ankles 1.0–1.5; the real walk of ``gait/`` knees 1.37, ankles
4.5 (``benchmarks/results/input_checks.md``; over seeds 201–230 at least 1.14 and 0.98). So an
exchange is refused when the crossed pairing leaves less than ``knee_ratio`` (0.8) or
``ankle_ratio`` (0.7) times the pairing as given. Which segment was exchanged: thighs and
shanks both cross the knees; exchanged shanks also cross the ankles, exchanged thighs do not;
exchanged feet cross the ankles alone. Where the ankles read within ``ankle_margin`` of 1, the
message names both candidates. On those 37 recordings, each with each segment's sensors
exchanged: no valid one refused; thighs named 34 of 37 and shanks 35 of 37, 2 of each as "thigh
or shank", none wrongly (the miss, with artefacts, left the knees at 0.83); feet 17 of 37 (the
real walk's among them: ankles that are no hinges cross as poorly as they pair). The test costs
0.4–0.7 s per trial (eight hinge fits of 1000 samples).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

from lowerlimb.calibration.hinge_axis import fit_hinge_axis
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.constraints.prefilter import lowpass
from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError
from lowerlimb.io.bilateral_trial import BilateralTrial

__all__ = ["CrossedLegsError", "LegPairing", "LegPairingParams", "check_leg_pairing", "leg_pairing"]


@dataclass(frozen=True)
class LegPairingParams:
    """Thresholds of the exchanged-sensor test.

    Attributes:
        knee_ratio: thighs or shanks are exchanged when the knees crossed leave less than this
            fraction of the knees as given (valid: at least 1.2 on every recording measured).
        ankle_ratio: feet are exchanged when the ankles crossed leave less than this fraction of
            the ankles as given (valid: at least 1.04).
        lowpass_hz: the gyros are low-passed at this cut-off first, Hz (impacts and wobble out).
        max_samples: each hinge is fitted on at most this many evenly spaced samples.
        hinge_starts: starting axis pairs of each hinge fit besides the principal axes
            (:attr:`~lowerlimb.calibration.options.CalibrationOptions.hinge_starts`).
        max_iter: Gauss–Newton iterations of each start (the test compares residual levels:
            a crossed pair's fit need not converge to tell).
        ankle_margin: with the knees crossed, the ankles' crossed / as-given ratio within this
            of 1 cannot tell exchanged thighs from exchanged shanks (valid ankles: 0.98 and up).
    """

    knee_ratio: float = 0.8
    ankle_ratio: float = 0.7
    lowpass_hz: float = 6.0
    max_samples: int = 1000
    hinge_starts: int = 1
    max_iter: int = 20
    ankle_margin: float = 0.05


@dataclass(frozen=True)
class LegPairing:
    """The two legs' knee and ankle hinge residuals, as given and crossed (rad/s, sums over both legs)."""

    knees: float
    knees_crossed: float
    ankles: float
    ankles_crossed: float

    def exchanged(self, params: LegPairingParams) -> str | None:
        """``"thigh"``, ``"shank"``, ``"thigh or shank"``, ``"foot"`` or ``None``: which are exchanged."""
        if self.knees_crossed < params.knee_ratio * self.knees:
            ankles = self.ankles_crossed / self.ankles
            if abs(ankles - 1.0) <= params.ankle_margin:
                return "thigh or shank"  # the ankles cannot tell
            return "shank" if ankles < 1.0 else "thigh"
        if self.ankles_crossed < params.ankle_ratio * self.ankles:
            return "shank" if self.knees_crossed < self.knees else "foot"  # both joints lean to crossing
        return None


class CrossedLegsError(InputError):
    """One segment's sensors look exchanged between the legs; carries both residuals (rad/s)."""

    def __init__(self, segment: str, as_given: float, crossed: float) -> None:
        self.segment = segment
        self.as_given, self.crossed = as_given, crossed
        joint = "ankle" if segment == "foot" else "knee"
        if segment == "thigh or shank":
            super().__init__(
                f"the left and right thigh or shank columns look swapped: the two knees fit as hinges "
                f"with {as_given:.3f} rad/s RMS as given and {crossed:.3f} rad/s with the left and right "
                f"thigh (or shank) sensors exchanged, and the ankles cannot tell which; exchange the "
                f"left_thigh_* and right_thigh_* columns or the left_shank_* and right_shank_* ones, "
                f"whichever were mixed up (or pass --no-order-check if the trial is right)"
            )
            return
        super().__init__(
            f"the left_{segment} and right_{segment} columns look swapped: the two {joint}s fit as "
            f"hinges with {as_given:.3f} rad/s RMS as given and {crossed:.3f} rad/s with the left and "
            f"right {segment} sensors exchanged; exchange the left_{segment}_* and right_{segment}_* "
            f"columns (or pass --no-order-check if the trial is right)"
        )


def _hinge_rms(wp: FloatArray, wc: FloatArray, rate_hz: float, params: LegPairingParams) -> float:
    """RMS residual of the gyro-only hinge fit of two sensors' prepared gyros (Hu 2021 eq. 12), rad/s.

    ``wp``, ``wc``: (M, 3) low-passed, subsampled gyros, rad/s; ``rate_hz``: their rate, Hz.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        options = CalibrationOptions(hinge_starts=params.hinge_starts, max_iter=params.max_iter)
        fit = fit_hinge_axis(wp, wc, rate_hz=rate_hz, method="gn", options=options)
    return float(fit.rms_residual)


def leg_pairing(trial: BilateralTrial, params: LegPairingParams | None = None) -> LegPairing:
    """The knees' and ankles' hinge residuals of a two-leg trial, as given and crossed."""
    p = params or LegPairingParams()
    rate = trial.rate_hz
    step = max(1, trial.time_s.size // p.max_samples)
    cut = min(p.lowpass_hz, 0.45 * rate)
    g = {  # each leg sensor's gyro low-passed and subsampled once
        f"{side}_{seg}": lowpass(trial.gyr[f"{side}_{seg}"], rate, cut, order=2)[::step]
        for side in ("left", "right")
        for seg in ("thigh", "shank", "foot")
    }

    def pair(upper: str, lower: str, crossed: bool) -> float:
        other = {"left": "right", "right": "left"}
        return sum(
            _hinge_rms(g[f"{side}_{upper}"], g[f"{other[side] if crossed else side}_{lower}"], rate / step, p)
            for side in ("left", "right")
        )

    return LegPairing(
        pair("thigh", "shank", False), pair("thigh", "shank", True), pair("shank", "foot", False),
        pair("shank", "foot", True),
    )  # fmt: skip


def check_leg_pairing(trial: BilateralTrial, params: LegPairingParams | None = None) -> None:
    """Refuse a two-leg trial one of whose segments' sensors are exchanged between the legs.

    Raises:
        CrossedLegsError: naming the segment and both residuals.
    """
    p = params or LegPairingParams()
    found = leg_pairing(trial, p)
    segment = found.exchanged(p)
    if segment == "foot":
        raise CrossedLegsError(segment, found.ankles, found.ankles_crossed)
    if segment is not None:
        raise CrossedLegsError(segment, found.knees, found.knees_crossed)
