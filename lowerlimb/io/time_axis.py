"""The sample-time properties shared by every recording type (one definition)."""

from __future__ import annotations

import numpy as np

from ..conventions import FloatArray

__all__ = ["TimeAxis"]


class TimeAxis:
    """Mixin for dataclasses with ``time_s``: (N,) strictly increasing sample times, s."""

    time_s: FloatArray

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return int(self.time_s.shape[0])

    @property
    def rate_hz(self) -> float:
        """Sampling rate, Hz (from the median time step)."""
        return float(1.0 / np.median(np.diff(self.time_s)))

    @property
    def duration_s(self) -> float:
        """Time span of the recording, s."""
        return float(self.time_s[-1] - self.time_s[0])
