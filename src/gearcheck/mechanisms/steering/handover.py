"""Every tooth pair's conjugate contact measured on the swept meshes, and the continuous drive it
gives through each hand-over, in towing and power mode, both directions (numpy only).

At each pose of the sweep (pinion angle and rack travel as the meshes pushed them) the tangency
point of each pinion flank with its rack flank is found on the pinion mesh's outline (the involute
through the flank's mesh vertices) and placed against the four ends of the two flanks — the rack
tooth's top and root corners (vertices of the rack mesh) and the pinion tooth's tip corner and
form-circle end (vertices of the pinion mesh):
:mod:`gearcheck.geometry.rack_pinion_mesh`. A pair is in conjugate contact while it lies on both;
its interval ends where a margin changes sign between two poses. The chain of intervals
(:func:`gearcheck.geometry.rack_pinion_contact.continuous_drive`) gives the mesh's own continuous
drive and the event that ends it, beside the exact model's. Why positions and not the rack's lag
behind r·φ: the module docstring of :mod:`gearcheck.geometry.rack_pinion_mesh`.

The − direction is the mirror image of the + one (the template model enforces mirror-symmetric
parts), swept on the same meshes: its pairs are named and compared by their mirror images
(pinion tooth j ↔ −1 − j, rack tooth k ↔ −k).

Where the exact model predicts a tight hand-over (the next pair's contact beginning within
:data:`TIGHT_DEG` of the last one's end, or after it) the sweep gets extra poses around both
events and inside any gap (:func:`extra_angles_deg`), so that it samples the gap itself.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import (
    PairContact,
    continuous_drive,
    end_name,
    pair_contact,
    pinion_name,
)
from gearcheck.geometry.rack_pinion_mesh import (
    MARGINS,
    FlankInvolute,
    contact_run,
    fit_involute,
    flank_chain,
    mesh_vertex,
    pair_margins,
)

MODES = ("towing", "power")
# A hand-over is tight when the next pair's contact begins less than this before the last pair's
# ends (or after it): the sweep then samples around both events and inside the gap.
TIGHT_DEG = 1.0
# Extra poses at each event of a tight hand-over, offset by these (deg), and one inside a gap.
EVENT_OFFSETS_DEG = (-0.05, -0.01, 0.0, 0.01, 0.05)
# A pair's margins are evaluated where its pinion tooth's centre line lies within this many
# angular pitches of straight down (the contact zone spans about one contact ratio of pitches).
ZONE_PITCHES = 3.0


@dataclass(frozen=True)
class FlankPair:
    """One tooth pair on the meshes, in one mode and direction: the pinion flank read from the mesh
    outline (the involute through its vertices, own frame), the rack flank's root and top corners
    (world at travel 0, vertices of the rack mesh), the pair's indices in this direction and those
    of its + direction image (the names and the model)."""

    j: int
    k: int
    j_plus: int
    k_plus: int
    flank: FlankInvolute
    rack_root: np.ndarray
    rack_top: np.ndarray


def flank_side(mode: str, direction: int) -> int:
    """+1: the pinion's right flanks meet the rack's left flanks (towing +, power −); −1: the
    pinion's left flanks meet the rack's right flanks (power +, towing −)."""
    return +1 if (mode == "towing") == (direction > 0) else -1


def flank_pairs(g: RackPinionGeometry, profile: np.ndarray, rack_points: np.ndarray, rack_pose: np.ndarray,
                mode: str, direction: int) -> list[FlankPair]:
    """The pairs that mesh in ``mode`` and ``direction`` on the meshes: ``profile`` the pinion
    outline (own frame, ordered by polar angle), ``rack_points`` the rack outline's vertices (own
    frame, xy), ``rack_pose`` the rack's pose at travel 0."""
    side = flank_side(mode, direction)
    out = []
    for j in range(g.sector_first_tooth, g.sector_last_tooth + 1):
        k = j + 1 if side > 0 else j
        if not g.rack_first_tooth <= k <= g.rack_last_tooth:
            continue
        corner = g.pinion_tip_corner(j, 0.0, side) - np.array([0.0, g.centre_height])
        flank = fit_involute(flank_chain(profile, corner, side, g.form_radius), side)
        bl, br, tr, tl = g.rack_tooth_polygon(k, 0.0)
        root, top = (bl, tl) if side > 0 else (br, tr)
        root = rack_points[mesh_vertex(rack_points, root, f"root corner of rack tooth {k}")]
        top = rack_points[mesh_vertex(rack_points, top, f"top corner of rack tooth {k}")]
        world = [(rack_pose[:2, :2] @ p + rack_pose[:2, 3]) for p in (root, top)]
        j_plus, k_plus = (j, k) if direction > 0 else (-1 - j, -k)
        out.append(FlankPair(j, k, j_plus, k_plus, flank, world[0], world[1]))
    return out


def measured_pairs(g: RackPinionGeometry, mode: str, pairs: list[FlankPair], angles: np.ndarray,
                   travels: np.ndarray, pinion_poses: np.ndarray, rack_axis: np.ndarray
                   ) -> tuple[tuple[PairContact, ...], np.ndarray]:
    """Each pair's conjugate contact interval along a swing of the meshes (angles and travels as
    swept, signed; ``pinion_poses`` (P, 4, 4) the pinion's world poses there), as the + direction's
    :class:`PairContact` (angle magnitudes), ends named by the flank end whose margin changed sign;
    and, per pose, whether any pair is in conjugate contact there."""
    angles = np.asarray(angles, float)
    mag = np.abs(angles)
    rot, shift = pinion_poses[:, :2, :2], pinion_poses[:, :2, 3]
    tau = g.angular_pitch
    out = []
    covered = np.zeros(len(angles), bool)
    for p in pairs:
        zone = np.abs((p.j + 0.5) * tau + angles) <= ZONE_PITCHES * tau
        margins = np.full((len(angles), len(MARGINS)), np.nan)
        if zone.any():
            margins[zone] = pair_margins(p.flank, rot[zone], shift[zone], p.rack_top, p.rack_root,
                                         np.asarray(travels, float)[zone], rack_axis)
        covered |= np.all(margins >= 0.0, axis=1)
        run = contact_run(mag, margins)
        if run is None:
            continue
        start, end, by_start, by_end = run
        out.append(PairContact(mode, p.j_plus, p.k_plus, start, end, _end_name(g, mode, p, by_start, start, "start"),
                               _end_name(g, mode, p, by_end, end, "end")))
    return tuple(out), covered


def _end_name(g: RackPinionGeometry, mode: str, p: FlankPair, which: int, angle: float, end: str) -> str:
    if which >= 0:
        return end_name(g, mode, p.j_plus, p.k_plus, MARGINS[which])
    if end == "start":
        return "at angle 0" if angle == 0.0 else f"before the first pose evaluated ({math.degrees(angle):.3f}°)"
    return f"beyond the end of the sweep ({math.degrees(angle):.3f}°)"


@dataclass(frozen=True)
class MeshDrive:
    """One mode and direction of the mesh's continuous drive: the limit (deg), the event that
    decides it, the gap (deg) if a hand-over gap does, and the largest difference (deg) between the
    mesh's and the exact model's contact ends of the pairs on the way (NaN when none compared)."""

    mode: str
    direction: int
    angle_deg: float
    event: str
    gap_deg: tuple[float, float] | None
    max_deviation_deg: float
    pairs: tuple[PairContact, ...]
    gap_poses: int = 0  # swept poses inside the gap at which no pair is in conjugate contact
    fit_residual_mm: float = math.nan  # the largest distance of a flank's vertex from its involute

    @property
    def bounded(self) -> bool:
        """The limit is only the end of the sweep: the last pair was still in contact there."""
        return self.gap_deg is None and "at the end of the sweep" in self.event


def mesh_drive(g: RackPinionGeometry, mode: str, direction: int, measured: tuple[PairContact, ...],
               angles: np.ndarray | None = None, covered: np.ndarray | None = None,
               flanks: list[FlankPair] | None = None) -> MeshDrive:
    """The chain of the measured intervals, how far their ends lie from the exact model's (pairs on
    the way to the limit, ends crossed within the sweep) and, given the swept ``angles`` and where
    a pair was in contact (``covered``, :func:`measured_pairs`), how many poses the sweep has inside
    a gap with no pair in contact."""
    drive = continuous_drive(g, mode, measured)
    limit = drive.angle_rad
    worst = math.nan
    for p in drive.pairs:
        if p.start_rad > limit + 1e-12:
            continue
        exact = pair_contact(g, mode, p.j, p.k)
        for mine, theirs, by in ((p.start_rad, exact.start_rad, p.start_by), (p.end_rad, exact.end_rad, p.end_by)):
            if by.startswith(("beyond", "before")) or by == "at angle 0":
                continue
            d = abs(math.degrees(mine - theirs))
            worst = d if math.isnan(worst) else max(worst, d)
    gap = None if drive.gap_rad is None else (math.degrees(drive.gap_rad[0]), math.degrees(drive.gap_rad[1]))
    event = drive.event
    if gap is None and "beyond the end of the sweep" in event:
        last = max(drive.pairs, key=lambda p: p.end_rad)
        event = (f"{mode}: {pinion_name(g, last.j)} still in conjugate contact at the end of the sweep "
                 f"({drive.angle_deg:.3f}°)")
    inside = 0
    if drive.gap_rad is not None and angles is not None and covered is not None:
        mag = np.abs(np.asarray(angles, float))
        inside = int(np.sum((mag > drive.gap_rad[0]) & (mag < drive.gap_rad[1]) & ~covered))
    residual = max((p.flank.residual_mm for p in flanks), default=math.nan) if flanks else math.nan
    return MeshDrive(mode, direction, drive.angle_deg, event, gap, worst, drive.pairs, inside, residual)


def extra_angles_deg(g: RackPinionGeometry, mode: str, limit_deg: float) -> list[float]:
    """Pinion angles (deg, magnitudes ≤ ``limit_deg``) to add to the sweep: around both events of
    every tight hand-over the exact model predicts on the way to its limit, inside any gap, and
    around the limit itself."""
    drive = continuous_drive(g, mode)
    events: list[float] = [drive.angle_deg]
    for end, start in drive.handovers:
        a, b = math.degrees(end), math.degrees(start)
        if b > a - TIGHT_DEG:
            events += [a, b]
    out = [e + d for e in events for d in EVENT_OFFSETS_DEG]
    if drive.gap_rad is not None:
        out.append(0.5 * math.degrees(drive.gap_rad[0] + drive.gap_rad[1]))
    return sorted({round(a, 9) for a in out if 0.0 < a <= limit_deg})
