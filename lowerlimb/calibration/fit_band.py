"""The band a leg's joints are fitted in: wider than the coherent band, unless that breaks the leg.

Why: each joint's sensor pair is low-passed at most at the edge of the band in which the
two sensors move as one rigid chain (the rigid-band cap,
:func:`~lowerlimb.calibration._prepare.rigid_band_cap_hz`), and a pair with impacts at most
at the impact limit (:mod:`~lowerlimb.calibration.impact_window`). That is what lets a real
walk with soft-tissue wobble calibrate at all. But a filter at the edge of the joint's
band also attenuates the joint's own motion there, and the low-passed norm form of Hu et
al. 2021 eq. 3 then places the centres too near the sensors. On the rigid seven-IMU
simulator (``simulate_bilateral`` seeds 201–206, twelve legs; ``benchmarks/length_variants.py``,
``benchmarks/gait.py``) with every cap at the band's edge:

* thigh −20.8 mm and shank −23.6 mm mean length error (79 / 78 mm worst);
* the hip in the pelvis sensor 33 mm worst, in the thigh sensor 41 mm, the ankle in the
  shank sensor 134 mm, in the foot sensor 27 mm; the knee axis 0.9°.

With the caps widened by half (:attr:`~CalibrationOptions.fit_band_factor` 1.5; the
sensors' own noise-limited cut-offs stay):

* thigh −4.6 mm and shank −8.6 mm (22 / 46 mm worst; 2.6 / 1.6 mm median);
* the hip 17 / 18 mm worst, the ankle 52 / 9 mm, the knee axis 0.2°; step width 9.9 mm
  median (13.1), 33 mm worst (45); the angles within 0.1°.

The wider band is not always safe. On the real walk of ``gait/`` the left leg's knee,
fitted in it, leaves its axis line 70 mm from the hip (a knee centre on the thigh
sensor's far side, beside the hip: the sensor's wobble above the coherent band is
not a hinge's motion); at the band's edge the thigh is 10 mm from Plug-in Gait's. On
its right leg the widened band kept a plausible leg (thigh +29 → −11 mm against Plug-in
Gait) but moved the knee 8 cm along its axis: the ankle's sideways place in the chain
(the two ankles 29.0 → 18.9 cm apart sideways at standing) and the step width error
(12 → 102 mm median) with it. Both legs' sensors show that they are not rigid on the
bone: the knee axis seen from the thigh and from the shank sensor differs by 17–18° in
elevation at standing, where a hinge keeps it equal (the simulator's rigid sensors: 0.1°).
That rule rests on one real recording. The threshold, 6°: an ideal hinge keeps the two
estimates equal (the rigid simulator: ≤ 0.2°), but a real knee turns as it flexes. The
simulator's knees that turn inwards by 0.2 rad per rad of flexion (about 11° over a stride)
show 3–4° on rigid sensors; at the earlier threshold, 2°, their legs kept the coherent band
(thigh −22 mm and shank −37 mm mean length error, step width 125 mm worst), at 6° they are
widened (−12 and −20 mm, 44 mm; ``benchmarks/results/gait_knee_rotation.md``). The real
walk's 17–24° stay far beyond it. With the simulator's real-walk artefacts, a worst case
harsher than the real walk (``sim_signatures.md``), the legs show 0.1–7.8°, neither band gives
lengths within centimetres, and the change from 2° to 6° is mixed there (``gait_artefacts.md``:
initial contact 12.3 → 9.4 ms median, step width 98 → 83 mm, but thigh 50 → 64 mm).

So :func:`~lowerlimb.calibration.leg.calibrate_leg` fits the leg in the coherent band, as
the options give it, and then, where a coherent-band cap lowered a joint's cut-offs
(:attr:`FitBand.capped`; else the widened band gives the same fit, :data:`NO_CAP_BINDS`),
in the widened band. It keeps the widened fit unless that fit shows that the sensors do not
sit rigidly: the two knee axis
estimates disagree at standing by more than ``fit_band_max_mismatch_deg``
(:func:`axis_mismatch_reason`, checked as soon as the knee is fitted; the knee's own
mismatch warning then says so), or a segment is implausible (:func:`implausible_segment`,
with a warning of its own). The coherent fit is kept beside a widened one
(``LegCalibration.coherent_fit``) for the clock search. With two cores the widened fit runs
beside the coherent one, in a forked child dropped where no cap binds
(:class:`~lowerlimb.side_by_side.Beside`); the fits are the same. A trial without a standing start
reads the knee's mismatch over the motion instead (:func:`moving_mismatch_reason`,
:func:`~lowerlimb.calibration.knee_line.moving_axis_mismatch`; since 0.5.15): the simulated
two-leg walks cut mid-stride are widened as their whole walks are and land within 2 mm of
them (they kept the coherent band before: thighs down to −82 mm, shanks down to −82 mm), and
the real walk cut after its standing start keeps the coherent band (17 / 22° over the
motion), unchanged (``benchmarks/results/cut_start.md``).
``CalibrationOptions.fit_band_without_standing=False`` keeps such a trial in the coherent band.

The caps can also be wrong the other way. They end a joint's band where the two sensors'
acceleration norms stop being coherent, which soft tissue does, but so does rigid rotation
about the hip: the pelvis and the thigh sensor see different centripetal and tangential
accelerations. A simulated shuffling walk with turns about (seed 203) had both hip pairs
capped at the 2 Hz floor, both legs implausible in both bands (thighs 144–229 mm), and fell
back on de Leva. So where the coherent and the widened fit are both implausible and the knee
shows rigid sensors, the leg is fitted once more without the caps and kept if plausible
(:attr:`FitBand.uncapped`; there the hips and ankles came out 1–3 mm from the truth).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np

from lowerlimb.calibration.geometry import distance_to_line
from lowerlimb.calibration.knee_line import moving_axis_mismatch, standing_axis_mismatch
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.calibration.results import HingeJointCalibration, SphericalJointCalibration
from lowerlimb.conventions import FloatArray

__all__ = [
    "NO_CAP_BINDS",
    "NO_STANDING_START",
    "FitBand",
    "axis_mismatch_reason",
    "implausible_segment",
    "moving_mismatch_reason",
    "segment_lengths_m",
    "widened_caps",
]


class _LegJoints(Protocol):
    hip: SphericalJointCalibration
    knee: HingeJointCalibration
    ankle: SphericalJointCalibration


def widened_caps(options: CalibrationOptions) -> CalibrationOptions:
    """The options with the rigid-band caps widened by ``fit_band_factor`` (``rigid_band_factor``).

    The sensors' own adaptive cut-offs (a noise-limited bandwidth, ``cutoff_factor``) and the
    impact limit are not widened: widening the adaptive cut-offs too put a one-leg simulated
    walk's ankle 16 mm off in the shank sensor instead of 9 mm.
    """
    return replace(options, rigid_band_factor=options.rigid_band_factor * options.fit_band_factor)


def segment_lengths_m(leg: _LegJoints) -> tuple[float, float]:
    """Thigh and shank length, m: the hip and the ankle centre's distance from the knee axis line.

    Args:
        leg: calibrated hip, knee and ankle (the thigh length in the thigh sensor frame, the
            shank length in the shank sensor frame).
    """
    k = leg.knee
    return (
        distance_to_line(leg.hip.center_in_child_sensor, k.center_in_parent_sensor, k.axis_in_parent_sensor),
        distance_to_line(leg.ankle.center_in_parent_sensor, k.center_in_child_sensor, k.axis_in_child_sensor),
    )


def implausible_segment(leg: _LegJoints, options: CalibrationOptions) -> str | None:
    """Why a leg's thigh or shank is implausible, or ``None`` when both are plausible.

    A segment is plausible when its length (:func:`segment_lengths_m`) lies within
    ``fit_band_min_ratio`` … ``fit_band_max_ratio`` times its anthropometric length at the
    prior's stature (``thigh_length_per_stature`` × ``prior_stature_m``, the same for the shank).
    """
    out = []
    for name, length, per_stature in zip(
        ("thigh", "shank"),
        segment_lengths_m(leg),
        (options.thigh_length_per_stature, options.shank_length_per_stature),
        strict=True,
    ):
        expected = per_stature * options.prior_stature_m
        lo, hi = options.fit_band_min_ratio * expected, options.fit_band_max_ratio * expected
        if not lo <= length <= hi:
            mm = f"{length * 1000:.0f} mm long, plausible {lo * 1000:.0f}–{hi * 1000:.0f} mm"
            out.append(f"the {name} {mm}")
    return " and ".join(out) or None


def axis_mismatch_reason(
    knee: HingeJointCalibration, up_thigh: FloatArray, up_shank: FloatArray, options: CalibrationOptions
) -> str | None:
    """Why a widened fit's knee shows sensors that are not rigid (``None``: it does not).

    Args:
        knee: the widened fit's knee.
        up_thigh: (3,) mean thigh accelerometer over the standing start, sensor frame, m/s².
        up_shank: the same for the shank.
        options: ``fit_band_max_mismatch_deg``.

    Returns:
        The reason when the knee axis's elevation above the standing horizontal, seen from the
        thigh and from the shank sensor, differs by more than ``fit_band_max_mismatch_deg``.
    """
    mismatch = float(np.degrees(standing_axis_mismatch(knee, up_thigh, up_shank)))
    if abs(mismatch) <= options.fit_band_max_mismatch_deg:
        return None
    return (
        f"the knee axis seen from the thigh and from the shank sensor differs by "
        f"{abs(mismatch):.0f}° in elevation at standing"
    )


def moving_mismatch_reason(
    knee: HingeJointCalibration,
    acc_thigh: FloatArray,
    acc_shank: FloatArray,
    rate_hz: float,
    options: CalibrationOptions,
) -> str | None:
    """:func:`axis_mismatch_reason` for a trial without a standing start: the mismatch over the motion.

    Args:
        knee: the widened fit's knee.
        acc_thigh: (N, 3) the thigh accelerometer, sensor frame, m/s².
        acc_shank: (N, 3) the shank accelerometer, sensor frame, m/s².
        rate_hz: sampling rate, Hz.
        options: ``fit_band_max_mismatch_deg``, ``moving_mismatch_lowpass_hz``.

    Returns:
        The reason when the median elevation difference
        (:func:`~lowerlimb.calibration.knee_line.moving_axis_mismatch`) exceeds
        ``fit_band_max_mismatch_deg``.
    """
    rad = moving_axis_mismatch(knee, acc_thigh, acc_shank, rate_hz, options.moving_mismatch_lowpass_hz)
    mismatch = float(np.degrees(rad))
    if abs(mismatch) <= options.fit_band_max_mismatch_deg:
        return None
    return (
        f"the knee axis seen from the thigh and from the shank sensor differs by "
        f"{abs(mismatch):.0f}° in elevation over the motion (median; no standing start)"
    )


#: :attr:`FitBand.reason` of a trial without a standing start fitted with
#: ``fit_band_without_standing=False``: nothing was read to show that its sensors are rigid.
NO_STANDING_START = "no standing start, where the two knee axis estimates would show rigid sensors"

#: :attr:`FitBand.reason` of a leg whose coherent-band caps lowered no cut-off: both bands give one fit.
NO_CAP_BINDS = "no rigid-band cap lowered a cut-off, so the widened band would give the same fit"


@dataclass(frozen=True)
class FitBand:
    """The band the leg's joints were fitted in (calibration.json ``fit_band``).

    Attributes:
        factor: the widening tried, ``CalibrationOptions.fit_band_factor`` (1: none).
        widened: whether the joints come from the widened band.
        reason: why the widened fit was not kept (``None`` when it was, or none was tried).
        capped: the joint sensor pairs (``"parent-child"``) whose cut-offs the coherent band's
            caps lowered; the band matters only for these (empty: it made no difference, or
            no coherent fit was made).
        uncapped: the joints come from a fit without the rigid-band caps, because the leg was
            implausible in both bands while its knee showed rigid sensors (``reason`` says
            why the widened fit was not kept).
    """

    factor: float = 1.0
    widened: bool = False
    reason: str | None = None
    capped: tuple[str, ...] = ()
    uncapped: bool = False

    def to_dict(self) -> dict[str, Any]:
        """The calibration.json record."""
        return {
            "factor": float(self.factor),
            "widened": bool(self.widened),
            "reason": self.reason,
            "capped": list(self.capped),
            "uncapped": bool(self.uncapped),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any] | None) -> FitBand:
        """Inverse of :meth:`to_dict` (``None`` or empty: an older calibration, nothing tried)."""
        if not d:
            return cls()
        capped = tuple(str(k) for k in d.get("capped", ()))
        widened, uncapped = bool(d.get("widened", False)), bool(d.get("uncapped", False))
        return cls(float(d.get("factor", 1.0)), widened, d.get("reason"), capped, uncapped)

    def uncapped_message(self, coherent_reason: str) -> str:
        """The warning of a leg refitted without the rigid-band caps."""
        return (
            f"calibration: the leg was implausible both where its sensors' acceleration norms are "
            f"coherent ({coherent_reason}) and in a band {self.factor:g}× wider ({self.reason}), while "
            f"its knee showed sensors rigid on the bone; fitted without the rigid-band caps, as "
            f"rotation about the hip (turns about, a shuffling gait) also makes the norms incoherent"
        )

    def fallback_message(self) -> str:
        """The warning of a leg refitted in the coherent band."""
        return (
            f"calibration: fitted in a band {self.factor:g}× wider than where its sensors move as one "
            f"chain, the leg was implausible ({self.reason}), so its joints were fitted within that "
            f"band, where segment lengths can come out a few centimetres short; above it the sensors "
            f"move against the bone (soft tissue, loose straps)"
        )
