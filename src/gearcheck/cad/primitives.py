"""Solids of the simple specs in :mod:`gearcheck.geometry.solids` (rings, fused ring stacks),
and the one Boolean intersection the CAD layer uses."""

from __future__ import annotations

import cadquery as cq
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
from OCP.TopoDS import TopoDS_Shape
from OCP.TopTools import TopTools_ListOfShape

from gearcheck.geometry.solids import Ring, RingStack


def boolean_common(a: TopoDS_Shape, b: TopoDS_Shape, fuzzy_mm: float | None = None) -> TopoDS_Shape | None:
    """The common part of two shapes (OCCT's general-fuse Common); ``fuzzy_mm`` makes it treat
    surfaces that close as touching and leaves the arguments untouched. None when OCCT fails."""
    op = BRepAlgoAPI_Common()
    args, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
    args.Append(a)
    tools.Append(b)
    op.SetArguments(args)
    op.SetTools(tools)
    if fuzzy_mm is not None:
        op.SetFuzzyValue(fuzzy_mm)
        op.SetNonDestructive(True)
    op.Build()
    return op.Shape() if op.IsDone() else None


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
