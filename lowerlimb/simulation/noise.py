"""Sensor error models of the simulator: white noise, constant gyro and accelerometer biases, soft tissue."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import FloatArray


@dataclass(frozen=True)
class ImuNoise:
    """White noise and bias added to the ideal IMU signals.

    The default is a realistic consumer-grade MEMS IMU at 100 Hz
    (docs/methods.md: gyro 0.01–0.02 rad/s, accelerometer 0.05–0.1 m/s² white noise,
    constant gyro bias ≈ 0.01 rad/s).

    Attributes:
        gyr_std_rps: gyro white-noise standard deviation per axis, rad/s.
        acc_std_mps2: accelerometer white-noise standard deviation per axis, m/s².
        gyr_bias_rps: norm of the constant gyro bias of each sensor (random
            direction), rad/s.
        mag_std_ut: magnetometer white-noise standard deviation per axis, µT.
        acc_bias_mps2: norm of the constant accelerometer bias of each sensor (random
            direction), m/s². Off by default (the benchmarks' walks predate it); the real
            walk's Xsens MTw read 9.83–9.95 m/s² at rest, so 0.02–0.14 m/s² along their
            standing vertical, and consumer MEMS parts are specified at 0.2–0.6 m/s²
            (``benchmarks/results/acc_bias.md``).
    """

    gyr_std_rps: float = 0.015
    acc_std_mps2: float = 0.08
    gyr_bias_rps: float = 0.01
    mag_std_ut: float = 0.5
    acc_bias_mps2: float = 0.0

    @classmethod
    def none(cls) -> ImuNoise:
        """Noise-free, bias-free signals."""
        return cls(0.0, 0.0, 0.0, 0.0)

    def to_dict(self) -> dict[str, float]:
        """The noise levels by name (truth files record them)."""
        return {
            "gyr_std_rps": self.gyr_std_rps,
            "acc_std_mps2": self.acc_std_mps2,
            "gyr_bias_rps": self.gyr_bias_rps,
            "mag_std_ut": self.mag_std_ut,
            "acc_bias_mps2": self.acc_bias_mps2,
        }

    def acc_bias(self, rng: np.random.Generator) -> FloatArray:
        """(3,) one sensor's constant accelerometer bias, m/s² (zeros, drawing nothing, when off)."""
        if not self.acc_bias_mps2:
            return np.zeros(3)
        d = rng.normal(size=3)
        return self.acc_bias_mps2 * d / np.linalg.norm(d)


@dataclass(frozen=True)
class SoftTissue:
    """Soft-tissue artefact: each IMU slides on its segment linearly with joint angles.

    The displacement of sensor S in its segment frame is ``Δ_S = Σ_j a_Sj θ_j``
    over the joint angles that deform the tissue under it (pelvis: hip
    flexion; thigh: hip and knee flexion; shank: knee and ankle flexion;
    foot: ankle flexion), with ``a_Sj`` random directions of norm
    ``amplitude_m_per_rad`` (as in the time-varying S2J paper, Lee & Lee 2022).

    Attributes:
        amplitude_m_per_rad: displacement per radian of joint angle, m/rad.
        seed: seeds the directions ``a_Sj``: they belong to the subject and
            the mounting, so trials of one subject share them. ``None`` uses
            the trial's seed.
    """

    amplitude_m_per_rad: float = 0.012
    seed: int | None = None
