"""Roller-chain links as B-rep solids, from :class:`gearcheck.geometry.roller_chain.LinkSpec`.

Each link in its own frame (axes at (0, 0) and (p, 0), parallel to z): the inner link fuses its
rollers (d1, length b1, per strand) with its inner plates; the outer link fuses its pins (d2,
through every strand) with its outer plates. Plates are stadiums (depth h2, round ends about the
axes). The rollers, pins and plates are kept as features for exact confirmations. A multi-strand
inner link is a compound of one solid per strand (the strands' inner links are held together only
by the outer link's pins)."""

from __future__ import annotations

from dataclasses import dataclass

import cadquery as cq

from gearcheck.geometry.roller_chain import LinkSpec


@dataclass(frozen=True)
class LinkSolids:
    link: cq.Shape
    features: dict


def _plate(spec: LinkSpec, z0: float, z1: float) -> cq.Shape:
    p, h = spec.pitch_mm, spec.plate_depth_mm
    wp = cq.Workplane("XY", origin=(0, 0, z0)).center(p / 2.0, 0).slot2D(p + h, h).extrude(z1 - z0)
    return wp.findSolid()


def _fuse(shapes: list[cq.Shape]) -> cq.Shape:
    out = shapes[0]
    if len(shapes) > 1:
        out = out.fuse(*shapes[1:])
    return out.clean()


def build_link(spec: LinkSpec) -> LinkSolids:
    """The link solid and its features ("rollers" and "plates", or "pins" and "plates")."""
    plates = [_plate(spec, z0, z1) for z0, z1 in spec.plate_z_ranges()]
    bodies: list[cq.Shape]
    if spec.kind == "inner":
        b = spec.inner_width_mm
        bodies = [cq.Solid.makeCylinder(spec.roller_radius_mm, b, cq.Vector(x, 0, zs - b / 2.0))
                  for zs in spec.strand_z() for x in (0.0, spec.pitch_mm)]
        name = "rollers"
    else:
        w = spec.width_mm
        bodies = [cq.Solid.makeCylinder(spec.pin_radius_mm, w, cq.Vector(x, 0, -w / 2.0)) for x in (0.0, spec.pitch_mm)]
        name = "pins"
    solids = _fuse(plates + bodies).Solids()
    # an inner link is one solid per strand (its strands hang on the outer link's pins only)
    expected = spec.strands if spec.kind == "inner" else 1
    if len(solids) != expected:
        raise RuntimeError(f"{spec.kind} link fuse gave {len(solids)} solids, expected {expected}")
    link = solids[0] if expected == 1 else cq.Compound.makeCompound(solids)
    return LinkSolids(link, {name: cq.Compound.makeCompound(bodies), "plates": cq.Compound.makeCompound(plates)})
