"""Track drive sweep: tooth–sleeve clearance, seated tip gap and tip-to-plate distance over an
engagement cycle, on the generated meshes (cad) and in the exact 2-D model (numpy)."""

import contextlib
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.design import load_template
from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.track_section import ExactSection, plate_boundary
from gearcheck.mechanism import HookError, get
from gearcheck.mechanisms.track import sweep as track_sweep
from gearcheck.report.files import summary_json
from gearcheck.sweep.bodies import Body, MeshData
from gearcheck.sweep.engine import Scene

TEMPLATE = "eod_track_drive"
# Reduced sampling for the tests: 24 steps per cycle (β/24 = 0.61°) still covers the cycle plus
# margins and every link passes in, seated and out; the default (60) only refines the curves.
TEST_STEPS = 24


@pytest.fixture(scope="module")
def model(templates_dir):
    """The layout the mechanism's assembly derives for its sweep."""
    return get("track").assembly(load_template(templates_dir / f"{TEMPLATE}.toml").params).layout


@pytest.fixture(scope="module")
def exact(model):
    return ExactSection(model.gap, model.link)


def verdict_pass(result) -> int:
    """summary.json's ``verdict_pass`` for a sweep result."""
    return json.loads(summary_json(result))["track"]["verdict_pass"]


def seated_link(model, angle=0.0):
    return int(np.flatnonzero(model.wrap.seated_links(angle))[3])


# --- exact 2-D model and pose data (no CAD) ----------------------------------------------------


def test_exact_model_seated_values_match_the_closed_forms(model, exact):
    """A seated sleeve is concentric with its seat (ri − R) and the plate face lies the template gap
    above the tip corner (e from the closed form in analysis): the polyline model measures both,
    within its chord sagitta."""
    j = seated_link(model)
    sleeve, plate = exact.link_distances(tc.sprocket_matrix(0.0), model.wrap.link_matrices(0.0)[j])
    assert sleeve == pytest.approx(model.seating_clearance_mm, abs=exact.sagitta_mm + 1e-9)
    assert plate == pytest.approx(model.tip_gap_mm, abs=exact.sagitta_mm + 1e-9)
    assert exact.sagitta_mm < 1e-4


def test_exact_model_contact_from_both_sides(model, exact):
    """The plate pushed towards the axis by the gap ∓ 0.01 mm clears / enters the tooth."""
    j = seated_link(model)
    pose = model.wrap.link_matrices(0.0)[j]
    s = tc.sprocket_matrix(0.0)

    def pushed(by):
        moved = pose.copy()
        moved[:3, 3] -= by * pose[:3, 1]
        return exact.link_distances(s, moved)[1]

    assert pushed(model.tip_gap_mm - 0.01) == pytest.approx(0.01, abs=1e-6)
    assert pushed(model.tip_gap_mm + 0.01) < 0.0


def test_exact_model_repeats_after_one_cycle(model, exact):
    """After β every pose repeats shifted by one pin (and two grooves): per-link distances agree."""
    beta = model.wrap.cycle_rad
    for angle in (0.1 * beta, 0.55 * beta):
        now = [exact.link_distances(tc.sprocket_matrix(angle), m) for m in model.wrap.link_matrices(angle)]
        later = [exact.link_distances(tc.sprocket_matrix(angle + beta), m)
                 for m in model.wrap.link_matrices(angle + beta)]
        for j in range(2, model.wrap.links - 1):  # link j + 1 later is where link j was
            assert later[j] == pytest.approx(now[j - 1], abs=1e-9)


def test_exact_model_shortcuts_agree_with_the_full_figures(model, exact):
    """The sleeve's clearance alone is link_distances' first figure, and a sleeve or plate called
    clear of the outline without measuring measures clear; over the sweep's poses, new chain and
    one pulled 3 % into the teeth."""
    import dataclasses

    sunk = dataclasses.replace(model.wrap, pitch_mm=model.wrap.pitch_mm * 0.97)
    called_clear = 0
    for wrap in (model.wrap, sunk):
        for a in track_sweep.sweep_angles(wrap, TEST_STEPS)[::3]:
            sprocket = tc.sprocket_matrix(float(a))
            for pose in wrap.link_matrices(float(a)):
                sleeve, plate = exact.link_distances(sprocket, pose)
                assert exact.sleeve_clearance(sprocket, pose) == sleeve
                sleeve_clear, plate_clear = exact.clear_of_outline(sprocket, pose)
                assert (not sleeve_clear or sleeve > 0.0) and (not plate_clear or plate > 0.0)
                called_clear += sleeve_clear + plate_clear
    assert called_clear > 0


def test_plate_boundary_leaves_out_the_part_inside_the_sleeve(model):
    geo = model.link
    segments = plate_boundary(geo)
    r, e = geo.sleeve_radius_mm, geo.plate_offset_mm
    for a, b in segments:
        for t in np.linspace(0, 1, 11):
            assert np.hypot(*(a + t * (b - a))) >= r - 1e-9
    bottom = [(a, b) for a, b in segments if abs(a[1] - e) < 1e-12 and abs(b[1] - e) < 1e-12]
    assert len(bottom) == 1
    assert min(bottom[0][0][0], bottom[0][1][0]) == pytest.approx(math.sqrt(r * r - e * e), abs=1e-9)


def test_sweep_angles_cover_a_cycle_with_margins(model):
    beta = model.wrap.cycle_rad
    angles = track_sweep.sweep_angles(model.wrap, 60, 0.125)
    assert angles[0] < 0.0 and angles[-1] > beta
    assert np.isclose(angles, 0.0).any() and np.isclose(angles, beta).any()
    covered = (angles[-1] - angles[0]) / beta  # margins rounded up to whole steps
    assert 1.25 <= covered <= 1.25 + 2.0 / 60 + 1e-12


def test_sweep_modules_do_not_import_cadquery():
    code = ("import sys, gearcheck.mechanisms.track.mechanism, gearcheck.mechanisms.track.assembly, "
            "gearcheck.mechanisms.track.sweep, gearcheck.mechanisms.track.verdicts, "
            "gearcheck.mechanisms.track.report, gearcheck.geometry.track_section; "
            "sys.exit(any(m.split('.')[0] in ('cadquery', 'OCP') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


# --- the sweep on the generated meshes ----------------------------------------------------------


def counting_progress(counted: list):
    """A pipeline progress factory that records every update."""

    class Bar:
        def update(self, n: int = 1) -> None:
            counted.append(n)

    @contextlib.contextmanager
    def progress(_desc, _total=None, _unit=""):
        yield Bar()

    return progress


def sweep(run, jobs: int = 1, **options):
    return pipeline.sweep(run.design, run.assembly, run.bodies, jobs=jobs, options=options)


@pytest.fixture(scope="module")
def template_run(build_bodies):
    run = build_bodies(TEMPLATE)
    counted = []
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": TEST_STEPS},
                            progress=counting_progress(counted))
    return run.design, run.bodies, result, sum(counted)


@pytest.mark.cad
def test_template_sweep_verdicts_and_figures(template_run):
    loaded, bodies, result, progressed = template_run
    s = result.summary
    bound = s["mesh_error_bound_mm"]
    assert result.passed and verdict_pass(result) == 1, [v for v in result.verdicts if not v.passed]
    assert {v.name for v in result.verdicts} >= {"no_interference", "seated_tip_gap_in_window",
                                                  "min_tip_plate_distance", "contact_proven", "mesh_agrees_with_exact"}
    # coverage: at least one whole cycle, every pose counted by the progress callback
    assert s["cycles_covered"] >= 1.0
    # (the declared chain wear adds the same poses again for the worn chain: tests/test_track_wear.py)
    assert s["poses"] == len(result.rows) == s["wear"]["mesh_declared_poses"]
    assert progressed == 2 * s["poses"]
    assert s["cycle_deg"] == pytest.approx(720.0 / loaded.params.sprocket.teeth)
    # no interference anywhere; the seated sleeve's clearance ri − R is resolved beyond the bound
    assert s["collisions"] == 0 and not any(r["collide"] for r in result.rows)
    assert s["min_tooth_sleeve_clearance_mm"] > bound
    assert s["seated_sleeve_clearance_mm"] == pytest.approx(s["model_seated_sleeve_clearance_mm"], abs=bound)
    # the seated gap is the template's 0.75 mm (mesh: a plane against exact tip-corner vertices)
    assert s["seated_tip_gap_mm"] == pytest.approx(0.75, abs=bound)
    assert s["seated_tip_gap_max_mm"] == pytest.approx(0.75, abs=bound)
    assert s["min_tip_plate_distance_mm"] >= 0.5
    assert s["min_tip_plate_distance_mm"] == pytest.approx(s["seated_tip_gap_mm"], abs=1e-9)
    assert s["min_at_seated_links"] == 1
    # contact from both sides: free at gap − tol, touching at gap + tol, bracket = measured gap
    c = s["contact"]
    assert c["tip_gap_free_at_minus_tol"] == c["tip_gap_touching_at_plus_tol"] == 1
    assert c["tip_gap_free_mm"] <= s["seated_tip_gap_mm"] + 1e-9 <= c["tip_gap_touching_mm"] + 2e-9
    assert (c["tip_gap_free_mm"] + c["tip_gap_touching_mm"]) / 2 == pytest.approx(s["seated_tip_gap_mm"], abs=bound)
    assert c["seat_free_at_minus_tol"] == c["seat_touching_at_plus_tol"] == 1
    assert (c["seat_free_mm"] + c["seat_touching_mm"]) / 2 == pytest.approx(
        s["min_tooth_sleeve_clearance_mm"], abs=bound)
    # mesh and exact 2-D model agree at every pose and link
    assert s["exact"]["max_mesh_deviation_mm"] <= bound
    for row in result.rows:
        assert row["min_tip_plate_distance_mm"] == pytest.approx(row["exact_min_tip_plate_mm"], abs=bound)
        assert row["min_tooth_sleeve_clearance_mm"] == pytest.approx(row["exact_min_tooth_sleeve_mm"], abs=bound)
    # report data: flat rows with the same keys, worst poses for exact confirmation
    keys = set(result.rows[0])
    assert {"angle_deg", "min_tooth_sleeve_clearance_mm", "min_tip_plate_distance_mm", "seated_links",
            "collide"} <= keys and all(set(r) == keys for r in result.rows)
    assert {r["seated_links"] for r in result.rows} <= {8, 9}
    assert len(result.worst_poses) == 2 and result.plots[0].hlines[0][1] == 0.5


@pytest.mark.cad
def test_worst_poses_are_the_reported_minima(template_run):
    """Re-measure the worst poses from their own data (poses as data, nothing else shared)."""
    loaded, bodies, result, _ = template_run
    link = next(b for n, b in bodies.items() if n.startswith("link_"))
    _, plate = track_sweep.split_link_mesh(link.mesh, loaded.params.chain.sleeve_diameter_mm / 2.0)
    scene = Scene([bodies["sprocket"].mesh, plate, MeshData("whole", link.mesh.vertices, link.mesh.faces)])
    sleeve_pose, plate_pose = result.worst_poses
    assert sleeve_pose.part_b in bodies and plate_pose.part_b.endswith(".plate")
    scene.set_pose("sprocket", np.array(sleeve_pose.pose_a))
    scene.set_pose("whole", np.array(sleeve_pose.pose_b))
    assert scene.distance("sprocket", "whole").distance == pytest.approx(sleeve_pose.mesh_distance_mm, abs=1e-9)
    scene.set_pose("sprocket", np.array(plate_pose.pose_a))
    scene.set_pose("plate", np.array(plate_pose.pose_b))
    assert scene.distance("sprocket", "plate").distance == pytest.approx(
        result.summary["min_tip_plate_distance_mm"], abs=1e-9)


@pytest.mark.cad
def test_pose_evaluation_matches_every_query_at_every_pose(build_bodies):
    """The sweep's task (intersection tested only within 1 µm, exact figures from the plan's table)
    gives the figures of every query at every pose, bit for bit: distances, intersections (also
    for a chain pulled into the teeth, where the test runs), and the exact 2-D distances."""
    import dataclasses

    from gearcheck.mechanisms.track import clearance
    from gearcheck.sweep.plan import make_scene

    run = build_bodies(TEMPLATE)
    plan = get("track").plan(run.design.params, run.assembly, run.bodies, {"steps_per_cycle": TEST_STEPS})
    model = run.assembly.layout
    sunk = dataclasses.replace(model, wrap=dataclasses.replace(model.wrap, pitch_mm=model.wrap.pitch_mm * 0.97))
    scene = make_scene(plan.meshes)
    exact = ExactSection(model.gap, model.link)
    angles = clearance.sweep_angles(model.wrap, TEST_STEPS)
    touching = 0
    for m in (model, clearance.worn_model(model), sunk):
        table = clearance.exact_table(m, angles)
        for i in range(0, len(angles), 5):
            a = float(angles[i])
            got = track_sweep.evaluate_pose(scene, m, a)
            sprocket = tc.sprocket_matrix(a)
            scene.set_pose("sprocket", sprocket)
            for j, pose in enumerate(m.wrap.link_matrices(a)):
                scene.set_poses({track_sweep.SLEEVE: pose, track_sweep.PLATE: pose, "link": pose})
                assert got[j, 0] == scene.distance("sprocket", track_sweep.SLEEVE).distance
                assert got[j, 1] == scene.distance("sprocket", track_sweep.PLATE).distance
                assert got[j, 2] == scene.collide("sprocket", "link")
                assert tuple(table[i, j]) == exact.link_distances(sprocket, pose)
                touching += got[j, 2]
    assert touching > 0  # the sunk chain intersects the teeth: the test ran and found it


@pytest.mark.cad
def test_bodies_from_another_wrap_are_refused(build_bodies):
    run = build_bodies(TEMPLATE)
    moved = dict(run.bodies)
    name = "link_03"
    b = run.bodies[name]
    moved[name] = Body(b.mesh, b.pose @ tc.planar_matrix(0.0, 0.0, 0.01), b.error_bound_mm)
    with pytest.raises(ValueError, match="link_03: pose differs"):
        pipeline.sweep(run.design, run.assembly, moved, jobs=1, options={"steps_per_cycle": 2})
    # every link must be a copy of one mesh (the sweep moves one link mesh along the wrap)
    other = dict(run.bodies)
    other[name] = Body(run.bodies["sprocket"].mesh, b.pose, b.error_bound_mm)
    # the plan hook refuses them: its ValueError comes out naming the mechanism and the hook
    with pytest.raises(HookError, match="the track mechanism's plan hook failed: ValueError: .*share one mesh"):
        pipeline.sweep(run.design, run.assembly, other, jobs=1, options={"steps_per_cycle": 2})
    with pytest.raises(HookError, match="plan hook failed: ValueError: track sweep: unknown options"):
        pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps": 2})


@pytest.mark.cad
def test_seated_gap_follows_the_template_gap(build_bodies):
    """--set track_plate.tip_gap_mm=0.5 moves the plate face: the measured seated gap follows, the
    contact bracket with it, and 0.5 mm is still inside the paper's window."""
    result = sweep(build_bodies(TEMPLATE, ("track_plate.tip_gap_mm=0.5",)), jobs=2, steps_per_cycle=12)
    s = result.summary
    bound = s["mesh_error_bound_mm"]
    assert s["seated_tip_gap_mm"] == pytest.approx(0.5, abs=bound)
    assert s["min_tip_plate_distance_mm"] == pytest.approx(0.5, abs=bound)
    c = s["contact"]
    assert (c["tip_gap_free_mm"] + c["tip_gap_touching_mm"]) / 2 == pytest.approx(s["seated_tip_gap_mm"], abs=bound)
    assert s["collisions"] == 0 and result.passed


@pytest.mark.cad
def test_a_gap_below_the_window_fails(build_bodies):
    """A plate 0.3 mm over the tips: measured as such, the window verdicts fail, the rest hold."""
    result = sweep(build_bodies(TEMPLATE, ("track_plate.tip_gap_mm=0.3",)), jobs=1, steps_per_cycle=4)
    verdicts = {v.name: v.passed for v in result.verdicts}
    assert result.summary["seated_tip_gap_mm"] == pytest.approx(0.3, abs=result.summary["mesh_error_bound_mm"])
    assert not verdicts["seated_tip_gap_in_window"] and not verdicts["min_tip_plate_distance"]
    assert verdicts["no_interference"] and verdicts["contact_proven"] and not result.passed
    assert verdict_pass(result) == 0


def test_the_reduce_step_proves_contact_on_the_scene_its_first_work_built(build_bodies, monkeypatch):
    """The contact proofs of the reduce step use one scene whose BVHs the plan's first work builds
    (while the workers start), not a second scene built after the sweep."""
    from gearcheck.executor import SerialExecutor
    from gearcheck.sweep.plan import run_plan

    run = build_bodies(TEMPLATE)
    plan = get("track").plan(run.design.params, run.assembly, run.bodies, {"steps_per_cycle": TEST_STEPS})
    scene = plan.reduce.args[0].scene
    assert plan.first is not None and scene.built == []
    results = run_plan(SerialExecutor(), plan)
    assert sorted(scene.built) == sorted(scene.names)

    def no_new_scene(*_args, **_kwargs):
        raise AssertionError("the reduce step built a scene of its own")

    monkeypatch.setattr(track_sweep, "Scene", no_new_scene)
    outcome = plan.reduce(results)
    assert outcome.summary
