"""Angular play of a straight bevel pair with exact spherical-involute flanks (numpy only).

The independent check of the mesh sweep: no meshes, no CAD. Each gear is the analytic tooth of
:mod:`gearcheck.geometry.bevel` (flanks are cones through the gear's own apex over the spherical
involute, bounded by the root and tip cones and by the front and back cones), placed by a rigid
4×4 pose and scaled by a factor about its apex. Scaling about the apex leaves every flank cone
where it is and only moves the toe and heel (r·cos(θ − δ) = f·Ri … f·Re), so a thermal state
"scale f about a datum on the axis" is "scale f about the apex" plus a shift of the apex along
the axis (:func:`scale_about_apex`).

Play of the big gear against one small gear (the small gear held at its drive angle): turn the
big gear about its own axis until a flank touches, both ways. For the + direction (right-handed
about the big gear's +z) the big gear's side +1 flanks close on the small gear's side +1 flanks
(the small gear would be driven the other way about its own axis, ω_small/ω_big = −z_big/z_small,
so its tooth is pushed on its +azimuth side); the − direction uses the −1 flanks.

First contact, exactly: a point p of one gear's flank reaches the other gear's flank cone at
the turn δ(p) where its signed distance d(p, δ) to that cone (closed form,
:func:`gearcheck.geometry.bevel` ``minus_flank_signed``) is zero; d is smooth and nearly linear
in δ, so a vectorised secant solve per point converges in a few steps. The contact angle is the
extreme δ(p) over both flank surfaces — samples of the big gear's flank against the small gear's
cone and samples of the small gear's flank against the big gear's cone — keeping only roots
where the point then lies inside the other gear's tooth zone (between its root and tip cones and
between its front and back cones). Using both surfaces catches edge contacts to second order
(an edge of one gear against the face of the other, the usual contact once the apexes are
displaced and the mesh is no longer conjugate). The best samples are then refined on a local
parameter grid (:data:`REFINE_LEVELS`), so the sampling leaves an error far below 1e-3′.

Angles: radians inside; :func:`arcmin` converts. Play is measured on the big gear's axis.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bevel import BevelGearSpec, flank_azimuth, line_of_action, mate_rotation, minus_flank_signed

ARCMIN_PER_RAD = 10800.0 / math.pi

# Flank sampling: polar angle root → tip (uniform), and toe → heel along the rulings (uniform).
# Coarse on purpose: the samples only rank candidates; the refinement below finds the extreme
# (checked against 160 × 33 samples with deeper refinement: ≤ 1e-4′ on the template's poses).
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
# big_gear_contacts solves this many pairs per vectorised batch (memory: ~1 MB of points per pair).
BATCH_PAIRS = 48


def arcmin(angle_rad):
    return np.asarray(angle_rad) * ARCMIN_PER_RAD


def rot_z4(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def translation4(vector) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = vector
    return m


def scale_about_apex(pose: np.ndarray, factor: float, datum_local) -> np.ndarray:
    """Pose of a gear scaled by ``factor`` about a datum of its own frame, rewritten as a scale
    about its apex (frame origin) followed by this pose: p → datum + f·(p − datum) = f·p +
    (1 − f)·datum."""
    return np.asarray(pose, float) @ translation4((1.0 - factor) * np.asarray(datum_local, float))


@dataclass(frozen=True)
class PlacedGear:
    """An analytic gear: its design, its pose (frame → world, at its current turn) and its
    scale about its apex (1 when warm)."""

    spec: BevelGearSpec
    pose: np.ndarray
    scale: float = 1.0

    def turned(self, angle: float) -> PlacedGear:
        return PlacedGear(self.spec, self.pose @ rot_z4(angle), self.scale)


@dataclass(frozen=True)
class Contact:
    """First contact of the big gear turning one way: its turn (rad, about its own axis, from
    its given pose), the contact point (world) and where it lies."""

    angle_rad: float
    point: np.ndarray
    on: str  # "big" or "small": whose flank the contact point was sampled on
    tooth: int  # that gear's tooth index
    profile: float  # 0 root … 1 tip
    ruling: float  # 0 toe … 1 heel


@dataclass(frozen=True)
class Play:
    """Contact turns of the big gear both ways (plus ≥ minus when there is play)."""

    plus: Contact
    minus: Contact

    @property
    def total_rad(self) -> float:
        return self.plus.angle_rad - self.minus.angle_rad

    @property
    def total_arcmin(self) -> float:
        return float(arcmin(self.total_rad))


# -- geometry of one flank ------------------------------------------------------------------
def _flank_points(spec: BevelGearSpec, scale, tooth, side: int, profile, ruling) -> np.ndarray:
    """Points (…, 3), gear frame, of tooth ``tooth``'s flank ``side`` at parameters profile ∈
    [0, 1] (polar angle root cone → tip cone) and ruling ∈ [0, 1] (front cone → back cone)."""
    tooth, profile, ruling = np.broadcast_arrays(np.asarray(tooth, float), np.asarray(profile, float),
                                                 np.asarray(ruling, float))
    theta = spec.root_angle_rad + profile * (spec.face_angle_rad - spec.root_angle_rad)
    az = flank_azimuth(spec, theta, side) + tooth * spec.angular_pitch_rad
    ri, re = spec.inner_cone_distance_mm, spec.outer_cone_distance_mm
    r = scale * (ri + ruling * (re - ri)) / np.cos(theta - spec.pitch_angle_rad)
    st = np.sin(theta)
    return np.stack([r * st * np.cos(az), r * st * np.sin(az), r * np.cos(theta)], axis=-1)


def _signed_to_flank(spec: BevelGearSpec, q: np.ndarray, tooth: np.ndarray, side: int) -> np.ndarray:
    """Signed distance (mm, + outside the tooth) of points q (N, 3), gear frame, from the flank
    ``side`` of the given teeth (one tooth per point), extended over the whole cone."""
    ang = -tooth * spec.angular_pitch_rad
    c, s = np.cos(ang), np.sin(ang)
    x = c * q[:, 0] - s * q[:, 1]
    y = s * q[:, 0] + c * q[:, 1]
    if side == 1:
        y = -y  # side +1 is the mirror image of side −1 in the xz-plane
    return minus_flank_signed(spec, np.stack([x, y, q[:, 2]], axis=-1))


def _in_tooth_zone(spec: BevelGearSpec, scale, q: np.ndarray) -> np.ndarray:
    """Points (gear frame, (…, 3)) between the root and tip cones and between the front and back
    cones of a gear scaled by ``scale`` (broadcast over the points): only there can a point be
    inside a tooth (under the root cone is the blank: tip–root clearance is 0.25·m, far beyond
    any displacement studied)."""
    r = np.linalg.norm(q, axis=-1)
    theta = np.arctan2(np.hypot(q[..., 0], q[..., 1]), q[..., 2])
    along = r * np.cos(theta - spec.pitch_angle_rad)
    return ((theta >= spec.root_angle_rad - ZONE_TOL) & (theta <= spec.face_angle_rad + ZONE_TOL)
            & (along >= scale * spec.inner_cone_distance_mm - ZONE_TOL)
            & (along <= scale * spec.outer_cone_distance_mm + ZONE_TOL))


def _zone_azimuth(this: PlacedGear, other: PlacedGear) -> float:
    """Azimuth, in this gear's frame, of the other gear's axis: where the mesh zone is."""
    axis = this.pose[:3, :3].T @ other.pose[:3, 2]
    return math.atan2(axis[1], axis[0])


def _window_teeth(spec: BevelGearSpec, zone_azimuth: float, window: int) -> np.ndarray:
    centre = round(zone_azimuth / spec.angular_pitch_rad)
    return np.arange(centre - window, centre + window + 1)


def _facing_tooth(spec: BevelGearSpec, q: np.ndarray, side: int) -> np.ndarray:
    """Index of the tooth whose flank ``side`` faces each point (…, 3): the tooth space on side
    s of tooth k is centred at azimuth k·p + s·p/2."""
    pitch = spec.angular_pitch_rad
    az = np.arctan2(q[..., 1], q[..., 0])
    return np.round((az - side * pitch / 2.0) / pitch)


def _turn_z(p: np.ndarray, angle) -> np.ndarray:
    """Points (…, 3) turned by ``angle`` (broadcast over the points) about z."""
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * p[..., 0] - s * p[..., 1], s * p[..., 0] + c * p[..., 1], p[..., 2]], axis=-1)


# -- contact roots -------------------------------------------------------------------------
class _FlankSet:
    """Points of one gear's flank (one side) that move, as the big gear turns by δ, against the
    other gear's flank cone of the same side: q(δ) = Rz(−δ)^a · C · Rz(δ)^b · p in the other
    gear's frame (a = 1 when the other gear is the big one, b = 1 when this one is).

    Batched: N pairs of the same two designs, each with its own poses and scales. Every array of
    points or parameters has the shape (N, K, …): K points of pair n in row n."""

    def __init__(self, this: Sequence[PlacedGear], other: Sequence[PlacedGear], this_is_big: bool, side: int,
                 window: int):
        self.spec, self.other_spec = this[0].spec, other[0].spec
        self.big, self.side = this_is_big, side
        relative = np.stack([np.linalg.inv(o.pose) @ t.pose for t, o in zip(this, other, strict=True)])
        self.rot_t = np.ascontiguousarray(np.transpose(relative[:, :3, :3], (0, 2, 1)))  # this → other frame
        self.shift = relative[:, None, :3, 3]
        self.scale = np.array([t.scale for t in this])[:, None]
        self.other_scale = np.array([o.scale for o in other])[:, None]
        self.teeth = np.stack([_window_teeth(self.spec, _zone_azimuth(t, o), window)
                               for t, o in zip(this, other, strict=True)])

    def to_other(self, p: np.ndarray, delta) -> np.ndarray:
        if self.big:  # this gear turns: rotate its points first
            p = _turn_z(p, delta)
        q = p @ self.rot_t + self.shift
        if not self.big:  # the other (big) gear turns by δ: undo it in its frame
            q = _turn_z(q, -np.asarray(delta))
        return q

    def points(self, tooth, profile, ruling) -> np.ndarray:
        return _flank_points(self.spec, self.scale, tooth, self.side, profile, ruling)

    def _distance(self, q: np.ndarray, facing: np.ndarray) -> np.ndarray:
        return _signed_to_flank(self.other_spec, q.reshape(-1, 3), facing.reshape(-1), self.side).reshape(q.shape[:-1])

    def estimate(self, tooth, profile, ruling, direction: int) -> np.ndarray:
        """One secant step from δ = 0: the turn at which each point would reach the other
        gear's flank cone (d is nearly linear in δ); ±inf where it cannot (moving away, out of
        the other's tooth zone or beyond MAX_CONTACT_ANGLE_RAD). For ranking samples."""
        p = self.points(tooth, profile, ruling)
        q0 = self.to_other(p, 0.0)
        facing = _facing_tooth(self.other_spec, q0, self.side)
        step = direction * SECANT_FIRST_STEP_RAD
        d0 = self._distance(q0, facing)
        d1 = self._distance(self.to_other(p, step), facing)
        slope = (d1 - d0) / step
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(direction * slope < 0.0, -d0 / slope, np.nan)
        ok = np.isfinite(delta) & (np.abs(delta) < MAX_CONTACT_ANGLE_RAD)
        delta = np.where(ok, delta, 0.0)
        ok &= _in_tooth_zone(self.other_spec, self.other_scale, self.to_other(p, delta))
        return np.where(ok, delta, direction * np.inf)

    def roots(self, tooth, profile, ruling, direction: int) -> np.ndarray:
        """Turn δ (rad) at which each point reaches the other gear's flank cone inside its tooth
        zone (secant solve to ROOT_TOL_MM; a converged point stays put); ±inf (sign of
        direction) where there is none within MAX_CONTACT_ANGLE_RAD."""
        p = self.points(tooth, profile, ruling)
        facing = _facing_tooth(self.other_spec, self.to_other(p, 0.0), self.side)

        def dist(delta):
            return self._distance(self.to_other(p, delta), facing)

        a = np.zeros(p.shape[:-1])
        fa = dist(a)
        b = np.full(p.shape[:-1], direction * SECANT_FIRST_STEP_RAD)
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
        ok &= _in_tooth_zone(self.other_spec, self.other_scale, self.to_other(p, b))
        return np.where(ok, b, direction * np.inf)


def teeth_window(big: BevelGearSpec, small: BevelGearSpec) -> int:
    """Teeth on either side of the mesh zone that the contact can reach (both gears)."""
    path = line_of_action(big, small)
    reach = max(path.pitch_arc - path.start_arc, path.end_arc - path.pitch_arc) / path.base_pitch_arc
    return min(max(MIN_TEETH_WINDOW, math.ceil(reach) + 1), MAX_TEETH_WINDOW)


def _candidates(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pair (row), the REFINE_CANDIDATES smallest keys of a (N, teeth, profile, ruling) grid
    that are separate local extremes (another tooth, or more than two cells apart on the same
    tooth): their flat grid indices (N, C) and whether each is finite (N, C)."""
    n = key.shape[0]
    flat = key.reshape(n, -1)
    ii, jj, mm = np.unravel_index(np.arange(flat.shape[1]), key.shape[1:])
    excluded = np.zeros(flat.shape, dtype=bool)
    rows = np.arange(n)
    picked, valid = [], []
    for _ in range(REFINE_CANDIDATES):
        masked = np.where(excluded, np.inf, flat)
        f = np.argmin(masked, axis=1)
        picked.append(f)
        valid.append(np.isfinite(masked[rows, f]))
        excluded |= ((ii[None, :] == ii[f][:, None]) & (np.abs(jj[None, :] - jj[f][:, None]) <= 2)
                     & (np.abs(mm[None, :] - mm[f][:, None]) <= 2))
    return np.stack(picked, axis=1), np.stack(valid, axis=1)


def _refine(fs: _FlankSet, centres: np.ndarray, valid: np.ndarray, dt: float, du: float, direction: int):
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
        key = (direction * fs.estimate(K.reshape(n, -1), T.reshape(n, -1), U.reshape(n, -1),
                                       direction)).reshape(T.shape)
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


def _first_contacts(sets: list[_FlankSet], direction: int):
    """Extreme root over both flank sets (min for +, max for −), per pair: samples ranked by a
    one-step estimate, the best REFINE_CANDIDATES per set (separate local extremes: another tooth
    or two cells apart) refined on a shrinking local grid of the flank parameters and solved.
    Returns per pair: direction·δ (inf: no contact), tooth, profile, ruling, the winning set's
    index, and whether the winner lies on the outermost sampled tooth (the window is too narrow:
    a tooth beyond it may touch first)."""
    t = np.linspace(0.0, 1.0, PROFILE_SAMPLES)
    u = np.linspace(0.0, 1.0, RULING_SAMPLES)
    dt, du = 1.0 / (PROFILE_SAMPLES - 1), 1.0 / (RULING_SAMPLES - 1)
    n = sets[0].teeth.shape[0]
    rows = np.arange(n)
    best = np.full(n, np.inf)
    tooth, tb, ub = np.zeros(n), np.zeros(n), np.zeros(n)
    which = np.zeros(n, dtype=int)
    for s, fs in enumerate(sets):
        nk = fs.teeth.shape[1]
        shape = (n, nk, len(t), len(u))
        K = np.broadcast_to(fs.teeth[:, :, None, None], shape).reshape(n, -1)
        T = np.broadcast_to(t[None, None, :, None], shape).reshape(n, -1)
        U = np.broadcast_to(u[None, None, None, :], shape).reshape(n, -1)
        key = (direction * fs.estimate(K, T, U, direction)).reshape(shape)
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


def big_gear_contacts(bigs: Sequence[PlacedGear], smalls: Sequence[PlacedGear], direction: int) -> list[Contact]:
    """:func:`big_gear_contact` for many pairs at once (the same two designs; each pair its own
    poses and scales), vectorised over the pairs in chunks of :data:`BATCH_PAIRS`."""
    if direction not in (-1, 1):
        raise ValueError("direction must be +1 or -1")
    if len(bigs) != len(smalls):
        raise ValueError("one small gear per big gear")
    if not bigs:
        return []
    big_spec, small_spec = bigs[0].spec, smalls[0].spec
    if any(b.spec != big_spec for b in bigs) or any(s.spec != small_spec for s in smalls):
        raise ValueError("a batch holds pairs of the same two gear designs")
    out: list[Contact | None] = [None] * len(bigs)
    side = direction  # + direction: side +1 flanks of both gears (module docstring)
    for start in range(0, len(bigs), BATCH_PAIRS):
        todo = np.arange(start, min(start + BATCH_PAIRS, len(bigs)))
        window = teeth_window(big_spec, small_spec)
        while todo.size:
            if window > MAX_TEETH_WINDOW:
                raise RuntimeError(f"contact on the outermost sampled tooth with {MAX_TEETH_WINDOW} teeth on either "
                                   "side of the mesh zone")
            b = [bigs[int(i)] for i in todo]
            s = [smalls[int(i)] for i in todo]
            sets = [_FlankSet(b, s, True, side, window), _FlankSet(s, b, False, side, window)]
            key, tooth, tb, ub, which, narrow = _first_contacts(sets, direction)
            if not np.all(np.isfinite(key)):
                raise RuntimeError("no contact within MAX_CONTACT_ANGLE_RAD: the gears are not in mesh")
            for k in np.flatnonzero(~narrow):
                this = b[k] if which[k] == 0 else s[k]
                delta = direction * float(key[k])
                p = _flank_points(this.spec, this.scale, tooth[k], side, tb[k], ub[k])
                pose = this.turned(delta).pose if which[k] == 0 else this.pose
                out[todo[k]] = Contact(delta, pose[:3, :3] @ p + pose[:3, 3], "big" if which[k] == 0 else "small",
                                       int(tooth[k]), float(tb[k]), float(ub[k]))
            todo = todo[narrow]
            window += 1
    return [c for c in out if c is not None]


def big_gear_contact(big: PlacedGear, small: PlacedGear, direction: int) -> Contact:
    """Turn of the big gear about its own axis (from its given pose) at which it first touches
    the small gear, turning + (direction = +1) or − (−1)."""
    return big_gear_contacts([big], [small], direction)[0]


def big_gear_play(big: PlacedGear, small: PlacedGear) -> Play:
    """Contact turns of the big gear both ways against one small gear held still."""
    return Play(big_gear_contact(big, small, +1), big_gear_contact(big, small, -1))


# -- a single pair on its nominal mounting -------------------------------------------------
def nominal_small_pose(big: BevelGearSpec, small: BevelGearSpec) -> np.ndarray:
    """Small gear frame → world for the pair on a common apex, world = the big gear's frame at
    turn 0 (the small gear's tooth 0 in a big tooth space: mate_rotation's phasing)."""
    m = np.eye(4)
    m[:3, :3] = mate_rotation(big, 0.0, small)
    return m


def pitch_element_normal(big: BevelGearSpec) -> np.ndarray:
    """Unit normal to the pitch element (at the big gear's azimuth 0) in the plane of the two
    axes, pointing from the big gear toward the small gear (world = big frame at turn 0)."""
    d = big.pitch_angle_rad
    return np.array([math.cos(d), 0.0, -math.sin(d)])


def conjugate_big_turn(big: BevelGearSpec, small: BevelGearSpec, drive_angle: float) -> float:
    """Big-gear turn that keeps the pitch cones rolling when the small gear turns by drive_angle."""
    return -drive_angle * small.teeth / big.teeth


@dataclass(frozen=True)
class PlayCycle:
    drive_angles_rad: np.ndarray  # small gear turns
    plus_rad: np.ndarray  # big-gear contact turns from the conjugate position, + way
    minus_rad: np.ndarray  # − way (negative when there is play on that side)

    @property
    def total_arcmin(self) -> np.ndarray:
        return arcmin(self.plus_rad - self.minus_rad)

    @property
    def min_total_arcmin(self) -> float:
        return float(self.total_arcmin.min())


def pair_play_over_cycle(big: BevelGearSpec, small: BevelGearSpec, drive_angles_rad,
                         big_displacement: np.ndarray | None = None,
                         small_displacement: np.ndarray | None = None,
                         big_scale: float = 1.0, small_scale: float = 1.0) -> PlayCycle:
    """Play of the big gear against one small gear over drive angles of the small gear, each
    gear rigidly displaced (world 4×4, applied after its nominal pose) and scaled about its apex.
    One small-gear tooth pitch covers the whole cycle (identical teeth)."""
    db = np.eye(4) if big_displacement is None else np.asarray(big_displacement, float)
    ds = np.eye(4) if small_displacement is None else np.asarray(small_displacement, float)
    small_nominal = nominal_small_pose(big, small)
    plus, minus = [], []
    angles = np.asarray(drive_angles_rad, float)
    for phi in angles:
        s = PlacedGear(small, ds @ small_nominal @ rot_z4(phi), small_scale)
        b = PlacedGear(big, db @ rot_z4(conjugate_big_turn(big, small, phi)), big_scale)
        play = big_gear_play(b, s)
        plus.append(play.plus.angle_rad)
        minus.append(play.minus.angle_rad)
    return PlayCycle(angles, np.array(plus), np.array(minus))
