"""Nose-wheel steering pinion sector and trimmed rack as built solids (the steering mechanism's
parts hook): measurements on the B-rep (CadQuery/OCP, marked ``cad``; one module-scoped build),
and the pure helpers the CAD module consumes (numpy, unmarked).

Tolerances: the issue's acceptance tolerance is 0.01 mm on trims and tooth thickness and 1 µm on
the flank; quantities the construction fixes exactly (axis, datum, frames) are held to 1 µm;
B-rep distances (BRepExtrema) are exact to ~1e-7 mm on planes/cylinders and ~1e-6 mm at a
tangent line contact (the distance there is flat to second order). "Both sides" checks move the
pinion 0.01 mm past / short of contact.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.design import load_template
from gearcheck.geometry import rack_pinion as rp
from gearcheck.mechanisms.steering import analysis

from conftest import TEMPLATES

ACCEPT_MM = 0.01  # trimmed heights and pitch-circle tooth thickness
FLANK_TOL_MM = 1e-3  # flank ≤ 1 µm from the exact involute
EXACT_MM = 1e-6  # a dimension the construction fixes exactly (axis, datum, corners)
CONTACT_TOL_MM = 1e-3  # zero backlash: nominal min distance below this counts as touching
PAST_CONTACT_MM = 0.01  # pinion moved this far towards / away from the rack
CLASSIFIER_TOL_MM = 1e-7  # point-in-solid tolerance (ON band) for the thickness bisection
BISECT_TOL_RAD = 1e-10  # r·1e-10 ≈ 1e-8 mm on the pitch circle
FLANK_SAMPLES_U = 41  # per flank along the profile (× 3 heights = 123 points per face)


@pytest.fixture(scope="module")
def design():
    return load_template(TEMPLATES / "nose_wheel_steering.toml")


@pytest.fixture(scope="module")
def params(design):
    return design.params


@pytest.fixture(scope="module")
def geom(params):
    return analysis.geometry_from_params(params)


# ----------------------------------------------------------------- pure helpers (numpy only)

def test_tooth_pieces_close_and_lie_on_the_exact_profile(geom):
    for j in (geom.sector_first_tooth, 0):
        pieces = rp.pinion_tooth_pieces(geom, j, 24, 24)
        assert [p.kind for p in pieces] == ["fillet", "involute", "tip", "involute", "fillet"]
        for a, b in zip(pieces[:-1], pieces[1:], strict=True):  # shared end points, bit for bit
            assert (a.rho[-1], a.gamma[-1]) == (b.rho[0], b.gamma[0])
        assert np.all(np.diff(np.concatenate([p.gamma for p in pieces])) >= 0)  # counter-clockwise
        for piece, side in ((pieces[1], -1), (pieces[3], +1)):
            assert np.abs(rp.involute_flank_distance(geom, piece.rho, piece.gamma, side)).max() < 1e-12
        assert pieces[2].rho[0] == geom.pinion_tip_radius(j)
        assert pieces[0].rho[0] == pytest.approx(geom.root_radius, abs=1e-12)
        assert -pieces[0].gamma[0] == pytest.approx(rp.pinion_root_land_start(geom), abs=1e-15)


def test_involute_flank_distance_is_the_normal_offset(geom):
    # Moving a flank point by d along the flank normal (tangent to the base circle) changes the
    # distance by exactly d: the involutes of one base circle are parallel curves.
    rho = np.linspace(geom.form_radius, geom.tip_radius, 7)
    gam = geom.involute_half_angle(rho)
    alpha_rho = np.arccos(geom.base_radius / rho)
    pts = rp.pinion_local_xy(rho, gam)
    # right flank's outward normal: along the base-circle tangent from its tangent point T (at
    # γ − α_ρ) through the point, i.e. cos α_ρ along +γ plus sin α_ρ outward
    radial = pts / rho[:, None]
    tangent_dir = np.stack([-radial[:, 1], radial[:, 0]], axis=-1)  # +γ direction
    normal = np.cos(alpha_rho)[:, None] * tangent_dir + np.sin(alpha_rho)[:, None] * radial
    moved = pts + 0.003 * normal
    r2, g2 = rp.pinion_local_polar(moved)
    assert rp.involute_flank_distance(geom, r2, g2, +1) == pytest.approx(np.full(7, 0.003), abs=1e-12)


# ----------------------------------------------------------------------- built solids (cad)

@pytest.fixture(scope="module")
def assembly(design):
    return design.impl.assembly(design.params)


@pytest.fixture(scope="module")
def built(design, assembly):
    """The parts hook's pinion and rack at angle 0 (φ = 0, L = 0)."""
    from types import SimpleNamespace

    parts = design.impl.parts(assembly)
    return SimpleNamespace(parts=parts, **{p.name: p for p in parts})


@pytest.fixture(scope="module")
def occ():
    """OCP names used by the measurements (imported lazily: the numpy tests need none)."""
    from types import SimpleNamespace

    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Section
    from OCP.BRepClass3d import BRepClass3d_SolidClassifier
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepTools import BRepTools
    from OCP.GeomAbs import GeomAbs_Cylinder, GeomAbs_Plane
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_IN, TopAbs_ON
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt

    return SimpleNamespace(
        BRepAdaptor_Surface=BRepAdaptor_Surface, BRepAlgoAPI_Common=BRepAlgoAPI_Common,
        BRepAlgoAPI_Section=BRepAlgoAPI_Section, BRepClass3d_SolidClassifier=BRepClass3d_SolidClassifier,
        BRepExtrema_DistShapeShape=BRepExtrema_DistShapeShape, BRepGProp=BRepGProp, BRepTools=BRepTools,
        GeomAbs_Cylinder=GeomAbs_Cylinder, GeomAbs_Plane=GeomAbs_Plane, GProp_GProps=GProp_GProps,
        TopAbs_IN=TopAbs_IN, TopAbs_ON=TopAbs_ON, gp_Dir=gp_Dir, gp_Pln=gp_Pln, gp_Pnt=gp_Pnt)


def _volume(occ, shape) -> float:
    props = occ.GProp_GProps()
    occ.BRepGProp.VolumeProperties_s(shape, props, 1e-6, False)
    return props.Mass()


def _common_volume(occ, a, b) -> float:
    op = occ.BRepAlgoAPI_Common(a.wrapped, b.wrapped)
    assert op.IsDone()
    return _volume(occ, op.Shape())


def _distance(occ, a, b):
    d = occ.BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    assert d.IsDone()
    return d


@pytest.mark.cad
def test_every_solid_is_valid(built):
    from gearcheck.cad.rack_pinion import is_valid

    for part in built.parts:
        assert part.solid.isValid() and is_valid(part.solid), part.name
        assert is_valid(part.placed()), part.name
        assert len(part.solid.Solids()) == 1
    assert [(p.name, p.material) for p in built.parts] == [("pinion", "steel"), ("rack", "steel")]


@pytest.mark.cad
def test_pinion_volume_is_the_outline_area_times_face_width(built, geom, assembly):
    # The numpy outline (100-segment polylines, area error < 1e-4 mm²) minus the bore, times b.
    spec = assembly.solids["pinion"]
    FACE_WIDTH_MM, PINION_BORE_DIAMETER_MM = spec.face_width_mm, spec.bore_diameter_mm
    assert (FACE_WIDTH_MM, PINION_BORE_DIAMETER_MM) == (30.0, 60.0)

    xy = geom.pinion_blank_outline(0.0, arc_segments=20000)
    x, y = xy[:, 0], xy[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    area -= math.pi * (PINION_BORE_DIAMETER_MM / 2.0) ** 2
    assert built.pinion.solid.Volume() == pytest.approx(area * FACE_WIDTH_MM, rel=1e-5)


@pytest.mark.cad
def test_trimmed_heights_measured_on_the_rack_section(built, geom, occ):
    """Section the rack at mid-face; each end tooth's top edge runs from its left corner to its
    right corner: hS2 → hS6 on k = −7, hS4 → hS8 on k = −6, mirrored at k = 7, 6. The corners
    lie on the standard straight flanks (trimming only lowers the top)."""
    section = occ.BRepAlgoAPI_Section(built.rack.solid.wrapped, occ.gp_Pln(occ.gp_Pnt(0, 0, 0), occ.gp_Dir(0, 0, 1)))
    section.Build()
    import cadquery as cq

    segments = [tuple(np.array(v.toTuple()[:2]) for v in e.Vertices())
                for e in cq.Shape.cast(section.Shape()).Edges()]
    p, root = geom.pitch, geom.rack_root_height
    g = geom
    expected = {
        g.rack_first_tooth: (g.hS2_mm, g.hS6_mm), g.rack_first_tooth + 1: (g.hS4_mm, g.hS8_mm),
        g.rack_last_tooth: (g.hS6_mm, g.hS2_mm), g.rack_last_tooth - 1: (g.hS8_mm, g.hS4_mm),
        0: (g.rack_top_height, g.rack_top_height),  # an untrimmed tooth keeps the standard top
    }
    for k, (h_left, h_right) in expected.items():
        centre = k * p
        tops = [s for s in segments
                if all(abs(v[0] - centre) < p / 2 and v[1] > root + 1.0 for v in s)]
        assert len(tops) == 1, k
        left, right = sorted(tops[0], key=lambda v: v[0])
        assert left[1] == pytest.approx(h_left, abs=ACCEPT_MM)
        assert right[1] == pytest.approx(h_right, abs=ACCEPT_MM)
        # on the standard flanks: x = centre ∓ w(y)
        assert left[0] == pytest.approx(centre - float(geom.rack_half_width(left[1])), abs=EXACT_MM)
        assert right[0] == pytest.approx(centre + float(geom.rack_half_width(right[1])), abs=EXACT_MM)


def _pitch_crossing(occ, classifier, r: float, inside: float, outside: float) -> float:
    """Polar angle (pinion frame) where the circle of radius r at z = 0 crosses the solid's
    boundary between γ = inside (in the material) and γ = outside."""
    def state(gamma: float):
        x, y = rp.pinion_local_xy(r, gamma)
        classifier.Perform(occ.gp_Pnt(float(x), float(y), 0.0), CLASSIFIER_TOL_MM)
        return classifier.State()

    assert state(inside) == occ.TopAbs_IN and state(outside) not in (occ.TopAbs_IN, occ.TopAbs_ON)
    while abs(outside - inside) > BISECT_TOL_RAD:
        mid = 0.5 * (inside + outside)
        s = state(mid)
        if s == occ.TopAbs_ON:
            return mid
        if s == occ.TopAbs_IN:
            inside = mid
        else:
            outside = mid
    return 0.5 * (inside + outside)


@pytest.mark.cad
def test_pinion_tooth_thickness_on_the_pitch_circle(built, geom, occ):
    """Every sector tooth (topped ones too: RS1 > r): arc between its flanks on r = 84 at
    mid-face = s = πm/2 + 2xm·tanα (x = 0: 2π mm)."""
    classifier = occ.BRepClass3d_SolidClassifier(built.pinion.solid.wrapped)
    r, tau = geom.pitch_radius, geom.angular_pitch
    s_theory = geom.module_mm * (math.pi / 2 + 2 * geom.profile_shift * math.tan(geom.pressure_angle_rad))
    assert s_theory == pytest.approx(2 * math.pi, abs=1e-12)
    errors = []
    for j in range(geom.sector_first_tooth, geom.sector_last_tooth + 1):
        c = float(geom.pinion_tooth_angle(j, 0.0))
        left = _pitch_crossing(occ, classifier, r, c, c - tau / 2)
        right = _pitch_crossing(occ, classifier, r, c, c + tau / 2)
        errors.append(r * (right - left) - s_theory)
        assert 0.5 * (left + right) == pytest.approx(c, abs=EXACT_MM / r)  # centred on its line
    assert np.abs(errors).max() < ACCEPT_MM
    assert np.abs(errors).max() < 1e-5  # measured: ≤ 1e-8 mm (spline error ~1e-9 mm)


@pytest.mark.cad
def test_centre_to_datum_is_H(built, geom, occ):
    """The placed pinion's cylindrical faces (tip arcs, root arcs, bore) share one axis along z
    through (0, H); the rack's bottom face is the plane y = 0: their distance is H = 107."""
    pinion, rack = built.pinion.placed(), built.rack.placed()
    axes = []
    for face in pinion.Faces():
        surf = occ.BRepAdaptor_Surface(face.wrapped)
        if surf.GetType() != occ.GeomAbs_Cylinder:
            continue
        ax = surf.Cylinder().Axis()
        loc, d = ax.Location(), ax.Direction()
        assert abs(abs(d.Z()) - 1.0) < 1e-12
        axes.append((loc.X(), loc.Y(), surf.Cylinder().Radius()))
    radii = {round(a[2], 6) for a in axes}
    assert {geom.tip_radius, geom.topped_radius_mm, geom.root_radius} <= radii
    axes = np.array(axes)
    assert np.abs(axes[:, 0]).max() < EXACT_MM
    axis_y = axes[:, 1].mean()
    assert np.ptp(axes[:, 1]) < EXACT_MM

    datum = []
    for face in rack.Faces():
        surf = occ.BRepAdaptor_Surface(face.wrapped)
        if surf.GetType() != occ.GeomAbs_Plane:
            continue
        bb = face.BoundingBox()
        if bb.ymax - bb.ymin < EXACT_MM and bb.ymax < 1.0:  # a horizontal face at the bottom
            datum.append(surf.Plane().Location().Y())
    assert len(datum) == 1
    assert rack.BoundingBox().ymin == pytest.approx(datum[0], abs=EXACT_MM)
    assert axis_y - datum[0] == pytest.approx(107.0, abs=1e-3)  # H = 107


@pytest.mark.cad
def test_pinion_flanks_are_the_exact_involute(built, geom, occ):
    """All 32 involute flank faces, ≥ 100 points each (41 along the profile × 3 heights),
    against the closed-form involute: |distance| ≤ 1 µm."""
    pinion = built.pinion.solid
    tau = geom.angular_pitch
    worst, flanks, samples = 0.0, 0, 0
    for face in pinion.Faces():
        surf = occ.BRepAdaptor_Surface(face.wrapped)
        u0, u1, v0, v1 = occ.BRepTools.UVBounds_s(face.wrapped)
        pts = np.array([[q.X(), q.Y(), q.Z()] for q in
                        (surf.Value(u, v) for u in np.linspace(u0, u1, FLANK_SAMPLES_U)
                         for v in np.linspace(v0, v1, 3))])
        rho, gam = rp.pinion_local_polar(pts[:, :2])
        if rho.min() < geom.form_radius - EXACT_MM or rho.max() - rho.min() < 1.0:
            continue  # fillets, root and tip arcs, bore
        j = math.floor(gam.mean() / tau)
        centre = (j + 0.5) * tau
        side = 1 if gam.mean() > centre else -1
        # the face spans form circle → this tooth's tip radius
        assert rho.min() == pytest.approx(geom.form_radius, abs=EXACT_MM)
        assert rho.max() == pytest.approx(geom.pinion_tip_radius(j), abs=EXACT_MM)
        d = rp.involute_flank_distance(geom, rho, gam - centre, side)
        worst = max(worst, float(np.abs(d).max()))
        flanks += 1
        samples = len(pts)
    assert flanks == 2 * (geom.sector_last_tooth - geom.sector_first_tooth + 1)
    assert samples >= 100
    assert worst <= FLANK_TOL_MM
    assert worst <= 1e-5  # measured 0.0005 µm with 24 points per flank


@pytest.mark.cad
def test_frames_match_the_geometry_at_another_pose(built, geom, occ):
    """Pose as data: at φ = 0.3 rad and L = 17 mm (each part moved by its typed motion from its
    pose as built, as the sweep moves it), the numpy model's tip corners S1/S3 and the trimmed
    corners S2…S8 lie on the boundary of the placed solids."""
    import dataclasses

    phi, travel = 0.3, 17.0
    moved_pinion = dataclasses.replace(built.pinion, pose=built.pinion.motion.matrix(phi) @ built.pinion.pose)
    moved_rack = dataclasses.replace(built.rack, pose=built.rack.motion.matrix(travel) @ built.rack.pose)
    np.testing.assert_allclose(moved_pinion.pose, rp.pinion_pose(geom, phi), atol=1e-12)
    np.testing.assert_allclose(moved_rack.pose, rp.rack_pose(travel), atol=1e-12)
    pinion = occ.BRepClass3d_SolidClassifier(moved_pinion.placed().wrapped)
    rack = occ.BRepClass3d_SolidClassifier(moved_rack.placed().wrapped)
    first = geom.sector_first_tooth
    corners = [(pinion, geom.pinion_tip_corner(j, phi, side)) for j in (first, first + 1, geom.sector_last_tooth)
               for side in (-1, 1)]
    corners += [(rack, c) for c in geom.trim_corners(travel).values()]
    for classifier, (x, y) in corners:
        for z in (-10.0, 0.0, 10.0):
            classifier.Perform(occ.gp_Pnt(float(x), float(y), z), EXACT_MM)
            assert classifier.State() == occ.TopAbs_ON, (x, y, z)


@pytest.mark.cad
def test_pinion_and_rack_touch_without_overlap_at_angle_0(built, geom, occ):
    """Zero backlash: at angle 0 the bodies touch (min distance ≈ 0) with no common volume, the
    contacts lie on the two lines of action through P = (0, h) at ±α (towing and power side);
    lifted 0.01 mm the gap is exactly 0.01·sin α, pushed 0.01 mm they overlap."""
    pinion, rack = built.pinion.placed(), built.rack.placed()
    a, h = geom.pressure_angle_rad, geom.rolling_line_height

    nominal = _distance(occ, pinion, rack)
    assert nominal.Value() < CONTACT_TOL_MM
    assert _common_volume(occ, pinion, rack) < 1e-6  # mm³
    sides = set()
    for i in range(1, nominal.NbSolution() + 1):
        q = nominal.PointOnShape1(i)
        towing = q.X() * math.sin(a) + (q.Y() - h) * math.cos(a)  # distance to the towing line
        power = -q.X() * math.sin(a) + (q.Y() - h) * math.cos(a)
        assert min(abs(towing), abs(power)) < CONTACT_TOL_MM
        sides.add("towing" if abs(towing) < abs(power) else "power")
    assert sides == {"towing", "power"}

    # pulled apart along y the flank gap is δ·sin α (flanks at α to the vertical); pushed, they
    # overlap (measured 0.295 mm³ for δ = 0.01 mm)
    lifted = _distance(occ, pinion.translate((0, PAST_CONTACT_MM, 0)), rack)
    assert lifted.Value() == pytest.approx(PAST_CONTACT_MM * math.sin(a), abs=1e-6)
    assert _common_volume(occ, pinion.translate((0, -PAST_CONTACT_MM, 0)), rack) > 1e-3  # mm³


@pytest.mark.cad
def test_every_contact_the_line_of_action_predicts_touches(built, geom, occ):
    """Angle 0, both sides: contacts lie on each line of action at t = −(s/2)·cos α + n·pb
    (from P, towards +x on the towing side / −x on the power side), between the rack tooth's top
    corner (t = −(top − h)/sin α) and the pinion tip circle (t = √(Ra² − rb²) − r·sin α). At each,
    the nearest pinion and rack faces touch (< 1 µm; measured 1.5e-7 mm, BRepExtrema's own
    precision on a B-spline/plane tangency)."""
    import cadquery as cq

    pinion, rack = built.pinion.placed(), built.rack.placed()
    a, h, r = geom.pressure_angle_rad, geom.rolling_line_height, geom.pitch_radius
    t_start = -(geom.rack_top_height - h) / math.sin(a)
    t_end = math.sqrt(geom.tip_radius ** 2 - geom.base_radius ** 2) - r * math.sin(a)
    t0 = -geom.pinion_pitch_thickness / 2 * math.cos(a)
    ts = [t0 + n * geom.base_pitch for n in range(-3, 4) if t_start < t0 + n * geom.base_pitch < t_end]
    assert len(ts) == 2  # contact ratio between 1 and 2 at angle 0 (1.59 untrimmed)

    def faces_near(shape, point):
        v = cq.Vertex.makeVertex(*point).wrapped
        return [f for f in shape.Faces() if occ.BRepExtrema_DistShapeShape(f.wrapped, v).Value() < CONTACT_TOL_MM]

    for side in (+1, -1):  # towing line (cos α, −sin α); power line (−cos α, −sin α)
        for t in ts:
            q = (side * t * math.cos(a), h - t * math.sin(a), 0.0)
            gaps = [occ.BRepExtrema_DistShapeShape(f.wrapped, g.wrapped).Value()
                    for f in faces_near(pinion, q) for g in faces_near(rack, q)]
            assert gaps and min(gaps) < CONTACT_TOL_MM, (side, t)


@pytest.mark.cad
def test_parts_at_angle_0_are_posed_as_documented(built, geom):
    np.testing.assert_allclose(built.pinion.pose[:3, 3], [0.0, geom.centre_to_datum_mm, 0.0], atol=0)
    np.testing.assert_allclose(built.pinion.pose[:3, :3], np.eye(3), atol=0)
    np.testing.assert_allclose(built.rack.pose, np.eye(4), atol=0)
