"""Every threshold of gait-event detection, foot integration and gait parameters, in one place.

Times are in seconds and rates in physical units, so the defaults hold at any
sampling rate: a window of ``w`` seconds is ``max(1, round(w * rate_hz))``
samples (:func:`samples`). Defaults follow the cited papers where they give a
number and are stated as choices where they do not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lowerlimb.errors import InputError

__all__ = ["GaitParams", "samples"]


@dataclass(frozen=True)
class GaitParams:
    """Thresholds of :mod:`lowerlimb.gait`.

    Attributes:
        sagittal_lowpass_hz: Cut-off of the zero-phase 2nd-order Butterworth low-pass
            applied to the sagittal shank angular velocity before minima are searched
            (Aminian et al. 2002 remove content above ~ 15 Hz with a wavelet), Hz.
        midswing_lowpass_hz: Cut-off of the stronger low-pass used only to find the
            mid-swing peaks (one clean peak per stride), Hz.
        midswing_min_rps: Smallest mid-swing peak; Salarian et al. 2004 use 50 deg/s, rad/s.
        min_stride_time_s: Shortest time between two mid-swing peaks of one leg, s.
        max_stride_time_s: Longest gait cycle; minima further than about half of it
            from a mid-swing peak are not searched, s.
        ic_search_s: Initial contact is the first local minimum of the sagittal rate
            within this time after the mid-swing peak (Salarian 2004: the minimum
            following mid-swing), s.
        to_search_s: Toe-off is the deepest local minimum within this time before the
            mid-swing peak (Salarian 2004: the minimum preceding mid-swing), s.
        event_min_rps: An event minimum must lie below ``-event_min_rps``, rad/s; with a
            foot IMU, the foot's heel rocker after an initial contact must reach it too.
        heel_rocker_s: With a foot IMU, initial contact is the swing-to-heel-rocker zero
            crossing of the foot's sagittal rate (:mod:`lowerlimb.gait.foot_contact`); the
            rate must fall below ``-event_min_rps`` within this time after it (the heel
            rocker lasts about 10 % of the cycle, ~0.1 s; Perry & Burnfield 2010), s.
        ic_refine_lowpass_hz: The swing-to-heel-rocker crossing found on the signal low-passed
            at :attr:`sagittal_lowpass_hz` is re-timed on the same rate low-passed at this
            higher cut-off (the nearest crossing within :attr:`ic_refine_s`): the heel
            rocker starts with a kink, and a low cut-off spreads it backwards and moves
            the crossing early (13 ms at 15 Hz on the seven-IMU simulator's exact contacts,
            6 ms at 40 Hz; benchmarks/gait.py), Hz. Unchanged above Nyquist.
        ic_refine_s: Half-width of the window, around the coarse crossing, searched for the
            re-timed one, s.
        unloading_lowpass_hz: With a foot IMU, toe-off is the half-way point of the fall
            of the foot's specific-force magnitude as the forefoot unloads
            (:mod:`lowerlimb.gait.toe_off`); the magnitude is low-passed at this cut-off
            first (unchanged at or below 100 Hz sampling), Hz.
        min_event_rate_hz: a recording below this rate has its initial contacts, toe-offs
            and mid-swings found on its shank and foot signals interpolated (band-limited) to
            the smallest integer multiple of its rate at or above it; the stationary periods
            and the sagittal rates keep the recorded samples (:mod:`lowerlimb.upsample`;
            ``None``: never), Hz.
        unloading_min_mps2: The unloading counts only when the magnitude falls at least
            this far below that peak (about a third of g; on the real walk of ``gait/``
            it falls 10-17 m/s²), else toe-off comes from the shank, m/s².
        unloading_max_offset: The unloading counts only when it lies within this fraction
            of the push-off rate bracket's length from the bracket's middle, which the
            rate features straddle about evenly (:mod:`lowerlimb.gait.toe_off`); further
            away it is the swing's first transient, not the forefoot's unloading.
        level_at_stance: Pin the foot's tilt to gravity at every stationary period before
            the strapdown (:func:`~lowerlimb.gait.trajectory.levelled_at_stance`): the still
            foot's accelerometer reads gravity alone, where the filter's tilt lags a gyro bias.
        cut_restore: Give a foot accelerometer cut at its range the force it lost in each
            swing before the strapdown (:mod:`lowerlimb.gait.cut_force`), and a foot gyro cut
            at its range the rotation it lost, before everything else
            (:mod:`lowerlimb.gait.cut_rate`); ``False``: use the cut signals as recorded.
        cut_restore_ridge_s2: Ridge ``λ`` of the force restored to a foot accelerometer cut
            at its range, from each swing's end velocity (:mod:`lowerlimb.gait.cut_force`),
            s² (10⁻⁴; 0 let one simulated swing's many cut runs put its stride 52 % off).
        cut_rate_tilt_sd_rad: SD of the foot's tilt at rest from its accelerometer, the weight of
            the tilt equations of a cut gyro's swing (:mod:`lowerlimb.gait.cut_rate`), rad
            (0.03: 1.7°).
        cut_rate_prior_fraction: SD of a cut gyro run's prior height as a fraction of it.
        cut_rate_prior_min_rps: ... and at least this, rad/s.
        cut_rate_rest_s: The foot's gravity direction at a rest is the mean of its
            accelerometer over this long at the rest's end next to the swing, s.
        cut_segment_fit: Fit a cut thigh or shank gyro run's height to its joints'
            accelerations (:mod:`lowerlimb.gait.cut_segment`); ``False``: its parabola prior.
        cut_segment_acc_sd_mps2: SD of a joint centre's acceleration norm seen from the two
            sensors, the weight of a cut thigh or shank gyro run's joint equations
            (:mod:`lowerlimb.gait.cut_segment`), m/s².
        cut_segment_margin_s: The joint equations of a cut run are taken over the run and
            this long on either side, s (at least the angular acceleration's window).
        walking_gyro_rps: A sample counts as walking for the principal-axis fit when
            the smoothed shank gyro norm exceeds this, rad/s.
        shoe_window_s: Window of the SHOE detector (Skog et al. 2010, eq. 8), s.
        shoe_sigma_acc_mps2: Accelerometer noise scale sigma_a of SHOE (a model
            parameter that also absorbs foot vibration during stance), m/s².
        shoe_sigma_gyr_rps: Gyroscope noise scale sigma_w of SHOE, rad/s.
        shoe_threshold: Detection threshold gamma of the SHOE statistic (dimensionless:
            the statistic is a mean of squared, sigma-normalised residuals).
        min_stationary_s: Stationary runs shorter than this are dropped, s.
        merge_gap_s: Moving gaps shorter than this between stationary runs are closed, s.
        gravity_mps2: Gravity magnitude; ``None`` measures it as the median specific-force
            norm over the stationary samples, m/s².
        turn_heading_deg: A stride whose foot heading changes by more than this between
            its two contacts is a turning stride, deg.
        stance_turn_deg: A contact whose foot turns about the vertical by more than this
            between initial contact and the end of its stationary period
            (:func:`~lowerlimb.gait.contacts.stance_turn_rad`) pivoted, and the strides and
            steps ending on it are turning ones: its ankle moved while the foot stood, deg.
            Straight stances of the real walk of ``gait/`` range over 4–8°; the
            simulator's pivoting feet through a turn about 17–180°.
        pair_yaw_window_s: Standard deviation of the Gaussian kernel over which the heading
            between the two feet's trajectories is averaged, s (``inf``: one rotation for
            the whole walk).
        pair_yaw_at_mid_time: compare each right stride's direction with the left heading
            interpolated at its own mid-time (``False``: the most overlapping left stride's,
            as before; on a bending walk that differs by half a stride's turn, always of one
            sign, and drifts the step width).
        max_standing_leg_tilt_deg: In the standing reference, a calibrated leg (hip to
            ankle) tilted further than this from the vertical is taken as a calibration error
            and replaced by the vertical when the feet are anchored to each other, deg
            (people stand with their legs within a few degrees of vertical).
        chain_drift_knot_s: Knot spacing of the piecewise-linear drift between the two
            feet's tracks that the calibrated chain removes (:mod:`lowerlimb.gait.drift`),
            s; ``None``: no drift removal (the single standing anchor only). 30 s: on the 14
            simulated walks of ``benchmarks/results/gait_drift_knots.md`` (60 s to 10 minutes,
            steady or changing pace) the median of the walks' median step width errors is
            9.6 mm (15 s: 9.7, 20 s: 9.6, 60 s: 10.3, 120 s: 11.0, none: 34.4). With the right
            track placed on the left only, 15–20 s fitted the chain's noise on the 60 s walks
            (12.9 / 11.8 mm); averaged over both placements they no longer do, and 30 s stays,
            in the middle of the flat range.
        chain_drift_sd_m: Prior SD of the drift's change from one knot to the next, m
            (a smoothness prior; on the simulated 10-minute walks the drift changes by
            up to 0.2 m a minute).
        chain_anchor_sd_m: Prior SD of the drift at the standing anchor itself, m: the
            anchor's own error (the chain's geometry at one instant; 40–90 mm on two of six
            60 s simulated walks, within 2 mm of Vicon's stance width on the real walk). A
            walk that turns separates it from the chain's bias and the fit corrects it;
            walking straight the prior keeps the anchor (:mod:`lowerlimb.gait.drift`).
            ``None``: the drift is pinned to zero at the anchor.
        chain_drift_min_steps: Fewer chain steps than this leave the tracks as anchored.
        chain_drift_gap_s: A foot integrated this long without a stationary period (its
            track unaided by a zero-velocity update: a turn about on a pivoting foot, a
            stumble) breaks the drift: knots at both ends of the gap, the drift's change
            across it almost free (:attr:`chain_drift_break_sd_m`), s; ``None``: no breaks.
            Walking, a foot's gaps are its swings, 0.4–0.9 s.
        chain_drift_break_sd_m: Prior SD of the drift's change across such a gap, m.
        straight_heading_spread: A drift fit whose steps' walking directions spread less
            than this (:attr:`~lowerlimb.gait.drift.TrackDrift.heading_spread`) cannot tell
            the chain's bias from the anchor's error: the walk counts as straight and step
            width rests on the standing chain (``gait.json``'s ``step_width_basis``; 0.003–0.03
            on simulated treadmill walks, 0.33–0.54 on walks that bend by 17–46°).
        chain_drift_huber: Huber threshold of the drift fit, in robust SDs of its residuals.
        chain_drift_iterations: Reweighting passes of the drift fit.
        chain_stance_margin_s: The chain's walking direction is the stance ankle's path
            under the pelvis from this long after the stance leg's initial contact to
            this long before its toe-off (the flat-foot part), s.
        sensor_to_ankle_m: Constant vector from the foot sensor to the ankle centre in
            the foot sensor frame, m (zeros: gait geometry on the sensor positions).
        max_ds_fraction: A double-support interval longer than this fraction of the
            stride is treated as a detection failure and not used.
        pelvis_turn_edge_dps: A turn of the walker (:mod:`lowerlimb.gait.turns`) lasts while
            the pelvis's stride-smoothed vertical rate stays above this, deg/s (El-Gohary et
            al. 2014: 5).
        pelvis_turn_peak_dps: ... and must peak above this, deg/s (El-Gohary et al. 2014: 15;
            a walk bending on a 15 m radius at 1.4 m/s turns at 5).
        pelvis_turn_merge_s: Turns of one direction less than this apart are one turn with a
            hesitation, s (Shah et al. 2021 merge gradual turns within 0.5 s).
        pelvis_turn_min_deg: Smallest turn angle kept, deg (El-Gohary et al. 2014: 45).
        pelvis_turn_duration_s: Shortest and longest turn kept, s (El-Gohary et al. 2014:
            0.5 and 10).
        min_leg_strides: Fewest strides of at least ``min_leg_stride_m`` for a single-leg trial
            to have a gait (:mod:`lowerlimb.gait.one_leg`).
        min_leg_stride_m: Shortest stride that counts as walking there, m: a simulated
            sit-to-stand (seed 3002) showed two "strides" of 2 cm between its foot's rests.
    """

    sagittal_lowpass_hz: float = 15.0
    midswing_lowpass_hz: float = 3.0
    midswing_min_rps: float = np.deg2rad(50.0)
    min_stride_time_s: float = 0.6
    max_stride_time_s: float = 2.5
    ic_search_s: float = 0.6
    to_search_s: float = 0.6
    event_min_rps: float = np.deg2rad(10.0)
    heel_rocker_s: float = 0.15
    ic_refine_lowpass_hz: float = 40.0
    ic_refine_s: float = 0.04
    unloading_lowpass_hz: float = 50.0
    unloading_min_mps2: float = 3.0
    unloading_max_offset: float = 0.25
    level_at_stance: bool = True
    cut_restore: bool = True
    cut_restore_ridge_s2: float = 1e-4
    cut_rate_tilt_sd_rad: float = 0.03
    cut_rate_prior_fraction: float = 0.5
    cut_rate_prior_min_rps: float = 1.0
    cut_rate_rest_s: float = 0.05
    cut_segment_fit: bool = True
    cut_segment_acc_sd_mps2: float = 2.0
    cut_segment_margin_s: float = 0.05
    min_event_rate_hz: float | None = 100.0
    walking_gyro_rps: float = 1.0
    shoe_window_s: float = 0.05
    shoe_sigma_acc_mps2: float = 0.5
    shoe_sigma_gyr_rps: float = np.deg2rad(20.0)
    shoe_threshold: float = 1.0
    min_stationary_s: float = 0.05
    merge_gap_s: float = 0.03
    gravity_mps2: float | None = None
    turn_heading_deg: float = 20.0
    stance_turn_deg: float = 20.0
    pair_yaw_window_s: float = 10.0
    pair_yaw_at_mid_time: bool = True
    max_standing_leg_tilt_deg: float = 15.0
    chain_drift_knot_s: float | None = 30.0
    chain_drift_sd_m: float = 0.05
    chain_anchor_sd_m: float | None = 0.02
    chain_drift_min_steps: int = 20
    chain_drift_gap_s: float | None = 1.5
    chain_drift_break_sd_m: float = 1.0
    straight_heading_spread: float = 0.1
    chain_drift_huber: float = 2.5
    chain_drift_iterations: int = 5
    chain_stance_margin_s: float = 0.1
    sensor_to_ankle_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    max_ds_fraction: float = 0.4
    pelvis_turn_edge_dps: float = 5.0
    pelvis_turn_peak_dps: float = 15.0
    pelvis_turn_merge_s: float = 0.5
    pelvis_turn_min_deg: float = 45.0
    pelvis_turn_duration_s: tuple[float, float] = (0.5, 10.0)
    min_leg_strides: int = 2
    min_leg_stride_m: float = 0.1

    def __post_init__(self) -> None:
        if self.min_leg_strides < 1 or not 0 <= self.min_leg_stride_m < np.inf:
            raise InputError(
                f"min_leg_strides must be >= 1 and min_leg_stride_m >= 0 m, got {self.min_leg_strides} "
                f"and {self.min_leg_stride_m}"
            )
        rate = self.min_event_rate_hz
        if rate is not None and not 0 < rate < np.inf:
            raise InputError(f"min_event_rate_hz must be > 0 Hz or None, got {rate}")
        knot = self.chain_drift_knot_s
        if knot is not None and not knot > 0:
            raise InputError(f"chain_drift_knot_s must be > 0 s or None (no drift removal), got {knot}")
        gap = self.chain_drift_gap_s
        if gap is not None and not gap > 0:
            raise InputError(f"chain_drift_gap_s must be > 0 s or None (no breaks), got {gap}")
        edge, peak = self.pelvis_turn_edge_dps, self.pelvis_turn_peak_dps
        if not (0 < edge <= peak < np.inf):
            raise InputError(
                "pelvis_turn_edge_dps and pelvis_turn_peak_dps must satisfy 0 < edge <= peak, got "
                f"{edge} and {peak}"
            )
        lo, hi = self.pelvis_turn_duration_s
        if not (0 <= lo < hi):
            raise InputError(
                "pelvis_turn_duration_s must be (shortest, longest) with 0 <= shortest < longest, got "
                f"{(lo, hi)}"
            )
        if not (self.pelvis_turn_merge_s >= 0 and self.pelvis_turn_min_deg >= 0):
            raise InputError(
                "pelvis_turn_merge_s and pelvis_turn_min_deg must be >= 0, got "
                f"{self.pelvis_turn_merge_s} and {self.pelvis_turn_min_deg}"
            )
        for name in ("chain_drift_sd_m", "chain_drift_huber", "chain_drift_break_sd_m", "stance_turn_deg"):
            if not getattr(self, name) > 0:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)}")
        anchor_sd = self.chain_anchor_sd_m
        if anchor_sd is not None and not anchor_sd > 0:
            raise InputError(f"chain_anchor_sd_m must be > 0 m or None (pinned anchor), got {anchor_sd}")
        if self.chain_drift_min_steps < 1 or self.chain_drift_iterations < 1:
            raise InputError(
                "chain_drift_min_steps and chain_drift_iterations must be at least 1, got "
                f"{self.chain_drift_min_steps} and {self.chain_drift_iterations}"
            )
        if not 0.0 <= self.straight_heading_spread <= 1.0:
            raise InputError(
                f"straight_heading_spread must be within [0, 1], got {self.straight_heading_spread}"
            )
        cut_rate = (
            "cut_rate_tilt_sd_rad",
            "cut_rate_prior_fraction",
            "cut_rate_prior_min_rps",
            "cut_rate_rest_s",
            "cut_segment_acc_sd_mps2",
            "cut_segment_margin_s",
        )
        for name in cut_rate:
            if not 0 < getattr(self, name) < np.inf:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)}")
        if not 0 < self.cut_rate_rest_s < np.inf:
            raise InputError(f"cut_rate_rest_s must be > 0 s, got {self.cut_rate_rest_s}")
        if not 0 <= self.cut_restore_ridge_s2 < np.inf:
            raise InputError(f"cut_restore_ridge_s2 must be >= 0 s², got {self.cut_restore_ridge_s2}")
        if not self.chain_stance_margin_s >= 0:
            raise InputError(f"chain_stance_margin_s must be >= 0 s, got {self.chain_stance_margin_s}")


def samples(duration_s: float, rate_hz: float) -> int:
    """A duration in samples at ``rate_hz``, at least one."""
    return max(1, int(round(duration_s * rate_hz)))
