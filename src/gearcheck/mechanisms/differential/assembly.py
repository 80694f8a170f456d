"""The differential's parts as data (numpy only): four spherical-involute bevel gears on their
axes, the big gears' titanium shafts and shims, and the housing mounting faces as simple
aluminium walls; their poses, materials, colours and motions, and the layout the sweep works
from.

Layout along a big gear's axis (from the common apex outwards, the paper's mounting drawing):
gear body to l12 behind its outer pitch circle plane, the Ti shaft (l11) up to the housing
mounting face at b/2, through the wall, and a collar outside the wall with the shim between
collar and wall: a shim of thickness x moves shaft and gear out by x (ΔS1 = x, eq. (11)). Small
gears bear on the housing mounting faces at a/2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.solids import Ring, RingStack
from gearcheck.mechanism import Assembly, PartSpec
from gearcheck.mechanisms.differential.poses import GearSpecs, assembly_poses, axis_of, gear_specs, homogeneous
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, GearThermal, thermal_state
from gearcheck.sweep.motion import Rotation

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

# Keys of the distinct solids (copies share one).
BIG_GEAR, SMALL_GEAR = "big_gear", "small_gear"
SHAFT, SHIM, BIG_WALL, SMALL_WALL = "shaft", "shim", "big_wall", "small_wall"


@dataclass(frozen=True)
class Layout:
    """What the sweep works from, derived from the parameters once: the two gear designs, the
    shim the parts were built with, the study shims, and each gear's warm → cold state at the
    built shim (scales and datums are the same for every shim; only the datum shifts change)."""

    specs: GearSpecs
    template_shim_mm: float
    study_shims_mm: tuple[float, ...]
    thermal: dict[str, GearThermal]
    big_gears: tuple[str, ...] = BIG_GEARS
    small_gears: tuple[str, ...] = SMALL_GEARS


def _axis_frame(pose: np.ndarray) -> np.ndarray:
    """The gear pose without its shim shift: the housing frame of that gear's axis."""
    return homogeneous(pose[:3, :3])


def _turning(pose: np.ndarray) -> Rotation:
    """Rotation about a gear's own axis through its apex."""
    return Rotation.about(axis_of(pose), pose[:3, 3])


def build_assembly(params) -> Assembly:
    specs = gear_specs(params)
    shim = params.shim.thickness_mm
    poses = assembly_poses(specs, shim).as_dict()
    materials = params.materials
    half_a = params.dimensions.a_mm / 2.0
    half_b = params.dimensions.b_mm / 2.0

    parts: list[PartSpec] = []
    for name, pose in poses.items():
        solid = BIG_GEAR if name.startswith("big") else SMALL_GEAR
        parts.append(PartSpec(name, solid, materials.gear, pose, STEEL, _turning(pose)))

    # one solid per kind, placed on each side by its axis frame
    back = specs.big.mounting_distance + shim  # gear back face, moved out by the shim
    wall_out = half_b + WALL_THICKNESS_MM
    solids = {
        BIG_GEAR: specs.big,
        SMALL_GEAR: specs.small,
        SHAFT: RingStack((Ring(0.0, SHAFT_RADIUS_MM, back, wall_out + shim),
                          Ring(0.0, COLLAR_RADIUS_MM, wall_out + shim, wall_out + shim + COLLAR_THICKNESS_MM))),
        BIG_WALL: Ring(SHAFT_RADIUS_MM + HOLE_CLEARANCE_MM, BIG_WALL_OUTER_RADIUS_MM, half_b, wall_out),
        SMALL_WALL: Ring(specs.small.bore_mm / 2.0 + HOLE_CLEARANCE_MM, SMALL_WALL_OUTER_RADIUS_MM,
                         half_a, half_a + WALL_THICKNESS_MM),
    }
    if shim > 0:
        solids[SHIM] = Ring(SHAFT_RADIUS_MM + HOLE_CLEARANCE_MM, COLLAR_RADIUS_MM, wall_out, wall_out + shim)
    for side in ("right", "left"):
        pose = poses[f"big_gear_{side}"]
        frame = _axis_frame(pose)
        parts.append(PartSpec(f"shaft_{side}", SHAFT, materials.shaft, frame, TITANIUM, _turning(pose)))
        if shim > 0:
            parts.append(PartSpec(f"shim_{side}", SHIM, "steel shim", frame, STEEL))
        parts.append(PartSpec(f"housing_face_{side}", BIG_WALL, materials.housing, frame, ALUMINIUM))
    for side in ("front", "back"):
        frame = _axis_frame(poses[f"small_gear_{side}"])
        parts.append(PartSpec(f"housing_face_{side}", SMALL_WALL, materials.housing, frame, ALUMINIUM))

    layout = Layout(specs=specs, template_shim_mm=shim, study_shims_mm=tuple(params.shim.study_mm),
                    thermal=thermal_state(params, specs=specs))
    return Assembly("differential", tuple(parts), solids, layout)
