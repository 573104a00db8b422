"""lowerlimb: wearable IMU motion capture of the human leg."""

from __future__ import annotations

__version__ = "0.1.0"

__all__ = ["__version__"]
