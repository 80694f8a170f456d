"""The assembly sweep's meshes and states (numpy): the temperature states (each part grown by its
own CTE about its datum), each pair's meshes pruned to what comes within a margin of the other
over the motion, the play part's directed meshes for each sense, every state's copies."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gearcheck.mechanisms.assembly.assembly import Layout, PairRule
from gearcheck.mechanisms.assembly.kinematics import Kinematics
from gearcheck.sweep.bodies import Body, MeshData, submesh
from gearcheck.sweep.motion import Rotation
from gearcheck.sweep.prune import approaching_faces, largest_step, near_faces

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


def axis_radius(line, point: np.ndarray) -> float:
    """Distance of a world point from a revolute joint's axis (mm)."""
    axis, origin = np.asarray(line.motion.axis, float), np.asarray(line.motion.origin, float)
    v = point - origin
    return float(np.linalg.norm(v - axis * (v @ axis)))


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


def overlap_mover(kin: Kinematics, rule: PairRule) -> str | None:
    """The part moved to free an overlapping pair: a jointed part of the pair, the driven one first."""
    jointed = [p for p in (rule.b, rule.a) if p in kin.lines]
    driven = [p for p in jointed if p != kin.driver]
    return (driven or jointed)[0] if jointed else None


def box_corners(mesh: MeshData) -> np.ndarray:
    """The corners of the mesh's box, in its own frame (every vertex lies inside it)."""
    v = np.asarray(mesh.vertices, float)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def reach_mm(kin: Kinematics, part: str, move: float, corners: np.ndarray) -> float:
    """The largest displacement (mm) of any point of ``part`` when its joint moves by ``move``."""
    line = kin.lines.get(part)
    if line is None or move <= 0.0:
        return 0.0
    if line.unit == "mm":
        return move
    return max(axis_radius(line, c) for c in corners) * 2.0 * math.sin(math.radians(move) / 2.0)


def base_margin(lay: Layout) -> float:
    """The distance below which every figure of a pruned pair is exact (mm): at least 1 mm, twice
    the largest required clearance and twice the contact tolerance."""
    required = [r.min_clearance_mm for r in lay.pairs if r.kind == "clearance"]
    return max(1.0, 2.0 * max(required, default=0.0), 2.0 * lay.contact_tolerance_mm)


def swept_capsule(kin: Kinematics, part: str, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """A capsule (a segment and a radius, world) holding ``part`` wherever its coupled motion takes
    it, between the poses too: a turning part's cylinder of revolution about its axis (any turn), a
    sliding part's box swept over its stroke, a part the motion does not move its box's sphere."""
    centre = corners.mean(axis=0)
    half = 0.5 * float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0)))
    line = kin.lines.get(part)
    if line is None or part not in kin.moving():
        return centre, centre, half
    axis = np.asarray(line.motion.axis, float)
    if isinstance(line.motion, Rotation):
        origin = np.asarray(line.motion.origin, float)
        v = corners - origin
        h = v @ axis
        radius = float(np.linalg.norm(v - np.outer(h, axis), axis=1).max())
        return origin + axis * h.min(), origin + axis * h.max(), radius
    q = line.gain * kin.coordinates + line.offset
    return centre + axis * float(q.min()), centre + axis * float(q.max()), half


# The pruning places the parts at every s-th pose where s steps move no point more than this share
# of the base margin (the margins grow by the larger step between the poses it keeps).
PRUNE_STEP_SHARE = 0.125


def pruning_coordinates(kin: Kinematics, corners: Mapping[str, np.ndarray], base: float) -> np.ndarray:
    """The driver coordinates the pruning places the parts at: every pose, or, where the poses are
    much closer together than the margin needs (a fine step), every s-th of them and the last, s
    steps moving no point of any part more than :data:`PRUNE_STEP_SHARE` of the base margin. Each
    pruning step adds the largest step between the coordinates it keeps to its margin, so it stays
    right: it keeps more faces where it keeps fewer poses, in time and memory that do not grow with
    a finer motion."""
    x = kin.coordinates
    if len(x) <= 2:
        return x
    dx = float(np.abs(np.diff(x)).max())
    step = max((reach_mm(kin, p, abs(kin.lines[p].gain) * dx, corners[p]) for p in kin.moving() if p in corners),
               default=0.0)
    stride = int(PRUNE_STEP_SHARE * base / step) if step > 0.0 else 1
    if stride <= 1:
        return x
    return np.concatenate([x[::stride], x[-1:]]) if (len(x) - 1) % stride else x[::stride]


def near_pairs(lay: Layout, kin: Kinematics, corners: Mapping[str, np.ndarray], growth: float) -> np.ndarray:
    """Which pairs (in ``lay.pairs`` order) can come within the pruning margin over the motion, from
    a lower bound of their distance over the whole motion, between the poses too (the larger of: the
    gap between their swept boxes less each one's largest step between poses; the gap between their
    swept capsules): the pairs the faces are then pruned for. The margin here is the pruning
    margin less its step term (the bound holds between the poses): the base margin, the play searched
    (or the base margin again), the thermal growth of both."""
    from gearcheck.sweep.prune import box_gaps, segment_distances, swept_box

    if not lay.pairs:
        return np.zeros(0, bool)
    base = base_margin(lay)
    names = list(corners)
    index = {p: k for k, p in enumerate(names)}
    moving = set(kin.moving())
    coordinates = pruning_coordinates(kin, corners, base)
    lo, hi, step = np.empty((len(names), 3)), np.empty((len(names), 3)), np.empty(len(names))
    seg = np.empty((2, len(names), 3))
    radius = np.empty(len(names))
    for k, p in enumerate(names):
        xs = coordinates if p in moving else coordinates[:1]
        lo[k], hi[k], step[k] = swept_box(corners[p], kin.poses(p, xs))
        seg[0, k], seg[1, k], radius[k] = swept_capsule(kin, p, corners[p])
    i = np.array([index[r.a] for r in lay.pairs])
    j = np.array([index[r.b] for r in lay.pairs])
    play_reach = {p: reach_mm(kin, p, lay.play_limit, corners[p]) for p in names if p == lay.play}
    reach = np.array([max([play_reach.get(r.a, 0.0), play_reach.get(r.b, 0.0), base]) for r in lay.pairs])
    lower = np.maximum(box_gaps(lo, hi, i, j) - step[i] - step[j],
                       segment_distances(seg[0, i], seg[1, i], seg[0, j], seg[1, j]) - radius[i] - radius[j])
    return lower <= base + reach + 2.0 * growth


def pair_meshes(lay: Layout, kin: Kinematics, bodies: Mapping[str, Body], states: list[StateSpec]
                ) -> tuple[dict[str, tuple[MeshData, MeshData]], frozenset[str], dict[str, float], float]:
    """Each pair's two meshes pruned to what comes within the margin of the other over the motion
    (:mod:`gearcheck.sweep.prune`); the pairs never within it; each pair's clearing-move reach (the
    mover's unit: a move that displaces no point more than the base margin); the base margin.
    Pairs whose swept volumes never come within the margin (:func:`near_pairs`) are far without
    a face placed; the others' relative poses are computed for all poses at once."""
    from gearcheck.sweep.prune import relative_poses

    base = base_margin(lay)
    corners = {p: box_corners(b.mesh) for p, b in bodies.items()}
    growth = max((abs(st.scales.get(p, 1.0) - 1.0) * float(np.linalg.norm(c - np.asarray(st.datums.get(p, (0, 0, 0))),
                                                                          axis=1).max())
                  for st in states for p, c in corners.items()), default=0.0)
    unit_reach = {p: reach_mm(kin, p, 1.0, corners[p]) for p in bodies}  # mm per unit move (deg or mm)
    near = near_pairs(lay, kin, corners, growth)
    coordinates = pruning_coordinates(kin, corners, base)
    meshes, far, reach = {}, set(), {}
    for rule, candidate in zip(lay.pairs, near, strict=True):
        mover = overlap_mover(kin, rule)
        if mover is None:
            reach[rule.key] = 0.0
        else:
            reach[rule.key] = base / unit_reach[mover] if unit_reach[mover] > 0 else 0.0
        if not candidate:
            far.add(rule.key)
            continue
        play_reach = max((reach_mm(kin, p, lay.play_limit, corners[p]) for p in (rule.a, rule.b) if p == lay.play),
                         default=0.0)
        xs = coordinates if rule.moving else coordinates[:1]
        pose_a, pose_b = kin.poses(rule.a, xs), kin.poses(rule.b, xs)
        masks = []
        for me, other, rel in ((rule.a, rule.b, relative_poses(pose_a, pose_b)),
                               (rule.b, rule.a, relative_poses(pose_b, pose_a))):
            step = largest_step(corners[other], rel)
            margin = base + max(base, play_reach) + step + 2.0 * growth
            masks.append(near_faces(bodies[me].mesh, bodies[other].mesh, rel, margin, step=step))
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
