"""Hand-overs between tooth pairs: the conjugate contact intervals measured on mesh-like outlines
(vertices on the exact flanks, ~1 mm chords, like the built meshes) against the exact intervals of
``geometry/rack_pinion_contact.py`` — and why the rack's lag behind r·φ cannot show a hand-over
gap, which the contact positions do.

The numpy tests build the outlines from the drawing (no CAD); the check at the end sweeps the
built meshes of the design with a 0.11° gap between G2's and G1's towing contact.
"""

import math

import numpy as np
import pytest

import gearcheck
from gearcheck.geometry.rack_pinion import pinion_local_xy, pinion_pose, pinion_tooth_pieces
from gearcheck.geometry.rack_pinion_contact import continuous_drive, whole_drive
from gearcheck.geometry.rack_pinion_mesh import contact_run, fit_involute
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import handover as ho

TEMPLATE = "nose_wheel_steering"
HANDOVER_GAP = ["trim.hS2_mm=24.1", "trim.hS6_mm=24.6", "targets.continuous_drive_deg=60.5"]
# Contact ends on mesh-like outlines (exact vertices, the rack at r·φ) against the exact intervals:
# the involute through the vertices is the flank, so only round-off is left (measured ≤ 1e-6°).
EVENT_TOL_DEG = 1e-3
# On the swept meshes the rack travel is the meshes' push, behind the exact one by up to the chord
# sag (µm): a few thousandths of a degree at the rack corners (measured ≤ 0.0006°).
SWEPT_TOL_DEG = 0.005
# Flank points per involute: ~1 mm chords on the template's ~9 mm flanks, like the 0.01 mm meshes.
FLANK_POINTS = 10


def _geometry(templates_dir, overrides=()):
    return an.geometry_from_params(gearcheck.load(templates_dir / f"{TEMPLATE}.toml", list(overrides)).params)


def _outline(g):
    """The sector's outline as a mesh has it: exact points of every tooth piece (own frame, ordered
    by polar angle), ~1 mm apart on the flanks; the tip lands as a few points."""
    pts = []
    for j in range(g.sector_first_tooth, g.sector_last_tooth + 1):
        for piece in pinion_tooth_pieces(g, j, FLANK_POINTS, 6):
            rho, gam = piece.rho, piece.gamma
            if piece.kind == "tip":  # the arc: 6 chords
                gam = np.linspace(gam[0], gam[-1], 7)
                rho = np.full(7, rho[0])
            pts.append(pinion_local_xy(rho, gam + (j + 0.5) * g.angular_pitch))
    pts = np.unique(np.round(np.concatenate(pts), 12), axis=0)
    gamma = np.arctan2(pts[:, 0], -pts[:, 1])
    return pts[np.argsort(gamma)]


def _rack_points(g):
    return np.concatenate([g.rack_tooth_polygon(k, 0.0) for k in range(g.rack_first_tooth, g.rack_last_tooth + 1)])


def _drive(g, mode, direction, step_deg=0.25, travel=None):
    """The mesh-like drive along a conjugate swing (rack at r·φ unless ``travel`` is given)."""
    pairs = ho.flank_pairs(g, _outline(g), _rack_points(g), np.eye(4), mode, direction)
    grid = np.arange(0.0, 70.0, step_deg)
    mag = np.radians(np.unique(np.concatenate([grid, ho.extra_angles_deg(g, mode, 70.0)])))
    angles = direction * mag
    travels = g.pitch_radius * angles if travel is None else travel(angles)
    poses = np.array([pinion_pose(g, float(a)) for a in angles])
    measured, covered = ho.measured_pairs(g, mode, pairs, angles, travels, poses, np.array([1.0, 0.0, 0.0]))
    return ho.mesh_drive(g, mode, direction, measured, angles, covered)


# ----------------------------------------------------------------------------- numpy only

@pytest.mark.parametrize("side", [+1, -1])
def test_involute_read_from_its_vertices(side):
    """A few unevenly spaced exact points of an involute (like a short flank's mesh vertices, 0.25 to
    0.9 mm apart, near a base circle of 44.6 mm): the fit recovers its base radius and start angle,
    so the tangent — which turns exactly with the roll angle — is found where the vertices give no
    chord parallel to it, and beyond the last vertex. Points of a circle are not an involute: the
    residual says so."""
    base, start = 44.6237, 0.3
    u = np.array([0.095, 0.15, 0.2, 0.28, 0.31, 0.339])
    rho = base * np.sqrt(1.0 + u * u)
    gamma = start - side * (u - np.arctan(u))
    chain = np.stack([rho * np.sin(gamma), -rho * np.cos(gamma)], axis=1)
    f = fit_involute(chain, side)
    assert f.base_radius == pytest.approx(base, abs=1e-9) and f.start_angle == pytest.approx(start, abs=1e-12)
    assert f.residual_mm < 1e-9 and f.u_corner == pytest.approx(0.339, abs=1e-9)
    for target in (0.12, 0.339, 0.37):  # inside, at the tip corner, beyond it
        tangent = start - math.pi / 2 - side * target  # the tangent's direction there
        normal = np.array([[-math.sin(tangent), math.cos(tangent)]])
        assert f.tangency_roll(normal)[0] == pytest.approx(target, abs=1e-12)
        assert f.tangency_roll(-normal)[0] == pytest.approx(target, abs=1e-12)  # either sense of the normal
        # the exact point: finite differences along the exact involute agree with that tangent
        a, b = f.points(np.array([target - 1e-6, target + 1e-6]))
        d = (b - a) / np.linalg.norm(b - a)
        assert abs(d @ normal[0]) < 1e-6
    # the osculating circle at roll 0.2 (centre on the base circle, radius base·u) through the same
    # span: agrees with the involute to second order, yet its points are off it by microns
    u_m = 0.2
    p_m = f.points(np.array([u_m]))[0]
    theta = start - math.pi / 2 - side * u_m
    n = np.array([-math.sin(theta), math.cos(theta)])
    centre = min((p_m + sign * base * u_m * n for sign in (1.0, -1.0)), key=lambda c: abs(np.hypot(*c) - base))
    assert np.hypot(*centre) == pytest.approx(base, abs=1e-9)
    a0 = math.atan2(p_m[1] - centre[1], p_m[0] - centre[0])
    span = a0 + np.linspace(-0.06, 0.06, 6)
    arc = centre + base * u_m * np.stack([np.cos(span), np.sin(span)], axis=1)
    if np.hypot(*arc[0]) > np.hypot(*arc[-1]):
        arc = arc[::-1]  # inner → outer, as a flank chain
    assert fit_involute(arc, side).residual_mm > 1e-4


def test_contact_run_interpolates_the_deciding_margin():
    angles = np.linspace(0.0, 1.0, 11)
    margins = np.stack([0.55 - angles, angles - 0.22, np.full(11, 1.0), np.full(11, 1.0)], axis=1)
    start, end, by_start, by_end = contact_run(angles, margins)
    assert start == pytest.approx(0.22) and end == pytest.approx(0.55)
    assert (by_start, by_end) == (1, 0)
    assert contact_run(angles, -np.ones((11, 4))) is None


@pytest.mark.parametrize("direction", [+1, -1])
def test_mesh_like_outline_finds_the_handover_gap(templates_dir, direction):
    """hS2 lowered to 24.1 mm: G1's towing contact begins at S2 0.11° after G2's ends at its tip
    corner. Measured on the mesh-like outlines the same gap opens, within the tolerance at both ends,
    and the poses added inside it have no pair in conjugate contact."""
    g = _geometry(templates_dir, HANDOVER_GAP[:2])
    exact = continuous_drive(g, "towing")
    a, b = (math.degrees(x) for x in exact.gap_rad)
    assert b - a == pytest.approx(0.111, abs=2e-3)
    mesh = _drive(g, "towing", direction)
    assert mesh.gap_deg is not None, mesh.event
    assert mesh.gap_deg[0] == pytest.approx(a, abs=EVENT_TOL_DEG)
    assert mesh.gap_deg[1] == pytest.approx(b, abs=EVENT_TOL_DEG)
    assert "hand-over gap G2→G1" in mesh.event and "at S3" in mesh.event and "begins at S2" in mesh.event
    assert mesh.gap_poses >= 3
    assert mesh.max_deviation_deg <= EVENT_TOL_DEG


def test_the_gap_is_found_on_a_coarse_grid_too(templates_dir):
    """The contact ends come from margins that change sign between poses, not from a pose inside the
    gap: 2° steps (no pose added) still find it."""
    g = _geometry(templates_dir, HANDOVER_GAP[:2])
    pairs = ho.flank_pairs(g, _outline(g), _rack_points(g), np.eye(4), "towing", 1)
    angles = np.radians(np.arange(0.0, 70.0, 2.0))
    poses = np.array([pinion_pose(g, float(x)) for x in angles])
    measured, _ = ho.measured_pairs(g, "towing", pairs, angles, g.pitch_radius * angles, poses, np.array([1.0, 0, 0]))
    mesh = ho.mesh_drive(g, "towing", 1, measured)
    exact = continuous_drive(g, "towing")
    assert mesh.gap_deg is not None
    assert mesh.gap_deg[0] == pytest.approx(math.degrees(exact.gap_rad[0]), abs=EVENT_TOL_DEG)


def test_mesh_like_outline_matches_the_template_drive(templates_dir):
    """The template: no gap; towing ends where G1's contact reaches S1, power where the first rack
    tooth's contact reaches S6, both within the tolerance of the exact model, in both directions."""
    g = _geometry(templates_dir)
    towing, power = whole_drive(g)
    for direction in (+1, -1):
        for mode, exact in (("towing", towing), ("power", power)):
            mesh = _drive(g, mode, direction)
            assert mesh.gap_deg is None, mesh.event
            assert mesh.angle_deg == pytest.approx(exact.angle_deg, abs=EVENT_TOL_DEG), (mode, direction)
            assert mesh.max_deviation_deg <= EVENT_TOL_DEG
    assert "S1" in _drive(g, "towing", 1).event and "S6" in _drive(g, "power", 1).event


def test_the_lag_behind_r_phi_cannot_show_the_gap(templates_dir):
    """Why the contact positions: through the 0.11° gap G2's tip corner drags the rack on, which
    falls behind r·φ by well under a µm (the exact push model, 0.001° steps) — a contact tolerance
    of 0.02 mm, or any mesh, cannot see that."""
    g = _geometry(templates_dir, HANDOVER_GAP[:2])
    a, b = continuous_drive(g, "towing").gap_rad
    phis = np.linspace(a - 1e-3, b + 1e-3, 200)
    push = an.sweep(g, phis, g.pitch_radius * phis[0], +1)
    lag = g.pitch_radius * phis - push.travel_mm
    assert np.max(np.abs(lag)) < 1e-3  # mm: under a µm
    # and the rack never stops: no turning freely either
    assert np.all(np.diff(push.travel_mm) > 0.0)


def test_extra_poses_only_at_tight_handovers(templates_dir):
    """Poses are added around the hand-overs the model finds tight (G2→G1 on the gap design, the
    trimmed end on the template) and the limit, not around the inner pairs' 4° overlaps."""
    g = _geometry(templates_dir, HANDOVER_GAP[:2])
    extra = ho.extra_angles_deg(g, "towing", 100.0)
    a, b = (math.degrees(x) for x in continuous_drive(g, "towing").gap_rad)
    assert any(a < x < b for x in extra)
    assert min(extra) > 40.0 and len(extra) <= 30


# ----------------------------------------------------------------------------- the check

@pytest.mark.cad
def test_the_sweep_sees_the_handover_gap(templates_dir, tmp_path):
    """The whole check on the built meshes: the mesh sweep finds the gap in both directions by
    itself (its figure alone is short of the target), beside the exact model's; the verdict names
    the event and rests on both."""
    design = gearcheck.load(templates_dir / f"{TEMPLATE}.toml", HANDOVER_GAP)
    run = design.check(out=tmp_path, jobs=2)
    v = next(x for x in run.result.verdicts if x.name == "continuous_drive")
    g = an.geometry_from_params(design.params)
    exact = continuous_drive(g, "towing")
    a, b = (math.degrees(x) for x in exact.gap_rad)
    s = run.summary["steering"]
    for side in (s, s["minus"]):
        gap = side["geom_towing_gap_deg"]
        assert gap[0] == pytest.approx(a, abs=SWEPT_TOL_DEG) and gap[1] == pytest.approx(b, abs=SWEPT_TOL_DEG)
        assert side["geom_towing_gap_poses"] >= 3
        assert side["geom_towing_drive_deg"] < design.params.targets.continuous_drive_deg
    assert not v.passed
    assert v.figures["mesh_deg"] < v.figures["target_deg"] and v.figures["model_deg"] < v.figures["target_deg"]
    assert v.figures["model_deg"] == pytest.approx(a, abs=1e-6)
    assert "hand-over gap G2→G1" in v.measured and "exact model: towing 60.073°" in v.measured
    assert v.evidence.startswith("exact model and mesh sweep")
    assert s["max_handover_deviation_deg"] <= SWEPT_TOL_DEG and s["max_flank_fit_residual_mm"] < 1e-5
