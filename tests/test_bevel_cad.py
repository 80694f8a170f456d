"""Built bevel gears (CadQuery/OCP): the solid matches the spherical-involute mathematics.

The differential's pair: z = 13 / 33, module 2.5, face 14, α 20°, Σ 90°, x = ±0.39 (Gleason's
long/short addendum rule, 0.389, rounded; see docs/bevel.md). Built once per module.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytestmark = pytest.mark.cad

cq = pytest.importorskip("cadquery")
trimesh = pytest.importorskip("trimesh")

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Surface  # noqa: E402
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common  # noqa: E402
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402
from OCP.BRepTools import BRepTools  # noqa: E402
from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d  # noqa: E402
from OCP.Geom import Geom_Circle  # noqa: E402
from OCP.GeomAPI import GeomAPI_IntCS  # noqa: E402
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Pnt2d  # noqa: E402
from OCP.TopAbs import TopAbs_IN  # noqa: E402

from gearcheck.cad.bevel import (build_bevel_gear, flank_faces, is_valid,  # noqa: E402
                                 volume_mm3)
from gearcheck.cad.mesh import mesh_shape  # noqa: E402
from gearcheck.geometry.bevel import (BevelGearSpec, flank_distance, mating_spec,  # noqa: E402
                                      pitch_cone_tooth_thickness)
from gearcheck.geometry.bevel_volume import analytic_volume_mm3  # noqa: E402

PINION = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0,
                       pressure_angle_deg=20.0, profile_shift=0.39, bore_mm=10.0)
GEAR = mating_spec(PINION, bore_mm=20.0)

FLANK_TOL_MM = 1e-3  # brief: exact flanks within 1 µm
THICKNESS_TOL_MM = 0.01  # brief
MESH_TOL_MM = 0.01  # the sweep's chordal tolerance
BUILD_TIME_BUDGET_S = 2.0  # brief target (measured ~0.5 s; 4× headroom for a shared machine)


@pytest.fixture(scope="module")
def built():
    out = {}
    for spec in (PINION, GEAR):
        build = build_bevel_gear(spec)
        out[spec.teeth] = (spec, build, mesh_shape(build.solid, MESH_TOL_MM))
    return out


@pytest.fixture(params=[13, 33], ids=["z13", "z33"])
def gear(request, built):
    return built[request.param]


def _face_grid(face, n):
    """Points of the face on an n × n grid of its UV box, kept where inside the trim."""
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face.wrapped)
    surface = BRepAdaptor_Surface(face.wrapped)
    classifier = BRepTopAdaptor_FClass2d(face.wrapped, 1e-9)
    pts = []
    for u in np.linspace(u0, u1, n):
        for v in np.linspace(v0, v1, n):
            if classifier.Perform(gp_Pnt2d(u, v)) == TopAbs_IN:
                pts.append(surface.Value(u, v).Coord())
    return np.array(pts)


def test_solid_is_valid_and_one_piece(gear):
    spec, build, _ = gear
    assert build.solid.ShapeType() == "Solid"
    assert is_valid(build.solid)
    assert build.solid.isValid()


def test_build_time(gear):
    spec, build, _ = gear
    assert build.total_s < BUILD_TIME_BUDGET_S, build


def test_volume_equals_analytic_volume(gear):
    # independent of CAD: Pappus under the root + ∫ tooth width over the polar angle. Spline
    # error (< 0.1 µm over ~2000 mm² of flank) is worth < 0.001 mm³.
    spec, build, _ = gear
    assert volume_mm3(build.solid) == pytest.approx(analytic_volume_mm3(spec), abs=0.01)


def test_tooth_zero_flanks_are_spherical_involutes(gear):
    spec, build, _ = gear
    faces = flank_faces(spec, build.solid)
    for side in (-1, 1):
        pts = _face_grid(faces[(0, side)], 20)
        assert len(pts) >= 100
        dev = flank_distance(spec, pts, side=side)
        assert dev.max() <= FLANK_TOL_MM, dev.max()
        # and the samples really span the face width (toe to heel)
        r = np.linalg.norm(pts, axis=1)
        assert r.max() - r.min() > 0.9 * spec.face_width_mm


def test_every_flank_of_every_tooth(gear):
    spec, build, _ = gear
    faces = flank_faces(spec, build.solid)
    assert sorted(faces) == [(k, s) for k in range(spec.teeth) for s in (-1, 1)]
    worst = max(flank_distance(spec, _face_grid(f, 6), side=key[1]).max()
                for key, f in faces.items())
    assert worst <= FLANK_TOL_MM


def _pitch_circle_crossings(spec, face, cone_distance):
    """Azimuths where the pitch circle at ``cone_distance`` crosses the face's surface, each
    checked to lie on the face itself (trimmed) within 1e-6 mm."""
    d = spec.pitch_angle_rad
    circle = Geom_Circle(gp_Ax2(gp_Pnt(0, 0, cone_distance * math.cos(d)), gp_Dir(0, 0, 1)),
                         cone_distance * math.sin(d))
    inter = GeomAPI_IntCS(circle, BRep_Tool.Surface_s(face.wrapped))
    out = []
    for i in range(1, inter.NbPoints() + 1):
        p = inter.Point(i)
        dist = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(p).Vertex(), face.wrapped)
        if dist.Value() < 1e-6:
            out.append(math.atan2(p.Y(), p.X()))
    return out


def test_pitch_cone_tooth_thickness_at_both_ends(gear):
    spec, build, _ = gear
    faces = flank_faces(spec, build.solid)
    measured = {}
    for r in (spec.outer_cone_distance_mm, spec.inner_cone_distance_mm):
        (a_minus,) = _pitch_circle_crossings(spec, faces[(0, -1)], r)
        (a_plus,) = _pitch_circle_crossings(spec, faces[(0, 1)], r)
        measured[r] = r * math.sin(spec.pitch_angle_rad) * (a_plus - a_minus)
        assert measured[r] == pytest.approx(float(pitch_cone_tooth_thickness(spec, r)),
                                            abs=THICKNESS_TOL_MM)
    ratio = measured[spec.outer_cone_distance_mm] / measured[spec.inner_cone_distance_mm]
    # the tooth tapers to the apex: thickness ∝ cone distance (1e-4: sub-µm errors on 3–5 mm)
    assert ratio == pytest.approx(spec.outer_cone_distance_mm / spec.inner_cone_distance_mm,
                                  rel=1e-4)


def test_tooth_count_on_the_mean_pitch_circle(gear):
    spec, build, _ = gear
    r = spec.outer_cone_distance_mm - spec.face_width_mm / 2
    d = spec.pitch_angle_rad
    half = math.pi / spec.teeth  # start the circle in a tooth space, not inside tooth 0
    frame = gp_Ax2(gp_Pnt(0, 0, r * math.cos(d)), gp_Dir(0, 0, 1),
                   gp_Dir(math.cos(half), math.sin(half), 0))
    circle = BRepBuilderAPI_MakeEdge(Geom_Circle(frame, r * math.sin(d))).Edge()
    op = BRepAlgoAPI_Common(build.solid.wrapped, circle)
    pieces = cq.Shape.cast(op.Shape()).Edges()
    assert len(pieces) == spec.teeth
    # each piece is one tooth: its arc is the pitch thickness at r
    lengths = np.array([e.Length() for e in pieces])
    assert np.allclose(lengths, pitch_cone_tooth_thickness(spec, r), atol=1e-5)


def test_mesh_is_watertight_and_consistently_wound(gear):
    spec, build, mesh = gear
    assert mesh.is_watertight()
    assert mesh.is_winding_consistent()
    assert mesh.volume() > 0  # outward normals
    # and trimesh's independent verdict (watertight, consistent winding, outward, volume)
    tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    assert tm.is_watertight and tm.is_winding_consistent and tm.is_volume
    assert tm.volume == pytest.approx(mesh.volume(), rel=1e-12)


def test_mesh_error_and_volume_within_tessellation_bound(gear):
    spec, build, mesh = gear
    # measured chord error (centroids and edge midpoints) within the requested tolerance
    assert mesh.sampled_error_mm <= MESH_TOL_MM
    v_brep = volume_mm3(build.solid)
    # every surface point lies within the bound of the mesh: |ΔV| ≤ area · bound
    assert abs(mesh.volume() - v_brep) <= build.solid.Area() * mesh.error_bound_mm
    assert mesh.volume() < v_brep  # convex flanks, tips, hub: chords cut inside


def test_flank_triangles_lie_within_tolerance_of_the_analytic_flank(gear):
    spec, build, mesh = gear
    flanks = list(flank_faces(spec, build.solid).values())
    flank_ids = [i for i, f in enumerate(build.solid.Faces()) if any(f.isSame(g) for g in flanks)]
    assert len(flank_ids) == 2 * spec.teeth
    tris = mesh.faces[np.isin(mesh.face_ids, flank_ids)]
    w = np.array([[a, b, 1 - a - b] for a in np.linspace(0, 1, 5) for b in np.linspace(0, 1, 5)
                  if a + b <= 1 + 1e-12])
    pts = np.einsum("wk,tkd->twd", w, mesh.vertices[tris]).reshape(-1, 3)
    dev = flank_distance(spec, pts)
    assert dev.max() <= MESH_TOL_MM
    assert len(tris) > 100 * spec.teeth
