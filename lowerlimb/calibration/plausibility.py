"""Is the trial what the user said it is? Swapped sensor columns and the wrong ``--side``.

Two mistakes give plausible-looking numbers and exit 0 unless they are caught:

- **Swapped columns** (thigh data under ``shank_*`` and the other way round, or
  shank and foot). The joint constraints themselves tell: the pelvis and the
  real thigh share a joint centre, so the spherical residual (Hu 2021 eq. 7)
  of pelvis–thigh is far below that of pelvis–shank, and that of shank–foot
  below that of thigh–foot (the two joints whose pairs change when thigh and
  shank are exchanged; their residuals are summed); likewise the thigh and
  the real shank share the knee, the thigh and the foot share no point. When
  the alternative pairing fits clearly better (its residual below
  ``swap_ratio`` times the assumed one), the columns are swapped. The two pairings
  are seen through one filter, the lower of their rigid-band caps: a pair that shares
  no joint gets a low cap, and its residual, measured in a narrower band, looked
  better than the real joint's (``_lower_cap``).

  When only the knee says "shank and foot", the gyros get a say: a knee lift barely
  moves the ankle, so the foot shares the knee almost as well as the shank, and the
  shank's soft tissue made a valid simulated knee lift (artefact profile, seed 2) fit
  0.11 m/s² with the foot against 0.19 with the shank. The knee is a hinge and the
  thigh–foot pair is not (it carries the ankle too): when the gyro-only hinge fit
  (eq. 12) leaves ``swap_hinge_veto`` times more with the foot than with the shank, the
  shank/foot verdict is dropped. The ankle's term alone then decides whether the
  thigh and shank are the exchanged pair (in a squat with artefacts the pelvis's noise,
  0.34 m/s² either way, drowned it in the summed test, and the knee's test named the
  wrong pair), and only where the summed hip-and-ankle test leans the same way (the
  knee's vetoed verdict with an ankle that barely moves, as in a knee lift or a squat, let
  the ankle's term alone refuse five valid trials with soft tissue whose summed test
  favoured the columns as given by 1.35–3.9×); otherwise a :class:`SwapVetoWarning` says
  what was kept. On 72 simulated
  one-leg trials (6 motions × seeds 1–6, rigid and with artefacts), each as given and
  with each of the two swaps: false refusals 2 → 0 (a knee lift and a sit-to-stand, both
  with artefacts), thigh/shank swaps named 69 → 71 (the two others had been named
  shank/foot), shank/foot swaps caught 53 either way; nothing else changed.
- **The wrong leg** (a left-leg trial run with ``--side right``). The knee axis
  is signed by flexion, so it points to the subject's right whatever the side
  given; in the pelvis segment frame built from it (z to the right), the hip
  centre of a left leg lies to the left of a pelvis sensor on the sacrum
  (negative z, about 5–10 cm) and that of a right leg to the right. A lateral
  offset beyond ``side_min_offset_m`` with the sign of the other side means the
  side is wrong. A pelvis sensor far off the midline defeats the test, hence
  ``check_side=False`` (CLI ``--no-side-check``).

  The hip centre in a sacral sensor is the least determined quantity of walking: soft
  tissue and impacts move its lateral coordinate by centimetres to decimetres (on the
  simulator's real-walk artefacts it lay on the wrong side in 4 of 10 one-leg walks,
  each refused). So the verdict needs a second witness that no joint centre enters:
  **the pelvis turns with the swinging leg** (Perry & Burnfield 2010: it rotates about
  ±4° so that the swinging side advances), clockwise seen from above while a left thigh
  flexes, anticlockwise for a right one. The correlation of the pelvis's rate about the
  vertical with the thigh's flexion rate (:func:`pelvis_turn_side_cue`) is negative for a
  left leg and positive for a right one (real walk: −0.26 / +0.30). When it confirms the
  side given at least ``side_cue_min_corr`` strongly, a contrary hip position gives a
  :class:`SideEvidenceWarning`, not an error. When it names the other side, as the hip
  does, the two witnesses decide together even if the hip's offset is within
  ``side_min_sigmas`` of its spread (the real walk's left leg given as right: 3.3 cm,
  1.8 σ, cue −0.26). Motions without a gait (squats) leave it near zero and the hip decides
  alone, clear of its spread.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace
from functools import cache

import numpy as np
from scipy.signal import butter, sosfiltfilt

from lowerlimb.calibration._prepare import PreparedSignals, joint_signals, rigid_band_cap_hz
from lowerlimb.calibration._solve import subsample_step
from lowerlimb.calibration.hinge_axis import fit_hinge_axis
from lowerlimb.calibration.joint_center import fit_spherical
from lowerlimb.calibration.options import CalibrationOptions
from lowerlimb.conventions import FloatArray
from lowerlimb.errors import InputError

__all__ = [
    "PlausibilityParams",
    "SensorOrderError",
    "SIDE_MIN_MOTION_S",
    "SideEvidenceWarning",
    "SwapVetoWarning",
    "WrongSideError",
    "check_sensor_order",
    "check_side",
    "pelvis_turn_side_cue",
]


@dataclass(frozen=True)
class PlausibilityParams:
    """Thresholds of the plausibility checks.

    Attributes:
        swap_ratio: the alternative pairing's residual must be below this fraction
            of the assumed pairing's for the columns to count as swapped.
        side_min_offset_m: lateral hip offset from the pelvis sensor, in the pelvis
            segment frame, beyond which the side is decided, m.
        side_max_offset_m: beyond this lateral offset the hip centre itself is
            implausible (a poor calibration) and no side verdict is given, m.
        side_min_sigmas: the lateral offset must also exceed this many standard
            deviations of the hip centre (along its most poorly determined direction):
            a nearly planar walk leaves the hip centre unobservable, and its sign then
            says nothing about the side.
        order_check_samples: the swap test fits each pairing on at most this many
            evenly spaced samples (it compares two residual levels; a long trial's
            every sample only makes it slower).
        swap_hinge_veto: a shank/foot swap found by the knee's centre is not refused when
            the gyro-only hinge fit (eq. 12) of thigh and foot leaves more than this
            many times the residual of thigh and shank (the knee as given is the better
            hinge). Simulated one-leg motions, no swap: thigh–foot 1.6–22× thigh–shank
            (0.8–0.95× on walks with the artefact profile, whose shank gyro carries the
            impacts); swapped, the ratio inverts. Squats, half-squats, sit-to-stands and knee
            lifts with the artefact profile (seeds 3001–3022, 20 s): 0.75–8.3× (median 2.8)
            as given, 0.12–1.34× (median 0.36) with shank and foot exchanged; at 1.5 two
            valid trials (1.47×, 1.49×) were refused. The real walk's legs: 1.08 / 1.06× as
            given, 0.93 / 0.95× exchanged (its knees are no better hinges than its ankles),
            so the veto sits between those and the valid trials' 1.47.
        side_cue_lowpass_hz: low-pass cut-off of the two rates of the pelvis-turn cue, Hz
            (the stride's fundamental is ~1 Hz, impacts and wobble lie far above).
        side_cue_min_corr: least magnitude of the pelvis-turn correlation that counts as
            a witness for a side (one-leg simulated walks: 0.2–0.3; squats: ~0).
    """

    swap_ratio: float = 0.7
    side_min_offset_m: float = 0.03
    side_max_offset_m: float = 0.2
    side_min_sigmas: float = 2.0
    order_check_samples: int = 1500
    swap_hinge_veto: float = 1.2
    side_cue_lowpass_hz: float = 3.0
    side_cue_min_corr: float = 0.15


#: Least motion after the standing start for a side verdict, s: with a second of walking
#: (a 2 s trial) the hip centre lands anywhere and a left leg was called a right one.
SIDE_MIN_MOTION_S = 2.0


class SwapVetoWarning(UserWarning):
    """The knee's centre says shank and foot are swapped; its hinge says they are not."""


class SensorOrderError(InputError):
    """Two sensors' columns look swapped; carries both residuals (m/s²)."""

    def __init__(self, first: str, second: str, assumed_rms: float, swapped_rms: float, joint: str) -> None:
        self.first, self.second = first, second
        self.assumed_rms, self.swapped_rms = assumed_rms, swapped_rms
        super().__init__(
            f"the {first} and {second} columns look swapped: as given, the {joint} constraints leave "
            f"{assumed_rms:.2f} m/s² RMS, with the two sensors exchanged {swapped_rms:.2f} m/s²; "
            f"exchange the {first}_* and {second}_* columns (or pass --no-order-check if the "
            f"trial is right)"
        )


class WrongSideError(InputError):
    """The calibrated geometry belongs to the other leg; carries the lateral offset (m)."""

    def __init__(self, side: str, lateral_m: float, *, fix: str = "", no_check: str = "") -> None:
        """The error for ``side`` and the hip centre's lateral offset ``lateral_m`` (m).

        ``fix`` says how to give the other side and ``no_check`` how to turn the check off
        (default: ``calibrate``'s options ``--side`` and ``--no-side-check``).
        """
        self.side = side
        self.lateral_m = lateral_m
        other = "right" if side == "left" else "left"
        where = "right" if lateral_m > 0 else "left"
        fix = fix or f"rerun with --side {other}"
        no_check = no_check or "pass --no-side-check"
        super().__init__(
            f"this looks like a {other} leg, not {side}: the calibrated hip centre lies "
            f"{abs(lateral_m) * 100:.1f} cm to the {where} of the pelvis sensor; {fix} (a pelvis "
            f"accelerometer that reads -9.81 along up at rest mirrors the hip too: negate its acc "
            f"columns; or {no_check} if the pelvis sensor is not on the sacrum)"
        )


def _residual(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    sig: PreparedSignals,
    parent: str,
    child: str,
    options: CalibrationOptions,
    max_samples: int,
    cap_hz: float | None = None,
) -> float:
    """RMS residual of a quiet spherical fit of the pair, filtered at the caller's cap (Hz)."""
    quiet = replace(options, center_std_tol_m=np.inf, min_rms_rate_rps=0.0, noise_correction=False)
    data = joint_signals(acc, gyr, sig, parent, child, quiet, cap_hz=cap_hz, own_band=False)
    data = data.subsample(subsample_step(data.n_samples, max_samples))
    return fit_spherical(data, method="gn", options=quiet).rms_residual


def _lower_cap(caps: tuple[float | None, float | None]) -> float | None:
    """The lower rigid-band cap of two alternative pairs (Hz, ``None``: neither is capped).

    A residual's RMS grows with the band it is measured in: two pairs are compared seen
    through one filter, or a pair that is no joint (thigh–foot), whose accelerometer norms
    never agree and whose rigid band therefore caps it low (2 Hz), fits "better" than the
    joint it stands in for, seen unfiltered with its soft tissue (a slow simulated walk
    with the real-walk artefacts: 0.71 against 2.31 m/s² at the knee, refused as swapped).
    """
    given = [c for c in caps if c is not None]
    return min(given) if given else None


def check_sensor_order(
    acc: Mapping[str, FloatArray],
    gyr: Mapping[str, FloatArray],
    sig: PreparedSignals,
    options: CalibrationOptions,
    params: PlausibilityParams | None = None,
) -> None:
    """Refuse a trial whose thigh/shank or shank/foot columns are swapped (module docstring).

    Args:
        acc: ``{sensor: (N, 3)}`` raw accelerometers of pelvis, thigh, shank, foot, m/s².
        gyr: ``{sensor: (N, 3)}`` raw gyros, rad/s.
        sig: the prepared signals of the four sensors.
        options: calibration options.
        params: thresholds (defaults: :class:`PlausibilityParams`).

    Raises:
        SensorOrderError: naming the two sensors and both residuals.
    """
    p = params or PlausibilityParams()

    @cache
    def own_cap(pair: tuple[str, str]) -> float | None:
        return rigid_band_cap_hz(
            acc[pair[0]], acc[pair[1]], sig.rate_hz, options, np.hstack([gyr[pair[0]], gyr[pair[1]]])
        )

    def res(parent: str, child: str, rival: tuple[str, str]) -> float:
        """The pair's residual, seen through the filter of its ``rival`` pair too."""
        cap = _lower_cap((own_cap((parent, child)), own_cap(rival)))
        return _residual(acc, gyr, sig, parent, child, options, p.order_check_samples, cap)

    # thigh/shank exchanged: hip(pelvis, thigh) + ankle(shank, foot) against
    # hip(pelvis, shank) + ankle(thigh, foot); the knee pair is the same either way
    ankle = {
        "shank": res("shank", "foot", ("thigh", "foot")),
        "thigh": res("thigh", "foot", ("shank", "foot")),
    }
    assumed_th = res("pelvis", "thigh", ("pelvis", "shank")) + ankle["shank"]
    swapped_th = res("pelvis", "shank", ("pelvis", "thigh")) + ankle["thigh"]
    if swapped_th < p.swap_ratio * assumed_th:
        raise SensorOrderError("thigh", "shank", assumed_th, swapped_th, "hip and ankle")
    # shank/foot exchanged: knee(thigh, shank) against knee(thigh, foot); the ankle
    # pair is the same either way and the hip does not involve them
    assumed, swapped = res("thigh", "shank", ("thigh", "foot")), res("thigh", "foot", ("thigh", "shank"))
    if not swapped < p.swap_ratio * assumed:
        return
    h_shank = _hinge_residual(sig, "thigh", "shank", options, p.order_check_samples)
    h_foot = _hinge_residual(sig, "thigh", "foot", options, p.order_check_samples)
    if not h_foot > p.swap_hinge_veto * h_shank:
        raise SensorOrderError("shank", "foot", assumed, swapped, "knee")
    # as given the knee is the better hinge: a knee centre that fits the foot better then
    # comes from thigh data in the shank columns when the ankle says so too (the hip's
    # term, in a squat, is the pelvis's noise either way)
    if ankle["thigh"] < p.swap_ratio * ankle["shank"] and swapped_th < assumed_th:
        raise SensorOrderError("thigh", "shank", assumed_th, swapped_th, "hip and ankle")
    warnings.warn(
        SwapVetoWarning(
            f"the knee's centre fits {swapped:.2f} m/s² with the shank and foot columns exchanged "
            f"against {assumed:.2f} as given, but as given the knee is the better hinge "
            f"({h_shank:.3f} against {h_foot:.3f} rad/s); kept the columns (soft tissue on the "
            f"shank, with an ankle that barely moves, can do this)"
        ),
        stacklevel=3,
    )


def _hinge_residual(
    sig: PreparedSignals, parent: str, child: str, options: CalibrationOptions, max_samples: int
) -> float:
    """RMS residual of a quiet hinge fit of two sensors' gyros (Hu 2021 eq. 12), rad/s."""
    step = subsample_step(sig.gyr[parent].shape[0], max_samples)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        wp, wc = sig.gyr[parent][::step], sig.gyr[child][::step]
        fit = fit_hinge_axis(wp, wc, rate_hz=sig.rate_hz / step, method="gn", options=options)
    return fit.rms_residual


class SideEvidenceWarning(UserWarning):
    """The hip centre lies on the other side, but the pelvis's turning confirms the side given."""


def pelvis_turn_side_cue(
    gyr_pelvis: FloatArray,
    gyr_thigh: FloatArray,
    knee_axis_in_thigh: FloatArray,
    up_in_pelvis: FloatArray,
    rate_hz: float,
    params: PlausibilityParams | None = None,
) -> float:
    """Correlation in [−1, 1] of the pelvis's turning with the thigh's flexion: < 0 left, > 0 right.

    Args:
        gyr_pelvis: (N, 3) pelvis gyro, pelvis sensor frame, rad/s.
        gyr_thigh: (N, 3) thigh gyro, thigh sensor frame, rad/s.
        knee_axis_in_thigh: (3,) the knee axis (pointing right) in the thigh sensor frame.
        up_in_pelvis: (3,) the upward direction in the pelvis sensor frame (any length).
        rate_hz: sampling rate, Hz.
        params: the low-pass cut-off (defaults: :class:`PlausibilityParams`).

    Returns:
        The correlation; 0 when either rate is constant.
    """
    p = params or PlausibilityParams()
    up = np.asarray(up_in_pelvis, dtype=float)
    axis = np.asarray(knee_axis_in_thigh, dtype=float)
    turn = np.asarray(gyr_pelvis, dtype=float) @ (up / np.linalg.norm(up))
    flex = np.asarray(gyr_thigh, dtype=float) @ (axis / np.linalg.norm(axis))
    if p.side_cue_lowpass_hz < 0.45 * rate_hz and turn.shape[0] > 30:
        sos = butter(2, p.side_cue_lowpass_hz, fs=rate_hz, output="sos")
        turn, flex = sosfiltfilt(sos, turn), sosfiltfilt(sos, flex)
    if not (np.std(turn) > 0 and np.std(flex) > 0):
        return 0.0
    return float(np.corrcoef(turn, flex)[0, 1])


def check_side(
    side: str,
    hip_from_pelvis_sensor: FloatArray,
    params: PlausibilityParams | None = None,
    *,
    hip_std_m: float = 0.0,
    pelvis_turn: float | None = None,
) -> None:
    """Refuse a side contradicted by the calibrated hip position (module docstring).

    Args:
        side: the side given, ``"left"`` or ``"right"``.
        hip_from_pelvis_sensor: (3,) hip centre minus pelvis sensor origin, in the
            pelvis segment frame (ISB: x anterior, y up, z right), m.
        params: thresholds (defaults: :class:`PlausibilityParams`).
        hip_std_m: standard deviation of the calibrated hip centre along its most poorly
            determined direction, m (0 when unknown).
        pelvis_turn: the pelvis-turn cue (:func:`pelvis_turn_side_cue`), or ``None``.

    Raises:
        WrongSideError: with the lateral offset, unless the pelvis-turn cue confirms ``side``.

    Warns:
        SideEvidenceWarning: the hip says the other side, the pelvis-turn cue this one.
    """
    p = params or PlausibilityParams()
    lateral = float(np.asarray(hip_from_pelvis_sensor, dtype=float)[2])
    if not p.side_min_offset_m <= abs(lateral) <= p.side_max_offset_m:
        return
    if (lateral > 0) == (side == "right"):
        return
    cue = 0.0 if pelvis_turn is None or abs(pelvis_turn) < p.side_cue_min_corr else pelvis_turn
    if cue != 0.0 and (cue > 0) == (side == "right"):
        where = "right" if lateral > 0 else "left"
        warnings.warn(
            SideEvidenceWarning(
                f"the calibrated hip centre lies {abs(lateral) * 100:.1f} cm to the {where} of the pelvis "
                f"sensor, as for a {'right' if lateral > 0 else 'left'} leg, but the pelvis turns with this "
                f"leg's swing as with a {side} leg (correlation {pelvis_turn:+.2f}); kept {side}: the hip "
                f"centre in the pelvis sensor is unreliable in this trial"
            ),
            stacklevel=2,
        )
        return
    # the hip alone must stand clear of its spread; with the turn cue as a second witness it need not
    if cue == 0.0 and not abs(lateral) >= p.side_min_sigmas * hip_std_m:
        return
    raise WrongSideError(side, lateral)
