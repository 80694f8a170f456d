"""Plane involute helpers (numpy only)."""

from __future__ import annotations

import numpy as np


def inv(alpha):
    """Involute function inv(α) = tan α − α (radians)."""
    return np.tan(alpha) - alpha


def inv_inverse(value: float) -> float:
    """The pressure angle α (radians) with inv(α) = value, for 0 ≤ value < inv(89°)."""
    if value < 0:
        raise ValueError("inv(α) is non-negative")
    if value == 0:
        return 0.0
    from scipy.optimize import brentq  # lazy: sweep workers import this module and never call it

    return float(brentq(lambda a: inv(a) - value, 0.0, np.radians(89.0), xtol=1e-15))
