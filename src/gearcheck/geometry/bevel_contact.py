"""First contact of straight bevel pairs with exact spherical-involute flanks, vectorised over
many pairs (numpy only): the solver behind :func:`gearcheck.geometry.bevel_play.big_gear_contacts`.

A point p of one gear's flank reaches the other gear's flank cone at the turn δ(p) of the big
gear where its signed distance d(p, δ) to that cone (closed form, the one of
:func:`gearcheck.geometry.bevel.minus_flank_signed`) is zero; d is smooth and nearly linear in δ,
so a secant solve per point converges in a few steps. The contact is the extreme δ(p) over both
flank surfaces — samples of the big gear's flank against the small gear's cone and samples of
the small gear's flank against the big gear's cone — keeping only roots where the point then lies
inside the other gear's tooth zone (between its root and tip cones and its front and back
cones). Using both surfaces catches edge contacts (an edge of one gear against the face of the
other, the usual contact once the apexes are displaced). The samples are ranked by a one-step
estimate; the best are refined on a shrinking local grid of the flank parameters and solved.

Arrays: a batch holds N pairs of the same two designs, each with its own relative pose, scales
and way of turning (±1: the side of the flanks that close). Points are kept as three coordinate
arrays (x, y, z) of the same shape, never as (…, 3) stacks: every elementwise operation then runs
over one contiguous array (a trailing axis of 3 makes numpy's inner loops three elements long).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bevel import BevelGearSpec, flank_azimuth, involute_azimuth, line_of_action

# Flank sampling: polar angle root → tip (uniform), and toe → heel along the rulings (uniform).
# Coarse on purpose: the samples only rank candidates; the refinement below finds the extreme.
PROFILE_SAMPLES = 28
RULING_SAMPLES = 5
# Teeth sampled on either side of the mesh zone: the longer reach of the path of contact from
# the pitch point, in pitches, rounded up, plus one (non-conjugate meshes close up the
# neighbours), at least MIN_TEETH_WINDOW (see teeth_window; the template: 0.95 pitches → 2). A
# contact found on the outermost sampled tooth still widens the window by one and solves
# again, up to MAX_TEETH_WINDOW, beyond which it raises.
MIN_TEETH_WINDOW = 2
MAX_TEETH_WINDOW = 8
# Secant solve of d(p, δ) = 0 per point: first step, iterations, convergence on the distance.
SECANT_FIRST_STEP_RAD = 1e-3
SECANT_ITERATIONS = 8
ROOT_TOL_MM = 1e-10
# A root beyond this turn belongs to another tooth pair, not to this contact (69′).
MAX_CONTACT_ANGLE_RAD = 0.02
# Local refinement of the best samples: levels (the cell halves each level, so an edge–edge
# contact cut off by the other gear's zone boundary is located to 1/64 of a sample cell), grid
# points per parameter and level, how many candidates (separate local extremes) per flank set.
REFINE_LEVELS = 6
REFINE_GRID = 5
REFINE_CANDIDATES = 2
# Points of a flank at the other gear's zone boundary count as inside within this (mm / rad).
ZONE_TOL = 1e-9
# The zone test that rules flank samples out before their distances are taken is this much wider
# than the one that rules on roots (rad / mm): rounding can never drop a sample the latter keeps.
ZONE_PREFILTER_TOL = 1e-7
# Pairs per vectorised batch (each way of turning a pair counts once): the refinement and the
# roots of a batch share each array (fewer, longer numpy calls); the flank samples go through
# GRID_PAIRS pairs at a time (longer arrays fall out of the cache and run slower).
BATCH_PAIRS = 1024
GRID_PAIRS = 48

Xyz = tuple[np.ndarray, np.ndarray, np.ndarray]


# -- one flank -----------------------------------------------------------------------------
@dataclass(frozen=True)
class _Flank:
    """One gear design's constants for the hot loops (worked out once per design)."""

    base: float  # δb
    sin_base: float
    cos_base: float
    tan_base: float
    start: float  # azimuth of tooth 0's −flank's involute start (its base point)
    half: float  # half the tooth's azimuth on the pitch cone + inv(δ): flank azimuth = side·(half − inv(θ))
    pitch: float  # angular pitch
    root: float
    face: float
    pitch_angle: float
    cos_pitch: float
    sin_pitch: float
    inner: float  # cone distances
    outer: float


@functools.lru_cache(maxsize=64)
def flank_constants(spec: BevelGearSpec) -> _Flank:
    db = spec.base_angle_rad
    half = spec.pitch_thickness_angle_rad / 2 + float(involute_azimuth(db, spec.pitch_angle_rad))
    return _Flank(db, math.sin(db), math.cos(db), math.tan(db), float(flank_azimuth(spec, db, -1)), half,
                  spec.angular_pitch_rad, spec.root_angle_rad, spec.face_angle_rad, spec.pitch_angle_rad,
                  math.cos(spec.pitch_angle_rad), math.sin(spec.pitch_angle_rad), spec.inner_cone_distance_mm,
                  spec.outer_cone_distance_mm)


def _involute(f: _Flank, theta: np.ndarray) -> np.ndarray:
    """inv(θ) of the basic spherical involute for θ ≥ δb (radial below): with s the arc rolled off
    (tan s = √(sin²θ − sin²δb) / cos θ), φ = s / sin δb and inv = φ − atan(tan s / sin δb)
    (:func:`gearcheck.geometry.bevel.involute_azimuth`, one arctan2 fewer)."""
    theta = np.maximum(theta, f.base)
    root = np.sqrt(np.maximum(np.sin(theta - f.base) * np.sin(theta + f.base), 0.0))
    c = np.cos(theta)
    return np.arctan2(root, c) / f.sin_base - np.arctan2(root, c * f.sin_base)


def flank_xyz(spec: BevelGearSpec, scale, tooth, side, profile, ruling) -> Xyz:
    """Points, gear frame, of tooth ``tooth``'s flank ``side`` at parameters profile ∈ [0, 1]
    (polar angle root cone → tip cone) and ruling ∈ [0, 1] (front cone → back cone), broadcast."""
    f = flank_constants(spec)
    theta = f.root + np.asarray(profile, float) * (f.face - f.root)
    az = side * (f.half - _involute(f, theta)) + np.asarray(tooth, float) * f.pitch
    r = scale * (f.inner + np.asarray(ruling, float) * (f.outer - f.inner)) / np.cos(theta - f.pitch_angle)
    st = r * np.sin(theta)
    x, y, z = st * np.cos(az), st * np.sin(az), r * np.cos(theta)
    return np.broadcast_arrays(x, y, z)  # type: ignore[return-value]


def signed_to_flank(spec: BevelGearSpec, x, y, z, tooth, side) -> np.ndarray:
    """Signed distance (mm, + outside the tooth) of points (gear frame) from the flank ``side``
    (±1, or one per point) of the given teeth (one per point), extended over the whole cone: the
    closed form of :func:`gearcheck.geometry.bevel.minus_flank_signed` (side +1 is the mirror
    image of side −1 in the xz-plane) in the point's cylindrical coordinates, without turning
    the points to tooth 0 (the same figures to rounding; a test holds them together)."""
    f = flank_constants(spec)
    rho = np.sqrt(x * x + y * y)  # (np.hypot is an order slower)
    r = np.sqrt(rho * rho + z * z)
    a = -side * (np.arctan2(y, x) - tooth * f.pitch) - f.start
    a = a - (2.0 * math.pi) * np.round(a / (2.0 * math.pi))  # (−π, π]: the point's azimuth from the start
    with np.errstate(divide="ignore", invalid="ignore"):
        s = rho / r
        root = np.sqrt(np.maximum((s - f.sin_base) * (s + f.sin_base), 0.0))  # √(sin²θ − sin²δb)
        cos_t = z / r
    beta = np.arctan2(root / f.cos_base, f.tan_base * cos_t)
    sigma = np.arctan2(root, cos_t)
    out = r * np.sin(sigma - (a + beta) * f.sin_base)
    above = rho * f.cos_base - z * f.sin_base >= 0.0  # θ ≥ δb: the closed form
    if not above.all():  # below the base cone: the distance to the meridian half-plane
        out = np.where(above, out, rho * np.sin(-a))
    return out


def in_tooth_zone(spec: BevelGearSpec, scale, x, y, z, tol: float = 0.0, along_tol=0.0) -> np.ndarray:
    """Points (gear frame) between the root and tip cones and between the front and back cones of
    a gear scaled by ``scale`` (broadcast): only there can a point be inside a tooth (under the
    root cone is the blank: tip–root clearance is 0.25·m, far beyond any displacement studied).
    ``tol`` / ``along_tol`` widen the zone (rad / mm, on top of ZONE_TOL)."""
    f = flank_constants(spec)
    rho = np.sqrt(x * x + y * y)
    theta = np.arctan2(rho, z)
    along = rho * f.sin_pitch + z * f.cos_pitch  # r·cos(θ − δ)
    t_tol, a_tol = ZONE_TOL + tol, ZONE_TOL + along_tol
    return ((theta >= f.root - t_tol) & (theta <= f.face + t_tol)
            & (along >= scale * f.inner - a_tol) & (along <= scale * f.outer + a_tol))


def zone_excess(spec: BevelGearSpec, scale, x, y, z) -> np.ndarray:
    """How far (mm) points (gear frame) lie outside the tooth zone of :func:`in_tooth_zone`: along
    the face beyond the front or back cone, and across it beyond the tip or root cone (the arc at
    the point's radius), combined as one distance (0 inside). With a point's distance d to a
    flank's cone, √(d² + excess²) is its distance to the flank bounded by the zone, to first order:
    a point beyond the flank's edge is that far from the edge."""
    f = flank_constants(spec)
    rho = np.sqrt(x * x + y * y)
    r = np.sqrt(rho * rho + z * z)
    theta = np.arctan2(rho, z)
    along = rho * f.sin_pitch + z * f.cos_pitch
    beyond_along = np.maximum(np.maximum(scale * f.inner - along, along - scale * f.outer), 0.0)
    beyond_height = r * np.maximum(np.maximum(theta - f.face, f.root - theta), 0.0)
    return np.sqrt(beyond_along * beyond_along + beyond_height * beyond_height)


def facing_tooth(spec: BevelGearSpec, x, y, side) -> np.ndarray:
    """Index of the tooth whose flank ``side`` faces each point: the tooth space on side s of
    tooth k is centred at azimuth k·p + s·p/2."""
    pitch = spec.angular_pitch_rad
    return np.round((np.arctan2(y, x) - side * pitch / 2.0) / pitch)


def teeth_window(big: BevelGearSpec, small: BevelGearSpec) -> int:
    """Teeth on either side of the mesh zone that the contact can reach (both gears)."""
    path = line_of_action(big, small)
    reach = max(path.pitch_arc - path.start_arc, path.end_arc - path.pitch_arc) / path.base_pitch_arc
    return min(max(MIN_TEETH_WINDOW, math.ceil(reach) + 1), MAX_TEETH_WINDOW)


# -- moving points -------------------------------------------------------------------------
class _Mover:
    """Points of one flank set in the other gear's frame as the big gear turns by δ: ``mover(δ)``.
    The parts that do not depend on δ are worked out once: when this gear is the big one,
    R·Rz(δ)·p = cos δ·R(p − p_z ẑ) + sin δ·R(ẑ × p) + p_z·R ẑ + t; when the other is, its turn is
    undone about its own z. ``take(index)`` keeps some points (flattened)."""

    def __init__(self, parts: tuple[Xyz, ...]):
        self.parts = parts

    @classmethod
    def of(cls, fs: _FlankSet, p: Xyz) -> _Mover:
        px, py, pz = p
        r, t = fs.coef, fs.shift  # r[i][j]: component j of this frame's axis i in the other's; (N, 1) each
        if fs.big:
            return cls((tuple(px * r[0][j] + py * r[1][j] for j in range(3)),
                        tuple(px * r[1][j] - py * r[0][j] for j in range(3)),
                        tuple(pz * r[2][j] + t[j] for j in range(3))))
        return cls((tuple(px * r[0][j] + py * r[1][j] + pz * r[2][j] + t[j] for j in range(3)),))

    def take(self, index) -> _Mover:
        return _Mover(tuple(tuple(c[index] for c in part) for part in self.parts))

    def __call__(self, delta) -> Xyz:
        delta = np.asarray(delta, float)
        if len(self.parts) == 1:
            x, y, z = self.parts[0]
            if delta.ndim == 0 and delta == 0.0:
                return x, y, z
            c, s = np.cos(delta), np.sin(delta)
            return c * x + s * y, c * y - s * x, z
        flat, cross, axial = self.parts
        if delta.ndim == 0:
            c, s = math.cos(delta), math.sin(delta)
        else:
            c, s = np.cos(delta), np.sin(delta)
        return tuple(c * flat[j] + s * cross[j] + axial[j] for j in range(3))


class _FlankSet:
    """Points of one gear's flank (each pair's side) that move, as the big gear turns by δ,
    against the other gear's flank cone of the same side. Batched: N pairs; every array of
    points or parameters has the shape (N, K): K points of pair n in row n."""

    def __init__(self, spec: BevelGearSpec, other_spec: BevelGearSpec, this_is_big: bool, relative: np.ndarray,
                 scale: np.ndarray, other_scale: np.ndarray, side: np.ndarray, window: int):
        self.spec, self.other_spec, self.big = spec, other_spec, this_is_big
        self.side = np.asarray(side, float).reshape(-1, 1)  # ±1 per pair
        rot = relative[:, :3, :3]  # this frame → other frame
        self.coef = [[rot[:, j, i, None] for j in range(3)] for i in range(3)]
        self.shift = [relative[:, j, 3, None] for j in range(3)]
        self.scale = np.asarray(scale, float).reshape(-1, 1)
        self.other_scale = np.asarray(other_scale, float).reshape(-1, 1)
        axis = relative[:, 2, :3]  # the other gear's axis in this frame (row 2 of the rotation)
        centre = np.round(np.arctan2(axis[:, 1], axis[:, 0]) / spec.angular_pitch_rad)
        self.teeth = centre[:, None] + np.arange(-window, window + 1)[None, :]

    def rows(self, part: slice) -> _FlankSet:
        """The same set for a slice of its pairs (views, no copies)."""
        sub = object.__new__(_FlankSet)
        sub.spec, sub.other_spec, sub.big = self.spec, self.other_spec, self.big
        sub.side, sub.scale, sub.other_scale, sub.teeth = (self.side[part], self.scale[part], self.other_scale[part],
                                                           self.teeth[part])
        sub.coef = [[c[part] for c in row] for row in self.coef]
        sub.shift = [c[part] for c in self.shift]
        return sub

    def points(self, tooth, profile, ruling) -> Xyz:
        return flank_xyz(self.spec, self.scale, tooth, self.side, profile, ruling)

    def grid_points(self, profile: np.ndarray, ruling: np.ndarray) -> Xyz:
        """The flank points of every window tooth of every pair on a grid of profile × ruling
        parameters, (N, teeth·profile·ruling) each, as :meth:`points` gives them, with the
        polar-angle terms worked out once per profile value rather than once per point."""
        f = flank_constants(self.spec)
        theta = f.root + profile * (f.face - f.root)
        az = self.side[:, :, None] * (f.half - _involute(f, theta))[None, None, :] + self.teeth[:, :, None] * f.pitch
        rr = (f.inner + ruling * (f.outer - f.inner))[None, :] / np.cos(theta - f.pitch_angle)[:, None]
        rr = self.scale[:, :, None, None] * rr[None, None]  # (N, 1, profile, ruling)
        st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
        n = az.shape[0]
        shape = (*az.shape, len(ruling))
        x = rr * (st * np.cos(az)[..., None])
        y = rr * (st * np.sin(az)[..., None])
        z = np.broadcast_to(rr * ct, shape)
        return x.reshape(n, -1), y.reshape(n, -1), np.ascontiguousarray(z).reshape(n, -1)

    def mover(self, p: Xyz) -> _Mover:
        return _Mover.of(self, p)

    def estimate(self, p: Xyz, direction, all_points: bool = False) -> np.ndarray:
        """One secant step from δ = 0: the turn at which each point would reach the other gear's
        flank cone (d is nearly linear in δ); ±inf where it cannot (moving away, out of the
        other's tooth zone or beyond MAX_CONTACT_ANGLE_RAD). For ranking samples. Unless
        ``all_points``, only the points that :meth:`_may_touch` are tried (flank samples: most
        lie far from the mesh)."""
        at = self.mover(p)
        q0 = at(0.0)
        shape = q0[0].shape
        way = np.broadcast_to(direction, shape)
        side = np.broadcast_to(self.side, shape)
        other_scale = np.broadcast_to(self.other_scale, shape)
        if all_points:
            return self._estimate(at, q0, way, side, other_scale)
        out = np.full(shape, np.inf) * way
        index = np.nonzero(self._may_touch(p, q0))
        if index[0].size:
            out[index] = self._estimate(at.take(index), tuple(c[index] for c in q0), way[index],  # type: ignore[arg-type]
                                        side[index], other_scale[index])
        return out

    def _estimate(self, at: _Mover, q0: Xyz, way: np.ndarray, side: np.ndarray, other_scale) -> np.ndarray:
        facing = facing_tooth(self.other_spec, q0[0], q0[1], side)
        step = way * SECANT_FIRST_STEP_RAD
        d0 = signed_to_flank(self.other_spec, *q0, facing, side)
        d1 = signed_to_flank(self.other_spec, *at(step), facing, side)
        slope = (d1 - d0) / step
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(way * slope < 0.0, -d0 / slope, np.nan)
        ok = np.isfinite(delta) & (np.abs(delta) < MAX_CONTACT_ANGLE_RAD)
        delta = np.where(ok, delta, 0.0)
        ok &= in_tooth_zone(self.other_spec, other_scale, *at(delta))
        return np.where(ok, delta, way * np.inf)

    def _may_touch(self, p: Xyz, q0: Xyz) -> np.ndarray:
        """Points that may lie in the other gear's tooth zone after a turn of at most
        MAX_CONTACT_ANGLE_RAD (a root elsewhere does not count). When the other gear is the big
        one it turns about its own axis and its zone is round about it: the zone now is the zone
        then (with a margin for rounding). When this gear turns, a point moves by at most |p|·|δ|
        and its polar angle about the other's axis by at most |δ|: the zone widened by that,
        twice over."""
        if not self.big:
            return in_tooth_zone(self.other_spec, self.other_scale, *q0, tol=ZONE_PREFILTER_TOL)

        def norm(v: Xyz) -> np.ndarray:
            return np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])

        widen = 2.0 * MAX_CONTACT_ANGLE_RAD
        return in_tooth_zone(self.other_spec, self.other_scale, *q0, tol=widen, along_tol=widen * (norm(p) + norm(q0)))

    def roots(self, tooth, profile, ruling, direction) -> np.ndarray:
        """Turn δ (rad) at which each point reaches the other gear's flank cone inside its tooth
        zone (secant solve to ROOT_TOL_MM; a converged point stays put); ±inf (sign of
        direction) where there is none within MAX_CONTACT_ANGLE_RAD."""
        at = self.mover(self.points(tooth, profile, ruling))
        q0 = at(0.0)
        shape = q0[0].shape
        side = np.broadcast_to(self.side, shape)
        facing = facing_tooth(self.other_spec, q0[0], q0[1], side)

        def dist(delta):
            return signed_to_flank(self.other_spec, *at(delta), facing, side)

        a = np.zeros(shape)
        fa = dist(a)
        b = np.full(shape, direction * SECANT_FIRST_STEP_RAD)
        fb = dist(b)
        slope = (fb - fa) / (b - a)
        for _ in range(SECANT_ITERATIONS):
            active = np.abs(fb) >= ROOT_TOL_MM
            if not active.any():
                break
            with np.errstate(divide="ignore", invalid="ignore"):
                c = b - fb / slope
            c = np.where(active & np.isfinite(c) & (np.abs(c) < 10 * MAX_CONTACT_ANGLE_RAD), c, b)
            moved = c != b
            fc = dist(c)
            with np.errstate(divide="ignore", invalid="ignore"):
                slope = np.where(moved, (fc - fb) / (c - b), slope)
            a, fa = np.where(moved, b, a), np.where(moved, fb, fa)
            b, fb = c, np.where(moved, fc, fb)
        ok = (np.abs(fb) < 1e3 * ROOT_TOL_MM) & (np.abs(b) < MAX_CONTACT_ANGLE_RAD)
        ok &= direction * slope < 0.0  # approaching the cone as the big gear turns this way
        ok &= in_tooth_zone(self.other_spec, self.other_scale, *at(b))
        return np.where(ok, b, direction * np.inf)


# -- search --------------------------------------------------------------------------------
def _candidates(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pair (row), the REFINE_CANDIDATES smallest keys of a (N, teeth, profile, ruling) grid
    that are separate local extremes (another tooth, or more than two cells apart on the same
    tooth): their flat grid indices (N, C) and whether each is finite (N, C)."""
    n, _, n_t, n_u = key.shape
    masked = key.reshape(n, -1).copy()
    rows = np.arange(n)
    dj, dm = (g.reshape(-1) for g in np.meshgrid(np.arange(-2, 3), np.arange(-2, 3), indexing="ij"))
    picked, valid = [], []
    for c in range(REFINE_CANDIDATES):
        f = np.argmin(masked, axis=1)
        picked.append(f)
        valid.append(np.isfinite(masked[rows, f]))
        if c + 1 < REFINE_CANDIDATES:  # rule out the cells within two of this one on its tooth
            j, m = (f // n_u) % n_t, f % n_u
            jj, mm = j[:, None] + dj, m[:, None] + dm
            inside = (jj >= 0) & (jj < n_t) & (mm >= 0) & (mm < n_u)
            near = f[:, None] + dj * n_u + dm
            masked[np.broadcast_to(rows[:, None], near.shape)[inside], near[inside]] = np.inf
    return np.stack(picked, axis=1), np.stack(valid, axis=1)


def _refine(fs: _FlankSet, centres: np.ndarray, valid: np.ndarray, dt: float, du: float, direction: np.ndarray):
    """Local grid search for the extreme root around each candidate (tooth, profile, ruling) —
    centres (N, C, 3), all in one evaluation per level, the cell shrinking each level. Grid
    points are ranked by the one-step estimate; the winners are then solved to ROOT_TOL_MM.
    Returns per pair the best solved key (direction·δ, inf if none) and its tooth, profile, ruling."""
    grid = np.linspace(-1.0, 1.0, REFINE_GRID)
    gt, gu = (g.reshape(-1) for g in np.meshgrid(grid, grid, indexing="ij"))
    n, c = valid.shape
    centres = centres.copy()
    keys = np.full((n, c), np.inf)
    for _ in range(REFINE_LEVELS):
        T = np.clip(centres[..., 1, None] + dt * gt, 0.0, 1.0)  # (N, C, G²)
        U = np.clip(centres[..., 2, None] + du * gu, 0.0, 1.0)
        K = np.broadcast_to(centres[..., 0, None], T.shape)
        p = fs.points(K.reshape(n, -1), T.reshape(n, -1), U.reshape(n, -1))
        key = (direction * fs.estimate(p, direction, all_points=True)).reshape(T.shape)
        i = np.argmin(key, axis=2)[..., None]
        k_best = np.take_along_axis(key, i, axis=2)[..., 0]
        better = k_best < keys
        keys = np.where(better, k_best, keys)
        centres[..., 1] = np.where(better, np.take_along_axis(T, i, axis=2)[..., 0], centres[..., 1])
        centres[..., 2] = np.where(better, np.take_along_axis(U, i, axis=2)[..., 0], centres[..., 2])
        dt, du = 2.0 * dt / (REFINE_GRID - 1), 2.0 * du / (REFINE_GRID - 1)
    solved = direction * fs.roots(centres[..., 0], centres[..., 1], centres[..., 2], direction)
    solved = np.where(valid, solved, np.inf)
    j = np.argmin(solved, axis=1)
    rows = np.arange(n)
    return solved[rows, j], centres[rows, j, 0], centres[rows, j, 1], centres[rows, j, 2]


def _first_contacts(sets: list[_FlankSet], direction: np.ndarray):
    """Extreme root over both flank sets (min for +, max for −), per pair: samples ranked by a
    one-step estimate, the best REFINE_CANDIDATES per set (separate local extremes: another tooth
    or two cells apart) refined on a shrinking local grid of the flank parameters and solved.
    ``direction``: ±1 per pair, (N, 1). Returns per pair: direction·δ (inf: no contact), tooth,
    profile, ruling, the winning set's index, and whether the winner lies on the outermost
    sampled tooth (the window is too narrow: a tooth beyond it may touch first)."""
    t = np.linspace(0.0, 1.0, PROFILE_SAMPLES)
    u = np.linspace(0.0, 1.0, RULING_SAMPLES)
    dt, du = 1.0 / (PROFILE_SAMPLES - 1), 1.0 / (RULING_SAMPLES - 1)
    n = sets[0].teeth.shape[0]
    rows = np.arange(n)
    best = np.full(n, np.inf)
    tooth, tb, ub = np.zeros(n), np.zeros(n), np.zeros(n)
    which = np.zeros(n, dtype=int)
    for s, fs in enumerate(sets):
        shape = (n, fs.teeth.shape[1], len(t), len(u))
        key = np.empty(shape)
        for lo in range(0, n, GRID_PAIRS):  # the samples in cache-sized slices of the pairs
            part = slice(lo, lo + GRID_PAIRS)
            sub = fs.rows(part)
            way = direction[part]
            key[part] = (way * sub.estimate(sub.grid_points(t, u), way)).reshape((len(way), *shape[1:]))
        flat, valid = _candidates(key)
        if not valid.any():
            continue
        i, j, m = np.unravel_index(flat, shape[1:])
        centres = np.stack([np.take_along_axis(fs.teeth, i, axis=1).astype(float), t[j], u[m]], axis=-1)
        k_s, tooth_s, tb_s, ub_s = _refine(fs, centres, valid, dt, du, direction)
        better = k_s < best
        best = np.where(better, k_s, best)
        tooth, tb, ub = np.where(better, tooth_s, tooth), np.where(better, tb_s, tb), np.where(better, ub_s, ub)
        which = np.where(better, s, which)
    teeth = np.stack([fs.teeth for fs in sets])[which, rows]  # (N, window teeth) of each winner
    narrow = np.isfinite(best) & ((tooth == teeth[:, 0]) | (tooth == teeth[:, -1]))
    return best, tooth, tb, ub, which, narrow


def rigid_inverse(poses: np.ndarray) -> np.ndarray:
    """The inverse of rigid 4×4 transforms (rotation and translation), one or a stack (..., 4, 4):
    Rᵀ, −Rᵀ·t."""
    poses = np.asarray(poses, float)
    out = np.zeros_like(poses)
    rt = np.swapaxes(poses[..., :3, :3], -1, -2)
    out[..., :3, :3] = rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", rt, poses[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


@dataclass(frozen=True)
class Solution:
    """First contacts of N pairs: the big gear's turn (rad, signed), which flank the contact
    point was sampled on (0 big, 1 small), that gear's tooth and flank parameters, and the point
    (world, (N, 3))."""

    angle_rad: np.ndarray
    on: np.ndarray
    tooth: np.ndarray
    profile: np.ndarray
    ruling: np.ndarray
    point: np.ndarray


def first_contacts(big: BevelGearSpec, small: BevelGearSpec, big_poses: np.ndarray, small_poses: np.ndarray,
                   big_scales: np.ndarray, small_scales: np.ndarray, directions: np.ndarray) -> Solution:
    """The first contact of each pair (big gear turning its way about its own axis from its pose,
    the small gear held), in batches of BATCH_PAIRS. Raises RuntimeError when a pair has none
    within MAX_CONTACT_ANGLE_RAD, or only on the outermost tooth of the widest window."""
    n = len(big_poses)
    out = {k: np.zeros(n) for k in ("angle", "on", "tooth", "profile", "ruling")}
    point = np.zeros((n, 3))
    big_inv, small_inv = rigid_inverse(big_poses), rigid_inverse(small_poses)
    for start in range(0, n, BATCH_PAIRS):
        todo = np.arange(start, min(start + BATCH_PAIRS, n))
        window = teeth_window(big, small)
        while todo.size:
            if window > MAX_TEETH_WINDOW:
                raise RuntimeError(f"contact on the outermost sampled tooth with {MAX_TEETH_WINDOW} teeth on either "
                                   "side of the mesh zone")
            side = directions[todo].astype(float).reshape(-1, 1)  # + direction: side +1 flanks of both gears
            sets = [_FlankSet(big, small, True, small_inv[todo] @ big_poses[todo], big_scales[todo],
                              small_scales[todo], side, window),
                    _FlankSet(small, big, False, big_inv[todo] @ small_poses[todo], small_scales[todo],
                              big_scales[todo], side, window)]
            key, tooth, tb, ub, which, narrow = _first_contacts(sets, side)
            if not np.all(np.isfinite(key)):
                raise RuntimeError("no contact within MAX_CONTACT_ANGLE_RAD: the gears are not in mesh")
            done = np.flatnonzero(~narrow)
            rows = todo[done]
            delta = side[done, 0] * key[done]
            for k, v in (("angle", delta), ("on", which[done]), ("tooth", tooth[done]), ("profile", tb[done]),
                         ("ruling", ub[done])):
                out[k][rows] = v
            gears = ((big, big_poses, big_scales), (small, small_poses, small_scales))
            for w, (spec, poses, scales) in enumerate(gears):
                on = which[done] == w  # the point on the winner's flank, in the world
                if not on.any():
                    continue
                r = rows[on]
                local = np.stack(flank_xyz(spec, scales[r], tooth[done][on], side[done][on, 0], tb[done][on],
                                           ub[done][on]), axis=-1)
                if w == 0:  # the big gear turned to the contact
                    c, s = np.cos(delta[on]), np.sin(delta[on])
                    local = np.stack([c * local[:, 0] - s * local[:, 1], s * local[:, 0] + c * local[:, 1],
                                      local[:, 2]], axis=-1)
                point[r] = np.einsum("nij,nj->ni", poses[r, :3, :3], local) + poses[r, :3, 3]
            todo = todo[narrow]
            window += 1
    return Solution(out["angle"], out["on"].astype(int), out["tooth"].astype(int), out["profile"], out["ruling"], point)
