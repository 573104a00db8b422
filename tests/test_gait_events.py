import numpy as np
import pytest

from lowerlimb.gait import (
    GaitParams,
    GaitSignalError,
    NoGaitCyclesError,
    detect_side_events,
    sagittal_rate,
)


def _shank_gyro(rate_hz: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Periodic sagittal shank rate with known IC/TO on exact samples, embedded in 3-D."""
    rng = np.random.default_rng(seed)
    T, n_cycles = 1.1, 8
    t = np.arange(int((n_cycles * T + 2.0) * rate_hz)) / rate_hz
    om = np.zeros_like(t)
    ic, to = [], []
    for k in range(n_cycles):
        t_to = round((1.0 + k * T) * rate_hz) / rate_hz
        t_ic = round((t_to + 0.42) * rate_hz) / rate_hz
        t_ms = 0.5 * (t_to + t_ic)
        om += -2.5 * np.exp(-0.5 * ((t - t_to) / 0.04) ** 2)
        om += 4.5 * np.exp(-0.5 * ((t - t_ms) / 0.06) ** 2)
        om += -1.5 * np.exp(-0.5 * ((t - t_ic) / 0.03) ** 2)
        to.append(t_to)
        ic.append(t_ic)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    other = np.cross(axis, rng.normal(size=3))
    other /= np.linalg.norm(other)
    gyr = om[:, None] * axis + 0.3 * np.sin(2 * np.pi * t / T)[:, None] * other
    gyr += 0.01 * rng.normal(size=gyr.shape)
    return gyr, np.array(ic), np.array(to), axis


@pytest.mark.parametrize("rate_hz", [100.0, 200.0])
def test_events_recovered_to_one_sample(rate_hz):
    gyr, ic, to, _ = _shank_gyro(rate_hz)
    ev = detect_side_events(gyr, rate_hz, "left")
    assert len(ev.initial_contact_s) == len(ic)
    assert len(ev.toe_off_s) == len(to)
    assert np.max(np.abs(ev.initial_contact_s - ic)) <= 1.0 / rate_hz
    assert np.max(np.abs(ev.toe_off_s - to)) <= 1.0 / rate_hz


def test_sagittal_axis_sign_from_data():
    gyr, _, _, axis = _shank_gyro(100.0)
    for sign in (1.0, -1.0):
        sr = sagittal_rate(sign * gyr, 100.0)
        assert abs(abs(sr.axis_in_sensor @ axis) - 1.0) < 1e-2
        assert sr.omega_rps.max() > -sr.omega_rps.min()  # mid-swing is the positive peak
        assert np.sign(sr.axis_in_sensor @ axis) == sign


def test_start_time_offsets_events():
    gyr, ic, _, _ = _shank_gyro(100.0)
    ev = detect_side_events(gyr, 100.0, "right", start_time_s=5.0)
    assert np.allclose(ev.initial_contact_s - 5.0, ic, atol=0.011)


def test_still_shank_raises_with_data():
    with pytest.raises(NoGaitCyclesError, match="no gait cycle on the left side") as e:
        detect_side_events(np.zeros((500, 3)), 100.0, "left")
    assert e.value.required_rps == GaitParams().midswing_min_rps


def test_bad_shapes_raise():
    with pytest.raises(GaitSignalError, match=r"\(N, 3\)"):
        detect_side_events(np.zeros((500, 2)), 100.0, "left")
    gyr, _, _, _ = _shank_gyro(100.0)
    with pytest.raises(GaitSignalError, match="foot_gyr"):
        detect_side_events(gyr, 100.0, "left", foot_gyr=np.zeros((10, 3)), foot_acc=np.zeros((10, 3)))
    bad = gyr.copy()
    bad[3, 1] = np.nan
    with pytest.raises(GaitSignalError, match="NaN"):
        detect_side_events(bad, 100.0, "left")
