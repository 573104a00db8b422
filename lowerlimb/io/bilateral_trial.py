"""``BilateralTrial``: a seven-IMU (two-leg) recording read from the trial CSV (docs/formats.md, "Two legs").

The sensors are :data:`~lowerlimb.io.recording.TWO_LEG_SENSORS` (``pelvis``, then
``left_thigh, left_shank, left_foot, right_thigh, right_shank, right_foot``), each
with the single-leg suffixes ``_acc_{x,y,z}`` (m/s²), ``_gyr_{x,y,z}`` (rad/s) and
optionally ``_mag_{x,y,z}`` (µT). :func:`trial_layout` tells a two-leg header from
a single-leg one. A two-leg trial is validated leg by leg with
:meth:`ImuTrial.validate <lowerlimb.io.trial.ImuTrial.validate>` (``pelvis`` with
each side's three sensors), so its messages are the single-leg ones, with the
column names as they are in the file (``left_thigh_gyr_x``, not ``thigh_gyr_x``).
"""

from __future__ import annotations

import csv
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..conventions import SENSORS, SIDES, FloatArray
from ..errors import InputError, MissingColumnError, TooShortError
from ..stillness import StillPeriod, detect_still_period
from .csv_header import header_line
from .header_units import check_mag_units
from .mag_cells import bridged_magnetometer
from .recording import TWO_LEG_SENSORS
from .time_axis import TimeAxis
from .trial import (
    MIN_DURATION_S,
    ImuTrial,
    NoMotionError,
    check_distinct_sensors,
    check_unique_columns,
    column_names,
    has_all_mag,
    header_names,
    mag_columns,
    on_uniform_clock,
    one_side_prefix,
    read_numbers,
    unreadable_csv,
)

__all__ = ["LAYOUTS", "BilateralTrial", "read_header", "trial_layout", "with_file_names"]

#: The two trial layouts: ``"one_leg"`` (pelvis, thigh, shank, foot) and ``"two_legs"`` (seven IMUs).
LAYOUTS: tuple[str, ...] = ("one_leg", "two_legs")

_LEG_SENSOR = re.compile(r"\b(thigh|shank|foot)(?=_|\b)")


def read_header(path: str | os.PathLike[str]) -> list[str]:
    """The header row of a CSV file as column names (:func:`~lowerlimb.io.trial.header_names`).

    Raises:
        FileNotFoundError: ``path`` does not exist.
        InputError: the file is empty, binary or not UTF-8, or the csv module cannot read its header
            (:func:`~lowerlimb.io.csv_header.header_line`: blank, ``#`` and ``sep=`` lines before it
            are skipped).
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"trial file not found: {path}")
    try:
        return header_names(next(csv.reader([header_line(path).text])))
    except csv.Error as e:
        raise unreadable_csv(path, e) from None


def trial_layout(header: list[str]) -> str:
    """``"two_legs"`` when the header names both sides' ``left_*``/``right_*`` sensors, else ``"one_leg"``.

    A header naming one side only (``pelvis``, ``left_thigh`` …) is that one leg
    (:func:`~lowerlimb.io.trial.one_side_prefix`).

    Raises:
        InputError: the header mixes single-leg (``thigh_acc_x``) and two-leg (``left_thigh_acc_x``) names.
    """
    two = [h for h in header if h.rsplit("_", 2)[0] in TWO_LEG_SENSORS[1:]]
    if not two or one_side_prefix(header) is not None:
        return "one_leg"
    one = [h for h in header if h.rsplit("_", 2)[0] in SENSORS[1:]]
    if one:
        raise InputError(
            f"the header mixes single-leg columns ('{one[0]}') and two-leg columns ('{two[0]}'); "
            f"name the sensors either {', '.join(SENSORS)} (one leg) or "
            f"{', '.join(TWO_LEG_SENSORS)} (two legs), see docs/formats.md"
        )
    return "two_legs"


def with_file_names(e: InputError, side: str) -> InputError:
    """The same error with the leg's sensor names as in the file (``thigh`` → ``left_thigh``)."""
    out = type(e).__new__(type(e))  # the same subclass, its data copied (constructors differ)
    out.__dict__.update(e.__dict__)
    out.args = (_LEG_SENSOR.sub(lambda m: f"{side}_{m.group(1)}", str(e)),) + tuple(e.args[1:])
    for attr in ("column", "signal", "sensor"):
        value = getattr(e, attr, None)
        if isinstance(value, str):
            setattr(out, attr, _LEG_SENSOR.sub(lambda m: f"{side}_{m.group(1)}", value))
    return out


@dataclass
class BilateralTrial(TimeAxis):
    """A synchronous recording of the seven IMUs of a two-leg trial.

    Attributes:
        time_s: (N,) sample times, s, strictly increasing and evenly spaced.
        acc: ``{sensor: (N, 3)}`` specific force in the sensor frame, m/s², for
            every name of :data:`TWO_LEG_SENSORS`.
        gyr: ``{sensor: (N, 3)}`` angular velocity in the sensor frame, rad/s.
        mag: ``{sensor: (N, 3)}`` magnetic field in the sensor frame, µT, or None.
        source: the file it was read from (for messages).
    """

    time_s: FloatArray
    acc: dict[str, FloatArray]
    gyr: dict[str, FloatArray]
    mag: dict[str, FloatArray] | None = None
    source: str = field(default="", repr=False)

    def leg(self, side: str) -> ImuTrial:
        """One leg as a single-leg :class:`ImuTrial`: ``pelvis`` and that side's thigh, shank, foot.

        The arrays are shared, not copied; the pelvis arrays are the same objects in both legs.

        Raises:
            InputError: ``side`` is not ``"left"`` or ``"right"``.
        """
        if side not in SIDES:
            raise InputError(f"unknown side '{side}'; use left or right")

        def pick(signals: dict[str, FloatArray]) -> dict[str, FloatArray]:
            return {s: signals[s if s == "pelvis" else f"{side}_{s}"] for s in SENSORS}

        return ImuTrial(
            self.time_s,
            pick(self.acc),
            pick(self.gyr),
            None if self.mag is None else pick(self.mag),
            side,
            source=self.source,
        )

    def validate(self) -> None:
        """Check the recording leg by leg with :meth:`ImuTrial.validate`; raise the first problem.

        Raises:
            InputError: any problem of :meth:`ImuTrial.validate` (same subclass and wording,
                column names as in the file), or a missing sensor.
        """
        for name, signals in (("acc", self.acc), ("gyr", self.gyr), ("mag", self.mag or {})):
            for sensor in TWO_LEG_SENSORS if name != "mag" or self.mag else ():
                if sensor not in signals:
                    raise MissingColumnError(f"{sensor}_{name}_x", [], self.source, two_legs=True)
        for side in SIDES:
            try:
                self.leg(side).validate()
            except InputError as e:
                raise with_file_names(e, side) from None
        check_distinct_sensors(self.acc, self.gyr, TWO_LEG_SENSORS)

    def check_motion(self, min_gyro_std_rps: float) -> None:
        """Refuse a trial in which either leg has no motion to calibrate from (:meth:`ImuTrial.check_motion`).

        Raises:
            NoMotionError: naming the still sensor as in the file (``right_thigh``); a two-leg
                trial cannot reuse a calibration, so the message does not offer it.
        """
        for side in SIDES:
            try:
                self.leg(side).check_motion(min_gyro_std_rps)
            except NoMotionError as e:
                sensor = f"{side}_{e.sensor}"
                raise NoMotionError(
                    sensor, e.gyro_std_rps, e.required_rps, reusable=False, acc_std_mps2=e.acc_std_mps2
                ) from None

    def still_period(self) -> StillPeriod:
        """The still run at the start of the recording, over all seven IMUs."""
        return detect_still_period(
            [self.gyr[s] for s in TWO_LEG_SENSORS], [self.acc[s] for s in TWO_LEG_SENSORS], self.rate_hz
        )

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> BilateralTrial:
        """Read and validate a two-leg trial CSV.

        Raises:
            FileNotFoundError: when ``path`` does not exist.
            InputError: a single-leg or mixed header, any problem of :meth:`validate`, or a
                non-numeric cell.
        """
        path = os.fspath(path)
        header = read_header(path)
        if trial_layout(header) != "two_legs":
            raise InputError(
                f"{path} is not a two-leg trial: its header has no left_* and right_* sensor columns; "
                f"read a single-leg trial with ImuTrial.from_csv"
            )
        if "time" not in header:
            raise MissingColumnError("time", header, path, two_legs=True)
        check_unique_columns(header, path)
        check_mag_units(header, path)
        has_mag = has_all_mag(header, TWO_LEG_SENSORS)
        signals = ("acc", "gyr", "mag") if has_mag else ("acc", "gyr")
        names = ["time"] + [n for s in TWO_LEG_SENSORS for g in signals for n in column_names(s, g)]
        col = {name: i for i, name in enumerate(header)}
        for n in names:
            if n not in col:
                raise MissingColumnError(n, header, path, two_legs=True)
        raw = read_numbers(path, header, [col[n] for n in names], blank_ok=mag_columns(header))
        if raw.size == 0:
            raise TooShortError(0.0, MIN_DURATION_S)
        k = {n: i for i, n in enumerate(names)}

        def block(sensor: str, signal: str) -> FloatArray:
            return np.ascontiguousarray(raw[:, [k[n] for n in column_names(sensor, signal)]])

        acc = {s: block(s, "acc") for s in TWO_LEG_SENSORS}
        gyr = {s: block(s, "gyr") for s in TWO_LEG_SENSORS}
        mag = {s: block(s, "mag") for s in TWO_LEG_SENSORS} if has_mag else None
        mag = bridged_magnetometer(raw[:, 0], mag)
        time_s, acc, gyr, mag = on_uniform_clock(raw[:, 0].copy(), acc, gyr, mag)
        trial = cls(time_s, acc, gyr, mag, source=path)
        trial.validate()
        return trial

    @classmethod
    def from_legs(cls, left: ImuTrial, right: ImuTrial) -> BilateralTrial:
        """Join two single-leg trials that share the pelvis sensor (the left trial's pelvis is kept).

        Raises:
            InputError: the two trials have different time axes.
        """
        if left.time_s.shape != right.time_s.shape or not np.allclose(left.time_s, right.time_s):
            raise InputError("the two legs have different time axes; give trials of one recording")

        def join(a: dict[str, FloatArray], b: dict[str, FloatArray]) -> dict[str, FloatArray]:
            out = {"pelvis": a["pelvis"]}
            out |= {f"left_{s}": a[s] for s in SENSORS[1:]}
            out |= {f"right_{s}": b[s] for s in SENSORS[1:]}
            return out

        mag = None if left.mag is None or right.mag is None else join(left.mag, right.mag)
        return cls(left.time_s.copy(), join(left.acc, right.acc), join(left.gyr, right.gyr), mag)

    def header(self) -> list[str]:
        """CSV header of this trial (docs/formats.md, "Two legs")."""
        names = ["time"]
        for s in TWO_LEG_SENSORS:
            names += column_names(s, "acc") + column_names(s, "gyr")
            if self.mag is not None:
                names += column_names(s, "mag")
        return names

    def to_csv(self, path: str | os.PathLike[str]) -> None:
        """Write the two-leg trial CSV (full float precision)."""
        cols = [self.time_s[:, None]]
        for s in TWO_LEG_SENSORS:
            cols += [self.acc[s], self.gyr[s]] + ([self.mag[s]] if self.mag is not None else [])
        np.savetxt(
            path, np.hstack(cols), delimiter=",", header=",".join(self.header()), comments="", fmt="%.9g"
        )
