"""The differential's exact least play over the continuous cycle, not only at the swept drive
angles: refined between them (gearcheck.sweep.certify.refine_least) for every swept state and every
temperature of the exact range. On a coarse grid (3 drive angles per cycle) the figures never lie
above the exact model sampled 100× finer, and the verdicts are the default grid's."""

from __future__ import annotations

import pytest

from gearcheck.mechanisms.differential import temperature as T

COARSE = 3
FINE = 100 * COARSE


@pytest.fixture(scope="module")
def coarse(build_bodies):
    from gearcheck import pipeline

    run = build_bodies("zhurong_differential")
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1,
                            options={"angles_per_cycle": COARSE, "range_shims": "template"})
    return run.design.params, result


def test_coarse_figures_never_lie_above_the_fine_exact_minima(coarse):
    params, result = coarse
    shim = params.shim.thickness_mm
    added = 0
    for name, state in result.summary["states"].items():
        fine = float(T.exact_plays(params, shim, [state["temperature_C"]], angles_per_cycle=FINE).least_arcmin[0])
        assert state["exact_play_min_arcmin"] <= fine + 1e-9, name
        assert state["exact_play_min_arcmin"] >= fine - 2e-3, name  # a bracket, not a loose bound
        assert state["exact_play_bracket_arcmin"] <= 2e-3
        added += state["exact_play_points_added"]
    assert added > 0
    # the exact range: each range's least over the continuous cycle (refined where it can be the least)
    er = result.summary["exact_range"]
    for which in ("operating", "storage"):
        least, at = er[f"{which}_least_play_arcmin"], er[f"{which}_least_play_at_C"]
        fine = float(T.exact_plays(params, shim, [at], angles_per_cycle=FINE).least_arcmin[0])
        assert fine - 2e-3 <= least <= fine + 1e-9, which


def test_the_sampled_minimum_misses_what_the_refinement_finds(coarse):
    _, result = coarse
    warm = result.summary["states"]["warm"]
    assert warm["exact_play_sampled_min_arcmin"] - warm["exact_play_min_arcmin"] > 5e-4


def test_coarse_verdicts_equal_the_default_grids(coarse, template_check):
    _, result = coarse
    default = {v.name: v.level for v in template_check("zhurong_differential").verdicts}
    mine = {v.name: v.level for v in result.verdicts}  # the sweep's verdicts (the check adds its self-checks)
    assert mine == {name: default[name] for name in mine}
