import numpy as np
import pytest
from rigid_pair import rigid_pair

from lowerlimb.constraints.angular_acceleration import angular_acceleration, smooth, window_length
from lowerlimb.constraints.prefilter import adaptive_cutoff_hz, lowpass, motion_bandwidth_hz, usable_cutoff_hz
from lowerlimb.errors import InputError, ShapeError


def test_window_length_is_odd_and_long_enough():
    assert window_length(100.0, 0.07, 4) == 7
    assert window_length(40.0, 0.07, 4) == 5  # at least polyorder + 1, odd
    assert window_length(1000.0, 0.05, 2) == 51
    for rate in (10.0, 33.0, 100.0, 285.7):
        n = window_length(rate, 0.07, 4)
        assert n % 2 == 1 and n >= 5


def test_derivative_of_quartic_motion_is_exact():
    t = np.arange(500) / 100.0
    w = np.stack([t**4 - t, 0.5 * t**3, np.ones_like(t)], axis=1)
    dw = np.stack([4 * t**3 - 1, 1.5 * t**2, np.zeros_like(t)], axis=1)
    assert np.allclose(angular_acceleration(w, 100.0), dw, atol=1e-7)


def test_rigid_body_alpha_within_a_fraction_of_its_range():
    p = rigid_pair("spherical", seed=2)
    a = angular_acceleration(p.gyr_child, p.rate_hz)
    err = np.abs(a - p.angacc_child)[5:-5]
    assert err.max() < 0.01 * np.abs(p.angacc_child).max()


def test_smooth_keeps_slow_signal():
    t = np.arange(1000) / 100.0
    x = np.stack([np.sin(2 * np.pi * 0.5 * t)] * 3, axis=1)
    assert np.allclose(smooth(x, 100.0), x, atol=1e-4)


@pytest.mark.parametrize("bad", [np.zeros((10, 2)), np.zeros(30), np.zeros((3, 10, 3))])
def test_shape_errors(bad):
    with pytest.raises(ShapeError, match=r"\(N, 3\)"):
        angular_acceleration(bad, 100.0)


def test_rate_and_length_errors():
    with pytest.raises(InputError, match="rate_hz"):
        angular_acceleration(np.zeros((50, 3)), 0.0)
    with pytest.raises(InputError, match="at least"):
        angular_acceleration(np.zeros((3, 3)), 100.0)


def test_bandwidth_of_a_slow_and_a_fast_motion():
    rng = np.random.default_rng(0)
    t = np.arange(6000) / 100.0
    slow = np.stack([np.sin(2 * np.pi * 1.0 * t)] * 3, axis=1) + 0.015 * rng.normal(size=(6000, 3))
    fast = slow + np.stack([0.5 * np.sin(2 * np.pi * 8.0 * t)] * 3, axis=1)
    b_slow = motion_bandwidth_hz(slow, 100.0, noise_std=0.015)
    b_fast = motion_bandwidth_hz(fast, 100.0, noise_std=0.015)
    assert 0.8 < b_slow < 2.0
    assert 7.5 < b_fast < 10.0
    # without a noise estimate the top of the spectrum sets the level
    assert abs(motion_bandwidth_hz(fast, 100.0) - b_fast) < 1.0
    fc = adaptive_cutoff_hz(slow, 100.0, noise_std=0.015)
    assert fc is not None and 2.5 <= fc < 4.0
    assert adaptive_cutoff_hz(fast + 2 * rng.normal(size=fast.shape), 100.0, noise_std=0.015) is None


def test_lowpass_passes_the_band_and_removes_noise():
    rng = np.random.default_rng(1)
    t = np.arange(4000) / 100.0
    x = np.stack([np.sin(2 * np.pi * 0.7 * t)] * 3, axis=1)
    y = lowpass(x + 0.05 * rng.normal(size=x.shape), 100.0, 4.0)
    assert np.std((y - x)[100:-100]) < 0.015
    assert lowpass(x, 100.0, None) is not None
    assert np.array_equal(lowpass(x, 100.0, None), x)
    with pytest.raises(InputError, match="half the sampling rate"):
        lowpass(x, 100.0, 60.0)


def test_a_derived_cutoff_past_nyquist_leaves_the_signal_unfiltered():
    """A cap times a probe factor can pass 0.45·rate: that means no filter, not an error."""
    from lowerlimb.calibration._prepare import prepare_signals
    from lowerlimb.calibration.options import CalibrationOptions

    assert usable_cutoff_hz(None, 100.0) is None
    assert usable_cutoff_hz(96.1, 100.0) is None and usable_cutoff_hz(45.0, 100.0) is None
    assert usable_cutoff_hz(44.9, 100.0) == 44.9
    rng = np.random.default_rng(2)
    gyr = {k: rng.normal(size=(600, 3)) for k in ("p", "c")}
    acc = {k: 9.81 * np.array([0.0, 0.0, 1.0]) + rng.normal(size=(600, 3)) for k in ("p", "c")}
    # the knee line's probes once asked for 3 x a 32 Hz cap at 100 Hz and raised InputError
    sig = prepare_signals(acc, gyr, 100.0, CalibrationOptions(), n_still=100, set_hz={"p": 96.1, "c": 8.0})
    assert sig.cutoff_hz == {"p": None, "c": 8.0}
    np.testing.assert_allclose(sig.gyr["p"], gyr["p"] - sig.gyro_bias["p"])
