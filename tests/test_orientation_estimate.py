"""estimate_orientation: validation at the boundary, with the messages that name the fix."""

import numpy as np
import pytest

from lowerlimb.errors import InputError, NonFiniteValueError, ShapeError, UnitError
from lowerlimb.orientation import MadgwickParams, MahonyParams, estimate_orientation

N = 300


@pytest.fixture()
def still():
    rng = np.random.default_rng(0)
    gyr = 0.01 * rng.normal(size=(N, 3))
    acc = np.tile([0.0, 0.0, 9.81], (N, 1)) + 0.05 * rng.normal(size=(N, 3))
    mag = np.tile([0.0, 20.0, -45.0], (N, 1))
    return gyr, acc, mag


def test_returns_unit_quaternions(still):
    gyr, acc, mag = still
    for method in ("mahony", "ftecf", "madgwick", "quest_kf"):
        for m in (None, mag):
            q = estimate_orientation(gyr, acc, m, rate_hz=100.0, method=method)
            assert q.shape == (N, 4)
            np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
            # sensor axes aligned with ENU: identity
            assert np.degrees(2 * np.arccos(min(1.0, abs(q[-1, 0])))) < 1.0


def test_accepts_lists_and_params(still):
    gyr, acc, _ = still
    q = estimate_orientation(gyr.tolist(), acc.tolist(), rate_hz=100, params=MahonyParams(kp=1.0))
    assert q.shape == (N, 4)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"gyr": np.zeros((N, 2))}, ShapeError, r"gyr must have shape \(N, 3\)"),
        ({"acc": np.zeros((3, N))}, ShapeError, r"transpose it"),
        ({"gyr": np.zeros((0, 3)), "acc": np.zeros((0, 3))}, ShapeError, "no samples"),
        ({"mag": np.zeros((N - 1, 3))}, ShapeError, "same number of samples.*mag 299"),
        ({"rate_hz": 0.0}, InputError, "positive sampling rate"),
        ({"rate_hz": -100.0}, InputError, "positive sampling rate"),
        ({"rate_hz": float("nan")}, InputError, "positive sampling rate"),
        ({"rate_hz": "100"}, InputError, "rate_hz must be a number"),
        ({"method": "kalman"}, InputError, "choose one of mahony, ftecf, madgwick, quest_kf"),
        ({"params": MadgwickParams()}, InputError, "must be a MahonyParams"),
        ({"acc": "abc"}, InputError, "numeric"),
    ],
)
def test_bad_input_raises_with_the_fix(still, kwargs, error, match):
    gyr, acc, mag = still
    args = {"gyr": gyr, "acc": acc, "mag": mag, "rate_hz": 100.0, "method": "mahony"} | kwargs
    with pytest.raises(error, match=match):
        estimate_orientation(
            args.pop("gyr"), args.pop("acc"), args.pop("mag"), rate_hz=args.pop("rate_hz"), **args
        )


def test_nan_names_signal_axis_and_row(still):
    gyr, acc, _ = still
    acc = acc.copy()
    acc[42, 1] = np.nan
    with pytest.raises(NonFiniteValueError, match="'acc_y'.*row 42.*fill or cut the gap") as e:
        estimate_orientation(gyr, acc, rate_hz=100.0)
    assert (e.value.column, e.value.row) == ("acc_y", 42)


def test_gyro_in_deg_per_s(still):
    gyr, acc, _ = still
    gyr = gyr.copy()
    gyr[100:150, 2] = 120.0  # a 120 °/s turn, given in deg/s
    with pytest.raises(UnitError, match=r"look like deg/s.*rad/s \(multiply by π/180\)") as e:
        estimate_orientation(gyr, acc, rate_hz=100.0)
    assert e.value.signal == "gyr"
    assert e.value.value == pytest.approx(120.0)


def test_accelerometer_in_g(still):
    gyr, acc, _ = still
    with pytest.raises(UnitError, match=r"look like g.*m/s² \(multiply by 9.81\)"):
        estimate_orientation(gyr, acc / 9.81, rate_hz=100.0)


def test_start_without_gravity_or_heading(still):
    gyr, acc, mag = still
    acc = acc.copy()
    acc[:10] = 0.0  # a logger that starts with zeros
    with pytest.raises(InputError, match="cut the leading zero samples"):
        estimate_orientation(gyr, acc, rate_hz=100.0)
    with pytest.raises(InputError, match="mag=None for a 6-axis estimate"):
        estimate_orientation(gyr, still[1], np.tile([0.0, 0.0, -45.0], (N, 1)), rate_hz=100.0)
    with pytest.raises(InputError, match="magnetometer reads zero"):
        estimate_orientation(gyr, still[1], np.zeros((N, 3)), rate_hz=100.0)
