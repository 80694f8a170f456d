"""The differential's mesh contacts found in few FCL queries are the plain bisection's, bit for bit.

Two shortcuts are checked here against the slow path they replace: the halving replayed around an
estimate (a congruent pair's contact, or a distance query's), and every thermal state sharing the
meshes as built (a uniform scale of the world changes no contact).
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from gearcheck.geometry.bisect import bisect, bisect_predicted


def test_replayed_halving_is_the_plain_bisection():
    rng = random.Random(7)
    for _ in range(400):
        lo, hi = sorted(rng.uniform(-5.0, 5.0) for _ in range(2))
        threshold = rng.uniform(lo, hi)
        tol = 10 ** rng.uniform(-9, -3)
        flip = rng.random() < 0.5  # touching end below as well as above
        free, touching = (hi, lo) if flip else (lo, hi)
        asked = []

        def flag(x: float, t=threshold, f=flip, a=asked) -> bool:
            a.append(x)
            return x <= t if f else x >= t

        plain = bisect(flag, free, touching, tol, check_ends=False)
        plain_calls = len(asked)
        # a good estimate: the same bracket, and only a few calls
        margin = tol
        found = bisect_predicted(flag, free, touching, tol, threshold + rng.uniform(-0.5, 0.5) * tol, margin)
        assert found is not None
        bracket, calls = found
        assert (bracket.free, bracket.touching) == (plain.free, plain.touching)
        assert calls <= 6 and (calls < plain_calls or plain_calls <= 6)
        # a wrong estimate: no bracket is made up (None), or the one found is proven and still exact
        wrong = bisect_predicted(flag, free, touching, tol, threshold + rng.choice((-1, 1)) * 50 * tol, tol)
        if wrong is not None:
            assert (wrong[0].free, wrong[0].touching) == (plain.free, plain.touching)


def test_answers_carried_between_tries_are_used_and_change_nothing():
    """A wider try after a missed narrow one, sharing the answers: the plain bisection's bracket,
    no turn asked twice, and fewer calls than the wide try alone."""
    rng = random.Random(11)
    saved = 0
    for _ in range(300):
        lo, hi = sorted(rng.uniform(-5.0, 5.0) for _ in range(2))
        threshold = rng.uniform(lo, hi)
        tol = (hi - lo) * 10 ** rng.uniform(-6, -3)
        flip = rng.random() < 0.5
        free, touching = (hi, lo) if flip else (lo, hi)
        calls: list[float] = []

        def flag(x: float, t=threshold, f=flip, c=calls) -> bool:
            c.append(x)
            return x <= t if f else x >= t

        plain = bisect(flag, free, touching, tol, check_ends=False)
        sign = 1.0 if touching > free else -1.0
        estimate = threshold + sign * rng.uniform(2.0, 80.0) * tol  # an overshoot, as the meshes' misses are
        calls.clear()
        asked: dict[float, bool] = {}
        assert bisect_predicted(flag, free, touching, tol, estimate, 0.5 * tol, asked=asked) is None
        found = bisect_predicted(flag, free, touching, tol, estimate, 160 * tol, asked=asked)
        assert found is not None
        assert (found[0].free, found[0].touching) == (plain.free, plain.touching)
        assert len(calls) == len(set(calls))  # nothing asked twice
        calls.clear()
        alone = bisect_predicted(flag, free, touching, tol, estimate, 160 * tol)
        assert alone is not None and (alone[0].free, alone[0].touching) == (plain.free, plain.touching)
        assert found[1] <= alone[1] == len(calls)  # the wide try's calls, with the answers shared and alone
        saved += alone[1] - found[1]
        # answers that contradict one change decide nothing: the bracket is still proven
        odd = {free + 0.5 * (touching - free): True, free + 0.25 * (touching - free): False,
               free + 0.2 * (touching - free): True}
        mixed = bisect_predicted(flag, free, touching, tol, threshold, tol, asked=dict(odd))
        if mixed is not None:
            assert not flag(mixed[0].free) and flag(mixed[0].touching) and mixed[0].width <= tol
    assert saved > 0


def test_earlier_answers_decide_midpoints_beyond_them_whatever_the_estimate():
    # the plain bracket's two ends already answered: every midpoint is decided by them (one change
    # over the bracket), so even an estimate far off finds that bracket with no new call
    threshold, tol = 0.3141, 1e-6

    def flag(x: float) -> bool:
        return x >= threshold

    plain = bisect(flag, -1.0, 2.0, tol, check_ends=False)
    asked = {plain.free: False, plain.touching: True}
    found = bisect_predicted(flag, -1.0, 2.0, tol, 1.7, 0.0, asked=asked)
    assert found is not None and (found[0].free, found[0].touching) == (plain.free, plain.touching)
    assert found[1] == 0
    assert bisect_predicted(flag, -1.0, 2.0, tol, 1.7, 0.0) is None  # the same estimate alone misses


def test_a_proven_bracket_holds_even_when_the_flag_is_not_monotone():
    # two contacts: flag true on [1, 2] and beyond 3; an estimate near 3 proves a real change there
    def flag(x: float) -> bool:
        return 1.0 <= x <= 2.0 or x >= 3.0

    found = bisect_predicted(flag, 2.5, 4.0, 1e-6, 3.0, 1e-6)
    assert found is not None
    bracket, _ = found
    assert not flag(bracket.free) and flag(bracket.touching) and bracket.width <= 1e-6


@pytest.fixture(scope="module")
def plan_and_run(build_bodies):
    run = build_bodies("zhurong_differential")
    design = run.design
    options = {"angles_per_cycle": 2, "shims_mm": [0.0], "range_shims": "template"}
    plan = design.impl.plan(design.params, run.assembly, run.bodies, options)
    return run, plan


def _contacts(plan, scene, limit):
    from gearcheck.mechanisms.differential import sweep as ds

    out = []
    for fn, args in plan.tasks:
        if fn is ds.measure_contact:
            out.append(fn(scene, *args))
            if len(out) == limit:
                break
    return out


def test_estimated_contacts_are_the_plain_bisections(plan_and_run, monkeypatch):
    from gearcheck.mechanisms.differential import sweep as ds
    from gearcheck.sweep.plan import make_scene

    _, plan = plan_and_run
    scene = make_scene(plan.meshes)
    fast = _contacts(plan, scene, 24)
    # the slow path: no distance estimate, no hint from a congruent pair
    monkeypatch.setattr(ds, "NEWTON_MARGINS_TOL", ())
    original = ds._bisect_mesh
    monkeypatch.setattr(ds, "_bisect_mesh", lambda *a, **k: original(*a[:9]))
    slow = _contacts(plan, scene, 24)
    found_by = set()
    calls = [0, 0]
    for f, s in zip(fast, slow, strict=True):
        for mf, ms in zip(f["mesh"], s["mesh"], strict=True):
            assert (mf["free_rad"], mf["touching_rad"], mf["widened"], mf["centred_collides"]) == \
                   (ms["free_rad"], ms["touching_rad"], ms["widened"], ms["centred_collides"])
            assert ms["found_by"] == "bisection"
            if mf["found_by"] != "bisection":  # else the estimate missed: the plain path ran
                assert mf["calls"] < ms["calls"]
            found_by.add(mf["found_by"])
            calls[0] += mf["calls"]
            calls[1] += ms["calls"]
    assert {"hint", "distance"} <= found_by
    assert calls[0] < 0.6 * calls[1]
    # the fast path's distance estimates were asked between the contact's two teeth
    assert all(args[4] is not None for fn, args in plan.tasks[:24] if fn is ds.measure_contact)


def test_contact_teeth_are_the_meshes_teeth_that_hold_the_nearest_points(plan_and_run):
    """Each task's two contact teeth, cut from the pruned meshes by the worker, are exactly the
    meshes' faces on the tooth the exact contact lies on (as the faces are numbered by their
    centroids), cut once per scene; and the pruned meshes' own nearest points at the exact contact
    lie on those teeth for nearly every contact (where they do not, the estimate may miss and the
    bracket is still proven)."""
    from gearcheck.geometry import bevel_play as bp
    from gearcheck.geometry.bevel_mesh import ToothFaces
    from gearcheck.mechanisms.differential import sweep as ds
    from gearcheck.sweep.plan import make_scene

    _run, plan = plan_and_run
    by_name = {m.name: m for m in plan.meshes}
    scene = make_scene(plan.meshes)
    on_teeth = checked = 0
    for fn, args in plan.tasks:
        if fn is not ds.measure_contact:
            continue
        exact_rad, _d, meshes, _tol, teeth = args
        assert teeth is not None
        big_mesh, small_mesh, big_pose, small_pose, _ = meshes[0]
        poses = {big_mesh: big_pose @ bp.rot_z4(exact_rad), small_mesh: small_pose}
        located = {}
        for mesh, (k, spec) in zip((big_mesh, small_mesh), teeth, strict=True):
            name = ds.cut_tooth(scene, mesh, k, spec)
            assert name is not None and ds.cut_tooth(scene, mesh, k, spec) == name
            whole, part = by_name[mesh], scene.mesh(name)
            tooth = ToothFaces.of(whole.vertices, whole.faces, spec).tooth
            assert len(part.faces) == int(np.sum(tooth == k)) > 0
            assert np.array_equal(np.sort(part.vertices[part.faces].reshape(-1, 9), axis=0),
                                  np.sort(whole.vertices[whole.faces[tooth == k]].reshape(-1, 9), axis=0))
            located[mesh] = (k, spec)
        scene.set_poses(poses)
        near = scene.distance(big_mesh, small_mesh)
        hits = 0
        for mesh, point in ((big_mesh, near.point_a), (small_mesh, near.point_b)):
            k, spec = located[mesh]
            hits += ds.tooth_of(poses[mesh], point, spec) == k
        on_teeth += hits == 2
        checked += 1
        if checked == 40:
            break
    assert checked == 40 and on_teeth >= 34


def test_shared_meshes_decide_contact_as_the_scaled_ones(plan_and_run):
    """Every state's contact bracket, found on the meshes as built (world scaled by the small
    gear's factor), holds on the gears scaled about their datums and posed as in that state."""
    from gearcheck.geometry import bevel_play as bp
    from gearcheck.mechanisms.differential import sweep as ds
    from gearcheck.sweep.engine import Scene
    from gearcheck.sweep.plan import make_scene

    run, plan = plan_and_run
    setup = plan.reduce.args[0]
    scene = make_scene(plan.meshes)
    scaled_states = 0
    for (fn, args), owners in zip(plan.tasks, setup.owners, strict=False):
        if fn is not ds.measure_contact:
            continue
        result = fn(scene, *args)
        (i, state, _k, big, small, d) = owners[0]
        thermal = setup.thermal_at[(setup.shims[i], state)]
        tb, ts = thermal[big], thermal[small]
        if tb.scale == 1.0:
            continue
        scaled_states += 1
        # the same pair in the old form: each gear's vertices scaled about its datum, cold pose
        mesh_big = ds.mesh_name(big, small, d, "big", "")
        mesh_small = ds.mesh_name(big, small, d, "small", "")
        by_name = {m.name: m for m in plan.meshes}
        from gearcheck.sweep.bodies import Body

        def scaled(name, th):
            return Body(by_name[name], np.eye(4), 0.0).scaled(th.scale, th.datum_local).mesh

        old = Scene([scaled(mesh_big, tb), scaled(mesh_small, ts)])
        _, _, big_pose, small_pose, _ = args[2][0]
        # undo the normalisation: the old poses are the cold poses of the datum-scaled meshes
        phi_poses = {big: big_pose.copy(), small: small_pose.copy()}
        for name, th in ((big, tb), (small, ts)):
            phi_poses[name][:3, 3] *= ts.scale
            shift = np.eye(4)
            shift[:3, 3] = (1.0 - th.scale) * th.datum_local
            phi_poses[name] = phi_poses[name] @ np.linalg.inv(shift)
        old.set_pose(mesh_small, phi_poses[small])
        m = result["mesh"][0]
        for turn, expected in ((m["free_rad"], False), (m["touching_rad"], True)):
            old.set_pose(mesh_big, phi_poses[big] @ bp.rot_z4(turn))
            assert old.collide(mesh_big, mesh_small) is expected
        if scaled_states >= 8:
            break
    assert scaled_states >= 8
    assert math.isfinite(setup.bound_arcmin)


def test_tasks_run_grouped_by_their_meshes_in_two_halves_with_the_exact_range_between(plan_and_run):
    """Two processes (workers from the front, the calling process from the back) each build the
    BVHs of their own half of the mesh groups and meet in the exact range tasks (no mesh)."""
    from gearcheck.mechanisms.differential import sweep as ds

    _, plan = plan_and_run
    order = plan.order
    assert sorted(order) == list(range(len(plan.tasks)))
    kinds = [plan.tasks[i][0] for i in order]
    ranged = [j for j, k in enumerate(kinds) if k is ds.exact_range_task]
    assert ranged == list(range(ranged[0], ranged[-1] + 1))  # side by side
    front, back = order[:ranged[0]], order[ranged[-1] + 1:]
    assert all(kinds[j] is ds.measure_contact for j in range(len(kinds)) if j not in ranged)

    def groups_of(part: list[int]) -> list[tuple]:
        return [tuple(sorted(n for entry in plan.tasks[i][1][2] for n in entry[:2])) for i in part]

    groups = groups_of(front) + groups_of(back)
    runs = [g for j, g in enumerate(groups) if j == 0 or g != groups[j - 1]]
    assert len(runs) == len(set(groups)) >= 2  # each group's tasks side by side, once
    assert not set(groups_of(front)) & set(groups_of(back))  # no mesh group in both halves
    assert not {n for g in groups_of(front) for n in g} & {n for g in groups_of(back) for n in g}
    weight = [sum(plan.weights[i] for i in part) for part in (front, back)]
    largest = max(sum(plan.weights[i] for i in front + back if groups_of([i])[0] == g) for g in set(groups))
    assert front and back and abs(weight[0] - weight[1]) <= largest  # the halves about even
    # every pruned mesh is used by some task; a group uses a few of them
    assert {n for g in groups for n in g} == {m.name for m in plan.meshes}
    assert max(len(g) for g in groups) < len(plan.meshes)


def test_worst_pose_distances_on_the_shared_whole_meshes_are_the_scaled_parts(plan_and_run):
    """The reduce step measures the worst poses on the whole meshes as built (world scaled by the
    small gear's factor); the same poses on the parts scaled as the report states them (each
    part's mesh scaled about its frame origin, posed by the worst pose) give the same distance."""
    from gearcheck.executor import SerialExecutor
    from gearcheck.sweep.engine import Scene
    from gearcheck.sweep.plan import make_scene, run_task

    run, plan = plan_and_run
    results = SerialExecutor().map(run_task, plan.tasks, setup=make_scene, shared=plan.meshes, first=plan.first)
    outcome = plan.reduce(results)
    assert len(outcome.worst_poses) == 2
    for worst in outcome.worst_poses:
        scene = Scene([run.bodies[worst.part_a].scaled(worst.scale_a).mesh,
                       run.bodies[worst.part_b].scaled(worst.scale_b).mesh])
        scene.set_pose(worst.part_a, np.asarray(worst.pose_a))
        scene.set_pose(worst.part_b, np.asarray(worst.pose_b))
        expected = scene.distance(worst.part_a, worst.part_b)
        assert worst.mesh_distance_mm == pytest.approx(expected.distance, rel=1e-9, abs=1e-12)
        # what the confirmation would otherwise ask the meshes itself
        assert worst.mesh_overlap is scene.collide(worst.part_a, worst.part_b)
        midpoint = 0.5 * (expected.point_a + expected.point_b)
        assert np.allclose(worst.mesh_nearest_midpoint, midpoint, rtol=0.0, atol=1e-9)
    assert worst.scale_a != 1.0  # a cold state: the normalisation is exercised
