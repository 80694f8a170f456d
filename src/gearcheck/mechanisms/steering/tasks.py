"""The steering sweep's worker tasks (numpy + the FCL scene only): towing and power mode in one
direction each, on the meshes of :mod:`.meshes`.

**Towing** (the pinion drives): the pinion turns 0 → ±max → 0. At each angle the rack moves only
as far as a tooth pushes it: if the rack flanks that a tooth can push (those facing against the
push; a trimmed top never pushes, the push model's rule) collide at the rack's previous travel,
the rack advances by the smallest amount that clears them, at most the model's push reach
(bisection on the travel between a colliding and a free travel: contact proven from both sides);
otherwise it stands, and a jam shows as interference. On the return swing the other flanks push
it back the same way. Events, each by bisection between grid poses:

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
the rack's driving flanks (bisection on the pinion angle, replayed around where one distance query
expects the contact and proven from both sides: :func:`_bisect_move`). The continuous-drive limit is
where the driving contact on the first rack tooth reaches its top corner S6 (eq 19): a contact
*position*, linear in the angle, never a threshold on the lag behind the conjugate ratio (that lag
grows with the square of the overshoot and hides below the mesh error). The FCL nearest points
locate the contact; because the pinion mesh is a polygon (vertices on the exact flank, chords inside
it), the raw nearest point sits on a mesh vertex and jumps by a chord (~1 mm along the flank) — and
near the corner the vertex/flank and corner/chord contacts, whose exact versions are tangent there,
swap within the mesh error, so the raw point reaches the corner up to ~1° early or late. The
position is therefore taken as the tangency point of the flank the mesh vertices describe
(:func:`gearcheck.geometry.rack_pinion_power.tangency_offset`). The limit is the travel where that
point reaches S6 (bisection on L); the raw corner contact is reported beside it.

**Interference**: at every pose the whole walls are tested. Zero backlash means the non-driving
flanks touch at zero clearance too, so a collision is measured, not just flagged: the rack shift
along its travel that clears each side (an upper bound of the normal depth), and the pose passes
when that depth is within the contact tolerance (no smaller than the sum of the two meshes' error
bounds).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bisect import Bracket, bisect, bisect_predicted, remembered
from gearcheck.geometry.rack_pinion_power import tangency_offset
from gearcheck.mechanism import Assembly
from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.mechanisms.steering.meshes import (
    PINION,
    RACK,
    RACK_FACING_MINUS_X,
    RACK_FACING_PLUS_X,
    pusher,
    rack_flank_faces,
)
from gearcheck.sweep.bodies import MeshData, submesh
from gearcheck.sweep.engine import Scene
from gearcheck.sweep.motion import Rotation, Translation
from gearcheck.sweep.tools import REACH_SAMPLES, CountedScene, clearing_distance, contact_distance, extrapolated_event

# The swept rack without the flanks named (those just bisected to contact): meshes of :func:`rest_meshes`.
REST_OF = {RACK_FACING_MINUS_X: "rack_but_left_flanks", RACK_FACING_PLUS_X: "rack_but_right_flanks"}

# Bisection tolerances.
TRAVEL_BISECT_TOL_MM = 1e-4  # rack travel where a pushed rack just clears the pinion (1/500 of the curve tolerance)
ANGLE_BISECT_TOL_RAD = 1e-8  # pinion angle where a driven pinion just clears the rack (1e-6 mm at r)
EVENT_ANGLE_TOL_RAD = 1e-7  # disengage / grazing end / re-engage angles
EVENT_TRAVEL_TOL_MM = 1e-5  # travel where the power-mode contact reaches S6
# Where one distance query puts the contact, the replayed halving asks the collide flag only within
# these margins (bisection tolerances) of it, each tried in turn, before the plain bisection.
ESTIMATE_MARGINS_TOL = (2.0, 160.0)


@dataclass(frozen=True)
class Kinematics:
    """Poses as data: the pinion turns by its motion, the rack slides by its own, each on top of
    its pose as built (angle 0, travel 0)."""

    pinion_base: np.ndarray
    pinion_motion: Rotation
    rack_base: np.ndarray
    rack_motion: Translation

    @classmethod
    def of(cls, assembly: Assembly) -> Kinematics:
        """From the assembly's part specs: a rotating pinion and a sliding rack."""
        pinion, rack = assembly.part(PINION), assembly.part(RACK)
        if not isinstance(pinion.motion, Rotation) or not isinstance(rack.motion, Translation):
            raise ValueError("steering sweep needs a rotating pinion and a sliding rack (PartSpec.motion)")
        return cls(np.asarray(pinion.pose, float), pinion.motion, np.asarray(rack.pose, float), rack.motion)

    @property
    def centre_height_mm(self) -> float:
        """Height of the pinion axis above the rack datum."""
        return float(self.pinion_motion.origin[1])

    def pinion(self, angle: float) -> np.ndarray:
        """Pinion frame → world at pinion angle φ (right-handed about the axis)."""
        return self.pinion_motion.matrix(angle) @ self.pinion_base

    def rack(self, travel: float) -> np.ndarray:
        """Rack frame → world at travel L."""
        return self.rack_motion.matrix(travel) @ self.rack_base


class _Probe:
    """The counted scene with the pinion/rack poses set from angle and travel. A body already
    at the asked angle or travel (the same bits) is left where it is: a bisection on the travel
    keeps the pinion's pose, one on the angle the rack's (the same transform, not recomputed)."""

    def __init__(self, scene: Scene, kin: Kinematics):
        self.scene, self.kin = CountedScene(scene), kin
        self._at: dict[str, str] = {}  # body → the angle or travel it is posed at (float.hex)

    @property
    def queries(self) -> int:
        return self.scene.queries

    def place(self, angle: float, travel: float, rack_mesh: str = RACK) -> None:
        key = float(angle).hex()
        if self._at.get(PINION) != key:
            self.scene.set_pose(PINION, self.kin.pinion(angle))
            self._at[PINION] = key
        key = float(travel).hex()
        if self._at.get(rack_mesh) != key:
            self.scene.set_pose(rack_mesh, self.kin.rack(travel))
            self._at[rack_mesh] = key

    def set_pose(self, name: str, pose: np.ndarray) -> None:
        """A pose not given by angle or travel."""
        self.scene.set_pose(name, pose)
        self._at.pop(name, None)

    def hits(self, angle: float, travel: float, rack_mesh: str = RACK) -> bool:
        self.place(angle, travel, rack_mesh)
        return self.scene.collide(PINION, rack_mesh)

    def distance(self, angle: float, travel: float, rack_mesh: str = RACK):
        self.place(angle, travel, rack_mesh)
        return self.scene.distance(PINION, rack_mesh)

    def turn_to_contact(self, angle: float, travel: float, rack_mesh: str, sense: int, free: float) -> float | None:
        """Where the pinion's turn, ``free`` (towards ``sense``) at this free pose, reaches contact
        with the rack, from one distance query: the gap d between the nearest points p (pinion) and q
        (rack) opens at the rate s = −sense·n·(a × (p − o)) per radian of turn (n the unit normal
        from p to q, a and o the pinion's axis and origin), so contact is expected d / s back. An
        estimate only (None when the walls touch or the gap does not close that way): the contact
        is proven by collisions (:func:`_bisect_move`)."""
        near = self.distance(angle, travel, rack_mesh)
        gap = near.point_b - near.point_a
        d = float(np.linalg.norm(gap))
        if not d > 0.0:
            return None
        motion = self.kin.pinion_motion
        axis, origin = np.asarray(motion.axis, float), np.asarray(motion.origin, float)
        rate = -sense * float(np.dot(gap / d, np.cross(axis, near.point_a - origin)))
        if not rate > 0.0:
            return None
        return free - d / rate


def _clearing_move(hits_at: Callable[[float], bool], reach: float, predicted: float, tol: float,
                   estimate_at: Callable[[float], float | None] | None = None) -> float | None:
    """:func:`gearcheck.sweep.tools.smallest_clearing_move`, the same move bit for bit in fewer
    collide calls: the same first bracket (around ``predicted`` when it holds, else between the
    last colliding and the first free of the reach's samples), then :func:`_bisect_move`."""
    if predicted > 0.0:
        near, far = max(0.995 * predicted - 2e-4, 0.0), 1.005 * predicted + 2e-4
        if far <= reach and not hits_at(far) and (near == 0.0 or hits_at(near)):
            return _bisect_move(hits_at, far, near, tol, estimate_at).free
    previous = 0.0
    for i in range(1, REACH_SAMPLES + 1):
        d = reach * i / REACH_SAMPLES
        if not hits_at(d):
            return _bisect_move(hits_at, d, previous, tol, estimate_at).free
        previous = d
    return None


def _bisect_move(hits_at: Callable[[float], bool], free: float, touching: float, tol: float,
                 estimate_at: Callable[[float], float | None] | None) -> Bracket:
    """The bracket the plain bisection ends with from [free, touching] (both ends already asked:
    free, colliding). With ``estimate_at`` (where one distance query at the free end expects the
    contact) lying strictly inside the bracket, :func:`gearcheck.geometry.bisect.bisect_predicted`
    replays the same halving, asks only the midpoints within a margin of the estimate and proves
    the final bracket from both sides; where the flag changes once over the bracket (the contact
    of a part moving into another) that is the plain bisection's bracket, bit for bit. When the
    estimate misses (no proven bracket within any margin) the plain bisection runs."""
    estimate = estimate_at(free) if estimate_at is not None else None
    hits, asked = remembered(hits_at)  # answers shared by the tries: none is asked twice
    if estimate is not None and min(free, touching) < estimate < max(free, touching):
        for m in ESTIMATE_MARGINS_TOL:
            found = bisect_predicted(hits, free, touching, tol, estimate, m * tol, asked=asked)
            if found is not None:
                return found[0]
    return bisect(hits, free, touching, tol, check_ends=False)


def _push_rack(probe: _Probe, angle: float, travel: float, sense: int, reach: float,
               predicted: float = 0.0) -> tuple[float, bool]:
    """Rack travel after the pinion turns to ``angle``: unchanged when the faces a tooth can push
    are clear, else the smallest advance (towards ``sense``, at most ``reach``) that clears them;
    unchanged (jammed, reported as interference) when no advance within reach does."""
    faces = pusher(sense)
    if not probe.hits(angle, travel, faces):
        return travel, False
    # no distance estimate: the bracket is a few tolerances wide, a distance query costs more than it saves
    move = _clearing_move(lambda d: probe.hits(angle, travel + sense * d, faces), reach, predicted,
                          TRAVEL_BISECT_TOL_MM)
    return (travel, False) if move is None else (travel + sense * move, True)


def _turn_pinion(probe: _Probe, angle: float, travel: float, sense: int, reach: float,
                 predicted: float = 0.0) -> tuple[float, bool]:
    """Pinion angle after the rack moves to ``travel`` (power mode, the rack pushing towards
    ``sense``): unchanged when clear, else the smallest turn (also towards ``sense``, at most
    ``reach``) that clears the rack's driving flanks (those facing ``sense``)."""
    faces = pusher(-sense)
    if not probe.hits(angle, travel, faces):
        return angle, False

    def estimate_at(d: float) -> float | None:
        return probe.turn_to_contact(angle + sense * d, travel, faces, sense, d)

    move = _clearing_move(lambda d: probe.hits(angle + sense * d, travel, faces), reach, predicted,
                          ANGLE_BISECT_TOL_RAD, estimate_at)
    return (angle, False) if move is None else (angle + sense * move, True)


def rest_meshes(rack: MeshData, g: RackPinionGeometry) -> list[MeshData]:
    """The swept rack (``rack``, the :data:`RACK` mesh) without its left flanks, and without its
    right flanks: :data:`REST_OF` names them by the flanks left out."""
    left, right = rack_flank_faces(g, rack)
    return [submesh(rack, REST_OF[RACK_FACING_MINUS_X], ~left), submesh(rack, REST_OF[RACK_FACING_PLUS_X], ~right)]


def signed_clearance(probe: _Probe, angle: float, travel: float, tol: float, limit: float,
                     in_contact: str | None = None) -> float:
    """Mesh distance between the walls when clear (0 when ``in_contact``: the pose was just
    bisected to contact with those rack faces, so the distance is within the bisection tolerance
    and is not measured again). The bisection proved those faces free at this very pose (its free
    end was asked), so the whole rack collides exactly when the rest of it does
    (:func:`rest_meshes`): a mesh collides when one of its triangles crosses one of the other's,
    and the faces split the rack's triangles in two — the rest is asked alone, a smaller BVH
    that does not descend to the contact just bisected. When they collide, minus the depth
    measured as the rack shifts along its travel that clear the left- and the right-facing flanks
    (an upper bound of the normal depth), or, for a hit on faces that do not face the travel
    (tops), the drop of the rack that clears it."""
    if not (probe.hits(angle, travel, REST_OF[in_contact]) if in_contact else probe.hits(angle, travel)):
        return 0.0 if in_contact else probe.distance(angle, travel).distance
    depth = 0.0
    for sense in (+1, -1):
        faces = pusher(sense)
        if probe.hits(angle, travel, faces):
            def shifted(d: float, faces: str = faces, sense: int = sense) -> bool:
                return probe.hits(angle, travel + sense * d, faces)

            depth += clearing_distance(shifted, tol, limit, TRAVEL_BISECT_TOL_MM)
    if depth == 0.0:
        kin = probe.kin

        def hits_lowered(d: float) -> bool:
            probe.set_pose(PINION, kin.pinion(angle))
            pose = kin.rack(travel)
            pose[1, 3] -= d
            probe.set_pose(RACK, pose)
            return probe.scene.collide(PINION, RACK)

        depth = clearing_distance(hits_lowered, tol, limit, TRAVEL_BISECT_TOL_MM)
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
        clearance.append(signed_clearance(probe, float(angle), travel, tol, limit, pusher(sense) if moved else None))
    return np.array(travels), np.array(pushed), np.array(clearance)


def towing_task(scene: Scene, kin: Kinematics, direction: int, angles: np.ndarray, tol: float, reach_rate: float,
                limit: float) -> dict:
    """Both towing swings in one direction (angles 0 → ±max, magnitudes increasing) and their
    events (see the module docstring)."""
    t0, c0 = time.perf_counter(), time.process_time()
    probe = _Probe(scene, kin)
    out = direction * np.asarray(angles, float)
    travel_out, pushed_out, clear_out = _swing(probe, out, 0.0, direction, reach_rate, tol, limit)
    stand = float(travel_out[-1])
    back = out[::-1]
    travel_back, pushed_back, clear_back = _swing(probe, back, stand, -direction, reach_rate, tol, limit)
    faces = pusher(direction)

    # Disengage: the pinion reaches the rack held δ short of its standing travel.
    def touches_short(delta: float, angle: float) -> bool:
        return probe.hits(angle, stand - direction * delta, faces)

    def grid_short(delta: float) -> np.ndarray:
        return direction * (travel_out - (stand - direction * delta)) >= 0.0

    disengage, dis_bracket = extrapolated_event(out, grid_short, touches_short, tol, EVENT_ANGLE_TOL_RAD, first=True)
    i_dis = int(np.searchsorted(np.abs(out), abs(disengage))) if math.isfinite(disengage) else len(out)
    creep = float(np.max(np.abs(travel_out[i_dis:] - stand))) if i_dis < len(out) else math.nan

    # Grazing end: where the pinion no longer touches the rack held δ short (after the stop).
    standing = np.arange(len(out)) >= i_dis

    def grid_graze(delta: float) -> np.ndarray:
        return standing & np.array([touches_short(delta, float(a)) if s else False
                                    for a, s in zip(out, standing, strict=True)])

    graze_end, _ = extrapolated_event(out, grid_graze, touches_short, tol, EVENT_ANGLE_TOL_RAD, first=False)

    # Closest approach past the disengage, and the rack shift that brings it to contact.
    worst = {}
    if i_dis < len(out):
        j = i_dis + int(np.argmin(clear_out[i_dis:]))
        angle, travel = float(out[j]), float(travel_out[j])
        d = probe.distance(angle, travel)
        shift = contact_distance(lambda s: probe.hits(angle, travel - direction * s, faces), tol / 8.0, limit,
                                 TRAVEL_BISECT_TOL_MM)
        worst = {"angle": angle, "travel": travel, "distance": d.distance, "contact_shift": shift,
                 "point_pinion": d.point_a, "point_rack": d.point_b}

    # Re-engage: the return swing first touches the standing rack's other flanks.
    reengage, re_bracket = math.nan, None
    moved = np.flatnonzero(pushed_back)
    if moved.size and moved[0] > 0:
        i = int(moved[0])
        back_faces = pusher(-direction)
        re_bracket = bisect(lambda a: probe.hits(a, stand, back_faces), float(back[i - 1]), float(back[i]),
                            EVENT_ANGLE_TOL_RAD)
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
    faces = pusher(-direction)  # the rack's flanks facing the way it drives

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
        clear.append(signed_clearance(probe, angle, float(travel), tol, limit, faces if moved else None))
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

        # the bisection's vocabulary: "free" = offset still negative, "touching" = reached
        bracket = bisect(reached, lo_travel, float(travels[i + 1]), EVENT_TRAVEL_TOL_MM)
        limit_travel = bracket.value
        limit_angle = 0.5 * (state.get(bracket.free, lo_angle) + state.get(bracket.touching, float(angles_a[i + 1])))
    raw = np.flatnonzero(corner_flags)
    raw_angle = float(angles_a[raw[0]]) if raw.size else math.nan
    return {
        "direction": direction, "travels": travels, "angles": angles_a, "clearance": np.array(clear),
        "offsets": offsets_a, "at_corner": np.array(corner_flags), "limit_travel": limit_travel,
        "limit_angle": limit_angle, "limit_bracket": None if bracket is None else (bracket.free, bracket.touching),
        "raw_corner_angle": raw_angle, "queries": probe.queries, "seconds": time.perf_counter() - t0,
        "cpu_seconds": time.process_time() - c0,
    }
