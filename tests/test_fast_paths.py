"""Each faster path gives the numbers (and the errors) of the slower call it replaced."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter1d
from scipy.signal import csd, welch

from lowerlimb.constraints.prefilter import welch_spectra
from lowerlimb.errors import InputError
from lowerlimb.io.numeric_csv import read_numeric_table
from lowerlimb.io.trial import ImuTrial
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


@pytest.mark.parametrize(
    "body",
    [
        "0,1.5,2\n0.01,-1e3,4.25\n",
        "0,,2\n0.01,3,4\n",  # empty cell: NaN
        "0,abc,2\n0.01,3,4\n",  # bad cell: NaN
        "0,1,2\n\n0.01,3,4\n",  # blank line
        "0,1,2\r\n0.01,3,4\r\n",
        "# note\n0,1,2\n",
    ],
)
def test_numeric_table_is_genfromtxt(tmp_path, body):
    path = tmp_path / "t.csv"
    path.write_text("time,a,b\n" + body)
    ref = np.genfromtxt(path, delimiter=",", skip_header=1, dtype=float, ndmin=2)
    np.testing.assert_array_equal(read_numeric_table(path), ref)


def test_ragged_rows_keep_their_message(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("time,a\n0,1\n0.01,2,3\n")
    with pytest.raises(InputError, match="rows of unequal length or bad cells"):
        ImuTrial.from_csv(path)
