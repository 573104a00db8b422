"""The simulated foot's push-off: heel rise about the metatarsal heads, then the toes roll off.

The simulated foot is a rearfoot (the IMU's segment, the leg model's foot) with a
massless toe segment hinged to it at the metatarsophalangeal (MTP) joint. The toe
segment carries no sensor and is not in the leg model; it only constrains where the
rearfoot can be while the toes touch the ground. Terminal stance and pre-swing then
go as Perry & Burnfield (2010, *Gait Analysis*, ch. 4 and 7) describe them:

1. **Forefoot rocker** (heel-off → toe roll): the rearfoot rotates about the MTP joint
   centre, fixed in the world, while the toes lie flat: the MTP joint dorsiflexes by
   as much as the heel rises.
2. **Toe rocker** (pre-swing, from the other foot's initial contact to toe-off): the
   limb unloads onto the other foot, and the toe segment itself tilts about the toe
   tip, which is the last point in contact (the hallux is the last part of the foot
   loaded; Perry & Burnfield 2010, ch. 4 and 7). The MTP joint, and the rearfoot with
   it, is lifted up and forwards while the tip stays put; the toe's tilt accelerates
   up to toe-off, so the joint's dorsiflexion peaks shortly before it.
3. **Toe-off** is the instant the toe tip leaves the ground.

The rearfoot pitch (its rotation about the foot's medio-lateral axis) does not stop
at toe-off: the ankle's largest plantarflexion comes in initial swing, a few per cent
of the cycle after toe-off (Perry & Burnfield 2010, ch. 7: peak plantarflexion ~20° at
the start of initial swing; Winter 2009, *Biomechanics and Motor Control of Human
Movement*, app. A: peak plantarflexion ~62-64 % of the cycle for a toe-off at ~60 %),
so the rearfoot's plantarflexion rate rises from zero at heel-off, peaks in pre-swing
and has already slowed a little at toe-off. The pitch is a polynomial bell of its rate
between heel-off and toe-off (:func:`push_off_shape`). After toe-off the rearfoot keeps
its rate for a few tens of ms and is then stopped within a few tens of ms
(:func:`~.footsteps._post_toe_off_pitch`, durations drawn per walk): on the real walk of
``gait/`` the foot's sagittal rate stays at its toe-off value for ~30 ms and falls to
zero within the next ~30 ms, with a 20-30 m/s² spike of the foot IMU's specific force
where it is stopped. Toe-off is a C¹ join of the foot's motion (the floor's push on the
toe ends there; :func:`~.footsteps._released`), as initial contact is.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PreSwingParams", "push_off_shape", "toe_roll_shape"]


@dataclass(frozen=True)
class PreSwingParams:
    """Geometry and timing of the simulated foot's push-off.

    Attributes:
        mtp_ahead_fraction: The MTP joint's functional rotation axis lies this fraction of
            the foot length ahead of the ankle centre. The anatomical axis, through the
            first and fifth metatarsal heads, crosses the foot's midline at ~68 % of the
            foot length from the heel, and the functional axis of the joint in walking lies
            ~16 % of the foot length anterior to it ("Three-dimensional kinematics of the
            human metatarsophalangeal joint during level walking", Front. Bioeng.
            Biotechnol. 2:73, 2014, doi:10.3389/fbioe.2014.00073): ~84 % from the heel,
            and the simulator's heel is 22 % behind the ankle.
        mtp_height_m: Height of that axis above the sole with the foot flat, m (the
            metatarsal heads' centres ~2 cm up, the functional axis ~2 % of the foot length
            above them; same source).
        toe_tip_fraction: The toe tip lies this fraction of the foot length ahead of the
            ankle, on the sole (de Leva 1996's foot length runs heel to toe tip).
        mtp_at_toe_off_deg: MTP dorsiflexion at toe-off, deg. The toes dorsiflex most
            during push-off, 60° barefoot and 45-50° in soft shoes (Bojsen-Møller &
            Lamoreux 1979, "Significance of free dorsiflexion of the toes in walking", Acta
            Orthop. Scand. 50); that peak comes shortly before toe-off, when the toe rolls
            off over its tip faster than the rearfoot still rises. With 30° here and the
            rearfoot at 55-65° the toe segment is tilted 25-35° at toe-off and the joint
            peaks at ~40-45° some 40 ms earlier.
        largest_plantarflexion_fraction: The rearfoot's plantarflexion rate returns to
            zero this fraction of the stride after toe-off (peak ankle plantarflexion in
            initial swing, a few per cent of the cycle after toe-off; Winter 2009, app. A;
            Perry & Burnfield 2010, ch. 7). It sets the time scale of the stance's
            push-off polynomial (:func:`push_off_shape`); after toe-off the swing's own
            hold and stop take over (:class:`~.footsteps.WalkDraw`).
        toe_roll_power: The toe segment's tilt grows as this power of the time into the toe
            rocker (:func:`toe_roll_shape`). With 3 the metatarsal heads accelerate forwards
            at only 4-7 m/s² in the last 40 ms before toe-off on the walks drawn here; on the
            real walk of ``gait/`` the Plug-in Gait TOE marker, on the second metatarsal
            head, does at 11-14 m/s² (Vicon, 10 Hz low-pass), and the foot IMU's specific
            force rises into toe-off (12 → 20 m/s² over the last 100 ms) where with 3 it
            falls. 4 puts 6-14 m/s² there and the rise back in.
        max_toe_roll_s: The toe rocker lasts the pre-swing (the double support before
            toe-off), at most this long, s. At a normal pace the double support lasts
            0.08-0.14 s; a slow walker's lasts 0.17-0.26 s, but the real walk of ``gait/``,
            slow (0.8 m/s, 1.43 s strides), still rolls off the toe tip fast: its foot
            IMU's specific force peaks at 20-24 m/s² at toe-off, as at a normal pace. A toe
            rocker stretched over the whole slow double support left no such peak (the
            magnitude fell smoothly through toe-off).
    """

    mtp_ahead_fraction: float = 0.62
    mtp_height_m: float = 0.025
    toe_tip_fraction: float = 0.78
    mtp_at_toe_off_deg: float = 30.0
    largest_plantarflexion_fraction: float = 0.05
    toe_roll_power: int = 4
    max_toe_roll_s: float = 0.14


def push_off_shape(u: float, from_standing: bool) -> float:
    """Normalised rearfoot pitch 0 → 1 over heel-off (u = 0) → largest plantarflexion (u = 1).

    The rate is the bell ``∝ u^a (1 − u)``: zero at heel-off and at the largest
    plantarflexion, fastest at ``u = a / (a + 1)``. Walking, ``a = 2`` (the heel leaves the
    floor with zero rate and zero angular acceleration, peak rate at 2/3); from standing,
    ``a = 3`` (zero jerk as well: a straight knee bends like the square root of the heel's
    rise; peak at 3/4).

    Args:
        u: Time from heel-off over the time from heel-off to the largest plantarflexion
            (may exceed 1 for the derivatives at toe-off: the polynomial continues).
        from_standing: The first heel rise of the walk.

    Returns:
        The pitch as a fraction of the largest plantarflexion.
    """
    if from_standing:
        return float(5.0 * u**4 - 4.0 * u**5)
    return float(4.0 * u**3 - 3.0 * u**4)


def toe_roll_shape(v: float, power: int = 4) -> float:
    """Normalised toe-segment tilt 0 → 1 over the toe rocker (v = 0 its start, v = 1 toe-off).

    ``v^power`` (:attr:`PreSwingParams.toe_roll_power`): the toe starts to tilt with zero
    rate and zero angular acceleration (for ``power ≥ 3``: the rearfoot's pose stays C²
    where its pivot moves from the MTP joint to the toe tip), and its tilt still
    accelerates when the tip leaves: the MTP joint is thrown forwards and up hardest just
    before toe-off.
    """
    return float(v**power) if v > 0.0 else 0.0
