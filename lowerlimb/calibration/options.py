"""Tuning parameters of the joint-constraint calibration, with their defaults in one place."""

from __future__ import annotations

import math
from dataclasses import dataclass

from lowerlimb.constraints.angular_acceleration import DEFAULT_POLYORDER, DEFAULT_WINDOW_S
from lowerlimb.errors import InputError
from lowerlimb.methods import CALIBRATION_METHODS, CENTRE_FORMS

__all__ = ["CENTRE_FORMS", "METHODS", "CalibrationOptions", "check_method"]

#: Accepted ``method`` values: CasADi Gauss–Newton (default), NumPy Gauss–Newton
#: with the analytic Jacobians, the two swarms (Hu 2021 §3.2–3.3), and a swarm
#: followed by a CasADi refinement.
METHODS: tuple[str, ...] = tuple(CALIBRATION_METHODS)


def check_method(method: str) -> str:
    """Return ``method`` if it is one of :data:`METHODS`.

    Raises:
        InputError: naming the accepted values.
    """
    if method not in METHODS:
        raise InputError(f"unknown calibration method {method!r}; use one of {', '.join(METHODS)}")
    return method


@dataclass(frozen=True)
class CalibrationOptions:
    """Parameters of the joint-constraint calibration (defaults chosen on the simulator).

    Attributes:
        prefilter: low-pass each sensor's gyro and accelerometer at a cut-off
            adapted to its motion (:mod:`lowerlimb.constraints.prefilter`).
        cutoff_hz: a fixed cut-off for every sensor instead of the adaptive one, Hz.
        cutoff_factor: adaptive cut-off over the motion bandwidth (1.5: best worst case
            on simulated walking among 1.25–3; see benchmarks/calibration_accuracy.py
            ``--option cutoff_factor=…``).
        min_cutoff_hz: lowest adaptive cut-off, Hz.
        filter_regressor: low-pass the kinematic matrix ``K = [ω]ײ + [α]×`` built
            from the unfiltered gyro, like the accelerometer, instead of building it
            from the low-passed gyro (the rigid-body relation is linear in ``a`` and
            ``K``, not in ω; :func:`~lowerlimb.calibration._prepare.filtered_regressor`).
        centre_form: ``"norm"`` (default: the norm form of eq. 3 decides the centres) or
            ``"aligned"``: the hip and knee centres are refined by the 3-D
            constraint in gyro-aligned frames, at the same cut-offs
            (:mod:`~lowerlimb.calibration.aligned_form`; the diagnostics stay the norm form's).
        aligned_window_s: the aligned form's window for the slowly varying rotation
            between the two sensors' integration frames, s.
        aligned_iterations: its alternations of the windows' rotations and the centres.
        aligned_joints: the joints the aligned form refines (a subset of ``("hip", "knee")``).
        hip_in_pelvis_form: the form that decides the hip centre *in the pelvis sensor*
            when ``centre_form`` leaves the hip to the norm form: ``"aligned"`` (default)
            or ``"norm"``. The pelvis barely turns in walking, and the norm form's
            low-passed norms put that centre 8–20 cm off on seven-IMU simulated walks
            and 13 cm apart vertically between the two legs of the real walk; the
            aligned form: 5 mm and 8 mm (``benchmarks/results/aligned_form.md``). The hip
            in the thigh sensor keeps the norm form.
        rigid_band: cap each joint's cut-off at the band in which its two sensors
            are coherent (:func:`~lowerlimb.constraints.prefilter.rigid_band_hz`):
            soft-tissue wobble, strap resonance and impact ringing of real
            thigh and shank sensors lie above it and break the rigid-body
            constraint.
        rigid_band_coherence: coherence below which the band ends (0–1).
        rigid_band_factor: cap = factor × band edge.
        rigid_band_max_rotation: the band is sought in the Welch segments in which the two
            sensors' squared angular rate stays below this many times its median over the
            moving segments (:func:`~lowerlimb.constraints.prefilter.rigid_band_hz`): a fast
            turn makes rigid sensors' acceleration norms incoherent (the centripetal terms
            differ), which soft tissue is not needed for; ``None``: every segment. 4: on
            seven-IMU walks with 0.6 s turns about (seeds 201–203) the legs went from 25 / 21 mm
            median (57 mm worst) to within 2 mm; the real walk's segments, its 0.3 s spin turn
            included, all stay below it.
        rigid_band_min_hz: lowest cap, Hz.
        rigid_band_trigger: a sensor is capped only when its adaptive cut-off
            exceeds this multiple of the cap (else its own slow motion limits it).
        pair_band_test: a two-IMU spherical fit
            (:func:`~lowerlimb.calibration.joint_center.calibrate_spherical_joint`, the
            ``estimate_joint_center`` API) is fitted both at its sensors' own cut-offs and,
            where its rigid band caps them, at the cap, and keeps the cap only where the two
            fits say the sensors move on their segments (:mod:`~lowerlimb.calibration.pair_band`).
            ``False``: the own cut-offs alone (before 0.5.14). A leg's joints are always capped.
        pair_band_margin: the capped fit is kept when its low-band gain exceeds its full-band
            cost by more than this (both ratios − 1). 0.1: the mechanical rig's rigid trials
            reach 0.06, the real walk's hips and ankles 0.36–1.5, simulated walks and mixed
            motions with incoherent tissue forces (``sim_signatures.md``'s ``own 3``) 0.02–3.7.
        shared_joint_cutoff: filter both sensors of a joint at one cut-off, the
            higher of their two (each after the rigid-band cap): the constraint
            compares what both sensors see of the joint, and different filters
            on the two sides break it (:mod:`~lowerlimb.calibration.joint_cutoff`;
            ``False``: each sensor keeps its own cut-off, as before).
        angacc_window_s: Savitzky–Golay window of the gyro derivative, s.
        angacc_polyorder: Savitzky–Golay polynomial order.
        remove_gyro_bias: subtract the mean gyro of a still period detected at the
            start of the recording (realistic MEMS bias ≈ 0.01 rad/s).
        still_min_s: shortest still period used for the bias, s.
        still_end_min_s: a recording that does not start still has its bias measured over
            a still end at least this long, s (a deliberate stand; on the rig's 2D_01
            trial, whose still end is 0.66 s, that short a window moved the centre from
            4.5 to 4.7 mm). ``None``: never from the end.
        center_bound_m: search box ``[-b, b]³`` of each joint-centre coordinate, m
            (the swarms sample it; Hu 2021 use 0.2 m, too small for a hip seen
            from a mid-thigh sensor).
        check_sensor_order: refuse a trial whose thigh/shank or shank/foot columns
            look swapped (:mod:`~lowerlimb.calibration.plausibility`); with two legs, also one
            whose left and right thigh, shank or foot columns do
            (:mod:`~lowerlimb.bilateral.leg_pairing`).
        check_signs: refuse a trial in which a sensor turns about the vertical against
            its neighbours, the sign of an accelerometer or gyro inverted
            (:mod:`~lowerlimb.orientation.sign_check`; checked after the orientation filters).
        max_iter: iteration limit of the Gauss–Newton solvers.
        tol: convergence tolerance of the Gauss–Newton solvers (relative step).
        sign_raw_window_s: the overall hinge sign's test on the angle from the standing start
            looks at this long a stretch after it, s
            (:func:`~lowerlimb.calibration.hinge_axis.flexion_sign_margin`): over a whole
            20-minute walk the residual gyro bias drifted the angle by 4.4 rad, one-sidedly,
            and that test flipped a simulated knee.
        sign_raw_min_score: below this one-sidedness score (0–1) the test from the standing
            start is left out and the drift-free test alone decides the overall hinge sign (a
            knee flexing 60° from a straight leg scores 0.72 even if it also extends 10° beyond
            straight, and 0.97 on both knees of the real walk; that walk's right knee with its
            gyros cut at ±300 °/s scored 0.22 and came out mirrored).
        sign_drift_free_min_score: ... but only when the drift-free test scores at least
            this (0–1); below it that test says nothing and the higher score of the two
            decides. Flexion pulses about as long as the rests between them, as in repeated
            knee lifts, swing about their running mean to both sides alike: a simulated knee
            lift with the artefact profile (seed 2, 40 s) scored 0.059 drift-free (0.002
            with the true axes) against 0.27 from the start, and came out mirrored (hip and
            knee flexion −57 / −58° median); a gait-like knee scores about 0.3 drift-free.
        sign_one_sided_margin: when neither the gyro coherence nor the accelerometers settle
            a hinge's relative axis sign, the candidate whose drift-free joint angle is more
            one-sided by at least this score (0–1) is taken
            (:func:`~lowerlimb.calibration.hinge_axis.drift_free_one_sidedness`; a walking knee
            scores 0.3–0.4 with the right sign and under 0.05 with the wrong one on the
            seven-IMU simulator with artefacts).
        hinge_gravity_rate_rps: weight of the still-period gravity rows of the hinge
            fit, as the angular rate (rad/s) of the pseudo-samples, one per still
            sample (0: off; see :func:`~lowerlimb.calibration.hinge_axis.fit_hinge_axis`).
        hinge_band_hz: upper edge of a hinge's motion band, Hz: the hinge axes are also fitted
            on gyros low-passed there (``None``: not), and those are kept when the two fits
            disagree (:mod:`~lowerlimb.calibration.hinge_band`; a walking knee moves below a
            few hertz, soft-tissue wobble lies at 7–20 Hz).
        hinge_band_max_disagreement_deg: largest angle between the full-band and the
            band-limited axes (either sensor) at which the full-band ones are kept, deg (rigid
            simulated walks: 0.3–1°; with soft-tissue artefacts: up to 40°).
        hinge_starts: number of starting axis pairs of the hinge problem (the
            residual has sign symmetries and local minima).
        hinge_centre_start_m: the leg's knee centre (Gauss–Newton from zero) is also fitted
            from ± this along each of its five coordinates, on at most
            ``hinge_centre_start_samples`` samples; an anatomically placed centre (below the
            thigh sensor, above the shank sensor, along each one's standing up) is preferred,
            then a lower cost, and the best basin is refined on all samples (``None``: zero
            alone). The norm form is not convex: on the real walk of ``gait/`` with the left
            thigh sensor moved 6–12 cm up the thigh, the start at zero ended 39 cm up the
            thigh, above the sensor, at 1.4 times the best cost; on a simulated walk with heavy
            soft-tissue artefacts the lowest cost lay above the thigh sensor, so cost alone
            does not decide.
        hinge_centre_start_samples: evenly spaced samples those starts are tried on (600:
            half the time of 1500 for the same basins on the real walk, 0.12 s per leg).
        swarm_samples: the swarms evaluate their population cost on at most this
            many evenly spaced samples.
        n_particles: DWPSO population.
        n_wolves: GWO population.
        swarm_iter: iterations of the pure swarms (``dwpso``, ``gwo``); 300 because
            150 often stops short of the ankle's narrow valley on walking.
        hybrid_swarm_iter: iterations of the swarm stage of ``dwpso+casadi`` and
            ``gwo+casadi`` (it only needs the right basin).
        seed: seed of the swarms.
        noise_floor_mps2: lower bound of the residual noise assumed for the
            spherical covariance, m/s² (noise-free data would otherwise report
            zero uncertainty even when a direction is unobservable).
        noise_floor_rps: the same for the hinge residual, rad/s.
        noise_correction: subtract the expected gyro-noise part of the spherical
            cost (errors in variables: the corrected score of Nakamura 1990,
            :mod:`~lowerlimb.calibration.noise_correction`), with the white-noise
            level of each gyro measured in the still start.
        noise_correction_max_fraction: the correction removes at most this
            fraction λ of the data's information ``JᵀJ`` along any direction.
            The corrected estimator's standard deviation grows as 1/(1 − λ) and
            it loses its minimum at λ = 1, so Fuller (1987, *Measurement Error
            Models*, §2.5) limits the correction; 0.2 keeps the growth ≤ 1.25 and
            scored as 0.5 did on simulated walks and squats
            (``benchmarks/calibration_accuracy.py --option noise_correction_max_fraction=…``).
        robust: fit the spherical joints by Huber's M-estimator (iteratively
            reweighted, :mod:`~lowerlimb.calibration.robust_weights`): the few
            samples that break the rigid constraint count less. Off: on the
            seven-IMU simulator it brought the ankle in the shank from 60 to 3 mm
            median (the simulator's contacts break the constraint; measured
            before ``impact_exclusion``, which now removes those samples), but on
            real data with optical truth it moves the rig's 2-DoF centre from 6.4
            to 9.9 mm and the real walk's step width from 16.8 to 23.4 mm median
            (the norm residual grows with the motion, so the weights also discount
            the most informative samples).
        huber_k: Huber's threshold in robust standard deviations (1.345: 95 %
            efficiency at Gaussian noise, Holland & Welsch 1977).
        robust_passes: most reweighting passes.
        impact_exclusion: leave the samples near impacts out of the spherical
            joint-centre fits (:mod:`~lowerlimb.calibration.impact_window`): at foot
            contacts the rigid constraint fails because the filters and the α
            derivative smear the kinks of the motion (and, on real legs, the
            impact rings in the strap and the soft tissue). A leg's calibration
            applies it to the joints in ``impact_joints``;
            :func:`~lowerlimb.calibration.joint_center.calibrate_spherical_joint`
            to its one pair.
        saturation_exclusion: leave the samples at which a joint's sensor sits at the
            end of its range (:mod:`~lowerlimb.io.saturation`), and those within
            ``impact_window_s`` of them, out of a leg's hip and ankle fits: a cut
            accelerometer or gyro breaks the rigid constraint there. On simulated seven-IMU
            walks with every accelerometer cut at ±2 g the shank went from 121 to 7 mm
            (median) off its true length (``benchmarks/results/saturation.md``). Nothing
            changes on a trial with no cut sensor. The knee's fit keeps every sample.
        impact_joints: the leg's spherical joints (``"hip"``, ``"ankle"``) whose fits
            leave impacts out. The ankle only: its pair spans the foot contact
            (on seven-IMU simulated walks the ankle in the shank went from 60 to
            4 mm median), while leaving impacts out of the hip fit did not help
            the simulated hip in the thigh and shortened the real walk's left thigh
            by 11 mm against Vicon.
        impact_jerk_mps3: a sample whose accelerometer jerk (norm of the specific
            force's derivative) exceeds this in the joint's sensors or the leg's
            foot sensor marks an impact, m/s³.
        impact_window_s: samples this close to a marked one are left out, s (the
            reach of the prefilter and of the α derivative's smearing).
        impact_max_excluded: at most this fraction of the samples is left out (0–1);
            beyond it the jerk threshold is raised.
        impact_max_cutoff_hz: when a leg's trial has impacts, the pairs of
            ``impact_joints`` are low-passed at no more than this, Hz, both sensors alike
            (``None``: no limit; :func:`~lowerlimb.calibration.impact_window.impact_cutoff_limit_hz`;
            the single-joint entry points keep their pair's cut-off).
            A foot's gyro is broadband with its contacts, so its adaptive cut-off
            leaves the pair unfiltered, and the unfiltered contacts bias the ankle
            centre along its flexion axis, where walking pins it least. On rigid
            seven-IMU simulated walks (six seeds per pace) the ankle in the shank
            sensor went from 8.5 / 44 / 38 mm median (normal / slow / shuffling pace;
            134 / 64 / 84 worst) to 4.6 / 6.0 / 5.2 (134 / 49 / 9.4 worst, where a lower
            rigid-band cap binds); with both sensors forced to 10 Hz 6.2 / 7.2 / 3.5, to
            15 Hz 5.8 / 10.4 / 11.5, to 20 Hz 3.7 / 14.6 / 15.1. Walking's
            kinematics lie below it (gait's marker data are low-passed at about 6 Hz,
            Winter 2009). Real legs' soft tissue usually caps the pair lower already
            (the rigid band: 5.5 / 7.0 Hz on the real walk of ``gait/``).
        center_std_tol_m: warn when a joint centre's standard deviation along its
            weakest direction exceeds this, m.
        axis_std_tol_deg: warn when the hinge axis's standard deviation exceeds this, deg.
        min_rms_rate_rps: warn when a sensor's RMS angular rate is below this,
            rad/s (a segment that hardly rotates does not reveal the joint).
        anthropometric_prior: add a weak Gaussian prior on the hip centre in the
            thigh sensor and the ankle centre in the shank sensor (knee centre ±
            de Leva segment length along the standing long axis;
            :mod:`~lowerlimb.calibration.segment_prior`). It only decides the
            directions the motion leaves undetermined (nearly straight walking).
        prior_stature_m: stature that scales the prior's segment lengths, m.
        thigh_length_per_stature: thigh (hip–knee) length over stature
            (de Leva 1996 Table 4: 422.2 / 1741 mm).
        shank_length_per_stature: shank (knee–ankle) length over stature
            (de Leva 1996 Table 4: 434.0 / 1741 mm).
        prior_std_along: the prior's standard deviation along the segment, as a
            fraction of its length (adult spread of segment length over stature
            plus the knee-centre gauge).
        prior_std_across_m: its standard deviation across the segment, m (sensor
            placement, the segment's curvature and a few degrees of standing tilt).
        prior_std_axis_m: its standard deviation along the knee axis about the
            sensor, m (the sensor sits on the skin, a segment radius from the bone).
        prior_weight: multiplier of the prior's rows against the data's.
        knee_line_prior: weigh the knee's relative position along its axis (the
            ankle minus the hip centre along the knee axis) against an anatomical
            prior (:mod:`~lowerlimb.calibration.knee_line`; only with
            ``anthropometric_prior``).
        knee_line_mean_m: that prior's mean, m (hip, knee and ankle centres on one
            line perpendicular to the knee axis).
        knee_line_std_m: its standard deviation, m (3° over a 0.8 m leg).
        knee_line_min_data_std_m: the smallest spread granted to the data's
            estimate of it, m.
        knee_line_probe_factors: the knee centre is refitted without its low-pass
            cap and at these multiples of it; the largest shift of that relative
            position is the systematic part of the data's spread.
        knee_line_max_mismatch_deg: the prior applies only when the knee axis's
            elevation above the standing horizontal agrees in the thigh and the shank
            sensor to within this, deg (a hinge keeps it; soft tissue on a real
            thigh does not).
        cutoff_probe: repeat the hip and ankle fits with every prefilter cut-off
            widened and record how far each centre moves
            (:mod:`~lowerlimb.calibration.cutoff_probe`; a record, no estimate changes).
        cutoff_probe_factor: the widening factor (> 1).
        fit_band_factor: :func:`~lowerlimb.calibration.leg.calibrate_leg` fits the joints with
            every rigid-band cap multiplied by this, and again as the options give them when
            that fit shows sensors that are not rigid on the bone
            (:mod:`~lowerlimb.calibration.fit_band`; 1: one fit, as given; ≥ 1).
        fit_band_max_mismatch_deg: the widened fit is not kept when its knee axis seen from
            the thigh and from the shank sensor differs by more than this in elevation at the
            standing start, deg (the sensors are not rigid on the bone). An ideal hinge keeps
            it (the rigid seven-IMU simulator's legs: at most 0.2°), but a real knee turns as
            it flexes: the simulator's knees with ``knee_rotation_per_flexion=0.2`` (about 11°
            of tibial rotation over a stride) show 3–4° on rigid sensors, which the earlier
            2° took for loose sensors (thigh and shank 13–37 mm short,
            ``gait_knee_rotation.md``). The real walk's legs: 17–24°; the simulator's
            real-walk artefacts: 0.1–7.8°.
        fit_band_without_standing: a leg recorded without a standing start is tried in the
            widened band too, its knee's mismatch read over the motion
            (:func:`~lowerlimb.calibration.fit_band.moving_mismatch_reason`); off, such a leg
            keeps the coherent band, as before 0.5.15.
        moving_mismatch_lowpass_hz: without a still start, the hinge pair API
            (:func:`~lowerlimb.calibration.hinge_joint.calibrate_hinge_joint`) reads that
            mismatch as its median over the motion, on accelerometers low-passed at this
            cut-off, Hz (:func:`~lowerlimb.calibration.knee_line.moving_axis_mismatch`).
        fit_band_min_ratio: a segment of the widened fit shorter than this times its
            anthropometric length (at ``prior_stature_m``) is implausible.
        fit_band_max_ratio: one longer than this times it is implausible.
        split_half_probe: repeat the hip and ankle fits on each half of the recording and
            record half the difference (:mod:`~lowerlimb.calibration.split_half`; a
            record and a warning, no estimate changes). Refits are thinned to at most
            ``cutoff_probe_max_samples / 2`` samples in all.
        cutoff_shift_warn_m: warn when a centre moves by more than this (in either sensor
            frame) when the cut-off probe widens the cut-offs, m.
        split_half_warn_m: warn when a centre moves by more than this between the halves
            (half the difference, in either sensor frame), m.
        cutoff_probe_max_samples: the probe refits a longer trial on every k-th sample, so
            that at most this many remain (a record of centimetre shifts does not need all of
            a 20-minute walk; the refits were a third of its calibration time).
        min_fit_rate_hz: a trial recorded below this rate is interpolated (band-limited)
            to the smallest integer multiple of its rate at or above it (5 % below it counts as
            reaching it) for the joint calibration only (:mod:`~lowerlimb.upsample`; ``None``: never).
        fit_max_samples: a longer trial's joint-centre fits (norm and aligned form) and
            hinge-axis solves use every k-th sample of the low-passed signals, so that at
            most this many remain (``None``: all samples; the hinge's sign rules and every
            diagnostic still read all of them). Neighbouring low-passed samples nearly
            repeat each other; the spreads stay as they were because they scale with the
            residual's correlation time. Trials up to 2 minutes at 100 Hz are fitted on
            every sample (``benchmarks/results/fit_thinning.md``).
        clock_sync: estimate the sensors' clock offsets from the joints after a first
            calibration and, when they explain the joints' mismatch, re-time the signals
            and calibrate again (:mod:`~lowerlimb.calibration.clock_sync`; applied by
            :func:`lowerlimb.pipeline.process_trial`).
        clock_max_offset_s: largest offset searched per joint, s.
        clock_min_explained: a joint's lag counts when it removes at least this share of
            the mean squared mismatch of the two sensors' acceleration norms at the joint
            (0-1; a synchronised real walk: 0.01-0.18, a 10 ms offset: 0.5-0.7).
        clock_split_tol_s: ... and when the lags of the trial's two halves agree within this, s.
        clock_lowpass_hz: low-pass of those norms before they are compared, Hz.
        clock_passes: at most this many estimate-and-recalibrate passes.
        clock_max_residual_growth: a re-timing step is undone when the joints it moved fit
            worse by more than this factor (the geometric mean of their residual ratios: the
            knee's hinge axis, the hip's and ankle's centre;
            :func:`~lowerlimb.calibration.clock_sync.worse_fits`).
        clock_hint_min_lag_s: a thigh or shank sensor whose two joints' lags, neither counted,
            both say it runs late (or early) against its neighbours by at least this each, s ...
        clock_hint_min_explained: ... each explaining at least this share of its joint's
            mismatch ...
        clock_hint_max_ratio: ... and agreeing within this factor, is re-timed by itself, by the
            mean of the two (where the joints then fit no worse; else a
            :class:`~lowerlimb.calibration.clock_sync.ClockHintWarning` names it). The real walk
            with its right shank 30 ms late: knee +22 ms, ankle −13 ms, explaining 0.21 and 0.28,
            re-timed +18 ms (thigh and shank −44 / −30 mm → −5 / +2 mm; 50 ms late: a thigh
            that fell back on de Leva → −3 mm). As recorded its lags stay within ±3 ms;
            synchronised simulated walks with the real-walk artefacts: no thigh or shank named.
        rest_gravity_warn_mps2: warn (:class:`~lowerlimb.calibration.rest_gravity.AccelerometerOffsetWarning`)
            when an accelerometer's norm at the standing start is further than this from
            9.81 m/s², m/s² (``None``: no check; :mod:`~lowerlimb.calibration.rest_gravity`). The
            real walk's Xsens MTw are within 0.14; local gravity varies by ±0.03.
        rest_gravity_correction: take each accelerometer's offset at the standing start off
            along its standing vertical before the joint fits
            (:func:`~lowerlimb.calibration.rest_gravity.vertical_offsets_removed`; nothing
            without a standing start). Every sensor at rest reads the same gravity, so the
            differences of their norms are sensor errors, which the joint constraint turns
            into centimetres of centre (``benchmarks/results/acc_bias.md``). Off: on the
            simulator it undoes added biases, but on the real walk it trades the thighs
            −10 / +29 for −23 / +16 mm, the left hip-to-ankle distance 23 for 40 mm and the
            worst step 35 for 44 mm.
        thigh_twist: undo the thigh sensor's turn about the femur with the thigh's flexion
            (:mod:`~lowerlimb.calibration.thigh_twist`; applied by
            :func:`lowerlimb.pipeline.process_trial`, recorded in calibration.json
            ``thigh_twist`` and re-applied when that calibration is reused). Off: on the
            simulator it returns the rigid results, but on the real walk it puts both thighs
            30–80 mm longer than Plug-in Gait's (``benchmarks/results/thigh_twist.md``).
        thigh_twist_highpass_hz: high-pass of the thigh's flexion angle that drives the
            twist (against the drift of the gyro's integral), Hz.
        thigh_twist_min_mismatch_deg: no twist is sought when the knee axes from the two
            sensors differ by less than this at standing, degrees (6, as
            ``fit_band_max_mismatch_deg``: a knee that turns as it flexes gives 3–4° on rigid
            sensors, and at 2° the twist found on such knees made knee rotation 6.4 → 8.1°
            worse; a sensor turning 0.15 rad/rad with hip flexion gives 9°).
        thigh_twist_tol_deg: the search stops when the mismatch is within this, degrees.
        thigh_twist_max: the largest twist searched, rad per rad of flexion.
        thigh_twist_slope_deg: the mismatch per unit of twist assumed for the first step,
            degrees per rad/rad (45: between the simulator's 60 and the real walk's 30).
        thigh_twist_steps: at most this many secant steps.
        thigh_twist_min_evidence: warn (``ThighTwistWarning``) when the thigh gyro alone sees less
            than this share of the twist found, or the other sign
            (:func:`~lowerlimb.calibration.thigh_twist.gyro_evidence`; simulated twists: 0.63–0.79,
            the real walk: 0.86–0.88).
    """

    prefilter: bool = True
    filter_regressor: bool = False
    centre_form: str = "norm"
    aligned_window_s: float = 2.0
    aligned_iterations: int = 4
    aligned_joints: tuple[str, ...] = ("hip", "knee")
    hip_in_pelvis_form: str = "aligned"
    cutoff_hz: float | None = None
    cutoff_factor: float = 1.5
    min_cutoff_hz: float = 2.5
    rigid_band: bool = True
    rigid_band_coherence: float = 0.3
    rigid_band_factor: float = 1.0
    rigid_band_max_rotation: float | None = 4.0
    rigid_band_min_hz: float = 2.0
    rigid_band_trigger: float = 3.0
    pair_band_test: bool = True
    pair_band_margin: float = 0.1
    shared_joint_cutoff: bool = True
    angacc_window_s: float = DEFAULT_WINDOW_S
    angacc_polyorder: int = DEFAULT_POLYORDER
    remove_gyro_bias: bool = True
    still_min_s: float = 0.5
    still_end_min_s: float | None = 1.0
    center_bound_m: float = 0.4
    check_sensor_order: bool = True
    check_signs: bool = True
    max_iter: int = 50
    tol: float = 1e-7
    hinge_gravity_rate_rps: float = 0.0
    hinge_band_hz: float | None = 4.0
    hinge_band_max_disagreement_deg: float = 5.0
    sign_raw_window_s: float = 60.0
    sign_raw_min_score: float = 0.7
    sign_drift_free_min_score: float = 0.15
    sign_one_sided_margin: float = 0.15
    hinge_starts: int = 3
    hinge_centre_start_m: float | None = 0.25
    hinge_centre_start_samples: int = 600
    swarm_samples: int = 1500
    n_particles: int = 40
    n_wolves: int = 30
    swarm_iter: int = 300
    hybrid_swarm_iter: int = 60
    seed: int = 0
    noise_floor_mps2: float = 0.1
    noise_floor_rps: float = 0.015
    noise_correction: bool = True
    noise_correction_max_fraction: float = 0.2
    robust: bool = False
    huber_k: float = 1.345
    robust_passes: int = 5
    impact_exclusion: bool = True
    saturation_exclusion: bool = True
    impact_joints: tuple[str, ...] = ("ankle",)
    impact_jerk_mps3: float = 1000.0
    impact_window_s: float = 0.05
    impact_max_excluded: float = 0.5
    impact_max_cutoff_hz: float | None = 12.0
    center_std_tol_m: float = 0.015
    axis_std_tol_deg: float = 1.0
    min_rms_rate_rps: float = 0.1
    anthropometric_prior: bool = True
    prior_stature_m: float = 1.75
    thigh_length_per_stature: float = 422.2 / 1741.0
    shank_length_per_stature: float = 434.0 / 1741.0
    prior_std_along: float = 0.12
    prior_std_across_m: float = 0.035
    prior_std_axis_m: float = 0.06
    prior_weight: float = 1.0
    knee_line_prior: bool = True
    knee_line_mean_m: float = 0.0
    knee_line_std_m: float = 0.04
    knee_line_min_data_std_m: float = 0.005
    knee_line_probe_factors: tuple[float, ...] = (1.5, 3.0)
    knee_line_max_mismatch_deg: float = 5.0
    cutoff_probe: bool = True
    cutoff_probe_factor: float = 1.5
    fit_band_factor: float = 1.5
    fit_band_max_mismatch_deg: float = 6.0
    moving_mismatch_lowpass_hz: float = 1.0
    fit_band_without_standing: bool = True
    fit_band_min_ratio: float = 0.6
    fit_band_max_ratio: float = 1.5
    cutoff_probe_max_samples: int = 6000
    cutoff_shift_warn_m: float = 0.03
    split_half_probe: bool = True
    split_half_warn_m: float = 0.03
    min_fit_rate_hz: float | None = 100.0
    fit_max_samples: int | None = 12000
    clock_sync: bool = True
    clock_max_offset_s: float = 0.06
    clock_min_explained: float = 0.3
    clock_split_tol_s: float = 0.005
    clock_lowpass_hz: float = 10.0
    clock_passes: int = 3
    clock_max_residual_growth: float = 1.1
    clock_hint_min_lag_s: float = 0.01
    clock_hint_min_explained: float = 0.1
    clock_hint_max_ratio: float = 2.0
    rest_gravity_warn_mps2: float | None = 0.2
    rest_gravity_correction: bool = False
    thigh_twist: bool = False
    thigh_twist_highpass_hz: float = 0.1
    thigh_twist_min_mismatch_deg: float = 6.0
    thigh_twist_tol_deg: float = 0.5
    thigh_twist_max: float = 1.0
    thigh_twist_slope_deg: float = 45.0
    thigh_twist_steps: int = 5
    thigh_twist_min_evidence: float = 1.0 / 3.0

    def __post_init__(self) -> None:
        if self.angacc_window_s <= 0:
            raise InputError(f"angacc_window_s must be > 0 s, got {self.angacc_window_s}")
        for name in (
            "prior_stature_m",
            "prior_std_along",
            "prior_std_across_m",
            "prior_std_axis_m",
            "knee_line_std_m",
            "knee_line_min_data_std_m",
            "knee_line_max_mismatch_deg",
            "fit_band_max_mismatch_deg",
            "moving_mismatch_lowpass_hz",
            "hinge_band_max_disagreement_deg",
        ):
            if getattr(self, name) <= 0:
                raise InputError(f"{name} must be > 0, got {getattr(self, name)}")
        if self.hinge_band_hz is not None and not self.hinge_band_hz > 0:
            raise InputError(f"hinge_band_hz must be > 0 Hz or None, got {self.hinge_band_hz}")
        if not 0.0 < self.noise_correction_max_fraction < 1.0:
            raise InputError(
                f"noise_correction_max_fraction must be in (0, 1), got {self.noise_correction_max_fraction}"
            )
        rotation = self.rigid_band_max_rotation
        if rotation is not None and not 1.0 < rotation < math.inf:
            raise InputError(f"rigid_band_max_rotation must be > 1 or None (every segment), got {rotation}")
        if self.huber_k <= 0:
            raise InputError(f"huber_k must be > 0, got {self.huber_k}")
        if self.impact_jerk_mps3 <= 0 or self.impact_window_s < 0:
            raise InputError(
                f"impact_jerk_mps3 must be > 0 and impact_window_s >= 0, got "
                f"{self.impact_jerk_mps3} and {self.impact_window_s}"
            )
        unknown = set(self.impact_joints) - {"hip", "ankle"}
        if unknown:
            raise InputError(f"impact_joints may hold 'hip' and 'ankle', got {sorted(unknown)}")
        if not 0.0 <= self.impact_max_excluded < 1.0:
            raise InputError(f"impact_max_excluded must be in [0, 1), got {self.impact_max_excluded}")
        if self.rest_gravity_warn_mps2 is not None and not self.rest_gravity_warn_mps2 > 0:
            raise InputError(
                f"rest_gravity_warn_mps2 must be > 0 m/s² or None, got {self.rest_gravity_warn_mps2}"
            )
        if self.impact_max_cutoff_hz is not None and not self.impact_max_cutoff_hz > 0:
            raise InputError(f"impact_max_cutoff_hz must be > 0 Hz or None, got {self.impact_max_cutoff_hz}")
        if not all(f > 0 for f in self.knee_line_probe_factors):
            raise InputError(f"knee_line_probe_factors must all be > 0, got {self.knee_line_probe_factors}")
        end = self.still_end_min_s
        if end is not None and not 0 < end < math.inf:
            raise InputError(f"still_end_min_s must be > 0 s or None (no bias from a still end), got {end}")
        if self.min_fit_rate_hz is not None and not 0 < self.min_fit_rate_hz < math.inf:
            raise InputError(f"min_fit_rate_hz must be > 0 Hz or None, got {self.min_fit_rate_hz}")
        if self.fit_max_samples is not None and self.fit_max_samples < 100:
            raise InputError(f"fit_max_samples must be >= 100 or None, got {self.fit_max_samples}")
        if self.cutoff_probe_max_samples < 100:
            raise InputError(f"cutoff_probe_max_samples must be >= 100, got {self.cutoff_probe_max_samples}")
        for name in ("split_half_warn_m", "cutoff_shift_warn_m"):
            if not 0.0 < getattr(self, name) < math.inf:
                raise InputError(f"{name} must be a length > 0 in m, got {getattr(self, name)}")
        if not 1.0 <= self.fit_band_factor < math.inf:
            raise InputError(f"fit_band_factor must be >= 1 (1: no widened fit), got {self.fit_band_factor}")
        if not 0.0 < self.fit_band_min_ratio < 1.0 < self.fit_band_max_ratio < math.inf:
            raise InputError(
                "fit_band_min_ratio must be in (0, 1) and fit_band_max_ratio > 1, got "
                f"{self.fit_band_min_ratio} and {self.fit_band_max_ratio}"
            )
        if not self.cutoff_probe_factor > 1.0:
            raise InputError(f"cutoff_probe_factor must be > 1, got {self.cutoff_probe_factor}")
        if not 0.0 < self.clock_min_explained <= 1.0:
            raise InputError(f"clock_min_explained must be in (0, 1], got {self.clock_min_explained}")
        if not (
            self.clock_max_offset_s > 0
            and self.clock_lowpass_hz > 0
            and self.clock_split_tol_s > 0
            and self.clock_passes >= 1
        ):
            raise InputError(
                f"clock_max_offset_s, clock_lowpass_hz and clock_split_tol_s must be > 0 and "
                f"clock_passes >= 1, got {self.clock_max_offset_s}, {self.clock_lowpass_hz}, "
                f"{self.clock_split_tol_s}, {self.clock_passes}"
            )
        if not self.clock_max_residual_growth >= 1.0:
            raise InputError(
                f"clock_max_residual_growth must be >= 1 (1: any growth undoes a step), got "
                f"{self.clock_max_residual_growth}"
            )
        self._check_thigh_twist()
        if self.centre_form not in CENTRE_FORMS:
            forms = ", ".join(CENTRE_FORMS)
            raise InputError(f"centre_form must be one of {forms}, got {self.centre_form!r}")
        if self.hip_in_pelvis_form not in CENTRE_FORMS:
            forms = ", ".join(CENTRE_FORMS)
            raise InputError(f"hip_in_pelvis_form must be one of {forms}, got {self.hip_in_pelvis_form!r}")
        if not set(self.aligned_joints) <= {"hip", "knee"}:
            raise InputError(f"aligned_joints may hold 'hip' and 'knee', got {list(self.aligned_joints)}")
        if not self.sign_raw_window_s > 0:
            raise InputError(f"sign_raw_window_s must be > 0 s, got {self.sign_raw_window_s}")
        if not 0.0 <= self.sign_raw_min_score <= 1.0:
            raise InputError(f"sign_raw_min_score must be in [0, 1], got {self.sign_raw_min_score}")
        if not 0.0 <= self.sign_drift_free_min_score <= 1.0:
            raise InputError(
                f"sign_drift_free_min_score must be in [0, 1], got {self.sign_drift_free_min_score}"
            )
        if not self.aligned_window_s > 0 or self.aligned_iterations < 1:
            raise InputError(
                f"aligned_window_s must be > 0 s and aligned_iterations >= 1, got "
                f"{self.aligned_window_s} and {self.aligned_iterations}"
            )
        if self.hinge_centre_start_samples < 50:
            raise InputError(
                f"hinge_centre_start_samples must be >= 50, got {self.hinge_centre_start_samples}"
            )
        start = self.hinge_centre_start_m
        if start is not None and not 0 < start < self.center_bound_m:
            raise InputError(
                f"hinge_centre_start_m must be > 0 and < center_bound_m ({self.center_bound_m:g} m) or None, "
                f"got {start}"
            )
        if self.center_bound_m <= 0:
            raise InputError(f"center_bound_m must be > 0 m, got {self.center_bound_m}")
        for name in (
            "max_iter",
            "hinge_starts",
            "swarm_samples",
            "n_particles",
            "n_wolves",
            "swarm_iter",
            "hybrid_swarm_iter",
            "robust_passes",
        ):
            if getattr(self, name) < 1:
                raise InputError(f"{name} must be >= 1, got {getattr(self, name)}")

    def _check_thigh_twist(self) -> None:
        if not (
            0.0 < self.thigh_twist_highpass_hz < math.inf
            and 0.0 <= self.thigh_twist_min_mismatch_deg < math.inf
            and 0.0 < self.thigh_twist_tol_deg < math.inf
            and 0.0 < self.thigh_twist_max < math.inf
            and 0.0 < self.thigh_twist_slope_deg < math.inf
            and self.thigh_twist_steps >= 1
            and 0.0 <= self.thigh_twist_min_evidence < math.inf
        ):
            raise InputError(
                "thigh_twist_highpass_hz, thigh_twist_tol_deg, thigh_twist_max and thigh_twist_slope_deg "
                "must be > 0, thigh_twist_min_mismatch_deg and thigh_twist_min_evidence >= 0 and "
                "thigh_twist_steps >= 1, got "
                f"{self.thigh_twist_highpass_hz}, {self.thigh_twist_tol_deg}, {self.thigh_twist_max}, "
                f"{self.thigh_twist_slope_deg}, {self.thigh_twist_min_mismatch_deg}, "
                f"{self.thigh_twist_min_evidence}, {self.thigh_twist_steps}"
            )
