"""Each faster path gives the numbers (and the errors) of the slower call it replaced."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter1d
from scipy.signal import csd, welch

from lowerlimb.constraints.prefilter import welch_spectra
from lowerlimb.segments.heading import _gaussian_smooth


@pytest.mark.parametrize(("n", "nper"), [(30000, 128), (1000, 77), (517, 128)])
def test_welch_spectra_are_scipys(n, nper):
    rng = np.random.default_rng(n)
    a = rng.normal(size=n).cumsum()
    b = a + rng.normal(size=n)
    f, P_aa, P_bb, P_ab = welch_spectra(a, b, 100.0, nper)
    f_ref, P_ref = welch(a, fs=100.0, nperseg=nper)
    np.testing.assert_allclose(f, f_ref)
    np.testing.assert_allclose(P_aa, P_ref, rtol=1e-10, atol=1e-12 * P_ref.max())
    np.testing.assert_allclose(
        P_bb, welch(b, fs=100.0, nperseg=nper)[1], rtol=1e-10, atol=1e-12 * P_ref.max()
    )
    np.testing.assert_allclose(
        P_ab, csd(a, b, fs=100.0, nperseg=nper)[1], rtol=1e-10, atol=1e-12 * P_ref.max()
    )


@pytest.mark.parametrize("n", [30000, 1700, 300])
@pytest.mark.parametrize("sigma", [1.0, 50.5, 200.0])
def test_gaussian_smooth_is_ndimage_reflect(n, sigma):
    x = np.random.default_rng(1).normal(size=n).cumsum()
    np.testing.assert_allclose(
        _gaussian_smooth(x, sigma), gaussian_filter1d(x, sigma, mode="reflect"), atol=1e-12 * np.abs(x).max()
    )
