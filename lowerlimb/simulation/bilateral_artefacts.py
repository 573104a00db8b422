"""The realism profile on the seven-IMU walk: non-rigid sensors on both legs, seven sensors' errors.

The single-leg simulator's profile (:mod:`lowerlimb.simulation.artefacts`) applied leg by
leg to :func:`~lowerlimb.simulation.bilateral_walk.simulate_bilateral`:

- each leg's pelvis, thigh, shank and foot sensor moves on its segment
  (:func:`~lowerlimb.simulation.simulator.tissue_at_contacts`): impacts at the leg's own
  initial contacts (ipsilateral) and at the other foot's (contralateral), weighted by the
  walk's start-up ramp; wobbling tissue driven by the leg's rigid sensor accelerations;
  skin motion driven by the leg's joint angles, rates and accelerations;
- the one pelvis sensor is the left leg's: the right leg's pelvis sensor is given the
  left's motion, so the two legs' pelvis frames stay identical (``real_walk()`` has the
  same pelvis impact at either foot's contact);
- the seven sensors draw their own clock offset, jitter, scale and misalignment errors,
  applied to the measured trial only.

Random draws come, in this order, from the profile's own stream: the left leg's skin
directions, the right leg's, then the seven sensors' errors (two-leg sensor order).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..conventions import SENSORS, SIDES, FloatArray
from .artefacts import Artefacts
from .footsteps import FootPlan
from .sensor_errors import SensorErrors
from .simulator import _SensorSignals, _Trajectories, tissue_at_contacts
from .tissue_motion import TissueMotion

__all__ = ["BilateralArtefactTruth", "bilateral_artefact_truth", "bilateral_tissue_motion"]


@dataclass
class BilateralArtefactTruth:
    """What the realism profile did in one seven-IMU walk.

    Attributes:
        params: the :class:`Artefacts` used.
        contact_times_s: ``{side: (K,)}`` initial contacts that drove the impacts, s (each
            leg's ipsilateral impacts; the other side's are its contralateral ones).
        impact_weight: ``{side: (K,)}`` scale of each of those impacts (the start-up ramp), 0–1.
        displacement_m: ``{two-leg sensor: (N, 3)}`` displacement of the sensor from its
            nominal (mean) place, segment frame, m (zero-mean).
        rotation_rad: ``{two-leg sensor: (N, 3)}`` rotation vector from the nominal to the
            actual sensor frame, nominal sensor frame, rad (zero-mean).
        clock_offset_s: ``{two-leg sensor: float}`` constant clock offset: the sample stamped
            ``t`` was taken at ``t + offset`` (plus jitter), s.
        acc_matrix: ``{two-leg sensor: (3, 3)}`` accelerometer scale × misalignment.
        gyr_matrix: ``{two-leg sensor: (3, 3)}`` gyro scale × misalignment.
    """

    params: Artefacts
    contact_times_s: dict[str, FloatArray]
    impact_weight: dict[str, FloatArray]
    displacement_m: dict[str, FloatArray]
    rotation_rad: dict[str, FloatArray]
    clock_offset_s: dict[str, float]
    acc_matrix: dict[str, FloatArray]
    gyr_matrix: dict[str, FloatArray]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (time series reduced to RMS values) for ``truth.json``."""

        def rms(x: dict[str, FloatArray]) -> dict[str, float]:
            return {s: float(np.sqrt(np.mean(np.sum(v**2, axis=1)))) for s, v in x.items()}

        return {
            "params": self.params.to_dict(),
            "contact_times_s": {s: v.tolist() for s, v in self.contact_times_s.items()},
            "impact_weight": {s: v.tolist() for s, v in self.impact_weight.items()},
            "displacement_rms_m": rms(self.displacement_m),
            "rotation_rms_rad": rms(self.rotation_rad),
            "clock_offset_s": dict(self.clock_offset_s),
            "acc_matrix": {s: m.tolist() for s, m in self.acc_matrix.items()},
            "gyr_matrix": {s: m.tolist() for s, m in self.gyr_matrix.items()},
        }


def _other(side: str) -> str:
    return SIDES[1 - SIDES.index(side)]


def bilateral_tissue_motion(
    art: Artefacts,
    rate_hz: float,
    feet: dict[str, FootPlan],
    ramp: FloatArray,
    traj: dict[str, _Trajectories],
    sig: dict[str, _SensorSignals],
    rng: np.random.Generator,
) -> tuple[dict[str, dict[str, TissueMotion]], dict[str, FloatArray]]:
    """Each leg's non-rigid sensor motion, the pelvis sensor's taken from the left leg.

    Args:
        art: the realism profile.
        rate_hz: sampling rate, Hz.
        feet: ``{side: FootPlan}``; their true initial contacts (s) place the impacts.
        ramp: (N,) the walk's start-up ramp (0 standing, 1 walking), weighting each impact.
        traj: ``{side: trajectories}`` of each leg's simulation model (root + leg DOFs).
        sig: ``{side: rigid signals}`` with angular acceleration, before gravity.
        rng: the profile's own random stream (left leg's draws first).

    Returns:
        ``{side: {sensor: TissueMotion}}`` (segment frames) and ``{side: (K,)}`` the weight
        of each ipsilateral impact.
    """
    tissue: dict[str, dict[str, TissueMotion]] = {}
    weights: dict[str, FloatArray] = {}
    for side in SIDES:
        tr = traj[side]
        ipsi = feet[side].events.initial_contact_s
        contra = feet[_other(side)].events.initial_contact_s
        weights[side] = np.interp(ipsi, tr.t, ramp)
        w = (weights[side], np.interp(contra, tr.t, ramp))
        QVA = (tr.Q, tr.V, tr.A)
        tissue[side] = tissue_at_contacts(
            art, rate_hz, tr.t, (ipsi, contra), w, sig[side].acc, sig[side].base_pl, QVA, rng, side
        )
    tissue["right"]["pelvis"] = tissue["left"]["pelvis"]
    return tissue, weights


def bilateral_artefact_truth(
    art: Artefacts,
    errors: SensorErrors,
    feet: dict[str, FootPlan],
    weights: dict[str, FloatArray],
    tissue: dict[str, dict[str, TissueMotion]],
    base_pl: dict[str, dict[str, pin.SE3]],
) -> BilateralArtefactTruth:
    """What the profile did, under the two-leg sensor names (pelvis from the left leg).

    Args:
        art: the realism profile.
        errors: the seven sensors' clock, scale and misalignment errors.
        feet: ``{side: FootPlan}`` (their initial contacts, s).
        weights: ``{side: (K,)}`` impact weights of :func:`bilateral_tissue_motion`.
        tissue: ``{side: {sensor: TissueMotion}}`` of :func:`bilateral_tissue_motion`.
        base_pl: ``{side: {sensor: nominal placement in the segment frame}}``.
    """
    disp: dict[str, FloatArray] = {}
    rot: dict[str, FloatArray] = {}
    for side in SIDES:
        for sensor in SENSORS:
            if sensor == "pelvis" and side != "left":
                continue
            name = sensor if sensor == "pelvis" else f"{side}_{sensor}"
            tm = tissue[side][sensor]
            disp[name] = tm.d
            rot[name] = tm.th @ base_pl[side][sensor].rotation
    return BilateralArtefactTruth(
        params=art,
        contact_times_s={s: feet[s].events.initial_contact_s.copy() for s in SIDES},
        impact_weight=weights,
        displacement_m=disp,
        rotation_rad=rot,
        clock_offset_s=errors.clock_offset_s,
        acc_matrix=errors.acc_matrix,
        gyr_matrix=errors.gyr_matrix,
    )
