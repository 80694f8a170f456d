"""Differential sweep: the exact-flank play model, the geometric thermal state, and (``cad``) the
FCL mesh sweep checked against them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry import bevel_play as bp
from gearcheck.design import load_template
from gearcheck.geometry.bevel import BevelGearSpec, mating_spec
from gearcheck.mechanisms.differential import analyse_params
from gearcheck.mechanisms.differential.poses import assembly_poses, gear_specs
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, thermal_state

# The template's pair: z13/z33, m 2.5, 14 mm face, x = ±0.39, 0.031 mm thinning per mesh.
SMALL = BevelGearSpec(teeth=13, mate_teeth=33, module_mm=2.5, face_width_mm=14.0, profile_shift=0.39,
                      thinning_mm=0.0155)
BIG = mating_spec(SMALL, thinning_mm=0.0155)
HALF_RADIUS = BIG.outer_pitch_diameter_mm / 2.0  # d1/2 of eq (10)
TAN_ALPHA = math.tan(math.radians(20.0))
ANGLES = np.linspace(0.0, SMALL.angular_pitch_rad, 6, endpoint=False)


def _law_arcmin(shift_mm: float, radius_mm: float = HALF_RADIUS) -> float:
    """First-order backlash change of a normal shift: 2·tanα·r on a pitch radius, as an angle."""
    return 2.0 * TAN_ALPHA * shift_mm / radius_mm * bp.ARCMIN_PER_RAD


@pytest.fixture(scope="module")
def nominal():
    return bp.pair_play_over_cycle(BIG, SMALL, ANGLES)


@pytest.fixture(scope="module")
def template(templates_dir):
    return load_template(templates_dir / "zhurong_differential.toml").params


# -- exact-flank model ----------------------------------------------------------------------
def test_centred_pair_has_the_designed_play_at_every_angle(nominal):
    # no displacement: the pair is conjugate, the play is the thinning on d1/2 at every pose,
    # split evenly between the two ways (the resolution of the model is ~1e-4′)
    designed = 0.031 / HALF_RADIUS * bp.ARCMIN_PER_RAD
    assert np.allclose(nominal.total_arcmin, designed, atol=1e-4)
    assert np.allclose(bp.arcmin(nominal.plus_rad), -bp.arcmin(nominal.minus_rad), atol=1e-4)


def test_opening_normal_shift_follows_the_first_order_law(nominal):
    # the law: a pure normal shift r (here the small gear moved 30 µm away along the
    # normal to the pitch element) changes the cycle-minimum play by 2·tanα·r/(d1/2), within 2 %;
    # an opening is decided at the heel, where eq (10) converts
    r = 0.030
    shifted = bp.pair_play_over_cycle(BIG, SMALL, ANGLES,
                                      small_displacement=bp.translation4(r * bp.pitch_element_normal(BIG)))
    gain = shifted.min_total_arcmin - nominal.min_total_arcmin
    assert gain == pytest.approx(_law_arcmin(r), rel=0.02)


def test_closing_normal_shift_is_decided_at_the_toe(nominal):
    # the same shift toward the mesh loses the same mm of backlash along the whole face, but the
    # designed backlash tapers with the cone distance: the toe closes first, so the loss is the
    # law on the toe pitch radius Ri·sin δ1 (Re/Ri = 1.46 times the eq (10) figure), within 2 %
    r = 0.020
    shifted = bp.pair_play_over_cycle(BIG, SMALL, ANGLES,
                                      small_displacement=bp.translation4(-r * bp.pitch_element_normal(BIG)))
    loss = nominal.min_total_arcmin - shifted.min_total_arcmin
    toe_radius = BIG.inner_cone_distance_mm * math.sin(BIG.pitch_angle_rad)
    assert loss == pytest.approx(_law_arcmin(r, toe_radius), rel=0.02)
    assert loss > 1.4 * _law_arcmin(r)


def test_slide_along_the_pitch_element_loses_play_either_way(nominal):
    # docs/differential.md: a slide moves the gear's apex off the common apex, the mesh is no longer
    # conjugate and neighbouring pairs close up — 30 µm either way loses ≈ 0.3–1′ where the
    # first-order model (clean eq 9) says ±2tan(θ/2)·t/(d1/2) = ±0.22′
    d = BIG.pitch_angle_rad
    element = np.array([math.sin(d), 0.0, math.cos(d)])
    losses = []
    for t in (0.03, -0.03):
        slid = bp.pair_play_over_cycle(BIG, SMALL, ANGLES, small_displacement=bp.translation4(t * element))
        losses.append(nominal.min_total_arcmin - slid.min_total_arcmin)
    model = (math.pi * 2.5 / 2) / BIG.outer_cone_distance_mm * 0.03 / HALF_RADIUS * bp.ARCMIN_PER_RAD
    assert model == pytest.approx(0.22, abs=0.01)
    assert min(losses) > model and max(losses) > 3 * model


def _axial(big_mm: float, small_mm: float):
    """Each gear moved along its own axis toward the apex (small axis = world x)."""
    return dict(big_displacement=bp.translation4([0.0, 0.0, -big_mm]),
                small_displacement=bp.translation4([-small_mm, 0.0, 0.0]))


def test_play_repeats_every_small_gear_pitch():
    # identical teeth: one small-gear pitch of drive is the whole cycle, also off the common apex
    pitch = SMALL.angular_pitch_rad
    angles = np.array([0.1, 0.37]) * pitch
    shift = _axial(0.042, 0.053)
    a = bp.pair_play_over_cycle(BIG, SMALL, angles, **shift)
    b = bp.pair_play_over_cycle(BIG, SMALL, angles + pitch, **shift)
    assert np.allclose(bp.arcmin(a.plus_rad), bp.arcmin(b.plus_rad), atol=1e-4)
    assert np.allclose(bp.arcmin(a.minus_rad), bp.arcmin(b.minus_rad), atol=1e-4)


def test_plus_and_minus_are_mirror_images():
    # the pair is symmetric about the plane of the two axes, and axial shifts keep it so: turning
    # + at drive φ is turning − at drive −φ
    shift = _axial(0.042, 0.053)
    phi = np.array([0.13, 0.31]) * SMALL.angular_pitch_rad
    fwd = bp.pair_play_over_cycle(BIG, SMALL, phi, **shift)
    back = bp.pair_play_over_cycle(BIG, SMALL, -phi, **shift)
    assert np.allclose(bp.arcmin(fwd.plus_rad), -bp.arcmin(back.minus_rad), atol=1e-4)


def test_scale_about_the_apex_changes_no_play(nominal):
    # flanks are cones through the apex: shrinking a gear about its apex only moves toe and heel
    cold = bp.pair_play_over_cycle(BIG, SMALL, ANGLES[:2], big_scale=0.999, small_scale=0.999)
    assert np.allclose(cold.total_arcmin, nominal.total_arcmin[:2], atol=1e-4)


def test_contact_is_on_the_flanks_of_both_gears():
    # the first contact lies on the big gear's flank surface and on the small gear's (its
    # world point, taken back to each gear's frame, is on that gear's analytic flank)
    from gearcheck.geometry.bevel import flank_distance

    big = bp.PlacedGear(BIG, np.eye(4))
    small = bp.PlacedGear(SMALL, bp.translation4([-0.05, 0.0, 0.0]) @ bp.nominal_small_pose(BIG, SMALL))
    for direction in (1, -1):
        c = bp.big_gear_contact(big, small, direction)
        turned = big.turned(c.angle_rad).pose
        for pose, spec in ((turned, BIG), (small.pose, SMALL)):
            local = np.linalg.inv(pose) @ np.append(c.point, 1.0)
            assert flank_distance(spec, local[:3])[0] < 1e-6


def test_play_period_is_half_a_pitch_when_the_big_gear_is_odd():
    # each big gear meets its two small gears 180° apart: half a tooth apart when z_big is odd, so
    # its play repeats every half small-gear pitch; in phase when z_big is even (a whole pitch)
    from gearcheck.geometry.bevel_mesh import play_period
    from gearcheck.mechanisms.differential.poses import GearSpecs

    for big_teeth, fraction in ((33, 0.5), (32, 1.0)):
        small = BevelGearSpec(teeth=13, mate_teeth=big_teeth, module_mm=2.5, face_width_mm=14.0, profile_shift=0.39,
                              thinning_mm=0.0155)
        specs = GearSpecs(big=mating_spec(small, thinning_mm=0.0155), small=small)
        built = assembly_poses(specs).as_dict()
        period = play_period(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small)
        assert period == pytest.approx(fraction * small.angular_pitch_rad, rel=1e-12)


# -- thermal state --------------------------------------------------------------------------
def test_apex_shifts_are_eqs_6_and_7(template):
    # the datum moves with housing, shim and shaft, the body scales about it; the apex then moves
    # by −ΔS1 / −ΔS2 (outward +): the scale about the datum is eq (6)'s Δd2/2 term. Without a
    # shim exactly; with one, plus its own shrink ξ3·x·ΔT (0.1 µm), which eq (6) leaves out.
    approach = analyse_params(template).approach
    drop = approach.temperature_drop_K
    for shim in (0.0, 0.1):
        state = thermal_state(template, shim_mm=shim)
        for name in BIG_GEARS:
            shim_shrink = template.materials.gear_cte_per_K * shim * drop
            assert state[name].apex_shift_mm == pytest.approx(-approach.big_approach_mm - shim_shrink, abs=1e-12)
    # small gear: equal when a/2 = l2 + d1/2 (template: exactly)
        for name in SMALL_GEARS:
            assert state[name].apex_shift_mm == pytest.approx(-approach.small_approach_mm, abs=1e-9)


def test_thermal_state_is_per_part_not_a_uniform_scale(template):
    state = thermal_state(template)
    dT = template.operating.cold_C - template.operating.warm_C
    specs = gear_specs(template)
    for name, th in state.items():
        assert th.scale == pytest.approx(1.0 + template.materials.gear_cte_per_K * dT)  # steel body
        # a uniform scale by the housing's CTE would move the datum by ξ1·ΔT·(its distance)
        uniform = template.materials.housing_cte_per_K * dT * float(th.datum_local[2])
        assert abs(th.datum_shift_mm - uniform) > 1e-3 if name in BIG_GEARS else True
        assert np.allclose(th.axis, assembly_poses(specs).as_dict()[name][:3, 2])
    # cold pose of a point: datum fixed in its own frame up to the datum shift
    th = state["big_gear_right"]
    pose = assembly_poses(specs).big_right
    p = th.datum_local + np.array([3.0, -2.0, -20.0])
    scaled = th.datum_local + th.scale * (p - th.datum_local)
    a = th.cold_pose(pose) @ np.append(scaled, 1.0)
    b = th.cold_pose_about_origin(pose) @ np.append(th.scale * p, 1.0)
    assert np.allclose(a, b, atol=1e-12)


def _exact_big_gear_play(params, shim_mm, angles, state_name):
    """Exact play of the right output shaft (tighter of its two meshes each way) over angles."""
    specs = gear_specs(params)
    poses0 = assembly_poses(specs, shim_mm).as_dict()
    thermal = thermal_state(params, specs=specs, shim_mm=shim_mm)
    out = []
    for phi in angles:
        placed = {}
        for name, pose in poses0.items():
            spec = specs.big if name in BIG_GEARS else specs.small
            turn = bp.conjugate_big_turn(specs.big, specs.small, phi) if name in BIG_GEARS else phi
            pose = pose @ bp.rot_z4(turn)
            if state_name == "cold":
                placed[name] = bp.PlacedGear(spec, thermal[name].cold_pose_about_origin(pose), thermal[name].scale)
            else:
                placed[name] = bp.PlacedGear(spec, pose)
        plays = [bp.big_gear_play(placed["big_gear_right"], placed[s]) for s in SMALL_GEARS]
        out.append(min(p.plus.angle_rad for p in plays) - max(p.minus.angle_rad for p in plays))
    return bp.arcmin(np.array(out))


def test_equal_ctes_lose_no_play(templates_dir):
    # every part of the same material: the chain is a uniform scale about the centre (each apex
    # moves by ξ·ΔT times its offset, the shim), the flank cones stay, the play stays
    xi = 10.8e-6
    params = load_template(templates_dir / "zhurong_differential.toml",
                           [f"materials.housing_cte_per_K={xi}", f"materials.shaft_cte_per_K={xi}"]).params
    dT = params.operating.cold_C - params.operating.warm_C
    for name, th in thermal_state(params).items():
        offset = params.shim.thickness_mm if name in BIG_GEARS else 0.0
        assert th.apex_shift_mm == pytest.approx(xi * dT * offset, abs=1e-12)
    angles = np.array([0.0, 0.2]) * gear_specs(params).small.angular_pitch_rad
    warm = _exact_big_gear_play(params, 0.1, angles, "warm")
    cold = _exact_big_gear_play(params, 0.1, angles, "cold")
    assert np.abs(warm - cold).max() < 2e-4  # the model's resolution


def test_exact_cold_drop_exceeds_the_paper_model(template):
    # docs/differential.md: with shim 0.10 the exact flanks lose ≈ 3.9–4.4′ per side over a tooth cycle,
    # more than the first-order model's 3.39′ (paper form) — a finding, not a fit; 6 angles over
    # the half-pitch period of the shaft's play (z_big odd)
    specs = gear_specs(template)
    angles = np.arange(6) / 6 * specs.small.angular_pitch_rad / 2
    drop = _exact_big_gear_play(template, 0.1, angles, "warm").min() - \
        _exact_big_gear_play(template, 0.1, angles, "cold").min()
    model = analyse_params(template).cold.per_side_arcmin
    assert 3.9 <= drop <= 4.6
    assert drop > 1.13 * model


# -- the mesh sweep (CAD) -------------------------------------------------------------------
@pytest.mark.cad
def test_mesh_sweep_agrees_with_the_exact_flanks(build_bodies):
    import contextlib

    from gearcheck import pipeline

    run = build_bodies("zhurong_differential")
    counted = []

    class _Bar:
        def update(self, n: int = 1) -> None:
            counted.append(n)

    @contextlib.contextmanager
    def progress(_desc, _total=None, _unit=""):
        yield _Bar()

    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, progress=progress,
                            options={"angles_per_cycle": 4, "shims_mm": [0.0, 0.1], "range_shims": "template"})
    s = result.summary
    verdicts = {v.name: v for v in result.verdicts}
    assert verdicts["mesh_agrees_with_exact"].passed
    assert "mesh_agrees_with_exact" not in s  # the verdict only, not a duplicate in the summary
    assert s["max_mesh_exact_contact_deviation_arcmin"] <= s["mesh_error_bound_arcmin"] + 0.02 * 9.0
    # meshes overstate clearance (chords inside convex flanks), never by more than the bound
    assert s["geom_play_min_arcmin_at_warm"] >= s["exact_play_min_arcmin_at_warm"] - 1e-3
    assert s["geom_play_min_arcmin_at_cold"] > 0.0
    assert result.passed
    assert all(v.evidence for v in result.verdicts)
    # the finding: the geometry loses more than the paper's first-order model
    assert s["geom_cold_drop_per_side_arcmin"] > s["model_cold_drop_per_side_arcmin"]
    # no shim binds cold (the paper shims for this reason)
    study = s["shim_study"]
    assert study["geom_play_min_arcmin_at_cold"][study["shims_mm"].index(0.0)] < 0.0
    # the template's shim is also measured at the operating range's ends and the storage minimum,
    # each checked against the exact flanks; the storage minimum binds (a warning, not a failure)
    states = s["states"]
    assert set(states) == {"warm", "cold", "operating_min", "operating_max", "storage_min"}
    for state in states.values():
        assert abs(state["geom_play_min_arcmin"] - state["exact_play_min_arcmin"]) <= 2 * s["mesh_error_bound_arcmin"]
    assert states["storage_min"]["exact_play_min_arcmin"] < 0.0 < states["operating_min"]["exact_play_min_arcmin"]
    assert verdicts["storage_play_positive"].level == "warn" and verdicts["operating_play_positive"].level == "pass"
    # the exact range over the grid meets the meshed states' exact figures (same model, other batch)
    er = s["exact_range"]
    for state in states.values():
        i = er["temperatures_C"].index(state["temperature_C"])
        assert er["exact_least_play_per_side_arcmin"][i] == pytest.approx(state["exact_play_min_arcmin"], abs=0.05)
    assert er["binds_in_storage_range"] == 1 and er["binding_onset_C"] < -100.0
    # rows: one per (shim, state, drive angle): 2 states at shim 0, 5 at the template's; same keys
    assert len(result.rows) == (2 + 5) * 4 and len({tuple(r) for r in result.rows}) == 1

    def plain(v) -> bool:
        if isinstance(v, dict):
            return all(plain(x) for x in v.values())
        if isinstance(v, list):
            return all(isinstance(x, (int, float)) for x in v)
        return isinstance(v, (int, float))

    assert all(plain(v) for v in s.values())
    assert sum(counted) > 0
    contact, centred = result.worst_poses
    assert contact.mesh_distance_mm < 1e-4 < centred.mesh_distance_mm
    assert contact.scale_a < 1.0
    assert contact.label.startswith("cold least play")
