"""Where the differential's parts sit: gear specs and 4×4 poses (numpy only; poses are data).

World frame: the common apex at the origin, the output shafts (big gears) on ±Y, the cross axis
(small gears) on ±X. Each gear's own frame has its apex at the origin, its axis +z pointing from
the apex into its body, and tooth 0 on +x (:mod:`gearcheck.geometry.bevel`).

Phasing comes from :func:`gearcheck.geometry.bevel.mate_rotation` (tooth centre opposite a
tooth-space centre, so the designed backlash splits evenly between the flanks). The two small
gears sit 180° apart on each big gear; the second big gear is phased from the first small gear,
and the assembly condition (z_big + z_big) / 2 integer, checked in :func:`assembly_poses`,
makes it mesh with the second small gear too.

The shim moves each big gear (and its shaft) out along its own axis by the shim thickness: its
apex leaves the common apex by x, which is what opens the backlash (the paper's shim section, ΔS1 = x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bevel import BevelGearSpec, mate_rotation

# Bores: not in the paper; a shaft through the big gear, a pin through the small one.
BIG_GEAR_BORE_MM = 20.0
SMALL_GEAR_BORE_MM = 10.0


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def homogeneous(rotation: np.ndarray, translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


# local frame → world, for a gear whose axis points along world ±Y or ±X (columns: x, y, z)
FRAME_PLUS_Y = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class GearSpecs:
    big: BevelGearSpec
    small: BevelGearSpec


def design_thinning_min_mm(params) -> float:
    """The least tooth thinning of one mesh the gears are built with: solved from a measured
    backlash when the template is calibrated (:mod:`.calibration`, stored by the validation),
    else the template's ``backlash.mesh_thinning_min_mm``."""
    solved = params.design_thinning() if hasattr(params, "design_thinning") else None
    return solved.min_mm if solved is not None else params.backlash.mesh_thinning_min_mm


def gear_specs(params, thinning_mm: float | None = None) -> GearSpecs:
    """The two gear designs from the template: long/short addendum (+x on the small gear, −x on
    the big one) and the mesh thinning split equally between the two gears — the designed least
    (the tightest mesh, the one that binds first when cold, :func:`design_thinning_min_mm`) unless
    ``thinning_mm`` is given."""
    g = params.gears
    thinning = (design_thinning_min_mm(params) if thinning_mm is None else thinning_mm) / 2.0
    d = params.dimensions
    small = BevelGearSpec(
        teeth=g.small_teeth, mate_teeth=g.big_teeth, module_mm=g.module_mm,
        face_width_mm=g.face_width_mm, pressure_angle_deg=g.pressure_angle_deg,
        shaft_angle_deg=g.shaft_angle_deg, profile_shift=g.small_profile_shift,
        thinning_mm=thinning, bore_mm=SMALL_GEAR_BORE_MM,
        # small gear: mounting face a/2 from the apex (the paper's mounting drawing: l2 behind the pitch circle)
        mounting_distance_mm=d.a_mm / 2.0,
    )
    big = BevelGearSpec(
        teeth=g.big_teeth, mate_teeth=g.small_teeth, module_mm=g.module_mm,
        face_width_mm=g.face_width_mm, pressure_angle_deg=g.pressure_angle_deg,
        shaft_angle_deg=g.shaft_angle_deg, profile_shift=-g.small_profile_shift,
        thinning_mm=thinning, bore_mm=BIG_GEAR_BORE_MM,
        # big gear body ends l12 behind its outer pitch circle plane (d2/2 from the apex), where
        # the Ti shaft (l11) takes over up to the housing face
        mounting_distance_mm=small.outer_pitch_diameter_mm / 2.0 + d.l12_mm,
    )
    return GearSpecs(big=big, small=small)


@dataclass(frozen=True)
class AssemblyPoses:
    """Gear-frame → world transforms of the four gears (4×4), at drive angle 0."""

    big_right: np.ndarray
    big_left: np.ndarray
    small_front: np.ndarray
    small_back: np.ndarray

    def as_dict(self) -> dict[str, np.ndarray]:
        return {
            "big_gear_right": self.big_right,
            "big_gear_left": self.big_left,
            "small_gear_front": self.small_front,
            "small_gear_back": self.small_back,
        }


def _mate_at_azimuth(this: BevelGearSpec, mate: BevelGearSpec, azimuth: float) -> np.ndarray:
    """Rotation (mate frame → this frame) of a mate meshing at ``azimuth`` about this gear's axis.

    mate_rotation(this, angle) mounts the mate at azimuth 0 of the fixed frame with this gear
    turned by ``angle``: seen from this gear's body the mate then sits at azimuth −angle."""
    return mate_rotation(this, -azimuth, mate)


def _check_meshes_with(big_pose: np.ndarray, small_pose: np.ndarray, small: BevelGearSpec,
                       big: BevelGearSpec) -> None:
    """The big gear phased from one small gear must also mesh with the other: the pose the second
    small gear asks for may differ from ``big_pose`` only by whole tooth pitches about the axis."""
    other_in_small = small_pose.T @ big_pose[:, 2]
    azimuth = math.atan2(other_in_small[1], other_in_small[0])
    wanted = small_pose @ _mate_at_azimuth(small, big, azimuth)
    relative = big_pose.T @ wanted  # a rotation about z if the axes agree
    if not np.allclose(relative[:, 2], [0.0, 0.0, 1.0], atol=1e-9):
        raise ValueError("big gears are not coaxial")
    turn = math.atan2(relative[1, 0], relative[0, 0]) / (2 * math.pi / big.teeth)
    if abs(turn - round(turn)) > 1e-6:
        raise ValueError(f"assembly condition fails: the second small gear is {turn % 1:.3f} "
                         f"pitch out of phase (two small gears need an even 2·z_big / 2)")


def assembly_poses(specs: GearSpecs, shim_mm: float = 0.0) -> AssemblyPoses:
    big, small = specs.big, specs.small
    big_right = FRAME_PLUS_Y
    small_front = big_right @ _mate_at_azimuth(big, small, 0.0)
    small_back = big_right @ _mate_at_azimuth(big, small, math.pi)
    # the left big gear meshes with the front small gear opposite the right one
    right_in_small = small_front.T @ big_right[:, 2]  # right gear's axis in the small frame
    azimuth_right = math.atan2(right_in_small[1], right_in_small[0])
    big_left = small_front @ _mate_at_azimuth(small, big, azimuth_right + math.pi)
    _check_meshes_with(big_left, small_back, small, big)
    shift = shim_mm
    return AssemblyPoses(
        big_right=homogeneous(big_right, shift * big_right[:, 2]),
        big_left=homogeneous(big_left, shift * big_left[:, 2]),
        small_front=homogeneous(small_front),
        small_back=homogeneous(small_back),
    )


def axis_of(pose: np.ndarray) -> np.ndarray:
    """World direction of a gear's axis (apex → body)."""
    return pose[:3, 2].copy()


def apex_of(pose: np.ndarray) -> np.ndarray:
    """World position of a gear's cone apex."""
    return pose[:3, 3].copy()
