"""Conjugate contact of the trimmed rack and pinion measured on their meshes (numpy only): where a
pinion flank, as its mesh outline has it, is tangent to a straight rack flank, and whether that
point lies on both real flanks. The contact intervals of :mod:`.rack_pinion_contact`, measured on
the swept poses instead of derived from the drawing.

Why positions and not the rack's lag: where one tooth pair's conjugate contact ends before the
next one's begins, the first pair's tip corner drags the rack on (corner contact) and the rack
falls behind r·φ only with the square of the overshoot — a 0.11° hand-over gap leaves it 0.09 µm
behind, a hundredth of the meshes' chord error. The contact *position* moves along the line of
action at the base radius per radian (≈ 1.3 mm per degree on the template), so where it leaves a
flank is decided to thousandths of a degree.

The tangency point: the mesh's flank vertices are exact points of the B-rep flank, so each flank
is read as the involute through them — its base radius and the angle where it leaves the base
circle fitted to the vertices (:func:`fit_involute`; the largest distance of a vertex from it is
reported, and must be nil: a flank that is not an involute of the pinion's axis shows there). On
an involute the tangent turns exactly with the roll angle, so the point where it is tangent to a
rack flank of a given direction is closed-form, and so are its distances along the line of action
to the tip corner and to the form-circle end (vertices of the mesh) — beyond them too, on the
involute's continuation, where the margin is negative. Interpolating the chord directions instead
cannot do this where a flank is short and its curvature changes fast (five 0.25–0.7 mm chords on a
small pinion near its base circle): there the tip-corner event came out 0.12° early.

Frames: the pinion outline in its own frame (centre at the origin, :func:`gearcheck.geometry.
rack_pinion.pinion_local_xy`); world poses as 2×2 rotations and translations given by the caller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A corner of the drawing is a vertex of the mesh within this (B-rep vertices are mesh vertices).
CORNER_MATCH_MM = 1e-6
# The four ends of a pair's conjugate contact (columns of :func:`pair_margins`).
MARGINS = ("rack_top", "rack_root", "pinion_tip", "pinion_form")


def mesh_vertex(points: np.ndarray, target, what: str = "corner") -> int:
    """Index of the vertex of ``points`` (n, 2) at ``target`` (a corner of the drawing): the mesh
    must have a vertex there (ValueError otherwise)."""
    d = np.hypot(points[:, 0] - target[0], points[:, 1] - target[1])
    i = int(np.argmin(d))
    if d[i] > CORNER_MATCH_MM:
        raise ValueError(f"the mesh has no vertex at the {what} ({target[0]:.6f}, {target[1]:.6f}); "
                         f"nearest {d[i]:.2e} mm away")
    return i


def flank_chain(profile: np.ndarray, corner, side: int, form_radius: float) -> np.ndarray:
    """One pinion flank on the mesh outline, from its form-circle end to its tip ``corner``
    (inner → corner, (m, 2)). ``profile``: the outline ordered by polar angle (own frame,
    :func:`gearcheck.mechanisms.steering.meshes.pinion_profile`); ``side`` +1: the right flank,
    which lies at larger polar angles than its tip corner, −1: the left flank."""
    i = mesh_vertex(profile, corner, "pinion tip corner")
    rho = np.hypot(profile[:, 0], profile[:, 1])
    step = 1 if side > 0 else -1
    idx = [i]
    while 0 <= idx[-1] + step < len(profile):
        nxt = idx[-1] + step
        if not (rho[nxt] < rho[idx[-1]] and rho[nxt] >= form_radius - CORNER_MATCH_MM):
            break
        idx.append(nxt)
    if len(idx) < 2:
        raise ValueError(f"pinion flank at ({corner[0]:.3f}, {corner[1]:.3f}) has no chord on the mesh")
    return profile[idx[::-1]]


def _polar(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(ρ, γ) about the pinion's axis, γ from straight down, counter-clockwise."""
    return np.hypot(points[:, 0], points[:, 1]), np.arctan2(points[:, 0], -points[:, 1])


def _inv_roll(base: float, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """inv α at radius ρ of an involute of ``base`` radius, and its derivative by the base radius."""
    u = np.sqrt(np.maximum(rho * rho / (base * base) - 1.0, 0.0))  # tan α
    inv = u - np.arctan(u)
    # d(inv α)/d base = tan²α · dα/d base, dα/d base = −1/(ρ·sin α) = −1/(base·tan α)
    return inv, -u / base


@dataclass(frozen=True)
class FlankInvolute:
    """The involute through one flank's mesh vertices (own frame): γ(ρ) = γ0 − side·inv α(ρ),
    cos α = base/ρ. A point at roll u (= tan α, negative on the continuation below the base circle)
    lies at ρ = base·√(1 + u²); its tangent points at γ0 − π/2 − side·u."""

    base_radius: float
    start_angle: float  # γ0: where the involute leaves the base circle
    side: int
    u_inner: float  # roll at the chain's inner end (form circle) and at its tip corner
    u_corner: float
    residual_mm: float  # the largest distance of a vertex from the involute (along the arc)

    def points(self, u: np.ndarray | float) -> np.ndarray:
        u = np.asarray(u, float)
        rho = self.base_radius * np.sqrt(1.0 + u * u)
        gamma = self.start_angle - self.side * (u - np.arctan(u))
        return np.stack([rho * np.sin(gamma), -rho * np.cos(gamma)], axis=-1)

    def tangency_roll(self, normals: np.ndarray) -> np.ndarray:
        """Roll u (P,) where the flank is tangent to lines of unit normal ``normals`` (P, 2, own
        frame): the tangent's direction is fixed modulo π, so u is the solution nearest the flank."""
        theta_n = np.arctan2(normals[:, 1], normals[:, 0])
        u = self.side * (self.start_angle - np.pi - theta_n)
        middle = 0.5 * (self.u_inner + self.u_corner)
        return u + np.pi * np.round((middle - u) / np.pi)


def _seed_base(chain: np.ndarray, rho: np.ndarray) -> float:
    """A first base radius for :func:`fit_involute`: from the curvature of the middle three vertices
    (ρ_c² = ρ² − base² on an involute), or with two vertices (a flank the mesher draws as one
    chord) from the chord's angle to the radius at its middle (on an involute the tangent meets the
    radius at the pressure angle there, cos α = base/ρ)."""
    top = float(rho.min())
    if len(chain) < 3:
        mid = 0.5 * (chain[0] + chain[-1])
        chord = chain[-1] - chain[0]
        rho_mid = float(np.linalg.norm(mid))
        cos_a = abs(float(chord @ mid)) / (float(np.linalg.norm(chord)) * rho_mid)
        return min(max(rho_mid * cos_a, 0.25 * top), top)
    m = len(chain) // 2
    a, b, c = chain[m - 1], chain[m], chain[m + 1]
    area2 = abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
    sides = np.linalg.norm(b - a) * np.linalg.norm(c - b) * np.linalg.norm(c - a)
    rho_c = sides / (2.0 * area2) if area2 > 0.0 else 0.0
    return float(np.sqrt(max(rho[m] ** 2 - rho_c ** 2, 0.25 * top * top)))


def fit_involute(chain: np.ndarray, side: int, iterations: int = 30) -> FlankInvolute:
    """The involute of the pinion's axis through the vertices of a flank ``chain`` (inner → tip
    corner, at least two vertices, own frame; ``side`` as :func:`flank_chain`): base radius and
    start angle by Gauss-Newton from :func:`_seed_base`. Two vertices (a short flank, e.g. a
    topped end tooth's just above the form circle, whose one chord sags less than the mesh's
    tolerance) determine the involute exactly: its residual is then nil by construction, and only
    the other flanks measure how far the mesh is from an involute."""
    rho, gamma = _polar(chain)
    if len(chain) < 2:
        raise ValueError("an involute needs at least two vertices of its flank")
    top = float(rho.min())
    base = _seed_base(chain, rho)
    for _ in range(iterations):
        base = min(base, top)
        inv, dinv = _inv_roll(base, rho)
        r = gamma + side * inv
        r -= r.mean()
        jac = side * (dinv - dinv.mean())
        jj = float(jac @ jac)
        if jj == 0.0:
            break
        step = float(jac @ r) / jj
        base = min(base - step, top)
        if abs(step) < 1e-13 * base:
            break
    inv, _ = _inv_roll(base, rho)
    start = float(np.mean(gamma + side * inv))
    residual = float(np.max(np.abs(gamma + side * inv - start) * rho))
    u = np.sqrt(np.maximum(rho * rho / (base * base) - 1.0, 0.0))
    return FlankInvolute(base, start, side, float(u[0]), float(u[-1]), residual)


def pair_margins(flank: FlankInvolute, rotations: np.ndarray, translations: np.ndarray, rack_top: np.ndarray,
                 rack_root: np.ndarray, travels: np.ndarray, rack_axis: np.ndarray) -> np.ndarray:
    """Margins (P, 4) of one tooth pair's conjugate contact at P poses, in mm, columns
    :data:`MARGINS`: positive when the tangency point of the pinion ``flank`` (fitted to its mesh
    vertices, own frame) with the rack flank from ``rack_root`` to ``rack_top`` (rack frame,
    travel 0) lies below the rack's top corner, above its root corner (along the rack flank),
    short of the pinion's tip corner and beyond its form-circle end (along the line of action: the
    roll times the base radius); contact is conjugate where all four are. Each moves linearly
    with the pinion angle, so a sign change between two poses is placed by linear interpolation.
    ``rotations`` (P, 2, 2) and ``translations`` (P, 2): pinion frame → world; the rack moves by
    ``travels`` (P,) along ``rack_axis`` (world, unit)."""
    up = np.asarray(rack_top, float) - np.asarray(rack_root, float)
    up /= np.linalg.norm(up)
    normal = np.array([-up[1], up[0]])  # either sense: the tangent's direction is fixed modulo π
    local = np.einsum("pji,j->pi", rotations, normal)  # the normal in the pinion's frame: Rᵀ·n
    u = flank.tangency_roll(local)
    points = flank.points(u)
    world = np.einsum("pij,pj->pi", rotations, points) + translations
    shift = np.asarray(travels, float)[:, None] * np.asarray(rack_axis, float)[:2][None, :]
    top = (np.asarray(rack_top, float)[None, :] + shift - world) @ up
    root = (world - np.asarray(rack_root, float)[None, :] - shift) @ up
    b = flank.base_radius  # the pinion margins along the line of action: base·roll, linear in the angle
    return np.stack([top, root, b * (flank.u_corner - u), b * (u - flank.u_inner)], axis=1)


def contact_run(angles: np.ndarray, margins: np.ndarray) -> tuple[float, float, int, int] | None:
    """The first run of conjugate contact along a swing: ``angles`` (P,, magnitudes increasing)
    and ``margins`` (P, 4) (NaN rows: not evaluated). Returns (start, end, the margin that starts
    it, the margin that ends it) with each end interpolated linearly between the two poses where
    the deciding margin changes sign; an end at the swing's first or last pose is that pose's angle
    and margin −1 (not crossed within the swing). None when no pose is in contact."""
    angles = np.asarray(angles, float)
    ok = np.all(np.isfinite(margins), axis=1)
    idx = np.flatnonzero(ok)
    if not idx.size:
        return None
    m = margins[idx]
    inside = np.all(m >= 0.0, axis=1)
    hits = np.flatnonzero(inside)
    if not hits.size:
        return None
    a = int(hits[0])
    after = np.flatnonzero(~inside[a:])
    b = a + int(after[0]) - 1 if after.size else len(idx) - 1

    def crossing(p_out: int, p_in: int) -> tuple[float, int]:
        """Where contact begins between a pose outside it and one inside: the crossing, nearest the
        pose inside, of the margins negative outside."""
        x_out, x_in = angles[idx[p_out]], angles[idx[p_in]]
        best, by = x_out, int(np.argmin(m[p_out]))
        for q in np.flatnonzero(m[p_out] < 0.0):
            y_out, y_in = m[p_out, q], m[p_in, q]
            x = x_out + (x_in - x_out) * (y_out / (y_out - y_in))
            if abs(x_in - x) < abs(x_in - best):
                best, by = x, int(q)
        return float(best), by

    start, by_start = crossing(a - 1, a) if a > 0 and idx[a - 1] == idx[a] - 1 else (float(angles[idx[a]]), -1)
    end, by_end = (crossing(b + 1, b) if b + 1 < len(idx) and idx[b + 1] == idx[b] + 1
                   else (float(angles[idx[b]]), -1))
    return start, end, by_start, by_end
