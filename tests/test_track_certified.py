"""The track's clearances certified over the continuous motion (gearcheck.mechanisms.track.certified):
the path bound of a link relative to the sprocket holds against the wrap's own poses sampled finely,
a seated link does not move, and on coarse grids the certified minima never lie above the exact
model's minima sampled 100× finer, with the same verdicts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry import track_chain as tc
from gearcheck.mechanisms.track.certified import link_path_mm

WRAP = tc.ChainWrap.centred(49, 30.0)
REACH = 20.0  # mm: points of a link up to this far from its own pin axis


def _relative_points(wrap: tc.ChainWrap, link: int, angle: float, points: np.ndarray) -> np.ndarray:
    """The link's points (its frame) in the sprocket's frame at drive angle ``angle``."""
    rel = np.linalg.solve(tc.sprocket_matrix(angle), wrap.link_matrices(angle)[link])
    return points @ rel[:3, :3].T + rel[:3, 3]


def test_the_path_bound_holds_on_the_wraps_own_poses():
    rng = np.random.default_rng(7)
    ring = REACH * np.column_stack([np.cos(np.linspace(0, 2 * math.pi, 24)), np.sin(np.linspace(0, 2 * math.pi, 24)),
                                    np.zeros(24)])
    beta = WRAP.cycle_rad
    checked_moving = 0
    for _ in range(200):
        a0 = float(rng.uniform(-beta, 2 * beta))
        a1 = a0 + float(rng.uniform(0.0, beta))  # up to a whole cycle: seatings inside the interval
        link = int(rng.integers(0, WRAP.links))
        bound = link_path_mm(WRAP, link, a0, a1, REACH)
        fine = np.linspace(a0, a1, 400)
        placed = np.stack([_relative_points(WRAP, link, float(a), ring) for a in fine])
        path = np.linalg.norm(np.diff(placed, axis=0), axis=2).sum(axis=0).max()  # the longest polyline path
        assert path <= bound * (1 + 1e-9) + 1e-9
        if bound > 0.0:
            checked_moving += 1
            assert bound <= 3.0 * path + 1e-6 * REACH or path < 1e-9  # not absurdly loose
        else:
            assert path < 1e-9  # a seated link stands still relative to the sprocket
    assert checked_moving > 50


def test_a_link_seated_at_both_ends_does_not_move():
    angles = np.linspace(0.0, WRAP.cycle_rad, 7)
    seated = [WRAP.seated_links(float(a)) for a in angles]
    link = next(j for j in range(WRAP.links) if all(s[j] for s in seated))
    assert link_path_mm(WRAP, link, float(angles[0]), float(angles[-1]), REACH) == 0.0


# --- on the template's meshes: a coarse grid against the exact model sampled 100× finer ----------

COARSE = 6  # sprocket angles per engagement cycle
FINE = 100 * COARSE


def _fine_exact(model) -> np.ndarray:
    from gearcheck.mechanisms.track.clearance import exact_table, sweep_angles

    return exact_table(model, sweep_angles(model.wrap, FINE))


@pytest.fixture(scope="module", params=[(), ("track_plate.tip_gap_mm=0.3",)], ids=["template", "tip_gap_0.3"])
def coarse(request, build_bodies):
    from gearcheck import pipeline

    run = build_bodies("eod_track_drive", request.param)
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": COARSE})
    return run.assembly.layout, result


def _track(result) -> dict:
    return result.summary.get("track", result.summary)


def test_coarse_certified_minima_never_lie_above_the_fine_exact_minima(coarse):
    model, result = coarse
    track = _track(result)
    cert, fine = track["certified"], _fine_exact(model)
    bound = track["mesh_error_bound_mm"]
    sleeve, plate = float(fine[..., 0].min()), float(fine[..., 1].min())
    # the coarse sweep covers the fine one's range (and a little more): its bounds lie below
    assert cert["exact_sleeve_certified_min_mm"] <= sleeve + 1e-12
    assert cert["exact_plate_certified_min_mm"] <= plate + 1e-12
    assert cert["sleeve_certified_min_mm"] <= sleeve + bound  # the meshes: within their error bound
    assert cert["plate_certified_min_mm"] <= plate + bound
    # and not far below: sharpened towards the figure
    assert cert["exact_sleeve_certified_min_mm"] >= sleeve - 0.02
    assert cert["exact_plate_certified_min_mm"] >= plate - 0.02
    # the coarse samples alone do not see the fine minimum: the refinement found what lies between
    coarse_exact = min(track["exact"]["min_tooth_sleeve_clearance_mm"], track["exact"]["min_tip_plate_distance_mm"])
    assert coarse_exact > min(sleeve, plate) - 1e-12
    assert cert["exact_sleeve_intervals_refined"] + cert["exact_plate_intervals_refined"] > 0


def test_coarse_verdicts_equal_the_fine_grids(coarse):
    from gearcheck.mechanisms.track.verdicts import rounded

    model, result = coarse
    fine = _fine_exact(model)
    levels = {v.name: v.level for v in result.verdicts}
    free = float(fine[..., 0].min()) >= 0.0 and float(fine[..., 1].min()) >= 0.0
    plate_ok = rounded(float(fine[..., 1].min())) >= model.required_gap_min_mm
    assert (levels["no_interference"] == "pass") == free
    assert (levels["min_tip_plate_distance"] == "pass") == plate_ok
    cert = _track(result)["certified"]
    assert cert["sleeve_certified_min_mm"] <= cert["sleeve_sampled_min_mm"]
    assert cert["plate_certified_min_mm"] <= cert["plate_sampled_min_mm"]


def test_the_worn_chain_is_certified_too(coarse):
    from gearcheck.mechanisms.track.clearance import exact_table, sweep_angles, worn_model

    model, result = coarse
    track = _track(result)
    worn = worn_model(model)
    assert worn is not None  # the template declares a chain wear
    cert = track["wear"]["mesh_declared_certified"]
    fine = exact_table(worn, sweep_angles(worn.wrap, FINE))
    sleeve, plate = float(fine[..., 0].min()), float(fine[..., 1].min())
    bound = track["mesh_error_bound_mm"]
    assert cert["exact_sleeve_certified_min_mm"] <= sleeve + 1e-12
    assert cert["exact_plate_certified_min_mm"] <= plate + 1e-12
    assert cert["sleeve_certified_min_mm"] <= sleeve + bound and cert["plate_certified_min_mm"] <= plate + bound
    assert cert["exact_sleeve_certified_min_mm"] >= sleeve - 0.02  # sharpened: the figure that decides
    wear = next(v for v in result.verdicts if v.name == "chain_wear_within_limit")
    assert (wear.level == "pass") == (sleeve >= 0.0 and plate >= 0.0 and track["wear"]["declared_seats"] == 1)
    assert "certified over the continuous motion" in wear.measured


# ----------------------------------------------------------------------------- the polygon effect

@pytest.mark.parametrize("teeth, pitch_mm", [(49, 30.0), (20, 50.8), (31, 19.05)])
def test_the_polygon_effect_on_the_wraps_poses_is_the_closed_form(teeth, pitch_mm):
    """The entry run's speed ripple and chordal rise measured on the wrap's poses over a cycle equal
    those of a z/2-sided polygon, 1 − cos(360°/z) and R·(1 − cos(360°/z)), to 1e-6 (every other
    tooth engages: a link subtends two tooth steps)."""
    wrap = tc.ChainWrap.centred(teeth, pitch_mm)
    effect = tc.polygon_effect(wrap)
    assert effect.ripple == pytest.approx(tc.speed_ripple(teeth), abs=1e-6)
    assert effect.rise_mm == pytest.approx(tc.chordal_rise(pitch_mm, teeth), abs=1e-6)
    # the speed peaks mid-cycle at ω·R (the seated pin at the run's tangent point) and is least at the
    # seatings, where it is continuous across the cycle (the same on both sides)
    assert effect.speed.max() == pytest.approx(1.0, abs=1e-9)
    assert effect.speed[0] == pytest.approx(effect.speed[-1], abs=1e-9) == pytest.approx(effect.speed.min(), abs=1e-9)


def test_the_check_reports_the_polygon_effect(coarse):
    polygon = _track(coarse[1])["tca"]["polygon"]
    assert polygon["speed_ripple_pct"] == pytest.approx(polygon["closed_form_speed_ripple_pct"], abs=1e-4)
    assert polygon["chordal_rise_mm"] == pytest.approx(polygon["closed_form_chordal_rise_mm"], abs=1e-6)
