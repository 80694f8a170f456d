"""Steering sweeps on the built meshes: towing and power mode against the exact-polyline push model
and the closed forms of ``analysis`` — and a trimmed rack the check must reject.

Reference values (docs/steering.md, clean model as machined): disengage 76.01° at 110.18 mm,
re-engage 74.06°, G1's tip land grazes S2 for 4.10°, power-mode contact reaches S6 at 62.33°.
"""

import dataclasses
import json
import math

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.design import load_template
from gearcheck.geometry.rack_pinion_power import power_model_angle, power_model_travel, tangency_offset
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering.tasks import Kinematics
from gearcheck.mechanisms.steering.verdicts import TOWING_CURVE_TOL_MM
from gearcheck.report.files import summary_json

TEMPLATE = "nose_wheel_steering"
# Coarser than the default 0.25°: every event is bisected between grid poses, so the step only
# sets the curve sampling and how closely the tip-land vertices are caught passing S2 (creep).
TEST_STEP_DEG = 0.5
# Event angles (disengage, re-engage, grazing) against the push model: the mesh's contacts at
# the events are exact vertices on planes (S1 on the rack flank, S6 on a chord, the tip land's
# vertices), so they land within hundredths of a degree; 0.1° is the figure.
EVENT_TOL_DEG = 0.1
# Power-mode limit: the contact point is the tangency point interpolated between the chord
# midpoints of the pinion mesh (~1 mm chords on a flank whose radius of curvature is ~30 mm); the
# curvature change along a chord leaves a few µm along the flank, and the contact runs along the
# flank at r·sin α = 35.5 mm/rad, so a few hundredths of a degree. 0.1° (60 µm along the flank)
# is the stricter end of the 0.1–0.2°.
CONTINUOUS_TOL_DEG = 0.1
# Travel at the stop: the curve tolerance of the issue (the measured gap is the tip land's creep,
# under 0.02 mm at this step).
TRAVEL_TOL_MM = 0.05


def _model(params):
    g = an.geometry_from_params(params)
    return g, an.analyse_towing(g, params.towing.max_angle_deg)


# ----------------------------------------------------------------------------- pure numpy

def test_tangency_offset_finds_the_touching_point_between_mesh_vertices():
    """A polygon inscribed in a circle (1 mm chords, like the pinion mesh) against a straight
    flank tangent to the circle: the estimate finds the tangent point to well under a µm, where
    the nearest vertex alone is off by up to half a chord."""
    radius, chord = 30.0, 1.0
    step = 2.0 * math.asin(chord / (2.0 * radius))
    centre = np.array([3.0, 40.0])
    worst_estimate = worst_vertex = 0.0
    for phase in np.linspace(0.0, 1.0, 11):
        theta = -math.pi / 2 + (np.arange(-12, 13) + phase) * step
        polygon = centre + radius * np.stack([np.cos(theta), np.sin(theta)], axis=1)
        for tilt in (-0.2, 0.0, 0.3):
            normal = np.array([math.sin(tilt), math.cos(tilt)])  # the flank's outward normal, towards the circle
            up = np.array([normal[1], -normal[0]])
            touching = centre - radius * normal
            corner = touching + 0.7 * up
            vertex = polygon[np.argmin(polygon @ normal)]
            offset = tangency_offset(polygon, vertex, normal, corner, up)
            worst_estimate = max(worst_estimate, abs(offset + 0.7))
            worst_vertex = max(worst_vertex, abs(up @ (vertex - corner) + 0.7))
    assert worst_estimate < 1e-4
    assert worst_vertex > 0.4  # the raw vertex: up to half a chord


def test_power_model_leaves_the_conjugate_line_tangentially_at_S6(templates_dir):
    """Rack drives: L = r·φ up to φS6 (eq 19); then the S6 corner rides the involute and the
    pinion lags, with the same slope at the junction (which is why a lag threshold cannot find
    it), growing with the square of the overshoot."""
    params = load_template(templates_dir / f"{TEMPLATE}.toml", []).params
    g = an.geometry_from_params(params)
    r = g.pitch_radius
    end = an.continuous_power_angle(g) * r
    h = 1e-4
    assert power_model_angle(g, end + h) == pytest.approx(end / r + h / r, abs=1e-9)
    slope_after = (power_model_angle(g, end + 2 * h) - power_model_angle(g, end + h)) / h
    assert slope_after == pytest.approx(1.0 / r, rel=1e-3)
    lag_1, lag_2 = (((end + d) / r - power_model_angle(g, end + d)) for d in (1.0, 2.0))
    assert lag_1 > 0 and lag_2 / lag_1 == pytest.approx(4.0, rel=0.1)
    for travel in (10.0, end - 0.1, end + 0.5, end + 8.0):
        assert power_model_travel(g, power_model_angle(g, travel)) == pytest.approx(travel, abs=1e-8)


# --------------------------------------------------------------------------- on the meshes

def _sweep(run, assembly=None, bodies=None, step_deg: float = TEST_STEP_DEG):
    return pipeline.sweep(run.design, assembly or run.assembly, bodies or run.bodies, jobs=1,
                          options={"towing_step_deg": step_deg, "power_step_deg": step_deg})


def _written(result) -> dict:
    """The steering section of summary.json as the check writes it (verdicts and verdict_pass
    included)."""
    return json.loads(summary_json(result))["steering"]


@pytest.fixture(scope="module")
def checked(build_bodies):
    run = build_bodies(TEMPLATE)
    return run.design.params, run.bodies, _sweep(run)


def _both(summary):
    return summary, summary["minus"]


@pytest.mark.cad
def test_sweep_poses_are_the_cad_poses(build_bodies):
    from gearcheck.geometry.rack_pinion import pinion_pose, rack_pose

    run = build_bodies(TEMPLATE)
    g = an.geometry_from_params(run.design.params)
    kin = Kinematics.of(run.assembly)
    # the meshed bodies sit where the kinematics put them at angle 0 / travel 0 (the CAD poses)
    np.testing.assert_allclose(run.bodies["pinion"].pose, kin.pinion(0.0), atol=1e-12)
    np.testing.assert_allclose(run.bodies["rack"].pose, kin.rack(0.0), atol=1e-12)
    for phi in (0.0, 0.3, -1.2, math.radians(76.0)):
        np.testing.assert_allclose(kin.pinion(phi), pinion_pose(g, phi), atol=1e-12)
    for travel in (0.0, 12.5, -110.2):
        np.testing.assert_allclose(kin.rack(travel), rack_pose(travel), atol=1e-12)


@pytest.mark.cad
def test_rack_stops_where_the_push_model_says(checked):
    params, _, result = checked
    _, tow = _model(params)
    model_deg = math.degrees(tow.disengage_rad)
    assert model_deg == pytest.approx(76.01, abs=0.01)
    for s in _both(result.summary):
        assert s["geom_disengage_angle_deg"] == pytest.approx(model_deg, abs=EVENT_TOL_DEG)
        assert s["geom_rack_travel_at_disengage_mm"] == pytest.approx(tow.travel_at_disengage_mm, abs=TRAVEL_TOL_MM)
        # it then stands: only the tip land's chord vertices nudge it, within the contact tolerance
        assert 0.0 <= s["geom_rack_motion_after_disengage_mm"] <= result.summary["contact_tolerance_mm"]
        assert s["geom_grazing_span_deg"] == pytest.approx(math.degrees(tow.grazing_end_rad - tow.disengage_rad),
                                                           abs=EVENT_TOL_DEG)
        assert s["geom_reengage_angle_deg"] == pytest.approx(math.degrees(tow.reengage_rad), abs=EVENT_TOL_DEG)


@pytest.mark.cad
def test_towing_curve_agrees_with_the_push_model(checked):
    params, _, result = checked
    assert result.summary["max_towing_curve_deviation_mm"] <= TOWING_CURVE_TOL_MM
    towing = [r for r in result.rows if r["mode"] == "towing"]
    swings = {(r["direction"], r["swing"]) for r in towing}
    assert swings == {(1, "out"), (1, "back"), (-1, "out"), (-1, "back")}
    dev = np.array([r["deviation_mm"] for r in towing])
    assert np.max(np.abs(dev)) == pytest.approx(result.summary["max_towing_curve_deviation_mm"], abs=1e-12)
    # the swing really goes out and comes back: the rack leaves 0, stands near 110 mm, returns to 0
    out = [r for r in towing if r["direction"] == 1 and r["swing"] == "out"]
    back = [r for r in towing if r["direction"] == 1 and r["swing"] == "back"]
    assert out[0]["rack_travel_geom_mm"] == pytest.approx(0.0, abs=1e-3)
    assert out[-1]["pinion_angle_deg"] == pytest.approx(params.towing.max_angle_deg)
    assert back[-1]["rack_travel_geom_mm"] == pytest.approx(0.0, abs=1e-3)
    assert min(r["rack_travel_geom_mm"] for r in towing if r["direction"] == -1) == pytest.approx(
        -result.summary["geom_rack_travel_at_disengage_mm"], abs=TRAVEL_TOL_MM)


@pytest.mark.cad
def test_no_interference_and_the_contact_is_reached(checked):
    """Zero backlash: every pose is in contact or clear within the contact tolerance, which is no
    smaller than the two meshes' error bounds; past the stop the grazing pose is a real contact
    (a few µm of rack shift closes it), so the claim is not about a pair pulled apart."""
    _, bodies, result = checked
    s = result.summary
    bound = bodies["pinion"].error_bound_mm + bodies["rack"].error_bound_mm
    assert s["mesh_error_bound_mm"] == pytest.approx(bound)
    assert s["contact_tolerance_mm"] >= bound
    for d in _both(s):
        assert d["min_signed_clearance_mm"] >= -s["contact_tolerance_mm"]
        assert d["min_clearance_past_disengage_mm"] >= -s["contact_tolerance_mm"]
        assert d["min_clearance_return_swing_mm"] >= -s["contact_tolerance_mm"]
        assert 0.0 < d["graze_contact_shift_mm"] <= s["contact_tolerance_mm"]
        assert d["graze_angle_deg"] > d["geom_disengage_angle_deg"]
    assert len(result.worst_poses) == 2
    for w in result.worst_poses:
        assert 0.0 <= w.mesh_distance_mm <= s["contact_tolerance_mm"]
        assert np.asarray(w.pose_a).shape == (4, 4) and np.asarray(w.pose_b).shape == (4, 4)


@pytest.mark.cad
def test_continuous_drive_limit_is_where_the_contact_reaches_S6(checked):
    params, _, result = checked
    g = an.geometry_from_params(params)
    model = math.degrees(an.continuous_power_angle(g))
    assert model == pytest.approx(62.33, abs=0.01)
    assert result.summary["model_continuous_drive_deg"] == pytest.approx(model)
    for s in _both(result.summary):
        assert s["geom_phi_S6_deg"] == pytest.approx(model, abs=CONTINUOUS_TOL_DEG)
        assert s["geom_phi_S6_deg"] >= params.targets.continuous_drive_deg
        assert s["max_power_curve_deviation_mm"] <= TOWING_CURVE_TOL_MM


@pytest.mark.cad
def test_verdicts_and_result_shape(checked):
    _, _, result = checked
    assert result.passed and _written(result)["verdict_pass"] == 1
    assert {v.name for v in result.verdicts} >= {"continuous_drive", "rack_stops", "no_interference_past_disengage",
                                                  "no_interference_reengage", "mesh_agrees_with_exact"}
    keys = set(result.rows[0])
    assert all(set(r) == keys for r in result.rows)
    assert {"mode", "direction", "pinion_angle_deg", "rack_travel_geom_mm", "rack_travel_model_mm",
            "deviation_mm", "min_distance_mm"} <= keys

    def numeric(tree):
        for v in tree.values():
            if isinstance(v, dict):
                yield from numeric(v)
            elif isinstance(v, list):
                yield from v
            else:
                yield v

    assert all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in numeric(result.summary))


@pytest.mark.cad
def test_a_rack_mounted_too_close_jams_and_is_reported(checked, build_bodies):
    """The same meshes with the rack raised 0.1 mm towards the pinion (centre distance short): a
    zero-backlash mesh then has no room, each pinion tooth overlaps its rack space by 2·0.1·tan α
    along the travel (0.093 mm). The check must report interference of that depth."""
    from gearcheck.sweep.bodies import Body

    params, bodies, _ = checked
    run = build_bodies(TEMPLATE)
    raise_mm = 0.1
    rack = bodies["rack"]
    pose = np.array(rack.pose, float)
    pose[1, 3] += raise_mm
    moved = dict(bodies, rack=Body(rack.mesh, pose, rack.error_bound_mm, rack.material, rack.motion))
    # the assembly as mounted: the rack's pose raised (the sweep moves it from there)
    spec = dataclasses.replace(run.assembly.part("rack"), pose=pose)
    mounted = dataclasses.replace(run.assembly, parts=(run.assembly.part("pinion"), spec))
    result = _sweep(run, mounted, moved, step_deg=2.0)
    verdicts = {v.name: v.passed for v in result.verdicts}
    assert not verdicts["no_interference_anywhere"] and not result.passed
    assert _written(result)["verdict_pass"] == 0
    # in conjugate towing (well before the trimmed teeth) every pose overlaps by 2·δ·tan α
    expected = 2.0 * raise_mm * math.tan(math.radians(params.pinion.pressure_angle_deg))
    depth = np.array([-r["signed_clearance_mm"] for r in result.rows
                      if r["mode"] == "towing" and r["swing"] == "out" and abs(r["pinion_angle_deg"]) <= 50.0])
    assert np.all(depth > result.summary["contact_tolerance_mm"])
    assert depth == pytest.approx(np.full(depth.shape, expected), abs=result.summary["mesh_error_bound_mm"])


def test_probe_leaves_an_unmoved_body_where_it_is_with_the_same_results(build_bodies, monkeypatch):
    """The probe skips re-posing a body already at the asked angle or travel: a towing and a power
    task give the same results, bit for bit and query for query, as when every query poses both."""
    from gearcheck.mechanisms.steering import sweep as steering_sweep
    from gearcheck.mechanisms.steering import tasks
    from gearcheck.sweep.plan import make_scene, run_task

    run = build_bodies(TEMPLATE)
    plan = steering_sweep.plan(run.design.params, run.assembly, run.bodies,
                               {"towing_step_deg": 2.0, "power_step_deg": 2.0})
    picked = [plan.tasks[0], plan.tasks[2]]  # power one way, towing both ways
    cached = [run_task(make_scene(plan.meshes), *t) for t in picked]

    def place_always(self, angle, travel, rack_mesh=tasks.RACK):
        self.scene.set_pose(tasks.PINION, self.kin.pinion(angle))
        self.scene.set_pose(rack_mesh, self.kin.rack(travel))

    monkeypatch.setattr(tasks._Probe, "place", place_always)
    posed = [run_task(make_scene(plan.meshes), *t) for t in picked]

    for a, b in zip(cached, posed, strict=True):
        assert _bit_same(a, b)


def test_estimated_contacts_are_the_plain_bisections(build_bodies, monkeypatch):
    """The sweep's shortcuts give the plain path's results, bit for bit, on the template's poses:
    the power mode's pinion angles found from a distance query's estimate (the halving replayed
    around it, the final bracket proven), the pushes without the repeated end queries (the plain
    path: sweep.tools.smallest_clearing_move), and the whole rack asked at a just-bisected contact
    as the rest of it (the plain path: the whole rack)."""
    from gearcheck.geometry import bisect as bisect_module
    from gearcheck.mechanisms.steering import sweep as steering_sweep
    from gearcheck.mechanisms.steering import tasks
    from gearcheck.sweep import tools
    from gearcheck.sweep.plan import make_scene

    run = build_bodies(TEMPLATE)
    plan = steering_sweep.plan(run.design.params, run.assembly, run.bodies)
    power = [t for t in plan.tasks if t[0] is tasks.power_task]
    coarse = steering_sweep.plan(run.design.params, run.assembly, run.bodies, {"towing_step_deg": 1.0})
    picked = power + [t for t in coarse.tasks if t[0] is tasks.towing_task]
    assert len(power) == 2 and len(picked) == 4
    faces = {m.name: len(m.faces) for m in plan.meshes}
    for flanks, rest in tasks.REST_OF.items():  # the flanks and the rest split the swept rack's triangles
        assert faces[flanks] + faces[rest] == faces[tasks.RACK] and faces[flanks] > 0
    proven = []

    def counted(*args, **kwargs):
        found = bisect_module.bisect_predicted(*args, **kwargs)
        proven.append(found is not None)
        return found

    monkeypatch.setattr(tasks, "bisect_predicted", counted)
    fast = [fn(make_scene(plan.meshes), *args) for fn, args in picked]
    monkeypatch.undo()
    assert sum(proven) >= 0.9 * sum(len(t[1][2]) for t in power)  # the estimate decides nearly every pose

    def plain(hits_at, reach, predicted, tol, estimate_at=None):
        return tools.smallest_clearing_move(hits_at, reach, predicted, tol)

    monkeypatch.setattr(tasks, "_clearing_move", plain)
    monkeypatch.setattr(tasks, "REST_OF", {faces: tasks.RACK for faces in tasks.REST_OF})
    slow = [fn(make_scene(plan.meshes), *args) for fn, args in picked]

    for f, s in zip(fast, slow, strict=True):
        assert _bit_same(f, s, skip=("queries",))
        assert f["queries"] < s["queries"]
    assert sum(f["queries"] for f in fast[:2]) < 0.5 * sum(s["queries"] for s in slow[:2])


def _bit_same(a, b, skip: tuple[str, ...] = ()) -> bool:
    """Two task results equal bit for bit (floats and arrays by their bits), timings and the keys
    in ``skip`` aside."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_bit_same(a[k], b[k], skip) for k in a
                                            if "seconds" not in k and k not in skip)
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(_bit_same(x, y, skip) for x, y in zip(a, b, strict=True))
    if isinstance(a, (np.ndarray, float)):
        x, y = np.asarray(a, float), np.asarray(b, float)
        return x.shape == y.shape and np.array_equal(x.view(np.int64), y.view(np.int64))
    return a == b
