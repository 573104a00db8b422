"""Realism profile of the simulator: impacts, wobbling soft tissue, skin motion, sensor errors.

Real thigh and shank IMUs in a walk carry heel-strike transients and
soft-tissue oscillation that rigid simulated sensors do not (issue 9). The
:class:`Artefacts` dataclass holds every parameter of these effects in one
place; :meth:`Artefacts.none` switches them off (the simulator then produces
exactly the rigid signals) and :meth:`Artefacts.real_walk` is tuned so that
a simulated walk matches the band powers of the real walk in
``../shared/data/gait`` (``benchmarks/sim_realism.py``).

The model, per sensor (segment frame: x anterior, y along the bone, z right):

1. **Impacts.** At each initial contact of the instrumented foot (and, for the
   pelvis, of the other foot) a Hann force pulse of ``impact_pulse_s`` drives
   a stiff mass–spring–damper "bone" mode of the segment
   (``bone_freq_hz``, ``bone_damping``) along ``impact_direction``; the pulse
   peak is ``impact_mps2[segment]`` (attenuated from foot to pelvis).
2. **Wobbling mass.** The sensor sits on soft tissue: a mass–spring–damper
   per segment (``tissue_freq_hz``, ``tissue_damping``) excited by minus the
   bone's acceleration at the sensor (the rigid motion, without gravity, plus
   the impact mode), scaled by ``tissue_gain``. The tissue displacement also
   rocks the sensor: rotation ``rock_rad_per_m[segment] · n × δ`` with ``n`` the skin
   normal (the sensor's z axis). Each mass is also driven by a force of its own
   (``tissue_random_mps2``: white, independent per sensor and axis, its RMS following
   the segment's own acceleration, so that it is silent at rest): muscle activation,
   the strap and the stride-to-stride variability that make real soft-tissue wobble
   incoherent between two sensors of one joint. Without it every artefact is a linear
   response to the shared gait and impacts, and the two accelerometer norms of a joint
   stay coherent to 15 Hz, where the real walk's fall below 0.3 from 3–5 Hz
   (``benchmarks/results/sim_signatures.md``).
3. **Skin twist.** The sensor turns about the bone's long axis (segment y) with
   the flexion of a driving joint (``skin_twist_driver``: by default the thigh's and
   the shank's with the knee, the pelvis's with the hip, the foot's with the ankle):
   ``skin_twist_rad_per_rad[segment] · θ``, positive an internal rotation of the sensor
   (its front turning medially) on either leg. It tilts the knee axis a hinge fit finds
   in that sensor. Driven by the knee (Akbarshahi et al. 2010, J Biomech 43:1292–1301:
   thigh soft-tissue artefact is mostly a rotation about the femur) the tilt is nearly
   the same from both sensors; driven by the hip, the two knee axis estimates differ at
   standing as on the real walk (0.3 rad/rad internal on both legs: 17–19° against the
   real walk's 17.5 / 18.5°, the left leg's negative as the real one's;
   ``benchmarks/results/sim_signatures.md``).
4. **Skin motion.** A displacement non-linear in the joint angles that
   deform the tissue under the sensor: ``Σ_j c_j θ_j²`` (quadratic) plus
   ``Σ_j e_j θ_sat tanh(θ_j / θ_sat)`` (saturating), random directions of
   norms ``skin_quadratic_m_per_rad2`` and ``skin_saturating_m``.
5. **Sensor errors** (measured trial only, not ``clean``): a constant clock
   offset per sensor and white timing jitter, accelerometer and gyro
   scale-factor errors and axis misalignment: ``M = diag(1 + s) (I + E)``
   with ``E`` a random off-diagonal matrix.

Displacements and rotations are made zero-mean over the trial, so each
sensor's nominal frame (the placement in the truth) is its mean frame.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ..conventions import SENSORS, FloatArray


def _per_segment(pelvis: float, thigh: float, shank: float, foot: float) -> dict[str, float]:
    return dict(zip(SENSORS, (pelvis, thigh, shank, foot), strict=True))


@dataclass(frozen=True)
class Artefacts:
    """Every parameter of the realism profile (see the module docstring).

    Per-segment values are dicts keyed by ``pelvis``, ``thigh``, ``shank``, ``foot``.

    Attributes:
        impact_mps2: peak of the heel-strike force pulse per unit mass on each
            segment at an ipsilateral initial contact, m/s².
        impact_contra_mps2: the same at the other foot's initial contact, m/s².
        impact_pulse_s: duration of the Hann force pulse, s.
        impact_direction: unit-less direction of the pulse in the segment frame
            (normalised), mostly along the bone.
        bone_freq_hz: natural frequency of the segment's impact mode, Hz.
        bone_damping: damping ratio of the impact mode.
        tissue_freq_hz: natural frequency of the wobbling mass under each sensor, Hz.
        tissue_damping: damping ratio of the wobbling mass.
        tissue_gain: fraction of the bone acceleration that excites the tissue.
        tissue_random_mps2: RMS of each wobbling mass's own random force per axis while
            walking, m/s² (scaled by the segment's smoothed acceleration over its RMS).
        rock_rad_per_m: sensor rotation per tissue/skin displacement, per segment, rad/m.
        skin_quadratic_m_per_rad2: norm of the quadratic skin-motion
            coefficient per driving joint angle, m/rad².
        skin_saturating_m: norm of the saturating skin displacement per
            driving joint angle, m.
        skin_saturation_rad: joint angle at which skin sliding saturates, rad.
        skin_twist_rad_per_rad: sensor rotation about the segment's long axis (y) per
            rad of the driving joint's flexion, per segment, rad/rad; positive internal
            (about +y on the right leg, −y on the left: segment frames are not mirrored).
        skin_twist_driver: the joint whose flexion twists each sensor, per segment:
            ``"hip"``, ``"knee"`` or ``"ankle"``.
        clock_offset_std_s: standard deviation of each sensor's constant clock offset, s.
        clock_jitter_std_s: standard deviation of the white sample-time jitter, s.
        acc_scale_std: standard deviation of the accelerometer scale-factor errors (unit-less).
        gyr_scale_std: standard deviation of the gyro scale-factor errors.
        misalignment_std_rad: standard deviation of each off-diagonal axis
            misalignment term (accelerometer and gyro separately), rad.
        seed: seeds the random directions, offsets and matrices; ``None``
            uses the trial's seed (through its own stream, so the rigid
            simulation with the same seed sees the same placements, motion and noise).
    """

    impact_mps2: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    impact_contra_mps2: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    impact_pulse_s: float = 0.03
    impact_direction: tuple[float, float, float] = (0.3, 1.0, 0.0)
    bone_freq_hz: dict[str, float] = field(default_factory=lambda: _per_segment(12.0, 15.0, 20.0, 25.0))
    bone_damping: float = 0.3
    tissue_freq_hz: dict[str, float] = field(default_factory=lambda: _per_segment(10.0, 9.0, 12.0, 25.0))
    tissue_damping: dict[str, float] = field(default_factory=lambda: _per_segment(0.3, 0.25, 0.25, 0.4))
    tissue_gain: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    tissue_random_mps2: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    rock_rad_per_m: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    skin_quadratic_m_per_rad2: dict[str, float] = field(
        default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0)
    )
    skin_saturating_m: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    skin_saturation_rad: float = 0.5
    skin_twist_rad_per_rad: dict[str, float] = field(default_factory=lambda: _per_segment(0.0, 0.0, 0.0, 0.0))
    skin_twist_driver: dict[str, str] = field(
        default_factory=lambda: {"pelvis": "hip", "thigh": "knee", "shank": "knee", "foot": "ankle"}
    )
    clock_offset_std_s: float = 0.0
    clock_jitter_std_s: float = 0.0
    acc_scale_std: float = 0.0
    gyr_scale_std: float = 0.0
    misalignment_std_rad: float = 0.0
    seed: int | None = None

    @classmethod
    def none(cls) -> Artefacts:
        """No artefacts: the simulator's rigid signals, bit-identical to running without a profile."""
        return cls()

    @classmethod
    def real_walk(cls, seed: int | None = None) -> Artefacts:
        """The profile tuned on the real walk (``benchmarks/results/sim_realism.md``)."""
        return cls(
            impact_mps2=_per_segment(17.0, 30.0, 50.0, 50.0),
            impact_contra_mps2=_per_segment(17.0, 3.0, 1.0, 0.5),
            impact_pulse_s=0.03,
            bone_freq_hz=_per_segment(7.0, 8.0, 20.0, 20.0),
            bone_damping=0.4,
            tissue_freq_hz=_per_segment(7.0, 9.0, 12.0, 20.0),
            tissue_damping=_per_segment(0.35, 0.25, 0.2, 0.35),
            tissue_gain=_per_segment(1.0, 1.0, 1.0, 1.0),
            rock_rad_per_m=_per_segment(10.0, 10.0, 10.0, 60.0),
            skin_quadratic_m_per_rad2=_per_segment(0.004, 0.008, 0.006, 0.002),
            skin_saturating_m=_per_segment(0.003, 0.008, 0.006, 0.002),
            skin_saturation_rad=0.5,
            clock_offset_std_s=0.01,
            clock_jitter_std_s=0.0005,
            acc_scale_std=0.01,
            gyr_scale_std=0.01,
            misalignment_std_rad=0.01,
            seed=seed,
        )

    @property
    def active(self) -> bool:
        """Whether any effect is switched on."""
        return self != Artefacts(seed=self.seed)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready parameters."""
        return asdict(self)


@dataclass
class ArtefactTruth:
    """What the artefacts were in one simulation.

    Attributes:
        params: the :class:`Artefacts` used.
        contact_times_s: (K,) initial contacts of the instrumented foot, s.
        contra_contact_times_s: (K',) initial contacts of the other foot, s.
        displacement_m: ``{sensor: (N, 3)}`` artefact displacement of the
            sensor from its nominal (mean) place, segment frame, m (impact mode,
            tissue and skin; zero-mean).
        rotation_rad: ``{sensor: (N, 3)}`` rotation vector from the nominal to
            the actual sensor frame, in the nominal sensor frame, rad (zero-mean).
        clock_offset_s: ``{sensor: float}`` constant clock offset: the sample
            stamped ``t`` was taken at ``t + offset`` (plus jitter), s.
        acc_matrix: ``{sensor: (3, 3)}`` accelerometer scale × misalignment:
            measured = M · true (before noise).
        gyr_matrix: ``{sensor: (3, 3)}`` the same for the gyro (before bias and noise).
    """

    params: Artefacts
    contact_times_s: FloatArray
    contra_contact_times_s: FloatArray
    displacement_m: dict[str, FloatArray]
    rotation_rad: dict[str, FloatArray]
    clock_offset_s: dict[str, float]
    acc_matrix: dict[str, FloatArray]
    gyr_matrix: dict[str, FloatArray]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (time series reduced to RMS values) for ``truth.json``."""
        rms = {s: float(np.sqrt(np.mean(np.sum(d**2, axis=1)))) for s, d in self.displacement_m.items()}
        rot = {s: float(np.sqrt(np.mean(np.sum(r**2, axis=1)))) for s, r in self.rotation_rad.items()}
        return {
            "params": self.params.to_dict(),
            "contact_times_s": self.contact_times_s.tolist(),
            "contra_contact_times_s": self.contra_contact_times_s.tolist(),
            "displacement_rms_m": rms,
            "rotation_rms_rad": rot,
            "clock_offset_s": dict(self.clock_offset_s),
            "acc_matrix": {s: m.tolist() for s, m in self.acc_matrix.items()},
            "gyr_matrix": {s: m.tolist() for s, m in self.gyr_matrix.items()},
        }
