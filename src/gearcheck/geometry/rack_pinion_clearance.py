"""Exact signed clearance between a pinion tooth and a rack tooth of the trimmed rack and pinion,
in closed form (numpy only), and its lower bound over an interval of motion.

Directions are angles ψ in the frame's polar convention (:mod:`gearcheck.geometry.rack_pinion`):
the unit vector e(ψ) = (sin ψ, −cos ψ), straight down at ψ = 0; a point at radius ρ and polar
angle γ about the pinion centre O is O + ρ·e(γ).

**The pinion tooth** is its working profile (the convex contact polygon of
:meth:`RackPinionGeometry.pinion_contact_polygon_polar` without the polyline): two involutes from
the form circle to the tip, the tip land, and the chord across the form circle (the rack never
reaches inside the form circle). Its support function in a direction δ from the tooth's centre
line is, for |δ| (the tooth is symmetric):

* ``r_t`` on the tip land's normals, |δ| ≤ β_t (β the involute half angle);
* ``r_t·cos(|δ| − β_t)`` on the tip corner's normal cone, up to C − ε_t;
* ``r_b·(C − |δ|)`` on the involute's normals, up to C − ε_f (linear: the involute's normal at
  roll ε has direction C − ε and support r_b·ε, C = s/(2r) + inv α + π/2);
* ``r_f·cos(|δ| − β_f)`` on the form point's cone, to π (the chord's normal).

It never increases with |δ| on [0, π], and is C¹ except at |δ| = π (the chord); its second
derivative is 0 on the tip land and involute normals and at most the corner's radius on a corner's
cone.

**The signed clearance** sd of two convex sets A (pinion tooth), B (rack tooth: a trapezoid) is
the largest separation min_B e·b − max_A e·a over unit directions e: their distance when apart, less
their penetration depth when they overlap. The largest is attained at a normal of B's edges or at a
direction in which one of B's vertices q is closest to A: a stationary direction of
e(ψ)·q − h_A(ψ) on one piece of A's support function (the radial direction through q on the tip
land, the tangents from q to the base circle on the involutes, the direction from a corner to q on
a corner's cone) or a piece's end. :func:`signed_clearance` evaluates every such candidate and
takes the largest: every candidate is a true separation (a lower bound), and the set holds the
maximiser, so the value is exact.

**Over an interval** of pinion angle [φa, φb] the separation in one direction e fixed in the
world is a function of φ, e_x·L(φ) − h_A(ψ_e − θ(φ)) + const: with L(φ) linear (the rack standing,
or driven in conjugate mesh) its second derivative is −h_A'' (|·| ≤ M, the largest curvature of
the pieces the direction sweeps), so it is no lower than min(sep(φa), sep(φb)) − M·Δφ²/8
(:func:`fixed_direction_bound`). On the tip land and the involutes M = 0: the conjugate pair's
separation is exactly linear, constant in conjugate mesh, which no path bound can show.
"""

from __future__ import annotations

import math
import numpy as np

from gearcheck.geometry.involute import inv
from gearcheck.geometry.rack_pinion import RackPinionGeometry


def direction(psi) -> np.ndarray:
    """Unit vectors e(ψ) = (sin ψ, −cos ψ); shape (..., 2)."""
    psi = np.asarray(psi, dtype=float)
    return np.stack([np.sin(psi), -np.cos(psi)], axis=-1)


def angle_of(vec) -> np.ndarray:
    """ψ with e(ψ) along ``vec`` (..., 2)."""
    vec = np.asarray(vec, dtype=float)
    return np.arctan2(vec[..., 0], -vec[..., 1])


def wrapped(delta) -> np.ndarray:
    """An angle brought into (−π, π]."""
    return np.pi - np.mod(np.pi - np.asarray(delta, dtype=float), 2.0 * np.pi)


class ToothPairs:
    """Pinion teeth j against rack teeth k, pair by pair (arrays over the pairs, the last axis but
    one of every result): each tooth's support function, each rack tooth's vertices and edges."""

    def __init__(self, g: RackPinionGeometry, pairs: list[tuple[int, int]]):
        self.g, self.pairs = g, list(pairs)
        rb = g.base_radius
        self.r_base = rb
        self.c = g.pinion_pitch_thickness / (2.0 * g.pitch_radius) + inv(g.pressure_angle_rad) + math.pi / 2.0
        r_tip = np.array([g.pinion_tip_radius(j) for j, _ in self.pairs])
        r_form = max(g.form_radius, rb)
        self.r_tip = r_tip[:, None]
        self.beta_tip = np.asarray(g.involute_half_angle(r_tip), dtype=float)[:, None]
        self.r_form = r_form
        self.beta_form = float(g.involute_half_angle(r_form))
        self.tip_end = self.c - np.sqrt(np.maximum(self.r_tip ** 2 / rb ** 2 - 1.0, 0.0))
        self.form_end = self.c - math.sqrt(max(r_form ** 2 / rb ** 2 - 1.0, 0.0))
        self.theta0 = np.array([(j + 0.5) * g.angular_pitch for j, _ in self.pairs])
        self.vertices = np.array([g.rack_tooth_polygon(k, 0.0) for _, k in self.pairs]).reshape(-1, 4, 2)
        d = np.roll(self.vertices, -1, axis=1) - self.vertices
        self.edges = angle_of(-np.stack([d[..., 1], -d[..., 0]], axis=-1))  # (P, 4): across each edge, inwards
        # circles holding each pinion tooth (about a point on its centre line) and each rack tooth
        self.hub = 0.5 * (self.r_form + self.r_tip[:, 0])
        corners = [(self.r_tip[:, 0], self.beta_tip[:, 0]), (np.full(len(self.pairs), self.r_form),
                                                              np.full(len(self.pairs), self.beta_form))]
        self.hub_radius = np.max([np.hypot(r * np.sin(b), r * np.cos(b) - self.hub) for r, b in corners], axis=0)
        self.rack_centre = self.vertices.mean(axis=1)
        self.rack_radius = np.linalg.norm(self.vertices - self.rack_centre[:, None], axis=-1).max(axis=1)
        self._taken: dict[tuple[int, ...], ToothPairs] = {}

    def take(self, index) -> ToothPairs:
        """The pairs ``index`` alone (kept: the same subsets come back interval after interval)."""
        key = tuple(int(i) for i in index)
        if key not in self._taken:
            self._taken[key] = ToothPairs(self.g, [self.pairs[i] for i in key])
        return self._taken[key]

    def apart(self, phi, travel) -> np.ndarray:
        """A lower bound (..., P) of each pair's signed clearance: the gap between the circles that
        hold the two teeth."""
        centre = np.array([0.0, self.g.centre_height]) + self.hub[:, None] * direction(self.theta(phi))
        rack = self.rack_centre + np.stack([np.asarray(travel, dtype=float), np.zeros_like(travel)],
                                           axis=-1)[..., None, :]
        return np.linalg.norm(centre - rack, axis=-1) - self.hub_radius - self.rack_radius

    def theta(self, phi) -> np.ndarray:
        """Each pair's tooth centre line at pinion angles φ (...): (..., P)."""
        return np.asarray(phi, dtype=float)[..., None] + self.theta0

    # --- the pinion tooth's support function (module doc), params broadcast over (..., P, n) ----
    def h(self, delta) -> np.ndarray:
        """Support (mm from the pinion centre) in the direction δ (..., P, n) from each centre line."""
        a = np.abs(wrapped(delta))
        return np.where(a <= self.beta_tip, self.r_tip,
                        np.where(a <= self.tip_end, self.r_tip * np.cos(a - self.beta_tip),
                                 np.where(a <= self.form_end, self.r_base * (self.c - a),
                                          self.r_form * np.cos(a - self.beta_form))))

    def slope(self, delta) -> np.ndarray:
        """dh/dδ, continuous across the pieces (h is C¹ but at |δ| = π)."""
        d = wrapped(delta)
        a, sign = np.abs(d), np.where(d >= 0.0, 1.0, -1.0)
        return -sign * np.where(a <= self.beta_tip, 0.0,
                                np.where(a <= self.tip_end, self.r_tip * np.sin(a - self.beta_tip),
                                         np.where(a <= self.form_end, self.r_base,
                                                  self.r_form * np.sin(a - self.beta_form))))

    def piece(self, delta) -> np.ndarray:
        """Which piece supports direction δ: 0 tip land, 1 tip corner, 2 involute, 3 form point."""
        a = np.abs(wrapped(delta))
        return np.where(a <= self.beta_tip, 0, np.where(a <= self.tip_end, 1, np.where(a <= self.form_end, 2, 3)))

    def concavity(self, d0, d1) -> np.ndarray:
        """A bound of max(h'', 0) over the directions between δ = d0 and d1 (the shorter way round):
        h'' ≤ 0 on the corners' cones facing out (h = ρ·cos, within π/2 of the corner), 0 on the
        tip land and the involutes, up to r_f on the form point's cone facing back; inf where the
        range holds |δ| = π (the chord's kink)."""
        d0, d1 = wrapped(d0), wrapped(d1)
        lo, hi = np.minimum(d0, d1), np.maximum(d0, d1)
        across = hi - lo > math.pi
        a_hi = np.maximum(np.abs(lo), np.abs(hi))
        return np.where(across, np.inf, np.where(a_hi > self.beta_form + math.pi / 2.0, self.r_form, 0.0))

    def support_point(self, phi, delta) -> np.ndarray:
        """World point (..., P, 2) of each tooth that supports direction δ (..., P) from its centre
        line (a corner's cone: the corner; the involute's normals: the involute point)."""
        piece = self.piece(np.asarray(delta)[..., None])[..., 0]
        side = np.where(wrapped(delta) >= 0.0, 1.0, -1.0)
        r_tip, b_tip = self.r_tip[:, 0], self.beta_tip[:, 0]
        eps = np.clip(self.c - np.abs(wrapped(delta)), 0.0, None)
        rho_inv = self.r_base * np.sqrt(1.0 + eps * eps)
        rho = np.where(piece <= 1, r_tip, np.where(piece == 2, rho_inv, self.r_form))
        beta = np.where(piece <= 1, b_tip, np.where(piece == 2, self.g.involute_half_angle(rho_inv), self.beta_form))
        rel = np.where(piece == 0, wrapped(delta), side * beta)
        return np.array([0.0, self.g.centre_height]) + rho[..., None] * direction(self.theta(phi) + rel)

    # --- separations -----------------------------------------------------------------------
    def separation(self, phi, travel, psi, corners=(0, 1, 2, 3)) -> np.ndarray:
        """min over each rack tooth's vertices of e·b − max over its pinion tooth of e·a, in the
        directions ``psi`` (..., P, n), pinion angles φ and travels L (...): a lower bound of each
        pair's signed clearance, equal to it in the maximising direction. ``corners``: those of
        the rack tooth's vertices alone (an edge: its two ends)."""
        psi = np.asarray(psi, dtype=float)
        e = direction(psi)
        travel = np.asarray(travel, dtype=float)[..., None, None]
        v = self.vertices[:, list(corners)]
        vx, vy = v[:, None, :, 0], v[:, None, :, 1]  # (P, 1, m)
        rack = np.min(e[..., 0, None] * vx + e[..., 1, None] * vy, axis=-1) + e[..., 0] * travel
        return rack - self.g.centre_height * e[..., 1] - self.h(psi - self.theta(phi)[..., None])

    def candidates(self, phi, travel) -> np.ndarray:
        """Directions ψ (..., P, 38) among which each pair's signed clearance is attained."""
        theta = self.theta(phi)[..., None]  # (..., P, 1)
        travel = np.asarray(travel, dtype=float)[..., None, None]
        qx = self.vertices[..., 0] + travel  # (..., P, 4)
        qy = np.broadcast_to(self.vertices[..., 1], qx.shape)
        rel = np.stack([qx, qy - self.g.centre_height], axis=-1)
        rho = np.hypot(rel[..., 0], rel[..., 1])
        gam = angle_of(rel)
        tangent = np.arcsin(np.clip(self.r_base / rho, -1.0, 1.0))
        cands = [np.broadcast_to(self.edges, qx.shape), gam, gam + tangent, gam - tangent]
        for r_c, b_c in ((self.r_tip, self.beta_tip), (self.r_tip, -self.beta_tip),
                         (self.r_form, self.beta_form), (self.r_form, -self.beta_form)):
            corner = np.asarray(r_c)[..., None] * direction(theta + b_c)  # (..., P, 1, 2)
            cands.append(angle_of(rel - corner))
        breaks = np.concatenate([s * d for d in (self.beta_tip, self.tip_end, np.full_like(self.beta_tip,
                                                                                             self.form_end))
                                 for s in (1.0, -1.0)], axis=-1)  # (P, 6)
        cands.append(theta + breaks)
        return np.concatenate(cands, axis=-1)

    def signed_clearance(self, phi, travel) -> tuple[np.ndarray, np.ndarray]:
        """Each pair's exact signed clearance (mm: distance apart, less the penetration depth where
        they overlap) at pinion angles φ and travels L (...), and the direction ψ attaining it:
        two arrays (..., P)."""
        psi = self.candidates(phi, travel)
        sep = self.separation(phi, travel, psi)
        i = np.argmax(sep, axis=-1)[..., None]
        return np.take_along_axis(sep, i, -1)[..., 0], np.take_along_axis(psi, i, -1)[..., 0]

    def fixed_direction_bound(self, phi0, phi1, travel0, travel1, psi, rate0=0.0, rate1=0.0, travel_curvature=0.0,
                              corners=(0, 1, 2, 3)) -> np.ndarray:
        """The least separation in world directions ψ (..., P, n) over pinion angles [φ0, φ1] while
        the travel runs from L0 to L1, dL/dφ = ``rate0``, ``rate1`` at the ends, |L''| ≤
        ``travel_curvature`` (0: standing, or linear in φ). The separation f(φ) = e_x·L(φ) −
        h(ψ − θ(φ)) + const has f'' ≥ −K, K = max(h'') + |e_x|·|L''| (the support is concave on
        the corners' cones, linear on the tip land and the involutes: K = 0 in a stand or conjugate
        mesh, where f is convex): :func:`envelope_least`. φ0, φ1, L0, L1, the rates and the
        curvature shaped (...); ``corners`` as :meth:`separation`."""
        f0 = self.separation(phi0, travel0, psi, corners)
        f1 = self.separation(phi1, travel1, psi, corners)
        ex = np.sin(psi)
        d0 = ex * np.asarray(rate0, dtype=float)[..., None, None] + self.slope(psi - self.theta(phi0)[..., None])
        d1 = ex * np.asarray(rate1, dtype=float)[..., None, None] + self.slope(psi - self.theta(phi1)[..., None])
        k = (np.abs(ex) * np.asarray(travel_curvature, dtype=float)[..., None, None]
             + self.concavity(psi - self.theta(phi0)[..., None], psi - self.theta(phi1)[..., None]))
        span = (np.asarray(phi1, dtype=float) - np.asarray(phi0, dtype=float))[..., None, None]
        return envelope_least(f0, f1, d0, d1, k, span)

    def travel_driven_bound(self, phi0, phi1, travel0, travel1, psi, turn0, turn1, turn_max, bend_max,
                            corners=(0, 1, 2, 3)) -> np.ndarray:
        """:meth:`fixed_direction_bound` with the travel as the parameter, the pinion angle following
        it: dφ/dL = ``turn0``, ``turn1`` at the ends, |dφ/dL| ≤ ``turn_max`` and |d²φ/dL²| ≤
        ``bend_max`` over the interval. f(L) = e_x·L − h(δ(L)) + const: f' = e_x + h'·φ', f'' =
        −h''·φ'² + h'·φ'' ≥ −(max(h'')·turn_max² + |h'|·bend_max), |h'| ≤ r_tip."""
        f0 = self.separation(phi0, travel0, psi, corners)
        f1 = self.separation(phi1, travel1, psi, corners)
        ex = np.sin(psi)
        sign = np.sign(np.asarray(travel1, dtype=float) - np.asarray(travel0, dtype=float))[..., None, None]
        d0 = sign * (ex + self.slope(psi - self.theta(phi0)[..., None]) * np.asarray(turn0)[..., None, None])
        d1 = sign * (ex + self.slope(psi - self.theta(phi1)[..., None]) * np.asarray(turn1)[..., None, None])
        k = (self.concavity(psi - self.theta(phi0)[..., None], psi - self.theta(phi1)[..., None])
             * np.asarray(turn_max, dtype=float)[..., None, None] ** 2
             + self.r_tip * np.asarray(bend_max, dtype=float)[..., None, None])
        span = np.abs(np.asarray(travel1, dtype=float) - np.asarray(travel0, dtype=float))[..., None, None]
        return envelope_least(f0, f1, d0, d1, k, span)


def envelope_least(f0, f1, d0, d1, k, span) -> np.ndarray:
    """The least a function f on [0, span] can take with f(0) = f0, f(span) = f1, slopes d0, d1
    there and f'' ≥ −k: f lies above both f0 + d0·t − k·t²/2 and f1 − d1·(span − t) − k·(span − t)²/2,
    and the least of their upper envelope lies at an end or where they cross (their difference is
    linear in t). −inf where k is not finite."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        gap = f0 - f1 + d1 * span + 0.5 * k * span * span
        turn = d0 - d1 - k * span
        t = np.where(turn != 0.0, -gap / turn, -1.0)
        inside = (t > 0.0) & (t < span)
        cross = np.where(inside, f0 + d0 * t - 0.5 * k * t * t, np.inf)
    least = np.minimum(np.minimum(f0, f1), cross)
    return np.where(np.isfinite(k), least, -np.inf)


def signed_clearance(g: RackPinionGeometry, j: int, k: int, phi, travel) -> tuple[np.ndarray, np.ndarray]:
    """:meth:`ToothPairs.signed_clearance` of one pair: arrays shaped like φ and L broadcast."""
    sd, psi = ToothPairs(g, [(j, k)]).signed_clearance(phi, travel)
    return sd[..., 0], psi[..., 0]
