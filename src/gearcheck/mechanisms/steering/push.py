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
    if ("push_beta_max",) not in g._cache:
        g._cache[("push_beta_max",)] = float(g.involute_half_angle(g.form_radius))
    beta_max = g._cache[("push_beta_max",)]
    lowest = g.centre_height - g.pinion_tip_radius(j) * np.cos(np.clip(theta - beta_max, 0.0, math.pi))
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
    """Pinion tooth j's contact polygon at a few angles (rows): its vertices (px, py, closed: the
    first repeated last) and the edges between them, every one evaluated (:func:`_crossing_extremes`)."""

    def __init__(self, px: np.ndarray, py: np.ndarray):
        self.px, self.py = px[:, :-1], py[:, :-1]
        bx, by = px[:, 1:], py[:, 1:]
        ax, ay = px[:, :-1], py[:, :-1]
        dy = by - ay
        self.ex, self.ey = ax, ay
        self.flat = dy == 0.0
        self.inv_dy = 1.0 / np.where(self.flat, 1.0, dy)
        self.slope_x = (bx - ax) * self.inv_dy


def _padded(rho: np.ndarray, gam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The polygon with repeats of its first vertex up to a whole number of :data:`BLOCK` s: they
    change no extreme of its vertices, and the edges to and between them are horizontal (none
    crosses a height), the closing edge still ends at the first vertex."""
    fill = np.zeros(-rho.size % BLOCK, dtype=int)
    return np.concatenate([rho, rho[fill]]), np.concatenate([gam, gam[fill]])


def _pinion_teeth(g: RackPinionGeometry) -> list[tuple[int, list[int], list[tuple], tuple[np.ndarray, np.ndarray]]]:
    """Per pinion tooth j: the rack teeth it can meet, their chains (:func:`_rack_chains`) and
    its contact polygon (polar); built once per geometry (they do not depend on the angle)."""
    key = ("push_teeth",)
    if key not in g._cache:
        g._cache[key] = [(j, ks, [_merged(_rack_chains(g, k)) for k in ks], _padded(*g.pinion_contact_polygon_polar(j)))
                         for j, ks in _tooth_pairs_by_pinion(g).items()]
    return g._cache[key]


def _crossing_extremes(poly: _Side, uy: float) -> tuple[np.ndarray, np.ndarray]:
    """Per row: the least and the greatest x at which a (non-horizontal) polygon edge crosses
    height ``uy`` (±inf where none). Depends only on the height, so every chain of every rack
    tooth with a vertex at that height shares it (the rack teeth have two or three heights)."""
    t = (uy - poly.ey) * poly.inv_dy
    crossing = ~poly.flat & (t >= 0.0) & (t <= 1.0)
    x = poly.ex + (uy - poly.ey) * poly.slope_x
    return np.where(crossing, x, np.inf).min(axis=1), np.where(crossing, x, -np.inf).max(axis=1)


def _merged(chains):
    """:func:`_rack_chains` with a side that has no top above its flank given as the flank itself
    (the same chain: :func:`all_intervals` computes it once)."""
    left, right, left_flank, right_flank, y0, top = chains

    def same(a, b) -> bool:
        return all(np.array_equal(u, v) for u, v in zip(a, b, strict=True))

    return (left_flank if same(left, left_flank) else left, right_flank if same(right, right_flank) else right,
            left_flank, right_flank, y0, top)


BLOCK = 24  # polygon vertices per block
PRUNE_MARGIN_MM = 1e-9  # added to each block's bound: ≫ the rounding of the chain and of the edges (≤ 1e-12 mm)
DIRECT_ROWS = 8  # fewer angles than this: every vertex evaluated (no bounds to set up)
SHARE_MARGIN_MM = 1e-9  # vertices this close to a chain's extreme are re-evaluated for its translates


def _vertex_values(px: np.ndarray, py: np.ndarray, chain) -> tuple[np.ndarray, np.ndarray]:
    """x − chain x(y) at each polygon vertex, +inf (first) or −inf (second) outside the chain's heights."""
    ys, xs = chain
    inside = (py >= ys[0]) & (py <= ys[-1])
    d = px - np.interp(py, ys, xs)
    return np.where(inside, d, np.inf), np.where(inside, d, -np.inf)


def _vertex_extremes(px: np.ndarray, py: np.ndarray, chain) -> tuple[np.ndarray, np.ndarray]:
    """min and max over each row's polygon vertices within the chain's heights of
    [x − chain x(y)] (±inf where none)."""
    d_lo, d_hi = _vertex_values(px, py, chain)
    return d_lo.min(axis=-1), d_hi.max(axis=-1)


class _Blocks:
    """Rows of polygon vertices cut into blocks of :data:`BLOCK` consecutive vertices (the last one
    padded with repeats of the row's first vertex, which change no minimum or maximum) and each
    block's least and greatest x and y."""

    def __init__(self, px: np.ndarray, py: np.ndarray):
        rows, n = px.shape
        nb = -(-n // BLOCK)
        if nb * BLOCK > n:
            fill = np.zeros(nb * BLOCK - n, dtype=int)
            px, py = np.concatenate([px, px[:, fill]], axis=1), np.concatenate([py, py[:, fill]], axis=1)
        self.px, self.py = px.reshape(rows, nb, BLOCK), py.reshape(rows, nb, BLOCK)
        self.x_min, self.x_max = self.px.min(axis=2), self.px.max(axis=2)
        self.y_min, self.y_max = self.py.min(axis=2), self.py.max(axis=2)
        # edge i runs from vertex i to vertex i + 1 (the last real one back to vertex 0, the padding
        # ones from vertex 0 to itself: horizontal, they cross nothing); a block's edges span its
        # vertices' heights and the next block's first vertex
        first = self.py[:, :, 0]
        self.edge_y_min = np.minimum(self.y_min, np.roll(first, -1, axis=1))
        self.edge_y_max = np.maximum(self.y_max, np.roll(first, -1, axis=1))

    def crossings(self, uy: float) -> tuple[np.ndarray, np.ndarray]:
        """:func:`_crossing_extremes` (bit-identical): only the blocks of edges whose heights reach
        ``uy`` (within :data:`PRUNE_MARGIN_MM`) are evaluated. An edge further away fails the
        crossing test: the rounding of its parameter t is relatively ~1e-16, far below
        margin / edge height."""
        rows = self.px.shape[0]
        lo, hi = np.full(rows, np.inf), np.full(rows, -np.inf)
        r, c = np.nonzero((self.edge_y_min - PRUNE_MARGIN_MM <= uy) & (uy <= self.edge_y_max + PRUNE_MARGIN_MM))
        if r.size:
            nxt = (c + 1) % self.px.shape[1]
            ax, ay = self.px[r, c], self.py[r, c]
            bx = np.concatenate([ax[:, 1:], self.px[r, nxt, :1]], axis=1)
            by = np.concatenate([ay[:, 1:], self.py[r, nxt, :1]], axis=1)
            dy = by - ay
            flat = dy == 0.0
            inv_dy = 1.0 / np.where(flat, 1.0, dy)
            slope_x = (bx - ax) * inv_dy
            t = (uy - ay) * inv_dy
            crossing = ~flat & (t >= 0.0) & (t <= 1.0)
            x = ax + (uy - ay) * slope_x
            at, start = np.unique(r, return_index=True)
            lo[at] = np.minimum.reduceat(np.where(crossing, x, np.inf).min(axis=1), start)
            hi[at] = np.maximum.reduceat(np.where(crossing, x, -np.inf).max(axis=1), start)
        return lo, hi


def _pruned_extremes(b: _Blocks, rows: np.ndarray, chain, lo: np.ndarray, hi: np.ndarray, near: bool = False):
    """:func:`_vertex_extremes` of the polygon rows ``rows`` of ``b``, folded into ``lo`` and ``hi``
    (values already achieved, e.g. edge crossings: min(lo, ·), max(hi, ·)), evaluating only the
    blocks that can change them; bit-identical to folding in every vertex.

    Why nothing is dropped: the chain x(y) is piecewise linear, so over a block's heights
    [y_min, y_max] it is at least the least of its values at y_min, y_max and its vertices
    between them (and at most the greatest); the interpolation's rounding (≤ 1e-12 mm) is far
    inside :data:`PRUNE_MARGIN_MM`, and x − c rounds monotonically in x and c. So every vertex
    of a block has x − c(y) ≤ x_max − c_least + margin (≥ x_min − c_greatest − margin); a block
    whose bound does not reach the row's achieved max (min), from the crossings and the block
    with the best bound, holds no vertex that could change it. The blocks that can are evaluated
    exactly like every vertex would be, and a max (min) is one of its operands.

    With ``near`` also the vertices that may lie within :data:`SHARE_MARGIN_MM` of the extremes
    (row and vertex index, by row): see :func:`_shared_extremes`."""
    ys, xs = chain
    y_lo, y_hi = b.y_min[rows], b.y_max[rows]
    c1, c2 = np.interp(y_lo, ys, xs), np.interp(y_hi, ys, xs)
    c_least, c_most = np.minimum(c1, c2), np.maximum(c1, c2)
    for yv, xv in zip(ys, xs, strict=True):
        between = (y_lo <= yv) & (yv <= y_hi)
        c_least = np.where(between, np.minimum(c_least, xv), c_least)
        c_most = np.where(between, np.maximum(c_most, xv), c_most)
    live = (y_hi >= ys[0]) & (y_lo <= ys[-1])  # the block may have a vertex within the chain's heights
    upper = np.where(live, b.x_max[rows] - c_least + PRUNE_MARGIN_MM, -np.inf)
    lower = np.where(live, b.x_min[rows] - c_most - PRUNE_MARGIN_MM, np.inf)
    n = np.arange(rows.size)
    seeds = np.concatenate([n, n]), np.concatenate([upper.argmax(axis=1), lower.argmin(axis=1)])
    s_lo, s_hi = _vertex_values(b.px[rows[seeds[0]], seeds[1]], b.py[rows[seeds[0]], seeds[1]], chain)
    lo = np.minimum(lo, np.minimum(s_lo[:rows.size].min(axis=1), s_lo[rows.size:].min(axis=1)))
    hi = np.maximum(hi, np.maximum(s_hi[:rows.size].max(axis=1), s_hi[rows.size:].max(axis=1)))
    open_ = (upper >= hi[:, None]) | (lower <= lo[:, None])
    open_[seeds] = False
    r, c = np.nonzero(open_)
    v_lo, v_hi = _vertex_values(b.px[rows[r], c], b.py[rows[r], c], chain)
    if r.size:
        at, start = np.unique(r, return_index=True)
        lo[at] = np.minimum(lo[at], np.minimum.reduceat(v_lo.min(axis=1), start))
        hi[at] = np.maximum(hi[at], np.maximum.reduceat(v_hi.max(axis=1), start))
    if not near:
        return lo, hi
    lo_near, hi_near = lo + SHARE_MARGIN_MM, hi - SHARE_MARGIN_MM
    e_r, e_b = np.concatenate([seeds[0], r]), np.concatenate([seeds[1], c])
    close = (np.concatenate([s_lo, v_lo]) <= lo_near[e_r, None]) | (np.concatenate([s_hi, v_hi]) >= hi_near[e_r, None])
    i, o = np.nonzero(close)
    evaluated = np.zeros(upper.shape, bool)
    evaluated[e_r, e_b] = True
    rr, bb = np.nonzero(live & ~evaluated & ((upper >= hi_near[:, None]) | (lower <= lo_near[:, None])))
    near_r = np.concatenate([e_r[i], np.repeat(rr, BLOCK)])
    near_v = np.concatenate([e_b[i] * BLOCK + o, (bb[:, None] * BLOCK + np.arange(BLOCK)).ravel()])
    order = np.argsort(near_r, kind="stable")
    return lo, hi, (near_r[order], near_v[order])


def _shared_extremes(b: _Blocks, rows: np.ndarray, chain, lo: np.ndarray, hi: np.ndarray, near
                     ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_pruned_extremes` of a chain that is a translate of one already done at the same
    rows (the same heights; its x's shifted by Δ to within 1e-10 mm), evaluating only the vertices
    ``near`` that one's extremes. Exact: x − c(y) of the translate is that of the first minus Δ
    to within ε ≤ 1e-10 + 1e-12 mm, and so are the edge crossings' terms, so a vertex that was
    more than :data:`SHARE_MARGIN_MM` (> 2ε) short of the first chain's extreme (its value, or its
    block's bound) is short of the translate's, and the extreme is one of the operands kept."""
    near_r, near_v = near
    if near_r.size:
        flat_x, flat_y = b.px.reshape(b.px.shape[0], -1), b.py.reshape(b.py.shape[0], -1)
        v_lo, v_hi = _vertex_values(flat_x[rows[near_r], near_v], flat_y[rows[near_r], near_v], chain)
        at, start = np.unique(near_r, return_index=True)
        lo[at] = np.minimum(lo[at], np.minimum.reduceat(v_lo, start))
        hi[at] = np.maximum(hi[at], np.maximum.reduceat(v_hi, start))
    return lo, hi


def _translate(a, b) -> bool:
    """Chain b is chain a shifted in x (same heights; the shifts of its vertices within 1e-10 mm)."""
    return (a[0].shape == b[0].shape and np.array_equal(a[0], b[0])
            and float(np.ptp(np.asarray(b[1]) - np.asarray(a[1]))) <= 1e-10)


class _ToothRows:
    """One pinion tooth's contact polygon at many angles (rows), with the edge crossings found
    so far (by height) for the chains of every rack tooth it meets."""

    def __init__(self, px: np.ndarray, py: np.ndarray):
        self.px, self.py = px, py
        self.blocks = _Blocks(px, py) if px.shape[0] >= DIRECT_ROWS else None
        self.closed = None if self.blocks else _Side(np.concatenate([px, px[:, :1]], axis=1),
                                                     np.concatenate([py, py[:, :1]], axis=1))
        self.cross: dict[float, tuple[np.ndarray, np.ndarray]] = {}
        self.done: list[tuple] = []  # (chain, rows, vertices near its extremes) for its translates

    def crossings(self, uy: float) -> tuple[np.ndarray, np.ndarray]:
        if uy not in self.cross:
            if self.blocks is not None:
                self.cross[uy] = self.blocks.crossings(uy)
            else:
                assert self.closed is not None
                self.cross[uy] = _crossing_extremes(self.closed, uy)
        return self.cross[uy]

    def extremes(self, chain, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """min and max over the chain's heights of [pinion boundary x(y) − chain x(y)] in rows ``keep``
        (±inf where the heights do not meet)."""
        lo, hi = np.full(keep.size, np.inf), np.full(keep.size, -np.inf)
        for uy, ux in zip(*chain, strict=True):
            x_lo, x_hi = self.crossings(float(uy))
            lo, hi = np.minimum(lo, x_lo[keep] - ux), np.maximum(hi, x_hi[keep] - ux)
        if self.blocks:
            for first, rows, near in self.done:
                if np.array_equal(rows, keep) and _translate(first, chain):
                    return _shared_extremes(self.blocks, keep, chain, lo, hi, near)
            lo, hi, near = _pruned_extremes(self.blocks, keep, chain, lo, hi, near=True)
            self.done.append((chain, keep, near))
            return lo, hi
        v_lo, v_hi = _vertex_extremes(self.px[keep], self.py[keep], chain)
        return np.minimum(lo, v_lo), np.maximum(hi, v_hi)


PARTS = ("whole", "left", "right")


def all_intervals(g: RackPinionGeometry, phis, only: tuple[int, int] | None = None, parts=PARTS):
    """:func:`overlap_intervals` both ways at once (the pinion polygons rotated once): returns
    pairs, (lo, hi) of whole teeth, (lo, hi) of the left flanks, (lo, hi) of the right flanks.

    For each chain (a rack tooth's side, or a flank alone) lo and hi are the min and max over
    the chain's heights of [pinion boundary x(y) − chain x(y)]: over the polygon's vertices
    within the chain's heights and over its edges crossing the chain's vertex heights. The
    crossings at a height are the same for every chain with a vertex there, so they are found
    once per pinion tooth (:meth:`_Blocks.crossings`); the vertices go through
    :func:`_pruned_extremes`, and the chains that are translates of one done (the same flank of
    another rack tooth) through :func:`_shared_extremes`; at a few angles every vertex and edge
    is evaluated. Every figure is an operand of the same arithmetic as evaluating every vertex
    and edge (bit-identical; tested against that). ``only``: that pair alone, ``parts``: those of
    ("whole", "left", "right") alone (the others NaN; the rest as when computing all)."""
    phis = np.atleast_1d(np.asarray(phis, dtype=float))
    pairs: list[tuple[int, int]] = []
    result = np.full((6, sum(len(t[1]) for t in _pinion_teeth(g)), phis.size), np.nan)
    for j, ks, chains, (rho, gam) in _pinion_teeth(g):
        wanted = [only is None or only == (j, k) for k in ks]
        idx = np.flatnonzero(_active(g, j, max(c[5] for c in chains), phis)) if any(wanted) else np.empty(0, int)
        if not idx.size:
            pairs += [(j, k) for k in ks]
            continue
        ang = gam[None, :] + g.pinion_tooth_angle(j, phis[idx])[:, None]
        py = g.centre_height - rho * np.cos(ang)
        y_min, y_max = py.min(axis=1), py.max(axis=1)
        overlaps = [(y_min <= c[5]) & (y_max >= c[4]) if w else np.zeros(idx.size, bool)
                    for c, w in zip(chains, wanted, strict=True)]
        rows_any = np.logical_or.reduce(overlaps)
        tooth = _ToothRows(rho * np.sin(ang[rows_any]), py[rows_any])
        for k, chain_set, overlap in zip(ks, chains, overlaps, strict=True):
            left_chain, right_chain, left_flank, right_flank = chain_set[:4]
            out = result[:, len(pairs)]
            pairs.append((j, k))
            if not overlap.any():
                continue
            at = idx[overlap]
            keep = np.flatnonzero(overlap[rows_any])
            done: dict[int, tuple[np.ndarray, np.ndarray]] = {}

            def extremes(chain, keep=keep, done=done, tooth=tooth):
                if id(chain) not in done:
                    done[id(chain)] = tooth.extremes(chain, keep)
                return done[id(chain)]

            found = [(extremes(right_chain)[0], extremes(left_chain)[1]) if "whole" in parts else None,
                     extremes(left_flank) if "left" in parts else None,
                     extremes(right_flank) if "right" in parts else None]
            for n, lo_hi in enumerate(found):
                if lo_hi is None:
                    continue
                lo_m, hi_m = lo_hi
                ok = np.isfinite(hi_m) & np.isfinite(lo_m)
                out[2 * n][at[ok]] = lo_m[ok]
                out[2 * n + 1][at[ok]] = hi_m[ok]
    return pairs, (result[0], result[1]), (result[2], result[3]), (result[4], result[5])


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
    pairs, _, left, right = all_intervals(g, phis, only=(j, k), parts=("left",) if direction > 0 else ("right",))
    n = pairs.index((j, k))
    lo, hi = left if direction > 0 else right
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


def _overlap_depths(lo: np.ndarray, hi: np.ndarray, travel: np.ndarray) -> np.ndarray:
    """Per angle (column): the deepest overlap of a pair (lo, hi) with the rack at ``travel``, 0 where none."""
    inside = (lo < travel) & (travel < hi)
    depth = np.where(inside, np.minimum(travel - lo, hi - travel), -np.inf).max(axis=0)
    return np.where(inside.any(axis=0), depth, 0.0)


def sweep(g: RackPinionGeometry, phis, travel_start: float, direction: int, intervals=None) -> Sweep:
    """Swing the pinion through ``phis`` (monotone, in the sense of ``direction``) starting
    with the rack at ``travel_start``; at each angle the rack moves only as far as a pinion
    tooth pushes it through a flank, at most :func:`push_reach` per step (see
    :data:`PUSH_NORMAL_MIN`); any overlap left (with the whole tooth) is interference.
    ``intervals`` may pass (pairs, push lo, push hi, overlap lo, overlap hi) precomputed at ``phis``."""
    phis = np.asarray(phis, dtype=float)
    if intervals is None:
        pairs, (full_lo, full_hi), left, right = all_intervals(g, phis, parts=("whole", "left" if direction > 0
                                                                              else "right"))
        lo, hi = left if direction > 0 else right
    else:
        pairs, lo, hi, full_lo, full_hi = intervals
    travel = np.empty(phis.size)
    depth = np.zeros(phis.size)
    current = float(travel_start)
    for i in range(phis.size):
        step = phis[i] - phis[i - 1] if i else 0.0
        current = _step(lo[:, i], hi[:, i], current, direction, push_reach(g, step))
        travel[i] = current
    if phis.size:
        depth = _overlap_depths(full_lo, full_hi, travel)
    rate = float(np.max(np.abs(np.diff(travel) / np.diff(phis)))) if phis.size > 1 else 0.0
    return Sweep(phis, travel, pairs, lo, hi, direction, float(depth.max()) if depth.size else 0.0, rate, depth)


def _travel_after(g: RackPinionGeometry, phi: float, travel_before: float, direction: int, phi_before: float) -> float:
    """Rack travel at one angle, given where it was at ``phi_before`` (for bisection)."""
    _, _, left, right = all_intervals(g, [phi], parts=("left",) if direction > 0 else ("right",))
    lo, hi = left if direction > 0 else right
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
                   extra_deg=CHECK_ANGLES_DEG, travel_start: float = 0.0) -> Towing:
    """Forward and return towing swings of the push model, with the disengage angle (from it
    on the rack never moves again), how long the last pushing tooth still touches the standing
    rack (zero-clearance grazing), and the re-engage angle (the return swing picks the rack
    up), each refined by bisection between grid angles. ``travel_start``: the rack's travel at
    angle 0 (0: rack tooth 0 centred, the tight mesh as designed)."""
    phis = towing_grid(max_angle_deg, step_deg, extra_deg)
    # every interval once on the grid: left flanks push the forward swing, right flanks the return
    pairs, (full_lo, full_hi), (left_lo, left_hi), (right_lo, right_hi) = all_intervals(g, phis)
    fwd = sweep(g, phis, travel_start, +1, (pairs, left_lo, left_hi, full_lo, full_hi))
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
            hi = all_intervals(g, [p], only=(j, k), parts=("left",))[2][1][n, 0]
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
