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
