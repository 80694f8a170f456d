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
def _flank_points(spec: BevelGearSpec, scale: float, tooth, side: int, profile, ruling) -> np.ndarray:
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


def _in_tooth_zone(spec: BevelGearSpec, scale: float, q: np.ndarray) -> np.ndarray:
    """Points (gear frame) between the root and tip cones and between the front and back cones:
    only there can a point be inside a tooth (under the root cone is the blank: tip–root
    clearance is 0.25·m, far beyond any displacement studied)."""
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
    """Index of the tooth whose flank ``side`` faces each point: the tooth space on side s of
    tooth k is centred at azimuth k·p + s·p/2."""
    pitch = spec.angular_pitch_rad
    az = np.arctan2(q[:, 1], q[:, 0])
    return np.round((az - side * pitch / 2.0) / pitch)


# -- contact roots -------------------------------------------------------------------------
class _FlankSet:
    """Points of one gear's flank (one side) that move, as the big gear turns by δ, against the
    other gear's flank cone of the same side: q(δ) = Rz(−δ)^a · C · Rz(δ)^b · p in the other
    gear's frame (a = 1 when the other gear is the big one, b = 1 when this one is)."""

    def __init__(self, this: PlacedGear, other: PlacedGear, this_is_big: bool, side: int, window: int):
        self.this, self.other, self.big, self.side = this, other, this_is_big, side
        self.relative = np.linalg.inv(other.pose) @ this.pose  # this frame → other frame
        self.teeth = _window_teeth(this.spec, _zone_azimuth(this, other), window)

    def to_other(self, p: np.ndarray, delta: np.ndarray) -> np.ndarray:
        if self.big:  # this gear turns: rotate its points first
            c, s = np.cos(delta), np.sin(delta)
            p = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1], p[:, 2]], axis=-1)
        q = p @ self.relative[:3, :3].T + self.relative[:3, 3]
        if not self.big:  # the other (big) gear turns by δ: undo it in its frame
            c, s = np.cos(-delta), np.sin(-delta)
            q = np.stack([c * q[:, 0] - s * q[:, 1], s * q[:, 0] + c * q[:, 1], q[:, 2]], axis=-1)
        return q

    def _points(self, tooth, profile, ruling) -> np.ndarray:
        return _flank_points(self.this.spec, self.this.scale, tooth, self.side, profile, ruling).reshape(-1, 3)

    def estimate(self, tooth, profile, ruling, direction: int) -> np.ndarray:
        """One secant step from δ = 0: the turn at which each point would reach the other
        gear's flank cone (d is nearly linear in δ); ±inf where it cannot (moving away, out of
        the other's tooth zone or beyond MAX_CONTACT_ANGLE_RAD). For ranking samples."""
        p = self._points(tooth, profile, ruling)
        spec_o = self.other.spec
        q0 = self.to_other(p, np.zeros(len(p)))
        facing = _facing_tooth(spec_o, q0, self.side)
        step = np.full(len(p), direction * SECANT_FIRST_STEP_RAD)
        d0 = _signed_to_flank(spec_o, q0, facing, self.side)
        d1 = _signed_to_flank(spec_o, self.to_other(p, step), facing, self.side)
        slope = (d1 - d0) / step
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(direction * slope < 0.0, -d0 / slope, np.nan)
        ok = np.isfinite(delta) & (np.abs(delta) < MAX_CONTACT_ANGLE_RAD)
        delta = np.where(ok, delta, 0.0)
        ok &= _in_tooth_zone(spec_o, self.other.scale, self.to_other(p, delta))
        return np.where(ok, delta, direction * np.inf)

    def roots(self, tooth, profile, ruling, direction: int) -> np.ndarray:
        """Turn δ (rad) at which each point reaches the other gear's flank cone inside its tooth
        zone (secant solve to ROOT_TOL_MM); ±inf (sign of direction) where there is none within
        MAX_CONTACT_ANGLE_RAD."""
        p = self._points(tooth, profile, ruling)
        spec_o = self.other.spec
        facing = _facing_tooth(spec_o, self.to_other(p, np.zeros(len(p))), self.side)

        def dist(delta):
            return _signed_to_flank(spec_o, self.to_other(p, delta), facing, self.side)

        a = np.zeros(len(p))
        fa = dist(a)
        b = np.full(len(p), direction * SECANT_FIRST_STEP_RAD)
        fb = dist(b)
        slope = (fb - fa) / (b - a)
        for _ in range(SECANT_ITERATIONS):
            with np.errstate(divide="ignore", invalid="ignore"):
                c = b - fb / slope
            c = np.where(np.isfinite(c) & (np.abs(c) < 10 * MAX_CONTACT_ANGLE_RAD), c, b)
            moved = c != b
            a, fa, b = b, fb, c
            fb = dist(b)
            with np.errstate(divide="ignore", invalid="ignore"):
                slope = np.where(moved, (fb - fa) / (b - a), slope)
            if np.all(~moved | (np.abs(fb) < ROOT_TOL_MM)):
                break
        ok = (np.abs(fb) < 1e3 * ROOT_TOL_MM) & (np.abs(b) < MAX_CONTACT_ANGLE_RAD)
        ok &= direction * slope < 0.0  # approaching the cone as the big gear turns this way
        ok &= _in_tooth_zone(spec_o, self.other.scale, self.to_other(p, b))
        return np.where(ok, b, direction * np.inf)


class _WindowTooNarrow(RuntimeError):
    """The extreme lies on the last tooth sampled: a tooth beyond it may touch first."""


def teeth_window(big: BevelGearSpec, small: BevelGearSpec) -> int:
    """Teeth on either side of the mesh zone that the contact can reach (both gears)."""
    path = line_of_action(big, small)
    reach = max(path.pitch_arc - path.start_arc, path.end_arc - path.pitch_arc) / path.base_pitch_arc
    return min(max(MIN_TEETH_WINDOW, math.ceil(reach) + 1), MAX_TEETH_WINDOW)


def _first_contact(sets: list[_FlankSet], direction: int) -> Contact:
    """Extreme root over both flank sets (min for +, max for −): samples ranked by a one-step
    estimate, the best REFINE_CANDIDATES per set (separate local extremes: another tooth or two
    cells apart) refined on a shrinking local grid of the flank parameters and solved."""
    t = np.linspace(0.0, 1.0, PROFILE_SAMPLES)
    u = np.linspace(0.0, 1.0, RULING_SAMPLES)
    dt, du = 1.0 / (PROFILE_SAMPLES - 1), 1.0 / (RULING_SAMPLES - 1)
    best = None  # (key, tooth, profile, ruling, set)
    for fs in sets:
        k, tt, uu = np.meshgrid(fs.teeth, t, u, indexing="ij")
        key = direction * fs.estimate(k, tt, uu, direction).reshape(k.shape)
        order = np.argsort(key, axis=None)
        picked: list[tuple[int, int, int]] = []  # grid indices (tooth, profile, ruling)
        for flat in order[: 50 * REFINE_CANDIDATES]:
            if not np.isfinite(key.flat[flat]) or len(picked) == REFINE_CANDIDATES:
                break
            idx = np.unravel_index(flat, key.shape)
            # a separate local extreme: another tooth, or two cells away on the same tooth
            if any(i == idx[0] and abs(j - idx[1]) <= 2 and abs(m - idx[2]) <= 2 for i, j, m in picked):
                continue
            picked.append((int(idx[0]), int(idx[1]), int(idx[2])))
        cands = [(float(fs.teeth[i]), float(t[j]), float(u[m])) for i, j, m in picked]
        if not cands:
            continue
        cand = _refine(fs, np.array(cands), dt, du, direction)
        if best is None or cand[0] < best[0]:
            best = cand + (fs,)
    if best is None or not np.isfinite(best[0]):
        raise RuntimeError("no contact within MAX_CONTACT_ANGLE_RAD: the gears are not in mesh")
    key, tooth, tb, ub, fs = best
    if tooth in (fs.teeth[0], fs.teeth[-1]):
        raise _WindowTooNarrow(f"contact on the outermost sampled tooth ({'big' if fs.big else 'small'} "
                               f"tooth {tooth})")
    delta = direction * key
    p = fs._points(tooth, tb, ub)
    pose = fs.this.turned(delta).pose if fs.big else fs.this.pose
    point = pose[:3, :3] @ p[0] + pose[:3, 3]
    return Contact(float(delta), point, "big" if fs.big else "small", int(tooth), tb, ub)


def _refine(fs: _FlankSet, cands: np.ndarray, dt: float, du: float, direction: int):
    """Local grid search for the extreme root around each candidate (tooth, profile, ruling),
    all candidates in one evaluation per level, the cell shrinking each level. Grid points are
    ranked by the one-step estimate; the winner is then solved to ROOT_TOL_MM."""
    grid = np.linspace(-1.0, 1.0, REFINE_GRID)
    gt, gu = np.meshgrid(grid, grid, indexing="ij")
    centres = cands.copy()
    keys = np.full(len(cands), np.inf)
    rows = np.arange(len(cands))
    for _ in range(REFINE_LEVELS):
        T = np.clip(centres[:, 1, None, None] + dt * gt, 0.0, 1.0)
        U = np.clip(centres[:, 2, None, None] + du * gu, 0.0, 1.0)
        K = np.broadcast_to(centres[:, 0, None, None], T.shape)
        key = (direction * fs.estimate(K, T, U, direction)).reshape(len(cands), -1)
        i = np.argmin(key, axis=1)
        better = key[rows, i] < keys
        keys = np.where(better, key[rows, i], keys)
        centres[better, 1] = T.reshape(len(cands), -1)[better, i[better]]
        centres[better, 2] = U.reshape(len(cands), -1)[better, i[better]]
        dt, du = 2.0 * dt / (REFINE_GRID - 1), 2.0 * du / (REFINE_GRID - 1)
    solved = direction * fs.roots(centres[:, 0], centres[:, 1], centres[:, 2], direction)
    j = int(np.argmin(solved))
    return float(solved[j]), int(centres[j, 0]), float(centres[j, 1]), float(centres[j, 2])


def big_gear_contact(big: PlacedGear, small: PlacedGear, direction: int) -> Contact:
    """Turn of the big gear about its own axis (from its given pose) at which it first touches
    the small gear, turning + (direction = +1) or − (−1)."""
    if direction not in (-1, 1):
        raise ValueError("direction must be +1 or -1")
    side = direction  # + direction: side +1 flanks of both gears (module docstring)
    for window in range(teeth_window(big.spec, small.spec), MAX_TEETH_WINDOW + 1):
        sets = [_FlankSet(big, small, True, side, window), _FlankSet(small, big, False, side, window)]
        try:
            return _first_contact(sets, direction)
        except _WindowTooNarrow as exc:
            reason = exc
    raise RuntimeError(f"{reason} with {MAX_TEETH_WINDOW} teeth on either side of the mesh zone")


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
