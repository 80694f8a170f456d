"""Angular play of a straight bevel pair with exact spherical-involute flanks (numpy only).

The independent check of the mesh sweep: no meshes, no CAD. Each gear is the analytic tooth of
:mod:`gearcheck.geometry.bevel` (flanks are cones through the gear's own apex over the spherical
involute, bounded by the root and tip cones and by the front and back cones), placed by a rigid
4×4 pose and scaled by a factor about its apex. Scaling about the apex leaves every flank cone
where it is and only moves the toe and heel (r·cos(θ − δ) = f·Ri … f·Re), so a thermal state
"scale f about a datum on the axis" is "scale f about the apex" plus a shift of the apex along
the axis (:func:`scale_about_apex`).

Play of the big gear against one small gear (the small gear held at its drive angle): turn the
big gear about its own axis until a flank touches, both ways. For the + direction (right-handed
about the big gear's +z) the big gear's side +1 flanks close on the small gear's side +1 flanks
(the small gear would be driven the other way about its own axis, ω_small/ω_big = −z_big/z_small,
so its tooth is pushed on its +azimuth side); the − direction uses the −1 flanks.

First contact, exactly: the extreme turn at which a point of either gear's flank reaches the
other gear's flank cone inside its tooth zone, solved on the closed-form distance to the cone
(:mod:`gearcheck.geometry.bevel_contact`, vectorised over many pairs).

Angles: radians inside; :func:`arcmin` converts. Play is measured on the big gear's axis.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import bevel_contact as bc
from gearcheck.geometry.bevel import BevelGearSpec, mate_rotation

ARCMIN_PER_RAD = 10800.0 / math.pi

# The contact solve and its sampling constants: :mod:`gearcheck.geometry.bevel_contact`.
teeth_window = bc.teeth_window


def arcmin(angle_rad):
    return np.asarray(angle_rad) * ARCMIN_PER_RAD


def rot_z4(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def translation4(vector) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = vector
    return m


def scale_about_apex(pose: np.ndarray, factor: float, datum_local) -> np.ndarray:
    """Pose of a gear scaled by ``factor`` about a datum of its own frame, rewritten as a scale
    about its apex (frame origin) followed by this pose: p → datum + f·(p − datum) = f·p +
    (1 − f)·datum."""
    return np.asarray(pose, float) @ translation4((1.0 - factor) * np.asarray(datum_local, float))


@dataclass(frozen=True)
class PlacedGear:
    """An analytic gear: its design, its pose (frame → world, at its current turn) and its
    scale about its apex (1 when warm)."""

    spec: BevelGearSpec
    pose: np.ndarray
    scale: float = 1.0

    def turned(self, angle: float) -> PlacedGear:
        return PlacedGear(self.spec, self.pose @ rot_z4(angle), self.scale)


@dataclass(frozen=True)
class Contact:
    """First contact of the big gear turning one way: its turn (rad, about its own axis, from
    its given pose), the contact point (world) and where it lies."""

    angle_rad: float
    point: np.ndarray
    on: str  # "big" or "small": whose flank the contact point was sampled on
    tooth: int  # that gear's tooth index
    profile: float  # 0 root … 1 tip
    ruling: float  # 0 toe … 1 heel


@dataclass(frozen=True)
class Play:
    """Contact turns of the big gear both ways (plus ≥ minus when there is play)."""

    plus: Contact
    minus: Contact

    @property
    def total_rad(self) -> float:
        return self.plus.angle_rad - self.minus.angle_rad

    @property
    def total_arcmin(self) -> float:
        return float(arcmin(self.total_rad))


def big_gear_contacts(bigs: Sequence[PlacedGear], smalls: Sequence[PlacedGear], direction: int) -> list[Contact]:
    """:func:`big_gear_contact` for many pairs at once (the same two designs; each pair its own
    poses and scales), vectorised over the pairs (:func:`gearcheck.geometry.bevel_contact.first_contacts`)."""
    if direction not in (-1, 1):
        raise ValueError("direction must be +1 or -1")
    return _contacts(bigs, smalls, np.full(len(bigs), direction))


def big_gear_contacts_both(bigs: Sequence[PlacedGear], smalls: Sequence[PlacedGear]
                           ) -> tuple[list[Contact], list[Contact]]:
    """:func:`big_gear_contacts` both ways (+, −) in one vectorised solve: the same figures, half
    the calls (the two ways' pairs share every array)."""
    n = len(bigs)
    both = _contacts(list(bigs) * 2, list(smalls) * 2, np.repeat([1, -1], n))
    return both[:n], both[n:]


def _contacts(bigs: Sequence[PlacedGear], smalls: Sequence[PlacedGear], directions: np.ndarray) -> list[Contact]:
    if len(bigs) != len(smalls):
        raise ValueError("one small gear per big gear")
    if not bigs:
        return []
    big_spec, small_spec = bigs[0].spec, smalls[0].spec
    if any(b.spec != big_spec for b in bigs) or any(s.spec != small_spec for s in smalls):
        raise ValueError("a batch holds pairs of the same two gear designs")
    got = bc.first_contacts(big_spec, small_spec, np.stack([b.pose for b in bigs]), np.stack([s.pose for s in smalls]),
                            np.array([b.scale for b in bigs], float), np.array([s.scale for s in smalls], float),
                            np.asarray(directions))
    return [Contact(float(got.angle_rad[k]), got.point[k], "big" if got.on[k] == 0 else "small", int(got.tooth[k]),
                    float(got.profile[k]), float(got.ruling[k])) for k in range(len(bigs))]


def big_gear_contact(big: PlacedGear, small: PlacedGear, direction: int) -> Contact:
    """Turn of the big gear about its own axis (from its given pose) at which it first touches
    the small gear, turning + (direction = +1) or − (−1)."""
    return big_gear_contacts([big], [small], direction)[0]


def big_gear_play(big: PlacedGear, small: PlacedGear) -> Play:
    """Contact turns of the big gear both ways against one small gear held still."""
    return Play(big_gear_contact(big, small, +1), big_gear_contact(big, small, -1))


# -- a single pair on its nominal mounting -------------------------------------------------
def nominal_small_pose(big: BevelGearSpec, small: BevelGearSpec) -> np.ndarray:
    """Small gear frame → world for the pair on a common apex, world = the big gear's frame at
    turn 0 (the small gear's tooth 0 in a big tooth space: mate_rotation's phasing)."""
    m = np.eye(4)
    m[:3, :3] = mate_rotation(big, 0.0, small)
    return m


def pitch_element_normal(big: BevelGearSpec) -> np.ndarray:
    """Unit normal to the pitch element (at the big gear's azimuth 0) in the plane of the two
    axes, pointing from the big gear toward the small gear (world = big frame at turn 0)."""
    d = big.pitch_angle_rad
    return np.array([math.cos(d), 0.0, -math.sin(d)])


def conjugate_big_turn(big: BevelGearSpec, small: BevelGearSpec, drive_angle: float) -> float:
    """Big-gear turn that keeps the pitch cones rolling when the small gear turns by drive_angle."""
    return -drive_angle * small.teeth / big.teeth


@dataclass(frozen=True)
class PlayCycle:
    drive_angles_rad: np.ndarray  # small gear turns
    plus_rad: np.ndarray  # big-gear contact turns from the conjugate position, + way
    minus_rad: np.ndarray  # − way (negative when there is play on that side)

    @property
    def total_arcmin(self) -> np.ndarray:
        return arcmin(self.plus_rad - self.minus_rad)

    @property
    def min_total_arcmin(self) -> float:
        return float(self.total_arcmin.min())


def pair_play_over_cycle(big: BevelGearSpec, small: BevelGearSpec, drive_angles_rad,
                         big_displacement: np.ndarray | None = None,
                         small_displacement: np.ndarray | None = None,
                         big_scale: float = 1.0, small_scale: float = 1.0) -> PlayCycle:
    """Play of the big gear against one small gear over drive angles of the small gear, each
    gear rigidly displaced (world 4×4, applied after its nominal pose) and scaled about its apex.
    One small-gear tooth pitch covers the whole cycle (identical teeth)."""
    db = np.eye(4) if big_displacement is None else np.asarray(big_displacement, float)
    ds = np.eye(4) if small_displacement is None else np.asarray(small_displacement, float)
    small_nominal = nominal_small_pose(big, small)
    plus, minus = [], []
    angles = np.asarray(drive_angles_rad, float)
    for phi in angles:
        s = PlacedGear(small, ds @ small_nominal @ rot_z4(phi), small_scale)
        b = PlacedGear(big, db @ rot_z4(conjugate_big_turn(big, small, phi)), big_scale)
        play = big_gear_play(b, s)
        plus.append(play.plus.angle_rad)
        minus.append(play.minus.angle_rad)
    return PlayCycle(angles, np.array(plus), np.array(minus))
