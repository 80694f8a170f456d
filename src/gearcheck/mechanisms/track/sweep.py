"""Track drive sweep: the sprocket turns, the chain advances, links swing into and out of mesh;
FCL on the generated meshes measures tooth–sleeve clearance and tip-to-plate distance at every
pose, and an exact 2-D model (:mod:`gearcheck.geometry.track_section`) checks every figure.

Poses are data (:class:`gearcheck.geometry.track_chain.ChainWrap`): at drive angle θ the sprocket
is ``sprocket_matrix(θ)`` and link j is ``wrap.link_matrices(θ)[j]``; every link body shares one
mesh in the link frame. One engagement cycle is β = 2·360°/z of sprocket rotation; after it every
pose repeats with the pin numbers shifted by one and the sprocket turned by two grooves, which is
one of its symmetries. So sweeping θ over one cycle moves every link of the segment through its
own stretch of the path, and together they cover the whole path (entry run, swinging in, seated,
swinging out, exit run). The sweep runs from −margin to β + margin so both ends of the cycle are
inside it.

The link solid is the sleeve fused with the plate, but the two clearances belong to different
features: the sleeve sits in its seat (ri − R, 0.1 mm) and the plate face over the tooth tip
(the tip gap, 0.75 mm). The link mesh is therefore split by position in the link frame
(:func:`split_link_mesh`): triangles whose vertices all lie within R of the pin axis are the
sleeve, the rest the plate.

The mesh sweep must agree with the exact 2-D model within the mesh-error bound at every pose and
link; the worst clearances are then proven from both sides (free at −tol, touching at +tol) in
this process.
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.track import GAP_CHECK_STEP_MM, analysis
from gearcheck.mechanisms.track import wear as track_wear
from gearcheck.mechanisms.track.assembly import LINK, SPROCKET, TrackModel
from gearcheck.mechanisms.track.certified import TrackCertificates, certify_track, reach_xy
from gearcheck.mechanisms.track.clearance import (CYCLE_MARGIN_FRACTION, STEPS_PER_CYCLE, exact_section,
                                                  exact_table, sweep_angles, worn_model)
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.bodies import Body, MeshData, pair_error_bound, submesh
from gearcheck.sweep.engine import Scene
from gearcheck.sweep.tools import ContactProof, prove_contact

# Sprocket angles per engagement cycle β: STEPS_PER_CYCLE (60: step β/60 = 0.245°, a seated pin
# moves 0.50 mm per step, far less than the 8 mm sleeve, so no body can pass through another
# between poses), and CYCLE_MARGIN_FRACTION of a cycle before θ = 0 and after β (see .clearance).
DEFAULT_OPTIONS = {"steps_per_cycle": STEPS_PER_CYCLE, "margin_fraction": CYCLE_MARGIN_FRACTION}
# Contact is judged with this tolerance, or the mesh-error bound if that is larger: pushed by the
# measured gap − tolerance the pair must be free, by gap + tolerance it must collide.
CONTACT_TOLERANCE_MM = 0.02
# Bisection on the push distance stops at this bracket width.
BISECTION_TOL_MM = 1e-5
# A link-mesh triangle belongs to the sleeve when all its vertices lie within R + this of the pin
# axis (mesh vertices lie on the B-rep surfaces; plate triangles reach out to the plate's far edges).
SLEEVE_SELECT_MARGIN_MM = 1e-4
# A link whose sleeve and plate both lie farther than this (mm) from the sprocket cannot intersect it
# (FCL's distance is 0 between surfaces that meet; 1 µm is far above its rounding at this size).
COLLIDE_SKIP_MM = 1e-3
# Rounding of measured values against the paper's window (report precision, 1 µm).
WINDOW_ROUNDING_MM = 1e-6

SLEEVE, PLATE = "sleeve", "plate"


def split_link_mesh(mesh: MeshData, sleeve_radius_mm: float,
                    margin_mm: float = SLEEVE_SELECT_MARGIN_MM) -> tuple[MeshData, MeshData]:
    """(sleeve, plate) sub-meshes of the fused link mesh (link frame: pin axis = z axis).

    Sleeve: triangles with every vertex within R + margin of the pin axis (its cylinder and the
    discs of its end faces); plate: the rest. The pieces are open surfaces, which is all FCL's
    mesh distance and collision need.
    """
    v, f = mesh.vertices, mesh.faces
    radius = np.hypot(v[:, 0], v[:, 1])
    on_sleeve = np.all(radius[f] <= sleeve_radius_mm + margin_mm, axis=1)
    if on_sleeve.all() or not on_sleeve.any():
        raise ValueError("link mesh does not split into sleeve and plate")
    return submesh(mesh, SLEEVE, on_sleeve), submesh(mesh, PLATE, ~on_sleeve)


# --------------------------------------------------------------------------------------------
# The task (runs in worker processes)

def evaluate_pose(scene: Scene, model: TrackModel, angle_rad: float) -> np.ndarray:
    """(links, 3) per link at drive angle θ: mesh sprocket–sleeve distance, mesh sprocket–plate
    distance (mm), and whether the sprocket and the whole link mesh intersect (1/0).

    The intersection test runs only where the sleeve or the plate comes within
    :data:`COLLIDE_SKIP_MM` of the sprocket: the link's surface is the sleeve's triangles and the
    plate's (:func:`split_link_mesh` parts them), and FCL's distance is 0 between surfaces that
    meet, so a link farther than that from the sprocket cannot intersect it (the test would say
    no). The exact 2-D figures of the same poses are computed once, in the process that plans
    and reduces (:func:`.clearance.exact_table`)."""
    sprocket = tc.sprocket_matrix(angle_rad)
    scene.set_pose(SPROCKET, sprocket)
    poses = model.wrap.link_matrices(angle_rad)
    out = np.zeros((len(poses), 3))
    for j, pose in enumerate(poses):
        scene.set_poses({SLEEVE: pose, PLATE: pose})
        out[j, 0] = scene.distance(SPROCKET, SLEEVE).distance
        out[j, 1] = scene.distance(SPROCKET, PLATE).distance
        if not (out[j, 0] > COLLIDE_SKIP_MM and out[j, 1] > COLLIDE_SKIP_MM):  # (a NaN would be tested)
            scene.set_pose(LINK, pose)
            out[j, 2] = scene.collide(SPROCKET, LINK)
    return out


# --------------------------------------------------------------------------------------------
# The plan


@dataclass(frozen=True)
class _Setup:
    """What the reduce step needs from the plan (this process only)."""

    model: TrackModel
    names: list[str]
    meshes: list[MeshData]
    bound: float
    contact_tol: float
    angles: np.ndarray
    started: float
    scene: Scene  # the reduce step's own (its contact proofs), built while the workers start
    worn_model: TrackModel | None = None  # the same chain re-wrapped at the declared worn pitch
    link_bound: float = 0.0  # the link mesh's own error bound (mm)


def link_names(assembly: Assembly) -> list[str]:
    return [p.name for p in assembly.parts if p.solid == LINK]


def sweep_options(options: Mapping[str, Any] | None) -> dict:
    unknown = sorted(set(options or {}) - set(DEFAULT_OPTIONS))
    if unknown:
        raise ValueError(f"track sweep: unknown options {unknown}; known: {sorted(DEFAULT_OPTIONS)}")
    return {**DEFAULT_OPTIONS, **(options or {})}


def plan_sweep(assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None = None) -> SweepPlan:
    """One task per sprocket angle (:func:`evaluate_pose`), over the sprocket, the link mesh split
    into sleeve and plate, and the whole link."""
    opts = sweep_options(options)
    model: TrackModel = assembly.layout
    names = link_names(assembly)
    first = bodies[names[0]].mesh
    for n in names[1:]:
        m = bodies[n].mesh
        if m.vertices.shape != first.vertices.shape or not np.array_equal(m.faces, first.faces):
            raise ValueError("link bodies do not share one mesh")
    sleeve_mesh, plate_mesh = split_link_mesh(first, model.sleeve_radius_mm)
    meshes = [bodies[SPROCKET].mesh, sleeve_mesh, plate_mesh, MeshData(LINK, first.vertices, first.faces)]
    bound = pair_error_bound(dict(bodies), SPROCKET, names[0])
    angles = sweep_angles(model.wrap, int(opts["steps_per_cycle"]), float(opts["margin_fraction"]))
    tasks = [(evaluate_pose, (model, float(a))) for a in angles]
    # the declared chain wear: the same link solids posed by the worn wrap (pins p·(1 + e) apart),
    # at the same angles, confirm the exact model's worn-pitch sweep on the meshes
    worn = worn_model(model)
    if worn is not None:
        tasks += [(evaluate_pose, (worn, float(a))) for a in angles]
    scene = Scene(meshes)
    setup = _Setup(model, names, meshes, bound, max(CONTACT_TOLERANCE_MM, bound), angles, time.perf_counter(),
                   scene, worn, bodies[names[0]].error_bound_mm)
    return SweepPlan(meshes, tasks, functools.partial(reduce_sweep, setup), options=opts, first=scene.build)


# --------------------------------------------------------------------------------------------
# Reduce


@dataclass(frozen=True)
class Extreme:
    value: float
    pose_index: int
    link: int


def _argmin(values: np.ndarray, mask: np.ndarray) -> Extreme:
    masked = np.where(mask, values, np.inf)
    i, j = np.unravel_index(int(np.argmin(masked)), masked.shape)
    return Extreme(float(masked[i, j]), int(i), int(j))


def rowmin(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    return np.where(mask, values, np.inf).min(axis=1)


def finite(x: float, fallback: float = -1.0) -> float:
    """Summary leaves must be plain finite numbers."""
    return float(x) if math.isfinite(x) else fallback


@dataclass(frozen=True)
class TrackSweep:
    """The reduced sweep (``SweepOutcome.data``): per-pose arrays, extremes, contact proofs."""

    model: TrackModel
    angles: np.ndarray
    names: list[str]
    sleeve_d: np.ndarray  # (poses, links) mesh distances
    plate_d: np.ndarray
    hits: np.ndarray
    ex_sleeve: np.ndarray  # (poses, links) exact 2-D distances
    ex_plate: np.ndarray
    links_seated: np.ndarray
    sleeve_seated: np.ndarray
    x: dict[str, Extreme]  # the extremes, by name (mesh; "ex_…": exact)
    seated_gap_max: float
    max_dev: float
    bound: float
    contact_tol: float
    gap_proof: ContactProof
    sleeve_proof: ContactProof
    gap_point_link: np.ndarray
    whole_link_at_sleeve: float
    model_gap: float
    sleeve_triangles: int
    plate_triangles: int
    outline_step_mm: float
    sagitta_mm: float
    sweep_s: float
    proof_s: float
    wear: track_wear.WearLimit | None = None  # the chain-wear limit (exact 2-D model), see :mod:`.wear`
    worn_mesh: WornMesh | None = None  # the mesh sweep of the chain at the declared worn pitch
    certified: TrackCertificates | None = None  # both figures over the continuous motion (:mod:`.certified`)
    worn_certified: TrackCertificates | None = None  # the same for the chain at the declared worn pitch
    polygon: tc.PolygonEffect | None = None  # the entry run's speed and height over a cycle (the wrap's poses)

    @property
    def collisions(self) -> int:
        return int(self.hits.sum())

    @property
    def colliding_poses(self) -> np.ndarray:
        return np.flatnonzero(self.hits.any(axis=1))

    @property
    def seated_counts(self) -> np.ndarray:
        return self.links_seated.sum(axis=1)

    @property
    def cycle_deg(self) -> float:
        return float(np.degrees(self.model.wrap.cycle_rad))

    def where(self, x: Extreme, sleeve: bool = False) -> str:
        """The link, its state and the angle of an extreme, in words."""
        seated, what = (self.sleeve_seated, "sleeve") if sleeve else (self.links_seated, "link")
        state = "seated" if seated[x.pose_index, x.link] else "off its seat"
        return f"{self.names[x.link]} ({what} {state}) at θ = {np.degrees(self.angles[x.pose_index]):.3f}°"


def _extremes(sleeve_d, plate_d, ex_sleeve, ex_plate, links_seated, sleeve_seated) -> dict[str, Extreme]:
    everything = np.ones_like(links_seated)
    return {
        "min_sleeve": _argmin(sleeve_d, everything),
        "min_plate": _argmin(plate_d, everything),
        "seated_gap": _argmin(plate_d, links_seated),
        "seated_sleeve": _argmin(sleeve_d, sleeve_seated),
        "off_sleeve": _argmin(sleeve_d, ~sleeve_seated),
        "off_plate": _argmin(plate_d, ~links_seated),
        "ex_min_sleeve": _argmin(ex_sleeve, everything),
        "ex_min_plate": _argmin(ex_plate, everything),
        "ex_seated_gap": _argmin(ex_plate, links_seated),
        "ex_seated_sleeve": _argmin(ex_sleeve, sleeve_seated),
        "ex_off_sleeve": _argmin(ex_sleeve, ~sleeve_seated),
        "ex_off_plate": _argmin(ex_plate, ~links_seated),
    }


def _proofs(setup: _Setup, x: dict, sleeve_seated: np.ndarray) -> dict:
    """Contact from both sides at the worst poses (in this process): the seated plate pushed to
    the tip, the worst sleeve pushed into its seat (or towards the nearest tooth point); the
    poses of the worst sleeve and plate, and the whole link's distance at the sleeve's pose."""
    angles, wrap = setup.angles, setup.model.wrap
    t2 = time.perf_counter()
    scene = setup.scene

    def place(index: int) -> tuple[np.ndarray, np.ndarray]:
        a = float(angles[index])
        s = tc.sprocket_matrix(a)
        scene.set_pose(SPROCKET, s)
        return s, wrap.link_matrices(a)

    seated_gap, min_sleeve, min_plate = x["seated_gap"], x["min_sleeve"], x["min_plate"]
    _, links_gap = place(seated_gap.pose_index)
    pose_gap = links_gap[seated_gap.link]
    inward = -pose_gap[:3, 1]  # the link's −y: from the plate face towards the sprocket axis
    gap_proof = prove_contact(scene, SPROCKET, PLATE, pose_gap, inward, seated_gap.value, setup.contact_tol,
                              "plate pushed towards the axis (plate alone: the sleeve would seat first)",
                              BISECTION_TOL_MM)
    scene.set_pose(PLATE, pose_gap)
    near_gap = scene.distance(SPROCKET, PLATE)
    gap_point_link = np.linalg.solve(pose_gap, np.append(near_gap.point_b, 1.0))[:2]

    s_sl, links_sl = place(min_sleeve.pose_index)
    pose_sl = links_sl[min_sleeve.link]
    if sleeve_seated[min_sleeve.pose_index, min_sleeve.link]:
        direction = -pose_sl[:3, 3] * np.array([1.0, 1.0, 0.0])  # radially in, into the seat
        how = "sleeve pushed radially into its seat"
    else:
        scene.set_pose(SLEEVE, pose_sl)
        near = scene.distance(SPROCKET, SLEEVE)
        direction = near.point_a - near.point_b  # from the sleeve's nearest point to the tooth's
        how = "sleeve pushed towards the nearest tooth point"
    sleeve_proof = prove_contact(scene, SPROCKET, SLEEVE, pose_sl, direction, min_sleeve.value, setup.contact_tol,
                                 how, BISECTION_TOL_MM)
    proof_s = time.perf_counter() - t2

    # whole-link distance at the sleeve's worst pose (what an exact B-rep distance of the whole
    # link will measure)
    scene.set_pose(LINK, pose_sl)
    whole_link_at_sleeve = scene.distance(SPROCKET, LINK).distance
    s_pl, links_pl = place(min_plate.pose_index)
    pose_pl = links_pl[min_plate.link]
    return {"gap_proof": gap_proof, "sleeve_proof": sleeve_proof, "gap_point_link": gap_point_link,
            "whole_link_at_sleeve": float(whole_link_at_sleeve), "s_sl": s_sl, "pose_sl": pose_sl,
            "s_pl": s_pl, "pose_pl": pose_pl, "proof_s": proof_s}


@dataclass(frozen=True)
class WornMesh:
    """The mesh sweep of the chain at the declared worn pitch, against the exact 2-D model."""

    poses: int
    collisions: int
    min_sleeve_mm: float
    min_plate_mm: float
    exact_min_sleeve_mm: float
    exact_min_plate_mm: float
    max_dev: float


def _worn_mesh(results: list, exact: np.ndarray | None, reach_mm: float) -> WornMesh | None:
    if not results or exact is None:
        return None
    out = np.array(results)
    sleeve_d, plate_d, hits = (out[..., k] for k in range(3))
    ex_sleeve, ex_plate = exact[..., 0], exact[..., 1]
    dev_sleeve = np.abs(np.where(sleeve_d < reach_mm / 2, sleeve_d - ex_sleeve, 0.0))
    dev_plate = np.abs(np.where(plate_d < reach_mm / 2, plate_d - ex_plate, 0.0))
    return WornMesh(len(out), int((hits > 0.5).sum()), float(sleeve_d.min()), float(plate_d.min()),
                    float(ex_sleeve.min()), float(ex_plate.min()), float(max(dev_sleeve.max(), dev_plate.max())))


def _certify(setup: _Setup, sleeve_d: np.ndarray, plate_d: np.ndarray, table: np.ndarray,
             model: TrackModel | None = None) -> TrackCertificates:
    """Both figures of every link certified over the continuous motion (:mod:`.certified`), on the
    meshes (distance queries in this process where an interval does not decide) and on the exact
    2-D model; the requirements: no interference for the sleeve, the least tip gap for the plate
    (``model``: the chain at the declared worn pitch instead, against no interference alone),
    each at report precision (as the verdicts read them: to half of :data:`WINDOW_ROUNDING_MM`),
    the exact model refined down to that too."""
    worn = model is not None
    model = setup.model if model is None else model
    scene, angles = setup.scene, setup.angles
    exact = exact_section(model)
    wrap = model.wrap
    names = (SLEEVE, PLATE)

    def mesh_measure(figure: int, link: int, a: float) -> float:
        scene.set_pose(SPROCKET, tc.sprocket_matrix(a))
        scene.set_pose(names[figure], wrap.link_matrices(a)[link])
        return scene.distance(SPROCKET, names[figure]).distance

    def exact_measure(figure: int, link: int, a: float) -> float:
        return exact.link_distances(tc.sprocket_matrix(a), wrap.link_matrices(a)[link])[figure]

    reach = (reach_xy(setup.meshes[1].vertices), reach_xy(setup.meshes[2].vertices))
    return certify_track(wrap, angles, (sleeve_d, plate_d), (table[..., 0], table[..., 1]),
                         0.0 if worn else model.required_gap_min_mm, mesh_measure, exact_measure, reach,
                         (setup.bound, 0.5 * WINDOW_ROUNDING_MM), exact.reach_mm, setup.link_bound,
                         0.5 * WINDOW_ROUNDING_MM)


def reduce_sweep(setup: _Setup, results: list) -> SweepOutcome:
    """Extremes over all poses and links, contact proofs at the worst poses, the summary, the
    worst poses for exact confirmation and the smallest clearance decided on."""
    sweep_s = time.perf_counter() - setup.started
    model, angles, names, bound = setup.model, setup.angles, setup.names, setup.bound
    wrap = model.wrap
    out = np.array(results[:len(angles)])  # (poses, links, 3)
    sleeve_d, plate_d, hits = out[..., 0], out[..., 1], out[..., 2] > 0.5
    table = exact_table(model, angles)  # (poses, links, 2), as the plan's smallest clearance read it
    ex_sleeve, ex_plate = table[..., 0], table[..., 1]
    tables = [(model.wrap, angles, table)]
    worn_table = None
    if setup.worn_model is not None:
        worn_table = exact_table(setup.worn_model, angles)
        tables.append((setup.worn_model.wrap, angles, worn_table))
    exact = exact_section(model)
    pins_seated = np.array([wrap.seated_pins(a) for a in angles])
    links_seated = pins_seated[:, :-1] & pins_seated[:, 1:]
    sleeve_seated = pins_seated[:, :-1]  # link j carries the sleeve on pin j

    # compared where the mesh sees the link within half the exact model's reach (farther links
    # do not matter for any minimum; an exact inf there is a disagreement)
    dev_sleeve = np.abs(np.where(sleeve_d < exact.reach_mm / 2, sleeve_d - ex_sleeve, 0.0))
    dev_plate = np.abs(np.where(plate_d < exact.reach_mm / 2, plate_d - ex_plate, 0.0))
    max_dev = float(max(dev_sleeve.max(), dev_plate.max()))
    x = _extremes(sleeve_d, plate_d, ex_sleeve, ex_plate, links_seated, sleeve_seated)
    seated_gap_max = float(np.where(links_seated, plate_d, -np.inf).max())

    pr = _proofs(setup, x, sleeve_seated)
    certified = _certify(setup, sleeve_d, plate_d, table)
    worn_certified = None
    if setup.worn_model is not None and worn_table is not None:
        worn_out = np.array(results[len(angles):])
        worn_certified = _certify(setup, worn_out[..., 0], worn_out[..., 1], worn_table, setup.worn_model)
    min_sleeve, min_plate = x["min_sleeve"], x["min_plate"]
    s_sl, pose_sl, s_pl, pose_pl = pr["s_sl"], pr["pose_sl"], pr["s_pl"], pr["pose_pl"]
    gap_proof, sleeve_proof, gap_point_link = pr["gap_proof"], pr["sleeve_proof"], pr["gap_point_link"]
    whole_link_at_sleeve, proof_s = pr["whole_link_at_sleeve"], pr["proof_s"]
    # the analytical model's tip gap, as `gearcheck calc` measures it on the 2-D outline
    model_gap = analysis.measured_tip_gap(iso606.sprocket_outline(model.gap, GAP_CHECK_STEP_MM), model.gap,
                                          wrap.pitch_mm, model.link.plate_offset_mm)

    data = TrackSweep(model, angles, names, sleeve_d, plate_d, hits, ex_sleeve, ex_plate, links_seated,
                      sleeve_seated, x, seated_gap_max, max_dev, bound, setup.contact_tol, gap_proof, sleeve_proof,
                      gap_point_link, float(whole_link_at_sleeve), model_gap, len(setup.meshes[1].faces),
                      len(setup.meshes[2].faces), exact.step_mm, exact.sagitta_mm, sweep_s, proof_s,
                      wear=track_wear.wear_limit(model.gap, model.link, wrap, model.wear_elongation, tables=tables),
                      worn_mesh=_worn_mesh(results[len(angles):], worn_table, exact.reach_mm), certified=certified,
                      worn_certified=worn_certified, polygon=tc.polygon_effect(wrap))
    worst = [
        WorstPose(f"track: min tooth–sleeve clearance, {data.where(min_sleeve, sleeve=True)}", SPROCKET,
                  names[min_sleeve.link], s_sl.tolist(), pose_sl.tolist(), float(whole_link_at_sleeve)),
        WorstPose(f"track: min tip-to-plate distance, {data.where(min_plate)} (plate alone)", SPROCKET,
                  f"{names[min_plate.link]}.plate", s_pl.tolist(), pose_pl.tolist(), min_plate.value),
    ]
    swept = len(results)  # sprocket poses swept: the new chain's and, where declared, the worn chain's
    timings = {"sweep_s": sweep_s, "sprocket_poses": swept, "poses_per_s": swept / sweep_s,
               "link_poses_per_s": swept * wrap.links / sweep_s, "contact_proof_s": proof_s,
               "certify_s": certified.seconds + (0.0 if worn_certified is None else worn_certified.seconds)}
    return SweepOutcome(summary(data), worst, timings, data)


def summary(d: TrackSweep) -> dict:
    """summary.json's track section (the verdicts are added beside it)."""
    x, model, angles, wrap = d.x, d.model, d.angles, d.model.wrap
    deg = np.degrees
    seated_counts = d.seated_counts
    n_poses = len(angles)
    return {
        "min_tip_plate_distance_mm": x["min_plate"].value,
        "min_tip_plate_angle_deg": float(deg(angles[x["min_plate"].pose_index])),
        "min_tip_plate_link": x["min_plate"].link,
        "min_tip_plate_link_seated": int(d.links_seated[x["min_plate"].pose_index, x["min_plate"].link]),
        "min_tip_plate_unseated_mm": finite(x["off_plate"].value),
        "min_tip_plate_unseated_angle_deg": float(deg(angles[x["off_plate"].pose_index])),
        "seated_tip_gap_mm": x["seated_gap"].value,
        "seated_tip_gap_max_mm": d.seated_gap_max,
        "seated_tip_gap_angle_deg": float(deg(angles[x["seated_gap"].pose_index])),
        "seated_tip_gap_link": x["seated_gap"].link,
        "template_tip_gap_mm": model.tip_gap_mm,
        "model_tip_gap_mm": d.model_gap,
        "min_tooth_sleeve_clearance_mm": x["min_sleeve"].value,
        "min_tooth_sleeve_angle_deg": float(deg(angles[x["min_sleeve"].pose_index])),
        "min_tooth_sleeve_link": x["min_sleeve"].link,
        "min_tooth_sleeve_seated": int(d.sleeve_seated[x["min_sleeve"].pose_index, x["min_sleeve"].link]),
        "seated_sleeve_clearance_mm": x["seated_sleeve"].value,
        "min_tooth_sleeve_unseated_mm": finite(x["off_sleeve"].value),
        "min_tooth_sleeve_unseated_angle_deg": float(deg(angles[x["off_sleeve"].pose_index])),
        "model_seated_sleeve_clearance_mm": model.seating_clearance_mm,
        "exact": {
            "min_tip_plate_distance_mm": x["ex_min_plate"].value,
            "seated_tip_gap_mm": x["ex_seated_gap"].value,
            "min_tip_plate_unseated_mm": finite(x["ex_off_plate"].value),
            "min_tooth_sleeve_clearance_mm": x["ex_min_sleeve"].value,
            "seated_sleeve_clearance_mm": x["ex_seated_sleeve"].value,
            "min_tooth_sleeve_unseated_mm": finite(x["ex_off_sleeve"].value),
            "max_mesh_deviation_mm": d.max_dev,
            "outline_step_mm": d.outline_step_mm,
            "sagitta_bound_mm": d.sagitta_mm,
        },
        "contact": {
            "tip_gap_free_mm": finite(d.gap_proof.free_mm),
            "tip_gap_touching_mm": finite(d.gap_proof.touching_mm),
            "tip_gap_free_at_minus_tol": int(d.gap_proof.free_at_minus),
            "tip_gap_touching_at_plus_tol": int(d.gap_proof.touching_at_plus),
            "seat_free_mm": finite(d.sleeve_proof.free_mm),
            "seat_touching_mm": finite(d.sleeve_proof.touching_mm),
            "seat_free_at_minus_tol": int(d.sleeve_proof.free_at_minus),
            "seat_touching_at_plus_tol": int(d.sleeve_proof.touching_at_plus),
        },
        "mesh_error_bound_mm": d.bound,
        "contact_tolerance_mm": d.contact_tol,
        "collisions": d.collisions,
        "poses": n_poses,
        "links": wrap.links,
        "link_poses": n_poses * wrap.links,
        "cycle_deg": d.cycle_deg,
        "cycles_covered": float((angles[-1] - angles[0]) / wrap.cycle_rad),
        "sweep_start_deg": float(deg(angles[0])),
        "sweep_end_deg": float(deg(angles[-1])),
        "step_deg": float(deg(angles[1] - angles[0])),
        "seated_links_min": int(seated_counts.min()),
        "seated_links_max": int(seated_counts.max()),
        "min_at_seated_links": int(x["ex_off_plate"].value >= x["ex_seated_gap"].value - WINDOW_ROUNDING_MM
                                   and x["ex_off_sleeve"].value >= x["ex_seated_sleeve"].value - WINDOW_ROUNDING_MM),
        **({} if d.wear is None else wear_summary(d.wear, d.worn_mesh, d.bound, d.worn_certified)),
        **({} if d.certified is None else {"certified": d.certified.summary()}),
        **({} if d.polygon is None else {"tca": {"polygon": polygon_summary(d.polygon, wrap)}}),
    }


def polygon_summary(p: tc.PolygonEffect, wrap: tc.ChainWrap) -> dict:
    """The polygon effect measured on the wrap's poses beside its every-other-tooth closed forms."""
    return {"speed_ripple_pct": 100.0 * p.ripple, "chordal_rise_mm": p.rise_mm,
            "closed_form_speed_ripple_pct": 100.0 * tc.speed_ripple(wrap.teeth),
            "closed_form_chordal_rise_mm": tc.chordal_rise(wrap.pitch_mm, wrap.teeth),
            "cycle_deg": float(np.degrees(wrap.cycle_rad)), "samples_per_cycle": int(p.angles.size - 1)}


def wear_summary(w: track_wear.WearLimit, worn: WornMesh | None = None, bound: float = 0.0,
                 certified: TrackCertificates | None = None) -> dict:
    """summary.json's wear figures (exact 2-D model; the mode as its index in ``track_wear.MODES``)
    and, when the declared wear is above zero, the mesh sweep of the worn chain and its clearances
    certified over the continuous motion."""
    mesh = {} if worn is None else {
        "mesh_declared_poses": worn.poses,
        "mesh_declared_collisions": worn.collisions,
        "mesh_declared_min_sleeve_mm": worn.min_sleeve_mm,
        "mesh_declared_min_plate_mm": worn.min_plate_mm,
        "mesh_declared_exact_min_sleeve_mm": finite(worn.exact_min_sleeve_mm),
        "mesh_declared_exact_min_plate_mm": finite(worn.exact_min_plate_mm),
        "mesh_declared_max_deviation_mm": worn.max_dev,
        "mesh_confirms_declared_sweep": int(worn.collisions == 0 and worn.max_dev <= bound
                                            and min(worn.exact_min_sleeve_mm, worn.exact_min_plate_mm) >= 0.0),
        **({} if certified is None else {"mesh_declared_certified": certified.summary()}),
    }
    return {
        "wear_limit_pct": 100.0 * w.limit,
        "wear_elongation_pct": 100.0 * w.declared,
        "wear_limit_mode": w.mode_code,
        "wear": {
            "limit_pct": 100.0 * w.limit,
            "bracket_lo_pct": 100.0 * w.lo,
            "fail_at_pct": finite(100.0 * w.fail_at),
            "limit_is_closed_form": int(w.closed_form),
            "tip_closed_form_pct": 100.0 * w.tip_closed_form,
            "bisection_tolerance_pct": 100.0 * w.tolerance,
            "declared_pct": 100.0 * w.declared,
            "limit_mode": w.mode_code,
            "limit_mode_tip": int(w.mode == "tip"),
            "limit_mode_jump": int(w.mode == "jump"),
            "limit_mode_sweep": int(w.mode == "sweep"),
            "declared_seats": int(w.declared_seat.ok),
            "declared_contact_radius_mm": finite(w.declared_seat.contact_radius_mm),
            "declared_sweep_clear": int(w.declared_sweep.ok),
            "declared_sweep_min_sleeve_mm": finite(w.declared_sweep.min_sleeve_mm),
            "declared_sweep_min_plate_mm": finite(w.declared_sweep.min_plate_mm),
            "decided_by_exact_2d": 1,
            **mesh,
        },
    }
