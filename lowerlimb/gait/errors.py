"""Errors of the gait layer; each carries the data that explains it."""

from __future__ import annotations

from lowerlimb.errors import InputError

__all__ = ["GaitSignalError", "NoGaitCyclesError"]


class GaitSignalError(InputError):
    """An IMU signal given to the gait layer has the wrong shape or is not finite."""

    def __init__(self, name: str, shape: tuple[int, ...], expected: str) -> None:
        self.name = name
        self.shape = shape
        self.expected = expected
        super().__init__(
            f"'{name}' has shape {shape} but {expected} is needed; pass the sensor-frame "
            f"signal as an (N, 3) array of finite values, one row per sample"
        )


class NoGaitCyclesError(InputError):
    """No mid-swing peak was found: the shank signal shows no walking."""

    def __init__(self, side: str, peak_rps: float, required_rps: float) -> None:
        self.side = side
        self.peak_rps = peak_rps
        self.required_rps = required_rps
        super().__init__(
            f"no gait cycle on the {side} side: the largest smoothed sagittal shank rate is "
            f"{peak_rps:.2f} rad/s, below the mid-swing threshold {required_rps:.2f} rad/s; "
            f"check that this is the shank gyro of a walking trial, in rad/s "
            f"(or lower GaitParams.midswing_min_rps)"
        )
