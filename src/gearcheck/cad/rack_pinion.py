"""Nose-wheel steering pinion sector and trimmed rack as B-rep solids (seed 003), from numpy data.

Both parts are planar outlines extruded along z (mid-plane z = 0), so each solid is exact where
its profile is exact:

- Pinion (its own frame: centre at the origin, axis +z, polar angle γ from −y counter-clockwise,
  tooth j centred at γ = (j + ½)·τ): per sector tooth, B-spline trochoid fillets and involute
  flanks interpolating exact points (:func:`gearcheck.geometry.rack_pinion.pinion_tooth_pieces`),
  a tip arc (radius Ra, or RS1 on G1 and its mirror); root-circle arcs between teeth and round
  the back; the bore as the inner wire. Pose at pinion angle φ: turn by φ about z, move to (0, H).
- Rack (its own frame is the world frame at travel 0: datum face y = 0, tooth k centred at
  x = k·p): the polygon of :meth:`RackPinionGeometry.rack_outline` — straight flanks, the trimmed
  tops S2–S6 / S4–S8 as straight lines between their corners, sharp roots, the bar down to the
  datum. Pose at travel L: move by L along x.

The paper gives neither face width, bore nor materials: they are named constants here.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import cadquery as cq
import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire
from OCP.BRepCheck import BRepCheck_Analyzer

from gearcheck.geometry import rack_pinion as rp
from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.cad.placement import Part
# Face width and pinion bore (not in the paper) live with the mechanism, whose template model
# checks that the bore fits before any CAD work; re-exported here.
from gearcheck.mechanisms.steering.layout import FACE_WIDTH_MM, PINION_BORE_DIAMETER_MM, bore_fits

# Exact points interpolated per involute flank (uniform in roll angle). Measured on the built
# solid against the closed-form involute (docs/rack_pinion_cad.md): 8 → 0.047 µm, 12 → 0.008 µm,
# 24 → 0.0005 µm; far inside the 1 µm the zero-backlash sweep needs.
FLANK_SPLINE_POINTS = 24
# Exact trochoid points per fillet (not a contact surface; the fillet meets the involute at the
# form circle, where both share the point and, in theory, the tangent).
FILLET_SPLINE_POINTS = 24
# Materials (not in the paper; aircraft steering gears are through-hardened alloy steel).
PINION_MATERIAL = "steel"
RACK_MATERIAL = "steel"


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


def build_pinion(g: RackPinionGeometry, face_width_mm: float = FACE_WIDTH_MM,
                 bore_diameter_mm: float = PINION_BORE_DIAMETER_MM,
                 flank_points: int = FLANK_SPLINE_POINTS) -> cq.Solid:
    """The pinion solid in its own frame, z from −b/2 to b/2."""
    if not bore_fits(g.root_radius, bore_diameter_mm):
        raise ValueError("pinion bore reaches the root circle")
    z0 = -face_width_mm / 2.0
    outer = pinion_outline_wire(g, z0, flank_points)
    bore = cq.Wire.makeCircle(bore_diameter_mm / 2.0, cq.Vector(0, 0, z0), cq.Vector(0, 0, 1))
    return cq.Solid.extrudeLinear(outer, [bore], cq.Vector(0, 0, face_width_mm))


def pinion_pose(g: RackPinionGeometry, phi: float) -> np.ndarray:
    """Pinion frame → world at pinion angle φ (counter-clockwise about z, centre at (0, H, 0))."""
    c, s = math.cos(phi), math.sin(phi)
    pose = np.eye(4)
    pose[:2, :2] = [[c, -s], [s, c]]
    pose[1, 3] = g.centre_to_datum_mm
    return pose


# ------------------------------------------------------------------------------------ rack

def rack_outline_wire(g: RackPinionGeometry, z: float = 0.0) -> cq.Wire:
    """The rack's outline in the plane z of its own frame (all straight lines)."""
    pts = [_v(p, z) for p in g.rack_outline(0.0)]
    return cq.Wire.makePolygon(pts, close=True)


def build_rack(g: RackPinionGeometry, face_width_mm: float = FACE_WIDTH_MM) -> cq.Solid:
    """The rack solid in its own frame, z from −b/2 to b/2; its bottom face is the datum y = 0."""
    z0 = -face_width_mm / 2.0
    return cq.Solid.extrudeLinear(rack_outline_wire(g, z0), [], cq.Vector(0, 0, face_width_mm))


def rack_pose(travel_mm: float) -> np.ndarray:
    """Rack frame → world at travel L (along +x)."""
    pose = np.eye(4)
    pose[0, 3] = travel_mm
    return pose


# ----------------------------------------------------------------------------------- parts

@dataclass(frozen=True)
class SteeringParts:
    """Pinion and rack at one pose, and what built them."""

    geometry: RackPinionGeometry
    pinion: Part
    rack: Part
    build_s: dict[str, float] = field(default_factory=dict)

    @property
    def parts(self) -> list[Part]:
        return [self.pinion, self.rack]


def steering_parts(params, pinion_angle_rad: float = 0.0, rack_travel_mm: float = 0.0,
                   face_width_mm: float = FACE_WIDTH_MM) -> SteeringParts:
    """Pinion and rack for the steering template's ``Params``. The default pose is angle 0
    (φ = 0, L = 0): pinion centre at (0, H, 0), rack tooth k = 0 centred under it, tight mesh."""
    from gearcheck.mechanisms.steering import analysis  # owns the template → geometry mapping

    g = analysis.geometry_from_params(params)
    t0 = time.perf_counter()
    pinion = build_pinion(g, face_width_mm)
    t1 = time.perf_counter()
    rack = build_rack(g, face_width_mm)
    t2 = time.perf_counter()
    return SteeringParts(
        geometry=g,
        pinion=Part("pinion", PINION_MATERIAL, pinion, pinion_pose(g, pinion_angle_rad), motion={"kind": "rotation", "axis": [0.0, 0.0, 1.0], "origin": [0.0, float(g.centre_to_datum_mm), 0.0]}),
        rack=Part("rack", RACK_MATERIAL, rack, rack_pose(rack_travel_mm), motion={"kind": "translation", "axis": [1.0, 0.0, 0.0]}),
        build_s={"pinion": t1 - t0, "rack": t2 - t1},
    )
