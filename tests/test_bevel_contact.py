"""The vectorised exact contact solve (geometry.bevel_contact): its fast closed forms equal the
reference ones of geometry.bevel, its sample filter never drops a sample that could count, and
solving both ways at once gives the figures of one way at a time."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry import bevel_contact as bc
from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel import BevelGearSpec, flank_azimuth, mating_spec, minus_flank_signed

PINION = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0, profile_shift=0.39,
                       thinning_mm=0.02)
GEAR = mating_spec(PINION)
BOTH = pytest.mark.parametrize("spec", [PINION, GEAR], ids=["z13", "z33"])


def _random_points(spec: BevelGearSpec, n: int, seed: int) -> np.ndarray:
    """Points around the tooth zone (polar angles from below the base cone to past the tip)."""
    rng = np.random.default_rng(seed)
    theta = rng.uniform(spec.root_angle_rad - 0.05, spec.face_angle_rad + 0.05, n)
    az = rng.uniform(-math.pi, math.pi, n)
    r = rng.uniform(0.5, 1.1, n) * spec.outer_cone_distance_mm
    return np.stack([r * np.sin(theta) * np.cos(az), r * np.sin(theta) * np.sin(az), r * np.cos(theta)], axis=-1)


@BOTH
@pytest.mark.parametrize("side", [-1, 1])
def test_signed_distance_equals_the_reference_closed_form(spec, side):
    """signed_to_flank (cylindrical coordinates, no turning to tooth 0) against minus_flank_signed
    on the points turned to tooth 0 (and mirrored for side +1): the same to 1e-12 mm."""
    p = _random_points(spec, 4000, 1 + side)
    tooth = np.round(np.arctan2(p[:, 1], p[:, 0]) / spec.angular_pitch_rad)
    a = -tooth * spec.angular_pitch_rad
    q = np.stack([np.cos(a) * p[:, 0] - np.sin(a) * p[:, 1], np.sin(a) * p[:, 0] + np.cos(a) * p[:, 1], p[:, 2]], -1)
    if side == 1:
        q[:, 1] = -q[:, 1]
    ref = minus_flank_signed(spec, q)
    fast = bc.signed_to_flank(spec, p[:, 0], p[:, 1], p[:, 2], tooth, side)
    assert np.abs(fast - ref).max() < 1e-12
    below = np.arctan2(np.hypot(p[:, 0], p[:, 1]), p[:, 2]) < spec.base_angle_rad
    assert below.any() and (~below).any()  # both branches measured


@BOTH
def test_flank_points_lie_on_their_flank(spec):
    """flank_xyz puts points on the flank (distance 0 to 1e-12 mm) at the polar angle asked."""
    rng = np.random.default_rng(3)
    t, u = rng.uniform(0, 1, 500), rng.uniform(0, 1, 500)
    tooth = rng.integers(-3, 4, 500).astype(float)
    for side in (-1, 1):
        x, y, z = bc.flank_xyz(spec, 1.0, tooth, side, t, u)
        assert np.abs(bc.signed_to_flank(spec, x, y, z, tooth, side)).max() < 1e-12
        theta = np.arctan2(np.hypot(x, y), z)
        assert theta == pytest.approx(spec.root_angle_rad + t * (spec.face_angle_rad - spec.root_angle_rad), abs=1e-13)
        # and at the azimuth of the reference flank
        az = np.arctan2(y, x) - tooth * spec.angular_pitch_rad
        assert np.angle(np.exp(1j * (az - flank_azimuth(spec, theta, side)))) == pytest.approx(0.0, abs=1e-12)


def _pairs(n: int) -> tuple[list[bp.PlacedGear], list[bp.PlacedGear]]:
    """The nominal pair over a drive cycle, each pose nudged (non-conjugate) and scaled."""
    rng = np.random.default_rng(7)
    bigs, smalls = [], []
    for phi in np.linspace(0.0, GEAR.angular_pitch_rad, n, endpoint=False):
        shift = bp.translation4(rng.normal(0.0, 0.01, 3))
        smalls.append(bp.PlacedGear(GEAR, shift @ bp.nominal_small_pose(PINION, GEAR) @ bp.rot_z4(phi),
                                    1.0 + rng.normal(0.0, 2e-4)))
        bigs.append(bp.PlacedGear(PINION, bp.rot_z4(bp.conjugate_big_turn(PINION, GEAR, phi)), 1.0))
    return bigs, smalls


def test_sample_filter_never_drops_a_sample_that_counts():
    """The zone prefilter of the flank samples: with it or without it, every sample's estimate is
    the same (bit for bit), for both flank sets and both ways."""
    bigs, smalls = _pairs(12)
    poses_b = np.stack([b.pose for b in bigs])
    poses_s = np.stack([s.pose for s in smalls])
    inv_b, inv_s = bc.rigid_inverse(poses_b), bc.rigid_inverse(poses_s)
    scales_b, scales_s = np.ones(12), np.array([s.scale for s in smalls])
    t = np.linspace(0, 1, bc.PROFILE_SAMPLES)
    u = np.linspace(0, 1, bc.RULING_SAMPLES)
    kept = 0
    for way in (1, -1):
        side = np.full((12, 1), float(way))
        for fs in (bc._FlankSet(PINION, GEAR, True, inv_s @ poses_b, scales_b, scales_s, side, 2),
                   bc._FlankSet(GEAR, PINION, False, inv_b @ poses_s, scales_s, scales_b, side, 2)):
            grid = fs.grid_points(t, u)
            filtered = fs.estimate(grid, side)
            everything = fs.estimate(grid, side, all_points=True)
            assert np.array_equal(filtered, everything)
            assert np.isfinite(everything).any()
            kept += int(fs._may_touch(grid, fs.mover(grid)(0.0)).sum())
    assert kept < 0.8 * 4 * 12 * 5 * len(t) * len(u)  # and it rules out a good share


def test_both_ways_at_once_equal_one_way_at_a_time():
    bigs, smalls = _pairs(8)
    plus, minus = bp.big_gear_contacts_both(bigs, smalls)
    for way, got in ((1, plus), (-1, minus)):
        alone = bp.big_gear_contacts(bigs, smalls, way)
        assert [c.angle_rad for c in got] == [c.angle_rad for c in alone]
        assert all(np.array_equal(a.point, b.point) and (a.on, a.tooth) == (b.on, b.tooth)
                   for a, b in zip(got, alone, strict=True))
    assert all(p.angle_rad > m.angle_rad for p, m in zip(plus, minus, strict=True))  # there is play


def test_contact_point_is_on_both_flanks():
    """The contact the solve returns lies on the winner's flank and on the other gear's flank
    cone (both within 1e-7 mm), with the big gear turned to the contact."""
    bigs, smalls = _pairs(6)
    for way in (1, -1):
        for big, small, c in zip(bigs, smalls, bp.big_gear_contacts(bigs, smalls, way), strict=True):
            for gear in (big.turned(c.angle_rad), small):
                local = np.linalg.solve(gear.pose, np.append(c.point, 1.0))[:3] / gear.scale
                d = min(abs(float(bc.signed_to_flank(gear.spec, *local, k, way))) for k in range(gear.spec.teeth))
                assert d < 1e-7
