"""The prefilter cut-offs of a joint's two sensors: one shared cut-off per joint.

Every joint constraint compares a quantity that both sensors see: the spherical
residual ``‖g_P‖ − ‖g_C‖`` (Hu et al. 2021, eq. 7) the acceleration of the one
joint centre, the hinge residual the angular velocity about the one axis. The
low-pass filter is linear, so filtering both sensors' signals with the *same*
filter keeps the constraint (up to the slow rotation between the two frames);
filtering them at *different* cut-offs removes the content between the two
cut-offs from one side only, and the fit absorbs that mismatch by moving the
centre. The adaptive cut-off of each sensor (:mod:`lowerlimb.constraints.prefilter`)
is a noise-limited *bandwidth*, so sensor noise lowers the cut-off of a slowly
rotating sensor (a pelvis in walking) below its neighbour's although the joint
centre it carries accelerates as fast: on simulated seven-IMU walks
(``benchmarks/noise_bias.py``) the pelvis fell from 7.0 to 4.4 Hz while the
thigh stayed at 7.0 Hz, and the hip in the thigh sensor moved 100–260 mm.

The shared cut-off is the higher of the two sensors' cut-offs, each after the
joint's rigid-band cap (:func:`~lowerlimb.calibration._prepare.rigid_band_cap_hz`,
applied only to a sensor that reaches well above it): the slower sensor's extra
noise is white and unbiased, while the faster sensor's lost motion content is
a systematic error.
"""

from __future__ import annotations

from lowerlimb.calibration.options import CalibrationOptions

__all__ = ["exceeds_cap", "joint_cutoffs_hz"]


def exceeds_cap(cutoff: float | None, cap: float | None, options: CalibrationOptions) -> bool:
    """Whether a sensor's cut-off reaches far enough above the rigid band to be capped.

    A sensor whose noise-based bandwidth lies within ``rigid_band_trigger`` times
    the band is limited by its own slow motion (a slow trial, little power
    where the coherence is measured) and keeps its cut-off; one that reaches
    far above it carries broadband incoherent content (wobble, impacts).

    Args:
        cutoff: the sensor's adaptive cut-off, Hz (``None``: unfiltered).
        cap: the joint's rigid-band cap, Hz (``None``: no cap).
        options: calibration options (``rigid_band_trigger``).
    """
    if cap is None:
        return False
    return cutoff is None or cutoff > options.rigid_band_trigger * cap


def joint_cutoffs_hz(
    parent_hz: float | None, child_hz: float | None, cap_hz: float | None, options: CalibrationOptions
) -> tuple[float | None, float | None]:
    """The cut-offs at which a joint's parent and child sensors are filtered, Hz.

    Args:
        parent_hz: the parent sensor's adaptive cut-off, Hz (``None``: unfiltered).
        child_hz: the child sensor's adaptive cut-off, Hz (``None``: unfiltered).
        cap_hz: the joint's rigid-band cap, Hz (``None``: no cap).
        options: ``shared_joint_cutoff`` (one cut-off for both, the higher of the
            capped pair; ``None`` when either is unfiltered) and the cap's trigger.

    Returns:
        ``(parent, child)`` cut-offs, Hz or ``None`` (unfiltered).
    """
    capped = tuple(cap_hz if exceeds_cap(fc, cap_hz, options) else fc for fc in (parent_hz, child_hz))
    if not options.shared_joint_cutoff or capped[0] == capped[1]:
        return capped[0], capped[1]
    if capped[0] is None or capped[1] is None:
        return None, None
    shared = max(capped[0], capped[1])
    return shared, shared
