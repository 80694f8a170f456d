"""Differential parts for `gearcheck build`: four spherical-involute bevel gears on their axes, the
big gears' titanium shafts and shims, and the housing mounting faces as simple aluminium walls.

Layout along a big gear's axis (from the common apex outwards, seed 000 fig. 3): gear body to
l12 behind its outer pitch circle plane, the Ti shaft (l11) up to the housing mounting face at b/2,
through the wall, and a collar outside the wall with the shim between collar and wall: a shim of
thickness x moves shaft and gear out by x (ΔS1 = x, eq. (11)). Small gears bear on the housing
mounting faces at a/2.
"""

from __future__ import annotations

import cadquery as cq
import numpy as np

from gearcheck.cad.bevel import build_bevel_gear
from gearcheck.cad.placement import Part
from gearcheck.mechanisms.differential.poses import assembly_poses, axis_of, gear_specs, homogeneous

# Simple bodies (not in the paper): wall thickness and sizes of shafts, collars and walls, mm.
WALL_THICKNESS_MM = 6.0
BIG_WALL_OUTER_RADIUS_MM = 30.0
SMALL_WALL_OUTER_RADIUS_MM = 20.0
SHAFT_RADIUS_MM = 9.9  # in the big gear's 20 mm bore
COLLAR_RADIUS_MM = 16.0
COLLAR_THICKNESS_MM = 3.0
HOLE_CLEARANCE_MM = 0.5

STEEL = (0.72, 0.72, 0.78)
TITANIUM = (0.55, 0.55, 0.6)
ALUMINIUM = (0.85, 0.85, 0.9)


def _ring(inner: float, outer: float, z0: float, z1: float) -> cq.Solid:
    """Annulus about +z between heights z0 < z1 (local frame of a gear axis)."""
    outer_cyl = cq.Solid.makeCylinder(outer, z1 - z0, cq.Vector(0, 0, z0))
    if inner <= 0:
        return outer_cyl
    return outer_cyl.cut(cq.Solid.makeCylinder(inner, z1 - z0, cq.Vector(0, 0, z0)))


def _axis_frame(pose: np.ndarray) -> np.ndarray:
    """The gear pose without its shim shift: the housing frame of that gear's axis."""
    return homogeneous(pose[:3, :3])


def build_parts(params) -> list[Part]:
    specs = gear_specs(params)
    shim = params.shim.thickness_mm
    poses = assembly_poses(specs, shim).as_dict()
    big = build_bevel_gear(specs.big).solid
    small = build_bevel_gear(specs.small).solid
    materials = params.materials
    half_a = params.dimensions.a_mm / 2.0
    half_b = params.dimensions.b_mm / 2.0

    parts: list[Part] = []
    for name, pose in poses.items():
        is_big = name.startswith("big")
        parts.append(Part(name, materials.gear, big if is_big else small, pose, STEEL,
                          motion={"kind": "rotation", "axis": axis_of(pose).tolist(),
                                  "origin": pose[:3, 3].tolist()}))

    # one solid per kind, placed on each side by its axis frame
    back = specs.big.mounting_distance + shim  # gear back face, moved out by the shim
    wall_out = half_b + WALL_THICKNESS_MM
    shaft = _ring(0.0, SHAFT_RADIUS_MM, back, wall_out + shim).fuse(
        _ring(0.0, COLLAR_RADIUS_MM, wall_out + shim, wall_out + shim + COLLAR_THICKNESS_MM)).clean()
    shim_ring = _ring(SHAFT_RADIUS_MM + HOLE_CLEARANCE_MM, COLLAR_RADIUS_MM, wall_out, wall_out + shim) if shim > 0 else None
    big_wall = _ring(SHAFT_RADIUS_MM + HOLE_CLEARANCE_MM, BIG_WALL_OUTER_RADIUS_MM, half_b, wall_out)
    small_wall = _ring(specs.small.bore_mm / 2.0 + HOLE_CLEARANCE_MM, SMALL_WALL_OUTER_RADIUS_MM,
                       half_a, half_a + WALL_THICKNESS_MM)
    for side in ("right", "left"):
        pose = poses[f"big_gear_{side}"]
        frame = _axis_frame(pose)
        parts.append(Part(f"shaft_{side}", materials.shaft, shaft, frame, TITANIUM,
                          motion={"kind": "rotation", "axis": axis_of(pose).tolist(), "origin": pose[:3, 3].tolist()}))
        if shim_ring is not None:
            parts.append(Part(f"shim_{side}", "steel shim", shim_ring, frame, STEEL))
        parts.append(Part(f"housing_face_{side}", materials.housing, big_wall, frame, ALUMINIUM))
    for side in ("front", "back"):
        frame = _axis_frame(poses[f"small_gear_{side}"])
        parts.append(Part(f"housing_face_{side}", materials.housing, small_wall, frame, ALUMINIUM))
    return parts
