"""Bevel gears in mesh as rigid bodies (numpy only): the poses of a bevel differential at a drive
angle, when two big/small meshes are the same mesh, the period of the play over the drive, and
which triangles of a gear's mesh can touch its mate.

Frames as in :mod:`gearcheck.geometry.bevel`: each gear's apex at its frame origin, its axis +z
(apex → body), tooth 0 on +x; poses are 4×4 gear frame → world transforms.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bevel import BevelGearSpec
from gearcheck.geometry.bevel_contact import rigid_inverse
from gearcheck.geometry.bevel_play import conjugate_big_turn, rot_z4, translation4

# A triangle counts as root land (dropped by tooth_half_mask) when no vertex rises this far above
# the root cone.
ROOT_LAND_MARGIN_RAD = 1e-5


def drive_poses(built: Mapping[str, np.ndarray], bigs: Sequence[str], smalls: Sequence[str], big: BevelGearSpec,
                small: BevelGearSpec, drive_angle: float, big_shift_mm: float = 0.0) -> dict[str, np.ndarray]:
    """Gear frame → world at a drive angle, from the poses the gears were built at: each small
    gear turned by ``drive_angle`` about its own axis, each big gear by the conjugate turn
    −φ·z_small/z_big about its own (the pitch cones roll; carrier held), and each big gear moved
    ``big_shift_mm`` out along its own axis (another shim than the built one)."""
    out = {}
    big_turn = conjugate_big_turn(big, small, drive_angle)
    for name in bigs:
        pose = built[name]
        out[name] = translation4(big_shift_mm * pose[:3, 2]) @ pose @ rot_z4(big_turn)
    for name in smalls:
        out[name] = built[name] @ rot_z4(drive_angle)
    return out


def congruent(q1: np.ndarray, q2: np.ndarray, big: BevelGearSpec, small: BevelGearSpec, tol: float = 1e-9) -> bool:
    """Two big/small pairs, given as small-frame → big-frame transforms, are the same mesh when
    q2 = Rz(k·pitch_big)·q1·Rz(j·pitch_small) for whole k, j (identical teeth relabelled)."""
    a1 = math.atan2(q1[1, 2], q1[0, 2])
    a2 = math.atan2(q2[1, 2], q2[0, 2])
    k = (a2 - a1) / big.angular_pitch_rad
    if abs(k - round(k)) > tol:
        return False
    m = rigid_inverse(rot_z4(round(k) * big.angular_pitch_rad) @ q1) @ q2
    if not (abs(m[0, 2]) <= tol and abs(m[1, 2]) <= tol and abs(m[2, 2] - 1.0) <= tol
            and abs(m[0, 3]) <= tol and abs(m[1, 3]) <= tol and abs(m[2, 3]) <= tol):
        return False
    j = math.atan2(m[1, 0], m[0, 0]) / small.angular_pitch_rad
    return abs(j - round(j)) <= tol


def play_period(built: Mapping[str, np.ndarray], bigs: Sequence[str], smalls: Sequence[str], big: BevelGearSpec,
                small: BevelGearSpec) -> float:
    """Drive period of every output shaft's play (two small gears on each big gear): half a
    small-gear pitch when each big gear's two meshes run half a tooth apart (z_big odd: the mesh
    with one small gear at φ + p/2 is congruent to the mesh with the other at φ), else a whole
    pitch."""
    pitch = small.angular_pitch_rad
    s0, s1 = smalls
    for name in bigs:
        a = drive_poses(built, bigs, smalls, big, small, 0.0, 0.0)
        h = drive_poses(built, bigs, smalls, big, small, pitch / 2.0, 0.0)
        for first, second in ((s0, s1), (s1, s0)):
            q1 = np.linalg.inv(a[name]) @ a[first]
            q2 = np.linalg.inv(h[name]) @ h[second]
            if not congruent(q2, q1, big, small):
                return pitch
    return pitch / 2.0


def zone_azimuth(this_pose: np.ndarray, other_pose: np.ndarray) -> float:
    """Azimuth, in this gear's frame, of the other gear's axis: where the mesh zone is."""
    axis = this_pose[:3, :3].T @ other_pose[:3, 2]
    return math.atan2(axis[1], axis[0])


@dataclass(frozen=True)
class ToothFaces:
    """Where each face (own frame) of a bevel gear's mesh lies: its tooth (index from azimuth 0),
    its side of that tooth's centre (−1, 0, +1) and whether it lies above the root land."""

    tooth: np.ndarray
    side: np.ndarray
    above_root: np.ndarray

    @classmethod
    def of(cls, vertices: np.ndarray, faces: np.ndarray, spec: BevelGearSpec) -> ToothFaces:
        pitch = spec.angular_pitch_rad
        centroid = vertices[faces].mean(axis=1)
        azimuth = np.arctan2(centroid[:, 1], centroid[:, 0])
        tooth = np.round(azimuth / pitch)
        offset = azimuth - tooth * pitch
        polar = np.arctan2(np.hypot(vertices[:, 0], vertices[:, 1]), vertices[:, 2])
        above_root = (polar[faces] > spec.root_angle_rad + ROOT_LAND_MARGIN_RAD).any(axis=1)
        return cls(np.mod(tooth, spec.teeth), np.sign(offset), above_root)

    def half_mask(self, side: int, teeth: np.ndarray, spec: BevelGearSpec) -> np.ndarray:
        return self.above_root & np.isin(self.tooth, np.mod(teeth, spec.teeth)) & (self.side == side)


def tooth_half_mask(vertices: np.ndarray, faces: np.ndarray, spec: BevelGearSpec, side: int,
                    teeth: np.ndarray) -> np.ndarray:
    """Faces (own frame) on the ``side`` half of the given teeth, above the root land: the side
    of a triangle is the sign of its centroid's azimuth from the nearest tooth centre. A tooth
    half carries its flank, its tip and its heel/toe edges, so every first contact of that
    flank side (face or edge) lies in it. For several masks of one mesh, locate its faces once
    with :class:`ToothFaces`."""
    return ToothFaces.of(vertices, faces, spec).half_mask(side, teeth, spec)
