"""The roller chain's clearances certified over the continuous motion
(gearcheck.mechanisms.roller_chain.certified): the path bounds of a roller and of a link's plates
relative to the sprocket hold against the wrap's own poses sampled finely, the anchors change only
at the events the bound cuts at, the exact plate bound is the least slab gap, and on a coarse grid
the certified minima never lie above the exact model's minima sampled 100× finer, with the same
verdicts."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry import roller_chain as rc
from gearcheck.mechanisms.roller_chain.certified import anchor_events, path_mm

WRAP = rc.RollerWrap.centred(21, 19.05)
REACH = 12.0  # mm: points up to this far from the roller's (the link's first roller's) axis


def _relative(wrap: rc.RollerWrap, link: int, angle: float, points: np.ndarray) -> np.ndarray:
    """Points of link ``link`` (its frame) in the sprocket's frame at drive angle ``angle``."""
    rel = np.linalg.solve(wrap.sprocket_matrix(angle), wrap.link_matrices(angle)[link])
    return points @ rel[:3, :3].T + rel[:3, 3]


@pytest.mark.parametrize("link", [True, False], ids=["plates", "roller"])
def test_the_path_bound_holds_on_the_wraps_own_poses(link):
    rng = np.random.default_rng(11)
    ring = REACH * np.column_stack([np.cos(np.linspace(0, 2 * math.pi, 24)), np.sin(np.linspace(0, 2 * math.pi, 24)),
                                    np.zeros(24)])
    beta, span = WRAP.cycle_rad, 2 * WRAP.cycle_rad
    moving = 0
    for _ in range(150):
        a0 = float(rng.uniform(0.0, span - 0.2 * beta))
        a1 = min(span, a0 + float(rng.uniform(0.0, beta)))
        i = int(rng.integers(0, WRAP.links if link else WRAP.rollers))
        # a roller: its inner link's frame, the ring about that roller's own axis
        owner, centre = (i, 0.0) if link else (i - i % 2 if i < WRAP.links else i - 1, WRAP.pitch_mm * (i % 2))
        if not link and i == WRAP.rollers - 1:
            owner, centre = WRAP.links - 1, WRAP.pitch_mm
        pts = ring + [centre, 0.0, 0.0]
        bound = path_mm(WRAP, i, a0, a1, REACH, link)
        fine = np.linspace(a0, a1, 300)
        placed = np.stack([_relative(WRAP, owner, float(a), pts) for a in fine])
        path = np.linalg.norm(np.diff(placed, axis=0), axis=2).sum(axis=0).max()
        assert path <= bound * (1 + 1e-7) + 1e-9, (i, a0, a1)  # equal where a ring point lies farthest out
        if bound > 0.0:
            moving += 1
        else:
            assert path < 1e-9  # seated throughout: it stands in its seat
    assert moving > 30


def test_the_anchors_change_only_at_the_events():
    angles = np.linspace(0.0, 2 * WRAP.cycle_rad, 4001)
    anchors = [WRAP.anchors(float(a)) for a in angles]
    events = anchor_events(WRAP, float(angles[0]), float(angles[-1]))
    changes = [k for k in range(1, len(angles)) if anchors[k] != anchors[k - 1]]
    assert changes and len(changes) <= len(events)
    for k in changes:  # each change brackets an event
        assert any(angles[k - 1] <= e <= angles[k] for e in events)
    for e in events:  # and each event is a change
        assert WRAP.anchors(e - 1e-7) != WRAP.anchors(e + 1e-7)


COARSE = 6  # sprocket angles per tooth pitch
FINE = 100 * COARSE


@pytest.fixture(scope="module")
def coarse(build_bodies):
    from gearcheck import pipeline

    run = build_bodies("roller_chain_12B_z21")
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": COARSE})
    return run.assembly.layout, result


def _fine_exact(model) -> tuple[np.ndarray, np.ndarray]:
    from gearcheck.mechanisms.roller_chain.sweep import exact_tables, sweep_angles

    rollers, plates, _ = exact_tables(model, sweep_angles(model.wrap, FINE))
    return rollers, plates


def test_coarse_certified_minima_never_lie_above_the_fine_exact_minima(coarse):
    model, result = coarse
    s = result.summary
    cert = s["certified"]
    rollers, plates = _fine_exact(model)
    fine_roller, fine_plate = float(rollers.min()), float(np.nanmin(plates))
    assert cert["exact_roller_certified_min_mm"] <= fine_roller + 1e-12
    assert cert["exact_roller_certified_min_mm"] >= fine_roller - 1e-3  # sharpened towards the figure
    assert cert["roller_certified_min_mm"] <= fine_roller + s["mesh_error_bound_mm"]
    # the plates: the least slab gap, which the fine sampling meets and never undercuts
    assert cert["exact_plate_certified_min_mm"] == pytest.approx(fine_plate, abs=1e-12)
    assert cert["plate_certified_min_mm"] <= fine_plate + s["mesh_error_bound_mm"]
    assert cert["exact_roller_intervals_refined"] > 0 and cert["roller_undecided_intervals"] == 0


def test_coarse_verdicts_equal_the_fine_grids(coarse):
    model, result = coarse
    rollers, plates = _fine_exact(model)
    levels = {v.name: v.level for v in result.verdicts}
    assert (levels["no_interference"] == "pass") == (rollers.min() > 0 and np.nanmin(plates) > 0)
    assert (levels["roller_tooth_clearance"] == "pass") == (rollers.min() > 0)
    assert (levels["plates_clear_teeth"] == "pass") == (np.nanmin(plates) > 0)
    text = next(v for v in result.verdicts if v.name == "roller_tooth_clearance").measured
    assert "over the continuous motion" in text
