"""The exact-polyline push model of towing the trimmed rack and pinion (numpy/scipy only).

For each pinion angle the rack sits at the smallest travel (forward swing) or the largest
(return swing) at which no pinion tooth overlaps a rack tooth, moving only when a tooth pushes
it through a flank. The disengage and re-engage angles, the towing curve and the interference
check come from it; the closed forms of :mod:`.analysis` cross-check it (tests).

Frame, tooth indices and angle-0 convention: :mod:`gearcheck.geometry.rack_pinion`. Angles in
radians unless a name says ``_deg``; the towing direction is the one in which the first rack
tooth (k = rack.first_tooth) comes under the pinion (φ > 0, rack moving +x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.geometry.bisect import bisect
from gearcheck.geometry.rack_pinion import RackPinionGeometry

# Named tolerances.
TRAVEL_TOL_MM = 1e-4  # rack standing still / a pair touching, within this (≫ polyline error, measured ≤ 0.04 µm)
ANGLE_STEP_DEG = 0.05  # towing-curve grid; events are refined by bisection
BISECT_TOL_RAD = 1e-7
CHECK_ANGLES_DEG = (68.0, 72.0, 75.0)  # towing-curve sample points reported as figures
# Only the rack's flanks push it. A trimmed top, even a steeply slanted one, is a cut the
# pinion is meant to clear (its tip land grazes S2 at most): a tooth that has to drive the rack
# through a top jams, and the overlap is reported as interference. A rack corner (a flank's end)
# can push through the pinion's flank, but only while the contact normal lies within 60° of the
# travel (|n_x| ≥ 0.5, flanks: cos α ≥ 0.82 for α ≤ 35°): flatter, the normal force would exceed
# twice the push. That bounds how fast a tooth drives the rack, |dL/dφ| = |v·n| / |n_x| ≤
# r_tip / 0.5; a push needing more within one step is a jam as well. The mesh sweep applies both
# rules to its faces (flank triangles only) and its reach.
PUSH_NORMAL_MIN = 0.5
PUSH_RATE_PER_TIP_RADIUS = 1.0 / PUSH_NORMAL_MIN



def _rack_chains(g: RackPinionGeometry, k: int):
    """Left and right boundary of rack tooth k at L = 0 as increasing-y polylines (y, x): the
    top (S2–S6 or S4–S8) joins the chain on its lower side. Also its two flanks alone (the
    faces that push the rack), the root height and the top height."""
    bl, br, tr, tl = g.rack_tooth_polygon(k, 0.0)
    y0, h_l, h_r = bl[1], tl[1], tr[1]
    left_pts, right_pts = [bl, tl] + ([tr] if h_r > h_l else []), [br, tr] + ([tl] if h_l > h_r else [])

    def chain(pts):
        return np.array([q[1] for q in pts]), np.array([q[0] for q in pts])

    return chain(left_pts), chain(right_pts), chain([bl, tl]), chain([br, tr]), y0, max(h_l, h_r)


def _active(g: RackPinionGeometry, j: int, y_top: float, phis: np.ndarray) -> np.ndarray:
    """Pinion angles at which tooth j can reach down to ``y_top`` (cheap bound)."""
    theta = np.abs(np.asarray(g.pinion_tooth_angle(j, phis)))
    beta_max = float(g.involute_half_angle(g.form_radius))
    lowest = g.centre_to_datum_mm - g.pinion_tip_radius(j) * np.cos(np.clip(theta - beta_max, 0.0, math.pi))
    return lowest <= y_top + 1e-6


def _tooth_pairs_by_pinion(g: RackPinionGeometry) -> dict[int, list[int]]:
    """Rack teeth each pinion tooth can meet: pinion tooth j lives between rack teeth j and
    j + 1; one more on each side catches a tooth that passes over a trimmed top."""
    out = {}
    for j in range(g.sector_first_tooth, g.sector_last_tooth + 1):
        ks = [k for k in (j - 1, j, j + 1, j + 2) if g.rack_first_tooth <= k <= g.rack_last_tooth]
        if ks:
            out[j] = ks
    return out


def tooth_pairs(g: RackPinionGeometry) -> list[tuple[int, int]]:
    """All (j, k) pairs the push model checks, in a fixed order."""
    return [(j, k) for j, ks in _tooth_pairs_by_pinion(g).items() for k in ks]


class _Side:
    """Pinion tooth j's contact polygon at many angles (rows): its vertices (px, py, closed: the
    first repeated last) and the edges between them, for the extremes of :func:`_offsets`."""

    def __init__(self, px: np.ndarray, py: np.ndarray):
        self.px, self.py = px[:, :-1], py[:, :-1]
        bx, by = px[:, 1:], py[:, 1:]
        ax, ay = px[:, :-1], py[:, :-1]
        dy = by - ay
        self.ex, self.ey = ax, ay
        self.flat = dy == 0.0
        self.inv_dy = 1.0 / np.where(self.flat, 1.0, dy)
        self.slope_x = (bx - ax) * self.inv_dy

    def rows(self, keep: np.ndarray) -> _Side:
        out = object.__new__(_Side)
        for name in ("px", "py", "ex", "ey", "flat", "inv_dy", "slope_x"):
            setattr(out, name, getattr(self, name)[keep])
        return out


def _offsets(poly: _Side, chain, want_lo: bool = True, want_hi: bool = True):
    """min and max over the chain's heights of [pinion boundary x(y) − chain x(y)], per angle
    (rows of the pinion polygon ``poly``): over its vertices within the chain's heights and its
    edges crossing the chain's vertex heights (±inf where none; None for an end not wanted)."""
    ys, xs = chain
    px, py = poly.px, poly.py
    inside = (py >= ys[0]) & (py <= ys[-1])
    d = px - np.interp(py, ys, xs)
    hi: Any = np.where(inside, d, -np.inf).max(axis=1) if want_hi else None
    lo: Any = np.where(inside, d, np.inf).min(axis=1) if want_lo else None
    for uy, ux in zip(ys, xs, strict=True):
        t = (uy - poly.ey) * poly.inv_dy
        crossing = ~poly.flat & (t >= 0.0) & (t <= 1.0)
        x = poly.ex + (uy - poly.ey) * poly.slope_x
        if want_hi:
            hi = np.maximum(hi, np.where(crossing, x, -np.inf).max(axis=1) - ux)
        if want_lo:
            lo = np.minimum(lo, np.where(crossing, x, np.inf).min(axis=1) - ux)
    return lo, hi


def all_intervals(g: RackPinionGeometry, phis):
    """:func:`overlap_intervals` both ways at once (the pinion polygons rotated once): returns
    pairs, (lo, hi) of whole teeth, (lo, hi) of the left flanks, (lo, hi) of the right flanks."""
    phis = np.atleast_1d(np.asarray(phis, dtype=float))
    pairs: list[tuple[int, int]] = []
    rows: list[list[np.ndarray]] = []
    for j, ks in _tooth_pairs_by_pinion(g).items():
        chains = [_rack_chains(g, k) for k in ks]
        idx = np.flatnonzero(_active(g, j, max(c[5] for c in chains), phis))
        if idx.size:
            rho, gam = g.pinion_contact_polygon_polar(j)
            ang = gam[None, :] + g.pinion_tooth_angle(j, phis[idx])[:, None]
            px = rho * np.sin(ang)
            py = g.centre_to_datum_mm - rho * np.cos(ang)
            closed = _Side(np.concatenate([px, px[:, :1]], axis=1), np.concatenate([py, py[:, :1]], axis=1))
            y_min, y_max = py.min(axis=1), py.max(axis=1)
        for k, (left_chain, right_chain, left_flank, right_flank, y0, top) in zip(ks, chains, strict=True):
            pairs.append((j, k))
            out = [np.full(phis.shape, np.nan) for _ in range(6)]
            rows.append(out)
            if not idx.size:
                continue
            overlap = (y_min <= top) & (y_max >= y0)
            if not overlap.any():
                continue
            at = idx[overlap]
            poly = closed.rows(overlap)
            found = [(_offsets(poly, right_chain, want_hi=False)[0], _offsets(poly, left_chain, want_lo=False)[1]),
                     _offsets(poly, left_flank), _offsets(poly, right_flank)]
            for n, (lo_m, hi_m) in enumerate(found):
                ok = np.isfinite(hi_m) & np.isfinite(lo_m)
                out[2 * n][at[ok]] = lo_m[ok]
                out[2 * n + 1][at[ok]] = hi_m[ok]
    shape = (len(pairs), phis.size)
    arrays = [np.array([r[n] for r in rows]).reshape(shape) for n in range(6)]
    return pairs, (arrays[0], arrays[1]), (arrays[2], arrays[3]), (arrays[4], arrays[5])


def overlap_intervals(g: RackPinionGeometry, phis, flanks: bool = False):
    """For every pair (j, k) of :func:`tooth_pairs` and every pinion angle φ: the interval
    (lo, hi) of rack travels L at which rack tooth k overlaps pinion tooth j (NaN where their
    heights never overlap). Both teeth are convex, so hi = max over y of [pinion right edge(y)
    − rack left edge(y)] and lo = min over y of [pinion left edge(y) − rack right edge(y)],
    and the extremes lie at vertex heights of either polygon. L = hi: the pinion tooth touches
    the left side of the rack tooth (towing drive side); L = lo: its right side.

    With ``flanks`` the intervals are those of each flank segment alone (the faces that push
    the rack): returns pairs, (lo, hi) of the left flanks and (lo, hi) of the right flanks; a
    tooth in (lo, hi) of a left flank cuts it, and the rack clears it at L = hi (pushed +x)."""
    pairs, whole, left, right = all_intervals(g, phis)
    if flanks:
        return pairs, left, right
    return pairs, whole[0], whole[1]


def push_intervals(g: RackPinionGeometry, phis, direction: int) -> tuple[list[tuple[int, int]], np.ndarray, np.ndarray]:
    """(pairs, lo, hi) of the flanks that push the rack towards ``direction``: left flanks (+x),
    right flanks (−x)."""
    pairs, left, right = overlap_intervals(g, phis, flanks=True)
    return (pairs, *left) if direction > 0 else (pairs, *right)


def pair_push_interval(g: RackPinionGeometry, j: int, k: int, phis, direction: int) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) of :func:`push_intervals` for one pair."""
    pairs, lo, hi = push_intervals(g, phis, direction)
    n = pairs.index((j, k))
    return lo[n], hi[n]


@dataclass(frozen=True)
class Sweep:
    """Rack travel along a swing of the pinion (rack pushed only by teeth)."""

    phi_rad: np.ndarray
    travel_mm: np.ndarray
    pairs: list[tuple[int, int]]
    lo: np.ndarray  # (n_pairs, n_phi) intervals of the pushing flanks, see push_intervals
    hi: np.ndarray
    direction: int  # +1: φ increasing, rack pushed +x; −1: φ decreasing, rack pushed −x
    max_overlap_mm: float  # deepest overlap left after the pushes (interference if > tolerance)
    max_rate: float  # largest |ΔL/Δφ| between grid points, mm/rad
    overlap_mm: np.ndarray  # overlap depth at each angle (0: clear or touching)

    @property
    def phi_deg(self) -> np.ndarray:
        return np.degrees(self.phi_rad)

    @property
    def jammed(self) -> np.ndarray:
        """Angles at which a tooth overlaps the rack it could not push (deeper than TRAVEL_TOL_MM)."""
        return self.overlap_mm > TRAVEL_TOL_MM


def push_reach(g: RackPinionGeometry, step_rad: float) -> float:
    """The farthest a tooth can drive the rack while the pinion turns by ``step_rad``."""
    return PUSH_RATE_PER_TIP_RADIUS * g.tip_radius * abs(step_rad)


def _step(lo: np.ndarray, hi: np.ndarray, travel: float, direction: int, reach: float = math.inf) -> float:
    """Travel after a turn: the nearest travel towards ``direction`` at which no pushing flank
    cuts a pinion tooth (``lo``, ``hi`` from :func:`push_intervals`), unless that takes more
    than ``reach`` (a jam: the rack stays)."""
    target = travel
    while True:
        cut = (lo < target) & (target < hi)
        if not cut.any():
            break
        target = float(hi[cut].max()) if direction > 0 else float(lo[cut].min())
    return target if abs(target - travel) <= reach else travel


def _overlap_depth(lo: np.ndarray, hi: np.ndarray, travel: float) -> float:
    inside = (lo < travel) & (travel < hi)
    if not inside.any():
        return 0.0
    return float(np.minimum(travel - lo[inside], hi[inside] - travel).max())


def sweep(g: RackPinionGeometry, phis, travel_start: float, direction: int, intervals=None) -> Sweep:
    """Swing the pinion through ``phis`` (monotone, in the sense of ``direction``) starting
    with the rack at ``travel_start``; at each angle the rack moves only as far as a pinion
    tooth pushes it through a flank, at most :func:`push_reach` per step (see
    :data:`PUSH_NORMAL_MIN`); any overlap left (with the whole tooth) is interference.
    ``intervals`` may pass (pairs, push lo, push hi, overlap lo, overlap hi) precomputed at ``phis``."""
    phis = np.asarray(phis, dtype=float)
    if intervals is None:
        pairs, lo, hi = push_intervals(g, phis, direction)
        _, full_lo, full_hi = overlap_intervals(g, phis)
    else:
        pairs, lo, hi, full_lo, full_hi = intervals
    travel = np.empty(phis.size)
    depth = np.zeros(phis.size)
    current = float(travel_start)
    for i in range(phis.size):
        step = phis[i] - phis[i - 1] if i else 0.0
        current = _step(lo[:, i], hi[:, i], current, direction, push_reach(g, step))
        travel[i] = current
        depth[i] = _overlap_depth(full_lo[:, i], full_hi[:, i], current)
    rate = float(np.max(np.abs(np.diff(travel) / np.diff(phis)))) if phis.size > 1 else 0.0
    return Sweep(phis, travel, pairs, lo, hi, direction, float(depth.max()) if depth.size else 0.0, rate, depth)


def _travel_after(g: RackPinionGeometry, phi: float, travel_before: float, direction: int, phi_before: float) -> float:
    """Rack travel at one angle, given where it was at ``phi_before`` (for bisection)."""
    _, lo, hi = push_intervals(g, [phi], direction)
    return _step(lo[:, 0], hi[:, 0], travel_before, direction, push_reach(g, phi - phi_before))


def _bisect(predicate, a: float, b: float) -> float:
    """Boundary between a (predicate False) and b (predicate True), to BISECT_TOL_RAD."""
    return bisect(predicate, a, b, BISECT_TOL_RAD, check_ends=False).value


@dataclass(frozen=True)
class Towing:
    forward: Sweep  # 0 → max angle
    back: Sweep  # max angle → 0, starting where the forward swing left the rack
    disengage_rad: float  # rack stops for good (forward); NaN if still moving at the end
    travel_at_disengage_mm: float
    grazing_end_rad: float  # the last pusher stops touching the standing rack (forward)
    reengage_rad: float  # a tooth picks the rack up again (return)
    last_pusher: tuple[int, int] | None = None  # (j, k) of the pair that pushed last (forward), if it stops


def towing_grid(max_angle_deg: float, step_deg: float = ANGLE_STEP_DEG, extra_deg=CHECK_ANGLES_DEG) -> np.ndarray:
    """Pinion angles (rad) from 0 to the towing swing, every ``step_deg``, plus ``extra_deg``."""
    n = max(int(math.ceil(max_angle_deg / step_deg)), 1)
    grid = np.linspace(0.0, max_angle_deg, n + 1)
    extra = [a for a in extra_deg if 0.0 <= a <= max_angle_deg]
    return np.radians(np.unique(np.concatenate([grid, extra])))


def analyse_towing(g: RackPinionGeometry, max_angle_deg: float, step_deg: float = ANGLE_STEP_DEG,
                   extra_deg=CHECK_ANGLES_DEG) -> Towing:
    """Forward and return towing swings of the push model, with the disengage angle (from it
    on the rack never moves again), how long the last pushing tooth still touches the standing
    rack (zero-clearance grazing), and the re-engage angle (the return swing picks the rack
    up), each refined by bisection between grid angles."""
    phis = towing_grid(max_angle_deg, step_deg, extra_deg)
    # every interval once on the grid: left flanks push the forward swing, right flanks the return
    pairs, (full_lo, full_hi), (left_lo, left_hi), (right_lo, right_hi) = all_intervals(g, phis)
    # angle 0: tight mesh, rack tooth 0 centred
    fwd = sweep(g, phis, 0.0, +1, (pairs, left_lo, left_hi, full_lo, full_hi))
    end = float(fwd.travel_mm[-1])
    moving_late = end - np.interp(phis[-1] - math.radians(1.0), phis, fwd.travel_mm) > TRAVEL_TOL_MM
    dis = graze = math.nan
    last: tuple[int, int] | None = None
    if not moving_late:
        i = int(np.argmax(fwd.travel_mm >= end - TRAVEL_TOL_MM))
        if i > 0:
            before = float(fwd.travel_mm[i - 1])
            dis = _bisect(lambda p: _travel_after(g, p, before, +1, phis[i - 1]) >= end - TRAVEL_TOL_MM,
                          phis[i - 1], phis[i])
        else:
            dis = float(phis[0])
        # the pair that pushed last, and where it stops touching
        n = int(np.nanargmin(np.abs(np.where(np.isfinite(fwd.hi[:, i]), fwd.hi[:, i] - end, np.inf))))
        j, k = fwd.pairs[n]
        last = (j, k)

        def apart(p: float) -> bool:
            hi = pair_push_interval(g, j, k, [p], +1)[1][0]
            return not (np.isfinite(hi) and hi >= end - TRAVEL_TOL_MM)

        touching = np.isfinite(fwd.hi[n]) & (fwd.hi[n] >= end - TRAVEL_TOL_MM)
        later = np.flatnonzero(~touching[i + 1:])
        if later.size:
            m = i + 1 + int(later[0])
            graze = _bisect(apart, phis[m - 1], phis[m])

    back_phis = phis[::-1]
    back = sweep(g, back_phis, end, -1,
                 (pairs, right_lo[:, ::-1], right_hi[:, ::-1], full_lo[:, ::-1], full_hi[:, ::-1]))
    re = math.nan
    moved = back.travel_mm < end - TRAVEL_TOL_MM
    if moved.any():
        i = int(np.argmax(moved))
        re = _bisect(lambda p: _travel_after(g, p, end, -1, back_phis[i - 1]) < end - TRAVEL_TOL_MM,
                     back_phis[i - 1], back_phis[i])
    return Towing(fwd, back, dis, end if math.isfinite(dis) else math.nan, graze, re, last)


def travel_on_curve(t: Towing, phi: float) -> float:
    """Forward-swing travel at φ (interpolated between grid points; exact at grid points)."""
    return float(np.interp(phi, t.forward.phi_rad, t.forward.travel_mm))
