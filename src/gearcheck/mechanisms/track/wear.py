"""Chain wear: the pitch elongation the unchanged sprocket tolerates before a link fails to seat
(numpy only; the exact 2-D model of :mod:`gearcheck.geometry.track_section`, no mesh).

Model (the classic roller-chain wear model, the one behind the "200/z %" replacement rule): wear
at the pins and sleeves lengthens every link from p to p' = p·(1 + e); the sprocket is unchanged,
so a worn chain can no longer reach the seating centres and rides on a larger pin circle,
R' = p' / (2·sin(360°/z)) = R·(1 + e), every pin on its groove's centre line, raised by R·e.
Under the drive the tooth pushes each sleeve tangentially, so a raised sleeve is moved round
(about the sprocket axis, at R') until it touches its driving flank. A link seats while

1. ``tip``: that contact lies on the flank (or the seating arc), below the tip corner. When the
   first contact reaches the tip corner the sleeve has ridden up the flank to the tip: the tooth
   pushes it outward and the chain climbs over it;
2. ``jump``: the sleeve meets the tooth at all before the tooth's centre line (else it passes
   over the tip land: it jumps a tooth; reached after ``tip``, reported if it decides);
3. ``sweep``: the worn chain, wrapped at p' on the same plan as the mesh sweep (the default
   segment, θ over one engagement cycle and its margins; the link solids unchanged, since wear
   is in the pin–sleeve joints, only their pins p' apart), keeps every sleeve and plate clear of
   the outline at every pose (the exact 2-D distances ≥ 0): no plate meets a tip, no sleeve
   swinging in hits a tooth.

The limit is the least e at which one of these fails, found by bisection on e (each predicate is
monotonic in e over the bracket: a larger pitch raises every pin further).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.track_section import ExactSection

# Upper end of the bisection bracket (fraction); the limit is searched in [0, this].
WEAR_BRACKET_MAX = 0.25
# Bisection stops when the bracket on e is this narrow (fraction: 1e-6 = 0.0001 % of pitch).
WEAR_BISECTION_TOL = 1e-6
# Outline sampling of the seat check (every arc end, hence the tip corner, is an exact vertex).
SEAT_OUTLINE_STEP_MM = 0.005
# A contact point this close to the tip circle counts as at the tip corner (mm).
TIP_CONTACT_TOL_MM = 1e-6
# Sweep of the worn chain: sprocket angles per engagement cycle (coarser than the mesh sweep's 60:
# the exact model is continuous, and at the limit the seat check, not the sweep, decides).
WORN_SWEEP_STEPS_PER_CYCLE = 30
WORN_SWEEP_MARGIN_FRACTION = 0.125

MODES = ("none", "tip", "jump", "sweep")
MODE_TEXT = {
    "none": "no failure up to the bracket end",
    "tip": "sleeve rides up the driving flank to the tip corner",
    "jump": "sleeve clears the tooth: jumps a tooth",
    "sweep": "worn chain meets the sprocket in the worn-pitch sweep (plate on a tip or sleeve on a tooth)",
}


@dataclass(frozen=True)
class SeatResult:
    ok: bool
    mode: str  # "tip", "jump" or "" when ok
    contact_radius_mm: float  # radius of the first contact point (nan if none)
    shift_deg: float  # rotation about the axis from the groove line to the first contact


def _outline_near_groove(gap: iso606.ToothGap, step_mm: float) -> np.ndarray:
    """Three pitches of the outline, grooves −1, 0, +1 (groove 0 centred on polar angle 0), as one
    open polyline in increasing polar angle (the pitch profile of :func:`iso606.tooth_gap_profile`
    turned by ∓360°/z)."""
    one = iso606.tooth_gap_profile(gap, step_mm)
    pieces = []
    for k in (-1, 0, 1):
        a = 2.0 * math.pi * k / gap.teeth
        rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        pieces.append((one if k == 1 else one[:-1]) @ rot.T)
    return np.vstack(pieces)


def seat_polyline(gap: iso606.ToothGap) -> np.ndarray:
    """The groove's outline for :func:`seat_check` (made once per gap, reused across elongations)."""
    return _outline_near_groove(gap, SEAT_OUTLINE_STEP_MM)


def _nearest(point: np.ndarray, poly: np.ndarray) -> tuple[float, np.ndarray]:
    """Distance from ``point`` to the open polyline ``poly`` and the nearest point on it (the
    first nearest segment's, in polyline order)."""
    a, b = poly[:-1], poly[1:]
    e = b - a
    t = np.clip(((point - a) * e).sum(axis=1) / np.maximum((e * e).sum(axis=1), 1e-300), 0.0, 1.0)
    q = a + t[:, None] * e
    d = np.hypot(*(q - point).T)
    k = int(np.argmin(d))
    return float(d[k]), q[k]


# Every this many vertices of the polyline, one is measured for the windowed search's upper bound.
_WINDOW_PROBE_STRIDE = 16
# The window's angle is widened by this factor over the bound (so what it excludes is strictly farther).
_WINDOW_WIDEN = 1.0 + 1e-9


class _Polyline:
    """An open polyline whose vertices have strictly increasing polar angles (the groove's
    outline, :func:`seat_polyline`), for :meth:`nearest` on an angular window of it.

    Same figures as :func:`_nearest`, bit for bit: the per-segment arithmetic is the same (its
    coordinate sums of two terms written out column by column, which is what the row sums
    compute), and the window holds every segment at the nearest distance. u, the distance to the
    nearest of every 16th vertex, bounds the nearest distance from above. A point at distance
    ≤ u·(1 + 1e-9) from c lies within δ = asin(u·(1 + 1e-9)/|c|) of c's polar angle; a segment whose
    two ends both lie beyond δ on one side lies wholly beyond it (polar angle is monotonic along a
    segment that spans less than π), at distance ≥ |c|·sin δ > u from c. So the segments with an
    end inside the window hold every nearest segment, and the first of them in polyline order is
    the whole polyline's first. Where the bound does not apply (polar angles not strictly
    increasing, u ≥ |c|) the whole polyline is searched."""

    def __init__(self, poly: np.ndarray):
        self.poly = poly
        self.polar = np.arctan2(poly[:, 1], poly[:, 0])
        self.windowed = bool(len(poly) > 2 and np.all(np.diff(self.polar) > 0.0)
                             and np.ptp(self.polar) < math.pi / 2.0)
        self.probes_x = np.ascontiguousarray(poly[::_WINDOW_PROBE_STRIDE, 0])
        self.probes_y = np.ascontiguousarray(poly[::_WINDOW_PROBE_STRIDE, 1])
        a, b = poly[:-1], poly[1:]
        e = b - a
        self.ax, self.ay = np.ascontiguousarray(a[:, 0]), np.ascontiguousarray(a[:, 1])
        self.ex, self.ey = np.ascontiguousarray(e[:, 0]), np.ascontiguousarray(e[:, 1])
        self.ee = np.maximum(self.ex * self.ex + self.ey * self.ey, 1e-300)

    def window(self, point: np.ndarray) -> slice:
        """The segments (indices) that hold every segment nearest to ``point``."""
        px, py = float(point[0]), float(point[1])
        rho = math.hypot(px, py)
        u = float(np.hypot(self.probes_x - px, self.probes_y - py).min()) * _WINDOW_WIDEN
        if not self.windowed or not u < rho:
            return slice(0, len(self.ax))
        delta = math.asin(u / rho)
        phi = math.atan2(py, px)
        if not -math.pi < phi - delta < phi + delta < math.pi:  # the window would wrap round
            return slice(0, len(self.ax))
        lo = int(np.searchsorted(self.polar, phi - delta, "left"))
        hi = int(np.searchsorted(self.polar, phi + delta, "right"))
        # segment i joins vertices i and i + 1: those with an end in [lo, hi)
        return slice(max(lo - 1, 0), min(hi, len(self.ax)))

    def nearest(self, point: np.ndarray) -> tuple[float, np.ndarray]:
        """:func:`_nearest` (point, whole polyline), on the window."""
        w = self.window(point)
        ax, ay, ex, ey = self.ax[w], self.ay[w], self.ex[w], self.ey[w]
        px, py = point[0], point[1]
        t = np.clip(((px - ax) * ex + (py - ay) * ey) / self.ee[w], 0.0, 1.0)
        qx, qy = ax + t * ex, ay + t * ey
        d = np.hypot(qx - px, qy - py)
        k = int(np.argmin(d))
        return float(d[k]), np.array([qx[k], qy[k]])


def seat_check(gap: iso606.ToothGap, sleeve_radius_mm: float, elongation: float,
               poly: np.ndarray | None = None) -> SeatResult:
    """Checks 1 and 2 for one pin of a chain worn by ``elongation`` (fraction)."""
    if poly is None:
        poly = _outline_near_groove(gap, SEAT_OUTLINE_STEP_MM)
    outline = _Polyline(poly)
    r_pin = gap.pitch_radius_mm * (1.0 + elongation)
    half = gap.half_pitch_angle_rad  # tooth centre at +π/z

    def clearance(phi: float) -> tuple[float, np.ndarray]:
        c = r_pin * np.array([math.cos(phi), math.sin(phi)])
        dist, q = outline.nearest(c)
        return dist - sleeve_radius_mm, q

    c0, _ = clearance(0.0)
    if c0 < 0.0:  # cannot happen for e ≥ 0 (the groove widens outward); kept as a guard
        return SeatResult(False, "tip", math.nan, 0.0)
    # scan to the first pose in contact, then bisect the shift
    n = 400
    phis = np.linspace(0.0, half, n + 1)
    lo = 0.0
    hi = None
    for phi in phis[1:]:
        if clearance(float(phi))[0] <= 0.0:
            hi = float(phi)
            break
        lo = float(phi)
    if hi is None:
        return SeatResult(False, "jump", math.nan, math.degrees(half))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if clearance(mid)[0] > 0.0:
            lo = mid
        else:
            hi = mid
    _, q = clearance(hi)
    rq = float(np.hypot(*q))
    on_tip = rq >= gap.tip_radius_mm - TIP_CONTACT_TOL_MM
    return SeatResult(not on_tip, "tip" if on_tip else "", rq, math.degrees(hi))


def tip_limit_closed_form(gap: iso606.ToothGap, sleeve_radius_mm: float) -> float:
    """Check 1's limit in closed form (fraction): the sleeve touches the flank exactly at the tip
    corner C, so its centre is C + r·n (n the flank's outward normal at C, from the flank centre
    through C) and R·(1 + e) = |C + r·n|. What `gearcheck calc` shows; the check bisects the exact
    model (all three modes)."""
    c, f = gap.tip_corner, gap.flank_centre
    n = (c - f) / float(np.hypot(*(c - f)))
    return float(np.hypot(*(c + sleeve_radius_mm * n))) / gap.pitch_radius_mm - 1.0


@dataclass(frozen=True)
class SweepCheck:
    ok: bool
    min_sleeve_mm: float
    min_plate_mm: float
    poses: int
    links: int


def worn_wrap(teeth: int, pitch_mm: float, elongation: float, wrap: tc.ChainWrap) -> tc.ChainWrap:
    """The default segment's wrap with every link pitch p·(1 + e) (same links, entry, wrap angle)."""
    return tc.ChainWrap(teeth, pitch_mm * (1.0 + elongation), wrap.links, wrap.first_pin_groove,
                        wrap.entry_angle_deg, wrap.wrap_angle_deg)


# An exact table already computed for a wrap: (wrap, angles, (angles, links, 2) distances), as
# :func:`gearcheck.mechanisms.track.clearance.exact_table` makes them.
ExactTable = tuple[tc.ChainWrap, np.ndarray, np.ndarray]


def _table_rows(tables: Sequence[ExactTable], wrap: tc.ChainWrap, angles: np.ndarray) -> np.ndarray | None:
    """The rows of a table of this very wrap at exactly these angles (every one found, equal to
    the last bit), or None."""
    for t_wrap, t_angles, table in tables:
        if t_wrap != wrap or not len(t_angles):
            continue
        idx = np.minimum(np.searchsorted(t_angles, angles), len(t_angles) - 1)
        if np.array_equal(t_angles[idx], angles):
            return table[idx]
    return None


def sweep_check(gap: iso606.ToothGap, link: tc.LinkGeometry, wrap: tc.ChainWrap, elongation: float,
                steps_per_cycle: int = WORN_SWEEP_STEPS_PER_CYCLE,
                margin_fraction: float = WORN_SWEEP_MARGIN_FRACTION, exact: ExactSection | None = None,
                tables: Sequence[ExactTable] = ()) -> SweepCheck:
    """Check 3: the exact 2-D distances of the worn chain over one engagement cycle and margins.

    The link solid is the new one (wear is in the pin–sleeve joints; plates and sleeves keep their
    shape), posed by the worn wrap, so the pins are p·(1 + e) apart: the same solid the mesh sweep
    poses, which can therefore confirm this check with the same meshes.

    ``tables``: exact tables already computed (the sweep's, at β/60 steps); where one holds this
    wrap at every one of these angles (β/30 steps: every other angle of the sweep's, the same
    numbers to the last bit, which is checked), its rows are these very figures and are read,
    not computed again."""
    w = worn_wrap(wrap.teeth, link.pitch_mm, elongation, wrap)
    before = int(math.ceil(margin_fraction * steps_per_cycle))
    angles = np.arange(-before, steps_per_cycle + before + 1) * w.cycle_rad / steps_per_cycle
    rows = _table_rows(tables, w, angles)
    if rows is not None:
        s_min, p_min = float(rows[..., 0].min()), float(rows[..., 1].min())
        return SweepCheck(s_min >= 0.0 and p_min >= 0.0, s_min, p_min, len(angles), w.links)
    exact = exact if exact is not None else ExactSection(gap, link)
    s_min = p_min = math.inf
    for a in angles:
        sp = tc.sprocket_matrix(float(a))
        for pose in w.link_matrices(float(a)):
            s, p = exact.link_distances(sp, pose)
            s_min, p_min = min(s_min, s), min(p_min, p)
    return SweepCheck(s_min >= 0.0 and p_min >= 0.0, s_min, p_min, len(angles), w.links)


def sweep_clear(gap: iso606.ToothGap, link: tc.LinkGeometry, wrap: tc.ChainWrap, elongation: float,
                exact: ExactSection | None = None, tables: Sequence[ExactTable] = ()) -> bool:
    """``sweep_check(...).ok`` (default steps and margin), measuring only what can decide it: a
    sleeve or plate wholly outside the circle through the outline's farthest vertex is clear
    without measuring (:meth:`ExactSection.clear_of_outline`), and the first pose that meets the
    outline ends the search."""
    w = worn_wrap(wrap.teeth, link.pitch_mm, elongation, wrap)
    before = int(math.ceil(WORN_SWEEP_MARGIN_FRACTION * WORN_SWEEP_STEPS_PER_CYCLE))
    angles = (np.arange(-before, WORN_SWEEP_STEPS_PER_CYCLE + before + 1) * w.cycle_rad
              / WORN_SWEEP_STEPS_PER_CYCLE)
    rows = _table_rows(tables, w, angles)
    if rows is not None:
        return bool(rows[..., 0].min() >= 0.0 and rows[..., 1].min() >= 0.0)
    exact = exact if exact is not None else ExactSection(gap, link)
    for a in angles:
        sp = tc.sprocket_matrix(float(a))
        for pose in w.link_matrices(float(a)):
            sleeve_clear, plate_clear = exact.clear_of_outline(sp, pose)
            if sleeve_clear and plate_clear:
                continue
            least = exact.sleeve_clearance(sp, pose) if plate_clear else min(exact.link_distances(sp, pose))
            if least < 0.0:
                return False
    return True


@dataclass(frozen=True)
class WearLimit:
    limit: float  # largest elongation (fraction) at which every link seats (bracket's passing end)
    fail_at: float  # bracket's failing end (limit + ≤ tolerance), nan if none failed
    mode: str  # what fails first: one of MODES
    declared: float  # the template's declared elongation (fraction)
    declared_seat: SeatResult
    declared_sweep: SweepCheck
    tolerance: float

    @property
    def ok(self) -> bool:
        return self.declared <= self.limit

    @property
    def mode_code(self) -> int:
        return MODES.index(self.mode)


def wear_limit(gap: iso606.ToothGap, link: tc.LinkGeometry, wrap: tc.ChainWrap, declared: float,
               tol: float = WEAR_BISECTION_TOL, bracket: float = WEAR_BRACKET_MAX,
               tables: Sequence[ExactTable] = ()) -> WearLimit:
    """The elongation at which a link first fails to seat (bisection on e), and both checks at the
    declared elongation (``tables``: see :func:`sweep_check`)."""
    poly = _outline_near_groove(gap, SEAT_OUTLINE_STEP_MM)
    section = ExactSection(gap, link)

    def clear(e: float) -> bool:
        return sweep_clear(gap, link, wrap, e, exact=section, tables=tables)

    declared_seat = seat_check(gap, link.sleeve_radius_mm, declared, poly)
    declared_sweep = sweep_check(gap, link, wrap, declared, exact=section, tables=tables)

    # bisection on the seat check alone first (cheap), then the sweep inside that bracket
    lo, hi, mode = 0.0, bracket, seat_check(gap, link.sleeve_radius_mm, bracket, poly).mode
    if not mode:
        hi, mode = math.nan, "none"
    elif not seat_check(gap, link.sleeve_radius_mm, 0.0, poly).ok:
        lo, hi, mode = 0.0, 0.0, seat_check(gap, link.sleeve_radius_mm, 0.0, poly).mode
    else:
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            m = seat_check(gap, link.sleeve_radius_mm, mid, poly).mode
            lo, hi, mode = (mid, hi, mode) if not m else (lo, mid, m)
    # does the worn-pitch sweep fail first?
    if not clear(lo):
        s_lo, s_hi = 0.0, lo
        if not clear(0.0):
            s_hi = 0.0
        else:
            while s_hi - s_lo > tol:
                mid = 0.5 * (s_lo + s_hi)
                s_lo, s_hi = (mid, s_hi) if clear(mid) else (s_lo, mid)
        lo, hi, mode = s_lo, s_hi, "sweep"
    return WearLimit(lo, hi, mode, declared, declared_seat, declared_sweep, tol)
