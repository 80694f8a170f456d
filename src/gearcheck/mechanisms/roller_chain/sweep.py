"""The roller-chain sweep: the sprocket turns through two tooth pitches (one inner and one outer
link through every place of the wrap: entry span, swinging in, seated, swinging out, exit span),
and FCL on the generated meshes measures at every pose every roller's distance to the teeth,
every link's plates' distance to the sprocket, and whether any link meets it; two gauge planes
measure the top span's height and advance, from which the chain's speed and chordal rise follow.

The inner link's mesh is split by position in its own frame: triangles whose vertices all lie
within d1/2 of a roller axis are that roller (roller a on the origin, roller b one pitch along
+x), the rest its plates; the outer link's triangles within d2/2 of an axis are its pins, the rest
its plates. Each figure is compared with the exact model (:mod:`gearcheck.geometry.roller_chain`:
the exact arcs of the tooth form, the plates' axial gaps); the worst poses are confirmed on the
exact B-rep by the pipeline.

Speed: the gauge planes are flat boxes far above the chain and far to its +x side; the top span's
last roller translates without turning, so its mesh's distance to each plane differs from its
centre's by a constant: differences of these distances are the span's exact motion. The speed at
θ is the mean of the one-sided three-point differences over θ … θ ± 2ε (ε = 1e-4 of a cycle), each
exact to O(ε²) on its side of a handover.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.geometry import roller_chain as rc
from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.roller_chain.assembly import INNER, OUTER, SPROCKET, link_name
from gearcheck.mechanisms.roller_chain.certified import ChainCertificates, certify_chain
from gearcheck.mechanisms.roller_chain.model import RollerChainModel
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.bodies import Body, MeshData, pair_error_bound, submesh
from gearcheck.sweep.engine import Scene

# Sprocket angles per tooth pitch (even: the handovers and the mid-pitch poses are on the grid). A
# seated roller moves R·2π/(16z) ≈ p/16 per step, far less than its radius d1/2 ≈ p/3, so no body
# passes through another between poses.
STEPS_PER_CYCLE = 16
CYCLES = 2
DEFAULT_OPTIONS = {"steps_per_cycle": STEPS_PER_CYCLE}
SPEED_EPS_CYCLES = 1e-4
AXIS_MARGIN_MM = 1e-4
COLLIDE_SKIP_MM = 1e-3
GAUGE_CLEAR_MM = 50.0

ROLLER_A, ROLLER_B, INNER_PLATES, OUTER_PLATES = "roller_a", "roller_b", "inner_plates", "outer_plates"
GAUGE_TOP, GAUGE_SIDE = "gauge_top", "gauge_side"


def split_link_mesh(mesh: MeshData, pitch_mm: float, radius_mm: float, names: tuple[str, ...]) -> list[MeshData]:
    """(body at the origin's axis, body at (p, 0)'s axis, plates) of a link mesh; ``radius_mm`` the
    roller's (inner link) or the pin's (outer link)."""
    v, f = mesh.vertices, mesh.faces
    ra = np.hypot(v[:, 0], v[:, 1])
    rb = np.hypot(v[:, 0] - pitch_mm, v[:, 1])
    lim = radius_mm + AXIS_MARGIN_MM
    on_a = np.all(ra[f] <= lim, axis=1)
    on_b = np.all(rb[f] <= lim, axis=1)
    plates = ~(on_a | on_b)
    if not (on_a.any() and on_b.any() and plates.any()):
        raise ValueError("link mesh does not split into its two axes' bodies and its plates")
    return [submesh(mesh, names[0], on_a), submesh(mesh, names[1], on_b), submesh(mesh, names[2], plates)]


def box_mesh(name: str, lo, hi) -> MeshData:
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    v = np.array([[x, y, z] for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)], float)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return MeshData(name, v, f)


@dataclass(frozen=True)
class Gauges:
    top_y: float  # lower face of the top gauge
    side_x: float  # left face of the side gauge


def gauges(model: RollerChainModel) -> Gauges:
    w = model.wrap
    r = w.pitch_radius_mm
    return Gauges(r + model.size.plate_depth_mm + GAUGE_CLEAR_MM,
                  r + (w.span + 4) * w.pitch_mm + GAUGE_CLEAR_MM)


def gauge_meshes(model: RollerChainModel) -> list[MeshData]:
    g, w = gauges(model), model.wrap
    big = 10.0 * (w.pitch_radius_mm + w.rollers * w.pitch_mm)
    return [box_mesh(GAUGE_TOP, (-big, g.top_y, -big), (big, g.top_y + 10.0, big)),
            box_mesh(GAUGE_SIDE, (g.side_x, -big, -big), (g.side_x + 10.0, big, big))]


# --------------------------------------------------------------------------------------------
# The task (worker processes: no CadQuery)

def evaluate_pose(scene, wrap: rc.RollerWrap, theta: float) -> dict:
    """At drive angle θ: every roller's mesh distance to the sprocket, every link's plates'
    distance, whether each link meets the sprocket, and the top span's gauge distances at θ − 2ε …
    θ + 2ε (its last roller to the top and side gauges)."""
    scene.set_pose(SPROCKET, wrap.sprocket_matrix(theta))
    poses = wrap.link_matrices(theta)
    rollers = np.zeros(wrap.rollers)
    plates = np.zeros(wrap.links)
    hits = np.zeros(wrap.links)
    for j, pose in enumerate(poses):
        if j % 2 == 0:
            scene.set_poses({ROLLER_A: pose, ROLLER_B: pose, INNER_PLATES: pose})
            rollers[j] = scene.distance(SPROCKET, ROLLER_A).distance
            rollers[j + 1] = scene.distance(SPROCKET, ROLLER_B).distance
            plates[j] = scene.distance(SPROCKET, INNER_PLATES).distance
            near = min(rollers[j], rollers[j + 1], plates[j])
            whole = INNER
        else:
            scene.set_pose(OUTER_PLATES, pose)
            plates[j] = scene.distance(SPROCKET, OUTER_PLATES).distance
            near, whole = plates[j], OUTER
        if not near > COLLIDE_SKIP_MM:
            scene.set_pose(whole, pose)
            hits[j] = float(scene.collide(SPROCKET, whole))
    probe = wrap.links - 1  # an inner link (rollers even): its roller b is the top span's last roller
    eps = SPEED_EPS_CYCLES * wrap.cycle_rad
    gauge = np.zeros((5, 2))
    for k, t in enumerate(theta + eps * np.arange(-2, 3)):
        scene.set_pose(ROLLER_B, wrap.link_matrices(t)[probe])
        gauge[k] = scene.distance(ROLLER_B, GAUGE_TOP).distance, scene.distance(ROLLER_B, GAUGE_SIDE).distance
    return {"rollers": rollers, "plates": plates, "hits": hits, "gauge": gauge}


# --------------------------------------------------------------------------------------------
# Plan

def sweep_options(options: Mapping[str, Any] | None) -> dict:
    unknown = sorted(set(options or {}) - set(DEFAULT_OPTIONS))
    if unknown:
        raise ValueError(f"roller_chain sweep: unknown options {unknown}; known: {sorted(DEFAULT_OPTIONS)}")
    opts = {**DEFAULT_OPTIONS, **(options or {})}
    if int(opts["steps_per_cycle"]) < 2 or int(opts["steps_per_cycle"]) % 2:
        raise ValueError("roller_chain sweep: steps_per_cycle must be even and ≥ 2")
    return opts


def sweep_angles(wrap: rc.RollerWrap, steps_per_cycle: int) -> np.ndarray:
    return np.arange(CYCLES * steps_per_cycle + 1) * (wrap.cycle_rad / steps_per_cycle)


@dataclass(frozen=True)
class _Setup:
    model: RollerChainModel
    angles: np.ndarray
    bound: float
    started: float
    meshes: list
    scene: Scene  # the reduce step's own (the certificates' distance queries); BVHs built on first use


def plan_sweep(assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None = None) -> SweepPlan:
    opts = sweep_options(options)
    model: RollerChainModel = assembly.layout
    wrap = model.wrap
    inner_mesh = bodies[link_name(0)].mesh
    outer_mesh = bodies[link_name(1)].mesh
    p = wrap.pitch_mm
    ra, rb, inner_plates = split_link_mesh(inner_mesh, p, model.roller_radius_mm, (ROLLER_A, ROLLER_B, INNER_PLATES))
    _, _, outer_plates = split_link_mesh(outer_mesh, p, model.outer.pin_radius_mm, ("pin_a", "pin_b", OUTER_PLATES))
    meshes = [bodies[SPROCKET].mesh, ra, rb, inner_plates, outer_plates,
              MeshData(INNER, inner_mesh.vertices, inner_mesh.faces),
              MeshData(OUTER, outer_mesh.vertices, outer_mesh.faces), *gauge_meshes(model)]
    bound = max(pair_error_bound(dict(bodies), SPROCKET, link_name(0)),
                pair_error_bound(dict(bodies), SPROCKET, link_name(1)))
    angles = sweep_angles(wrap, int(opts["steps_per_cycle"]))
    tasks = [(evaluate_pose, (wrap, float(a))) for a in angles]
    setup = _Setup(model, angles, bound, time.perf_counter(), meshes, Scene(meshes))
    return SweepPlan(meshes, tasks, functools.partial(reduce_sweep, setup), options=opts)


# --------------------------------------------------------------------------------------------
# Reduce

@dataclass(frozen=True)
class ChainSweep:
    """The reduced sweep (``SweepOutcome.data``)."""

    model: RollerChainModel
    angles: np.ndarray
    rollers: np.ndarray  # (poses, rollers) mesh clearances
    plates: np.ndarray  # (poses, links) mesh distances
    hits: np.ndarray  # (poses, links) bool
    seated: np.ndarray  # (poses, rollers) bool
    ex_rollers: np.ndarray  # exact
    ex_plates: np.ndarray  # exact where the plate overlaps the teeth in plan (else nan: not compared)
    height: np.ndarray  # top span's height change from the first pose (mesh gauges), mm
    speed: np.ndarray  # top span speed over ω·R (mesh gauges)
    ex_speed: np.ndarray  # exact: sin β of the entry anchor
    bound: float
    roller_dev: float
    plate_dev: float
    ripple: float  # mesh sweep
    rise: float  # mesh sweep, mm
    sweep_s: float
    wear: rc.WearLimit
    replacement_pct: float
    replacement_rule: str
    certified: ChainCertificates  # both figures over the continuous motion (:mod:`.certified`)


def _origin_to_segment(a: np.ndarray, b: np.ndarray) -> float:
    """Distance from the sprocket axis to the segment a–b (the plate's core line)."""
    ab = b - a
    t = min(1.0, max(0.0, -float(a @ ab) / float(ab @ ab)))
    return float(np.hypot(*(a + t * ab)))


def exact_at(model: RollerChainModel, a: float) -> tuple[np.ndarray, np.ndarray]:
    """(roller clearances, plate distances) of the exact model at drive angle ``a``; a plate's
    distance where the plate overlaps the teeth in plan (else NaN: not compared)."""
    wrap, gap, r = model.wrap, model.gap, model.roller_radius_mm
    h = model.size.plate_depth_mm / 2.0
    rollers = rc.roller_clearances(gap, wrap, a, r)
    plates = np.full(wrap.links, np.nan)
    c = wrap.centres(a)
    for j in range(wrap.links):
        # the plate overlaps the tooth row in plan when an end's axis lies within h2/2 of the
        # outline (the roller, r < h2/2, is outside the teeth): then the plates face the tooth
        # sides across the axial gap; the hub (multi-strand) lies under the chord's middle
        if min(rollers[j], rollers[j + 1]) + r < h:
            hub = (_origin_to_segment(c[j], c[j + 1]) - h - model.sprocket.hub_radius_mm
                   if model.strands > 1 else math.inf)
            plates[j] = min(model.plate_gap_mm(j), hub)
    return rollers, plates


def exact_tables(model: RollerChainModel, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(roller clearances, plate distances, top-span speed) of the exact model at the angles."""
    at = [exact_at(model, float(a)) for a in angles]
    speed = np.array([model.wrap.top_speed_ratio(float(a)) for a in angles])
    return np.array([r for r, _ in at]), np.array([p for _, p in at]), speed


def _certify(setup: _Setup, rollers: np.ndarray, plates: np.ndarray, ex_rollers: np.ndarray,
             ex_plates: np.ndarray) -> ChainCertificates:
    """Every roller's clearance and every link's plate distance certified over the continuous
    motion (:mod:`.certified`): on the meshes (distance queries in this process) and on the exact
    model."""
    model, scene, wrap = setup.model, setup.scene, setup.model.wrap
    names = {(0, 0): ROLLER_A, (0, 1): ROLLER_B, (1, 0): INNER_PLATES, (1, 1): OUTER_PLATES}

    def mesh_measure(figure: int, i: int, a: float) -> float:
        link = i - i % 2 if figure == 0 else i  # a roller: its inner link (roller a even, b odd)
        name = names[(figure, i % 2)]
        scene.set_pose(SPROCKET, wrap.sprocket_matrix(a))
        scene.set_pose(name, wrap.link_matrices(a)[link])
        return scene.distance(SPROCKET, name).distance

    @functools.lru_cache(maxsize=64)
    def exact(a: float) -> tuple[np.ndarray, np.ndarray]:
        return exact_at(model, a)

    def exact_measure(figure: int, i: int, a: float) -> float:
        return float(exact(a)[figure][i])

    roller = max(float(np.hypot(m.vertices[:, 0] - x, m.vertices[:, 1]).max())
                 for m, x in ((setup.meshes[1], 0.0), (setup.meshes[2], wrap.pitch_mm)))
    plate = max(float(np.hypot(m.vertices[:, 0], m.vertices[:, 1]).max()) for m in setup.meshes[3:5])
    gaps = np.array([min(model.plate_gap_mm(j), model.hub_gap_mm) for j in range(wrap.links)])
    return certify_chain(wrap, setup.angles, (rollers, plates), (ex_rollers, ex_plates), mesh_measure,
                         exact_measure, (max(roller, model.roller_radius_mm), plate), setup.bound, float(gaps.min()),
                         gaps)


def reduce_sweep(setup: _Setup, results: list) -> SweepOutcome:
    sweep_s = time.perf_counter() - setup.started
    model, angles, bound = setup.model, setup.angles, setup.bound
    wrap = model.wrap
    rollers = np.array([r["rollers"] for r in results])
    plates = np.array([r["plates"] for r in results])
    hits = np.array([r["hits"] for r in results]) > 0.5
    gauge = np.array([r["gauge"] for r in results])  # (poses, 3, 2)
    seated = np.array([wrap.seated(float(a)) for a in angles])
    ex_rollers, ex_plates, ex_speed = exact_tables(model, angles)
    eps = SPEED_EPS_CYCLES * wrap.cycle_rad
    # the side gauge's distance grows as the span moves −x (over the top); one-sided three-point
    # differences (O(ε²) on each side, so exact also at a handover, where the speed has a kink)
    side = gauge[:, :, 1]
    forward = (-3.0 * side[:, 2] + 4.0 * side[:, 3] - side[:, 4]) / (2.0 * eps)
    backward = (3.0 * side[:, 2] - 4.0 * side[:, 1] + side[:, 0]) / (2.0 * eps)
    speed = 0.5 * (forward + backward) / wrap.pitch_radius_mm
    height = -(gauge[:, 2, 0] - gauge[0, 2, 0])
    roller_dev = float(np.max(np.abs(np.where(rollers > COLLIDE_SKIP_MM, rollers - ex_rollers, 0.0))))
    plate_mask = np.isfinite(ex_plates) & (plates > COLLIDE_SKIP_MM)
    plate_dev = float(np.max(np.abs(np.where(plate_mask, plates - np.nan_to_num(ex_plates), 0.0))))
    ripple = float(1.0 - speed.min() / speed.max())
    rise = float(height.max() - height.min())
    replacement, rule = rc.replacement_limit_pct(model.teeth, model.fixed_centres)
    certified = _certify(setup, rollers, plates, ex_rollers, ex_plates)
    data = ChainSweep(model, angles, rollers, plates, hits, seated, ex_rollers, ex_plates, height, speed, ex_speed,
                      bound, roller_dev, plate_dev, ripple, rise, sweep_s,
                      rc.wear_limit(model.gap, model.roller_radius_mm), replacement, rule, certified)
    worst = _worst_poses(data)
    timings = {"sweep_s": sweep_s, "sprocket_poses": len(angles), "poses_per_s": len(angles) / max(sweep_s, 1e-9),
               "certify_s": certified.seconds}
    return SweepOutcome(summary(data), worst, timings, data)


def _worst_poses(d: ChainSweep) -> list[WorstPose]:
    wrap = d.model.wrap
    out = []
    i, k = (int(n) for n in np.unravel_index(int(np.argmin(d.rollers)), d.rollers.shape))
    j = k - k % 2  # the inner link that carries roller k
    a = float(d.angles[i])
    both = float(min(d.rollers[i, j], d.rollers[i, j + 1]))
    out.append(WorstPose(f"roller_chain: least roller–tooth clearance, roller {k} at θ = {math.degrees(a):.3f}°",
                         SPROCKET, f"{link_name(j)}.rollers", wrap.sprocket_matrix(a).tolist(),
                         wrap.link_matrices(a)[j].tolist(), both, key="least_roller_clearance"))
    i, j = (int(n) for n in np.unravel_index(int(np.argmin(d.plates)), d.plates.shape))
    a = float(d.angles[i])
    out.append(WorstPose(f"roller_chain: least plate–sprocket distance, {link_name(j)} at θ = "
                         f"{math.degrees(a):.3f}°", SPROCKET, f"{link_name(j)}.plates",
                         wrap.sprocket_matrix(a).tolist(), wrap.link_matrices(a)[j].tolist(),
                         float(d.plates[i, j]), key="least_plate_distance"))
    return out


def _min(values: np.ndarray, mask: np.ndarray) -> float:
    v = np.where(mask, values, np.inf)
    return float(v.min()) if np.isfinite(v).any() else -1.0


def summary(d: ChainSweep) -> dict:
    m, wrap = d.model, d.model.wrap
    moving = ~d.seated
    return {
        "min_roller_clearance_mm": float(d.rollers.min()),
        "min_seated_roller_clearance_mm": _min(d.rollers, d.seated),
        "max_seated_roller_clearance_mm": float(np.where(d.seated, d.rollers, -np.inf).max()),
        "min_engaging_roller_clearance_mm": _min(d.rollers, moving),
        "min_plate_distance_mm": float(d.plates.min()),
        "collisions": int(d.hits.sum()),
        "speed_ripple_pct": 100.0 * d.ripple,
        "chordal_rise_mm": d.rise,
        "exact": {
            "min_roller_clearance_mm": float(d.ex_rollers.min()),
            "seated_roller_clearance_mm": m.seating_clearance_mm,
            "min_engaging_roller_clearance_mm": _min(d.ex_rollers, moving),
            "min_plate_distance_mm": float(np.nanmin(d.ex_plates)),
            "speed_ripple_pct": 100.0 * rc.speed_ripple(m.teeth),
            "chordal_rise_mm": rc.chordal_rise(wrap.pitch_mm, m.teeth),
            "sampled_speed_ripple_pct": 100.0 * float(1.0 - d.ex_speed.min() / d.ex_speed.max()),
            "max_roller_deviation_mm": d.roller_dev,
            "max_plate_deviation_mm": d.plate_dev,
        },
        "wear": {
            "limit_pct": 100.0 * d.wear.limit,
            "closed_form_pct": 100.0 * d.wear.closed_form,
            "bisection_tolerance_pct": 100.0 * rc.WEAR_TOL,
            "replacement_limit_pct": d.replacement_pct,
            "fixed_centres": int(m.fixed_centres),
        },
        "mesh_error_bound_mm": d.bound,
        "poses": len(d.angles),
        "rollers": wrap.rollers,
        "links": wrap.links,
        "cycle_deg": math.degrees(wrap.cycle_rad),
        "step_deg": math.degrees(float(d.angles[1] - d.angles[0])),
        "seated_rollers_min": int(d.seated.sum(axis=1).min()),
        "seated_rollers_max": int(d.seated.sum(axis=1).max()),
        "certified": d.certified.summary(),
    }
