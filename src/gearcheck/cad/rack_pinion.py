"""Nose-wheel steering pinion sector and trimmed rack as B-rep solids, from numpy data.

Both parts are planar outlines extruded along z (mid-plane z = 0), so each solid is exact where
its profile is exact:

- Pinion (its own frame: centre at the origin, axis +z, polar angle γ from −y counter-clockwise,
  tooth j centred at γ = (j + ½)·τ): per sector tooth, B-spline trochoid fillets and involute
  flanks interpolating exact points (:func:`gearcheck.geometry.rack_pinion.pinion_tooth_pieces`),
  a tip arc (radius Ra, or RS1 on G1 and its mirror); root-circle arcs between teeth and round
  the back; the bore as the inner wire. Pose at pinion angle φ
  (:func:`gearcheck.geometry.rack_pinion.pinion_pose`): turn by φ about z, move to (0, H).
- Rack (its own frame is the world frame at travel 0: datum face y = 0, tooth k centred at
  x = k·p): the polygon of :meth:`RackPinionGeometry.rack_outline` — straight flanks, the trimmed
  tops S2–S6 / S4–S8 as straight lines between their corners, sharp roots, the bar down to the
  datum. Pose at travel L (:func:`gearcheck.geometry.rack_pinion.rack_pose`): move by L along x.

The paper gives neither face width nor bore: they come in as arguments (a mechanism's part specs,
:class:`gearcheck.geometry.rack_pinion.PinionSpec` / ``RackSpec``). Poses, materials and motions
are the mechanism's (its assembly); this module builds solids only.
"""

from __future__ import annotations

import math

import cadquery as cq
import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire
from OCP.BRepCheck import BRepCheck_Analyzer

from gearcheck.geometry import rack_pinion as rp
from gearcheck.geometry.rack_pinion import RackPinionGeometry, bore_fits

# Exact points interpolated per involute flank (uniform in roll angle). Measured on the built
# solid against the closed-form involute (docs/rack_pinion_cad.md): 8 → 0.047 µm, 12 → 0.008 µm,
# 24 → 0.0005 µm; far inside the 1 µm the zero-backlash sweep needs.
FLANK_SPLINE_POINTS = 24
# Exact trochoid points per fillet (not a contact surface; the fillet meets the involute at the
# form circle, where both share the point and, in theory, the tangent).
FILLET_SPLINE_POINTS = 24


def _v(p: np.ndarray, z: float) -> cq.Vector:
    return cq.Vector(float(p[0]), float(p[1]), z)


def _wire(edges: list[cq.Edge], what: str) -> cq.Wire:
    maker = BRepBuilderAPI_MakeWire()
    for e in edges:
        maker.Add(e.wrapped)
    if not maker.IsDone():
        raise RuntimeError(f"{what} outline does not close into a wire")
    return cq.Wire(maker.Wire())


def is_valid(shape: cq.Shape) -> bool:
    """BRepCheck_Analyzer on the whole shape."""
    return BRepCheck_Analyzer(shape.wrapped).IsValid()


# ---------------------------------------------------------------------------------- pinion

def pinion_outline_wire(g: RackPinionGeometry, z: float = 0.0, flank_points: int = FLANK_SPLINE_POINTS,
                        fillet_points: int = FILLET_SPLINE_POINTS) -> cq.Wire:
    """The pinion's outline in the plane z of its own frame, counter-clockwise: the sector teeth
    j = first…last with root arcs between them, and the root circle round the back."""
    rf = g.root_radius
    land = rp.pinion_root_land_start(g)
    first, last = g.sector_first_tooth, g.sector_last_tooth
    edges: list[cq.Edge] = []
    for j in range(first, last + 1):
        centre = float(g.pinion_tooth_angle(j, 0.0))
        for piece in rp.pinion_tooth_pieces(g, j, flank_points, fillet_points):
            pts = [_v(p, z) for p in rp.pinion_local_xy(piece.rho, piece.gamma + centre)]
            if piece.kind == "tip":
                edges.append(cq.Edge.makeThreePointArc(*pts))
            else:
                edges.append(cq.Edge.makeSpline(pts))
        # root land to the next tooth; after the last tooth, round the back to the first
        start = centre + land
        end = (centre + g.angular_pitch - land if j < last
               else float(g.pinion_tooth_angle(first, 0.0)) - land + 2.0 * math.pi)
        arc = rp.pinion_local_xy(np.full(3, rf), np.array([start, 0.5 * (start + end), end]))
        edges.append(cq.Edge.makeThreePointArc(*(_v(p, z) for p in arc)))
    return _wire(edges, "pinion")


def build_pinion(g: RackPinionGeometry, face_width_mm: float, bore_diameter_mm: float,
                 flank_points: int = FLANK_SPLINE_POINTS) -> cq.Solid:
    """The pinion solid in its own frame, z from −b/2 to b/2 (b = ``face_width_mm``), with a
    bore of ``bore_diameter_mm`` (inside the root circle)."""
    if not bore_fits(g.root_radius, bore_diameter_mm):
        raise ValueError("pinion bore reaches the root circle")
    z0 = -face_width_mm / 2.0
    outer = pinion_outline_wire(g, z0, flank_points)
    bore = cq.Wire.makeCircle(bore_diameter_mm / 2.0, cq.Vector(0, 0, z0), cq.Vector(0, 0, 1))
    return cq.Solid.extrudeLinear(outer, [bore], cq.Vector(0, 0, face_width_mm))


# ------------------------------------------------------------------------------------ rack

def rack_outline_wire(g: RackPinionGeometry, z: float = 0.0) -> cq.Wire:
    """The rack's outline in the plane z of its own frame (all straight lines)."""
    pts = [_v(p, z) for p in g.rack_outline(0.0)]
    return cq.Wire.makePolygon(pts, close=True)


def build_rack(g: RackPinionGeometry, face_width_mm: float) -> cq.Solid:
    """The rack solid in its own frame, z from −b/2 to b/2; its bottom face is the datum y = 0."""
    z0 = -face_width_mm / 2.0
    return cq.Solid.extrudeLinear(rack_outline_wire(g, z0), [], cq.Vector(0, 0, face_width_mm))
