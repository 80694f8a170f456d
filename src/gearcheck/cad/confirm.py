"""Exact B-rep distance (OCC BRepExtrema) at a sweep's worst poses, and the exact overlap where
the meshes overlap.

About 2.5 s per pose on whole gears, so only the few worst poses are confirmed: the mesh sweep
finds them, this measures them without chord error. Where the meshes overlap, the mesh's
nearest points mean nothing (FCL gives no depth), so the whole solids are measured: their
distance (0 when they intersect) and their common volume (BRepAlgoAPI_Common).
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Builder
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
from OCP.BRepClass3d import BRepClass3d_SolidClassifier
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepTools import BRepTools
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.TopAbs import TopAbs_IN
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.TopoDS import TopoDS_Compound
from OCP.BRep import BRep_Tool

from gearcheck.cad.placement import Part, place
from gearcheck.cad.primitives import boolean_common
from gearcheck.results import WorstPose

log = logging.getLogger("gearcheck")


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
# Fuzzy tolerance of the overlap Boolean (mm): far below any mesh-error bound; where it gives no
# sane volume (flanks crossing at grazing angles), the other tolerances are tried in turn.
COMMON_FUZZY_MM = 1e-5
COMMON_FUZZY_RETRIES_MM = (1e-4,)
# Two solids closer than this (mm) are in contact: a zero distance, to rounding.
CONTACT_MM = 1e-7
# A common volume below this (mm³) is a touch, not an overlap (rounding of the Boolean).
TOUCH_VOLUME_MM3 = 1e-9
# Where the volume cannot be had: the surface of each solid sampled on a grid of SAMPLES × SAMPLES
# points per face within DEPTH_RADIUS_MM of the contact, each point classified against the other
# solid, and the deepest one inside measured (a penetration depth, to the grid's spacing).
DEPTH_RADIUS_MM = 0.3
DEPTH_SAMPLES = 15


def _faces_near(shape, point: np.ndarray, radius: float):
    """Compound of the faces whose bounding box comes within ``radius`` of ``point`` (the whole
    shape where none does)."""
    faces = _faces_within(shape.wrapped, point, radius)
    return _compound(faces) if faces else shape.wrapped


def _compound(faces: list) -> TopoDS_Compound:
    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    for face in faces:
        builder.Add(compound, face)
    return compound


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
    return float(dist.Value()), _common_volume(a.wrapped, b.wrapped), point_a, point_b


def _common_volume(a, b) -> float:
    """The two solids' common volume (mm³), or NaN where no Boolean gives a sane one. Fuzzy
    first (a tolerance far below any mesh bound: the plain one returned a negative volume on the
    differential's cold gears, whose flanks cross at grazing angles), then the others in turn."""
    for fuzzy in (COMMON_FUZZY_MM, *COMMON_FUZZY_RETRIES_MM):
        t0 = time.perf_counter()
        common = boolean_common(a, b, fuzzy_mm=fuzzy)
        volume = math.nan
        if common is not None:
            props = GProp_GProps()
            BRepGProp.VolumeProperties_s(common, props)
            volume = float(props.Mass())
        log.info("common volume at fuzzy %g mm: %s (%.2f s)", fuzzy, f"{volume:.4g} mm³" if volume >= 0 else "none",
                 time.perf_counter() - t0)
        if volume >= 0.0:
            return volume
    return math.nan


def contact_state(parts: dict[str, Part], worst: WorstPose, distance_mm: float, volume_mm3: float | None,
                  near: np.ndarray) -> tuple[str, float]:
    """("clear" | "touching" | "overlapping", penetration depth in mm, NaN where not sampled) of the
    two solids at the worst pose. A zero distance cannot tell touching from overlapping: there the
    common volume decides (above :data:`TOUCH_VOLUME_MM3`: overlapping), and where no volume could
    be had (or none was asked for), the deepest sampled surface point of either solid inside the
    other (:func:`penetration_depth` around ``near``, the contact point)."""
    if distance_mm > CONTACT_MM:
        return "clear", 0.0
    if volume_mm3 is not None and math.isfinite(volume_mm3):
        return ("overlapping" if volume_mm3 > TOUCH_VOLUME_MM3 else "touching"), math.nan
    a = _posed(parts, worst.part_a, worst.pose_a, worst.scale_a)
    b = _posed(parts, worst.part_b, worst.pose_b, worst.scale_b)
    t0 = time.perf_counter()
    depth = max(penetration_depth(a.wrapped, b.wrapped, near), penetration_depth(b.wrapped, a.wrapped, near))
    log.info("sampled penetration depth %.3g mm (%.2f s)", depth, time.perf_counter() - t0)
    return ("overlapping" if depth > CONTACT_MM else "touching"), depth


def _faces_within(shape, point: np.ndarray, radius: float) -> list:
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    out = []
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    target = Bnd_Box(gp_Pnt(*point), gp_Pnt(*point))
    while explorer.More():
        face = TopoDS.Face_s(explorer.Current())
        box = Bnd_Box()
        BRepBndLib.Add_s(face, box)
        if box.Distance(target) <= radius:
            out.append(face)
        explorer.Next()
    return out


def penetration_depth(a, b, near: np.ndarray, radius: float = DEPTH_RADIUS_MM, samples: int = DEPTH_SAMPLES) -> float:
    """How deep (mm) the surface of solid ``a`` reaches into solid ``b`` around ``near``: each
    face of ``a`` within ``radius`` sampled on a ``samples`` × ``samples`` grid of its parameters
    spanning ``radius`` about the point nearest ``near`` (points off the trimmed face skipped),
    each point classified against ``b``, the distance to ``b``'s boundary of the deepest inside.
    0 where no sampled point is inside (touching, or an overlap thinner than the grid)."""
    classifier = BRepClass3d_SolidClassifier(b)
    boundary = _compound(_faces_within(b, near, 2.0 * radius + 1.0))  # depth is to b's faces around the contact
    deepest = 0.0
    for face in _faces_within(a, near, radius):
        surface = BRep_Tool.Surface_s(face)
        projection = GeomAPI_ProjectPointOnSurf(gp_Pnt(*near), surface)
        if projection.NbPoints() < 1:
            continue
        u0, v0 = projection.LowerDistanceParameters()
        p, du_vec, dv_vec = gp_Pnt(), gp_Vec(), gp_Vec()
        surface.D1(u0, v0, p, du_vec, dv_vec)
        if du_vec.Magnitude() <= 0.0 or dv_vec.Magnitude() <= 0.0:
            continue
        umin, umax, vmin, vmax = BRepTools.UVBounds_s(face)
        inside_face = BRepTopAdaptor_FClass2d(face, 1e-9)
        us = np.clip(u0 + np.linspace(-1, 1, samples) * radius / du_vec.Magnitude(), umin, umax)
        vs = np.clip(v0 + np.linspace(-1, 1, samples) * radius / dv_vec.Magnitude(), vmin, vmax)
        for u in us:
            for v in vs:
                if inside_face.Perform(gp_Pnt2d(float(u), float(v))) != TopAbs_IN:
                    continue
                point = surface.Value(float(u), float(v))
                classifier.Perform(point, 1e-9)
                if classifier.State() != TopAbs_IN:
                    continue
                vertex = BRepBuilderAPI_MakeVertex(point).Vertex()
                dist = BRepExtrema_DistShapeShape(vertex, boundary)
                if dist.IsDone():
                    deepest = max(deepest, float(dist.Value()))
    return deepest
