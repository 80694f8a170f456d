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

from gearcheck.geometry import bevel_contact as bc
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


@dataclass(frozen=True)
class Mounting:
    """A pair as mounted: each gear's rigid displacement (world 4×4, applied after its nominal
    pose: the big gear's at turn 0, the small gear's of :func:`gearcheck.geometry.bevel_play.nominal_small_pose`)
    and its scale about its apex."""

    big_displacement: np.ndarray
    small_displacement: np.ndarray
    big_scale: float = 1.0
    small_scale: float = 1.0

    @classmethod
    def of(cls, misalignment: Misalignment | None = None, big_scale: float = 1.0, small_scale: float = 1.0,
           big_displacement: np.ndarray | None = None, small_displacement: np.ndarray | None = None) -> Mounting:
        """Misaligned by ``misalignment``, then displaced by the given rigid displacements."""
        db, ds = (misalignment or Misalignment()).displacements()
        if big_displacement is not None:
            db = np.asarray(big_displacement, float) @ db
        if small_displacement is not None:
            ds = np.asarray(small_displacement, float) @ ds
        return cls(db, ds, big_scale, small_scale)

    def placed(self, big: BevelGearSpec, small: BevelGearSpec, drive_angle_rad: float,
               big_turn_rad: float = 0.0) -> tuple[bp.PlacedGear, bp.PlacedGear]:
        """(big, small) with the small gear turned by its drive angle and the big gear by the
        conjugate turn plus ``big_turn_rad``."""
        turn = bp.conjugate_big_turn(big, small, drive_angle_rad) + big_turn_rad
        return (bp.PlacedGear(big, self.big_displacement @ bp.rot_z4(turn), self.big_scale),
                bp.PlacedGear(small, self.small_displacement @ bp.nominal_small_pose(big, small)
                              @ bp.rot_z4(drive_angle_rad), self.small_scale))


def transmission_error(big: BevelGearSpec, small: BevelGearSpec, misalignment: Misalignment | None = None,
                       cycles: float = 2.0, per_cycle: int = 24, big_scale: float = 1.0, small_scale: float = 1.0,
                       big_displacement: np.ndarray | None = None,
                       small_displacement: np.ndarray | None = None) -> TransmissionError:
    """TE and contact path over ``cycles`` mesh cycles (a small-gear tooth pitch each) at
    ``per_cycle`` drive angles a cycle, the pair misaligned by ``misalignment`` (or displaced by
    the given rigid displacements, after it) and each gear scaled about its apex."""
    mounting = Mounting.of(misalignment, big_scale, small_scale, big_displacement, small_displacement)
    return mounted_transmission_error(big, small, mounting, cycles, per_cycle)


def mounted_transmission_error(big: BevelGearSpec, small: BevelGearSpec, mounting: Mounting, cycles: float = 2.0,
                               per_cycle: int = 24) -> TransmissionError:
    """:func:`transmission_error` of a pair as ``mounting`` places it."""
    angles = np.arange(int(round(cycles * per_cycle)) + 1) * small.angular_pitch_rad / per_cycle
    bigs, smalls = zip(*(mounting.placed(big, small, phi) for phi in angles), strict=True)
    plus, minus = bp.big_gear_contacts_both(bigs, smalls)
    spots = [np.array([on_big_tooth(b, c.angle_rad, c.point) for b, c in zip(bigs, way, strict=True)])
             for way in (plus, minus)]
    return TransmissionError(angles, -np.array([c.angle_rad for c in plus]), -np.array([c.angle_rad for c in minus]),
                             spots[0][:, 0], spots[0][:, 1], spots[1][:, 0], spots[1][:, 1])


def on_big_tooth(gear: bp.PlacedGear, turn_rad: float, point) -> tuple[float, float]:
    """(along 0 toe … 1 heel, height 0 root … 1 tip) of a world point on a gear turned by
    ``turn_rad`` from its placed pose, in its own unscaled design."""
    _, along, height = tooth_coordinates(gear, turn_rad, point)
    return along, height


def tooth_coordinates(gear: bp.PlacedGear, turn_rad: float, point) -> tuple[float, float, float]:
    """(cone distance mm, along 0 toe … 1 heel, height 0 root … 1 tip by polar angle) of a world
    point on a gear turned by ``turn_rad`` from its placed pose, in its own unscaled design."""
    local = np.linalg.solve(gear.turned(turn_rad).pose, np.append(np.asarray(point, float), 1.0))[:3] / gear.scale
    s = gear.spec
    theta = math.atan2(math.hypot(local[0], local[1]), local[2])
    cone = float(np.linalg.norm(local)) * math.cos(theta - s.pitch_angle_rad)
    return (cone, (cone - s.inner_cone_distance_mm) / (s.outer_cone_distance_mm - s.inner_cone_distance_mm),
            (theta - s.root_angle_rad) / (s.face_angle_rad - s.root_angle_rad))


# -- the contact pattern -------------------------------------------------------------------
# Marking compound (mm): where the gap to the mating flank is under it, the flank takes the mark.
COMPOUND_MM = 0.006
# The developed flank's grid (profile root → tip, ruling toe → heel) and the drive angles a mesh
# cycle the gap is taken at (the contact band moves a fraction of its width between them).
PATTERN_PROFILE, PATTERN_RULING, PATTERN_STEPS = 81, 57, 48


@dataclass(frozen=True)
class ContactPattern:
    """The unloaded contact pattern of one flank of the big gear's tooth: the least gap (mm) to
    the mating flank over a whole pass of the tooth through the mesh, on a grid of its flank
    parameters (``gap_mm[i, j]`` at height ``height[i]``, 0 root cone … 1 tip cone by polar
    angle, and ``along[j]``, 0 toe … 1 heel); inf where the mating flank never lies over it. The
    pattern is where the gap is under ``compound_mm``. ``developed`` maps the grid onto the flank
    developed flat (mm along the face from the toe, mm up the profile from the root cone)."""

    flank: str
    height: np.ndarray
    along: np.ndarray
    gap_mm: np.ndarray
    compound_mm: float
    inner_mm: float  # cone distances of toe and heel (the big gear, unscaled)
    outer_mm: float
    root_rad: float  # polar angles of root and tip cone
    face_rad: float
    form: float  # the involute's start (height fraction): below it the flank is not involute

    @property
    def marked(self) -> np.ndarray:
        return self.gap_mm <= self.compound_mm

    @property
    def length(self) -> float:
        """The pattern's span along the face (share of the face width; 0: no pattern)."""
        cols = np.flatnonzero(self.marked.any(axis=0))
        return float(self.along[cols[-1]] - self.along[cols[0]]) if cols.size else 0.0

    def developed(self, along=None, height=None) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) mm on the flank developed flat: x along the face from the toe, y up the profile
        (the arc from the root cone at that cone distance), of the points (``along`` 0 toe … 1
        heel, ``height`` 0 root … 1 tip; broadcast), by default of each grid point."""
        if along is None or height is None:
            along, height = self.along[None, :], self.height[:, None]
        cone = self.inner_mm + np.asarray(along, float) * (self.outer_mm - self.inner_mm)
        return np.broadcast_arrays(cone - self.inner_mm, np.asarray(height, float) * (self.face_rad - self.root_rad)
                                   * cone)  # type: ignore[return-value]

    def extent(self) -> dict[str, float]:
        """Where the pattern lies: its span along the face and in height (fractions), its centre
        (area-weighted on the developed flank), its share of the flank's area and whether it
        reaches the toe, the heel, the tip or the root edge, or runs below the form line (off the
        involute) (nan and False: no pattern)."""
        m = self.marked
        if not m.any():
            nan = float("nan")
            return {"along_min": nan, "along_max": nan, "height_min": nan, "height_max": nan, "centre_along": nan,
                    "centre_height": nan, "area_share": 0.0, "toe": False, "heel": False, "tip": False,
                    "root": False, "below_form": False}
        rows, cols = np.nonzero(m)
        weight = np.broadcast_to((self.inner_mm + self.along * (self.outer_mm - self.inner_mm))[None, :], m.shape)
        w = weight * m
        return {"along_min": float(self.along[cols.min()]), "along_max": float(self.along[cols.max()]),
                "height_min": float(self.height[rows.min()]), "height_max": float(self.height[rows.max()]),
                "centre_along": float((w * self.along[None, :]).sum() / w.sum()),
                "centre_height": float((w * self.height[:, None]).sum() / w.sum()),
                "area_share": float(w.sum() / weight.sum()),
                "toe": bool(m[:, 0].any()), "heel": bool(m[:, -1].any()), "tip": bool(m[-1].any()),
                "root": bool(m[0].any()), "below_form": bool(m[self.height < self.form - 1e-12].any())}


def contact_pattern(big: BevelGearSpec, small: BevelGearSpec, mounting: Mounting, te: TransmissionError,
                    flank: str = "drive", compound_mm: float = COMPOUND_MM, steps: int = PATTERN_STEPS,
                    profile: int = PATTERN_PROFILE, ruling: int = PATTERN_RULING) -> ContactPattern:
    """The contact pattern of the big gear's ``flank`` (drive: side +1, closed by the big gear's
    + turn; coast: side −1) with the pair mounted as ``mounting`` and turned to contact by
    ``te`` (its TE over at least one mesh cycle, interpolated between its drive angles): at
    ``steps`` drive angles over one cycle, the gap from each grid point of the big gear's flank
    (every tooth near the mesh) to the small gear's flank of the same side, bounded by its tooth
    zone (beyond the flank's edge, the distance to the edge: an edge of the small gear bearing on
    the big gear's face marks it too; :func:`gearcheck.geometry.bevel_contact.zone_excess`); the
    least over the angles and teeth (one cycle of every tooth is one whole pass of a tooth: the
    teeth are identical)."""
    side = 1.0 if flank == "drive" else -1.0
    curve = te.drive_rad if flank == "drive" else te.coast_rad
    pitch = small.angular_pitch_rad
    if te.drive_angles_rad[-1] - te.drive_angles_rad[0] < pitch * (1.0 - 1e-9):
        raise ValueError("the TE must cover a whole mesh cycle")
    f = bc.flank_constants(big)
    t = np.linspace(0.0, 1.0, profile)
    u = np.linspace(0.0, 1.0, ruling)
    window = bp.teeth_window(big, small) + 1
    teeth = np.arange(-window, window + 1)
    gap = np.full((profile, ruling), np.inf)
    for phi in te.drive_angles_rad[0] + np.arange(steps) * pitch / steps:
        turn = -float(np.interp(phi, te.drive_angles_rad, curve))  # the big gear's contact turn
        b, s = mounting.placed(big, small, phi, turn)
        rel = bc.rigid_inverse(s.pose) @ b.pose  # big frame → small frame
        centre = round(math.atan2(rel[2, 1], rel[2, 0]) / f.pitch)  # the big tooth facing the small gear
        x, y, z = bc.flank_xyz(big, b.scale, (centre + teeth)[:, None, None], side, t[None, :, None],
                               u[None, None, :])
        px = rel[0, 0] * x + rel[0, 1] * y + rel[0, 2] * z + rel[0, 3]
        py = rel[1, 0] * x + rel[1, 1] * y + rel[1, 2] * z + rel[1, 3]
        pz = rel[2, 0] * x + rel[2, 1] * y + rel[2, 2] * z + rel[2, 3]
        facing = bc.facing_tooth(small, px, py, side)
        d = bc.signed_to_flank(small, px, py, pz, facing, side)
        e = bc.zone_excess(small, s.scale, px, py, pz)  # beyond the small gear's flank: to its edge
        gap = np.minimum(gap, np.sqrt(d * d + e * e).min(axis=0))
    return ContactPattern(flank, t, u, gap, compound_mm, big.inner_cone_distance_mm, big.outer_cone_distance_mm,
                          big.root_angle_rad, big.face_angle_rad,
                          (big.form_angle_rad - big.root_angle_rad) / (big.face_angle_rad - big.root_angle_rad))


def pattern_patch(spec: BevelGearSpec, pattern: ContactPattern, teeth=None, every: int = 4,
                  lift_mm: float = 0.004) -> tuple[np.ndarray, np.ndarray]:
    """The pattern as a triangle mesh on the flanks of ``teeth`` (default every tooth) in the
    gear's own frame, for painting on the gear in a 3D view: the grid cells (every ``every``-th
    grid line) whose corners are all marked, lifted ``lift_mm`` off the flank (outward, across the
    tooth) so that it shows over the gear's own mesh. Returns (vertices (n, 3) float32, faces
    (m, 3) uint32)."""
    side = 1.0 if pattern.flank == "drive" else -1.0
    t, u = pattern.height[::every], pattern.along[::every]
    marked = pattern.marked[::every, ::every]
    cells = marked[:-1, :-1] & marked[1:, :-1] & marked[:-1, 1:] & marked[1:, 1:]
    i, j = np.nonzero(cells)
    if i.size == 0:
        return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32)
    used = np.zeros(marked.shape, bool)
    for di in (0, 1):
        for dj in (0, 1):
            used[i + di, j + dj] = True
    number = np.cumsum(used.ravel()).reshape(used.shape) - 1
    rows, cols = np.nonzero(used)
    a, b, c, d = number[i, j], number[i + 1, j], number[i + 1, j + 1], number[i, j + 1]
    quads = np.concatenate([np.stack([a, b, c], axis=1), np.stack([a, c, d], axis=1)])
    teeth = np.arange(spec.teeth) if teeth is None else np.asarray(teeth)
    verts, faces = [], []
    for k, tooth in enumerate(teeth):
        x, y, z = bc.flank_xyz(spec, 1.0, tooth, side, t[rows], u[cols])
        az = np.arctan2(y, x)
        verts.append(np.stack([x - side * lift_mm * np.sin(az), y + side * lift_mm * np.cos(az), z], axis=1))
        faces.append(quads + k * len(rows))
    return np.concatenate(verts).astype(np.float32), np.concatenate(faces).astype(np.uint32)
