"""Exact B-rep distance (OCC BRepExtrema) at a sweep's worst poses, and the exact overlap where
the meshes overlap.

About 2.5 s per pose on whole gears, so only the few worst poses are confirmed: the mesh sweep
finds them, this measures them without chord error. Where the meshes overlap, the mesh's
nearest points mean nothing (FCL gives no depth), so the whole solids are measured: their
distance (0 when they intersect) and their common volume (BRepAlgoAPI_Common).
"""

from __future__ import annotations

import math

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.gp import gp_Pnt
from OCP.TopoDS import TopoDS_Compound

from gearcheck.cad.placement import Part, place
from gearcheck.cad.primitives import boolean_common
from gearcheck.results import WorstPose


def _posed(parts: dict[str, Part], name: str, pose, scale: float):
    """``name`` is a part ("link_03") or one of its features ("link_03.plate")."""
    base, _, feature = name.partition(".")
    solid = parts[base].feature(feature)
    if scale != 1.0:
        solid = solid.scale(scale)  # about the own-frame origin
    return place(solid, np.asarray(pose, float))


# Faces farther than this from the mesh's nearest points are left out of the exact distance: the
# exact closest points lie within the mesh-error bound (hundredths of a mm) of the mesh's, and
# whole gears cost ~15 s per pair where the faces around the contact cost well under 1 s.
NEAR_RADIUS_MM = 5.0
# Fuzzy tolerance of the overlap Boolean (mm): far below any mesh-error bound.
COMMON_FUZZY_MM = 1e-5


def _faces_near(shape, point: np.ndarray, radius: float):
    """Compound of the faces whose bounding box comes within ``radius`` of ``point``."""
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    count = 0
    for face in shape.Faces():
        box = Bnd_Box()
        BRepBndLib.Add_s(face.wrapped, box)
        if box.Distance(Bnd_Box(gp_Pnt(*point), gp_Pnt(*point))) <= radius:
            builder.Add(compound, face.wrapped)
            count += 1
    return compound if count else shape.wrapped


def exact_distance(parts: dict[str, Part], worst: WorstPose, near: np.ndarray | None = None,
                   radius: float = NEAR_RADIUS_MM) -> float:
    """Exact distance between the two solids at the worst pose; with ``near`` (world point, e.g.
    the midpoint of the mesh's nearest points) only the faces around it are measured."""
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    if near is not None:
        dist = BRepExtrema_DistShapeShape(_faces_near(a, near, radius), _faces_near(b, near, radius))
    else:
        dist = BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    if not dist.IsDone():
        raise RuntimeError(f"BRepExtrema failed at {worst.label}")
    return float(dist.Value())


def exact_overlap(parts: dict[str, Part], worst: WorstPose) -> tuple[float, float]:
    """(distance, common volume in mm³) of the two whole solids at the worst pose: for poses
    where the meshes overlap (distance 0 when the solids intersect)."""
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    dist = BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    if not dist.IsDone():
        raise RuntimeError(f"BRepExtrema failed at {worst.label}")
    # a fuzzy Boolean (tolerance far below any mesh bound): the plain one returned a negative
    # volume on the differential's cold gears, whose flanks cross at grazing angles
    common = boolean_common(a.wrapped, b.wrapped, fuzzy_mm=COMMON_FUZZY_MM)
    volume = math.nan  # unknown unless the Boolean gives a sane volume
    if common is not None:
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(common, props)
        if props.Mass() >= 0.0:
            volume = float(props.Mass())
    return float(dist.Value()), volume
