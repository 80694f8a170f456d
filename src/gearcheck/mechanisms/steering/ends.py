"""The trimmed rack end teeth once their pinion tooth lets go (numpy only).

G1 drags the first rack tooth by its left flank until its tip corner S1 reaches the corner S2, G2
the second one until S3 reaches S4. From then on the tooth's tip land passes over the trimmed top
(S2–S6, S4–S8), and the top has to clear it. Whether it does depends on where the rack stands
while the tip land sweeps over the top, which the push model (:mod:`.push`) decides:

* S1 passes S2 with nothing else pushing: the rack stands at L(S1/S2) (eq 22), either for good (the
  paper's design) or until G2's corner S3, dragging the second tooth, picks it up again (RS1 below
  the equal-travel radius: the rack then stops for good later, when S3 reaches S4). S2 lies on G1's
  tip circle while the rack stands, so the top must lie under that circle's tangent at S2: the
  paper's tangent construction (hS6_max), applied at the stand that really happens.
* The rack stops for good with the drive corner outside the tip circle (S4 when G1 decides the
  stop, S2 when S3/S4 does): the tip land sweeps over the top at a distance, and the top may rise
  until it meets the tip circle.

While the rack moves on (+x) every point of it moves away from the pinion centre, so a top that
clears a tip circle at a stand clears it from then on. The rule (:func:`end_tops`): at every stand
that follows a tooth letting go of its drive corner, and at the final stop, the trimmed top must lie
outside the region the tip tooth sweeps during the stand (polar angles between its left flank at the
start and its right flank at the end, radii up to its tip circle); the least far-corner height that
fails is the limit, a design result. The push model's own overlap of each tip tooth with its end
tooth, on both towing swings, stands beside it; either failing fails the design (the push model's
limit lies about 0.002 mm of far-corner height above the rule's, its 0.1 µm contact tolerance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.mechanisms.steering import push
from gearcheck.mechanisms.steering.analysis import tangent_top_height, travel_corner_on_circle

# A drive corner this close to a tip circle lies on it (the closed forms put it there to 1e-12 mm).
ON_CIRCLE_MM = 1e-9
# Points along a trimmed top checked against the tooth's sweep, and the bisection on its far corner.
TOP_POINTS = 4001
HEIGHT_STEPS = 60
# A step past the corner event to see whether another tooth carries the rack on (rad, ≪ grid step).
AFTER_EVENT_RAD = 1e-6


@dataclass(frozen=True)
class Stand:
    """The rack standing at ``travel_mm`` from ``start_rad`` to ``end_rad`` (a pick-up, or the end of
    the swing when ``final``), after ``why``."""

    start_rad: float
    end_rad: float
    travel_mm: float
    why: str  # "S1 passes S2", "S3 passes S4" or "the rack stops for good"
    final: bool

    @property
    def start_deg(self) -> float:
        return math.degrees(self.start_rad)

    @property
    def end_deg(self) -> float:
        return math.degrees(self.end_rad)


@dataclass(frozen=True)
class EndTop:
    """One trimmed end tooth against the pinion tooth that drove it last."""

    tooth: str  # "G1" / "G2"
    tip_corner: str  # "S1" / "S3"
    corner: str  # drive corner, "S2" / "S4"
    far: str  # far corner, "S6" / "S8"
    field: str  # "trim.hS6_mm" / "trim.hS8_mm"
    circle: str  # "RS1" / "Ra"
    radius_mm: float
    height_mm: float  # machined far-corner height
    top_mm: float  # rack tooth top (the field's upper end)
    limit_mm: float  # highest far corner the tooth clears at every stand (top_mm: no limit below it; NaN: none)
    stand: Stand | None  # the stand that sets the limit
    corner_gap_mm: float  # drive corner outside the tip circle at that stand (0: on it)
    overlap_mm: float  # push model: deepest overlap of the pair, both swings (0: clear or touching)
    overlap_deg: float  # where (pinion angle, the + direction; NaN without overlap)
    overlap_swing: str  # "forward" / "return" / ""

    @property
    def clears(self) -> bool:
        """The rule at every stand (zero tolerance) and the push model (its contact tolerance)."""
        return (math.isfinite(self.limit_mm) and self.height_mm <= self.limit_mm + ON_CIRCLE_MM
                and self.overlap_mm <= push.TRAVEL_TOL_MM)

    @property
    def rack_tooth(self) -> str:
        return "first" if self.tooth == "G1" else "second"

    @property
    def on_circle(self) -> bool:
        return abs(self.corner_gap_mm) <= ON_CIRCLE_MM


def end_pairs(g: RackPinionGeometry) -> list[tuple[str, int, int, str, str, str, str, str]]:
    """(tooth, j, k, tip corner, drive corner, far corner, field, circle) of the two trimmed end teeth."""
    j, k = g.sector_first_tooth, g.rack_first_tooth
    return [("G1", j, k, "S1", "S2", "S6", "trim.hS6_mm", "RS1"),
            ("G2", j + 1, k + 1, "S3", "S4", "S8", "trim.hS8_mm", "Ra")]


def _corner_event(g: RackPinionGeometry, j: int, k: int) -> tuple[float, float]:
    """(φ, L) at which tooth j's right tip corner reaches rack tooth k's left top corner, the
    corner on the tip circle (eqs 3, 22)."""
    h_corner = g.rack_corner_heights(k)[0]
    radius = g.pinion_tip_radius(j)
    travel = travel_corner_on_circle(g, k, h_corner, radius)
    x = k * g.pitch + travel - float(g.rack_half_width(h_corner))
    polar = math.atan2(x, g.centre_height - h_corner)
    return polar - float(g.involute_half_angle(radius)) - (j + 0.5) * g.angular_pitch, travel


def _travel_at(g: RackPinionGeometry, tow: push.Towing, phi: float) -> float:
    """Forward-swing travel at φ, pushed exactly from the grid angle before it."""
    fwd = tow.forward
    i = int(np.searchsorted(fwd.phi_rad, phi, side="right")) - 1
    if i < 0:
        return float(fwd.travel_mm[0])
    return push._travel_after(g, phi, float(fwd.travel_mm[i]), +1, float(fwd.phi_rad[i]))


def stands(g: RackPinionGeometry, tow: push.Towing) -> list[Stand]:
    """The stands of the forward swing that follow an end tooth letting go of its drive corner (S1
    at S2, S3 at S4: the rack at that corner's travel, nothing carrying it on) and the final stop."""
    fwd = tow.forward
    end = float(fwd.phi_rad[-1])
    out: list[Stand] = []
    for _, j, k, tip, corner, *_ in end_pairs(g):
        phi, travel = _corner_event(g, j, k)
        if not (fwd.phi_rad[0] < phi < end):
            continue
        at = _travel_at(g, tow, phi)
        if abs(at - travel) > push.TRAVEL_TOL_MM:  # the rack is elsewhere: this tooth does not reach the corner
            continue
        if push._travel_after(g, phi + AFTER_EVENT_RAD, at, +1, phi) > at + push.TRAVEL_TOL_MM:
            continue  # another tooth carries the rack on as the corner passes
        moved = np.flatnonzero((fwd.phi_rad > phi) & (fwd.travel_mm > at + push.TRAVEL_TOL_MM))
        if moved.size:
            m = int(moved[0])
            lo = max(float(fwd.phi_rad[m - 1]), phi)
            pick = push._bisect(lambda p, lo=lo, at=at: push._travel_after(g, p, at, +1, lo)
                                > at + push.TRAVEL_TOL_MM, lo, float(fwd.phi_rad[m]))
            out.append(Stand(phi, pick, at, f"{tip} passes {corner}", False))
        else:
            out.append(Stand(phi, end, at, f"{tip} passes {corner}", True))
    if math.isfinite(tow.disengage_rad) and not any(
            s.final and abs(s.travel_mm - tow.travel_at_disengage_mm) <= push.TRAVEL_TOL_MM for s in out):
        out.append(Stand(tow.disengage_rad, end, tow.travel_at_disengage_mm, "the rack stops for good", True))
    return sorted(out, key=lambda s: s.start_rad)


def _top_points(g: RackPinionGeometry, k: int, travel: float, far_height: float) -> np.ndarray:
    """Points along rack tooth k's straight top from its left corner to its right corner, the right
    one at ``far_height`` on the real right flank."""
    h_left = g.rack_corner_heights(k)[0]
    c = k * g.pitch + travel
    left = np.array([c - float(g.rack_half_width(h_left)), h_left])
    right = np.array([c + float(g.rack_half_width(far_height)), far_height])
    s = np.linspace(0.0, 1.0, TOP_POINTS)[:, None]
    return left + s * (right - left)


def _swept_depth(g: RackPinionGeometry, j: int, stand: Stand, points: np.ndarray) -> float:
    """How deep the points lie inside the region pinion tooth j sweeps over the stand (> 0: inside),
    in mm: the least of their depth inside its tip circle and their arc distance inside the polar
    angles its flanks cover, the left flank at the start and the right flank at the end."""
    H = g.centre_height
    rho = np.hypot(points[:, 0], H - points[:, 1])
    polar = np.arctan2(points[:, 0], H - points[:, 1])
    radius = g.pinion_tip_radius(j)
    beta = g.involute_half_angle(np.clip(rho, g.base_radius, None))
    centre = (j + 0.5) * g.angular_pitch
    inside = np.minimum.reduce([radius - rho,
                                rho * (polar - (centre + stand.start_rad - beta)),
                                rho * ((centre + stand.end_rad + beta) - polar)])
    return float(inside.max())


def _corner_gap(g: RackPinionGeometry, j: int, k: int, travel: float) -> float:
    """How far rack tooth k's drive corner lies outside tooth j's tip circle at ``travel`` (mm)."""
    h_left = g.rack_corner_heights(k)[0]
    x = k * g.pitch + travel - float(g.rack_half_width(h_left))
    return math.hypot(x, g.centre_height - h_left) - g.pinion_tip_radius(j)


def _stand_limit(g: RackPinionGeometry, j: int, k: int, stand: Stand) -> float:
    """Highest far corner of rack tooth k whose top stays outside the sweep of tooth j during the
    stand: the tangent at the drive corner (closed form, hS6_max / hS8_max) when the corner lies on
    the tip circle inside the sweep, else by bisection; the rack top when even the untrimmed height
    clears, NaN when no height does."""
    top = g.rack_top_height

    def clear(height: float) -> bool:
        return _swept_depth(g, j, stand, _top_points(g, k, stand.travel_mm, height)) <= 0.0

    if clear(top):
        return top
    corner = _top_points(g, k, stand.travel_mm, top)[0]
    polar = math.atan2(corner[0], g.centre_height - corner[1])
    beta = float(g.involute_half_angle(g.pinion_tip_radius(j)))
    centre = (j + 0.5) * g.angular_pitch
    swept = centre + stand.start_rad - beta <= polar < centre + stand.end_rad + beta
    if abs(_corner_gap(g, j, k, stand.travel_mm)) <= ON_CIRCLE_MM and swept:
        return tangent_top_height(g, corner, k, stand.travel_mm)
    lo, hi = g.made_rolling_line_height, top
    if not clear(lo):
        return math.nan
    for _ in range(HEIGHT_STEPS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if clear(mid) else (lo, mid)
    return lo


def _pair_overlap(g: RackPinionGeometry, sweep: push.Sweep, j: int, k: int) -> tuple[float, float]:
    """(deepest overlap, angle) of pair (j, k) along a swing of the push model."""
    pairs, (lo, hi), _, _ = push.all_intervals(g, sweep.phi_rad, only=(j, k), parts=("whole",))
    n = pairs.index((j, k))
    depth = push._overlap_depths(lo[n:n + 1], hi[n:n + 1], sweep.travel_mm)
    i = int(np.argmax(depth))
    return float(depth[i]), float(sweep.phi_rad[i])


def end_tops(g: RackPinionGeometry, tow: push.Towing) -> tuple[EndTop, ...]:
    """Both trimmed end teeth against the rule above and the push model (the + towing direction; the
    other is its mirror image)."""
    found = stands(g, tow)
    out = []
    for tooth, j, k, tip, corner, far, field, circle in end_pairs(g):
        limit, deciding = g.rack_top_height, None
        for stand in found:
            at = _stand_limit(g, j, k, stand)
            if not at >= limit:  # NaN: no height clears
                limit, deciding = at, stand
        gap = _corner_gap(g, j, k, deciding.travel_mm) if deciding else math.nan
        worst = [(*_pair_overlap(g, s, j, k), name) for s, name in ((tow.forward, "forward"), (tow.back, "return"))]
        depth, angle, swing = max(worst, key=lambda w: w[0])
        touching = depth <= 0.0
        out.append(EndTop(tooth, tip, corner, far, field, circle, g.pinion_tip_radius(j), g.rack_corner_heights(k)[1],
                          g.rack_top_height, limit, deciding, gap, depth,
                          math.nan if touching else math.degrees(angle), "" if touching else swing))
    return tuple(out)
