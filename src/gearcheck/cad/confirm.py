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


def _measure(a, b, label: str) -> BRepExtrema_DistShapeShape:
    dist = BRepExtrema_DistShapeShape(a, b)
    if not dist.IsDone():
        raise RuntimeError(f"BRepExtrema failed at {label}")
    return dist


def _nearest_pair(dist: BRepExtrema_DistShapeShape) -> tuple[np.ndarray, np.ndarray]:
    """The closest points (world, mm) of a measured pair: of its solutions, the first (OCC may
    list several equal-distance pairs, e.g. along a line contact)."""
    if dist.NbSolution() < 1:
        raise RuntimeError("BRepExtrema gave no closest points")
    a, b = dist.PointOnShape1(1), dist.PointOnShape2(1)
    return np.array([a.X(), a.Y(), a.Z()]), np.array([b.X(), b.Y(), b.Z()])


def exact_closest(parts: dict[str, Part], worst: WorstPose, near: np.ndarray | None = None,
                  radius: float = NEAR_RADIUS_MM) -> tuple[float, np.ndarray, np.ndarray]:
    """(exact distance, closest point on part_a, closest point on part_b) at the worst pose, the
    points in world coordinates (mm, the parts posed and scaled as in the worst pose); with
    ``near`` only the faces around it are measured, as :func:`exact_distance`. Where the solids
    intersect the distance is 0 and the points are one common point."""
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    if near is not None:
        dist = _measure(_faces_near(a, near, radius), _faces_near(b, near, radius), worst.label)
    else:
        dist = _measure(a.wrapped, b.wrapped, worst.label)
    point_a, point_b = _nearest_pair(dist)
    return float(dist.Value()), point_a, point_b


def exact_distance(parts: dict[str, Part], worst: WorstPose, near: np.ndarray | None = None,
                   radius: float = NEAR_RADIUS_MM) -> float:
    """Exact distance between the two solids at the worst pose; with ``near`` (world point, e.g.
    the midpoint of the mesh's nearest points) only the faces around it are measured."""
    return exact_closest(parts, worst, near, radius)[0]


def exact_overlap(parts: dict[str, Part], worst: WorstPose) -> tuple[float, float]:
    """(distance, common volume in mm³) of the two whole solids at the worst pose: for poses
    where the meshes overlap (distance 0 when the solids intersect)."""
    distance, volume, _, _ = exact_overlap_closest(parts, worst)
    return distance, volume


def exact_overlap_closest(parts: dict[str, Part], worst: WorstPose) -> tuple[float, float, np.ndarray, np.ndarray]:
    """:func:`exact_overlap` with the closest points (world, mm) of the two whole solids: where
    they intersect, one point common to both (distance 0)."""
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    dist = _measure(a.wrapped, b.wrapped, worst.label)
    point_a, point_b = _nearest_pair(dist)
    # a fuzzy Boolean (tolerance far below any mesh bound): the plain one returned a negative
    # volume on the differential's cold gears, whose flanks cross at grazing angles
    common = boolean_common(a.wrapped, b.wrapped, fuzzy_mm=COMMON_FUZZY_MM)
    volume = math.nan  # unknown unless the Boolean gives a sane volume
    if common is not None:
        props = GProp_GProps()
        BRepGProp.VolumeProperties_s(common, props)
        if props.Mass() >= 0.0:
            volume = float(props.Mass())
    return float(dist.Value()), volume, point_a, point_b
