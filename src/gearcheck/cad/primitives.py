"""Solids of the simple specs in :mod:`gearcheck.geometry.solids` (rings, fused ring stacks)."""

from __future__ import annotations

import cadquery as cq

from gearcheck.geometry.solids import Ring, RingStack


def build_ring(ring: Ring) -> cq.Shape:
    """Annulus about +z between heights z0 < z1 (a full cylinder when the inner radius is 0)."""
    outer = cq.Solid.makeCylinder(ring.outer_mm, ring.height_mm, cq.Vector(0, 0, ring.z0_mm))
    if ring.inner_mm <= 0:
        return outer
    return outer.cut(cq.Solid.makeCylinder(ring.inner_mm, ring.height_mm, cq.Vector(0, 0, ring.z0_mm)))


def build_ring_stack(stack: RingStack) -> cq.Shape:
    """The rings fused in order into one solid, coplanar faces merged."""
    solid: cq.Shape = build_ring(stack.rings[0])
    if len(stack.rings) == 1:
        return solid
    for ring in stack.rings[1:]:
        solid = solid.fuse(build_ring(ring))
    return solid.clean()
