"""Tooth contact analysis of a straight bevel pair on its exact flanks (numpy only): transmission
error of the drive and the coast flank over the mesh cycle, and where the contact lies, with the
pair mounted as designed or misaligned.

**Frame** (as :func:`gearcheck.geometry.bevel_play.nominal_small_pose`): the world is the big
gear's frame at turn 0, its axis +z, the common apex at the origin; the small gear's axis is +x
(a 90° shaft angle), the common perpendicular of the two axes +y. Both gears' teeth lie on the
positive side of their axes.

**Misalignments** (:class:`Misalignment`, the usual E/P/G/Σ of bevel gear mounting): E moves the
small gear along +y (an offset between the axes), P moves it along its own axis away from the apex,
G moves the big gear along its own axis away from the apex, Σ turns the small gear's axis about +y
through the apex (the shaft angle grows by Σ). P and G > 0 open the mesh.

**Transmission error.** The small gear drives: it turns by φ (its drive angle), and a conjugate
big gear would turn by −φ·z_small/z_big. At each φ the big gear's first contact is solved both
ways on the exact flanks (:func:`gearcheck.geometry.bevel_play.big_gear_contacts_both`). The TE is
that contact angle less the conjugate one, measured in the big gear's direction of motion (so a
lagging driven gear has a negative TE): on the **drive** flank (the small gear pushing, the big
gear's + turn closes it) TE_drive = −plus, on the **coast** flank TE_coast = −minus. Their
difference is the play, TE_coast − TE_drive = plus − minus: the same solve as the play figures, one
model.

**Contact path**: where the first contact lies on the big gear's tooth (the driven gear, as
turned to the contact): 0 toe … 1 heel along the face (by cone distance), 0 root … 1 tip in height
(by polar angle between the root and the face cone).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel import BevelGearSpec

ARCSEC_PER_RAD = 648000.0 / math.pi


@dataclass(frozen=True)
class Misalignment:
    """E, P, G (mm) and Σ (rad) of the module doc."""

    offset_mm: float = 0.0  # E
    small_axial_mm: float = 0.0  # P
    big_axial_mm: float = 0.0  # G
    shaft_angle_rad: float = 0.0  # Σ

    def displacements(self) -> tuple[np.ndarray, np.ndarray]:
        """(big, small) rigid displacements (world 4×4, applied after each gear's nominal pose)."""
        big = bp.translation4([0.0, 0.0, self.big_axial_mm])
        c, s = math.cos(self.shaft_angle_rad), math.sin(self.shaft_angle_rad)
        turn = np.eye(4)
        turn[:3, :3] = [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]  # about +y: +x turns towards −z
        axis = turn[:3, 0]  # the small gear's axis after the turn
        small = bp.translation4(self.offset_mm * np.array([0.0, 1.0, 0.0]) + self.small_axial_mm * axis) @ turn
        return big, small


def equivalent_misalignment(big_displacement: np.ndarray, small_displacement: np.ndarray) -> dict[str, float]:
    """E, P, G, Σ of a pair of rigid displacements (world 4×4), read from the small gear's motion
    relative to the big gear: the turn about +y is Σ, the shift along +y is E, along the small
    axis P, and the big gear's shift along its axis G (the relative shift along +z, opposite).
    What E/P/G/Σ cannot hold (turns about x and z, a shift along z beyond G) is returned as
    ``tilt_rad`` and ``residual_mm``."""
    rel = np.linalg.inv(big_displacement) @ small_displacement
    r, t = rel[:3, :3], rel[:3, 3]
    sigma = math.atan2(r[0, 2], r[0, 0])
    tilt = float(np.linalg.norm([r[2, 1] - r[1, 2], r[1, 0] - r[0, 1]]) / 2.0)
    axis = np.array([math.cos(sigma), 0.0, -math.sin(sigma)])
    e = float(t[1])
    # t = E·y + P·axis − G·z: solve P, G from the x, z components
    a = np.array([[axis[0], 0.0], [axis[2], -1.0]])
    p, g = np.linalg.solve(a, [t[0], t[2]])
    return {"offset_mm": e, "small_axial_mm": float(p), "big_axial_mm": float(g), "shaft_angle_rad": sigma,
            "tilt_rad": tilt, "residual_mm": 0.0}


@dataclass(frozen=True)
class TransmissionError:
    """TE (rad, the big gear's angle in its direction of motion less the conjugate one) of the drive
    and the coast flank at the small gear's drive angles, and the contact path on each flank."""

    drive_angles_rad: np.ndarray
    drive_rad: np.ndarray
    coast_rad: np.ndarray
    drive_along: np.ndarray  # 0 toe … 1 heel
    drive_height: np.ndarray  # 0 root … 1 tip
    coast_along: np.ndarray
    coast_height: np.ndarray

    @property
    def play_rad(self) -> np.ndarray:
        """TE_coast − TE_drive: the play at each drive angle (the big gear's free turn)."""
        return self.coast_rad - self.drive_rad

    def peak_to_peak(self, flank: str) -> float:
        return float(np.ptp(self.drive_rad if flank == "drive" else self.coast_rad))

    def mean(self, flank: str) -> float:
        return float(np.mean(self.drive_rad if flank == "drive" else self.coast_rad))


def transmission_error(big: BevelGearSpec, small: BevelGearSpec, misalignment: Misalignment | None = None,
                       cycles: float = 2.0, per_cycle: int = 24, big_scale: float = 1.0, small_scale: float = 1.0,
                       big_displacement: np.ndarray | None = None,
                       small_displacement: np.ndarray | None = None) -> TransmissionError:
    """TE and contact path over ``cycles`` mesh cycles (a small-gear tooth pitch each) at
    ``per_cycle`` drive angles a cycle, the pair misaligned by ``misalignment`` (or displaced by
    the given rigid displacements, after it) and each gear scaled about its apex."""
    db, ds = (misalignment or Misalignment()).displacements()
    if big_displacement is not None:
        db = np.asarray(big_displacement, float) @ db
    if small_displacement is not None:
        ds = np.asarray(small_displacement, float) @ ds
    angles = np.arange(int(round(cycles * per_cycle)) + 1) * small.angular_pitch_rad / per_cycle
    nominal = bp.nominal_small_pose(big, small)
    bigs = [bp.PlacedGear(big, db @ bp.rot_z4(bp.conjugate_big_turn(big, small, phi)), big_scale) for phi in angles]
    smalls = [bp.PlacedGear(small, ds @ nominal @ bp.rot_z4(phi), small_scale) for phi in angles]
    plus, minus = bp.big_gear_contacts_both(bigs, smalls)
    spots = [np.array([on_big_tooth(b, c.angle_rad, c.point) for b, c in zip(bigs, way, strict=True)])
             for way in (plus, minus)]
    return TransmissionError(angles, -np.array([c.angle_rad for c in plus]), -np.array([c.angle_rad for c in minus]),
                             spots[0][:, 0], spots[0][:, 1], spots[1][:, 0], spots[1][:, 1])


def on_big_tooth(gear: bp.PlacedGear, turn_rad: float, point) -> tuple[float, float]:
    """(along 0 toe … 1 heel, height 0 root … 1 tip) of a world point on a gear turned by
    ``turn_rad`` from its placed pose, in its own unscaled design."""
    local = np.linalg.solve(gear.turned(turn_rad).pose, np.append(np.asarray(point, float), 1.0))[:3] / gear.scale
    s = gear.spec
    theta = math.atan2(math.hypot(local[0], local[1]), local[2])
    cone = float(np.linalg.norm(local)) * math.cos(theta - s.pitch_angle_rad)
    return ((cone - s.inner_cone_distance_mm) / (s.outer_cone_distance_mm - s.inner_cone_distance_mm),
            (theta - s.root_angle_rad) / (s.face_angle_rad - s.root_angle_rad))
