"""The sweep of a STEP assembly: every pose of the declared motion, in every temperature state.

At each pose every part is placed by its joint (coupled to the driver), and for every pair of
parts that is checked (every pair but the ignored; a pair the motion does not move relative to
each other only at the first pose):

* FCL collide; if the meshes are apart, FCL distance: the clearance and its nearest points;
* if they intersect, the overlap *along the motion*: the smallest move of one of the two parts
  along its own joint (the driven one where there is a choice), either way, that frees them —
  in mm for a slide, the angle times the radius of the freed contact for a turn. No mesh
  engine gives a penetration depth; this is the one a mechanism's motion defines, and the one a
  contact tolerance is about;
* the play part (if declared) turned (or slid) both ways from its coupled position, the others
  held, to contact with any part it is checked against: bisection on FCL collide, to
  :data:`BISECT_DEG` / :data:`BISECT_MM`.

Tasks are runs of consecutive poses of one state (a worker builds the BVHs of that state's
meshes once); the reduce step finds each pair's least clearance and deepest overlap and the least
play, over the motion and the states, and names the worst poses for the exact B-rep confirmation.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.assembly.assembly import Layout, PairRule
from gearcheck.mechanisms.assembly.kinematics import Kinematics
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.bodies import Body, MeshData, submesh
from gearcheck.sweep.motion import Rotation
from gearcheck.geometry.bisect import bisect, bisect_predicted, remembered
from gearcheck.sweep.prune import approaching_faces, largest_step, near_faces
from gearcheck.sweep.tools import CountedScene, clearing_distance

BISECT_DEG = 2e-4  # play and overlap bisections stop at this bracket (deg: 0.72″, 1.7e-4 mm at r = 50) ...
BISECT_MM = 1e-5  # ... or this (mm)
POSES_PER_TASK = 24
AS_BUILT = "as_built"


@dataclass(frozen=True)
class StateSpec:
    """One state: its name and each part's scale and datum (the file's frame)."""

    name: str
    scales: dict[str, float]
    datums: dict[str, tuple[float, float, float]]

    def fold(self, part: str, pose: np.ndarray) -> np.ndarray:
        """The pose of a part scaled about its datum, as a pose of the part scaled about its own
        origin (what a WorstPose carries): pose @ translation((1 − s)·d)."""
        s = self.scales.get(part, 1.0)
        d = np.asarray(self.datums.get(part, (0.0, 0.0, 0.0)), float)
        shift = np.eye(4)
        shift[:3, 3] = (1.0 - s) * d
        return pose @ shift


@dataclass(frozen=True)
class Spec:
    """What every task needs (picklable): the kinematics, the pair rules, the play part, and each
    pair's meshes (pruned to what comes within ``margin`` of the other part over the motion):
    ``meshes[pair key] = (mesh of a, mesh of b)``, ``far``: the pairs never within the margin (not
    queried), ``reach[pair key]``: the farthest clearing move searched (the mover's unit)."""

    kin: Kinematics
    pairs: tuple[PairRule, ...]
    play: str | None
    play_limit: float
    play_neighbours: tuple[str, ...]
    meshes: dict[str, tuple[str, str]]
    far: frozenset[str]
    reach: dict[str, float]
    margin: float
    centres: dict[str, tuple[float, float, float]]  # each part's bounding-box centre, its own frame
    # the play part against each neighbour, per turning sense (+1, −1): (its mesh, the neighbour's),
    # each kept to the faces that motion can meet first (sweep.prune.approaching_faces)
    play_meshes: dict[tuple[str, float], tuple[str, str]]

    def mesh(self, rule: PairRule, part: str, state: str) -> str:
        """The mesh of ``part`` against the other part of ``rule``, in ``state``."""
        name = self.meshes[rule.key][0 if part == rule.a else 1]
        return name if state == AS_BUILT else f"{name}@{state}"

    def rule(self, a: str, b: str) -> PairRule:
        return next(r for r in self.pairs if {r.a, r.b} == {a, b})


def _unit_tol(unit: str) -> float:
    return BISECT_DEG if unit == "deg" else BISECT_MM


def _overlap_mover(spec: Spec, rule: PairRule) -> str | None:
    """The part moved to free an overlapping pair: a jointed part of the pair, the driven one first."""
    jointed = [p for p in (rule.b, rule.a) if p in spec.kin.lines]
    driven = [p for p in jointed if p != spec.kin.driver]
    return (driven or jointed)[0] if jointed else None


def _radius(line, point: np.ndarray) -> float:
    """Distance of a world point from a revolute joint's axis (mm)."""
    axis, origin = np.asarray(line.motion.axis, float), np.asarray(line.motion.origin, float)
    v = point - origin
    return float(np.linalg.norm(v - axis * (v @ axis)))


def _overlap(scene: CountedScene, spec: Spec, rule: PairRule, state: str, x: float) -> tuple[float, float]:
    """(overlap along the motion in mm, in the mover's unit) of a pair whose meshes intersect at
    driver coordinate ``x``: the smaller of the two clearing moves (searched up to the pair's
    reach); NaN without a jointed part; where no move of the joint frees it, the least push."""
    mover = _overlap_mover(spec, rule)
    other_part = rule.a if mover == rule.b else rule.b
    if mover is None:
        return math.nan, math.nan
    line = spec.kin.lines[mover]
    name, other = spec.mesh(rule, mover, state), spec.mesh(rule, other_part, state)
    limit = spec.reach[rule.key]
    tol = _unit_tol(line.unit)
    best, best_pose = limit, None
    for sign in (1.0, -1.0):
        def hits_at(d: float, sign: float = sign) -> bool:
            scene.set_pose(name, spec.kin.pose(mover, x, sign * d))
            return scene.collide(name, other)
        # from the smallest move up: the window that frees a pair may be narrow
        move = clearing_distance(hits_at, start=tol, limit=limit, tol=tol)
        if move < best:
            best, best_pose = move, spec.kin.pose(mover, x, sign * move)
    scene.set_pose(name, spec.kin.pose(mover, x))
    if best_pose is None:  # jammed: no move of the joint frees it (a centre distance too short, say)
        push = _pushed_apart(scene, name, other, spec.kin.pose(mover, x), spec.kin.pose(other_part, x), spec.margin,
                             (spec.centres[mover], spec.centres[other_part]))
        return push, math.inf
    if line.unit == "mm":
        return best, best
    scene.set_pose(name, best_pose)
    d = scene.distance(name, other)
    scene.set_pose(name, spec.kin.pose(mover, x))
    r = _radius(line, 0.5 * (d.point_a + d.point_b))
    return math.radians(best) * r, best


def _centre(centre: tuple[float, float, float], pose: np.ndarray) -> np.ndarray:
    """A part's bounding-box centre, world frame, at ``pose``."""
    return pose[:3, :3] @ np.asarray(centre, float) + pose[:3, 3]


def _pushed_apart(scene: CountedScene, name: str, other: str, pose: np.ndarray, other_pose: np.ndarray,
                  limit: float, centres: tuple[tuple[float, float, float], tuple[float, float, float]]) -> float:
    """The smallest translation of ``name`` that frees it from ``other`` (mm), either way along two
    directions: the mean normal of the intersecting triangles, and the line between the two
    parts' centres (a gear pair's line of centres). The overlap of a pair no move of its joints
    frees; infinite where no push within ``limit`` (mm) frees it."""
    directions = []
    n = scene.scene.contact_normal(other, name)
    if n is not None:
        directions.append(n)
    c = _centre(centres[0], pose) - _centre(centres[1], other_pose)
    if float(np.linalg.norm(c)) > 1e-9:
        directions.append(c / np.linalg.norm(c))
    best = math.inf
    for direction in directions:
        for sign in (1.0, -1.0):
            def hits_at(d: float, sign: float = sign, direction: np.ndarray = direction) -> bool:
                moved = pose.copy()
                moved[:3, 3] += sign * d * direction
                scene.set_pose(name, moved)
                return scene.collide(name, other)
            move = clearing_distance(hits_at, BISECT_MM, limit, BISECT_MM)
            if move < limit:
                best = min(best, move)
    scene.set_pose(name, pose)
    return best


NEWTON_STEPS = 4  # distance queries at most per contact estimate
NEWTON_DAMPING = (0.6, 0.9, 0.95)  # each step goes this share of the predicted way (a first one runs long)


def _gap_rate(scene: CountedScene, spec: Spec, part: str, sign: float, ahead: list[str],
              facing: list[str]) -> tuple[float, float] | None:
    """(gap, closing rate per unit move) to the nearest neighbour at the current pose: the distance
    between the nearest points and n·v (n the unit normal from the mover's nearest point to the
    neighbour's, v the mover's velocity there per unit move of its joint). None where touching or
    the gap does not close."""
    line = spec.kin.lines[part]
    best = None
    for m, o in zip(ahead, facing, strict=True):
        d = scene.distance(m, o)
        if not d.distance > 0.0:
            return (0.0, 1.0)  # touching
        n = (d.point_b - d.point_a) / d.distance
        if line.unit == "deg":
            motion = line.motion
            assert isinstance(motion, Rotation)
            a, origin = np.asarray(motion.axis, float), np.asarray(motion.origin, float)
            rate = sign * float(n @ np.cross(a, d.point_a - origin)) * math.pi / 180.0
        else:
            rate = sign * float(n @ np.asarray(line.motion.axis, float))
        if rate > 1e-12 and (best is None or d.distance / rate < best[0] / best[1]):
            best = (d.distance, rate)
    return best


def _newton(scene: CountedScene, spec: Spec, part: str, x: float, sign: float, ahead: list[str],
            facing: list[str], tol: float, limit: float) -> tuple[float, float] | None:
    """(estimate, margin) of the move that brings the play part into contact, from damped Newton
    steps on the gap between nearest points (:func:`_gap_rate`, one distance query each; every
    step stays free, a positive distance says so): an estimate only, the contact is still proven
    by collisions. None where it cannot say."""
    free, at, step = 0.0, 0.0, math.inf
    for k in range(NEWTON_STEPS):
        pose = spec.kin.pose(part, x, sign * at)
        for name in ahead:
            scene.set_pose(name, pose)
        gr = _gap_rate(scene, spec, part, sign, ahead, facing)
        if gr is None:
            return None
        if gr[0] == 0.0:  # the step ran into contact: it lies between the last free move and this one
            return 0.5 * (free + at), 0.5 * (at - free) + tol
        free, step = at, gr[0] / gr[1]
        if step <= tol or at + step >= limit:
            break
        at += NEWTON_DAMPING[min(k, len(NEWTON_DAMPING) - 1)] * step
    return free + step, max(tol, step)


def _extrapolated(history: list[float], tol: float) -> tuple[float, float] | None:
    """(estimate, margin) of the next pose's move from the last poses' (the motion's poses are
    close: the contact moves little from one to the next), or None without two of them."""
    if len(history) < 2 or not all(math.isfinite(h) and h > 0.0 for h in history[-2:]):
        return None
    last, before = history[-1], history[-2]
    return last + (last - before), max(2.0 * tol, abs(last - before))


def _to_contact(hits_at: Callable[[float], bool], tol: float, limit: float,
                estimates: tuple[Callable[[], tuple[float, float] | None], ...]) -> float:
    """The touching end of the bracket the plain bisection of [0, limit] ends with (``limit`` where
    nothing touches within it), found around the first estimate that proves its bracket (each an
    (estimate, margin) or None, tried in order, answers shared), else by that bisection."""
    ask, asked = remembered(hits_at)
    for make in estimates:
        estimate = make()
        if estimate is None or not 0.0 < estimate[0] < limit:
            continue
        found = bisect_predicted(ask, 0.0, limit, tol, estimate[0], estimate[1], asked=asked)
        if found is not None:
            return found[0].touching
    return bisect(ask, 0.0, limit, tol, check_ends=False).touching if ask(limit) else limit


def _play(scene: CountedScene, spec: Spec, state: str, x: float, overlapping: bool,
          history: tuple[list[float], list[float]] = ([], [])) -> tuple[float, float, float, float]:
    """(plus, minus) moves of the play part from its coupled position to contact with any of its
    neighbours, the others held (a part already in contact, ``overlapping`` at the pose: the
    negative clearing move), and the index of the neighbour touched at each (NaN: none within the
    limit). Each move is the bracket the plain bisection of [0, limit] ends with, found with few
    collisions around a Newton estimate (:func:`_newton`; the bracket proven from both sides),
    else by the plain bisection."""
    part = spec.play
    assert part is not None
    line = spec.kin.lines[part]
    near = [n for n in spec.play_neighbours if spec.rule(part, n).key not in spec.far]
    pairs = [spec.rule(part, n) for n in near]
    mine = [spec.mesh(r, part, state) for r in pairs]  # whole pruned meshes: the pose itself
    others = [spec.mesh(r, r.b if r.a == part else r.a, state) for r in pairs]
    suffix = "" if state == AS_BUILT else f"@{state}"
    tol, limit = _unit_tol(line.unit), spec.play_limit
    moves, touched = [], []
    for sign, past in zip((1.0, -1.0), history, strict=True):
        names = [spec.play_meshes[(n, sign)] for n in near]
        ahead, facing = [m + suffix for m, _ in names], [o + suffix for _, o in names]
        nominal = spec.kin.pose(part, x)
        for name in ahead:
            scene.set_pose(name, nominal)
        for name in facing:  # the neighbours' directed meshes at this pose
            scene.set_pose(name, spec.kin.pose(name.partition("~")[0], x))

        def hits_at(d: float, sign: float = sign, ahead: list[str] = ahead, facing: list[str] = facing) -> bool:
            if d == 0.0:  # at the pose itself: the whole pruned meshes (an overlap may be on any face)
                return any(scene.collide(m, o) for m, o in zip(mine, others, strict=True))
            pose = spec.kin.pose(part, x, sign * d)
            for name in ahead:
                scene.set_pose(name, pose)
            return any(scene.collide(m, o) for m, o in zip(ahead, facing, strict=True))
        if overlapping:  # how far back the other way frees it, on the whole pruned meshes (any face)
            def back(d: float, s: float = -sign) -> bool:
                pose = spec.kin.pose(part, x, s * d)
                for name in mine:
                    scene.set_pose(name, pose)
                return any(scene.collide(m, o) for m, o in zip(mine, others, strict=True))
            move, at = -clearing_distance(back, tol, limit, tol), 0.0
            for name in mine:
                scene.set_pose(name, nominal)
        else:
            # the last poses' moves extrapolated (collisions only), else Newton steps on the gap
            move = _to_contact(hits_at, tol, limit, (
                functools.partial(_extrapolated, past, tol),
                functools.partial(_newton, scene, spec, part, x, sign, ahead, facing, tol, limit)))
            at = move
        who = None
        if move < limit and len(near) == 1:
            who = 0
        elif move < limit:
            pose = spec.kin.pose(part, x, sign * at)
            for name in ahead:
                scene.set_pose(name, pose)
            who = next((i for i, (m, o) in enumerate(zip(ahead, facing, strict=True)) if scene.collide(m, o)), None)
        moves.append(move)
        touched.append(math.nan if who is None else float(spec.play_neighbours.index(near[who])))
    return moves[0], moves[1], touched[0], touched[1]


def sweep_poses(scene, spec: Spec, state: str, indices: list[int], first: bool) -> dict:
    """One task: the poses ``indices`` of one state (``first``: the motion's first pose is among
    them, where pairs that do not move relative to each other are checked)."""
    scene = CountedScene(scene)
    kin = spec.kin
    n, m = len(indices), len(spec.pairs)
    clearance = np.full((n, m), np.nan)
    overlap_mm = np.full((n, m), np.nan)
    overlap_unit = np.full((n, m), np.nan)
    points = np.full((n, m, 6), np.nan)
    play = np.full((n, 4), np.nan)  # plus, minus, neighbour touched plus, minus
    start = time.perf_counter()
    play_s: list[float] = []  # one play measurement (both ways) per pose
    live = [r for r in spec.pairs if r.key not in spec.far]
    for row, i in enumerate(indices):
        x = float(kin.coordinates[i])
        scene.set_poses({spec.mesh(r, p, state): kin.pose(p, x) for r in live for p in (r.a, r.b)})
        for k, rule in enumerate(spec.pairs):
            if rule.key in spec.far or (not rule.moving and not (first and i == 0)):
                continue
            a, b = spec.mesh(rule, rule.a, state), spec.mesh(rule, rule.b, state)
            if scene.collide(a, b):
                overlap_mm[row, k], overlap_unit[row, k] = _overlap(scene, spec, rule, state, x)
                clearance[row, k] = -overlap_mm[row, k] if math.isfinite(overlap_mm[row, k]) else -math.inf
            else:
                d = scene.distance(a, b)
                clearance[row, k] = d.distance
                points[row, k] = np.concatenate([d.point_a, d.point_b])
        if spec.play:
            t0 = time.perf_counter()
            hit = any(np.isfinite(overlap_mm[row, k]) or np.isinf(overlap_mm[row, k])
                      for k, r in enumerate(spec.pairs) if spec.play in (r.a, r.b) and r.key not in spec.far)
            play[row] = _play(scene, spec, state, x, hit, (list(play[:row, 0]), list(play[:row, 1])))
            play_s.append(time.perf_counter() - t0)
    return {"indices": list(indices), "clearance": clearance, "overlap_mm": overlap_mm,
            "overlap_unit": overlap_unit, "points": points, "play": play, "queries": scene.queries,
            "play_s": play_s, "seconds": time.perf_counter() - start}


def state_specs(layout: Layout, bodies: Mapping[str, Body]) -> list[StateSpec]:
    """The file's own state, then each declared temperature state (each part by its own CTE)."""
    out = [StateSpec(AS_BUILT, {}, {})]
    for name, temp, ref in layout.states:
        scales, datums = {}, {}
        for part, body in bodies.items():
            scales[part] = 1.0 + layout.cte_per_K.get(part, 0.0) * (temp - ref)
            d = layout.datum.get(part)
            if d is None:
                v = body.mesh.vertices
                d = tuple(0.5 * (v.min(axis=0) + v.max(axis=0)))
            datums[part] = (float(d[0]), float(d[1]), float(d[2]))
        out.append(StateSpec(name, scales, datums))
    return out


def _corners(mesh: MeshData) -> np.ndarray:
    v = np.asarray(mesh.vertices, float)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def _reach_mm(kin: Kinematics, part: str, move: float, corners: np.ndarray) -> float:
    """The largest displacement (mm) of any point of ``part`` when its joint moves by ``move``."""
    line = kin.lines.get(part)
    if line is None or move <= 0.0:
        return 0.0
    if line.unit == "mm":
        return move
    return max(_radius(line, c) for c in corners) * 2.0 * math.sin(math.radians(move) / 2.0)


def _base_margin(lay: Layout) -> float:
    """The distance below which every figure of a pruned pair is exact (mm): at least 1 mm, twice
    the largest required clearance and twice the contact tolerance."""
    required = [r.min_clearance_mm for r in lay.pairs if r.kind == "clearance"]
    return max(1.0, 2.0 * max(required, default=0.0), 2.0 * lay.contact_tolerance_mm)


def pair_meshes(lay: Layout, kin: Kinematics, bodies: Mapping[str, Body], states: list[StateSpec]
                ) -> tuple[dict[str, tuple[MeshData, MeshData]], frozenset[str], dict[str, float], float]:
    """Each pair's two meshes pruned to what comes within the margin of the other over the motion
    (:mod:`gearcheck.sweep.prune`); the pairs never within it; each pair's clearing-move reach (the
    mover's unit: a move that displaces no point more than the base margin); the base margin."""
    base = _base_margin(lay)
    corners = {p: _corners(b.mesh) for p, b in bodies.items()}
    growth = max((abs(st.scales.get(p, 1.0) - 1.0) * float(np.linalg.norm(c - np.asarray(st.datums.get(p, (0, 0, 0))),
                                                                          axis=1).max())
                  for st in states for p, c in corners.items()), default=0.0)
    meshes, far, reach = {}, set(), {}
    for rule in lay.pairs:
        mover = next((p for p in (rule.b, rule.a) if p in kin.lines and p != kin.driver),
                     next((p for p in (rule.b, rule.a) if p in kin.lines), None))
        if mover is None:
            reach[rule.key] = 0.0
        else:
            unit_reach = _reach_mm(kin, mover, 1.0, corners[mover])  # mm per unit move (deg or mm)
            reach[rule.key] = base / unit_reach if unit_reach > 0 else 0.0
        play_reach = max((_reach_mm(kin, p, lay.play_limit, corners[p]) for p in (rule.a, rule.b) if p == lay.play),
                         default=0.0)
        xs = kin.coordinates if rule.moving else kin.coordinates[:1]
        masks = []
        for me, other in ((rule.a, rule.b), (rule.b, rule.a)):
            rel = np.array([np.linalg.inv(kin.pose(me, float(x))) @ kin.pose(other, float(x)) for x in xs])
            margin = base + max(base, play_reach) + largest_step(corners[other], rel) + 2.0 * growth
            masks.append(near_faces(bodies[me].mesh, bodies[other].mesh, rel, margin))
        if not masks[0].any() or not masks[1].any():
            far.add(rule.key)
            continue
        meshes[rule.key] = tuple(submesh(bodies[me].mesh, f"{me}~{other}", mask) if not mask.all()
                                 else MeshData(f"{me}~{other}", bodies[me].mesh.vertices, bodies[me].mesh.faces)
                                 for (me, other), mask in zip(((rule.a, rule.b), (rule.b, rule.a)), masks, strict=True))
    return meshes, frozenset(far), reach, base  # type: ignore[return-value]


def play_meshes(lay: Layout, kin: Kinematics, bodies: Mapping[str, Body], pairs: dict[str, tuple[MeshData, MeshData]]
                ) -> dict[tuple[str, float], tuple[MeshData, MeshData]]:
    """The play part and each neighbour's pruned meshes cut, for each turning sense, to the faces
    that motion can meet first: the other sense's flanks, a backlash away, left out of the BVHs
    every contact bisection traverses (the same contact, found faster)."""
    part = lay.play
    if part is None:
        return {}
    line = kin.lines[part]
    axis = np.asarray(line.motion.axis, float)
    origin = np.asarray(line.motion.origin, float) if isinstance(line.motion, Rotation) else None
    out = {}
    for n in lay.play_neighbours:
        rule = next(r for r in lay.pairs if {r.a, r.b} == {part, n})
        if rule.key not in pairs:
            continue
        mine, theirs = pairs[rule.key] if rule.a == part else pairs[rule.key][::-1]
        # the play joint's axis in the neighbour's frame at every pose (both joints fixed in the world)
        inv = [np.linalg.inv(kin.pose(n, float(x))) for x in kin.coordinates]
        axes = np.array([m[:3, :3] @ axis for m in inv])
        origins = None if origin is None else np.array([m[:3, :3] @ origin + m[:3, 3] for m in inv])
        for sign in (1.0, -1.0):
            keep_mine = approaching_faces(mine, axis, origin, sign, moving=True)
            keep_theirs = approaching_faces(theirs, axes, origins, sign, moving=False)
            if not (keep_mine.any() and keep_theirs.any()):  # nothing that sense could meet: whole meshes
                keep_mine, keep_theirs = np.ones(len(mine.faces), bool), np.ones(len(theirs.faces), bool)
            tag = "+" if sign > 0 else "-"
            out[(n, sign)] = (submesh(mine, f"{mine.name}{tag}", keep_mine),
                              submesh(theirs, f"{theirs.name}{tag}", keep_theirs))
    return out


def state_meshes(states: list[StateSpec], bodies: Mapping[str, Body],
                 pairs: dict[str, tuple[MeshData, MeshData]]) -> list[MeshData]:
    """Every pair's pruned meshes in every state (a state's: scaled about each part's datum)."""
    meshes = []
    for st in states:
        for mesh_a, mesh_b in pairs.values():
            for mesh in (mesh_a, mesh_b):
                part = mesh.name.partition("~")[0]
                if st.name == AS_BUILT:
                    meshes.append(mesh)
                    continue
                scale, datum = st.scales[part], np.asarray(st.datums[part], float)
                meshes.append(MeshData(f"{mesh.name}@{st.name}", datum + (mesh.vertices - datum) * scale, mesh.faces))
    return meshes


def plan_sweep(assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None) -> SweepPlan:
    lay: Layout = assembly.layout
    options = dict(options or {})
    kin = lay.kin
    stride = int(options.get("stride", 1))  # tests and fuzz: every stride-th pose only
    if stride > 1:
        kin = Kinematics(kin.lines, kin.driver, kin.coordinates[::stride].copy())
    states = state_specs(lay, bodies)
    pairs, far, reach, margin = pair_meshes(lay, kin, bodies, states)
    directed = play_meshes(lay, kin, bodies, pairs)
    play = {key: (a.name, b.name) for key, (a, b) in directed.items()}
    centres = {p: tuple(float(c) for c in _corners(b.mesh).mean(axis=0)) for p, b in bodies.items()}
    spec = Spec(kin, lay.pairs, lay.play, lay.play_limit, lay.play_neighbours,
                {k: (a.name, b.name) for k, (a, b) in pairs.items()}, far, reach, margin,
                centres, play)  # type: ignore[arg-type]
    per_task = int(options.get("poses_per_task", POSES_PER_TASK))
    count = len(kin.coordinates)
    tasks, weights = [], []
    for st in states:
        for start in range(0, count, per_task):
            idx = list(range(start, min(count, start + per_task)))
            tasks.append((sweep_poses, (spec, st.name, idx, start == 0)))
            weights.append(len(idx))

    def reduce(results: list) -> SweepOutcome:
        from gearcheck.mechanisms.assembly.reduce import reduce_sweep

        return reduce_sweep(lay, spec, states, bodies, results,
                            {k: (a.faces.shape[0], b.faces.shape[0]) for k, (a, b) in pairs.items()})

    every = {**{k: v for k, v in pairs.items()}, **{f"{n}{sign:+g}": m for (n, sign), m in directed.items()}}
    return SweepPlan(state_meshes(states, bodies, every), tasks, reduce, weights=weights, unit="pose",
                     options=options)


def worst_pose(label: str, key: str, spec: Spec, state: StateSpec, a: str, b: str, x: float,
               distance: float, extra: tuple[str, float] | None = None, overlap: bool | None = None,
               midpoint: np.ndarray | None = None) -> WorstPose:
    """A pose to confirm on the exact B-rep: the parts at driver coordinate ``x`` (one of them moved
    by ``extra``: (part, move)), scaled as the state scales them."""
    def pose(p: str) -> np.ndarray:
        move = extra[1] if extra is not None and extra[0] == p else 0.0
        return state.fold(p, spec.kin.pose(p, x, move))

    mid = (None if midpoint is None or not np.all(np.isfinite(midpoint))
           else (float(midpoint[0]), float(midpoint[1]), float(midpoint[2])))
    return WorstPose(label, a, b, pose(a).tolist(), pose(b).tolist(), float(distance),
                     state.scales.get(a, 1.0), state.scales.get(b, 1.0), key=key, mesh_overlap=overlap,
                     mesh_nearest_midpoint=mid)
