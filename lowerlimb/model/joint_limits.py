"""Effort and velocity limits of the lower-body URDF, from published strength and gait data.

A URDF ``<limit>`` needs an effort (N·m) and a velocity (rad/s). Here they are
the upper end of what healthy adults produce, so that a tool enforcing them
(a MuJoCo actuator, a ROS controller) never clips a real motion:

- **effort**: peak voluntary joint moments of healthy young adults, scaled by
  body mass (N·m/kg), rounded up. Flexion/extension of the hip, knee and ankle:
  isometric and isovelocity dynamometry of Anderson, Madigan & Nussbaum 2007
  ("Maximum voluntary joint torque as a function of joint angle and angular
  velocity", J. Biomech. 40:3105–3113), whose young men reach about 3 N·m/kg at
  the hip and knee and 2–2.5 N·m/kg in plantar flexion; hip ab/adduction and
  rotation: dynamometry of the same order (about 2 and 1 N·m/kg). The knee's
  ab/adduction and rotation and the ankle's inversion and rotation are passive
  or weakly actuated: their limits are the largest moments seen in gait
  (Winter, "Biomechanics and Motor Control of Human Movement", 4th ed., 2009,
  ch. 5), rounded up.
- **velocity**: the largest joint angular velocities of fast human motion —
  about 12–15 rad/s at the hip and 20–25 rad/s at the knee in sprinting and
  kicking, against 4–8 rad/s in walking (Winter 2009, appendix gait data) —
  rounded up; the secondary rotations are bounded at 10 rad/s.

These are bounds for simulators and controllers, not the strength of a given
subject.
"""

from __future__ import annotations

from ..conventions import JOINT_DOF_NAMES, JOINTS

#: Peak joint moment per kg body mass (N·m/kg) of each DOF (flexion, adduction, rotation).
EFFORT_NM_PER_KG: dict[str, tuple[float, float, float]] = {
    "hip": (3.5, 2.0, 1.0),
    "knee": (3.5, 1.0, 0.5),
    "ankle": (2.5, 0.6, 0.5),
}
#: Peak joint angular velocity (rad/s) of each DOF (flexion, adduction, rotation).
VELOCITY_RAD_S: dict[str, tuple[float, float, float]] = {
    "hip": (15.0, 10.0, 10.0),
    "knee": (25.0, 10.0, 10.0),
    "ankle": (20.0, 10.0, 10.0),
}

#: The XML comment written above the joints of the URDF.
LIMITS_SOURCE_COMMENT = (
    " Joint <limit> effort = body mass x peak voluntary moment per kg of healthy young adults, rounded up "
    "(hip/knee/ankle flexion-extension: Anderson, Madigan & Nussbaum 2007, J Biomech 40:3105; "
    "secondary DOFs: largest gait moments, Winter 2009, Biomechanics and Motor Control of Human Movement, "
    "4th ed.); velocity = peak joint angular velocities of sprinting and kicking, rounded up "
    "(walking reaches 4-8 rad/s, Winter 2009). Position limits: anatomical ranges of motion. "
)


def joint_limits(mass_kg: float) -> dict[str, tuple[float, float]]:
    """``{dof name: (effort N·m, velocity rad/s)}`` for a subject of ``mass_kg``, e.g. ``hip_flexion``."""
    out: dict[str, tuple[float, float]] = {}
    for joint in JOINTS:
        for k, dof in enumerate(JOINT_DOF_NAMES[joint]):
            out[dof] = (round(EFFORT_NM_PER_KG[joint][k] * mass_kg, 1), VELOCITY_RAD_S[joint][k])
    return out
