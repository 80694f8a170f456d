"""The exact B-rep confirmation of a sweep's worst poses: each pose re-measured on the CAD solids
(the faces around the meshes' nearest points, or the whole solids where the meshes overlap), and
the verdict that mesh and B-rep agree within the pair's mesh-error bound. A stage of
:mod:`gearcheck.pipeline`."""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from gearcheck.results import CheckResult, Confirmation, Verdict

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.pipeline import ProgressFactory
    from gearcheck.sweep.bodies import Body

log = logging.getLogger("gearcheck")


class _MeshPairs:
    """The meshes at the worst poses, for :func:`confirm`: one FCL scene per pair of parts at
    given scales, built once and posed for each worst pose that needs it. What it answers is
    what :func:`gearcheck.sweep.tools.meshes_overlap` and
    :func:`gearcheck.sweep.tools.mesh_nearest_midpoint` answer (the same meshes, scaled the same
    way, the same FCL queries); only the bounding-volume trees are not rebuilt for each query."""

    def __init__(self, bodies: Mapping[str, Body]):
        self.bodies = bodies
        self.scenes: dict[tuple, Any] = {}

    def _posed(self, name_a: str, name_b: str, worst: Any) -> Any:
        import numpy as np

        from gearcheck.sweep.engine import Scene

        key = (name_a, float(worst.scale_a), name_b, float(worst.scale_b))
        if key not in self.scenes:
            self.scenes[key] = Scene([self.bodies[name_a].scaled(worst.scale_a).mesh,
                                      self.bodies[name_b].scaled(worst.scale_b).mesh])
        scene = self.scenes[key]
        scene.set_pose(name_a, np.asarray(worst.pose_a, float))
        scene.set_pose(name_b, np.asarray(worst.pose_b, float))
        return scene

    def overlap(self, worst: Any) -> bool:
        """Whether the two meshes intersect at the worst pose (whole parts; the sweep's answer
        where it gave one)."""
        if worst.mesh_overlap is not None:
            return bool(worst.mesh_overlap)
        a, b = (n.partition(".")[0] for n in (worst.part_a, worst.part_b))
        return bool(self._posed(a, b, worst).collide(a, b))

    def nearest_midpoint(self, worst: Any) -> Any:
        """Where the meshes come closest (world frame; the sweep's answer where it gave one);
        None for a feature of a part."""
        import numpy as np

        if "." in worst.part_a or "." in worst.part_b:
            return None
        if worst.mesh_nearest_midpoint is not None:
            return np.asarray(worst.mesh_nearest_midpoint, float)
        d = self._posed(worst.part_a, worst.part_b, worst).distance(worst.part_a, worst.part_b)
        return 0.5 * (d.point_a + d.point_b)


def confirm(result: CheckResult, parts: list[Part], bodies: Mapping[str, Body],
            progress: ProgressFactory | None = None) -> list[Confirmation]:
    """Each worst pose re-measured on the exact B-rep (faces around the meshes' nearest points)."""
    from gearcheck.cad.confirm import contact_state, exact_closest, exact_overlap_closest
    from gearcheck.pipeline import no_progress

    progress = progress or no_progress

    by_name = {p.name: p for p in parts}
    meshes = _MeshPairs(bodies)
    log.info("stage confirm: %d worst poses on the exact B-rep", len(result.worst_poses))
    out = []
    with progress("exact B-rep distance at worst poses", len(result.worst_poses), "pose") as bar:
        for worst in result.worst_poses:
            bound = sum(bodies[n.partition(".")[0]].error_bound_mm for n in (worst.part_a, worst.part_b))
            overlap = None
            if worst.mesh_distance_mm <= 0.0 or meshes.overlap(worst):
                # the meshes' nearest points mean nothing here: measure the whole solids
                brep, overlap, point_a, point_b = exact_overlap_closest(by_name, worst)
            else:
                brep, point_a, point_b = exact_closest(by_name, worst, near=meshes.nearest_midpoint(worst))
            contact, depth = "", math.nan
            if brep <= bound:  # within the bound of zero: touching, overlapping, or clear?
                contact, depth = contact_state(by_name, worst, brep, overlap, (point_a + point_b) / 2.0)
            out.append(Confirmation(worst.label, worst.json_key, f"{worst.part_a} / {worst.part_b}",
                                    worst.mesh_distance_mm, brep, bound, overlap,
                                    tuple(float(v) for v in point_a), tuple(float(v) for v in point_b),
                                    contact, depth))
            bar.update(1)
    keys = [c.key for c in out]
    if len(set(keys)) != len(keys):  # summary.json keeps one entry per key: none may be lost
        raise RuntimeError(f"worst poses must have distinct keys, got {keys}")
    return out


def confirmation_verdict(confirmations: list[Confirmation], rule: Any = None) -> Verdict:
    """The exact B-rep confirmation as a verdict: at every worst pose the mesh and the exact
    solids agree within the pair's mesh-error bound (distances at free poses; contact or overlap
    where the meshes overlap). Where the meshes cannot resolve the design's smallest clearance
    (``rule``: :class:`gearcheck.resolution.Resolution`), the B-rep figures are the evidence at
    those poses, and the verdict says so."""
    bad = [c for c in confirmations if not c.agrees]
    parts = []
    for c in confirmations:
        if c.meshes_overlap:
            if c.overlap_mm3 == c.overlap_mm3:  # not NaN
                measure = f"common volume {c.overlap_mm3:.4g} mm³"
            else:
                measure = (f"no Boolean gave a common volume; sampled penetration depth {c.depth_mm * 1e3:.2f} µm"
                           if math.isfinite(c.depth_mm) else "common volume not computed")
            parts.append(f"{c.parts}: meshes overlap, exact distance {c.brep_mm:.2e} mm, solids "
                         f"{c.contact or 'in contact'} ({measure})")
        else:
            parts.append(f"{c.parts}: mesh {c.mesh_mm:.5f} vs B-rep {c.brep_mm:.5f} mm (bound {c.bound_mm:.4f})")
    unresolved = rule is not None and not rule.resolves
    evidence = ("exact B-rep: the meshes cannot resolve the smallest clearance, so the B-rep distances at the "
                "worst poses are the evidence there" if unresolved else "exact B-rep against the mesh sweep")
    return Verdict.of("exact_confirmation", "worst poses confirmed on the exact B-rep", not bad,
                      "; ".join(parts) if parts else "no worst pose to confirm",
                      {"poses": float(len(confirmations)), "disagreeing": float(len(bad))}, evidence=evidence)
