"""Exact B-rep distance (OCC BRepExtrema) at a sweep's worst poses.

About 2.5 s per pose on whole gears, so only the few worst poses are confirmed: the mesh sweep
finds them, this measures them without chord error.
"""

from __future__ import annotations

import numpy as np
from OCP.BRepExtrema import BRepExtrema_DistShapeShape

from gearcheck.cad.placement import Part, place
from gearcheck.sweep.result import WorstPose


def _posed(parts: dict[str, Part], name: str, pose, scale: float):
    """``name`` is a part ("link_03") or one of its features ("link_03.plate")."""
    base, _, feature = name.partition(".")
    solid = parts[base].feature(feature)
    if scale != 1.0:
        solid = solid.scale(scale)  # about the own-frame origin
    return place(solid, np.asarray(pose, float))


def exact_distance(parts: dict[str, Part], worst: WorstPose) -> float:
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    dist = BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    if not dist.IsDone():
        raise RuntimeError(f"BRepExtrema failed at {worst.label}")
    return float(dist.Value())
