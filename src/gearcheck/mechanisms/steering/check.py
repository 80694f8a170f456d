"""Steering sweeps with FCL on the built meshes (seed 003, issue 10): towing and power mode.

**Towing** (the pinion drives): the pinion turns 0 → ±max → 0. At each angle the rack moves only
as far as a tooth pushes it: if the rack flanks that a tooth can push (those facing against the
push; a trimmed top never pushes, the push model's rule) collide at the rack's previous travel,
the rack advances by the smallest amount that clears them, at most the model's push reach
(bisection on the travel between a colliding and a free travel: contact proven from both sides);
otherwise it stands, and a jam shows as interference. On the return swing the other flanks push
it back the same way.
This gives the towing curve L(φ), compared pose by pose with the exact-polyline push model
(:func:`analysis.sweep`). Events, each by bisection between grid poses:

* disengage: where the pushed rack reaches its standing travel. Right at the stop G1's tip land
  (an arc through S2) grazes S2 at zero clearance, so "touching the standing rack" is decided at
  the rack held δ and 2δ short of its standing travel (δ = contact tolerance; the pinion reaches
  it at φ(δ), φ(2δ)), and the angle is extrapolated to δ = 0: φ = 2·φ(δ) − φ(2δ). The same
  predicate gives the end of the grazing.
* re-engage: on the return swing, where the pinion first touches the standing rack's other
  flanks (corner S6, trailing flank of the next tooth).
* graze: the pose of closest approach past the disengage, with the rack shift that brings it to
  contact (the no-interference claim comes with the pose where contact is reached).

**Power** (the rack drives): the rack advances; the pinion turns by the smallest angle that clears
the rack's driving flanks (bisection on the pinion angle). The continuous-drive limit is where the
driving contact on the first rack tooth reaches its top corner S6 (eq 19): a contact *position*,
linear in the angle, never a threshold on the lag behind the conjugate ratio (that lag grows with
the square of the overshoot and hides below the mesh error). The FCL nearest points locate the
contact; because the pinion mesh is a polygon (vertices on the exact flank, chords inside it), the
raw nearest point sits on a mesh vertex and jumps by a chord (~1 mm along the flank) — and near
the corner the vertex/flank and corner/chord contacts, whose exact versions are tangent there,
swap within the mesh error, so the raw point reaches the corner up to ~1° early or late. The
position is therefore taken as the tangency point of the flank the mesh vertices describe: at
the support vertex the rack flank's direction lies between the two adjacent chord directions,
and the tangent direction is interpolated linearly between the chord midpoints
(:func:`tangency_offset`). The limit is the travel where that point reaches S6 (bisection on L);
the raw corner contact is reported beside it.

**Interference**: at every pose the whole walls are tested. Zero backlash means the non-driving
flanks touch at zero clearance too, so a collision is measured, not just flagged: the rack shift
along its travel that clears each side (an upper bound of the normal depth), and the pose passes
when that depth is within the contact tolerance (no smaller than the sum of the two meshes' error
bounds).

Meshes: both parts are straight extrusions over the same z range, so their solids overlap exactly
when their side walls cross (a profile wholly inside the other cannot happen with small steps):
the end faces are left out, and so are the pinion's walls that can never reach the rack (radius
below H − rack top: bore, roots) and the rack's walls below the pinion's tip circle.

Frame, angle 0 and tooth numbering: :mod:`gearcheck.geometry.rack_pinion`; the + swing is the
paper's (φ > 0, the first rack tooth k = rack.first_tooth comes under the pinion); the − swing is
its mirror image, swept on the same meshes (their triangulations are not mirror images).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from gearcheck.mechanisms.steering import analysis as an
from gearcheck.sweep.engine import Body, MeshData, Scene, bisect_contact
from gearcheck.sweep.pool import map_scene
from gearcheck.sweep.result import CheckResult, Comparison, Plot, Series, Verdict, WorstPose

SECTION = "steering"

# --- named tolerances ------------------------------------------------------------------------
# Zero backlash: flanks touch at zero clearance, so the mesh decides contact only to within its
# chord error. A collision whose depth along the travel is within this is contact, deeper is
# interference. 0.02 = the sum of both parts' error bounds at the default 0.01 mm tessellation;
# the check raises it to the bodies' own sum when that is larger.
CONTACT_TOL_MM = 0.02
# Issue 10: the towing curve must agree with the analytic one within this.
TOWING_CURVE_TOL_MM = 0.05
# Grid steps (events are refined by bisection, so the step sets only the curve sampling and
# how closely the tip-land vertices are caught passing over S2: the standing rack creeps by
# up to the chord sag / sin(polar angle of S2) between samples).
TOWING_STEP_DEG = 0.25
POWER_STEP_DEG = 0.25
# Bisection tolerances.
TRAVEL_BISECT_TOL_MM = 1e-4  # rack travel where a pushed rack just clears the pinion (1/500 of the curve tolerance)
ANGLE_BISECT_TOL_RAD = 1e-8  # pinion angle where a driven pinion just clears the rack (1e-6 mm at r)
EVENT_ANGLE_TOL_RAD = 1e-7  # disengage / grazing end / re-engage angles
EVENT_TRAVEL_TOL_MM = 1e-5  # travel where the power-mode contact reaches S6
# A rack triangle is a flank (the only faces that push the rack, see an.PUSH_NORMAL_MIN) when
# its centroid lies within this of a flank segment of the drawing, in the section plane.
FLANK_MATCH_MM = 1e-6
# Reach of one towing push: the push model's bound (tip radius / PUSH_NORMAL_MIN per radian) times
# the angle step, plus the contact tolerance (a pose that starts in contact). Power mode: the
# rack turns the pinion at most REACH_MARGIN / (centre height − rack top) rad per mm.
REACH_MARGIN = 1.5
# A reach is sampled upwards in this many steps for the first free travel.
REACH_SAMPLES = 16
# Walls kept: the pinion's reaching within this of the rack's top (radius ≥ H − top − margin),
# the rack's reaching within this of the pinion's tip circle.
WALL_REACH_MARGIN_MM = 1.0
# Most mesh vertices walked from the one nearest the FCL contact to the flank's support vertex.
TANGENCY_WINDOW = 8

PINION, RACK = "pinion", "rack"
RACK_FACING_MINUS_X = "rack_left_flanks"  # facing −x: pushed by the pinion towards +x
RACK_FACING_PLUS_X = "rack_right_flanks"  # facing +x: pushed towards −x, drive in power mode


# =============================================================================================
# Meshes and poses (numpy only)
# =============================================================================================

def _normals(mesh: MeshData) -> np.ndarray:
    t = mesh.vertices[mesh.faces]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return n / np.linalg.norm(n, axis=1)[:, None]


def submesh(mesh: MeshData, name: str, keep: np.ndarray) -> MeshData:
    """The triangles ``keep`` of ``mesh`` with their vertices, renumbered."""
    faces = mesh.faces[keep]
    used = np.unique(faces)
    index = np.full(len(mesh.vertices), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    return MeshData(name, mesh.vertices[used], index[faces])


def rack_flank_faces(g, rack: MeshData) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the rack triangles on the left flanks (facing −x) and on the right flanks
    (facing +x) of the drawing's teeth: matched by position, so that a trimmed top, however
    slanted, never counts as a flank (the push model's rule)."""
    centroid = rack.vertices[rack.faces].mean(axis=1)[:, :2]
    left = np.zeros(len(rack.faces), bool)
    right = np.zeros(len(rack.faces), bool)
    for k in range(g.rack_first_tooth, g.rack_last_tooth + 1):
        bl, br, tr, tl = g.rack_tooth_polygon(k, 0.0)
        for a, b, mask in ((bl, tl, left), (br, tr, right)):
            d = b - a
            t = (centroid - a) @ d / float(d @ d)
            rel = centroid - a
            off = np.abs(d[0] * rel[:, 1] - d[1] * rel[:, 0]) / float(np.linalg.norm(d))
            mask |= (t >= 0.0) & (t <= 1.0) & (off <= FLANK_MATCH_MM)
    return left, right


def sweep_meshes(pinion: Body, rack: Body, centre_height_mm: float, flanks: tuple[np.ndarray, np.ndarray]
                 ) -> tuple[list[MeshData], dict]:
    """The meshes the sweep uses (own frames): pinion and rack side walls that can meet, and the
    rack's left and right flanks apart (``flanks``: :func:`rack_flank_faces`, the faces that push).
    Also returns counts for the report."""
    zp, zr = pinion.mesh.vertices[:, 2], rack.mesh.vertices[:, 2]
    same_z = abs(zp.min() - zr.min()) < 1e-6 and abs(zp.max() - zr.max()) < 1e-6
    np_, nr = _normals(pinion.mesh), _normals(rack.mesh)
    walls_p = np.abs(np_[:, 2]) < 0.5 if same_z else np.ones(len(np_), bool)
    walls_r = np.abs(nr[:, 2]) < 0.5 if same_z else np.ones(len(nr), bool)
    rack_top = float(rack.mesh.vertices[:, 1].max())
    radius = np.hypot(pinion.mesh.vertices[:, 0], pinion.mesh.vertices[:, 1])[pinion.mesh.faces].max(axis=1)
    reach = centre_height_mm - rack_top - WALL_REACH_MARGIN_MM
    keep_p = walls_p & (radius >= reach)
    tip = float(radius.max())
    keep_r = walls_r & (rack.mesh.vertices[:, 1][rack.mesh.faces].max(axis=1) >= centre_height_mm - tip - WALL_REACH_MARGIN_MM)
    left, right = flanks
    meshes = [
        submesh(pinion.mesh, PINION, keep_p),
        submesh(rack.mesh, RACK, keep_r),
        submesh(rack.mesh, RACK_FACING_MINUS_X, keep_r & left),
        submesh(rack.mesh, RACK_FACING_PLUS_X, keep_r & right),
    ]
    info = {"pinion_triangles_total": len(pinion.mesh.faces), "pinion_triangles_swept": int(keep_p.sum()),
            "rack_triangles_total": len(rack.mesh.faces), "rack_triangles_swept": int(keep_r.sum()),
            "end_faces_dropped": int(same_z)}
    return meshes, info


def pinion_profile(pinion: MeshData) -> np.ndarray:
    """The pinion's outline as the mesh has it (own frame, (n, 2), ordered by polar angle): the
    vertices on one end face. Every wall triangle spans the face width, so these are all the
    profile's vertices (exact points of the B-rep outline); only the teeth are kept."""
    v = pinion.vertices
    ring = v[np.abs(v[:, 2] - v[:, 2].max()) < 1e-6]
    rho = np.hypot(ring[:, 0], ring[:, 1])
    ring = ring[rho > 0.8 * rho.max()]
    gamma = np.arctan2(ring[:, 0], -ring[:, 1])
    return ring[np.argsort(gamma), :2]


@dataclass(frozen=True)
class Kinematics:
    """Poses as data: the pinion turns about its motion axis, the rack slides along its own."""

    pinion_base: np.ndarray  # pose as built (angle 0)
    pinion_axis: np.ndarray
    pinion_origin: np.ndarray
    rack_base: np.ndarray  # pose as built (travel 0)
    rack_axis: np.ndarray

    @classmethod
    def from_bodies(cls, pinion: Body, rack: Body) -> "Kinematics":
        pm, rm = pinion.motion or {}, rack.motion or {}
        if pm.get("kind") != "rotation" or rm.get("kind") != "translation":
            raise ValueError("steering check needs a rotating pinion and a sliding rack (Body.motion)")
        axis = np.asarray(pm["axis"], float)
        raxis = np.asarray(rm["axis"], float)
        return cls(np.asarray(pinion.pose, float), axis / np.linalg.norm(axis), np.asarray(pm["origin"], float),
                   np.asarray(rack.pose, float), raxis / np.linalg.norm(raxis))

    def pinion(self, angle: float) -> np.ndarray:
        """Pinion frame → world at pinion angle φ (right-handed about the axis)."""
        k = self.pinion_axis
        kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        r = np.eye(3) + math.sin(angle) * kx + (1.0 - math.cos(angle)) * kx @ kx
        turn = np.eye(4)
        turn[:3, :3] = r
        turn[:3, 3] = self.pinion_origin - r @ self.pinion_origin
        return turn @ self.pinion_base

    def rack(self, travel: float) -> np.ndarray:
        """Rack frame → world at travel L."""
        move = np.eye(4)
        move[:3, 3] = self.rack_axis * travel
        return move @ self.rack_base


def tangency_offset(profile_world: np.ndarray, near: np.ndarray, normal: np.ndarray, corner: np.ndarray,
                    up: np.ndarray, window: int = TANGENCY_WINDOW) -> float:
    """Signed distance along a straight rack flank (direction ``up``, towards its ``corner``) from
    the corner to the point where the pinion's flank is tangent to it, from the pinion's mesh
    outline (world xy, ordered) near the contact point ``near``.

    The support vertex (least ``normal``·V, ``normal`` the flank's outward normal) is where the
    flank direction lies between the directions of the two chords on either side. On the smooth
    flank those chord directions are the tangents at (about) the chords' midpoints, and the
    tangent turns nearly uniformly between them, so the tangency point is found by linear
    interpolation of the tangent's normal component along M1 → V → M2. NaN when no vertex near
    ``near`` is a support vertex of the flank direction."""
    n = len(profile_world)
    height = profile_world @ normal
    i = int(np.argmin(np.linalg.norm(profile_world - near[:2], axis=1)))
    for _ in range(window):  # walk down to the local support vertex (never past the tooth)
        if 0 < i < n - 1 and height[i - 1] < height[i]:
            i -= 1
        elif 0 < i < n - 1 and height[i + 1] < height[i]:
            i += 1
        else:
            break
    if not 0 < i < n - 1:
        return math.nan
    v0, v1, v2 = profile_world[i - 1], profile_world[i], profile_world[i + 1]
    e1, e2 = v1 - v0, v2 - v1
    l1, l2 = float(np.linalg.norm(e1)), float(np.linalg.norm(e2))
    s1, s2 = float(normal @ e1) / l1, float(normal @ e2) / l2
    if not (s1 <= 0.0 <= s2) or s2 - s1 <= 0.0:
        return math.nan
    along = -s1 / (s2 - s1) * 0.5 * (l1 + l2)
    point = v0 + e1 * (0.5 + along / l1) if along <= 0.5 * l1 else v1 + e2 * ((along - 0.5 * l1) / l2)
    return float(up @ (point - corner))


# =============================================================================================
# Sweep tasks (run in workers: numpy + fcl only)
# =============================================================================================

class _Probe:
    """The scene with the pinion/rack poses set from angle and travel, counting FCL queries."""

    def __init__(self, scene: Scene, kin: Kinematics):
        self.scene, self.kin, self.queries = scene, kin, 0

    def place(self, angle: float, travel: float, rack_mesh: str = RACK) -> None:
        self.scene.set_pose(PINION, self.kin.pinion(angle))
        self.scene.set_pose(rack_mesh, self.kin.rack(travel))

    def hits(self, angle: float, travel: float, rack_mesh: str = RACK) -> bool:
        self.place(angle, travel, rack_mesh)
        self.queries += 1
        return self.scene.collide(PINION, rack_mesh)

    def distance(self, angle: float, travel: float, rack_mesh: str = RACK):
        self.place(angle, travel, rack_mesh)
        self.queries += 1
        return self.scene.distance(PINION, rack_mesh)


def _pusher(sense: int) -> str:
    """Rack faces a tooth pushes when it drives the rack towards ``sense`` (±x)."""
    return RACK_FACING_MINUS_X if sense > 0 else RACK_FACING_PLUS_X


def _smallest_clearing_move(hits_at, reach: float, predicted: float, tol: float) -> float | None:
    """Smallest move d in (0, reach] with ``hits_at(d)`` False, given ``hits_at(0)`` True:
    samples the reach upwards (the first free sample bounds the move; a jammed pose has none
    and returns None, so a part never jumps past a tooth), then bisection between the last
    colliding and the first free sample. ``predicted`` (expected from the last step) only
    narrows the first bracket when it holds."""
    if predicted > 0.0:
        near, far = max(0.995 * predicted - 2e-4, 0.0), 1.005 * predicted + 2e-4
        if far <= reach and not hits_at(far) and (near == 0.0 or hits_at(near)):
            return bisect_contact(hits_at, far, near, tol).free
    previous = 0.0
    for i in range(1, REACH_SAMPLES + 1):
        d = reach * i / REACH_SAMPLES
        if not hits_at(d):
            return bisect_contact(hits_at, d, previous, tol).free
        previous = d
    return None


def _push_rack(probe: _Probe, angle: float, travel: float, sense: int, reach: float,
               predicted: float = 0.0) -> tuple[float, bool]:
    """Rack travel after the pinion turns to ``angle``: unchanged when the faces a tooth can push
    are clear, else the smallest advance (towards ``sense``, at most ``reach``) that clears them;
    unchanged (jammed, reported as interference) when no advance within reach does."""
    faces = _pusher(sense)
    if not probe.hits(angle, travel, faces):
        return travel, False
    move = _smallest_clearing_move(lambda d: probe.hits(angle, travel + sense * d, faces), reach, predicted,
                                   TRAVEL_BISECT_TOL_MM)
    return (travel, False) if move is None else (travel + sense * move, True)


def _turn_pinion(probe: _Probe, angle: float, travel: float, sense: int, reach: float,
                 predicted: float = 0.0) -> tuple[float, bool]:
    """Pinion angle after the rack moves to ``travel`` (power mode, the rack pushing towards
    ``sense``): unchanged when clear, else the smallest turn (also towards ``sense``, at most
    ``reach``) that clears the rack's driving flanks (those facing ``sense``)."""
    faces = _pusher(-sense)
    if not probe.hits(angle, travel, faces):
        return angle, False
    move = _smallest_clearing_move(lambda d: probe.hits(angle + sense * d, travel, faces), reach, predicted,
                                   ANGLE_BISECT_TOL_RAD)
    return (angle, False) if move is None else (angle + sense * move, True)


def _shift_to_clear(probe: _Probe, angle: float, travel: float, faces: str, sense: int, start: float, limit: float) -> float:
    """Smallest rack shift towards ``sense`` that clears ``faces`` (upper end of the bracket)."""
    span = start
    while probe.hits(angle, travel + sense * span, faces):
        span *= 2.0
        if span > limit:
            return limit
    return bisect_contact(lambda d: probe.hits(angle, travel + sense * d, faces), span, 0.0, TRAVEL_BISECT_TOL_MM).free


def _shift_to_contact(probe: _Probe, angle: float, travel: float, faces: str, sense: int, start: float, limit: float) -> float:
    """Smallest rack shift towards ``sense`` that makes ``faces`` touch the pinion (upper end of
    the bracket; ``limit`` when no contact is reached within it)."""
    span = start
    while not probe.hits(angle, travel + sense * span, faces):
        span *= 2.0
        if span > limit:
            return limit
    return bisect_contact(lambda d: probe.hits(angle, travel + sense * d, faces), 0.0, span, TRAVEL_BISECT_TOL_MM).touching


def signed_clearance(probe: _Probe, angle: float, travel: float, tol: float, limit: float, in_contact: bool = False) -> float:
    """Mesh distance between the walls when clear (0 when ``in_contact``: the pose was just
    bisected to contact, so the distance is within the bisection tolerance and is not measured
    again); when they collide, minus the depth measured as the rack shifts along its travel that
    clear the left- and the right-facing flanks (an upper bound of the normal depth), or, for a
    hit on faces that do not face the travel (tops), the drop of the rack that clears it."""
    if not probe.hits(angle, travel):
        return 0.0 if in_contact else probe.distance(angle, travel).distance
    depth = 0.0
    for sense in (+1, -1):
        faces = _pusher(sense)
        if probe.hits(angle, travel, faces):
            depth += _shift_to_clear(probe, angle, travel, faces, sense, tol, limit)
    if depth == 0.0:
        kin = probe.kin

        def hits_lowered(d: float) -> bool:
            probe.scene.set_pose(PINION, kin.pinion(angle))
            pose = kin.rack(travel)
            pose[1, 3] -= d
            probe.scene.set_pose(RACK, pose)
            probe.queries += 1
            return probe.scene.collide(PINION, RACK)

        span = tol
        while hits_lowered(span) and span < limit:
            span *= 2.0
        depth = bisect_contact(hits_lowered, span, 0.0, TRAVEL_BISECT_TOL_MM).free if span < limit else limit
    return -depth


def _swing(probe: _Probe, angles: np.ndarray, travel: float, sense: int, reach_rate: float, tol: float, limit: float):
    travels, pushed, clearance = [], [], []
    rate = 0.0  # last push per radian, for the next first bracket
    for i, angle in enumerate(angles):
        step = abs(angle - angles[i - 1]) if i else abs(angles[1] - angles[0])
        before = travel
        travel, moved = _push_rack(probe, float(angle), travel, sense, reach_rate * step + tol, rate * step)
        rate = abs(travel - before) / step if moved and step > 0 else 0.0
        travels.append(travel)
        pushed.append(moved)
        clearance.append(signed_clearance(probe, float(angle), travel, tol, limit, moved))
    return np.array(travels), np.array(pushed), np.array(clearance)


def _extrapolated_event(angles: np.ndarray, on_grid, predicate_at, tol: float, first: bool):
    """Angle where ``predicate_at(δ, φ)`` starts holding (first=True: its first False → True along
    ``angles``) or stops (its last True → False), bracketed on the grid by ``on_grid(δ)`` (flags
    per grid angle) and bisected, at δ = tol and 2·tol, then extrapolated linearly to δ = 0.
    Returns the angle and the bracket at δ = tol."""
    values = []
    for delta in (tol, 2.0 * tol):
        flags = on_grid(delta)
        if first:
            hit = np.flatnonzero(flags)
            if not hit.size or hit[0] == 0:
                return math.nan, None
            i = int(hit[0])
            bracket = bisect_contact(lambda a: predicate_at(delta, a), float(angles[i - 1]), float(angles[i]), EVENT_ANGLE_TOL_RAD)
        else:
            hit = np.flatnonzero(flags)
            if not hit.size or hit[-1] == len(angles) - 1:
                return math.nan, None
            i = int(hit[-1])
            bracket = bisect_contact(lambda a: predicate_at(delta, a), float(angles[i + 1]), float(angles[i]), EVENT_ANGLE_TOL_RAD)
        values.append(bracket)
    return 2.0 * values[0].value - values[1].value, values[0]


def towing_task(scene: Scene, kin: Kinematics, direction: int, angles: np.ndarray, tol: float, reach_rate: float, limit: float) -> dict:
    """Both towing swings in one direction (angles 0 → ±max, magnitudes increasing) and their
    events. Module-level so that :func:`map_scene` can run it in a worker."""
    t0, c0 = time.perf_counter(), time.process_time()
    probe = _Probe(scene, kin)
    out = direction * np.asarray(angles, float)
    travel_out, pushed_out, clear_out = _swing(probe, out, 0.0, direction, reach_rate, tol, limit)
    stand = float(travel_out[-1])
    back = out[::-1]
    travel_back, pushed_back, clear_back = _swing(probe, back, stand, -direction, reach_rate, tol, limit)
    faces = _pusher(direction)

    # Disengage: the pinion reaches the rack held δ short of its standing travel.
    def touches_short(delta: float, angle: float) -> bool:
        return probe.hits(angle, stand - direction * delta, faces)

    def grid_short(delta: float) -> np.ndarray:
        return direction * (travel_out - (stand - direction * delta)) >= 0.0

    disengage, dis_bracket = _extrapolated_event(out, grid_short, touches_short, tol, first=True)
    i_dis = int(np.searchsorted(np.abs(out), abs(disengage))) if math.isfinite(disengage) else len(out)
    creep = float(np.max(np.abs(travel_out[i_dis:] - stand))) if i_dis < len(out) else math.nan

    # Grazing end: where the pinion no longer touches the rack held δ short (after the stop).
    standing = np.arange(len(out)) >= i_dis

    def grid_graze(delta: float) -> np.ndarray:
        return standing & np.array([touches_short(delta, float(a)) if s else False for a, s in zip(out, standing)])

    graze_end, _ = _extrapolated_event(out, grid_graze, touches_short, tol, first=False)

    # Closest approach past the disengage, and the rack shift that brings it to contact.
    worst = {}
    if i_dis < len(out):
        j = i_dis + int(np.argmin(clear_out[i_dis:]))
        angle, travel = float(out[j]), float(travel_out[j])
        d = probe.distance(angle, travel)
        shift = _shift_to_contact(probe, angle, travel, faces, -direction, tol / 8.0, limit)
        worst = {"angle": angle, "travel": travel, "distance": d.distance, "contact_shift": shift,
                 "point_pinion": d.point_a, "point_rack": d.point_b}

    # Re-engage: the return swing first touches the standing rack's other flanks.
    reengage, re_bracket = math.nan, None
    moved = np.flatnonzero(pushed_back)
    if moved.size and moved[0] > 0:
        i = int(moved[0])
        back_faces = _pusher(-direction)
        re_bracket = bisect_contact(lambda a: probe.hits(a, stand, back_faces), float(back[i - 1]), float(back[i]), EVENT_ANGLE_TOL_RAD)
        reengage = re_bracket.value

    return {
        "direction": direction, "angles_out": out, "travel_out": travel_out, "pushed_out": pushed_out,
        "clearance_out": clear_out, "angles_back": back, "travel_back": travel_back, "pushed_back": pushed_back,
        "clearance_back": clear_back, "stand": stand, "disengage": disengage,
        "disengage_bracket": None if dis_bracket is None else (dis_bracket.free, dis_bracket.touching),
        "creep": creep, "graze_end": graze_end, "worst": worst, "reengage": reengage,
        "reengage_bracket": None if re_bracket is None else (re_bracket.free, re_bracket.touching),
        "queries": probe.queries, "seconds": time.perf_counter() - t0, "cpu_seconds": time.process_time() - c0,
    }


def power_task(scene: Scene, kin: Kinematics, direction: int, travels: np.ndarray, tol: float, reach_rate: float,
               limit: float, profile: np.ndarray, corner: np.ndarray, normal: np.ndarray, up: np.ndarray,
               pitch: float) -> dict:
    """Power mode in one direction: the rack advances through ``travels`` (magnitudes increasing)
    and drives the pinion; the contact position on the first rack tooth's driving flank relative
    to its top corner (S6) at each pose, and the travel where it reaches the corner."""
    t0, c0 = time.perf_counter(), time.process_time()
    probe = _Probe(scene, kin)
    faces = _pusher(-direction)  # the rack's flanks facing the way it drives

    def corner_at(travel: float) -> np.ndarray:
        return (kin.rack(travel) @ np.array([corner[0], corner[1], 0.0, 1.0]))[:2]

    def contact(angle: float, travel: float):
        d = probe.distance(angle, travel, faces)
        pose = kin.pinion(angle)
        world = profile @ pose[:2, :2].T + pose[:2, 3]
        corner_w = corner_at(travel)
        at_corner = float(np.linalg.norm(d.point_b[:2] - corner_w)) < 1e-6
        return d, tangency_offset(world, d.point_a, normal, corner_w, up), at_corner

    travels = direction * np.asarray(travels, float)
    angle, rate = 0.0, 0.0
    angles, clear, offsets, corner_flags = [], [], [], []
    for i, travel in enumerate(travels):
        step = abs(travel - travels[i - 1]) if i else abs(travels[1] - travels[0])
        before = angle
        angle, moved = _turn_pinion(probe, angle, float(travel), direction, reach_rate * (step + tol), rate * step)
        rate = abs(angle - before) / step if moved and step > 0 else 0.0
        angles.append(angle)
        clear.append(signed_clearance(probe, angle, float(travel), tol, limit, moved))
        offset, at_corner = math.nan, False
        if abs(corner_at(float(travel))[0]) < 2.0 * pitch:  # the first rack tooth is in mesh
            d, offset, at_corner = contact(angle, float(travel))
            if float(np.linalg.norm(d.point_b[:2] - corner_at(float(travel)))) > 0.5 * pitch:
                offset = math.nan  # the contact is on another tooth
        offsets.append(offset)
        corner_flags.append(at_corner)
    angles_a, offsets_a = np.array(angles), np.array(offsets)

    # The limit: the tangency point reaches the corner (offset 0), bisection on the travel.
    limit_travel = limit_angle = math.nan
    bracket = None
    crossing = np.flatnonzero((offsets_a[:-1] < 0.0) & (offsets_a[1:] >= 0.0))
    if crossing.size:
        i = int(crossing[0])
        lo_travel, lo_angle = float(travels[i]), float(angles_a[i])
        state = {}

        def reached(travel: float) -> bool:
            a, _ = _turn_pinion(probe, lo_angle, travel, direction, reach_rate * (abs(travel - lo_travel) + tol))
            _, offset, _ = contact(a, travel)
            state[travel] = a
            return offset >= 0.0

        # bisect_contact's vocabulary: "free" = offset still negative, "touching" = reached
        bracket = bisect_contact(reached, lo_travel, float(travels[i + 1]), EVENT_TRAVEL_TOL_MM)
        limit_travel = bracket.value
        limit_angle = 0.5 * (state.get(bracket.free, lo_angle) + state.get(bracket.touching, float(angles_a[i + 1])))
    raw = np.flatnonzero(corner_flags)
    raw_angle = float(angles_a[raw[0]]) if raw.size else math.nan
    return {
        "direction": direction, "travels": travels, "angles": angles_a, "clearance": np.array(clear),
        "offsets": offsets_a, "at_corner": np.array(corner_flags), "limit_travel": limit_travel,
        "limit_angle": limit_angle, "limit_bracket": None if bracket is None else (bracket.free, bracket.touching),
        "raw_corner_angle": raw_angle, "queries": probe.queries, "seconds": time.perf_counter() - t0, "cpu_seconds": time.process_time() - c0,
    }


# =============================================================================================
# Power-mode model (closed form, beside the push model's towing curve)
# =============================================================================================

def _power_corner(g) -> tuple[float, float, float]:
    """S6 of the first rack tooth: x in the rack frame, height, and the travel at which it leaves
    the pinion's tip circle (the pinion is released)."""
    x0 = g.rack_first_tooth * g.pitch + float(g.rack_half_width(g.hS6_mm))
    dy = g.centre_to_datum_mm - g.hS6_mm
    return x0, dy, math.sqrt(g.tip_radius ** 2 - dy ** 2) - x0


def power_model_angle(g, travel: float) -> float:
    """Pinion angle driven by the rack (φ > 0, L > 0): conjugate L/r up to the S6 engagement
    (eq 19); beyond it the corner S6 = (k·p + L + w(hS6), hS6) rides on the left involute flank of
    pinion tooth j = k (k = rack.first_tooth): φ = γ(S6) + β(ρ(S6)) − (j + ½)·τ, until S6 leaves
    the tip circle and the pinion stops."""
    k = g.rack_first_tooth
    if travel <= an.phi_power_conjugate_end(g, k, g.hS6_mm) * g.pitch_radius:
        return travel / g.pitch_radius
    x0, dy, release = _power_corner(g)
    x = x0 + min(travel, release)
    rho = math.hypot(x, dy)
    return math.atan2(x, dy) + float(g.involute_half_angle(rho)) - (k + 0.5) * g.angular_pitch


def power_model_travel(g, angle: float) -> float:
    """Inverse of :func:`power_model_angle`: the rack travel that has driven the pinion to
    ``angle`` (NaN at or past the release, where any further travel gives the same angle)."""
    end = an.phi_power_conjugate_end(g, g.rack_first_tooth, g.hS6_mm)
    if angle <= end:
        return angle * g.pitch_radius
    release = _power_corner(g)[2]
    if angle >= power_model_angle(g, release):
        return math.nan
    return float(brentq(lambda t: power_model_angle(g, t) - angle, end * g.pitch_radius, release, xtol=1e-10))


# =============================================================================================
# The check
# =============================================================================================

def _deg(x: float) -> float:
    return math.degrees(x)


def _sign(direction: int) -> str:
    return "+" if direction > 0 else "−"


@dataclass(frozen=True)
class _Setup:
    """What the sweep needs, prepared from the template and the bodies."""

    g: object  # RackPinionGeometry (the drawing)
    kin: Kinematics
    meshes: list
    mesh_info: dict
    bound: float  # sum of the two meshes' error bounds
    tol: float  # contact tolerance
    limit: float  # deepest shift searched when measuring an overlap
    angles: np.ndarray  # towing grid, magnitudes (rad)
    travels: np.ndarray  # power grid, magnitudes (mm)
    reach_travel_per_rad: float
    reach_angle_per_mm: float
    profile: np.ndarray  # pinion outline from the mesh (own frame)
    corner: np.ndarray  # S6 of the first rack tooth (rack frame, + direction)
    normal: np.ndarray  # outward normal of its driving (right) flank
    up: np.ndarray  # along that flank towards S6


def _prepare(params, bodies: dict[str, Body], towing_step_deg: float, power_step_deg: float, tow_model) -> _Setup:
    g = an.geometry_from_params(params)
    pinion, rack = bodies[PINION], bodies[RACK]
    bound = pinion.error_bound_mm + rack.error_bound_mm
    kin = Kinematics.from_bodies(pinion, rack)
    centre_height = float(kin.pinion_origin[1])
    flanks = rack_flank_faces(g, rack.mesh)
    meshes, mesh_info = sweep_meshes(pinion, rack, centre_height, flanks)
    tip = float(np.hypot(pinion.mesh.vertices[:, 0], pinion.mesh.vertices[:, 1]).max())
    rack_top = float(rack.mesh.vertices[:, 1].max())

    # S6 as drawn must be a vertex of the rack mesh; the driving flank's normal comes from the
    # mesh triangles at that vertex.
    corner = np.asarray(g.trim_corners(0.0)["S6"], float)
    rv, rf = rack.mesh.vertices, rack.mesh.faces
    if float(np.min(np.hypot(rv[:, 0] - corner[0], rv[:, 1] - corner[1]))) > 1e-6:
        raise ValueError("the rack mesh has no vertex at the S6 corner of the drawing")
    nr = _normals(rack.mesh)
    touches = np.any(np.hypot(rv[rf][..., 0] - corner[0], rv[rf][..., 1] - corner[1]) < 1e-6, axis=1)
    facing = np.flatnonzero(touches & flanks[1])
    a = g.pressure_angle_rad
    normal = nr[facing[0], :2] / np.linalg.norm(nr[facing[0], :2]) if facing.size else np.array([math.cos(a), math.sin(a)])
    up = np.array([-normal[1], normal[0]])
    up = up if up[1] > 0 else -up

    max_deg = params.towing.max_angle_deg
    angles = an.towing_grid(max_deg, towing_step_deg, an.CHECK_ANGLES_DEG + (an.PAPER["adams_disengage_deg"],))
    # power mode over the towing stroke of the model (past the S6 limit, short of the release)
    stroke = float(tow_model.forward.travel_mm[-1])
    n_power = max(int(math.ceil(math.degrees(stroke / g.pitch_radius) / power_step_deg)), 2)
    return _Setup(
        g=g, kin=kin, meshes=meshes, mesh_info=mesh_info, bound=bound, tol=max(CONTACT_TOL_MM, bound),
        limit=0.5 * g.pitch, angles=angles, travels=np.linspace(0.0, stroke, n_power + 1),
        reach_travel_per_rad=tip * an.PUSH_RATE_PER_TIP_RADIUS, reach_angle_per_mm=REACH_MARGIN / (centre_height - rack_top),
        profile=pinion_profile(pinion.mesh), corner=corner, normal=normal, up=up,
    )


def _run_tasks(su: _Setup, progress, workers) -> list[dict]:
    mirror = np.array([-1.0, 1.0])
    tasks = [(towing_task, (su.kin, d, su.angles, su.tol, su.reach_travel_per_rad, su.limit)) for d in (+1, -1)]
    tasks += [(power_task, (su.kin, d, su.travels, su.tol, su.reach_angle_per_mm, su.limit, su.profile,
                            su.corner * m, su.normal * m, su.up * m, su.g.pitch))
              for d, m in ((+1, np.ones(2)), (-1, mirror))]
    sizes = iter([2 * len(su.angles)] * 2 + [len(su.travels)] * 2)  # poses per task, for the progress bar
    return map_scene(_dispatch, su.meshes, tasks, workers=workers,
                     progress=(lambda _n: progress(next(sizes))) if progress else None)


def _towing_rows(g, tow: dict) -> tuple[list[dict], dict, dict]:
    """Rows of both towing swings with the push model's travel at the same angles."""
    rows, deviation, curves = [], {}, {}
    for d, r in tow.items():
        out = an.sweep(g, r["angles_out"], 0.0, d)
        back = an.sweep(g, r["angles_back"], float(out.travel_mm[-1]), -d)
        curves[d] = {"out": out.travel_mm, "back": back.travel_mm}
        dev = []
        for swing in ("out", "back"):
            for a_, l_g, l_m, c in zip(r[f"angles_{swing}"], r[f"travel_{swing}"], curves[d][swing], r[f"clearance_{swing}"]):
                rows.append(_row("towing", d, swing, a_, l_g, l_m, c))
                dev.append(l_g - l_m)
        deviation[d] = float(np.max(np.abs(dev)))
    return rows, deviation, curves


def _power_rows(g, power: dict) -> tuple[list[dict], dict]:
    """Rows of power mode with the model's travel at the pinion angle the mesh gave."""
    rows, deviation = [], {}
    for d, r in power.items():
        dev = []
        for l_g, a_, c in zip(r["travels"], r["angles"], r["clearance"]):
            l_m = d * power_model_travel(g, d * a_)
            rows.append(_row("power", d, "drive", a_, l_g, l_m, c))
            dev.append(l_g - l_m)
        deviation[d] = float(np.nanmax(np.abs(dev)))
    return rows, deviation


def _direction_summary(r: dict, p: dict, towing_dev: float, power_dev: float) -> dict:
    """Geometry figures of one direction (angle and travel magnitudes)."""
    i_dis = int(np.searchsorted(np.abs(r["angles_out"]), abs(r["disengage"]))) if math.isfinite(r["disengage"]) else len(r["angles_out"])
    past = r["clearance_out"][i_dis:]
    w = r["worst"]
    return {
        "geom_disengage_angle_deg": abs(_deg(r["disengage"])),
        "geom_rack_travel_at_disengage_mm": abs(r["stand"]),
        "geom_rack_motion_after_disengage_mm": r["creep"],
        "geom_grazing_span_deg": abs(_deg(r["graze_end"] - r["disengage"])),
        "geom_reengage_angle_deg": abs(_deg(r["reengage"])),
        # contact proven from both sides: (free, touching) pinion angles of the brackets (disengage:
        # the pinion reaching the rack held one contact tolerance short of its stand)
        "geom_disengage_bracket_at_tol_deg": [abs(_deg(a)) for a in r["disengage_bracket"] or (math.nan, math.nan)],
        "geom_reengage_bracket_deg": [abs(_deg(a)) for a in r["reengage_bracket"] or (math.nan, math.nan)],
        "geom_continuous_angle_deg": abs(_deg(p["limit_angle"])),
        "geom_rack_travel_at_continuous_limit_mm": abs(p["limit_travel"]),
        "geom_raw_corner_contact_angle_deg": abs(_deg(p["raw_corner_angle"])),
        "max_towing_curve_deviation_mm": towing_dev,
        "max_power_curve_deviation_mm": power_dev,
        "min_signed_clearance_mm": float(min(np.min(r["clearance_out"]), np.min(r["clearance_back"]), np.min(p["clearance"]))),
        "min_clearance_past_disengage_mm": float(np.min(past)) if past.size else math.nan,
        "min_clearance_return_swing_mm": float(np.min(r["clearance_back"])),
        "graze_distance_mm": w.get("distance", math.nan),
        "graze_angle_deg": abs(_deg(w.get("angle", math.nan))),
        "graze_contact_shift_mm": w.get("contact_shift", math.nan),
    }


@dataclass(frozen=True)
class _Model:
    """The analytic figures beside the mesh (``analysis``)."""

    disengage_deg: float
    stand_mm: float
    graze_deg: float
    reengage_deg: float
    continuous_deg: float  # min(towing S1, power S6)
    power_limit_deg: float  # S6 (eq 19)
    s1_deg: float  # towing conjugate end (eq 17)

    @classmethod
    def of(cls, g, tow) -> "_Model":
        return cls(_deg(tow.disengage_rad), tow.travel_at_disengage_mm, _deg(tow.grazing_end_rad - tow.disengage_rad),
                   _deg(tow.reengage_rad), _deg(min(an.continuous_towing_angle(g), an.continuous_power_angle(g))),
                   _deg(an.continuous_power_angle(g)), _deg(an.phi_towing_conjugate_end(g, g.sector_first_tooth)))


def _verdicts(params, plus: dict, minus: dict, model: _Model, tol: float, poses: int) -> list[Verdict]:
    both = (plus, minus)

    def each(key):
        return [s[key] for s in both]

    def ok(values, test):
        return all(math.isfinite(v) and test(v) for v in values)

    target, max_deg = params.targets.continuous_angle_deg, params.towing.max_angle_deg
    cont, dis, creep = each("geom_continuous_angle_deg"), each("geom_disengage_angle_deg"), each("geom_rack_motion_after_disengage_mm")
    past, ret, re = each("min_clearance_past_disengage_mm"), each("min_clearance_return_swing_mm"), each("geom_reengage_angle_deg")
    clear, shifts, dev = each("min_signed_clearance_mm"), each("graze_contact_shift_mm"), each("max_towing_curve_deviation_mm")
    return [
        Verdict("continuous_drive", f"power mode drives continuously to ≥ {target:g}° (targets.continuous_angle_deg)",
                ok(cont, lambda c: c >= target),
                f"contact reaches S6 at +{cont[0]:.3f}° / −{cont[1]:.3f}° (model {model.power_limit_deg:.3f}°)"),
        Verdict("rack_stops", f"towing: the rack stops before ±{max_deg:g}° and stands to the end of the swing",
                ok(dis, lambda d: d < max_deg) and ok(creep, lambda c: c <= tol),
                f"stops at +{dis[0]:.3f}° / −{dis[1]:.3f}°, moves ≤ {max(creep):.4f} mm after (contact tolerance {tol:.3f} mm)"),
        Verdict("no_interference_past_disengage", "towing: no interference past the disengage (G1's tip land grazes S2)",
                ok(past, lambda c: c >= -tol),
                f"min signed clearance {min(past):.5f} mm ≥ −{tol:.3f} mm; contact reached {max(shifts):.5f} mm of rack shift away"),
        Verdict("no_interference_reengage", "towing: no interference on the return swing and re-engagement",
                ok(ret, lambda c: c >= -tol) and ok(re, lambda x: True),
                f"min signed clearance {min(ret):.5f} mm ≥ −{tol:.3f} mm; picked up at +{re[0]:.3f}° / −{re[1]:.3f}° "
                f"(free at {plus['geom_reengage_bracket_deg'][0]:.6f}°, touching at {plus['geom_reengage_bracket_deg'][1]:.6f}°)"),
        Verdict("no_interference_anywhere", "no interference at any pose (towing both ways, power mode)",
                ok(clear, lambda c: c >= -tol), f"min signed clearance {min(clear):.5f} mm ≥ −{tol:.3f} mm over {poses} poses"),
        Verdict("towing_curve", f"towing curve within {TOWING_CURVE_TOL_MM:g} mm of the analytic push model",
                ok(dev, lambda d: d <= TOWING_CURVE_TOL_MM),
                f"max |L_mesh − L_model| = {max(dev):.4f} mm (+: {dev[0]:.4f}, −: {dev[1]:.4f})"),
    ]


def paper_figures(params) -> dict:
    """The paper's figures for the paper's design, else all None (:func:`an.is_paper_design`)."""
    return dict(an.PAPER) if an.is_paper_design(params) else dict.fromkeys(an.PAPER)


def _comparisons(P: dict, plus: dict, model: _Model, travel_at_adams: float, max_dev: float) -> list[Comparison]:
    dis, stand, cont = plus["geom_disengage_angle_deg"], plus["geom_rack_travel_at_disengage_mm"], plus["geom_continuous_angle_deg"]
    return [
        Comparison("disengage angle (rack stops), theory", "deg", P["disengage_deg"], model.disengage_deg, dis,
                   "paper adds −(hS2 − h)·tanα/r to the angle (75.33 with it)"),
        Comparison("disengage angle, ADAMS simulation", "deg", P["adams_disengage_deg"], model.disengage_deg, dis,
                   f"ADAMS's point lies on the curve (mesh L(75.89°) = {travel_at_adams:.3f}); its 'stop' is a threshold on a flattening curve"),
        Comparison("disengage angle, test", "deg", P["test_disengage_deg"], model.disengage_deg, dis,
                   "backlash, deflection and build errors are not in the model (expect ±2–3°)"),
        Comparison("rack travel at disengage, theory (eq 22)", "mm", P["travel_disengage_mm"], model.stand_mm, stand,
                   "S1 rounded in the paper: RS1 = 84.298 gives 110.20 (dL/dRS1 = 4.2)"),
        Comparison("rack travel at disengage, ADAMS", "mm", P["adams_travel_mm"], model.stand_mm, stand,
                   f"at ADAMS's own angle the mesh curve gives {travel_at_adams:.3f}"),
        Comparison("rack travel at disengage, test", "mm", P["test_travel_mm"], model.stand_mm, stand,
                   "test rig: backlash and deflection"),
        Comparison("G1's tip land grazes S2 for", "deg", None, model.graze_deg, plus["geom_grazing_span_deg"],
                   "S2 lies on the RS1 circle by design (2·β(RS1))"),
        Comparison("re-engage angle (return swing picks the rack up)", "deg", None, model.reengage_deg,
                   plus["geom_reengage_angle_deg"], "next tooth's trailing flank meets S6; the paper prints no value"),
        Comparison("continuous drive (power mode, contact reaches S6), theory", "deg", P["phi_S6_deg"], model.continuous_deg,
                   cont, "paper used hS6 = 25.38 from its own lines (62.10° with it)"),
        Comparison("continuous drive, test", "deg", P["test_continuous_deg"], model.continuous_deg, cont,
                   "test includes backlash and deflection"),
        Comparison("raw FCL nearest point reaches S6 (diagnostic)", "deg", None, model.power_limit_deg,
                   plus["geom_raw_corner_contact_angle_deg"],
                   "vertex/flank and corner/chord contacts swap within the mesh error near the corner: ±1° ambiguity"),
        Comparison("max towing-curve deviation, mesh vs push model", "mm", None, None, max_dev,
                   f"limit {TOWING_CURVE_TOL_MM:g} mm (issue 10); mesh chords lie inside the flanks"),
    ]


def _plots(P: dict, tow: dict, power: dict, curves: dict, plus: dict, model: _Model) -> list[Plot]:
    dis, stand = plus["geom_disengage_angle_deg"], plus["geom_rack_travel_at_disengage_mm"]
    out, back = np.degrees(tow[1]["angles_out"]), np.degrees(tow[1]["angles_back"])
    stops = [("mesh stop", dis), ("model stop", model.disengage_deg), ("paper theory", P["disengage_deg"]),
             ("ADAMS", P["adams_disengage_deg"]), ("test", P["test_disengage_deg"]),
             ("mesh re-engage", plus["geom_reengage_angle_deg"])]
    near_out = (out >= dis - 16.0) & (out <= dis + 8.0)
    near_back = (back >= dis - 16.0) & (back <= dis + 8.0)
    return [
        Plot("Towing: rack travel against pinion angle (+ swing; − swing mirrored)", "pinion angle (deg)", "rack travel (mm)",
             [Series("mesh, out", list(out), list(tow[1]["travel_out"])),
              Series("mesh, back", list(back), list(tow[1]["travel_back"])),
              Series("model, out", list(out), list(curves[1]["out"]), "points"),
              Series("model, back", list(back), list(curves[1]["back"]), "points"),
              Series("mesh, − swing out (mirrored)", list(-np.degrees(tow[-1]["angles_out"])), list(-tow[-1]["travel_out"]))],
             markers=stops, hlines=[("mesh stand", stand), ("paper 110.20", P["travel_disengage_mm"])]),
        Plot("Towing near the stop (+ swing): rack travel against pinion angle", "pinion angle (deg)", "rack travel (mm)",
             [Series("mesh, out", list(out[near_out]), list(tow[1]["travel_out"][near_out])),
              Series("mesh, back", list(back[near_back]), list(tow[1]["travel_back"][near_back])),
              Series("model, out", list(out[near_out]), list(curves[1]["out"][near_out]), "points"),
              Series("model, back", list(back[near_back]), list(curves[1]["back"][near_back]), "points")],
             markers=stops + [("S1 engages (model)", model.s1_deg)],
             hlines=[("mesh stand", stand), ("paper theory 110.20", P["travel_disengage_mm"]),
                     ("ADAMS 110.05", P["adams_travel_mm"]), ("test 109.5", P["test_travel_mm"])]),
        Plot("Towing: mesh travel minus model travel, along the swing's travel", "pinion angle magnitude (deg)", "deviation (mm)",
             [Series(f"{_sign(d)} {swing}", list(np.abs(np.degrees(tow[d][f"angles_{swing}"]))),
                     list(d * (tow[d][f"travel_{swing}"] - curves[d][swing])))
              for d in (1, -1) for swing in ("out", "back")],
             hlines=[("+tolerance", TOWING_CURVE_TOL_MM), ("−tolerance", -TOWING_CURVE_TOL_MM)]),
        Plot("Power mode: driving contact position on the first rack tooth, from S6 (tangency from the mesh)",
             "pinion angle magnitude (deg)", "contact − S6 along the flank (mm)",
             [Series(f"{_sign(d)} direction", list(np.abs(np.degrees(power[d]["angles"]))), list(power[d]["offsets"]), "points")
              for d in (1, -1)],
             markers=[("mesh limit", plus["geom_continuous_angle_deg"]), ("model", model.power_limit_deg),
                      ("paper theory", P["phi_S6_deg"]), ("test", P["test_continuous_deg"]),
                      ("raw FCL corner contact", plus["geom_raw_corner_contact_angle_deg"])],
             hlines=[("S6", 0.0)]),
    ]


def _notes(P: dict, su: _Setup, plus: dict, minus: dict, model: _Model, speed: dict) -> list[str]:
    printed = (f"; paper {P['disengage_deg']}°/{P['travel_disengage_mm']} theory, {P['adams_disengage_deg']}°/"
               f"{P['adams_travel_mm']} ADAMS, {P['test_disengage_deg']:g}°/{P['test_travel_mm']} test"
               if P["disengage_deg"] is not None else "")
    return [
        f"Contact tolerance {su.tol:.3f} mm (≥ the meshes' error bound {su.bound:.3f} mm): zero-backlash flanks touch at "
        "zero clearance, so a collision is measured (the rack shift that clears it) and accepted up to this depth.",
        f"Towing: the rack stops at +{plus['geom_disengage_angle_deg']:.3f}° / −{minus['geom_disengage_angle_deg']:.3f}° "
        f"at {plus['geom_rack_travel_at_disengage_mm']:.3f} mm (model {model.disengage_deg:.3f}°, {model.stand_mm:.3f} mm"
        f"{printed}).",
        f"Past the stop G1's tip land grazes S2 (closest {plus['graze_distance_mm']:.2e} mm at {plus['graze_angle_deg']:.2f}°; "
        f"the rack reaches contact {plus['graze_contact_shift_mm']:.5f} mm further back) for {plus['geom_grazing_span_deg']:.2f}° "
        f"(model {model.graze_deg:.2f}°); the standing rack creeps ≤ {plus['geom_rack_motion_after_disengage_mm']:.4f} mm as "
        "the tip land's chord vertices pass S2.",
        f"The return swing picks the rack up at {plus['geom_reengage_angle_deg']:.3f}° (model {model.reengage_deg:.3f}°).",
        f"Power mode: the contact reaches S6 at {plus['geom_continuous_angle_deg']:.3f}° / {minus['geom_continuous_angle_deg']:.3f}° "
        f"(model {model.power_limit_deg:.3f}°). The raw FCL nearest point reaches the corner at "
        f"{plus['geom_raw_corner_contact_angle_deg']:.2f}° / {minus['geom_raw_corner_contact_angle_deg']:.2f}°: a polygonal flank's "
        "vertex/chord ambiguity, which the tangency estimate removes.",
        f"Speed: {speed['poses']} poses, {speed['fcl_queries']} FCL queries in {speed['elapsed_s']:.1f} s "
        f"({speed['poses_per_s']:.0f} poses/s, {speed['fcl_queries_per_s']:.0f} queries/s wall; "
        f"{speed['poses_per_cpu_s']:.0f} poses and {speed['fcl_queries_per_cpu_s']:.0f} queries per CPU-second); pinion walls swept "
        f"{su.mesh_info['pinion_triangles_swept']} of {su.mesh_info['pinion_triangles_total']} triangles.",
    ]


def run_check(params, bodies: dict[str, Body], progress=None, *, towing_step_deg: float = TOWING_STEP_DEG,
              power_step_deg: float = POWER_STEP_DEG, workers: int | None = None) -> CheckResult:
    """Towing (both swings, both directions) and power mode on the built meshes; see the module
    docstring. ``bodies``: "pinion" and "rack" (meshes in their own frames, poses as built at
    angle 0 / travel 0, motions: rotation about the pinion axis, translation along the rack)."""
    t_start = time.perf_counter()
    P = an.PAPER
    paper = paper_figures(params)
    g = an.geometry_from_params(params)
    tow_model = an.analyse_towing(g, params.towing.max_angle_deg, extra_deg=an.CHECK_ANGLES_DEG + (P["adams_disengage_deg"],))
    model = _Model.of(g, tow_model)
    su = _prepare(params, bodies, towing_step_deg, power_step_deg, tow_model)
    results = _run_tasks(su, progress, workers)
    tow = {r["direction"]: r for r in results[:2]}
    power = {r["direction"]: r for r in results[2:]}
    elapsed = time.perf_counter() - t_start

    rows, towing_dev, curves = _towing_rows(g, tow)
    power_rows, power_dev = _power_rows(g, power)
    rows += power_rows
    plus, minus = (_direction_summary(tow[d], power[d], towing_dev[d], power_dev[d]) for d in (+1, -1))
    queries = sum(r["queries"] for r in results)
    speed = {"poses": len(rows), "fcl_queries": queries, "elapsed_s": elapsed, "poses_per_s": len(rows) / elapsed,
             "fcl_queries_per_s": queries / elapsed, "task_seconds": [float(r["seconds"]) for r in results],
             "task_cpu_seconds": [float(r["cpu_seconds"]) for r in results]}
    speed["poses_per_cpu_s"] = len(rows) / sum(speed["task_cpu_seconds"])
    speed["fcl_queries_per_cpu_s"] = queries / sum(speed["task_cpu_seconds"])
    verdicts = _verdicts(params, plus, minus, model, su.tol, len(rows))
    passed = all(v.passed for v in verdicts)

    summary = {
        **plus,
        "model_disengage_angle_deg": model.disengage_deg,
        "paper_disengage_angle_deg": P["disengage_deg"],
        "paper_adams_disengage_angle_deg": P["adams_disengage_deg"],
        "paper_test_disengage_angle_deg": P["test_disengage_deg"],
        "model_rack_travel_at_disengage_mm": model.stand_mm,
        "paper_rack_travel_at_disengage_mm": P["travel_disengage_mm"],
        "paper_adams_rack_travel_mm": P["adams_travel_mm"],
        "paper_test_rack_travel_mm": P["test_travel_mm"],
        "model_grazing_span_deg": model.graze_deg,
        "model_reengage_angle_deg": model.reengage_deg,
        "model_continuous_angle_deg": model.continuous_deg,
        "paper_continuous_angle_deg": P["phi_S6_deg"],
        "paper_test_continuous_angle_deg": P["test_continuous_deg"],
        "max_towing_curve_deviation_mm": max(towing_dev.values()),
        "min_signed_clearance_mm": min(plus["min_signed_clearance_mm"], minus["min_signed_clearance_mm"]),
        "contact_tolerance_mm": su.tol,
        "mesh_error_bound_mm": su.bound,
        "minus": minus,
        "poses": speed["poses"],
        "fcl_queries": speed["fcl_queries"],
        **su.mesh_info,
        "verdict_pass": int(passed),
    }

    out_deg = np.degrees(tow[1]["angles_out"])
    travel_at_adams = float(tow[1]["travel_out"][int(np.argmin(np.abs(out_deg - P["adams_disengage_deg"])))])
    worst_poses = [
        WorstPose(f"towing {_sign(d)}: closest approach past the disengage (G1's tip land over S2)", PINION, RACK,
                  su.kin.pinion(w["angle"]).tolist(), su.kin.rack(w["travel"]).tolist(), float(w["distance"]))
        for d in (+1, -1) if (w := tow[d]["worst"])
    ]
    return CheckResult(SECTION, summary, verdicts, rows,
                       _comparisons(paper, plus, model, travel_at_adams, summary["max_towing_curve_deviation_mm"]),
                       _plots(paper, tow, power, curves, plus, model), _notes(paper, su, plus, minus, model, speed), worst_poses,
                       timings={k: v for k, v in speed.items() if k not in ("poses", "fcl_queries")})


def _row(mode: str, direction: int, swing: str, angle: float, travel_geom: float, travel_model: float, clearance: float) -> dict:
    """One sweep.csv row: the pose, the rack travel from the mesh and from the model at that
    pinion angle, their difference, the FCL distance (0 in contact) and the signed clearance
    (minus the measured depth where the walls collide)."""
    return {
        "mode": mode,
        "direction": direction,
        "swing": swing,
        "pinion_angle_deg": math.degrees(float(angle)),
        "rack_travel_geom_mm": float(travel_geom),
        "rack_travel_model_mm": float(travel_model),
        "deviation_mm": float(travel_geom - travel_model),
        "min_distance_mm": max(float(clearance), 0.0),
        "signed_clearance_mm": float(clearance),
    }


def _dispatch(scene: Scene, fn, args):
    """map_scene runs module-level functions by name; this one forwards to the task."""
    return fn(scene, *args)
