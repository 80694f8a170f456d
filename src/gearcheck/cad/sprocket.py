"""Track-drive sprocket and track links as B-rep solids (seed 002), from numpy data.

- Sprocket (its own frame: axis +z, mid-plane z = 0, groove k on polar angle k·2π/z): each tooth
  row is one planar outline of exact circular arcs from :class:`gearcheck.geometry.iso606.ToothGap`
  — per groove the seating arc (ri), two flank arcs (re), and the tip-circle land to the next
  groove — with the bore as inner circle, extruded to the tooth width. The two rows sit either side
  of the middle groove, whose floor (a hub cylinder) lies ``MIDDLE_GROOVE_DEPTH_MM`` below the
  root circle (the seating arcs' bottom). One fuse joins rows and hub.
- Link (its own frame, :mod:`gearcheck.geometry.track_chain`): the sleeve cylinder on the pin axis
  (z) fused with the plate box whose inner face lies e outside the pin line.
- :func:`track_drive_parts` composes them for a template: the sprocket plus a wrapped chain
  segment, every part as (local solid, 4×4 pose) so a sweep can move them as data.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import cadquery as cq
import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeWire

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.cad.placement import Part, place
# The layout (numbers) lives in the mechanism's pure module, which the template model also
# builds to reject a set before any CAD work; re-exported here for the CAD callers.
from gearcheck.mechanisms.track.layout import (  # noqa: F401
    BORE_DIAMETER_MM,
    DEFAULT_ENTRY_ANGLE_DEG,
    DEFAULT_RUN_LINKS,
    DEFAULT_WRAP_ANGLE_DEG,
    MIDDLE_GROOVE_DEPTH_MM,
    SprocketSpec,
    default_wrap,
    link_geometry,
    sprocket_spec,
)

SPROCKET_MATERIAL = "7075-T651 aluminium alloy"
LINK_MATERIAL = "cast aluminium track link with steel sleeve"


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
    for (_, a), (b, _) in zip(ranges[:-1], ranges[1:]):
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


@dataclass(frozen=True)
class TrackDriveParts:
    """The sprocket and a chain segment at one drive angle, and what built them."""

    sprocket_angle_rad: float
    sprocket_spec: SprocketSpec
    wrap: tc.ChainWrap
    link_geometry: tc.LinkGeometry
    link_solids: LinkSolids
    sprocket: Part
    links: list[Part]
    build_s: dict[str, float] = field(default_factory=dict)

    @property
    def parts(self) -> list[Part]:
        return [self.sprocket, *self.links]

    def seated_links(self) -> np.ndarray:
        return self.wrap.seated_links(self.sprocket_angle_rad)

    def link_poses(self, sprocket_angle_rad: float) -> np.ndarray:
        """(links, 4, 4) link poses at another drive angle (the same solids)."""
        return self.wrap.link_matrices(sprocket_angle_rad)


def track_drive_parts(params, sprocket_angle_rad: float = 0.0, links: int | None = None,
                      entry_angle_deg: float = DEFAULT_ENTRY_ANGLE_DEG,
                      wrap_angle_deg: float = DEFAULT_WRAP_ANGLE_DEG,
                      run_links: int = DEFAULT_RUN_LINKS) -> TrackDriveParts:
    """Sprocket + a chain segment for the track template's ``Params``, posed at drive angle θ:
    ``links`` links, or (None) as many as the wrap seats plus ``run_links`` on each run.

    The plate offset e comes from the mechanism analysis (the offset that leaves the template's
    tip gap under a seated link's plate); the solids are built once and shared by every link.
    """
    t0 = time.perf_counter()
    spec = sprocket_spec(params)
    sprocket = build_sprocket(spec)
    t1 = time.perf_counter()
    geo = link_geometry(params, spec.gap)
    link_solids = build_link(geo)
    t2 = time.perf_counter()
    wrap = default_wrap(params.sprocket.teeth, params.chain.pitch_mm, links, entry_angle_deg, wrap_angle_deg,
                        run_links)
    poses = wrap.link_matrices(sprocket_angle_rad)
    features = {"plate": link_solids.plate, "sleeve": link_solids.sleeve}
    link_parts = [Part(f"link_{j:02d}", LINK_MATERIAL, link_solids.link, poses[j], color=(0.3, 0.3, 0.35),
                       motion={"kind": "chain_link"}, features=features) for j in range(wrap.links)]
    return TrackDriveParts(
        sprocket_angle_rad=sprocket_angle_rad,
        sprocket_spec=spec,
        wrap=wrap,
        link_geometry=geo,
        link_solids=link_solids,
        sprocket=Part("sprocket", SPROCKET_MATERIAL, sprocket, tc.sprocket_matrix(sprocket_angle_rad), color=(0.75, 0.75, 0.8), motion={"kind": "rotation", "axis": [0.0, 0.0, 1.0], "origin": [0.0, 0.0, 0.0]}),
        links=link_parts,
        build_s={"sprocket": t1 - t0, "link": t2 - t1},
    )
