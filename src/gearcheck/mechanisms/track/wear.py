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

The limit is the least e at which one of these fails (each predicate is monotonic in e: a larger
pitch raises every pin further). Checks 1 and 2 are made on the exact arcs of the tooth form (no
polyline); check 1 has a closed form, which is the limit in that mode, and a bisection on e brackets
it. Check 3 is made on the outline polyline of :class:`ExactSection`, within its chord sagitta of
the arcs, and its bracket is widened by that (see :func:`wear_limit`).
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


# The pieces of the outline between groove 0's centre line (polar angle 0) and the next tooth's
# centre line (π/z), in order: the seating arc's +y half, the driving flank, the tip land.
SEAT, FLANK, LAND = 0, 1, 2
# Sleeve-centre angles scanned for the first contact before it is bisected (60 halvings).
SEAT_SCAN_STEPS = 400
SEAT_BISECTIONS = 60


def _arc_nearest(points: np.ndarray, centre: np.ndarray, radius: float, a0: float, span: float,
                 end0: np.ndarray, end1: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance from each point (N, 2) to the exact arc of ``radius`` about ``centre`` running
    counter-clockwise from angle ``a0`` through ``span`` (ends ``end0``, ``end1``, the construction's
    exact vertices), the nearest point on it, and whether that point is the far end ``end1``."""
    v = points - centre
    rho = np.hypot(v[:, 0], v[:, 1])
    on_arc = np.mod(np.arctan2(v[:, 1], v[:, 0]) - a0, 2.0 * math.pi) <= span
    d0 = np.hypot(*(points - end0).T)
    d1 = np.hypot(*(points - end1).T)
    far = ~on_arc & (d1 <= d0)
    dist = np.where(on_arc, np.abs(rho - radius), np.minimum(d0, d1))
    with np.errstate(invalid="ignore", divide="ignore"):
        q_arc = centre + radius * v / rho[:, None]
    q = np.where(on_arc[:, None], q_arc, np.where(far[:, None], end1, end0))
    return dist, q, far


def groove_nearest(gap: iso606.ToothGap, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance from sleeve centres (N, 2) lying between groove 0's centre line and the next
    tooth's (polar angles 0 … π/z) to the exact outline, the nearest point, and whether a contact
    there lies on the tip (the tip corner or the tip land).

    Exact arcs, no polyline: the outline in that wedge is the seating arc's +y half, the flank and
    the tip land up to the tooth's centre line; every other piece is a mirror image of one of
    these across a bounding line of the wedge, so lies farther from a point inside it."""
    j, c = gap.junction, gap.tip_corner
    ha = gap.seating_angle_rad / 2.0
    seat = _arc_nearest(points, gap.seating_centre, gap.seating_radius_mm, math.pi - ha, ha, j,
                        gap.seating_centre + np.array([-gap.seating_radius_mm, 0.0]))
    flank = _arc_nearest(points, gap.flank_centre, gap.flank_radius_mm, gap.flank_start_angle_rad,
                         gap.flank_sweep_rad, j, c)
    half = gap.half_pitch_angle_rad
    tooth_centre = gap.tip_radius_mm * np.array([math.cos(half), math.sin(half)])
    land = _arc_nearest(points, np.zeros(2), gap.tip_radius_mm, gap.tip_corner_angle_rad,
                        gap.tip_land_half_angle_rad, c, tooth_centre)
    dists = np.stack([seat[0], flank[0], land[0]])
    piece = np.argmin(dists, axis=0)
    rows = np.arange(len(points))
    q = np.stack([seat[1], flank[1], land[1]])[piece, rows]
    # On the tip when the centre lies past the flank's normal at the corner (the flank's nearest
    # point is its end, the corner), whichever of flank and land is reported nearest: at the corner
    # they differ only in the second order, below rounding, so their argmin does not decide.
    on_tip = flank[2] & (piece != SEAT)
    return dists[piece, rows], q, on_tip


def seat_check(gap: iso606.ToothGap, sleeve_radius_mm: float, elongation: float) -> SeatResult:
    """Checks 1 and 2 for one pin of a chain worn by ``elongation`` (fraction), on the exact arcs:
    the sleeve centre, on R·(1 + e), is turned from the groove's centre line towards the next
    tooth's until it first touches the outline (scan, then bisection of the angle); the link seats
    if that contact lies on the seating arc or the flank, below the tip corner."""
    r_pin = gap.pitch_radius_mm * (1.0 + elongation)
    half = gap.half_pitch_angle_rad  # tooth centre at +π/z

    def at(phis: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        centres = r_pin * np.column_stack([np.cos(phis), np.sin(phis)])
        dist, q, tip = groove_nearest(gap, centres)
        return dist - sleeve_radius_mm, q, tip

    phis = np.linspace(0.0, half, SEAT_SCAN_STEPS + 1)
    clearance = at(phis)[0]
    if clearance[0] < 0.0:  # cannot happen for e ≥ 0 (the groove widens outward); kept as a guard
        return SeatResult(False, "tip", math.nan, 0.0)
    touching = np.flatnonzero(clearance <= 0.0)
    if not touching.size:
        return SeatResult(False, "jump", math.nan, math.degrees(half))
    lo, hi = float(phis[touching[0] - 1]), float(phis[touching[0]])
    for _ in range(SEAT_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if at(np.array([mid]))[0][0] > 0.0:
            lo = mid
        else:
            hi = mid
    _, q, tip = at(np.array([hi]))
    on_tip = bool(tip[0])
    return SeatResult(not on_tip, "tip" if on_tip else "", float(np.hypot(*q[0])), math.degrees(hi))


def tip_limit_closed_form(gap: iso606.ToothGap, sleeve_radius_mm: float) -> float:
    """Check 1's limit in closed form (fraction): the sleeve touches the flank exactly at the tip
    corner C, so its centre is C + r·n (n the flank's outward normal at C, from the flank centre
    through C) and R·(1 + e) = |C + r·n|. Exact: along the sleeve centres' path round the groove
    (seating arc, flank, corner, tip land offset by r) the distance from the axis grows
    monotonically, so the first contact passes from the flank to the corner at this radius."""
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
                exact: ExactSection | None = None, tables: Sequence[ExactTable] = (),
                margin_mm: float = 0.0) -> bool:
    """``sweep_check(...).ok`` (default steps and margin), measuring only what can decide it: a
    sleeve or plate wholly outside the circle through the outline's farthest vertex (by more than
    ``margin_mm``) is clear without measuring (:meth:`ExactSection.clear_of_outline`), and the
    first pose that meets the outline ends the search. With ``margin_mm``: every distance
    ≥ ``margin_mm`` (the polyline's sagitta: certainly clear on the exact arcs; minus it: not
    certainly meeting them)."""
    w = worn_wrap(wrap.teeth, link.pitch_mm, elongation, wrap)
    before = int(math.ceil(WORN_SWEEP_MARGIN_FRACTION * WORN_SWEEP_STEPS_PER_CYCLE))
    angles = (np.arange(-before, WORN_SWEEP_STEPS_PER_CYCLE + before + 1) * w.cycle_rad
              / WORN_SWEEP_STEPS_PER_CYCLE)
    rows = _table_rows(tables, w, angles)
    if rows is not None:
        return bool(rows[..., 0].min() >= margin_mm and rows[..., 1].min() >= margin_mm)
    exact = exact if exact is not None else ExactSection(gap, link)
    for a in angles:
        sp = tc.sprocket_matrix(float(a))
        for pose in w.link_matrices(float(a)):
            sleeve_clear, plate_clear = exact.clear_of_outline(sp, pose, margin_mm)
            if sleeve_clear and plate_clear:
                continue
            least = exact.sleeve_clearance(sp, pose) if plate_clear else min(exact.link_distances(sp, pose))
            if least < margin_mm:
                return False
    return True


@dataclass(frozen=True)
class WearLimit:
    limit: float  # the elongation (fraction) at which a link first fails: see :func:`wear_limit`
    fail_at: float  # the bracket's failing end: the true limit is ≤ this (nan if none failed)
    mode: str  # what fails first: one of MODES
    declared: float  # the template's declared elongation (fraction)
    declared_seat: SeatResult
    declared_sweep: SweepCheck
    tolerance: float  # the bisections' tolerance on e (fraction)
    lo: float = 0.0  # the bracket's passing end: the true limit is ≥ this
    tip_closed_form: float = 0.0  # the tip mode's limit in closed form (fraction), whatever decides

    @property
    def ok(self) -> bool:
        return self.declared <= self.limit

    @property
    def mode_code(self) -> int:
        return MODES.index(self.mode)

    @property
    def closed_form(self) -> bool:
        """Whether the limit is the tip mode's closed form (else the bracket's passing end)."""
        return self.mode == "tip" and self.limit == self.tip_closed_form

    def bracket_text(self) -> str:
        """How the limit is known, in a few words (the verdict and the report say it)."""
        if self.mode == "none":
            return f"no failure up to {100 * self.lo:.4f} %"
        span = f"{100 * self.lo:.6f}–{100 * self.fail_at:.6f} %"
        if self.closed_form:
            return f"closed form on the exact arcs, inside the bisection bracket {span}"
        if self.mode == "sweep":
            return (f"true limit within {span}: bisection ±{100 * self.tolerance:.4f} % on the worn-pitch sweep, "
                    "widened by the outline's chord error")
        return f"true limit within {span}: bisection on the exact arcs"


def wear_limit(gap: iso606.ToothGap, link: tc.LinkGeometry, wrap: tc.ChainWrap, declared: float,
               tol: float = WEAR_BISECTION_TOL, bracket: float = WEAR_BRACKET_MAX,
               tables: Sequence[ExactTable] = ()) -> WearLimit:
    """The elongation at which a link first fails to seat, with a bracket [lo, fail_at] the true
    limit lies in, and both checks at the declared elongation (``tables``: see :func:`sweep_check`).

    Seat modes (tip, jump) on the exact arcs (:func:`seat_check`): bisection on e to ``tol``; in
    the tip mode the limit is its closed form (:func:`tip_limit_closed_form`), which the bracket
    holds. Then the worn-pitch sweep, on the outline polyline of :class:`ExactSection`, whose
    distances are within its chord sagitta s of the exact arcs' (the vertices lie on the arcs): a
    sweep whose distances are all ≥ s is certainly clear, one with a distance < −s certainly meets
    the sprocket. If the sweep is not certainly clear at the seat limit, two bisections find the
    last certainly clear e (the limit, conservative) and the first certainly failing one (the
    bracket's failing end; the seat limit's when the sweep is not certainly failing before it)."""
    section = ExactSection(gap, link)
    r = link.sleeve_radius_mm
    sag = section.sagitta_mm

    def clear(e: float, margin: float) -> bool:
        return sweep_clear(gap, link, wrap, e, exact=section, tables=tables, margin_mm=margin)

    declared_seat = seat_check(gap, r, declared)
    declared_sweep = sweep_check(gap, link, wrap, declared, exact=section, tables=tables)
    closed = tip_limit_closed_form(gap, r)

    # the seat check alone first (exact arcs, cheap), then the sweep up to its limit
    seat0 = seat_check(gap, r, 0.0)
    mode = seat_check(gap, r, bracket).mode
    if not seat0.ok:
        lo = hi = limit = 0.0
        mode = seat0.mode
    elif not mode:
        lo, hi, limit, mode = bracket, math.nan, bracket, "none"
    else:
        lo, hi = 0.0, bracket
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            m = seat_check(gap, r, mid).mode
            lo, hi, mode = (mid, hi, mode) if not m else (lo, mid, m)
        limit = lo
        if mode == "tip" and lo - tol <= closed <= hi + tol:
            limit, lo, hi = closed, min(lo, closed), max(hi, closed)
    # does the worn-pitch sweep fail first?
    if not clear(limit, sag):
        s_lo, s_hi = 0.0, limit
        if not clear(0.0, sag):
            s_hi = 0.0
        while s_hi - s_lo > tol:
            mid = 0.5 * (s_lo + s_hi)
            s_lo, s_hi = (mid, s_hi) if clear(mid, sag) else (s_lo, mid)
        if not clear(limit, -sag):  # certainly failing by the seat limit: where first?
            f_lo, f_hi = s_lo, limit
            while f_hi - f_lo > tol:
                mid = 0.5 * (f_lo + f_hi)
                f_lo, f_hi = (mid, f_hi) if clear(mid, -sag) else (f_lo, mid)
            hi = f_hi if clear(s_lo, -sag) else s_lo
        lo = limit = s_lo
        mode = "sweep"
    return WearLimit(limit, hi, mode, declared, declared_seat, declared_sweep, tol, lo, closed)
