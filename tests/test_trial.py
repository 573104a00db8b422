import numpy as np
import pytest
from simcache import cached_simulation

from lowerlimb.errors import (
    MissingColumnError,
    NonFiniteValueError,
    TimeAxisError,
    TooShortError,
    UnitError,
)
from lowerlimb.io import PacketGapError
from lowerlimb.io.trial import ImuTrial, PartialMagnetometerWarning, StandingStartWarning


def _trial():
    return cached_simulation("walk", 4.0, 3).trial


def _write(tmp_path, trial, edit=None):
    header = trial.header()
    data = trial.to_array()
    if edit:
        header, data = edit(header, data)
    path = tmp_path / "t.csv"
    np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.9g")
    return path


def test_csv_round_trip(tmp_path):
    trial = _trial()
    path = tmp_path / "t.csv"
    trial.to_csv(path)
    back = ImuTrial.from_csv(path, side="left")
    assert np.allclose(back.time_s, trial.time_s)
    for s in trial.acc:
        assert np.allclose(back.acc[s], trial.acc[s], rtol=1e-8, atol=1e-8)
        assert np.allclose(back.gyr[s], trial.gyr[s], rtol=1e-8, atol=1e-8)
        assert np.allclose(back.mag[s], trial.mag[s], rtol=1e-8, atol=1e-7)
    assert back.rate_hz == pytest.approx(100.0)


def test_missing_column(tmp_path):
    def drop(h, d):
        i = h.index("shank_gyr_y")
        return h[:i] + h[i + 1 :], np.delete(d, i, axis=1)

    with pytest.raises(MissingColumnError, match="missing column 'shank_gyr_y'") as e:
        ImuTrial.from_csv(_write(tmp_path, _trial(), drop))
    assert e.value.column == "shank_gyr_y"


def test_header_names_are_read_in_any_case(tmp_path):
    trial = _trial()
    back = ImuTrial.from_csv(_write(tmp_path, trial, lambda h, d: ([n.upper() for n in h], d)), side="left")
    np.testing.assert_array_equal(back.gyr["foot"], ImuTrial.from_csv(_write(tmp_path, trial)).gyr["foot"])


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("time", "time_s", r"missing column 'time' .*\(the file has 'time_s': rename it 'time', in s\)"),
        ("time", "Timestamp", r"\(the file has 'timestamp': rename it 'time', in s\)"),
        ("thigh_acc_y", "thigh_accel_y", r"\(the file has 'thigh_accel_y': rename it 'thigh_acc_y'\)"),
    ],
)
def test_a_misnamed_column_is_pointed_at(tmp_path, old, new, message):
    def rename(h, d):
        return [new if n == old else n for n in h], d

    with pytest.raises(MissingColumnError, match=message):
        ImuTrial.from_csv(_write(tmp_path, _trial(), rename))


def test_a_missing_axis_is_not_called_a_misnamed_neighbour(tmp_path):
    def drop(h, d):
        i = h.index("shank_gyr_y")
        return h[:i] + h[i + 1 :], np.delete(d, i, axis=1)

    with pytest.raises(MissingColumnError) as e:
        ImuTrial.from_csv(_write(tmp_path, _trial(), drop))
    assert "rename" not in str(e.value)


def test_nan(tmp_path):
    def nan(h, d):
        d = d.copy()
        d[10, h.index("foot_acc_z")] = np.nan
        return h, d

    with pytest.raises(NonFiniteValueError, match="'foot_acc_z' has a NaN or infinite value at data row 11"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), nan))


def test_non_increasing_time(tmp_path):
    def back(h, d):
        d = d.copy()
        d[50, 0] = d[49, 0]
        return h, d

    with pytest.raises(TimeAxisError, match="not strictly increasing.*sort the rows"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), back))


def test_stamps_repeated_in_batches_are_not_called_duplicates(tmp_path):
    def batches(h, d):
        d = d.copy()
        d[:, 0] = d[3::4, 0].repeat(4)  # four samples a batch, stamped as the last arrived
        return h, d

    trial = _trial()
    assert trial.n_samples % 4 == 0
    with pytest.raises(TimeAxisError, match=r"in 300 of 399 steps \(first at data rows 1 and 2.*in batches"):
        ImuTrial.from_csv(_write(tmp_path, trial, batches))


def test_a_gap_too_long_to_fill_is_refused(tmp_path):
    def gap(h, d):
        d = d.copy()
        d[200:, 0] += 0.5
        return h, d

    with pytest.raises(PacketGapError, match=r"gap of 0.51 s at 1.990 s.*cut the recording"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), gap))


def test_uneven_time_built_in_code_is_refused():
    trial = _trial()
    t = trial.time_s.copy()
    t[200:] += 0.05
    with pytest.raises(TimeAxisError, match="resample the trial to a constant rate.*on_uniform_clock"):
        ImuTrial(t, trial.acc, trial.gyr, trial.mag, "left").validate()


def test_gyro_in_degrees(tmp_path):
    def deg(h, d):
        d = d.copy()
        for s in ("pelvis", "thigh", "shank", "foot"):
            for a in "xyz":
                d[:, h.index(f"{s}_gyr_{a}")] = np.rad2deg(d[:, h.index(f"{s}_gyr_{a}")])
        return h, d

    with pytest.raises(UnitError, match=r"look like deg/s.*multiply by π/180"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), deg))


def test_accelerometer_in_g(tmp_path):
    def g(h, d):
        d = d.copy()
        for a in "xyz":
            d[:, h.index(f"thigh_acc_{a}")] /= 9.81
        return h, d

    with pytest.raises(UnitError, match=r"thigh accelerometer .* looks like g.*multiply by 9.81"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), g))


def test_too_short(tmp_path):
    with pytest.raises(TooShortError, match="at least 2.0 s are needed"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), lambda h, d: (h, d[:150])))


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        ImuTrial.from_csv(tmp_path / "nope.csv")


def test_standing_start_detected():
    trial = _trial()
    n = trial.standing_samples()
    assert 140 <= n <= 200  # 1.5 s still, then a slow quintic ramp starts
    ref = trial.reference_samples()
    assert ref.start == 0 and 100 <= ref.stop <= 150


def test_no_standing_start_warns_once():
    trial = _trial()
    cut = ImuTrial(
        trial.time_s[200:],
        {k: v[200:] for k, v in trial.acc.items()},
        {k: v[200:] for k, v in trial.gyr.items()},
        None,
        "left",
    )
    assert not cut.has_standing_start()
    with pytest.warns(StandingStartWarning, match="first second is taken as the angle reference"):
        ref = cut.reference_samples()
    assert ref == slice(0, 100)


def test_time_in_milliseconds(tmp_path):
    def ms(h, d):
        d = d.copy()
        d[:, 0] *= 1000.0
        return h, d

    with pytest.raises(UnitError, match=r"look like milliseconds.*divide the time column by 1000"):
        ImuTrial.from_csv(_write(tmp_path, _trial(), ms))


@pytest.mark.parametrize(
    ("scale", "unit", "divisor"),
    [
        (1e6, "microseconds", "1e6"),
        (1e9, "nanoseconds", "1e9"),
        (100.0, "milliseconds or sample numbers", "1000"),
    ],
)
def test_time_in_other_units(tmp_path, scale, unit, divisor):
    """The fix names the unit the steps look like (µs, ns; a step of 1 may be sample numbers at 100 Hz)."""

    def scaled(h, d):
        d = d.copy()
        d[:, 0] *= scale
        return h, d

    with pytest.raises(UnitError, match=rf"look like {unit} .*divide the time column by {divisor}\b") as e:
        ImuTrial.from_csv(_write(tmp_path, _trial(), scaled))
    assert ("divide by the rate in Hz" in str(e.value)) == (scale == 100.0)


def test_from_sample_cuts_every_signal_and_restarts_the_clock():
    trial = _trial()
    cut = trial.from_sample(250)
    assert cut.n_samples == trial.n_samples - 250 and cut.time_s[0] == 0.0
    assert cut.time_s[1] == pytest.approx(trial.time_s[251] - trial.time_s[250])
    for name in ("acc", "gyr"):
        for sensor, x in getattr(cut, name).items():
            assert np.array_equal(x, getattr(trial, name)[sensor][250:])
    assert cut.side == trial.side and cut.rate_hz == pytest.approx(trial.rate_hz)


@pytest.mark.parametrize("bad", [-1, 10_000, 2.5, True])
def test_from_sample_refuses_an_index_outside_the_recording(bad):
    from lowerlimb.errors import InputError

    trial = _trial()
    with pytest.raises(InputError, match="from_sample needs a sample index"):
        trial.from_sample(bad)


def test_magnetometer_of_some_sensors_only_is_said_and_not_used(tmp_path):
    def drop_foot_mag(h, d):
        idx = [h.index(f"foot_mag_{a}") for a in "xyz"]
        return [x for i, x in enumerate(h) if i not in idx], np.delete(d, idx, axis=1)

    path = _write(tmp_path, _trial(), drop_foot_mag)
    with pytest.warns(PartialMagnetometerWarning, match="for pelvis, thigh, shank but not for foot"):
        back = ImuTrial.from_csv(path)
    assert back.mag is None
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # all or none: no warning
        assert ImuTrial.from_csv(_write(tmp_path, _trial())).mag is not None
