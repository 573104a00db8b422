"""A gyro's unit from its accelerometer (``lowerlimb.io.gyro_scale``): slow motions in deg/s, and
rad/s data shrunk 57 times, which the range check cannot see."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from simcache import cached_simulation, data_dir, real_walk_leg_mapping

import lowerlimb as ll
from lowerlimb.errors import UnitError
from lowerlimb.io.gyro_scale import gyro_scale
from lowerlimb.io.trial import ImuTrial

DEG = np.pi / 180.0


def _slowed(trial: ImuTrial, factor: float, gyro_scale_factor: float) -> ImuTrial:
    """The trial played ``factor`` times slower, its gyro multiplied by ``gyro_scale_factor``."""
    return ImuTrial(
        trial.time_s * factor,
        {k: v.copy() for k, v in trial.acc.items()},
        {k: v * gyro_scale_factor / factor for k, v in trial.gyr.items()},
        None,
        side=trial.side,
    )


def test_a_slow_squat_in_degrees_per_second_is_refused() -> None:
    """Its fastest turn (32 deg/s read as rad/s) passes the range check; its turns do not."""
    trial = _slowed(cached_simulation("half-squat", 30.0, 1).trial, 3.5, 1.0 / DEG)
    assert max(np.abs(g).max() for g in trial.gyr.values()) < 35.0, "the range check must not see it"
    with pytest.raises(UnitError, match="gyro looks like deg/s.*multiply by π/180"):
        trial.validate()
    fixed = _slowed(cached_simulation("half-squat", 30.0, 1).trial, 3.5, 1.0)
    fixed.validate()


def test_a_gyro_57_times_too_small_is_refused() -> None:
    trial = _slowed(cached_simulation("sit-to-stand", 30.0, 1).trial, 1.0, DEG)
    with pytest.raises(UnitError, match="gyro turns about 57 times too little"):
        trial.validate()


@pytest.mark.parametrize("motion", ["walk", "squat", "half-squat", "knee-lift", "sit-to-stand", "mixed"])
def test_valid_simulated_gyros_land_near_the_accelerometer(motion: str) -> None:
    trial = cached_simulation(motion, 30.0, 1).trial
    for sensor in trial.gyr:
        scale = gyro_scale(trial.acc[sensor], trial.gyr[sensor], trial.rate_hz)
        assert scale.verdict() is None and not scale.as_given > 15.0, (sensor, scale)


DATA = data_dir()


@pytest.mark.data
@pytest.mark.skipif(DATA is None or not (DATA / "gait").is_dir(), reason="real-walk data absent")
def test_the_real_walks_gyros_land_within_two_degrees() -> None:
    assert DATA is not None
    for side in ("left", "right"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            t = ll.read_xsens(DATA / "gait" / "rawimu", real_walk_leg_mapping(side), side=side)
        for sensor in t.gyr:
            scale = gyro_scale(t.acc[sensor], t.gyr[sensor], t.rate_hz)
            assert scale.n_windows >= 100 and scale.as_given < 2.0, (side, sensor, scale)


def test_a_noisy_accelerometer_still_finds_its_quiet_moments() -> None:
    """At 0.25 m/s² of noise per axis no moment was quiet (0.3 m/s²) and nothing was decided."""
    rng = np.random.default_rng(0)
    base = cached_simulation("half-squat", 30.0, 1).trial
    noisy = {k: v + rng.normal(0.0, 0.25, v.shape) for k, v in base.acc.items()}
    trial = ImuTrial(base.time_s * 3.5, noisy, {k: np.degrees(v) / 3.5 for k, v in base.gyr.items()}, None)
    with pytest.raises(UnitError, match="gyro looks like deg/s"):
        trial.validate()
    fine = ImuTrial(base.time_s * 3.5, noisy, {k: v / 3.5 for k, v in base.gyr.items()}, None)
    fine.validate()
