"""``ImportedRecording``: what a vendor importer read, one leg (four IMUs) or two legs (seven).

A single-leg recording becomes an :class:`~lowerlimb.io.trial.ImuTrial`
(:meth:`ImportedRecording.to_trial`), validated by ``ImuTrial.validate``.
:class:`~lowerlimb.io.trial.ImuTrial` holds one leg only, so a two-leg recording
is validated leg by leg (``pelvis`` with the ``left_*`` sensors, then with the
``right_*`` sensors, each as an ``ImuTrial``) and written straight to the
two-leg trial CSV of docs/formats.md (:meth:`ImportedRecording.to_csv`).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from lowerlimb.conventions import SENSORS, SIDES, FloatArray, check_side
from lowerlimb.errors import InputError
from lowerlimb.io.trial import ImuTrial, check_distinct_sensors, column_names

from .errors import MappingError

#: Sensor names of a two-leg (seven-IMU) trial, in trial-CSV column order (docs/formats.md).
TWO_LEG_SENSORS: tuple[str, ...] = ("pelvis",) + tuple(f"{s}_{p}" for s in SIDES for p in SENSORS[1:])


def sensor_layout(names: Iterable[str], field_name: str = "sensors") -> tuple[str, ...]:
    """The sensor set that ``names`` spell: :data:`SENSORS` or :data:`TWO_LEG_SENSORS`, in order.

    Raises:
        MappingError: an unknown name, or a set that is neither complete layout.
    """
    given = list(names)
    for name in given:
        if name not in SENSORS and name not in TWO_LEG_SENSORS:
            raise MappingError(
                f"{field_name}.{name}",
                f"unknown segment '{name}'; use {', '.join(SENSORS)} (one leg, with a side) or "
                f"{', '.join(TWO_LEG_SENSORS)} (two legs)",
            )
    layout = TWO_LEG_SENSORS if any(n in TWO_LEG_SENSORS and n != "pelvis" for n in given) else SENSORS
    missing = [s for s in layout if s not in given]
    stray = [s for s in given if s not in layout]
    if stray:
        raise MappingError(
            f"{field_name}.{stray[0]}",
            f"'{stray[0]}' mixes the single-leg and the two-leg names; use either "
            f"{', '.join(SENSORS)} or {', '.join(TWO_LEG_SENSORS)}",
        )
    if missing:
        sides = {n.split("_", 1)[0] for n in given if n in TWO_LEG_SENSORS[1:]}
        one_leg = (
            f" (one leg: name its sensors {', '.join(SENSORS)} and give its side)"
            if layout == TWO_LEG_SENSORS and len(sides) == 1
            else ""
        )
        raise MappingError(
            f"{field_name}.{missing[0]}",
            f"no sensor given for {', '.join(missing)}; a trial needs all of {', '.join(layout)}{one_leg}",
        )
    return layout


@dataclass
class ImportedRecording:
    """A synchronous recording read from vendor files, in trial units.

    Attributes:
        time_s: (N,) sample times, s, starting at 0.
        acc: ``{sensor: (N, 3)}`` specific force in the sensor frame, m/s².
        gyr: ``{sensor: (N, 3)}`` angular velocity in the sensor frame, rad/s.
        mag: ``{sensor: (N, 3)}`` magnetic field in the sensor frame, µT, or None.
        side: instrumented leg of a single-leg recording; None for two legs.
        source: where it was read from (for messages).
        filled: ``{sensor: number of samples filled by interpolation}``.
    """

    time_s: FloatArray
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    mag: dict[str, FloatArray] | None
    side: str | None
    source: str = ""
    filled: dict[str, int] = field(default_factory=dict)

    @property
    def sensors(self) -> tuple[str, ...]:
        """The sensor names in trial-CSV order."""
        return sensor_layout(self.acc)

    @property
    def two_leg(self) -> bool:
        """True for a seven-IMU recording."""
        return self.sensors == TWO_LEG_SENSORS

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.time_s.shape[0])

    @property
    def n_filled(self) -> int:
        """Total samples filled by interpolation, over all sensors."""
        return int(sum(self.filled.values()))

    def _leg_trial(self, side: str, prefix: str) -> ImuTrial:
        def pick(signals: dict[str, FloatArray]) -> dict[str, FloatArray]:
            return {s: signals[s if s == "pelvis" else prefix + s] for s in SENSORS}

        return ImuTrial(
            self.time_s,
            pick(self.acc),
            pick(self.gyr),
            pick(self.mag) if self.mag is not None else None,
            side,
            source=self.source,
        )

    def to_trial(self) -> ImuTrial:
        """The validated single-leg :class:`~lowerlimb.io.trial.ImuTrial`.

        Raises:
            InputError: for a two-leg recording (write it with :meth:`to_csv`), or any
                problem found by :meth:`ImuTrial.validate`.
        """
        if self.two_leg:
            raise InputError(
                "ImuTrial holds one leg; write this two-leg recording with ImportedRecording.to_csv "
                "or 'lowerlimb import', or map pelvis, thigh, shank, foot of one side"
            )
        try:
            side = check_side(self.side or "left")
        except ValueError as e:
            raise MappingError("side", f"{e}; give side left or right") from None
        trial = self._leg_trial(side, "")
        trial.validate()
        return trial

    def validate(self) -> None:
        """Check the recording with :meth:`ImuTrial.validate` (each leg of a two-leg recording).

        Raises:
            InputError: the first problem found; for two legs prefixed with the leg.
            IdenticalSensorsError: two sensors of a two-leg recording (e.g. ``left_thigh``
                and ``right_thigh``) hold identical data.
        """
        if not self.two_leg:
            self.to_trial()
            return
        for side in SIDES:
            try:
                self._leg_trial(side, f"{side}_").validate()
            except InputError as e:
                raise InputError(f"{side} leg: {e}") from e
        check_distinct_sensors(self.acc, self.gyr, TWO_LEG_SENSORS)

    def header(self) -> list[str]:
        """Trial-CSV header (docs/formats.md: single-leg or two-leg names)."""
        names = ["time"]
        for s in self.sensors:
            names += column_names(s, "acc") + column_names(s, "gyr")
            if self.mag is not None:
                names += column_names(s, "mag")
        return names

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Validate, then write the trial CSV (single leg through :meth:`ImuTrial.to_csv`).

        Raises:
            InputError: any problem found by :meth:`validate`.
        """
        if not self.two_leg:
            self.to_trial().to_csv(path)
            return
        self.validate()
        cols = [self.time_s[:, None]]
        for s in self.sensors:
            cols += [self.acc[s], self.gyr[s]] + ([self.mag[s]] if self.mag is not None else [])
        np.savetxt(
            path, np.hstack(cols), delimiter=",", header=",".join(self.header()), comments="", fmt="%.9g"
        )
