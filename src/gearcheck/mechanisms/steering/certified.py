"""The exact model's clearance certified over the continuous motion (numpy only): every pinion tooth
against every rack tooth it can meet, on the towing swings and the power stroke, not only at the
swept poses.

The samples are the sweep's poses: pinion angles and the exact model's rack travel there (the push
model in towing, the closed form in power mode). At each the exact signed clearance of every tooth
pair is evaluated in closed form (:mod:`gearcheck.geometry.rack_pinion_clearance`). Between two
samples each pair is bounded by the best of:

* **the path bound** (always): no point of the tooth moves more than δ = r_tip·Δφ + |ΔL| relative
  to the rack (the travel is monotone), so the clearance stays ≥ (c0 + c1 − δ)/2;
* **fixed directions**, where the travel is known to be linear in the angle over the interval: the
  rack standing (equal travels at both ends), a pusher in conjugate mesh, or a tip corner dragging
  a flank (its travel's curvature bounded). A pusher is a pair whose pushing flank (the left flanks
  on the forward swing, the right ones on the return swing) touches the tooth at both ends, on the
  same piece of the tooth (involute or tip corner) and within the flank. The separation in a world
  direction is then smooth with a known curvature bound, exactly linear for the conjugate flank of
  the other side (zero backlash: it touches throughout, at zero clearance, which no path bound can
  show) and for the tip land grazing a standing corner;
* **the pusher itself** is in contact by the motion's definition (clearance 0 in its flank's
  direction). In power mode past S6 the closed form rides S6 on the involute: that pair is in
  contact the same way.

A known motion holds only while no other pair overlaps under it (that pair would push instead): an
interval where one does is bounded by the path bound alone. An interval whose bound lies below the
requirement while its ends pass is split at its middle (the push model's step, the pusher's contact
travel or the closed form gives the travel there) until it decides or is shorter than
:data:`RESOLUTION_RAD`; then the least bound is sharpened to :data:`PRECISION_MM` below the least
clearance measured beside it.

Only the + direction is evaluated: the design is mirror-symmetric (the parameters require it), so
the − direction is its mirror image.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from gearcheck.geometry import rack_pinion_clearance as rc
from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import pinion_name
from gearcheck.geometry.rack_pinion_power import phi_power_conjugate_end, power_model_angle
from gearcheck.mechanisms.steering import push

# The exact model decides interference within its own tolerance (the push model's touching).
EXACT_TOL_MM = push.TRAVEL_TOL_MM
# A pusher's flank touches within this (the push model's polyline lies within 0.05 µm of the exact
# flank; the clearance is evaluated in closed form to ~1e-12 mm).
TOUCH_MM = 1e-6
# The push on the exact teeth goes on from the push model's (polyline) travel by at most this: the
# polyline's chords sag up to (chord²/8ρ) inside the flanks (0.04 µm on the template, more on a
# coarse module), far less.
SNAP_MM = 1e-3
# A pair whose path bound stays above this over every interval is left out (its bound is kept).
NEAR_MM = 0.5
# An interval this short (rad of pinion angle, ~0.01 µm at the tip) is not split again.
RESOLUTION_RAD = 1e-7
# The certified minimum is sharpened to this below the least clearance measured beside it, with at
# most SHARPEN more samples per part; at most MAX_REFINED samples per part to decide.
PRECISION_MM = 1e-5
SHARPEN = 64
MAX_REFINED = 4000

STROKES = {"forward": "towing, forward swing", "past": "towing, past the disengage", "back": "towing, return swing",
           "power": "power mode"}
PARTS = tuple(STROKES)


@dataclass
class _Sample:
    phi: float
    travel: float
    sd: np.ndarray  # per pair
    psi: np.ndarray  # per pair: the direction attaining it


@dataclass
class PartCertificate:
    """One part of the motion (a stroke, or the forward swing before or past the disengage)."""

    name: str
    certified_min: float = math.inf
    sampled_min: float = math.inf
    between_rad: tuple[float, float] = (math.nan, math.nan)
    pair: tuple[int, int] = (0, 0)
    intervals: int = 0
    refined: int = 0
    undecided: int = 0
    known_motion: int = 0  # intervals bounded with the motion known (stand, pusher, closed form)


@dataclass
class ExactCertificate:
    """The exact model certified over the continuous motion, by part (:data:`STROKES`)."""

    parts: dict[str, PartCertificate] = field(default_factory=dict)
    requirement: float = -EXACT_TOL_MM

    def scope(self, *names: str) -> PartCertificate:
        """The least of the named parts (the parts that exist)."""
        have = [self.parts[n] for n in names if n in self.parts]
        if not have:
            return PartCertificate("none")
        worst = min(have, key=lambda p: p.certified_min)
        return PartCertificate(worst.name, worst.certified_min, min(p.sampled_min for p in have), worst.between_rad,
                               worst.pair, sum(p.intervals for p in have), sum(p.refined for p in have),
                               sum(p.undecided for p in have), sum(p.known_motion for p in have))


@dataclass(frozen=True)
class _Motion:
    """What drives an interval, where known: "stand", "rolling" (power mode's conjugate closed form),
    "push" (the pairs ``pushing``, dL/dφ ``rates`` at the ends, |L''| ≤ ``curvature``) or "ride"
    (``vertex`` of pair ``pair`` on its involute)."""

    kind: str
    pushing: np.ndarray | None = None
    rates: tuple[float, float] = (0.0, 0.0)
    curvature: float = 0.0
    pair: int = -1
    vertex: int = -1


@dataclass(frozen=True)
class _Set:
    """Some of the tooth pairs with their pushing flanks: the direction across each (ψ, its e_x)
    and each flank's top height."""

    tp: rc.ToothPairs
    flank: np.ndarray
    ex: np.ndarray
    flank_top: np.ndarray


class _Stroke:
    """The samples of one stroke and how to bound and refine the intervals between them, over the
    tooth pairs (P) of the push model; ``side`` +1: the left flanks push (+x), −1 the right ones.
    A sample holds every pair's exact clearance where the circles holding the two teeth come
    within :data:`NEAR_MM`, elsewhere that circles' gap (a lower bound); an interval is bounded in
    detail for the pairs its path bound leaves within :data:`NEAR_MM`."""

    def __init__(self, tp: rc.ToothPairs, phis, travels, side: int, mode: str):
        self._setup(tp, side, mode)
        phis = np.asarray(phis, dtype=float)
        travels = self.snapped(phis, np.asarray(travels, dtype=float))
        sd, psi = self._clearances(phis, travels)
        self.samples = [_Sample(float(phis[i]), float(travels[i]), sd[i], psi[i]) for i in range(phis.size)]

    def _setup(self, tp: rc.ToothPairs, side: int, mode: str) -> None:
        g = tp.g
        self.g, self.side, self.mode = g, side, mode
        self.edge = 3 if side > 0 else 1  # the pushing flank among each rack tooth's edges
        self.ends = (3, 0) if side > 0 else (1, 2)  # its two vertices
        self.root = g.rack_root_height
        self.conjugate_end = phi_power_conjugate_end(g, g.rack_first_tooth, g.hS6_mm)
        self.all = self._set(tp)
        self._sets: dict[tuple[int, ...], _Set] = {}

    def _set(self, tp: rc.ToothPairs) -> _Set:
        flank = tp.edges[:, self.edge]
        top = np.array([self.g.rack_corner_heights(k)[0 if self.side > 0 else 1] for _, k in tp.pairs])
        return _Set(tp, flank, np.sin(flank), top)

    def subset(self, index: np.ndarray) -> _Set:
        key = tuple(int(i) for i in index)
        if key not in self._sets:
            self._sets[key] = self._set(self.all.tp.take(key))
        return self._sets[key]

    def _clearances(self, phis: np.ndarray, travels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, P) clearances (exact where the teeth's circles come near, else the circles' gap) and
        directions (NaN where not exact) at poses (N,)."""
        sd = self.all.tp.apart(phis, travels)
        psi = np.full(sd.shape, np.nan)
        for n in range(sd.shape[-1]):
            near = sd[..., n] < NEAR_MM
            if near.any():
                s, p = self.all.tp.take([n]).signed_clearance(phis[near], travels[near])
                sd[near, n], psi[near, n] = s[..., 0], p[..., 0]
        return sd, psi

    def sample(self, phi: float, travel: float) -> _Sample:
        sd, psi = self._clearances(np.array([phi]), np.array([travel]))
        return _Sample(phi, travel, sd[0], psi[0])

    # --- who pushes ----------------------------------------------------------------------------
    def _touching(self, st: _Set, phi, travel, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per pair at (φ, L) (...): the separation in its pushing flank's direction, whether the
        tooth touches that flank within ``tol`` on its tip corner or involute and within the flank's
        heights, and the piece."""
        sep = st.tp.separation(phi, travel, st.flank[:, None])[..., 0]
        delta = st.flank - st.tp.theta(phi)
        piece = st.tp.piece(delta[..., None])[..., 0]
        height = st.tp.support_point(phi, delta)[..., 1]
        on = (np.abs(sep) <= tol) & ((piece == 1) | (piece == 2)) & (height >= self.root - 1e-9) \
            & (height <= st.flank_top + 1e-9)
        return sep, on, piece

    def snapped(self, phis: np.ndarray, travels: np.ndarray) -> np.ndarray:
        """Towing: the push on the exact teeth. The push model's polyline teeth lie inside the exact
        ones (by up to their chords' sag), so its rack stops a little short: each pose's travel is
        pushed on to where no pushing flank cuts an exact tooth, a flank on the tooth or a flank's
        end on its involute, as far as the farthest of those cut by at most :data:`SNAP_MM` (a deeper
        cut is no chord's doing: it stays, as the interference it is)."""
        if self.mode != "towing" or not phis.size:
            return travels
        st = self.all
        sep, on, _ = self._touching(st, phis, travels, SNAP_MM)
        found = [np.where(on, travels[..., None] - sep / st.ex, np.nan)]
        for vertex in self.ends:
            travel = np.broadcast_to(travels[..., None], sep.shape).copy()
            phi, rho, x, c = self._riding(st, vertex, travel)
            near = (np.abs(rc.wrapped(phi - phis[..., None])) * rho <= SNAP_MM) & (rho >= st.tp.r_form) \
                & (rho <= st.tp.r_tip[:, 0])
            for _ in range(3):  # Newton on φ(L) = φ
                travel = travel - rc.wrapped(phi - phis[..., None]) / self._turn(st, rho, x, c)
                phi, rho, x, c = self._riding(st, vertex, travel)
            found.append(np.where(near, travel, np.nan))
        ahead = (np.concatenate(found, axis=-1) - travels[..., None]) * self.side  # how far each pushes on
        ahead = np.where((ahead >= 0.0) & (ahead <= SNAP_MM), ahead, 0.0)
        return travels + self.side * ahead.max(axis=-1, initial=0.0)

    def pushers(self, st: _Set, a: _Sample, b: _Sample) -> tuple[np.ndarray, np.ndarray]:
        """Pairs whose pushing flank touches the tooth at both ends (on its tip corner or involute,
        within the flank), and whether that is the tip corner at either end."""
        _, on, piece = self._touching(st, np.array([a.phi, b.phi]), np.array([a.travel, b.travel]), TOUCH_MM)
        return on[0] & on[1], (piece[0] == 1) | (piece[1] == 1)

    def contact_rate(self, st: _Set, phi: float, pushing: np.ndarray) -> float:
        """dL/dφ of the first pusher's contact travel at φ (e_x·L = h(δ) + const)."""
        n = int(np.flatnonzero(pushing)[0])
        delta = st.flank[n] - st.tp.theta(phi)[n]
        return float(-st.tp.slope(np.full((len(st.tp.pairs), 1), delta))[n, 0] / st.ex[n])

    # --- a rack corner riding a pinion involute ---------------------------------------------------
    def _riding(self, st: _Set, vertex: int, travel) -> tuple[np.ndarray, ...]:
        """For the pushing flank's end ``vertex`` of each rack tooth at travel L: the pinion angle at
        which it lies on the facing involute of the pair's tooth (the right involute when the rack
        is pushed +x, the left one −x), its radius, its abscissa and depth below the centre."""
        tp = st.tp
        x = tp.vertices[:, vertex, 0] + travel
        c = self.g.centre_height - tp.vertices[:, vertex, 1]
        rho = np.hypot(x, c)
        beta = self.g.involute_half_angle(np.maximum(rho, tp.r_base))
        return np.arctan2(x, c) - self.side * beta - tp.theta0, rho, x, c

    def _turn(self, st: _Set, rho, x, c) -> np.ndarray:
        """dφ/dL of a corner riding the involute: dγ/dL − side·β'(ρ)·x/ρ, β' = −√(ρ² − rb²)/(rb·ρ)."""
        rb = st.tp.r_base
        w = np.sqrt(np.maximum(rho * rho - rb * rb, 0.0))
        return c / rho ** 2 + self.side * x * w / (rb * rho ** 2)

    def riders(self, st: _Set, a: _Sample, b: _Sample) -> list[tuple[int, int]]:
        """(pair, vertex) of the pushing flanks' ends that ride their tooth's involute at both ends
        (between the form and the tip circle)."""
        out = []
        for vertex in self.ends:
            ok = np.ones(len(st.tp.pairs), bool)
            for s in (a, b):
                phi, rho, _, _ = self._riding(st, vertex, s.travel)
                ok &= (np.abs(rc.wrapped(phi - s.phi)) * rho <= TOUCH_MM) & (rho >= st.tp.r_form) \
                    & (rho <= st.tp.r_tip[:, 0])
            out += [(int(n), vertex) for n in np.flatnonzero(ok)]
        return out

    def _ride_bounds(self, st: _Set, n: int, vertex: int, a: _Sample, b: _Sample) -> tuple[float, ...]:
        """dφ/dL at both ends, and bounds of |dφ/dL| and |d²φ/dL²| over the interval, of corner
        ``vertex`` of pair n riding its involute (φ = γ − side·β(ρ) − θ0: closed form in L)."""
        rb = st.tp.r_base
        ends = [self._riding(st, vertex, s.travel) for s in (a, b)]
        turns = [float(self._turn(st, r[1], r[2], r[3])[n]) for r in ends]
        x = np.array([ends[0][2][n], ends[1][2][n]])
        c = abs(float(ends[0][3][n]))
        x_max = float(np.max(np.abs(x)))
        rho_min = math.hypot(0.0 if x[0] * x[1] <= 0.0 else float(np.min(np.abs(x))), c)
        rho_max = math.hypot(x_max, c)
        w_min = math.sqrt(max(rho_min ** 2 - rb ** 2, 0.0))
        w_max = math.sqrt(max(rho_max ** 2 - rb ** 2, 0.0))
        turn_max = c / rho_min ** 2 + x_max * w_max / (rb * rho_min ** 2)
        bend_max = (2.0 * c * x_max / rho_min ** 4
                    + (w_max / rho_min ** 2 + (x_max ** 2 / (w_min * rho_min ** 2) if w_min > 0.0 else math.inf)
                       + 2.0 * x_max ** 2 * w_max / rho_min ** 4) / rb)
        return turns[0], turns[1], turn_max, bend_max

    # --- bounds ---------------------------------------------------------------------------------
    def _motion(self, st: _Set, a: _Sample, b: _Sample) -> _Motion | None:
        """What drives the interval, where known (:class:`_Motion`); None: only the path bound holds."""
        if a.travel == b.travel:
            return _Motion("stand")
        if self.mode == "power" and b.phi <= self.conjugate_end:
            return _Motion("rolling")
        if self.mode == "towing":
            pushing, corner = self.pushers(st, a, b)
            if pushing.any():
                curvature = float(np.max(np.where(pushing & corner, st.tp.r_tip[:, 0] / np.abs(st.ex), 0.0)))
                rates = (self.contact_rate(st, a.phi, pushing), self.contact_rate(st, b.phi, pushing))
                return _Motion("push", pushing, rates, curvature)
        riders = self.riders(st, a, b)
        return _Motion("ride", pair=riders[0][0], vertex=riders[0][1]) if riders else None

    def _fixed(self, st: _Set, motion: _Motion, a: _Sample, b: _Sample, psi, corners=(0, 1, 2, 3)) -> np.ndarray:
        """Each pair's separations in the directions ψ bounded over the interval under ``motion``."""
        tp, ends = st.tp, (a.phi, b.phi, a.travel, b.travel, psi)
        if motion.kind == "stand":
            return tp.fixed_direction_bound(*ends, corners=corners)
        if motion.kind == "rolling":
            r = self.g.pitch_radius
            return tp.fixed_direction_bound(*ends, r, r, corners=corners)
        if motion.kind == "push":
            return tp.fixed_direction_bound(*ends, motion.rates[0], motion.rates[1], motion.curvature, corners)
        turn0, turn1, turn_max, bend_max = self._ride_bounds(st, motion.pair, motion.vertex, a, b)
        return tp.travel_driven_bound(*ends, turn0, turn1, turn_max, bend_max, corners)

    def bound(self, a: _Sample, b: _Sample) -> tuple[float, int, bool]:
        """The least clearance any pair can have between two samples, the pair, and whether the
        motion was known there (module doc)."""
        move = abs(b.travel - a.travel)
        path = self.all.tp.r_tip[:, 0] * abs(b.phi - a.phi) + move
        lb = np.minimum(np.minimum(a.sd, b.sd), 0.5 * (a.sd + b.sd - path))
        index = np.flatnonzero(lb < NEAR_MM)
        if not index.size:
            return self._least(lb, move == 0.0)
        st = self.subset(index)
        sd_a, sd_b = a.sd[index], b.sd[index]
        edges = st.tp.edges
        psi = np.concatenate([edges, np.where(np.isnan(a.psi[index]), edges[:, 0], a.psi[index])[:, None],
                              np.where(np.isnan(b.psi[index]), edges[:, 0], b.psi[index])[:, None]], axis=-1)
        near = lb[index]
        # the rack as if standing at its first travel, less how far it moves (every separation is
        # 1-Lipschitz in the travel): exact in a stand, good wherever it barely moves
        near = np.maximum(near, st.tp.fixed_direction_bound(a.phi, b.phi, a.travel, a.travel, psi).max(axis=-1) - move)
        motion = self._motion(st, a, b)
        known = motion is not None
        if motion is not None and motion.kind != "stand":
            fixed = self._fixed(st, motion, a, b, psi).max(axis=-1)
            driving = np.zeros(index.size, bool)
            if motion.pushing is not None:
                driving = motion.pushing
            elif motion.kind == "ride":
                driving[motion.pair] = True
            # the driving pair is in contact by the motion's definition
            fixed = np.where(driving, np.maximum(fixed, np.minimum(np.minimum(sd_a, sd_b), 0.0)), fixed)
            deficit = 0.0
            if self.mode == "towing":
                # the motion holds while no other pair cuts a pushing flank (it would push instead):
                # one that may cut it by ε pushes the rack at most ε/|e_x| further
                cut = np.maximum(near, fixed)
                if np.any(~driving & (cut < -TOUCH_MM)):
                    cut = np.maximum(cut, self._fixed(st, motion, a, b, psi, self.ends).max(axis=-1))
                deficit = max(0.0, -float(np.min(np.where(driving, np.inf, cut), initial=np.inf)))
                deficit /= float(np.min(np.abs(st.ex)))
            if deficit <= EXACT_TOL_MM:
                near = np.maximum(near, fixed - deficit)
            else:
                known = False
        lb[index] = near
        return self._least(lb, known)

    @staticmethod
    def _least(lb: np.ndarray, known: bool) -> tuple[float, int, bool]:
        n = int(np.argmin(lb))
        return float(lb[n]), n, known

    def midpoint(self, a: _Sample, b: _Sample) -> tuple[float, float]:
        """A pose of the exact model between two samples: (φ, L)."""
        path = self.all.tp.r_tip[:, 0] * abs(b.phi - a.phi) + abs(b.travel - a.travel)
        index = np.flatnonzero(np.minimum(np.minimum(a.sd, b.sd), 0.5 * (a.sd + b.sd - path)) < NEAR_MM)
        st = self.subset(index) if index.size else self.all
        motion = self._motion(st, a, b)
        if motion is not None and motion.kind == "ride":
            travel = 0.5 * (a.travel + b.travel)
            return float(self._riding(st, motion.vertex, travel)[0][motion.pair]), travel
        phi = 0.5 * (a.phi + b.phi)
        if motion is None and self.mode == "power":
            return phi, _power_travel(self.g, a, b, phi)
        if motion is not None and motion.kind in ("stand", "rolling"):
            return phi, a.travel if motion.kind == "stand" else self.g.pitch_radius * phi + self.g.flank_offset
        if motion is not None and motion.pushing is not None:  # the pushers' contact travel (the farthest)
            contact = -st.tp.separation(phi, 0.0, st.flank[:, None])[..., 0] / st.ex
            return phi, float(np.where(motion.pushing, contact * self.side, -np.inf).max() * self.side)
        travel = push._travel_after(self.g, phi, a.travel, self.side, a.phi)
        travel = float(self.snapped(np.array([phi]), np.array([travel]))[0])
        return phi, min(max(travel, min(a.travel, b.travel)), max(a.travel, b.travel))


def exact_travels(g: RackPinionGeometry, phis, travels, side: int) -> np.ndarray:
    """The push model's towing travels pushed on to the exact teeth (:meth:`_Stroke.snapped`);
    ``side`` +1 the forward swing (left flanks push), −1 the return swing."""
    stroke = _Stroke.__new__(_Stroke)
    stroke._setup(rc.ToothPairs(g, push.tooth_pairs(g)), side, "towing")
    return stroke.snapped(np.asarray(phis, dtype=float), np.asarray(travels, dtype=float))


def _power_travel(g: RackPinionGeometry, a: _Sample, b: _Sample, phi: float) -> float:
    """The travel at which the closed-form power model reaches φ (bisection between the samples:
    the angle is monotone in the travel)."""
    lo, hi = a.travel, b.travel
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if power_model_angle(g, mid) < phi:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _certify_part(stroke: _Stroke, lo: int, hi: int, name: str, requirement: float) -> PartCertificate:
    """Branch and bound over the intervals between samples lo … hi of a stroke: the interval with
    the least bound is split while it does not decide the requirement (its ends pass, its bound
    does not) or lies more than :data:`PRECISION_MM` below its ends; the first that needs neither
    holds the certified minimum."""
    cert = PartCertificate(name)
    samples = stroke.samples[lo:hi + 1]
    if not samples:
        return cert
    cert.sampled_min = float(min(s.sd.min() for s in samples))
    if len(samples) == 1:
        cert.certified_min, cert.between_rad = cert.sampled_min, (samples[0].phi, samples[0].phi)
        return cert
    heap: list[tuple[float, int, _Sample, _Sample, int, bool]] = []
    order = itertools.count()  # ties in the bound never compare the samples

    def add(a: _Sample, b: _Sample) -> None:
        lb, n, known = stroke.bound(a, b)
        heapq.heappush(heap, (lb, next(order), a, b, n, known))

    for a, b in zip(samples[:-1], samples[1:], strict=True):
        add(a, b)
    cert.intervals = len(heap)
    sharpened = 0
    while True:
        lb, _, a, b, n, known = heap[0]
        ends = min(float(a.sd.min()), float(b.sd.min()))
        deciding = lb < requirement <= ends
        work = (deciding and cert.refined - sharpened < MAX_REFINED) or (
            not deciding and lb < ends - PRECISION_MM and sharpened < SHARPEN)
        if not work or abs(b.phi - a.phi) <= RESOLUTION_RAD:
            break
        heapq.heappop(heap)
        m = stroke.sample(*stroke.midpoint(a, b))
        cert.sampled_min = min(cert.sampled_min, float(m.sd.min()))
        cert.refined += 1
        sharpened += 0 if deciding else 1
        add(a, m)
        add(m, b)
    lb, _, a, b, n, _ = heap[0]
    cert.certified_min, cert.between_rad, cert.pair = lb, (a.phi, b.phi), stroke.all.tp.pairs[n]
    cert.undecided = sum(1 for e in heap if e[0] < requirement <= min(float(e[2].sd.min()), float(e[3].sd.min())))
    cert.known_motion = sum(1 for e in heap if e[5])
    return cert


def certify_exact(g: RackPinionGeometry, out_phis, out_travels, back_phis, back_travels, power_travels,
                  disengage_rad: float = math.nan) -> ExactCertificate:
    """The exact model's clearance over the continuous motion through the sweep's poses (+ direction):
    the forward swing (before and past the disengage), the return swing, the power stroke."""
    cert = ExactCertificate()
    tp = rc.ToothPairs(g, push.tooth_pairs(g))
    fwd = _Stroke(tp, out_phis, out_travels, +1, "towing")
    phis = np.asarray(out_phis, dtype=float)
    if math.isfinite(disengage_rad) and phis.size and phis[0] < disengage_rad < phis[-1]:
        cut = int(np.searchsorted(phis, disengage_rad))  # the first pose past it
        cert.parts["forward"] = _certify_part(fwd, 0, cut, STROKES["forward"], cert.requirement)
        cert.parts["past"] = _certify_part(fwd, cut, len(phis) - 1, STROKES["past"], cert.requirement)
    else:
        cert.parts["forward"] = _certify_part(fwd, 0, len(phis) - 1, STROKES["forward"], cert.requirement)
    back = _Stroke(tp, back_phis, back_travels, -1, "towing")
    cert.parts["back"] = _certify_part(back, 0, len(back.samples) - 1, STROKES["back"], cert.requirement)
    travels = np.asarray(power_travels, dtype=float)
    angles = np.array([power_model_angle(g, float(t)) for t in travels])
    power = _Stroke(tp, angles, travels, -1, "power")
    cert.parts["power"] = _certify_part(power, 0, len(power.samples) - 1, STROKES["power"], cert.requirement)
    return cert


def where(g: RackPinionGeometry, part: PartCertificate) -> str:
    """Where a part's certified minimum lies, in words."""
    a, b = sorted(math.degrees(x) for x in part.between_rad)
    j, k = part.pair
    at = f"at {a:.3f}°" if f"{a:.3f}" == f"{b:.3f}" else f"between {a:.3f}° and {b:.3f}°"
    return f"{part.name}, {pinion_name(g, j)} against rack tooth k = {k}, {at}"


def summary_entry(g: RackPinionGeometry, part: PartCertificate, mesh_sampled_mm: float) -> dict:
    """One interference claim's figures: the exact model's certified least clearance and where (the
    interval, the pair: pinion tooth j, rack tooth k; ``where`` in words, not for summary.json),
    what the samples and the refinement measured, and the mesh sweep's least at its poses beside it."""
    return {"certified_min_mm": part.certified_min, "sampled_min_mm": part.sampled_min,
            "mesh_sampled_min_mm": mesh_sampled_mm, "requirement_mm": -EXACT_TOL_MM,
            "certified_min_between_deg": sorted(math.degrees(a) for a in part.between_rad),
            "certified_min_pinion_tooth": part.pair[0], "certified_min_rack_tooth": part.pair[1],
            "intervals": part.intervals, "intervals_refined": part.refined, "undecided_intervals": part.undecided,
            "intervals_with_motion_known": part.known_motion, "where": where(g, part)}
