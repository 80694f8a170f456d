"""The differential over temperature and its calibration, on the exact-flank model (numpy, no
CAD): the grid over the operating and storage ranges, the heel/toe-limited slopes of the play, the
onset of binding, where the least play is decided, the thinning solved from a measured backlash,
the smallest clearance the sweep decides, the verdicts' evidence when the mesh cannot resolve it,
and calc's figures beside the paper's linear model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.design import load_template
from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel import flank_distance
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.differential import temperature as tp
from gearcheck.mechanisms.differential.analysis import analyse_params, model_per_side
from gearcheck.mechanisms.differential.calibration import SOLVE_TOL_ARCMIN, exact_warm_total
from gearcheck.mechanisms.differential.poses import gear_specs
from gearcheck.params import ParamError

DIFFERENTIAL = mechanism("differential")


def load(templates_dir, *overrides: str):
    return load_template(templates_dir / "zhurong_differential.toml", list(overrides)).params


@pytest.fixture(scope="module")
def template(templates_dir):
    return load(templates_dir)


@pytest.fixture(scope="module")
def grid(template):
    """The exact model over the whole grid at the template's shim, with the contact spots."""
    plays = tp.exact_plays(template, template.shim.thickness_mm, tp.temperature_grid(template), spots=True)
    return tp.range_check(template, template.shim.thickness_mm, plays=plays)


# -- the grid ------------------------------------------------------------------------------
def test_grid_covers_both_ranges_in_5_K_steps(template):
    temps = tp.temperature_grid(template)
    op = template.operating
    assert temps[0] == op.storage_min_C and temps[-1] == op.storage_max_C
    assert np.all(np.diff(temps) <= tp.GRID_STEP_K + 1e-9) and np.all(np.diff(temps) > 0)
    for t in (op.warm_C, op.cold_C, op.operating_min_C, op.operating_max_C):
        assert np.any(temps == t), t
    # a named temperature off the 5 K lattice is added exactly, not rounded onto it
    other = tp.temperature_grid(load_template_params_with(template, cold_C=-67.3))
    assert np.any(other == -67.3) and np.all(np.diff(other) <= tp.GRID_STEP_K + 1e-9)


def load_template_params_with(params, **operating):
    return params.model_copy(update={"operating": params.operating.model_copy(update=operating)})


def test_warm_play_is_the_measured_backlash(template, grid):
    # calibrated: the gears' thinning was solved so that the exact warm total at the measured shim
    # and temperature is the least measured total (16.8′), read as the least over the cycle
    c = template.calibration
    assert c.measured_shim_mm == template.shim.thickness_mm and c.measured_at_C == template.operating.warm_C
    # read at the cycle's drive angles (the poses measured); over the continuous cycle a little lower
    i = int(np.flatnonzero(grid.temperatures_C == template.operating.warm_C)[0])
    sampled = 2.0 * float(grid.plays.sampled_least_arcmin[i])
    assert sampled == pytest.approx(c.measured_backlash_total_min_arcmin, abs=2 * SOLVE_TOL_ARCMIN)
    assert sampled - 2e-3 <= 2.0 * grid.at("warm") <= sampled


def test_play_falls_heel_limited_then_toe_limited(template, grid):
    # cooling closes the mesh by translations: the same mm along the whole face, while the backlash
    # tapers with the cone distance. Near warm the play is decided at the heel, at the cold end at
    # the toe, so the loss per kelvin there is Re/Ri times the loss near warm (within 1 %), and both
    # exceed the paper's linear model (one tooth pair at the outer pitch point)
    temps, least = grid.temperatures_C, grid.least_arcmin
    warm_slope = (least[-1] - least[-2]) / (temps[-1] - temps[-2])
    cold_slope = (least[1] - least[0]) / (temps[1] - temps[0])
    spec = gear_specs(template).big
    assert cold_slope / warm_slope == pytest.approx(spec.outer_cone_distance_mm / spec.inner_cone_distance_mm,
                                                    rel=0.01)
    assert warm_slope == pytest.approx(0.048, abs=0.002) and cold_slope == pytest.approx(0.0705, abs=0.002)
    assert warm_slope > analyse_params(template).drop_per_side_per_K_arcmin
    # concave (min over contacts minus max over contacts of near-linear turns): the least over a
    # range is at its ends, so calc's named temperatures find what the grid finds
    second = np.diff(least, 2)
    assert np.all(second <= 1e-3)
    keys = tp.range_check(template, template.shim.thickness_mm, grid=False)
    assert keys.operating == pytest.approx(grid.operating, abs=1e-9)
    assert keys.storage == pytest.approx(grid.storage, abs=1e-9)


def test_contact_heel_warm_toe_cold(grid):
    spots = grid.plays.spots
    i_warm = int(np.argmin(np.abs(grid.temperatures_C - grid.keys["warm"])))
    assert spots[i_warm][0][0].along > 0.99  # the heel
    assert spots[0][0][0].along < 0.01  # the toe at the storage minimum
    for way in spots[i_warm] + spots[0]:
        for s in way:
            assert -1e-6 <= s.height <= 1 + 1e-6


def test_contact_point_lies_on_both_flanks(template):
    # the least-play contact at the storage minimum, taken back to each gear's frame, is on that
    # gear's analytic flank (the spots read the same point)
    specs = gear_specs(template)
    plays = tp.exact_plays(template, template.shim.thickness_mm, [template.operating.storage_min_C])
    k, b = np.unravel_index(np.argmin(plays.play_arcmin[0]), plays.play_arcmin[0].shape)
    from gearcheck.geometry.bevel_mesh import drive_poses
    from gearcheck.mechanisms.differential.poses import assembly_poses
    from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, thermal_state

    built = assembly_poses(specs, template.shim.thickness_mm).as_dict()
    thermal = thermal_state(template, cold_C=template.operating.storage_min_C, specs=specs)
    placed = tp.placed_gears(specs, drive_poses(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small,
                                                float(plays.angles_rad[k])), thermal)
    big = placed[BIG_GEARS[b]]
    small = placed[SMALL_GEARS[int(np.argmin(plays.plus_rad[0, k, b]))]]
    c = bp.big_gear_contact(big, small, 1)
    assert c.angle_rad == pytest.approx(plays.plus_rad[0, k, b].min(), abs=1e-12)
    for gear, turn in ((big, c.angle_rad), (small, 0.0)):
        pose = gear.turned(turn).pose
        local = np.linalg.solve(pose, np.append(c.point, 1.0))[:3] / gear.scale
        assert flank_distance(gear.spec, local)[0] < 1e-6
    spot = tp.flank_spot(big, c.angle_rad, c.point)
    assert spot.along == pytest.approx(0.0, abs=0.01)  # cold: the toe


# -- the ranges and the onset ---------------------------------------------------------------
def test_template_binds_only_in_storage_with_an_onset(template, grid):
    assert grid.level == "warn" and not grid.binds_operating and grid.binds_storage
    onset = grid.cold_onset_C
    op = template.operating
    assert op.storage_min_C < onset < op.operating_min_C
    # the onset is a sign change of the exact play itself within ±ONSET_TOL_K
    below, above = tp.exact_plays(template, template.shim.thickness_mm,
                                  [onset - tp.ONSET_TOL_K, onset + tp.ONSET_TOL_K]).least_arcmin
    assert below <= 0.0 < above
    deep = grid.at("storage_min")
    assert deep < 0.0
    d1_half = gear_specs(template).big.outer_pitch_diameter_mm / 2.0
    assert grid.depth_um(deep) == pytest.approx(-deep / bp.ARCMIN_PER_RAD * d1_half * 1e3, rel=1e-12)


def test_an_onset_solved_by_the_range_task_is_the_one_the_reduce_step_would_solve(template, grid):
    """The sweep's range tasks solve the crossings between their own temperatures (beside the other
    tasks); the reduce step takes them as they are and solves only a crossing that falls between
    two tasks' temperatures: the same onset, bit for bit, either way."""
    from gearcheck.mechanisms.differential.sweep import exact_range_task

    shim, temps = template.shim.thickness_mm, grid.temperatures_C
    i = int(np.flatnonzero(np.diff(np.sign(grid.least_arcmin)))[0])  # the crossing: temps[i], temps[i + 1]
    inside = exact_range_task(None, template, shim, [float(t) for t in temps[max(i - 1, 0):i + 2]], tp.ANGLES_PER_CYCLE)
    assert list(inside["onsets"].values()) == [grid.cold_onset_C] and inside["onset_s"] > 0.0
    # split between two tasks: neither sees the crossing, the reduce step solves it
    parts = [exact_range_task(None, template, shim, [float(temps[k])], tp.ANGLES_PER_CYCLE) for k in (i, i + 1)]
    assert all(p["onsets"] == {} for p in parts)
    merged = tp.merge_plays([p["plays"] for p in parts])
    assert tp.range_check(template, shim, plays=merged).onsets_C == (grid.cold_onset_C,)
    # a crossing given as solved is taken, not solved again
    key = next(iter(inside["onsets"]))
    assert tp.range_check(template, shim, plays=merged, solved={key: -99.5}).onsets_C == (-99.5,)


@pytest.mark.parametrize("shim, level", [(0.0, "fail"), (0.15, "pass")])
def test_range_levels_follow_the_shim(template, shim, level):
    r = tp.range_check(template, shim, grid=False)
    assert r.level == level
    if level == "pass":
        assert r.onsets_C == () and r.depth_um(r.at("storage_min")) == 0.0


def test_the_linear_model_misses_the_storage_binding(template):
    # the paper's linear model (at the paper-model thinning, [backlash]) says 5.18′ total, free, at
    # −130 °C; with the same thinning the exact geometry overlaps (≈ −1.42′ per side)
    r = analyse_params(template)
    linear = r.total_backlash_at(template.operating.storage_min_C, template.operating.warm_C,
                                 r.design.warm_total_min_arcmin)
    assert linear == pytest.approx(5.18, abs=0.01)
    specs = gear_specs(template, thinning_mm=template.backlash.mesh_thinning_min_mm)
    exact = tp.least_play(template, template.shim.thickness_mm, template.operating.storage_min_C, specs=specs)
    assert exact == pytest.approx(-1.42, abs=0.02)


# -- calibration -----------------------------------------------------------------------------
def test_solved_thinning_reproduces_the_measurement(template):
    th = template.thinning()
    c = template.calibration
    assert th.calibrated and th.min_mm > th.template_min_mm
    assert th.exact_evaluations == 3  # whole cycles: the template's thinning, the least, the largest
    for thinning, measured in ((th.min_mm, c.measured_backlash_total_min_arcmin),
                               (th.max_mm, c.measured_backlash_total_max_arcmin)):
        total = exact_warm_total(template, thinning, c.measured_shim_mm, c.measured_at_C)
        assert total == pytest.approx(measured, abs=2 * SOLVE_TOL_ARCMIN)
    # the paper-model thinning builds less than was measured on the exact geometry
    at_template = exact_warm_total(template, th.template_min_mm, c.measured_shim_mm, c.measured_at_C)
    assert at_template == pytest.approx(th.template_exact_total_min_arcmin, abs=1e-9)
    assert at_template < c.measured_backlash_total_min_arcmin - 1.0
    # a thinning turns each flank about its own axis: very nearly 2/(d1/2) rad of total per mm
    d1_half = gear_specs(template).big.outer_pitch_diameter_mm / 2.0
    slope = (c.measured_backlash_total_min_arcmin - at_template) / (th.min_mm - th.template_min_mm)
    assert slope == pytest.approx(2.0 * bp.ARCMIN_PER_RAD / d1_half, rel=0.02)
    # the gears are built with it, split over the two gears
    specs = gear_specs(template)
    assert specs.big.thinning_mm == specs.small.thinning_mm == pytest.approx(th.min_mm / 2.0, rel=1e-12)


def test_without_calibration_the_template_thinning_builds(templates_dir):
    from gearcheck.params import validate
    from gearcheck.params.common import read_toml

    data = read_toml(templates_dir / "zhurong_differential.toml")
    data.pop("mechanism")
    del data["calibration"]
    params = validate(DIFFERENTIAL.Params, data, "x.toml")
    assert not params.thinning().calibrated
    assert gear_specs(params).big.thinning_mm == pytest.approx(params.backlash.mesh_thinning_min_mm / 2.0)


def test_unreachable_measurement_is_rejected_with_its_bound(templates_dir):
    key = "calibration.measured_backlash_total_min_arcmin"
    with pytest.raises(ParamError) as info:
        load(templates_dir, f"{key}=5.0")
    err = info.value
    assert err.field == key and "\n" not in str(err) and "no tooth thinning" in str(err)
    bound = float(err.allowed.split(">= ")[1].split("′")[0])
    params = load(templates_dir, f"{key}={bound}")  # the printed bound itself is accepted
    assert params.thinning().min_mm == pytest.approx(0.0, abs=2e-4)


@pytest.mark.parametrize("overrides, field", [
    (["calibration.measured_backlash_total_max_arcmin=10"], "calibration.measured_backlash_total_max_arcmin"),
    (["calibration.measured_at_C=200"], "calibration.measured_at_C"),
    (["calibration.measured_backlash_total_min_arcmin=0"], "calibration.measured_backlash_total_min_arcmin"),
])
def test_bad_calibration_names_its_field(templates_dir, overrides, field):
    with pytest.raises(ParamError) as info:
        load(templates_dir, *overrides)
    assert info.value.field == field and "allowed" in str(info.value)


def test_calibration_needs_all_its_keys():
    from gearcheck.mechanisms.differential.params import Calibration

    with pytest.raises(ParamError) as info:
        Calibration(measured_backlash_total_min_arcmin=16.8)
    assert info.value.field.startswith("calibration.") and "all of" in info.value.allowed


# -- what the sweep decides, before meshing ----------------------------------------------------
@pytest.mark.parametrize("shim", [0.10, 0.15])
def test_smallest_clearance_is_the_least_exact_play_by_magnitude(templates_dir, shim):
    """Before meshing: the least |play| over the meshed states whose verdicts can fail (warm, the
    cold design point, the operating range's ends); the storage minimum, meshed too, only warns
    and rests on the exact model, so its few-µm overlap does not ask for sub-µm meshes."""
    params = load(templates_dir, f"shim.thickness_mm={shim}")
    c = DIFFERENTIAL.smallest_clearance(params)
    plays = {name: tp.least_play(params, shim, temp) for name, temp in tp.meshed_states(params)}
    decided = {k: v for k, v in plays.items() if k in tp.MESH_DECIDED_STATES}
    assert set(plays) - set(decided) == {"storage_min"}
    least = min(abs(v) for v in decided.values())
    d1_half = gear_specs(params).big.outer_pitch_diameter_mm / 2.0
    assert c.value_mm == pytest.approx(least / bp.ARCMIN_PER_RAD * d1_half, rel=1e-9)
    # the cold design point decides it (the least play in the operating states), a play, not an overlap
    assert "cold design point" in c.label and "overlap" not in c.label


# -- verdicts on a hand-made sweep: the exact model decides when the mesh cannot resolve ---------
def _sweep(params, geom_offset: float):
    """A sweep outcome whose mesh plays are the exact ones shifted by ``geom_offset`` (arcmin)."""
    from gearcheck.mechanisms.differential.reduce import SweepData
    from gearcheck.results import SweepOutcome

    shim = params.shim.thickness_mm
    states = tp.meshed_states(params)
    exact = tp.exact_plays(params, shim, [t for _, t in states], angles_per_cycle=2)
    shape = (1, len(states), 2, 2)
    plus, minus = exact.plus_arcmin.reshape(shape), exact.minus_arcmin.reshape(shape)
    specs = gear_specs(params)
    data = SweepData(
        specs=specs, shims=[shim], template_shim_mm=shim, t=0, z=None, states=states,
        index={n: j for j, (n, _) in enumerate(states)}, measured=np.ones(shape[:2], dtype=bool),
        angles=exact.angles_rad, period_rad=exact.period_rad, geom_plus=plus + geom_offset / 2,
        geom_minus=minus - geom_offset / 2, exact_plus=plus, exact_minus=minus,
        centred_free=np.ones(shape, dtype=bool), models=[model_per_side(params, shim)],
        model_per_K=analyse_params(params).drop_per_side_per_K_arcmin, warm_C=params.operating.warm_C,
        contact_dev=np.array([abs(geom_offset) / 2]), contact_ok=True, total_ok=True, contacts=4,
        bound_mm=0.006, bound_arcmin=0.5, exact_solves=exact.solves, exact_reused=exact.reused,
        ranges={0: tp.range_check(params, shim, grid=False)})
    return SweepOutcome({}, data=data)


def test_unresolved_mesh_leaves_the_play_verdicts_to_the_exact_model(templates_dir):
    from gearcheck.mechanisms.differential.verdicts import verdicts

    # shim 0.04 mm: +0.08′ per side cold on the exact flanks (≈1 µm on d1/2), far under any mesh
    params = load(templates_dir, "shim.thickness_mm=0.04")
    outcome = _sweep(params, geom_offset=-0.3)  # a mesh that reads an overlap cold
    exact_cold = outcome.data.exact_min[0, outcome.data.c]
    assert 0.0 < exact_cold < 0.2 and outcome.data.geom_min[0, outcome.data.c] < 0.0
    outcome.mesh_resolves = True
    by_mesh = {v.name: v for v in verdicts(params, outcome)}
    assert by_mesh["cold_play_positive"].level == "fail"
    assert by_mesh["cold_play_positive"].evidence.startswith("mesh sweep")
    outcome.mesh_resolves = False
    by_exact = {v.name: v for v in verdicts(params, outcome)}
    assert by_exact["cold_play_positive"].level == "pass"
    for name in ("no_interference_warm", "cold_play_positive", "operating_play_positive"):
        assert by_exact[name].evidence.startswith("exact model") and "cannot resolve" in by_exact[name].evidence
    assert all(v.evidence for v in by_exact.values())
    # storage binds at this shim: a warning naming the onset and the overlap at the storage minimum
    storage = by_exact["storage_play_positive"]
    assert storage.level == "warn" and "contact starts at" in storage.measured and "µm" in storage.measured
    assert storage.figures["binding_onset_C"] == pytest.approx(outcome.data.range.cold_onset_C)


def test_operating_binding_fails(templates_dir):
    from gearcheck.mechanisms.differential.verdicts import verdicts

    params = load(templates_dir, "shim.thickness_mm=0.0")
    outcome = _sweep(params, geom_offset=0.0)
    outcome.mesh_resolves = False
    levels = {v.name: v.level for v in verdicts(params, outcome)}
    assert levels["operating_play_positive"] == "fail" and levels["storage_play_positive"] == "warn"


# -- calc beside the paper's linear model --------------------------------------------------------
def test_calc_shows_the_exact_range_beside_the_linear_model(template, grid):
    figs = {f.key: f for f in DIFFERENTIAL.analyse(template)}
    linear = figs["cold_backlash_positive"]
    assert linear.value == 1.0 and "PASS" not in linear.note and "binds in storage" in linear.note
    assert "linear model" in linear.label
    assert figs["exact_range_verdict"].value == 0.5 and figs["exact_range_verdict"].note.startswith("WARN")
    assert figs["exact_play_min_arcmin_at_storage_min"].value == pytest.approx(grid.at("storage_min"))
    assert figs["exact_binding_onset_C"].value == pytest.approx(grid.cold_onset_C, abs=2 * tp.ONSET_TOL_K)
    assert figs["backlash_total_min_at_storage_min_arcmin"].value > 0.0  # the linear model, free
    assert "binds" in figs["backlash_total_min_at_storage_min_arcmin"].note
    th = template.thinning()
    assert figs["design_thinning_min_um"].value == pytest.approx(th.min_mm * 1e3)
    assert figs["paper_model_thinning_min_um"].value == pytest.approx(template.backlash.mesh_thinning_min_mm * 1e3)
    assert all(math.isfinite(f.value) for f in figs.values())


def test_a_shim_that_is_not_a_round_figure_keeps_its_key():
    """A study draws shims such as 0.09894159820366788 mm: the sweep's shim list keeps the
    template's shim exactly (its key in every table), a repeat of it is dropped, others are
    rounded to 1e-9 mm. Before, the rounded list lost the template's key (KeyError in the plan)."""
    from types import SimpleNamespace

    from gearcheck.mechanisms.differential.sweep import _shims

    odd = 0.09894159820366788
    shims = _shims(SimpleNamespace(template_shim_mm=odd, study_shims_mm=[0.0, 0.05, 0.1]), None)
    assert odd in shims and shims.index(odd) == 2 and shims == sorted(shims)
    assert _shims(SimpleNamespace(template_shim_mm=0.1, study_shims_mm=[0.1 + 1e-12, 0.05]), None) == [0.0, 0.05, 0.1]
