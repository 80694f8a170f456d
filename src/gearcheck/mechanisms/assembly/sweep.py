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

import dataclasses
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.assembly.assembly import Layout, PairRule
from gearcheck.mechanisms.assembly.kinematics import Kinematics
from gearcheck.mechanisms.assembly.local import Cuts
from gearcheck.mechanisms.assembly.play import contact_move
from gearcheck.mechanisms.assembly.meshes import (AS_BUILT, StateSpec, pair_meshes, play_meshes, state_meshes,
                                                  state_specs)
from gearcheck.mechanisms.assembly.meshes import axis_radius as _radius
from gearcheck.mechanisms.assembly.meshes import overlap_mover
from gearcheck.mechanisms.assembly.meshes import box_corners as _corners
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.bodies import Body, MeshData
from gearcheck.sweep.certify import certify
from gearcheck.sweep.motion import Rotation
from gearcheck.sweep.tools import CountedScene, clearing_distance

BISECT_DEG = 2e-4  # play and overlap bisections stop at this bracket (deg: 0.72″, 1.7e-4 mm at r = 50) ...
BISECT_MM = 1e-5  # ... or this (mm)
POSES_PER_TASK = 24
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
    # per pair: the convex hull vertices of its two pruned meshes, each in its part's frame, for the bound
    # on how fast the clearance can change over an interval (:func:`interval_path`)
    hulls: dict[str, tuple[np.ndarray, np.ndarray]]
    grown: float  # the largest thermal scale: a state's meshes are no larger than this times the built
    resolution: dict[str, float]  # per pair: its mesh-error bound, the sharpest a bound can be
    # the pairs queried (not far), as indices into ``pairs``: the columns of every task's arrays
    live: tuple[int, ...] = ()
    index: dict[frozenset[str], int] = dataclasses.field(default_factory=dict)  # {a, b} → its index in pairs

    def mesh(self, rule: PairRule, part: str, state: str) -> str:
        """The mesh of ``part`` against the other part of ``rule``, in ``state``."""
        name = self.meshes[rule.key][0 if part == rule.a else 1]
        return name if state == AS_BUILT else f"{name}@{state}"

    def rule(self, a: str, b: str) -> PairRule:
        k = self.index.get(frozenset((a, b)))
        return self.pairs[k] if k is not None else next(r for r in self.pairs if {r.a, r.b} == {a, b})

    def queried(self, a: str, b: str) -> bool:
        """Whether the pair of ``a`` and ``b`` is queried (checked, and not far)."""
        k = self.index.get(frozenset((a, b)))
        return k is not None and self.pairs[k].key not in self.far

    def for_tasks(self) -> Spec:
        """This spec as the tasks need it: the queried pairs only (their columns in order), so that
        what is sent with every task does not grow with the pairs never near (19,900 of a 200-part
        assembly's, against its 370 queried)."""
        live = self.live_rules
        keys = {r.key for r in live}
        return dataclasses.replace(self, pairs=tuple(live), live=tuple(range(len(live))), far=frozenset(),
                                   reach={k: v for k, v in self.reach.items() if k in keys},
                                   resolution={k: v for k, v in self.resolution.items() if k in keys},
                                   index={frozenset((r.a, r.b)): k for k, r in enumerate(live)})

    @property
    def live_rules(self) -> list[PairRule]:
        """The pairs queried, in column order."""
        return [self.pairs[k] for k in self.live]


def _unit_tol(unit: str) -> float:
    return BISECT_DEG if unit == "deg" else BISECT_MM


def _overlap(scene: CountedScene, spec: Spec, rule: PairRule, state: str, x: float) -> tuple[float, float]:
    """(overlap along the motion in mm, in the mover's unit) of a pair whose meshes intersect at
    driver coordinate ``x``: the smaller of the two clearing moves (searched up to the pair's
    reach); NaN without a jointed part; where no move of the joint frees it, the least push."""
    mover = overlap_mover(spec.kin, rule)
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


def _play(scene: CountedScene, spec: Spec, state: str, x: float, overlapping: bool,
          history: tuple[list[float], list[float]] = ([], []), free: bool = False,
          cuts: Cuts | None = None) -> tuple[float, float, float, float]:
    """(plus, minus) moves of the play part from its coupled position to contact with any of its
    neighbours, the others held (a part already in contact, ``overlapping`` at the pose: the
    negative clearing move), and the index of the neighbour touched at each (NaN: none within the
    limit); ``free``: every pair of the part was found apart at this pose (not asked again). Each
    move is the bracket the plain bisection of [0, limit] ends with, found with few collisions
    around an estimate (:func:`~gearcheck.mechanisms.assembly.play.contact_move`), else by the
    plain bisection. ``cuts``: the task's cuts around the contacts
    (:mod:`~gearcheck.mechanisms.assembly.local`), kept between poses."""
    part = spec.play
    assert part is not None
    line = spec.kin.lines[part]
    near = [n for n in spec.play_neighbours if spec.queried(part, n)]
    pairs = [spec.rule(part, n) for n in near]
    mine = [spec.mesh(r, part, state) for r in pairs]  # whole pruned meshes: the pose itself
    others = [spec.mesh(r, r.b if r.a == part else r.a, state) for r in pairs]
    suffix = "" if state == AS_BUILT else f"@{state}"
    tol, limit = _unit_tol(line.unit), spec.play_limit
    moves, touched = [], []
    own = cuts is None  # cuts for this pose alone: dropped from the scene when it is done
    cuts = Cuts(scene.scene) if cuts is None else cuts
    for sign, past in zip((1.0, -1.0), history, strict=True):
        names = [spec.play_meshes[(n, sign)] for n in near]
        ahead, facing = [m + suffix for m, _ in names], [o + suffix for _, o in names]
        nominal = spec.kin.pose(part, x)
        for name in ahead:
            scene.set_pose(name, nominal)
        for name in facing:  # the neighbours' directed meshes at this pose
            scene.set_pose(name, spec.kin.pose(name.partition("~")[0], x))

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
            move = at = contact_move(scene, spec, cuts, x, sign, [(sign, n, state) for n in near], ahead, facing,
                                     (mine, others), past, free, tol)
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
    if own:
        cuts.clear()
    return moves[0], moves[1], touched[0], touched[1]


def _certified(scene: CountedScene, spec: Spec, rule: PairRule, state: str, xs: list[float],
               cs: list[float]) -> dict:
    """The pair's clearance certified over the motion through the coordinates ``xs`` (clearances
    ``cs``, negative where overlapping): :func:`gearcheck.sweep.certify.certify`, a distance query at
    each refinement point (an overlap there: the overlap along the motion, negative)."""
    a, b = spec.mesh(rule, rule.a, state), spec.mesh(rule, rule.b, state)
    def measure(x: float) -> float:
        scene.set_pose(a, spec.kin.pose(rule.a, x))
        scene.set_pose(b, spec.kin.pose(rule.b, x))
        if scene.collide(a, b):
            depth = _overlap(scene, spec, rule, state, x)[0]
            return -depth if math.isfinite(depth) and depth > 0.0 else -BISECT_MM
        return scene.distance(a, b).distance

    # the poses' own intervals at once; a refinement's halves one by one
    spans = list(zip(xs[:-1], xs[1:], strict=True))
    paths = dict(zip(spans, interval_paths(spec, rule, np.asarray(xs[:-1]), np.asarray(xs[1:])), strict=True))

    def path(x0: float, x1: float) -> float:
        found = paths.get((x0, x1))
        return found if found is not None else interval_path(spec, rule, x0, x1)

    cert = certify(xs, cs, measure, path, rule.min_clearance_mm, spec.resolution[rule.key])
    return {"certified_min": cert.certified_min, "sampled_min": cert.sampled_min, "at": list(cert.at),
            "refined": cert.refined, "undecided": len(cert.undecided)}


def _certificates(scene: CountedScene, spec: Spec, state: str, indices: list[int], clearance: np.ndarray,
                  after: int | None) -> dict[str, dict]:
    """Each moving pair's clearance certified over a task's poses (``clearance``: one row per pose),
    on to the pose ``after`` (the next task's first: measured here, not recorded)."""
    kin = spec.kin
    certificates: dict[str, dict] = {}
    for k, rule in enumerate(spec.live_rules):
        if not rule.moving or rule.kind == "contact":
            continue
        xs = [float(kin.coordinates[i]) for i in indices]
        cs = [float(c) for c in clearance[:, k]]
        if after is not None:
            x = float(kin.coordinates[after])
            a, b = spec.mesh(rule, rule.a, state), spec.mesh(rule, rule.b, state)
            scene.set_pose(a, kin.pose(rule.a, x))
            scene.set_pose(b, kin.pose(rule.b, x))
            xs.append(x)
            cs.append(-BISECT_MM if scene.collide(a, b) else scene.distance(a, b).distance)
        certificates[rule.key] = _certified(scene, spec, rule, state, xs, cs)
    return certificates


def sweep_poses(scene, spec: Spec, state: str, indices: list[int], first: bool, after: int | None = None) -> dict:
    """One task: the poses ``indices`` of one state (``first``: the motion's first pose is among
    them, where pairs that do not move relative to each other are checked), and each moving pair's
    clearance certified over the motion from the first of them to the pose ``after`` (the next
    task's first, measured here too, not recorded: every interval is certified by one task)."""
    cpu0 = time.process_time()
    live = spec.live_rules
    scene.build(task_meshes(spec, state))
    scene = CountedScene(scene)
    kin = spec.kin
    n, m = len(indices), len(live)
    meshes = [(spec.mesh(r, r.a, state), spec.mesh(r, r.b, state)) for r in live]
    placed = sorted({(name, part) for r, pair in zip(live, meshes, strict=True)
                     for name, part in zip(pair, (r.a, r.b), strict=True)})
    parts = sorted({part for _, part in placed})
    mine = [k for k, r in enumerate(live) if spec.play in (r.a, r.b)]  # the play part's pairs
    clearance = np.full((n, m), np.nan)
    overlap_mm = np.full((n, m), np.nan)
    overlap_unit = np.full((n, m), np.nan)
    points = np.full((n, m, 6), np.nan)
    play = np.full((n, 4), np.nan)  # plus, minus, neighbour touched plus, minus
    start = time.perf_counter()
    play_s: list[float] = []  # one play measurement (both ways) per pose
    cuts = Cuts(scene.scene)
    for row, i in enumerate(indices):
        x = float(kin.coordinates[i])
        at = {p: kin.pose(p, x) for p in parts}
        scene.set_poses({name: at[part] for name, part in placed})
        for k, (rule, (a, b)) in enumerate(zip(live, meshes, strict=True)):
            if not rule.moving and not (first and i == 0):
                continue
            if scene.collide(a, b):
                overlap_mm[row, k], overlap_unit[row, k] = _overlap(scene, spec, rule, state, x)
                clearance[row, k] = -overlap_mm[row, k] if math.isfinite(overlap_mm[row, k]) else -math.inf
            else:
                d = scene.distance(a, b)
                clearance[row, k] = d.distance
                points[row, k] = np.concatenate([d.point_a, d.point_b])
        if spec.play:
            t0 = time.perf_counter()
            hit = any(np.isfinite(overlap_mm[row, k]) or np.isinf(overlap_mm[row, k]) for k in mine)
            free = all(clearance[row, k] > 0.0 for k in mine)  # each asked at this pose, and apart
            play[row] = _play(scene, spec, state, x, hit, (list(play[:row, 0]), list(play[:row, 1])), free, cuts)
            play_s.append(time.perf_counter() - t0)
    cuts.clear()
    certificates = _certificates(scene, spec, state, indices, clearance, after)
    return {"indices": list(indices), "clearance": clearance, "overlap_mm": overlap_mm,
            "overlap_unit": overlap_unit, "points": points, "play": play, "queries": scene.queries,
            "play_s": play_s, "seconds": time.perf_counter() - start, "certificates": certificates,
            "cpu_s": time.process_time() - cpu0}


def task_meshes(spec: Spec, state: str) -> list[str]:
    """The meshes a task of ``state`` queries: the queried pairs' and the play part's directed ones
    (their BVHs are built before the poses, not in a measurement's time)."""
    names = {spec.mesh(r, p, state) for r in spec.live_rules for p in (r.a, r.b)}
    if spec.play:
        suffix = "" if state == AS_BUILT else f"@{state}"
        names |= {n + suffix for (other, _), pair in spec.play_meshes.items()
                  if spec.queried(spec.play, other) for n in pair}
    return sorted(names)


# The sweep's cost is measured before it starts on at most this many of its queried pairs (spread
# over their sizes), at runs of this many consecutive poses spread over the motion (one at least,
# more until about CALIBRATION_S CPU seconds are spent, CALIBRATION_RUNS at most): the tasks' code.
CALIBRATION_PAIRS = 8
CALIBRATION_POSES = 12
CALIBRATION_RUNS = 8
CALIBRATION_S = 0.25


@dataclass(frozen=True)
class Calibration:
    """What one pair at one pose costs (CPU s, with its share of the certificate), one play
    measurement at one pose, one state's BVHs on one worker (from the sample's), and the time the
    measurement took."""

    pair_pose_s: float
    play_pose_s: float
    setup_s: float
    seconds: float


def calibrate(spec: Spec, meshes: list[MeshData]) -> Calibration:
    """The cost of the sweep's work measured on a sample of it, in this process, on a scene of
    its own (the results are the tasks', never the sample's): up to :data:`CALIBRATION_PAIRS`
    queried pairs, spread over their triangle counts, at runs of consecutive poses spread over the
    motion (queries, overlaps, the clearance certified between them): a first run of 2 poses, then
    runs of :data:`CALIBRATION_POSES` while less than :data:`CALIBRATION_S` CPU seconds are spent
    (an expensive pose is measured once or twice, a cheap one often). The play part's pairs with
    its play measured, the play's share timed apart (it serves for the pairs too where the sample
    is the play part's pairs)."""
    from gearcheck.sweep.engine import Scene

    t0 = time.perf_counter()
    by_name = {m.name: m for m in meshes}
    scene = Scene(meshes)  # BVHs built on first use: only the sample's
    size = {k: sum(len(by_name[spec.mesh(spec.pairs[k], p, AS_BUILT)].faces) for p in (spec.pairs[k].a,
                                                                                     spec.pairs[k].b))
            for k in spec.live}
    moving = [k for k in spec.live if spec.pairs[k].moving]
    count = len(spec.kin.coordinates)
    spread = [(2 * i + 1) * count // (2 * CALIBRATION_RUNS) for i in range(CALIBRATION_RUNS)]
    spread = spread[::2] + spread[1::2]  # every other first: the first runs span the motion

    def run(sub: Spec, start: int, length: int, first: bool = False) -> tuple[float, float, int]:
        """(CPU seconds, the play's seconds, poses) of one run."""
        start = max(0, min(count - length, start))
        idx = list(range(start, start + length)) if not first else [0]
        after = idx[-1] + 1 if idx[-1] + 1 < count else None
        scene.build(task_meshes(sub, AS_BUILT))
        out = sweep_poses(scene, sub, AS_BUILT, idx, first, after)
        return float(out["cpu_s"]), float(sum(out["play_s"])), len(idx)

    def runs(sub: Spec) -> tuple[float, float, int]:
        """CPU seconds, the play's seconds and poses of the runs: one at least, more while under
        :data:`CALIBRATION_S`."""
        spent = play = 0.0
        poses = 0
        for k, start in enumerate(spread):
            if k and spent >= CALIBRATION_S:
                break
            cpu, p, n = run(sub, start, min(2 if k == 0 else CALIBRATION_POSES, count))
            spent, play, poses = spent + cpu, play + p, poses + n
        return spent, play, poses

    pair_pose_s = play_pose_s = setup_s = 0.0
    mine = tuple(k for k in spec.live if spec.play in (spec.pairs[k].a, spec.pairs[k].b)) if spec.play else ()
    pool = moving or list(spec.live)
    sample: tuple[int, ...] = ()
    if pool:
        ranked = sorted(pool, key=lambda k: (size[k], k))
        n = min(CALIBRATION_PAIRS, len(ranked))
        sample = tuple(sorted({ranked[round(i * (len(ranked) - 1) / max(1, n - 1))] for i in range(n)}))
        sub = dataclasses.replace(spec, live=sample, play=None)
        c0 = time.process_time()
        scene.build(task_meshes(sub, AS_BUILT))
        built_s = time.process_time() - c0
        sampled = sum(len(by_name[m].faces) for m in task_meshes(sub, AS_BUILT))
        every = sum(len(by_name[m].faces) for m in task_meshes(spec, AS_BUILT))
        setup_s = built_s * every / max(sampled, 1)
        if not moving:
            pair_pose_s = run(sub, 0, 1, first=True)[0] / len(sample)
        elif not (mine and set(sample) <= set(mine)):
            spent, _, poses = runs(sub)
            pair_pose_s = spent / (len(sample) * poses)
    if mine:
        spent, play, poses = runs(dataclasses.replace(spec, live=mine))
        play_pose_s = play / poses
        if moving and set(sample) <= set(mine):
            pair_pose_s = max(0.0, spent - play) / (len(mine) * poses)
    return Calibration(pair_pose_s, play_pose_s, setup_s, time.perf_counter() - t0)


def _velocity(kin: Kinematics, part: str, w: np.ndarray) -> np.ndarray:
    """The velocity of ``part``'s motion at world points ``w`` ((n, 3)), per unit of the driver's
    coordinate (mm per deg or per mm): its joint's gain times its turn's (or slide's) field."""
    line = kin.lines.get(part)
    if line is None or not line.coupled:
        return np.zeros_like(w)
    a = np.asarray(line.motion.axis, float)
    if isinstance(line.motion, Rotation):
        return line.gain * math.pi / 180.0 * np.cross(a, w - np.asarray(line.motion.origin, float))
    return np.broadcast_to(line.gain * a, w.shape)


def _turn_rate(kin: Kinematics, part: str) -> np.ndarray:
    """The angular velocity of ``part``'s motion per unit of the driver's coordinate (rad; zero for
    a slide or a part that does not move)."""
    line = kin.lines.get(part)
    if line is None or not line.coupled or not isinstance(line.motion, Rotation):
        return np.zeros(3)
    return line.gain * math.pi / 180.0 * np.asarray(line.motion.axis, float)


def interval_path(spec: Spec, rule: PairRule, x0: float, x1: float) -> float:
    """The longest path (mm) any point of one of the pair's meshes can take relative to the other
    part over [x0, x1] (the clearance changes by no more: the distance is the same with both
    bodies placed in the other's frame, where only this one moves).

    The relative velocity of the two motions, v(w) = v_a(w) − v_b(w) per unit of the driver, is an
    affine field of the world point w with gradient Ω (the difference of the two turn rates); a
    point p of the mesh starts at w0 with relative speed s0 = |v(w0)| and moves through the world at
    the constant speed |v_a(w0)| of its own joint (an arc or a line), so over Δx its relative speed
    stays ≤ s0 + |Ω|·|v_a(w0)|·t and its path relative to the other part ≤ s0·Δx + |Ω|·|v_a(w0)|·Δx²/2.
    The relative speed is convex in w, so over the mesh the largest lies on the vertices of its
    convex hull (kept per pair, :func:`hull_points`). The smaller of the two meshes' figures is
    taken, grown by the thermal scale."""
    dx = abs(x1 - x0)
    kin = spec.kin
    omega = float(np.linalg.norm(_turn_rate(kin, rule.a) - _turn_rate(kin, rule.b)))
    best = math.inf
    for part, other, points in ((rule.a, rule.b, spec.hulls[rule.key][0]), (rule.b, rule.a, spec.hulls[rule.key][1])):
        m0 = kin.pose(part, x0)
        w = points @ m0[:3, :3].T + m0[:3, 3]
        own = _velocity(kin, part, w)
        s0 = np.linalg.norm(own - _velocity(kin, other, w), axis=1)
        path = s0 * dx + omega * np.linalg.norm(own, axis=1) * dx * dx / 2.0
        best = min(best, float(path.max()))
    return spec.grown * best


def interval_paths(spec: Spec, rule: PairRule, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """:func:`interval_path` over many intervals [x0[k], x1[k]] at once."""
    dx = np.abs(np.asarray(x1, float) - np.asarray(x0, float))
    if not len(dx):
        return dx
    kin = spec.kin
    omega = float(np.linalg.norm(_turn_rate(kin, rule.a) - _turn_rate(kin, rule.b)))
    best = np.full(len(dx), math.inf)
    for part, other, points in ((rule.a, rule.b, spec.hulls[rule.key][0]), (rule.b, rule.a, spec.hulls[rule.key][1])):
        m0 = kin.poses(part, x0)
        w = (points[None, :, :] @ np.swapaxes(m0[:, :3, :3], 1, 2) + m0[:, None, :3, 3]).reshape(-1, 3)
        own = _velocity(kin, part, w)
        s0 = np.linalg.norm(own - _velocity(kin, other, w), axis=1).reshape(len(dx), -1)
        speed = np.linalg.norm(own, axis=1).reshape(len(dx), -1)
        path = s0 * dx[:, None] + omega * speed * (dx * dx / 2.0)[:, None]
        best = np.minimum(best, path.max(axis=1))
    return spec.grown * best


def hull_points(mesh: MeshData) -> np.ndarray:
    """The vertices of the convex hull of a mesh's vertices (its part's frame): where a convex
    function of the point (a relative speed) is largest over the mesh. The box's corners where the
    hull cannot be built (a flat or tiny mesh)."""
    from scipy.spatial import ConvexHull, QhullError

    v = np.asarray(mesh.vertices, float)
    try:
        return v[ConvexHull(v).vertices]
    except (QhullError, ValueError):
        return _corners(mesh)


def plan_sweep(assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None,
               setting: tuple[str, float, str, float] = ("motion", math.nan, "", 0.0)) -> SweepPlan:
    """The tasks (runs of consecutive poses of one state), the reduce step, and the sweep's cost
    predicted from a measured sample of its work (:func:`calibrate`): ``setting`` is the template
    field that sets the poses, its value, unit and the motion's extent (0: a list of stops), named
    where the cost is over the budget."""
    from gearcheck.sweep_budget import SweepCost

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
    grown = 1.0 + max((abs(s - 1.0) for st in states for s in st.scales.values()), default=0.0)
    hulls = {key: (hull_points(ma), hull_points(mb)) for key, (ma, mb) in pairs.items()}
    resolution = {r.key: bodies[r.a].error_bound_mm + bodies[r.b].error_bound_mm for r in lay.pairs}
    live = tuple(k for k, r in enumerate(lay.pairs) if r.key not in far)
    index = {frozenset((r.a, r.b)): k for k, r in enumerate(lay.pairs)}
    spec = Spec(kin, lay.pairs, lay.play, lay.play_limit, lay.play_neighbours,
                {k: (a.name, b.name) for k, (a, b) in pairs.items()}, far, reach, margin,
                centres, play, hulls, grown, resolution, live, index)  # type: ignore[arg-type]
    tasked = spec.for_tasks()
    per_task = int(options.get("poses_per_task", POSES_PER_TASK))
    count = len(kin.coordinates)
    tasks, weights = [], []
    for st in states:
        for start in range(0, count, per_task):
            idx = list(range(start, min(count, start + per_task)))
            after = idx[-1] + 1 if idx[-1] + 1 < count else None
            tasks.append((sweep_poses, (tasked, st.name, idx, start == 0, after)))
            weights.append(len(idx))

    def reduce(results: list) -> SweepOutcome:
        from gearcheck.mechanisms.assembly.reduce import reduce_sweep

        return reduce_sweep(lay, spec, states, bodies, results,
                            {k: (a.faces.shape[0], b.faces.shape[0]) for k, (a, b) in pairs.items()})

    every = {**{k: v for k, v in pairs.items()}, **{f"{n}{sign:+g}": m for (n, sign), m in directed.items()}}
    meshes = state_meshes(states, bodies, every)
    cal = calibrate(tasked, meshes[:len(meshes) // len(states)])  # the file's own state: the first
    static = sum(not lay.pairs[k].moving for k in live)
    cost = SweepCost(count, len(states), len(live) - static, static, len(far), cal.pair_pose_s, cal.play_pose_s,
                     cal.setup_s, cal.seconds, *setting)
    return SweepPlan(meshes, tasks, reduce, weights=weights, unit="pose", options=options, cost=cost)


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
