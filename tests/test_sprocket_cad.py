"""Track-drive sprocket and chain: the pose math (numpy) and measurements on the built
solids (CadQuery/OCP, marked ``cad``; one module-scoped build, exact B-rep distances).

Tolerances: B-rep distances (BRepExtrema) and face geometry are exact to ~1e-7 mm; the
acceptance tolerance is 0.01 mm, and the "both sides" checks move a body 0.02 mm past contact.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.design import load_template
from gearcheck.mechanisms.track import analysis

from conftest import TEMPLATES

ACCEPT_MM = 0.01  # the acceptance tolerance on chord, gap
EXACT_MM = 1e-6  # B-rep measurement of a quantity the construction fixes exactly
PAST_CONTACT_MM = 0.02  # how far a body is pushed past (or short of) contact


@pytest.fixture(scope="module")
def params():
    return load_template(TEMPLATES / "eod_track_drive.toml").params


@pytest.fixture(scope="module")
def gap(params):
    sp, ch = params.sprocket, params.chain
    d = iso606.every_other_tooth_pitch_diameter(ch.pitch_mm, sp.teeth)
    return iso606.tooth_gap(d, sp.teeth, sp.seating_radius_mm, sp.flank_radius_mm, sp.seating_angle_deg,
                            d + sp.tip_over_pitch_mm)


@pytest.fixture(scope="module")
def wrap(params):
    return tc.ChainWrap.centred(params.sprocket.teeth, params.chain.pitch_mm)


# ---------------------------------------------------------------- pose math (numpy only)

def test_link_chord_is_the_pitch_at_every_angle(wrap, params):
    for theta in np.linspace(0.0, wrap.cycle_rad, 97):
        pins = wrap.pin_positions(theta)
        chords = np.linalg.norm(np.diff(pins, axis=0), axis=1)
        assert chords == pytest.approx(params.chain.pitch_mm, abs=1e-9)


def test_seated_pins_sit_on_their_grooves_and_the_rest_outside(wrap, gap):
    for theta in np.linspace(0.0, wrap.cycle_rad, 41):
        pins, seated = wrap.pin_positions(theta), wrap.seated_pins(theta)
        phi = wrap.groove_angles(theta)[seated]
        groove_centres = gap.pitch_radius_mm * np.column_stack([np.cos(phi), np.sin(phi)])
        assert np.abs(pins[seated] - groove_centres).max() < 1e-9
        # pins on the runs approach/leave from outside the pin circle (never dig under it)
        assert np.linalg.norm(pins[~seated], axis=1).min() >= gap.pitch_radius_mm - 1e-9


def test_poses_are_continuous_through_seating(wrap):
    """Pins move at most R·Δθ per step (seated pins exactly that, run pins with the chain):
    no jump when a pin seats or unseats."""
    thetas = np.linspace(-wrap.cycle_rad, 2 * wrap.cycle_rad, 1201)
    pins = np.stack([wrap.pin_positions(t) for t in thetas])
    steps = np.linalg.norm(np.diff(pins, axis=0), axis=2)
    assert steps.max() <= wrap.pin_radius_mm * (thetas[1] - thetas[0]) * (1 + 1e-6)
    seated = np.stack([wrap.seated_pins(t) for t in thetas])
    assert seated.any(axis=0).sum() >= 2 and (~seated).any(axis=0).any()  # pins do seat and unseat


def test_one_cycle_shifts_the_chain_by_one_link(wrap):
    for theta in (0.0, 0.3 * wrap.cycle_rad, 0.77 * wrap.cycle_rad):
        now, later = wrap.pin_positions(theta), wrap.pin_positions(theta + wrap.cycle_rad)
        assert np.abs(later[1:] - now[:-1]).max() < 1e-9


def test_default_wrap_has_links_seated_and_on_both_runs(wrap):
    assert wrap.links == 12  # round(120° / β) = 8 seated + 2 on each run
    seated = wrap.seated_links(0.0)
    assert seated.sum() == 8  # 120° wrap: 9 pins on the pin circle
    assert not seated[:2].any() and not seated[-2:].any()  # two links on each run


def test_sleeves_never_cut_the_outline_over_a_cycle(wrap, gap, params):
    """2-D: every sleeve circle stays outside the sampled sprocket outline through one engagement
    cycle (the wrap model lets links swing in and out without interference); seated sleeves
    keep ri − R at the seating bottom."""
    from scipy.spatial import cKDTree

    tree = cKDTree(iso606.sprocket_outline(gap, 0.02))
    r_sleeve = params.chain.sleeve_diameter_mm / 2
    clearance = np.inf
    for theta in np.linspace(0.0, wrap.cycle_rad, 201):
        c, s = math.cos(-theta), math.sin(-theta)
        pins = wrap.pin_positions(theta) @ np.array([[c, -s], [s, c]]).T  # sprocket frame
        clearance = min(clearance, (tree.query(pins)[0] - r_sleeve).min())
    assert clearance == pytest.approx(gap.seating_radius_mm - r_sleeve, abs=2e-3)


def test_link_geometry_plate_clears_the_next_sleeve_and_covers_the_teeth(params, gap):
    e = analysis.plate_offset_for_tip_gap(gap, params.track_plate.tip_gap_mm)
    geo = tc.link_geometry(params.chain.pitch_mm, params.chain.sleeve_diameter_mm, e, params.chain.track_width_mm)
    assert geo.sleeve_plate_clearance_mm() > 0.3
    # the tip corners nearest mid-span (the highest points under the plate) lie under the plate
    half_span = gap.tip_radius_mm * math.sin(gap.tip_corner_angle_rad)  # from mid-span, along the chord
    mid = geo.pitch_mm / 2
    assert geo.plate_start_x_mm < mid - half_span and mid + half_span < geo.plate_end_x_mm
    with pytest.raises(ValueError):
        tc.link_geometry(30.0, 8.0, 4.5, 60.0)  # e beyond the sleeve radius: sleeve cannot join the plate


def test_assembly_specs_poses_and_motions(params, wrap):
    """The mechanism's assembly (numpy only): the sprocket, then link_00 … link_NN posed by the
    default wrap at θ = 0, each link a copy of one link solid with plate and sleeve features."""
    from gearcheck.geometry.sprocket import SprocketSpec
    from gearcheck.mechanism import get
    from gearcheck.sweep.motion import ChainLink, Rotation

    assembly = get("track").assembly(params)
    assert assembly.names == ["sprocket"] + [f"link_{j:02d}" for j in range(wrap.links)]
    sprocket, links = assembly.parts[0], assembly.parts[1:]
    assert sprocket.solid == "sprocket" and sprocket.material == "7075-T651 aluminium alloy"
    assert sprocket.color == (0.75, 0.75, 0.8) and sprocket.features == ()
    assert sprocket.motion == Rotation.about((0, 0, 1), (0, 0, 0))
    assert np.array_equal(sprocket.pose, tc.sprocket_matrix(0.0))
    poses = wrap.link_matrices(0.0)
    for j, link in enumerate(links):
        assert link.solid == "link" and link.material == "cast aluminium track link with steel sleeve"
        assert link.color == (0.3, 0.3, 0.35) and link.features == ("plate", "sleeve")
        assert link.motion == ChainLink(j) and np.array_equal(link.pose, poses[j])
    assert isinstance(assembly.solids["sprocket"], SprocketSpec)
    assert assembly.solids["link"] == assembly.layout.link and assembly.layout.wrap == wrap
    assert assembly.solids["sprocket"].gap.pitch_radius_mm == pytest.approx(wrap.pin_radius_mm, abs=1e-12)


@pytest.mark.cad
def test_cad_module_imports_no_mechanism():
    """Solids are built from data specs: gearcheck.cad.sprocket never imports a mechanism."""
    import subprocess
    import sys

    code = ("import sys, gearcheck.cad.sprocket; "
            "sys.exit(any(m.startswith('gearcheck.mechanisms') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


# ---------------------------------------------------------------- solids (CadQuery / OCP)

def _distance(a, b):
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape

    d = BRepExtrema_DistShapeShape(a.wrapped, b.wrapped)
    d.Perform()
    assert d.IsDone()
    p1, p2 = d.PointOnShape1(1), d.PointOnShape2(1)
    return d.Value(), np.array([p1.X(), p1.Y(), p1.Z()]), np.array([p2.X(), p2.Y(), p2.Z()])


def _overlap_volume(a, b):
    return a.intersect(b).Volume()


def _cylinders(shape):
    """(radius, axis point (x, y), axis direction, face) of every cylindrical face."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cylinder

    out = []
    for f in shape.Faces():
        a = BRepAdaptor_Surface(f.wrapped)
        if a.GetType() == GeomAbs_Cylinder:
            c = a.Cylinder()
            loc, d = c.Location(), c.Axis().Direction()
            out.append((c.Radius(), np.array([loc.X(), loc.Y()]), np.array([d.X(), d.Y(), d.Z()]), f))
    return out


def place(shape, matrix):
    from gearcheck.cad.placement import place as _place

    return _place(shape, matrix)


def _shift(matrix, dx, dy):
    m = matrix.copy()
    m[0, 3] += dx
    m[1, 3] += dy
    return m


@pytest.fixture(scope="module")
def built(params):
    """The mechanism's own composition: ``assembly()`` (data) then ``parts()`` (its CAD hook)."""
    import time
    from types import SimpleNamespace

    from gearcheck.cad.sprocket import LinkSolids
    from gearcheck.mechanism import get

    impl = get("track")
    assembly = impl.assembly(params)
    t0 = time.perf_counter()
    built_parts = impl.parts(assembly)
    build_s = time.perf_counter() - t0
    sprocket, links = built_parts[0], built_parts[1:]
    first = links[0]
    parts = SimpleNamespace(
        assembly=assembly, parts=built_parts, sprocket=sprocket, links=links,
        link_solids=LinkSolids(first.solid, first.features["plate"], first.features["sleeve"]),
        sprocket_spec=assembly.solids["sprocket"], link_geometry=assembly.solids["link"],
        seated_links=lambda: assembly.layout.wrap.seated_links(0.0), build_s=build_s)
    return parts, parts.sprocket.placed()


@pytest.mark.cad
def test_every_solid_is_valid(built):
    parts, _ = built
    for s in (parts.link_solids.link, parts.link_solids.plate, parts.link_solids.sleeve):
        assert s.isValid()
    for part in parts.parts:
        assert part.placed().isValid() and len(part.solid.Solids()) == 1, part.name
    assert parts.build_s < 10.0  # sprocket and link together
    # parts in the assembly's order, posed as its specs say; one link solid (and its features) shared
    assert [p.name for p in parts.parts] == parts.assembly.names
    for part, spec in zip(parts.parts, parts.assembly.parts, strict=True):
        assert np.array_equal(part.pose, spec.pose) and part.material == spec.material and part.color == spec.color
        assert part.motion == spec.motion and set(part.features) == set(spec.features)
    for part in parts.links:
        assert part.solid is parts.link_solids.link
        assert part.features["plate"] is parts.link_solids.plate and part.features["sleeve"] is parts.link_solids.sleeve
    assert parts.sprocket.features == {}


@pytest.mark.cad
def test_tooth_count_on_the_solid(built, params):
    """Count the tooth sections a circle between pitch and tip circle cuts out of each row
    (its seam at +x lies in groove 0, so no tooth is split), and the tip-land faces."""
    import cadquery as cq

    parts, _ = built
    spec, s = parts.sprocket_spec, parts.sprocket.solid
    z = params.sprocket.teeth
    r = (spec.gap.pitch_radius_mm + spec.gap.tip_radius_mm) / 2
    for z0, z1 in spec.row_z_ranges():
        circle = cq.Edge.makeCircle(r, cq.Vector(0, 0, (z0 + z1) / 2), cq.Vector(0, 0, 1))
        assert len(s.intersect(circle).Edges()) == z
    lands = [(rad, f) for rad, c, _, f in _cylinders(s) if np.hypot(*c) < 1e-9 and rad > spec.gap.pitch_radius_mm]
    assert len(lands) == z * params.sprocket.tooth_rows
    angles = sorted(math.atan2(f.Center().y, f.Center().x) % (2 * math.pi) for _, f in lands
                    if f.Center().z > 0)
    assert np.diff(angles) == pytest.approx(2 * math.pi / z, abs=1e-9)  # evenly spaced, none missing


@pytest.mark.cad
def test_seating_radius_and_angle_measured_inside_iso_limits(built, params):
    parts, _ = built
    sp, dr = params.sprocket, params.chain.sleeve_diameter_mm
    lim = iso606.seating_limits(dr, sp.teeth)
    s = parts.sprocket.solid
    rp = parts.sprocket_spec.gap.pitch_radius_mm
    seats = [(rad, c, f) for rad, c, _, f in _cylinders(s) if abs(np.hypot(*c) - rp) < 1e-6]
    assert len(seats) == sp.teeth * sp.tooth_rows
    # flank arcs: the remaining cylinders off the axis (their centres lie beyond the next tooth)
    flanks = [rad for rad, c, _, _ in _cylinders(s) if np.hypot(*c) > 1e-9 and abs(np.hypot(*c) - rp) > 1e-6]
    assert len(flanks) == 2 * sp.teeth * sp.tooth_rows
    for rad in flanks:
        assert lim.flank_radius_min_mm <= rad <= lim.flank_radius_max_mm
    angles = []
    for rad, c, f in seats:
        assert lim.seating_radius_min_mm <= rad <= lim.seating_radius_max_mm
        assert rad == pytest.approx(sp.seating_radius_mm, abs=EXACT_MM)
        # the seating arc's ends (flank junctions) at one end plane, seen from the seating centre
        v = [np.array(p.toTuple()) for p in f.Vertices()]
        zmin = min(p[2] for p in v)
        ends = [p[:2] - c for p in v if abs(p[2] - zmin) < 1e-9]
        assert len(ends) == 2
        cosang = ends[0] @ ends[1] / (np.linalg.norm(ends[0]) * np.linalg.norm(ends[1]))
        angles.append(math.degrees(math.acos(cosang)))
    assert lim.seating_angle_min_deg <= min(angles) and max(angles) <= lim.seating_angle_max_deg
    assert np.array(angles) == pytest.approx(sp.seating_angle_deg, abs=1e-6)


@pytest.mark.cad
def test_chord_between_seated_sleeve_centres(built, params):
    parts, placed_sprocket = built
    seated = parts.seated_links()
    centres = []
    for part in parts.links:
        sleeve = place(parts.link_solids.sleeve, part.pose)
        (axis,) = [c for _, c, _, _ in _cylinders(sleeve)]
        centres.append(axis)
    groove_axes = [c for rad, c, _, _ in _cylinders(placed_sprocket)
                   if abs(rad - params.sprocket.seating_radius_mm) < 1e-6]
    for j in np.flatnonzero(seated):
        chord = np.linalg.norm(centres[j + 1] - centres[j])
        assert chord == pytest.approx(params.chain.pitch_mm, abs=ACCEPT_MM)
        assert chord == pytest.approx(params.chain.pitch_mm, abs=1e-9)  # in fact exact: d = p/sin(360°/z)
        # a seated sleeve is coaxial with a groove's seating arc
        assert min(np.linalg.norm(g - centres[j]) for g in groove_axes) < EXACT_MM


def _assert_contact_from_both_sides(sprocket, solid, pose, direction, clearance):
    """Moved ``clearance`` + PAST_CONTACT_MM along ``direction`` the solid cuts the sprocket; moved
    ``clearance`` − PAST_CONTACT_MM it clears by PAST_CONTACT_MM: the clearance is where contact is."""
    past = place(solid, _shift(pose, *((clearance + PAST_CONTACT_MM) * direction)))
    assert _overlap_volume(sprocket, past) > 0
    short = place(solid, _shift(pose, *((clearance - PAST_CONTACT_MM) * direction)))
    assert _distance(sprocket, short)[0] == pytest.approx(PAST_CONTACT_MM, abs=EXACT_MM)


@pytest.mark.cad
def test_seated_tip_to_plate_gap_is_the_templates(built, params):
    """Exact distance sprocket ↔ plate of every seated link = template tip gap; the nearest point is
    a tip corner under the plate's inner face. Pushed gap + 0.02 towards the axis the plate cuts the
    tooth; gap − 0.02, it clears by 0.02 (contact from both sides)."""
    parts, sprocket = built
    tp = params.track_plate
    r_tip = parts.sprocket_spec.gap.tip_radius_mm
    geo = parts.link_geometry
    seated = np.flatnonzero(parts.seated_links())
    for j in seated:
        pose = parts.links[j].pose
        plate = place(parts.link_solids.plate, parts.links[j].pose)
        gap, on_sprocket, on_plate = _distance(sprocket, plate)
        assert gap == pytest.approx(tp.tip_gap_mm, abs=ACCEPT_MM)
        assert tp.required_gap_min_mm <= gap <= tp.required_gap_max_mm
        assert np.hypot(*on_sprocket[:2]) == pytest.approx(r_tip, abs=EXACT_MM)
        local = np.linalg.inv(pose) @ np.append(on_plate, 1.0)
        assert local[1] == pytest.approx(geo.plate_offset_mm, abs=EXACT_MM)  # on the inner face
        assert geo.plate_start_x_mm < local[0] < geo.plate_end_x_mm
    j = seated[len(seated) // 2]
    pose = parts.links[j].pose
    inward = -pose[:2, 1]  # the link's −y axis, towards the sprocket
    _assert_contact_from_both_sides(sprocket, parts.link_solids.plate, pose, inward, tp.tip_gap_mm)


@pytest.mark.cad
def test_seated_sleeve_clearance_at_the_seating_bottom(built, params):
    """Seated sleeve ↔ sprocket: exact distance ri − R (theory 4.1 − 4 = 0.1 mm). Pushed towards the
    axis by that + 0.02 it cuts the seating arc; by that − 0.02 it clears by 0.02."""
    parts, sprocket = built
    theory = params.sprocket.seating_radius_mm - params.chain.sleeve_diameter_mm / 2
    seated = np.flatnonzero(parts.seated_links())
    for j in seated:
        sleeve = place(parts.link_solids.sleeve, parts.links[j].pose)
        clearance, on_sprocket, _ = _distance(sprocket, sleeve)
        assert clearance == pytest.approx(theory, abs=EXACT_MM)
    j = seated[len(seated) // 2]
    pose = parts.links[j].pose
    radial = -pose[:2, 3] / np.linalg.norm(pose[:2, 3])  # from the pin towards the sprocket axis
    _assert_contact_from_both_sides(sprocket, parts.link_solids.sleeve, pose, radial, theory)


@pytest.mark.cad
def test_no_part_interferes_at_the_nominal_pose(built, params):
    """Every link (seated or on a run) clears the sprocket, by no less than a seated sleeve's
    ri − R; each sleeve clears the previous link's plate by the designed clearance (independent of
    the joint angle: it turns about that pin); adjacent plates do not touch."""
    parts, sprocket = built
    seat_clearance = params.sprocket.seating_radius_mm - params.chain.sleeve_diameter_mm / 2
    for part in parts.links:
        assert _distance(sprocket, part.placed())[0] >= seat_clearance - EXACT_MM, part.name
    expected = parts.link_geometry.sleeve_plate_clearance_mm()
    poses = [p.pose for p in parts.links]
    for j in range(len(poses) - 1):
        sleeve_next = place(parts.link_solids.sleeve, poses[j + 1])
        plate = place(parts.link_solids.plate, poses[j])
        plate_next = place(parts.link_solids.plate, poses[j + 1])
        assert _distance(plate, sleeve_next)[0] == pytest.approx(expected, abs=EXACT_MM)
        assert _distance(plate, plate_next)[0] > 0.5
