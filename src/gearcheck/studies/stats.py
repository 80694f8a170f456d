"""Statistics of a study's table: distributions, failure probabilities with 95 % intervals, and
which inputs matter (numpy and scipy only).

- Probabilities: the Wilson score interval (95 %), which stays inside [0, 1] and is honest at
  0 or n failures (the normal approximation claims certainty there); with no failure in n
  variants it gives an upper bound of about 3.8/n.
- Sensitivity: standardised regression coefficients (SRC: the linear regression of the output on
  the inputs, each scaled by its standard deviation) with R², and the rank version (SRRC) for
  monotone non-linear responses. SRC² sums to R² for independent inputs: where R² is high the
  ranking explains the variance; where it is low, the report says the response is not linear.
"""

from __future__ import annotations

import math

import numpy as np

Z95 = 1.959963984540054  # two-sided 95 % normal quantile
PERCENTILES = (1, 5, 25, 50, 75, 95, 99)


def wilson(failures: int, n: int, z: float = Z95) -> tuple[float, float, float]:
    """(estimate, low, high) of a probability from ``failures`` in ``n`` trials."""
    if n <= 0:
        return math.nan, math.nan, math.nan
    p = failures / n
    denom = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    # at 0 or n failures one end is exactly 0 or 1 (rounding would leave 1e-18)
    low = 0.0 if failures == 0 else max(0.0, centre - half)
    high = 1.0 if failures == n else min(1.0, centre + half)
    return p, low, high


def describe(values: np.ndarray) -> dict[str, float]:
    """Mean, standard deviation, min, max and percentiles of the finite values (n counts them)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return {"n": 0}
    out = {"n": int(v.size), "mean": float(v.mean()), "sd": float(v.std(ddof=1)) if v.size > 1 else 0.0,
           "min": float(v.min()), "max": float(v.max())}
    for q, value in zip(PERCENTILES, np.percentile(v, PERCENTILES), strict=True):
        out[f"p{q:02d}"] = float(value)
    return out


def _ranks(x: np.ndarray) -> np.ndarray:
    from scipy.stats import rankdata

    return rankdata(x, axis=0)


def src(inputs: dict[str, np.ndarray], output: np.ndarray, ranked: bool = False) -> tuple[dict[str, float], float]:
    """Standardised (rank) regression coefficients of ``output`` on ``inputs`` and R². Inputs
    with no spread get 0; rows with a non-finite output are left out."""
    y = np.asarray(output, float)
    keep = np.isfinite(y)
    names = list(inputs)
    x = np.column_stack([np.asarray(inputs[k], float)[keep] for k in names]) if names else np.empty((keep.sum(), 0))
    y = y[keep]
    if y.size < len(names) + 2 or np.std(y) == 0.0:
        return {k: 0.0 for k in names}, math.nan
    if ranked:
        x, y = _ranks(x), _ranks(y)
    sx = x.std(axis=0)
    live = sx > 0
    xs = (x[:, live] - x[:, live].mean(axis=0)) / sx[live]
    ys = (y - y.mean()) / y.std()
    coef, *_ = np.linalg.lstsq(np.column_stack([np.ones(len(ys)), xs]), ys, rcond=None)
    fitted = np.column_stack([np.ones(len(ys)), xs]) @ coef
    r2 = 1.0 - float(np.sum((ys - fitted) ** 2) / np.sum(ys ** 2))
    out = dict.fromkeys(names, 0.0)
    for k, c in zip([n for n, alive in zip(names, live, strict=True) if alive], coef[1:], strict=True):
        out[k] = float(c)
    return out, r2


def failure_curve(x: np.ndarray, failed: np.ndarray, bins: int = 10) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P(failure) against one input: bin centres (equal counts), the fraction failing in each bin,
    and the bin counts."""
    x = np.asarray(x, float)
    failed = np.asarray(failed, bool)
    keep = np.isfinite(x)
    x, failed = x[keep], failed[keep]
    if x.size == 0 or np.ptp(x) == 0.0:
        return np.array([]), np.array([]), np.array([])
    edges = np.unique(np.quantile(x, np.linspace(0, 1, bins + 1)))
    idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, len(edges) - 2)
    counts = np.bincount(idx, minlength=len(edges) - 1)
    fails = np.bincount(idx, weights=failed.astype(float), minlength=len(edges) - 1)
    centres = 0.5 * (edges[:-1] + edges[1:])
    with np.errstate(invalid="ignore", divide="ignore"):
        frac = np.where(counts > 0, fails / np.maximum(counts, 1), np.nan)
    return centres, frac, counts
