"""Spherical-involute straight bevel mathematics (numpy only, no CAD)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry.bevel_volume import analytic_volume_mm3
from gearcheck.geometry.bevel import (BevelGearSpec, flank_azimuth,
                                      flank_directions, flank_distance, gleason_profile_shift,
                                      involute_azimuth, line_of_action, mate_rotation,
                                      mating_spec, pitch_cone_tooth_thickness,
                                      roll_angle_at_polar, section_profile, spherical_involute)
from gearcheck.geometry.involute import inv

PINION = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0,
                       profile_shift=0.39, bore_mm=10.0)
GEAR = mating_spec(PINION, bore_mm=20.0)
BOTH = pytest.mark.parametrize("spec", [PINION, GEAR], ids=["z13", "z33"])


def _rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# -- cones --------------------------------------------------------------------------------
@pytest.mark.parametrize("z1,z2,sigma", [(13, 33, 90.0), (20, 20, 90.0), (15, 40, 70.0),
                                         (20, 25, 110.0)])
def test_pitch_cones_roll_on_each_other(z1, z2, sigma):
    a = BevelGearSpec(teeth=z1, mate_teeth=z2, module_mm=2.0, face_width_mm=8.0,
                      shaft_angle_deg=sigma)
    b = mating_spec(a)
    assert math.degrees(a.pitch_angle_rad + b.pitch_angle_rad) == pytest.approx(sigma, abs=1e-12)
    # one outer cone distance for both (sine rule on the pitch cones)
    assert a.outer_cone_distance_mm == pytest.approx(b.outer_cone_distance_mm, rel=1e-14)
    # the pitch circles have the ratio of the tooth counts (same module)
    assert a.outer_pitch_diameter_mm / b.outer_pitch_diameter_mm == pytest.approx(z1 / z2)


def test_differential_pair_cones():
    # docs/differential.md: δ = atan(33/13) ≈ 68.5°, Re = 44.34 mm, d = 32.5 / 82.5 mm
    assert math.degrees(PINION.pitch_angle_rad) == pytest.approx(21.50, abs=0.01)
    assert math.degrees(GEAR.pitch_angle_rad) == pytest.approx(68.50, abs=0.01)
    assert PINION.outer_cone_distance_mm == pytest.approx(44.34, abs=0.005)
    assert PINION.virtual_teeth == pytest.approx(13.97, abs=0.01)
    assert GEAR.outer_pitch_diameter_mm == 82.5


def test_gleason_rule():
    # 0.46·(1 − (13/33)²) = 0.389; the tests use ±0.39
    assert gleason_profile_shift(13, 33) == pytest.approx(0.3886, abs=1e-4)
    assert gleason_profile_shift(20, 20) == 0.0


# -- spherical involute -------------------------------------------------------------------
def test_spherical_involute_rolls_without_slip():
    db = 0.9
    phi = np.linspace(0.0, 1.2, 50)
    u = spherical_involute(db, phi)
    assert np.allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-15)
    tangency = np.stack([np.sin(db) * np.cos(phi), np.sin(db) * np.sin(phi),
                         np.full_like(phi, np.cos(db))], -1)
    # the unrolled arc from the tangency point T equals the base-circle arc φ·sin δb
    arc = np.arccos(np.clip(np.einsum("ij,ij->i", u, tangency), -1, 1))
    assert np.allclose(arc, phi * np.sin(db), atol=1e-7)
    # the generating great circle (through T and u) is tangent to the base circle at T: its
    # plane contains T's base-circle tangent t, i.e. its normal T × u is perpendicular to t
    t_base = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)], -1)
    plane_normal = np.cross(tangency[1:], u[1:])
    assert np.allclose(np.einsum("ij,ij->i", plane_normal, t_base[1:]), 0, atol=1e-14)
    # ... and it is the curve normal: du/dφ is perpendicular to T and to u (so to its plane)
    h = 1e-6
    du = (spherical_involute(db, phi[1:] + h) - spherical_involute(db, phi[1:] - h)) / (2 * h)
    assert np.allclose(np.einsum("ij,ij->i", du, tangency[1:]), 0, atol=1e-8)
    assert np.allclose(np.einsum("ij,ij->i", du, u[1:]), 0, atol=1e-8)
    # polar angle: cos θ = cos δb · cos(φ sin δb), and the inverse
    theta = np.arccos(u[:, 2])
    assert np.allclose(roll_angle_at_polar(db, theta), phi, atol=1e-7)
    assert np.allclose(involute_azimuth(db, theta), np.arctan2(u[:, 1], u[:, 0]), atol=1e-12)


def test_spherical_involute_tends_to_the_plane_involute_near_the_pole():
    # a tiny base circle (radius δb on the sphere ≈ plane): η(θ) → inv(arccos(δb/θ))
    db = 1e-4
    theta = db * np.array([1.05, 1.3, 1.8, 2.5])
    assert np.allclose(involute_azimuth(db, theta), inv(np.arccos(db / theta)), rtol=1e-6)


@BOTH
def test_pressure_angle_at_the_pitch_cone(spec):
    # measured on the curve: the angle between the flank tangent and the meridian at the pitch
    # point is the pressure angle (this is what sin δb = sin δ cos α encodes)
    db = spec.base_angle_rad
    phi = float(roll_angle_at_polar(db, spec.pitch_angle_rad))
    h = 1e-7
    u = spherical_involute(db, phi)
    t = spherical_involute(db, phi + h) - spherical_involute(db, phi - h)
    t /= np.linalg.norm(t)
    a = math.atan2(u[1], u[0])
    e_azimuth = np.array([-math.sin(a), math.cos(a), 0.0])
    angle = math.acos(abs(t @ e_azimuth))  # tangent vs circumference = 90° − α
    assert math.degrees(math.pi / 2 - angle) == pytest.approx(spec.pressure_angle_deg, abs=1e-6)


# -- tooth thickness -----------------------------------------------------------------------
def test_tooth_thickness_on_the_pitch_cone():
    m, a = 2.5, math.radians(20)
    re = PINION.outer_cone_distance_mm
    assert pitch_cone_tooth_thickness(PINION, re) == pytest.approx(
        m * (math.pi / 2 + 2 * 0.39 * math.tan(a)))
    # the flanks cross the pitch cone at ±half that thickness
    half = float(flank_azimuth(PINION, PINION.pitch_angle_rad, +1))
    assert 2 * half * re * math.sin(PINION.pitch_angle_rad) == pytest.approx(
        float(pitch_cone_tooth_thickness(PINION, re)), rel=1e-13)
    # tapers to the apex
    assert pitch_cone_tooth_thickness(PINION, 0.5 * re) == pytest.approx(
        0.5 * pitch_cone_tooth_thickness(PINION, re))


@pytest.mark.parametrize("thinning", [0.0, 0.04])
def test_pair_thicknesses_fill_the_circular_pitch(thinning):
    p = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0,
                      profile_shift=0.39, thinning_mm=thinning)
    g = mating_spec(p)
    for r in (p.outer_cone_distance_mm, p.inner_cone_distance_mm):
        pitch = 2 * math.pi * r * math.sin(p.pitch_angle_rad) / p.teeth
        both = pitch_cone_tooth_thickness(p, r) + pitch_cone_tooth_thickness(g, r)
        # x1 + x2 = 0: zero backlash but for the thinning (which tapers like the tooth)
        assert both == pytest.approx(pitch - 2 * thinning * r / p.outer_cone_distance_mm,
                                     abs=1e-12)


def test_no_pointed_teeth_and_positive_root_space():
    for spec in (PINION, GEAR):
        assert spec.tip_land_angle_rad * spec.outer_cone_distance_mm > 0.25 * spec.module_mm
        assert spec.root_space_angle_rad > 0
    with pytest.raises(ValueError, match="pointed"):
        BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0,
                      profile_shift=1.0)


# -- undercut and contact -----------------------------------------------------------------
def test_profile_shift_avoids_undercut_of_the_13_tooth_pinion():
    # x = 0: the gear's tip reaches past the pinion's base tangency point (zv 13.97 < 17)
    bare = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0)
    assert not line_of_action(bare).interference_free
    assert line_of_action(bare).start_arc < 0
    # x = +0.39: contact starts on the involute, above the base cone (radial root unused)
    loa = line_of_action(PINION)
    assert loa.interference_free
    assert loa.start_polar_rad(PINION) > PINION.base_angle_rad
    assert line_of_action(GEAR).interference_free


def test_contact_ratio_is_the_same_seen_from_either_gear():
    a, b = line_of_action(PINION), line_of_action(GEAR)
    assert a.contact_ratio == pytest.approx(b.contact_ratio, rel=1e-12)
    assert 1.2 < a.contact_ratio < 2.0  # a working straight bevel pair
    assert a.base_pitch_arc == pytest.approx(b.base_pitch_arc, rel=1e-12)


def _gaps(driver, driven, samples=600, poses=24):
    """Per pose (over one driver tooth pitch): the smallest signed distance (+ = clear) of the
    driven gear's flank points from the driver's flanks, and of the driver's from the driven
    gear's, at the outer end. Only points within the other gear's root…tip cone band count."""
    re = driver.outer_cone_distance_mm
    out = []
    for angle in np.linspace(0.0, driver.angular_pitch_rad, poses, endpoint=False):
        rot = mate_rotation(driver, angle, driven)
        worst = np.inf
        for a, b, r in ((driver, driven, rot), (driven, driver, rot.T)):
            pts = np.concatenate([
                (flank_directions(b, side, samples) @ _rot_z(k * b.angular_pitch_rad).T)
                for k in range(b.teeth) for side in (-1, 1)]) * re
            q = pts @ r.T  # into a's frame
            theta = np.arctan2(np.hypot(q[:, 0], q[:, 1]), q[:, 2])
            near = (theta >= a.root_angle_rad) & (theta <= a.face_angle_rad)
            worst = min(worst, flank_distance(a, q[near], signed=True).min())
        out.append(worst)
    return np.array(out)


def test_pair_is_conjugate_with_zero_backlash():
    # Contact at every pose, overlap at none: the discretisation (600 points per flank) leaves
    # a second-order gap ≲ 1e-5 mm at the nearest sample.
    gaps = _gaps(PINION, GEAR)
    assert gaps.min() > -1e-9
    assert gaps.max() < 2e-5


def test_thinning_opens_the_normal_backlash():
    # jn = (j1 + j2)·cos α at the outer end (normal gap along the great circle of action);
    # centred mounting splits it equally between the two flanks of a tooth
    p = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0,
                      profile_shift=0.39, thinning_mm=0.02)
    gaps = _gaps(p, mating_spec(p, thinning_mm=0.03))
    assert np.allclose(gaps, 0.05 * math.cos(math.radians(20)) / 2, atol=2e-5)


def test_unshifted_pinion_interferes():
    # the other side of the undercut check: with x = 0 the gear tip digs into the pinion root
    bare = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0)
    assert _gaps(bare, mating_spec(bare), samples=200).min() < -1e-3


# -- sections -------------------------------------------------------------------------------
@BOTH
def test_section_points_lie_on_the_flank_cones(spec):
    z = 30.0
    prof = section_profile(spec, z, flank_points=40)
    pts = np.concatenate([np.c_[s.points, np.full(len(s.points), z)]
                          for s in prof.segments if s.kind in ("flank", "radial")])
    assert flank_distance(spec, pts).max() < 1e-12 * z
    kinds = [s.kind for s in prof.segments]
    assert kinds.count("tip") == kinds.count("root") == spec.teeth
    assert kinds.count("flank") == 2 * spec.teeth
    radial = spec.root_angle_rad < spec.base_angle_rad
    assert kinds.count("radial") == (2 * spec.teeth if radial else 0)
    for s in prof.segments:
        if s.kind in ("tip", "root"):
            angle = spec.face_angle_rad if s.kind == "tip" else spec.root_angle_rad
            assert np.allclose(np.hypot(*s.points.T), z * math.tan(angle), rtol=1e-14)


@BOTH
def test_section_outline_is_closed_and_counter_clockwise(spec):
    prof = section_profile(spec, 25.0, flank_points=400)
    segs = prof.segments
    for a, b in zip(segs, segs[1:] + segs[:1], strict=True):
        assert np.array_equal(a.points[-1], b.points[0])
    poly = prof.polyline(arc_points=2001)
    x, y = poly.T
    area = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    # the area equals ∫ 2π ρ · (fraction of the circle in material) dρ (no fold, no overlap)
    z = 25.0
    rho = np.linspace(0, z * math.tan(spec.face_angle_rad), 200001)
    theta = np.arctan2(rho, z)
    frac = np.where(theta < spec.root_angle_rad, 1.0,
                    spec.teeth * 2 * flank_azimuth(spec, theta, 1) / (2 * math.pi))
    # (polyline chords and the trapezoid rule: ~1e-6 relative)
    assert area == pytest.approx(np.trapezoid(2 * math.pi * rho * frac, rho), rel=1e-5)


def test_sections_are_homothetic_about_the_apex():
    a, b = section_profile(GEAR, 12.0), section_profile(GEAR, 30.0)
    for sa, sb in zip(a.segments, b.segments, strict=True):
        assert np.allclose(sb.points, sa.points * 2.5, rtol=0, atol=1e-12)


def test_sector_profile_is_tooth_zero():
    full = section_profile(PINION, 30.0)
    sector = section_profile(PINION, 30.0, sector=True)
    assert [s.kind for s in sector.segments] == ["side", "root"] + \
        [s.kind for s in full.segments[:5]] + ["root", "side"]
    for s, f in zip(sector.segments[2:7], full.segments[:5], strict=True):
        assert np.allclose(s.points, f.points, atol=1e-13)
    half = math.pi / PINION.teeth
    assert math.atan2(*sector.segments[0].points[1][::-1]) == pytest.approx(-half)
    assert math.atan2(*sector.segments[-1].points[0][::-1]) == pytest.approx(half)


# -- exact flank distance -------------------------------------------------------------------
@BOTH
@pytest.mark.parametrize("side", [-1, 1])
def test_flank_distance_along_the_surface_normal(spec, side):
    db = spec.base_angle_rad
    phi = np.linspace(roll_angle_at_polar(db, spec.form_angle_rad) + 0.01,
                      roll_angle_at_polar(db, spec.face_angle_rad), 15)
    polar = np.arccos(np.cos(db) * np.cos(phi * np.sin(db)))
    u = np.stack([np.sin(polar) * np.cos(flank_azimuth(spec, polar, side)),
                  np.sin(polar) * np.sin(flank_azimuth(spec, polar, side)), np.cos(polar)], -1)
    h = 1e-6
    du = np.stack([np.sin(polar + h) * np.cos(flank_azimuth(spec, polar + h, side)),
                   np.sin(polar + h) * np.sin(flank_azimuth(spec, polar + h, side)),
                   np.cos(polar + h)], -1) - u
    normal = np.cross(u, du)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    # orient the normal out of the tooth: away from the tooth centre (azimuth 0)
    normal *= np.sign(normal[:, 1] * side)[:, None]
    r = 40.0
    for offset in (-0.02, 0.0, 0.003, 0.05):
        d = flank_distance(spec, r * u + offset * normal, side=side, signed=True)
        assert np.allclose(d, offset, atol=1e-9)


@BOTH
def test_flank_distance_matches_brute_force(spec):
    # brute force: distance to each of 40000 rulings (lines through the apex) of the flank, the
    # smallest wins. Points 0.02–0.05 mm off the middle 80 % of the flank, so their feet are on
    # the involute; the ruling spacing (~0.1 µm) costs ≲ Δs²/(8h) ≈ 1e-10 mm.
    rng = np.random.default_rng(1)
    rulings = flank_directions(spec, -1, 40000)
    idx = rng.integers(4000, 36000, 30)
    normal = np.cross(rulings[idx], rulings[idx + 1] - rulings[idx - 1])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    h = rng.uniform(0.02, 0.05, (30, 1)) * rng.choice([-1, 1], (30, 1))
    picks = rulings[idx] * rng.uniform(25, 45, (30, 1)) + h * normal
    brute = np.linalg.norm(np.cross(picks[:, None, :], rulings[None]), axis=2).min(axis=1)
    exact = flank_distance(spec, picks, side=-1)
    assert np.all(exact <= brute + 1e-12)
    assert np.allclose(brute, exact, atol=1e-8)
    assert np.allclose(exact, np.abs(h[:, 0]), atol=1e-6)  # offset along the normal


@BOTH
def test_flank_distance_is_the_same_for_every_tooth(spec):
    u = flank_directions(spec, 1, 30) * 35.0
    for k in (1, spec.teeth // 2, spec.teeth - 1):
        moved = u @ _rot_z(k * spec.angular_pitch_rad).T
        assert flank_distance(spec, moved).max() < 1e-12 * 35


# -- blank and volume ------------------------------------------------------------------------
@BOTH
def test_blank_faces_stay_under_the_roots(spec):
    rz = spec.blank_profile()
    # every corner off the toothed zone is under the root cone, except the two tip corners
    # (front/back cone ∩ the outer cone beyond the tips)
    theta = np.arctan2(rz[:, 0], rz[:, 1])
    assert np.sum(theta > spec.root_angle_rad) == 2
    assert np.all(rz[:, 0] >= spec.bore_mm / 2 - 1e-12)


@BOTH
def test_analytic_volume_matches_a_grid_integration(spec):
    # independent check of the Pappus + Gauss–Legendre formula: midpoint rule over the meridian
    # plane, V = 2π ∫∫ ρ·(material fraction of the circle at (ρ, z)) dρ dz
    poly = spec.blank_profile()
    n = 1500
    rho = np.linspace(poly[:, 0].min(), poly[:, 0].max(), n + 1)
    z = np.linspace(poly[:, 1].min(), poly[:, 1].max(), n + 1)
    rho, z = 0.5 * (rho[1:] + rho[:-1]), 0.5 * (z[1:] + z[:-1])
    R, Z = np.meshgrid(rho, z)
    inside = np.zeros(R.shape, bool)
    for (x1, y1), (x2, y2) in zip(poly, np.roll(poly, -1, axis=0), strict=True):  # even-odd rule
        crosses = (y1 > Z) != (y2 > Z)
        with np.errstate(divide="ignore", invalid="ignore"):
            inside ^= crosses & (R < x1 + (x2 - x1) * (Z - y1) / (y2 - y1))
    theta = np.arctan2(R, Z)
    frac = np.where(theta < spec.root_angle_rad, 1.0,
                    np.where(theta <= spec.face_angle_rad,
                             spec.teeth * 2 * flank_azimuth(spec, theta, 1) / (2 * math.pi), 0))
    cell = (rho[1] - rho[0]) * (z[1] - z[0])
    grid = 2 * math.pi * np.sum(R * frac * inside) * cell
    v = analytic_volume_mm3(spec)
    assert v == pytest.approx(analytic_volume_mm3(spec, nodes=100), abs=1e-6)  # converged
    assert grid == pytest.approx(v, rel=2e-4)  # grid cells straddling the boundary


# -- gears in mesh as rigid bodies (geometry.bevel_mesh) ------------------------------------
def _pair(big_turn: float = 0.0, small_turn: float = 0.0) -> np.ndarray:
    """Small frame → big frame of the nominal pair, each gear turned about its own axis."""
    from gearcheck.geometry.bevel_play import nominal_small_pose, rot_z4

    return rot_z4(-big_turn) @ nominal_small_pose(GEAR, PINION) @ rot_z4(small_turn)


def test_congruent_pairs_are_whole_pitches_apart():
    # identical teeth relabelled: whole pitches of either gear give the same mesh; half a pitch
    # of either, or a rolled pose of both, does not (the rolled pose is congruent only at whole
    # pitches of the drive)
    from gearcheck.geometry.bevel_mesh import congruent

    q = _pair()
    for k, j in ((1, 0), (0, 1), (3, -2)):
        assert congruent(q, _pair(k * GEAR.angular_pitch_rad, j * PINION.angular_pitch_rad), GEAR, PINION)
    assert not congruent(q, _pair(0.5 * GEAR.angular_pitch_rad), GEAR, PINION)
    assert not congruent(q, _pair(0.0, 0.5 * PINION.angular_pitch_rad), GEAR, PINION)
    # rolling (the big gear turned −φ·z_small/z_big when the small one turns φ): the same mesh
    # again after one small-gear pitch of drive, not before
    for fraction, same in ((0.3, False), (0.5, False), (1.0, True)):
        phi = fraction * PINION.angular_pitch_rad
        assert congruent(q, _pair(-phi * PINION.teeth / GEAR.teeth, phi), GEAR, PINION, tol=1e-7) is same


def test_tooth_half_mask_keeps_one_flank_side_of_the_chosen_teeth():
    # points on the flanks of every tooth, both sides, plus root-land points: the mask keeps the
    # chosen side of the chosen teeth only (a "face" here is one point repeated)
    from gearcheck.geometry.bevel_mesh import tooth_half_mask

    def _unit(polar, azimuth):
        return np.array([math.sin(polar) * math.cos(azimuth), math.sin(polar) * math.sin(azimuth), math.cos(polar)])

    spec = GEAR
    theta = 0.5 * (spec.root_angle_rad + spec.face_angle_rad)
    r = spec.outer_cone_distance_mm
    points, expect = [], []
    for tooth in range(spec.teeth):
        for side in (-1, 1):
            az = float(flank_azimuth(spec, theta, side)) + tooth * spec.angular_pitch_rad
            points.append(r * _unit(theta, az))
            expect.append((tooth, side, True))
        # the root land between tooth and tooth + 1
        points.append(r * _unit(spec.root_angle_rad, (tooth + 0.5) * spec.angular_pitch_rad))
        expect.append((tooth, 1, False))
    vertices = np.array(points)
    faces = np.repeat(np.arange(len(points))[:, None], 3, axis=1)
    teeth = np.array([-1, 0, 1])  # −1 is tooth z − 1
    for side in (-1, 1):
        mask = tooth_half_mask(vertices, faces, spec, side, teeth)
        wanted = [flank and s == side and t in (spec.teeth - 1, 0, 1) for t, s, flank in expect]
        assert mask.tolist() == wanted
