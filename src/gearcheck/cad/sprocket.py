"""Track-drive sprocket and track links as B-rep solids, from numpy data specs.

- Sprocket (its own frame: axis +z, mid-plane z = 0, groove k on polar angle k·2π/z): each tooth
  row is one planar outline of exact circular arcs from :class:`gearcheck.geometry.iso606.ToothGap`
  — per groove the seating arc (ri), two flank arcs (re), and the tip-circle land to the next
  groove — with the bore as inner circle, extruded to the tooth width. The two rows sit either side
  of the middle groove, whose floor is a hub cylinder below the root circle (the seating arcs'
  bottom) at the spec's hub radius (:class:`gearcheck.geometry.sprocket.SprocketSpec`). One fuse
  joins rows and hub.
- Link (its own frame, :mod:`gearcheck.geometry.track_chain`): the sleeve cylinder on the pin axis
  (z) fused with the plate box whose inner face lies e outside the pin line.

Each solid is built in its own frame; a caller poses copies of it (every chain link shares one
link solid).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cadquery as cq
import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.sprocket import SprocketSpec


def _v(p: np.ndarray, z: float) -> cq.Vector:
    return cq.Vector(float(p[0]), float(p[1]), z)


def _rot(points: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s], [s, c]]).T


def _polar(centre: np.ndarray, radius: float, angle: float) -> np.ndarray:
    return centre + radius * np.array([math.cos(angle), math.sin(angle)])


def groove_arc_points(gap: iso606.ToothGap) -> list[np.ndarray]:
    """Groove 0's four arcs as (3, 2) arrays (start, middle, end), counter-clockwise round the
    sprocket: −y flank (tip corner → junction), seating arc, +y flank (junction → tip corner),
    tip land (tip corner → groove 1's −y tip corner). The end of each is the start of the next."""
    mirror = np.array([1.0, -1.0])
    fs, sweep = gap.flank_start_angle_rad, gap.flank_sweep_rad
    flank_mid = _polar(gap.flank_centre, gap.flank_radius_mm, fs + sweep / 2.0)
    flank_up = np.array([gap.junction, flank_mid, gap.tip_corner])
    flank_down = (flank_up * mirror)[::-1]
    seat_mid = gap.seating_centre + np.array([-gap.seating_radius_mm, 0.0])
    seat = np.array([gap.junction * mirror, seat_mid, gap.junction])
    step = 2.0 * math.pi / gap.teeth
    land = np.array([gap.tip_corner, _polar(np.zeros(2), gap.tip_radius_mm, step / 2.0),
                     _rot((gap.tip_corner * mirror)[None, :], step)[0]])
    return [flank_down, seat, flank_up, land]


def row_outline_wire(gap: iso606.ToothGap, z: float) -> cq.Wire:
    """One tooth row's outline in the plane z: 4·z exact circular arcs, closed."""
    step = 2.0 * math.pi / gap.teeth
    arcs = groove_arc_points(gap)
    # Every groove's −y tip corner computed once, so the land's end and the next flank's start
    # are the same numbers (the wire closes without tolerance).
    corner_down = gap.tip_corner * np.array([1.0, -1.0])
    corners = [_rot(corner_down[None, :], k * step)[0] for k in range(gap.teeth)]
    maker = BRepBuilderAPI_MakeWire()
    for k in range(gap.teeth):
        pieces = [_rot(a, k * step) for a in arcs]
        pieces[0][0] = corners[k]
        pieces[3][2] = corners[(k + 1) % gap.teeth]
        for p in pieces:
            maker.Add(cq.Edge.makeThreePointArc(_v(p[0], z), _v(p[1], z), _v(p[2], z)).wrapped)
    if not maker.IsDone():
        raise RuntimeError("sprocket outline does not close into a wire")
    return cq.Wire(maker.Wire())


def build_sprocket(spec: SprocketSpec) -> cq.Solid:
    """The sprocket solid in its own frame."""
    bore = spec.bore_radius_mm
    rows = []
    for z0, z1 in spec.row_z_ranges():
        outer = row_outline_wire(spec.gap, z0)
        inner = cq.Wire.makeCircle(bore, cq.Vector(0, 0, z0), cq.Vector(0, 0, 1))
        rows.append(cq.Solid.extrudeLinear(outer, [inner], cq.Vector(0, 0, z1 - z0)))
    ranges = spec.row_z_ranges()
    hubs = []
    for (_, a), (b, _) in zip(ranges[:-1], ranges[1:], strict=True):
        ring = cq.Solid.makeCylinder(spec.hub_radius_mm, b - a, cq.Vector(0, 0, a))
        hubs.append(ring.cut(cq.Solid.makeCylinder(bore, b - a, cq.Vector(0, 0, a))))
    if not hubs:
        return rows[0]
    fused = rows[0].fuse(*rows[1:], *hubs).clean()
    solids = fused.Solids()
    if len(solids) != 1:
        raise RuntimeError(f"sprocket fuse gave {len(solids)} solids")
    return solids[0]


@dataclass(frozen=True)
class LinkSolids:
    """A link's solids in its own frame: the fused link and, for measurements, its two bodies."""

    link: cq.Solid
    plate: cq.Solid
    sleeve: cq.Solid


def build_link(geo: tc.LinkGeometry) -> LinkSolids:
    """The link solid in its own frame (plate box fused with the sleeve cylinder), with the plate
    and the sleeve kept as features."""
    x0, x1, y0, y1 = geo.plate_rect()
    w = geo.plate_width_mm
    plate = cq.Solid.makeBox(x1 - x0, y1 - y0, w, cq.Vector(x0, y0, -w / 2.0))
    length = geo.sleeve_length_mm
    sleeve = cq.Solid.makeCylinder(geo.sleeve_radius_mm, length, cq.Vector(0, 0, -length / 2.0))
    fused = plate.fuse(sleeve).clean()
    solids = fused.Solids()
    if len(solids) != 1:
        raise RuntimeError(f"link fuse gave {len(solids)} solids (does the sleeve cross the plate face?)")
    return LinkSolids(solids[0], plate, sleeve)
