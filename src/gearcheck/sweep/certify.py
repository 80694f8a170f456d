"""Clearance certified over the continuous motion, not only at the sampled poses (numpy only).

A sweep measures a pair's clearance at poses x0 < x1 < …; between two poses the bodies move, and
the clearance there is not measured. It cannot be anything, though: the distance between two bodies
changes by no more than the largest displacement of any of their points (the distance is
1-Lipschitz in each body's placement), so over an interval whose ends have clearances c0 and c1,
while no point moves more than δ along its path over the whole interval,

    c(x) ≥ c0 − δ0(x)  and  c(x) ≥ c1 − δ1(x),  δ0(x) + δ1(x) ≤ δ   ⇒   c ≥ (c0 + c1 − δ) / 2,

and never more than the smaller end. δ is a path length (a rotation's arc, R·Δθ, R the farthest
point from the axis; a translation's length; summed over the two bodies), so it adds over
sub-intervals. Where the bound does not decide a requirement r (it lies below r while both ends
lie above), the interval is split at its middle and the clearance measured there, until every
piece decides, or a piece is so short that its δ is within ``resolution`` (the meshes' own error:
the bound can be no sharper than the measurement), where it is left undecided and reported.

:func:`certify` does this for one pair over one run of poses; the caller supplies the measurement
(a distance query at a coordinate) and the displacement bound of an interval.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np


def interval_bound(c0: float, c1: float, delta: float) -> float:
    """The least clearance an interval can have: its ends' clearances c0, c1, no point moving more
    than ``delta`` (mm, along its path) over it."""
    return min(c0, c1, 0.5 * (c0 + c1 - delta))


@dataclass
class Certificate:
    """A pair's clearance over a run of poses: ``certified_min`` a lower bound over the continuous
    motion, ``sampled_min`` the least clearance measured (at the poses and the refinement points),
    ``at`` the coordinate of the interval holding the certified minimum, ``refined`` the
    measurements added, ``undecided`` the intervals left too short to split (each (x0, x1, bound)),
    ``decides`` whether the bound decides the requirement everywhere."""

    requirement: float
    certified_min: float = math.inf
    sampled_min: float = math.inf
    at: tuple[float, float] = (math.nan, math.nan)
    refined: int = 0
    undecided: list[tuple[float, float, float]] = field(default_factory=list)

    @property
    def decides(self) -> bool:
        return not self.undecided

    @property
    def passed(self) -> bool:
        """The requirement holds over the continuous motion (certified), as far as the bound says."""
        return self.certified_min >= self.requirement


def certify(xs: Sequence[float], cs: Sequence[float], measure: Callable[[float], float],
            displacement: Callable[[float, float], float], requirement: float, resolution: float,
            max_measurements: int = 10_000, precision: float = math.inf, sharpen: int = 0) -> Certificate:
    """Certify a requirement (clearance ≥ ``requirement``) over the motion through the poses ``xs``
    with measured clearances ``cs``; ``measure(x)`` measures at a new coordinate, ``displacement(a,
    b)`` bounds the path of any point over [a, b]. Intervals whose ends already fail are not
    refined (a sample fails the requirement by itself); a piece is split while its bound is below
    the requirement and its δ above ``resolution``, at most ``max_measurements`` new measurements in
    all (then the rest is left undecided).

    Then, with ``sharpen`` > 0, the figure itself: the piece holding the certified minimum is split
    (at most ``sharpen`` more measurements) while its bound lies more than ``precision`` below the
    least clearance measured at its ends, so that the bound reported is close to the true least
    clearance, not only on the right side of the requirement. Clearances may be given as ``inf``
    only where no measurement is finite (callers give a finite lower bound, say a reach)."""
    cert = Certificate(requirement)
    if not len(xs):
        return cert
    cert.sampled_min = float(min(cs))
    stack = [(float(xs[i]), float(xs[i + 1]), float(cs[i]), float(cs[i + 1])) for i in range(len(xs) - 1)]
    stack.reverse()  # in motion order
    done: list[tuple[float, float, float, float, float, float]] = []  # (x0, x1, bound, c0, c1, δ)
    if len(xs) == 1:
        done.append((float(xs[0]), float(xs[0]), float(cs[0]), float(cs[0]), float(cs[0]), 0.0))

    def split(x0: float, x1: float, c0: float, c1: float) -> None:
        xm = 0.5 * (x0 + x1)
        cm = float(measure(xm))
        cert.refined += 1
        cert.sampled_min = min(cert.sampled_min, cm)
        stack.append((xm, x1, cm, c1))
        stack.append((x0, xm, c0, cm))

    def settle() -> None:
        while stack:
            x0, x1, c0, c1 = stack.pop()
            delta = displacement(x0, x1)
            bound = interval_bound(c0, c1, delta)
            ends_pass = min(c0, c1) >= requirement
            if bound >= requirement or not ends_pass:
                done.append((x0, x1, bound, c0, c1, delta))
                continue
            if delta <= resolution or cert.refined >= max_measurements:
                cert.undecided.append((x0, x1, bound))
                done.append((x0, x1, bound, c0, c1, delta))
                continue
            split(x0, x1, c0, c1)

    settle()
    extra = 0
    while extra < sharpen:
        worst = min(range(len(done)), key=lambda k: done[k][2])
        x0, x1, bound, c0, c1, delta = done[worst]
        if min(c0, c1) - bound <= precision or delta <= resolution or x1 <= x0:
            break
        done.pop(worst)
        split(x0, x1, c0, c1)
        extra += 1
        settle()  # both halves decided again
    if extra:  # the undecided pieces that were split are no longer pieces
        pieces = {(d[0], d[1]) for d in done}
        cert.undecided = [u for u in cert.undecided if (u[0], u[1]) in pieces]
    x0, x1, bound = min(done, key=lambda d: d[2])[:3]
    cert.certified_min, cert.at = bound, (x0, x1)
    return cert


def arc_displacement(radius_mm: float, angle_deg: float) -> float:
    """The path length of a point ``radius_mm`` from the axis turned by ``angle_deg``."""
    return radius_mm * math.radians(abs(angle_deg))


@dataclass
class Refined:
    """The least value of a periodic figure over its cycle, refined between the samples:
    ``least`` the least value evaluated (samples and points added), ``at`` where, ``lower`` the
    bracket's lower end: the least any interval can hold by the rate bound, and no higher than
    ``least`` less the precision asked for (the bracket [lower, least] is that wide unless the
    rounds ran out), ``rate`` the largest rate bound used (per unit of x), ``refined`` the points
    added."""

    least: float
    at: float
    lower: float
    rate: float
    refined: int
    rounds: int

    @property
    def bracket(self) -> float:
        return self.least - self.lower


RATE_FACTOR = 2.0  # the rate bound: this many times the steepest slope seen between neighbouring points


def refine_least(xs: Sequence[float], ys: Sequence[float],
                 evaluate: Callable[[list[float]], Sequence[float] | np.ndarray],
                 period: float, precision: float, max_rounds: int = 40, max_points: int = 4096) -> Refined:
    """Refine the least value of a figure y(x) periodic in x (one cycle sampled at ``xs``, the
    values ``ys``; ``evaluate(points)`` gives it at new points, all of a round in one call) until
    its bracket is below ``precision``: over each interval between neighbouring points (the last
    to the first one period on), y ≥ (y0 + y1 − k·Δx)/2 with k the interval's rate bound
    (:data:`RATE_FACTOR` times the steepest slope of it and its two neighbours, the new points
    included: a flat stretch is not held to the rate of a handover elsewhere), and every interval
    whose bound lies more than ``precision`` below the least value is split at its middle.
    A rate read from the samples is not a proof (a dip narrower than the spacing and steeper than
    every slope seen is missed): the refinement brackets the least value of a figure whose rate the
    samples show, to its printed precision; where a proven rate exists, :func:`certify` is the
    tool."""
    return refine_least_many([(xs, ys)], lambda asked: evaluate([x for _, x in asked]), period, precision,
                             max_rounds, max_points)[0]


class _Cycle:
    """One figure's points over its cycle, for :func:`refine_least_many`."""

    def __init__(self, xs: Sequence[float] | np.ndarray, ys: Sequence[float] | np.ndarray, period: float):
        x, y = np.asarray(xs, float), np.asarray(ys, float)
        keep = np.isfinite(y)
        self.x, self.y, self.period = x[keep], y[keep], period
        self.refined = self.rounds = 0
        self._sort()

    def _sort(self) -> None:
        order = np.argsort(self.x)
        self.x, self.y = self.x[order], self.y[order]

    def bounds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(each interval's lower bound, its ends' x (closed over the period), each interval's rate)."""
        xx = np.append(self.x, self.x[0] + self.period)
        yy = np.append(self.y, self.y[0])
        dx = np.diff(xx)
        slope = np.abs(np.diff(yy)) / np.where(dx > 0.0, dx, np.inf)
        rates = RATE_FACTOR * np.maximum.reduce([np.roll(slope, 1), slope, np.roll(slope, -1)])
        bound = np.minimum(np.minimum(yy[:-1], yy[1:]), 0.5 * (yy[:-1] + yy[1:] - rates * dx))
        return bound, xx, rates

    def needed(self, precision: float) -> list[float]:
        bound, xx, _ = self.bounds()
        need = np.flatnonzero(bound < float(self.y.min()) - precision)
        return [float((xx[k] + xx[k + 1]) / 2.0) for k in need]

    def add(self, xs: list[float], ys: np.ndarray) -> None:
        new_x = np.mod(np.asarray(xs) - self.x[0], self.period) + self.x[0]
        keep = np.isfinite(ys)
        self.x, self.y = np.concatenate([self.x, new_x[keep]]), np.concatenate([self.y, ys[keep]])
        self.refined += len(xs)
        self.rounds += 1
        self._sort()

    def result(self, precision: float = 0.0) -> Refined:
        """The bracket: its lower end no higher than the least value less ``precision`` (the rate is
        read from the samples: the bracket is stated at the precision the refinement was asked for,
        whatever the last bounds say)."""
        if not len(self.x):
            return Refined(math.nan, math.nan, math.nan, math.nan, self.refined, self.rounds)
        bound, _, rates = self.bounds()
        i = int(np.argmin(self.y))
        lower = min(float(bound.min()), float(self.y[i]) - precision)
        return Refined(float(self.y[i]), float(self.x[i]), lower, float(rates.max()), self.refined, self.rounds)


def rate_bound(xs: Sequence[float] | np.ndarray, ys: Sequence[float] | np.ndarray, period: float) -> float:
    """The least value a periodic figure sampled at ``xs`` can have by the rate bound of
    :func:`refine_least`, before any point is added (NaN without a finite sample)."""
    return _Cycle(xs, ys, period).result().lower


def refine_least_many(curves: Sequence[tuple[Sequence[float], Sequence[float]]],
                      evaluate: Callable[[list[tuple[int, float]]], Sequence[float] | np.ndarray],
                      period: float, precision: float, max_rounds: int = 40,
                      max_points: int = 4096) -> list[Refined]:
    """:func:`refine_least` for several figures of one period at once: each round asks
    ``evaluate`` for every figure's new points in one call, as (figure index, x) pairs."""
    cycles = [_Cycle(xs, ys, period) for xs, ys in curves]
    for _ in range(max_rounds):
        asked = [(k, x) for k, c in enumerate(cycles) if len(c.x) and c.refined < max_points
                 for x in c.needed(precision)]
        if not asked:
            break
        values = np.asarray(evaluate(asked), float)
        for k, c in enumerate(cycles):
            mine = [i for i, (owner, _) in enumerate(asked) if owner == k]
            if mine:
                c.add([asked[i][1] for i in mine], values[mine])
    return [c.result(precision) for c in cycles]


# A figure's certified minimum is sharpened to this (mm) below the least measured value beside it
# (report precision), with at most SHARPEN more measurements per item and SHARPEN_ITEMS items.
PRECISION_MM = 1e-4
SHARPEN = 48
SHARPEN_ITEMS = 3


@dataclass
class FigureCertificate:
    """One figure over many items (a chain's links or rollers): the least certified bound, where
    (item, angle interval in rad), the least measured value, the refinements, and the intervals
    left undecided (item, a0, a1)."""

    certified_min: float = math.inf
    sampled_min: float = math.inf
    link: int = -1
    between_rad: tuple[float, float] = (math.nan, math.nan)
    refined: int = 0
    undecided: list[tuple[int, float, float]] = field(default_factory=list)
    item: str = "link"

    def as_dict(self, prefix: str) -> dict:
        return {f"{prefix}certified_min_mm": self.certified_min, f"{prefix}sampled_min_mm": self.sampled_min,
                f"{prefix}certified_min_{self.item}": self.link,
                f"{prefix}certified_min_between_deg": [math.degrees(a) for a in self.between_rad],
                f"{prefix}intervals_refined": self.refined, f"{prefix}undecided_intervals": len(self.undecided)}


def certify_figure(angles: np.ndarray, values: np.ndarray, requirement: float, measure: Callable[[int, float], float],
                   path: Callable[[int, float, float], float], resolution_mm: float, floor_mm: float,
                   item: str = "link", sharpen_items: int = SHARPEN_ITEMS) -> FigureCertificate:
    """One figure (``values[:, i]`` at ``angles``, item i) certified for every item: ≥ ``requirement``
    over the continuous motion, refined by ``measure(i, angle)``, ``path(i, a0, a1)`` the longest
    path of a point of item i over [a0, a1]; a value that is not finite (nothing within the model's
    reach) counts as ``floor_mm``, a lower bound of it. Then the figure itself is sharpened: the
    item holding the least bound is certified again with its least piece split to
    :data:`PRECISION_MM` (the next item's, if it then holds the least; at most ``sharpen_items``)."""
    xs = [float(a) for a in angles]
    refined, sampled = 0, math.inf

    def finite(v: float) -> float:
        return float(v) if math.isfinite(v) else floor_mm

    def run(i: int, sharpen: int) -> Certificate:
        nonlocal refined, sampled
        cert = certify(xs, [finite(v) for v in values[:, i]], lambda x: finite(measure(i, x)),
                       lambda a0, a1: path(i, a0, a1), requirement, resolution_mm, precision=PRECISION_MM,
                       sharpen=sharpen)
        refined += cert.refined
        sampled = min(sampled, cert.sampled_min)
        return cert

    certs = {i: run(i, 0) for i in range(values.shape[1])}
    sharpened: set[int] = set()
    while True:
        worst = min(certs, key=lambda k: certs[k].certified_min)
        if worst in sharpened or len(sharpened) >= sharpen_items:
            break
        sharpened.add(worst)
        certs[worst] = run(worst, SHARPEN)
    out = FigureCertificate(refined=refined, sampled_min=sampled, item=item)
    for i, cert in certs.items():
        out.undecided += [(i, u[0], u[1]) for u in cert.undecided]
    out.link = worst
    out.certified_min, out.between_rad = certs[worst].certified_min, certs[worst].at
    return out
