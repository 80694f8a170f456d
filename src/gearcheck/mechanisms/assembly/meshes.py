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


def pair_meshes(lay: Layout, kin: Kinematics, bodies: Mapping[str, Body], states: list[StateSpec]
                ) -> tuple[dict[str, tuple[MeshData, MeshData]], frozenset[str], dict[str, float], float]:
    """Each pair's two meshes pruned to what comes within the margin of the other over the motion
    (:mod:`gearcheck.sweep.prune`); the pairs never within it; each pair's clearing-move reach (the
    mover's unit: a move that displaces no point more than the base margin); the base margin."""
    base = base_margin(lay)
    corners = {p: box_corners(b.mesh) for p, b in bodies.items()}
    growth = max((abs(st.scales.get(p, 1.0) - 1.0) * float(np.linalg.norm(c - np.asarray(st.datums.get(p, (0, 0, 0))),
                                                                          axis=1).max())
                  for st in states for p, c in corners.items()), default=0.0)
    meshes, far, reach = {}, set(), {}
    for rule in lay.pairs:
        mover = overlap_mover(kin, rule)
        if mover is None:
            reach[rule.key] = 0.0
        else:
            unit_reach = reach_mm(kin, mover, 1.0, corners[mover])  # mm per unit move (deg or mm)
            reach[rule.key] = base / unit_reach if unit_reach > 0 else 0.0
        play_reach = max((reach_mm(kin, p, lay.play_limit, corners[p]) for p in (rule.a, rule.b) if p == lay.play),
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
