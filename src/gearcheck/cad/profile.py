"""Prismatic solids from a planar outline (numpy in, B-rep out): a straight extrusion of a closed
polygon, with an optional round bore. For parts whose exact shape *is* that polygon (a plate,
a gear whose outline is given point by point), so the solid is exact wherever its outline is.
"""

from __future__ import annotations

import cadquery as cq
import numpy as np


def extruded_outline(outline_xy: np.ndarray, width_mm: float, bore_radius_mm: float = 0.0) -> cq.Solid:
    """The closed polygon ``outline_xy`` ((n, 2), counter-clockwise, mm, own frame) extruded along
    +z from z = −width/2 to +width/2, less a bore of ``bore_radius_mm`` about the z axis."""
    points = np.asarray(outline_xy, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise ValueError("an outline is an (n ≥ 3, 2) array of points")
    z0 = -width_mm / 2.0
    wire = cq.Wire.makePolygon([cq.Vector(float(x), float(y), z0) for x, y in points], close=True)
    holes = []
    if bore_radius_mm > 0.0:
        holes.append(cq.Wire.makeCircle(bore_radius_mm, cq.Vector(0, 0, z0), cq.Vector(0, 0, 1)))
    solid = cq.Solid.extrudeLinear(wire, holes, cq.Vector(0, 0, width_mm))
    if not solid.isValid():
        raise RuntimeError("extruded outline is not a valid solid (self-intersecting outline?)")
    return solid
