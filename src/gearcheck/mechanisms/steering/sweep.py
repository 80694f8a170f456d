"""The steering sweep as a plan (towing both ways, power mode both ways, on the built meshes) and
its reduction: per-pose rows against the push model and the power-mode model, the figures of
each direction, the summary and the poses to confirm exactly.

What each task does: :mod:`.tasks`. The + direction is the paper's (φ > 0, the first rack tooth
k = rack.first_tooth comes under the pinion); the − direction is its mirror image, swept on the
same meshes (their triangulations are not mirror images).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import stop_phrase, whole_drive
from gearcheck.geometry.rack_pinion_power import power_model_travel
from gearcheck.mechanism import Assembly, SweepPlan, Task
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import meshes as ms
from gearcheck.mechanisms.steering.meshes import PINION, RACK
from gearcheck.results import SweepOutcome, WorstPose

if TYPE_CHECKING:
    from gearcheck.mechanisms.steering.tasks import Kinematics
    from gearcheck.sweep.bodies import Body

# Zero backlash: flanks touch at zero clearance, so the mesh decides contact only to within its
# chord error. A collision whose depth along the travel is within this is contact, deeper is
# interference. 0.02 = the sum of both parts' error bounds at the default 0.01 mm tessellation;
# the check raises it to the bodies' own sum when that is larger.
CONTACT_TOL_MM = 0.02
# Grid steps (events are refined by bisection, so the step sets only the curve sampling and
# how closely the tip-land vertices are caught passing over S2: the standing rack creeps by
# up to the chord sag / sin(polar angle of S2) between samples).
TOWING_STEP_DEG = 0.25
POWER_STEP_DEG = 0.25
OPTIONS = {"towing_step_deg": TOWING_STEP_DEG, "power_step_deg": POWER_STEP_DEG}
# Reach of one towing push: the push model's bound (tip radius / PUSH_NORMAL_MIN per radian) times
# the angle step, plus the contact tolerance (a pose that starts in contact). Power mode: the
# rack turns the pinion at most REACH_MARGIN / (centre height − rack top) rad per mm.
REACH_MARGIN = 1.5


def sign(direction: int) -> str:
    return "+" if direction > 0 else "−"


@dataclass(frozen=True)
class ModelFigures:
    """The analytic figures beside the mesh (:mod:`.analysis`), in degrees and mm."""

    disengage_deg: float
    stand_mm: float
    graze_deg: float
    reengage_deg: float
    continuous_deg: float  # min(towing S1, power S6)
    power_limit_deg: float  # S6 (eq 19)
    s1_deg: float  # towing conjugate end (eq 17)
    # whole drive from the exact contact intervals of every tooth pair (rack_pinion_contact)
    towing_drive_deg: float = math.nan
    towing_drive_event: str = ""
    power_drive_deg: float = math.nan
    power_drive_event: str = ""
    contact_ratio: float = math.nan  # ε at the machined hS4 (eqs 1-2)
    stop_by: str = "G1's tip land grazes S2"  # past the stop, named by the pair that pushed last
    moving_at_end: bool = False  # the rack is still moving at the end of the towing swing

    @classmethod
    def of(cls, g: RackPinionGeometry, tow: an.Towing) -> ModelFigures:
        deg = math.degrees
        towing, power = whole_drive(g)
        return cls(deg(tow.disengage_rad), tow.travel_at_disengage_mm, deg(tow.grazing_end_rad - tow.disengage_rad),
                   deg(tow.reengage_rad), deg(min(an.continuous_towing_angle(g), an.continuous_power_angle(g))),
                   deg(an.continuous_power_angle(g)), deg(an.phi_towing_conjugate_end(g, g.sector_first_tooth)),
                   towing.angle_deg, towing.event, power.angle_deg, power.event,
                   an.contact_ratio(g, g.hS4_mm), stop_phrase(g, tow.last_pusher), math.isnan(tow.disengage_rad))


@dataclass(frozen=True)
class SteeringSweep:
    """What the verdicts and the report read (``SweepOutcome.data``): the per-pose rows, the raw
    task results by direction, the push model's curves at the mesh's angles, each direction's figures, the model
    figures, the contact tolerance and mesh bound, mesh counts and speed figures."""

    rows: list[dict]  # sweep.csv: one per pose
    tow: dict  # direction → towing_task result
    power: dict  # direction → power_task result
    curves: dict  # direction → {"out", "back"}: push-model travel at the mesh's angles
    plus: dict
    minus: dict
    model: ModelFigures
    tol: float  # contact tolerance
    bound: float  # sum of the two meshes' error bounds
    mesh_info: dict
    speed: dict
    travel_at_adams_mm: float  # mesh towing travel at the grid angle nearest ADAMS's disengage
    least_drive_deg: float = math.nan  # continuous_drive_deg: least of the model and the mesh


def plan(params, assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None = None
         ) -> SweepPlan:
    """Towing (both swings, both directions) and power mode on the built meshes; ``options``:
    ``towing_step_deg``, ``power_step_deg`` (grid steps, degrees of pinion angle)."""
    from gearcheck.mechanisms.steering.tasks import Kinematics, power_task, towing_task  # the tasks import FCL

    t_start = time.perf_counter()
    opts = dict(OPTIONS)
    unknown = sorted(set(options or {}) - set(OPTIONS))
    if unknown:
        raise ValueError(f"steering sweep: unknown options {unknown}; known: {sorted(OPTIONS)}")
    opts.update(options or {})
    layout = assembly.layout
    g = layout.geometry
    tow_model = an.analyse_towing(g, layout.towing_max_angle_deg,
                                  extra_deg=an.CHECK_ANGLES_DEG + (an.PAPER["adams_disengage_deg"],))
    model = ModelFigures.of(g, tow_model)

    pinion, rack = bodies[PINION], bodies[RACK]
    bound = pinion.error_bound_mm + rack.error_bound_mm
    tol = max(CONTACT_TOL_MM, bound)
    limit = layout.overlap_limit_mm
    kin = Kinematics.of(assembly)
    centre_height = kin.centre_height_mm
    flanks = ms.rack_flank_faces(g, rack.mesh)
    meshes, mesh_info = ms.sweep_meshes(pinion, rack, centre_height, flanks)
    tip = float(np.hypot(pinion.mesh.vertices[:, 0], pinion.mesh.vertices[:, 1]).max())
    rack_top = float(rack.mesh.vertices[:, 1].max())
    corner = layout.s6_corner
    normal, up = ms.driving_flank(g, rack.mesh, flanks[1], corner)
    profile = ms.pinion_profile(pinion.mesh)

    angles = an.towing_grid(layout.towing_max_angle_deg, opts["towing_step_deg"],
                            an.CHECK_ANGLES_DEG + (an.PAPER["adams_disengage_deg"],))
    # power mode over the towing stroke of the model (past the S6 limit, short of the release)
    stroke = float(tow_model.forward.travel_mm[-1])
    n_power = max(int(math.ceil(math.degrees(stroke / g.pitch_radius) / opts["power_step_deg"])), 2)
    travels = np.linspace(0.0, stroke, n_power + 1)
    reach_travel_per_rad = tip * an.PUSH_RATE_PER_TIP_RADIUS
    reach_angle_per_mm = REACH_MARGIN / (centre_height - rack_top)

    mirror = np.array([-1.0, 1.0])
    tasks: list[Task] = [(towing_task, (kin, d, angles, tol, reach_travel_per_rad, limit)) for d in (+1, -1)]
    tasks += [(power_task, (kin, d, travels, tol, reach_angle_per_mm, limit, profile, corner * m, normal * m,
                            up * m, g.pitch))
              for d, m in ((+1, np.ones(2)), (-1, mirror))]
    weights = [2 * len(angles)] * 2 + [len(travels)] * 2  # poses per task

    paper = an.is_paper_design(params)

    def reduce(results: list) -> SweepOutcome:
        return _reduce(g, kin, model, results, tol, bound, mesh_info, t_start, paper)

    return SweepPlan(meshes, tasks, reduce, weights, "pose", opts)


def _row(mode: str, direction: int, swing: str, angle: float, travel_geom: float, travel_model: float,
         clearance: float) -> dict:
    """One sweep.csv row: the pose, the rack travel from the mesh and from the model at that
    pinion angle, their difference, the FCL distance (0 in contact) and the signed clearance
    (minus the measured depth where the walls collide)."""
    return {
        "mode": mode,
        "direction": direction,
        "swing": swing,
        "pinion_angle_deg": math.degrees(float(angle)),
        "rack_travel_geom_mm": float(travel_geom),
        "rack_travel_model_mm": float(travel_model),
        "deviation_mm": float(travel_geom - travel_model),
        "min_distance_mm": max(float(clearance), 0.0),
        "signed_clearance_mm": float(clearance),
    }


def _towing_rows(g: RackPinionGeometry, tow: dict) -> tuple[list[dict], dict, dict]:
    """Rows of both towing swings with the push model's travel at the same angles."""
    rows, deviation, curves = [], {}, {}
    for d, r in tow.items():
        out = an.sweep(g, r["angles_out"], 0.0, d)
        back = an.sweep(g, r["angles_back"], float(out.travel_mm[-1]), -d)
        curves[d] = {"out": out.travel_mm, "back": back.travel_mm}
        dev = []
        for swing in ("out", "back"):
            for a_, l_g, l_m, c in zip(r[f"angles_{swing}"], r[f"travel_{swing}"], curves[d][swing],
                                       r[f"clearance_{swing}"], strict=True):
                rows.append(_row("towing", d, swing, a_, l_g, l_m, c))
                dev.append(l_g - l_m)
        deviation[d] = float(np.max(np.abs(dev)))
    return rows, deviation, curves


def _power_rows(g: RackPinionGeometry, power: dict) -> tuple[list[dict], dict]:
    """Rows of power mode with the model's travel at the pinion angle the mesh gave."""
    rows, deviation = [], {}
    for d, r in power.items():
        dev = []
        for l_g, a_, c in zip(r["travels"], r["angles"], r["clearance"], strict=True):
            l_m = d * power_model_travel(g, d * a_)
            rows.append(_row("power", d, "drive", a_, l_g, l_m, c))
            dev.append(l_g - l_m)
        deviation[d] = float(np.nanmax(np.abs(dev)))
    return rows, deviation


def towing_conjugate_end(g: RackPinionGeometry, r: dict, tol: float) -> float:
    """Mesh towing (one direction): the first pinion angle (rad, magnitude) at which the rack falls
    more than ``tol`` behind conjugate travel r·φ on the forward swing, linear between grid poses:
    where the mesh's continuous towing drive ends, to within the grid and the contact tolerance."""
    out = np.abs(r["angles_out"])
    lag = g.pitch_radius * out - np.abs(r["travel_out"]) - tol
    over = np.flatnonzero(lag > 0.0)
    if not over.size:
        return float(out[-1])
    i = int(over[0])
    if i == 0:
        return float(out[0])
    a0, a1, l0, l1 = out[i - 1], out[i], lag[i - 1], lag[i]
    return float(a0 + (a1 - a0) * (-l0) / (l1 - l0))


def _direction_summary(r: dict, p: dict, towing_dev: float, power_dev: float, towing_end: float) -> dict:
    """Geometry figures of one direction (angle and travel magnitudes)."""
    deg = math.degrees
    out = r["angles_out"]
    mag, travel = np.abs(out), np.abs(r["travel_out"])
    last_degree = float(travel[-1] - np.interp(mag[-1] - math.radians(1.0), mag, travel))
    i_dis = int(np.searchsorted(np.abs(out), abs(r["disengage"]))) if math.isfinite(r["disengage"]) else len(out)
    past = r["clearance_out"][i_dis:]
    w = r["worst"]
    return {
        "geom_disengage_angle_deg": abs(deg(r["disengage"])),
        "geom_rack_travel_at_disengage_mm": abs(r["stand"]),
        "geom_rack_motion_after_disengage_mm": r["creep"],
        "geom_grazing_span_deg": abs(deg(r["graze_end"] - r["disengage"])),
        "geom_reengage_angle_deg": abs(deg(r["reengage"])),
        # contact proven from both sides: (free, touching) pinion angles of the brackets (disengage:
        # the pinion reaching the rack held one contact tolerance short of its stand)
        "geom_disengage_bracket_at_tol_deg": [abs(deg(a)) for a in r["disengage_bracket"] or (math.nan, math.nan)],
        "geom_reengage_bracket_deg": [abs(deg(a)) for a in r["reengage_bracket"] or (math.nan, math.nan)],
        "geom_continuous_angle_deg": abs(deg(p["limit_angle"])),
        "geom_rack_travel_at_continuous_limit_mm": abs(p["limit_travel"]),
        "geom_raw_corner_contact_angle_deg": abs(deg(p["raw_corner_angle"])),
        "geom_towing_conjugate_end_deg": deg(towing_end),
        # the rack still moving at the end of the swing: it moved more than the contact tolerance
        # over the last degree of the forward swing (no disengage within towing.max_angle_deg)
        "geom_rack_motion_last_degree_mm": last_degree,
        "max_towing_curve_deviation_mm": towing_dev,
        "max_power_curve_deviation_mm": power_dev,
        "min_signed_clearance_mm": float(min(np.min(r["clearance_out"]), np.min(r["clearance_back"]),
                                             np.min(p["clearance"]))),
        "min_clearance_past_disengage_mm": float(np.min(past)) if past.size else math.nan,
        "min_clearance_return_swing_mm": float(np.min(r["clearance_back"])),
        "graze_distance_mm": w.get("distance", math.nan),
        "graze_angle_deg": abs(deg(w.get("angle", math.nan))),
        "graze_contact_shift_mm": w.get("contact_shift", math.nan),
    }


def _least(*values: float) -> float:
    """The least finite value (NaN when there is none)."""
    finite = [v for v in values if math.isfinite(v)]
    return min(finite) if finite else math.nan


def _reduce(g: RackPinionGeometry, kin: Kinematics, model: ModelFigures, results: list, tol: float, bound: float,
            mesh_info: dict, t_start: float, paper: bool = True) -> SweepOutcome:
    P = an.PAPER
    tow = {r["direction"]: r for r in results[:2]}
    power = {r["direction"]: r for r in results[2:]}
    elapsed = time.perf_counter() - t_start

    rows, towing_dev, curves = _towing_rows(g, tow)
    power_rows, power_dev = _power_rows(g, power)
    rows += power_rows
    plus, minus = (_direction_summary(tow[d], power[d], towing_dev[d], power_dev[d],
                                      towing_conjugate_end(g, tow[d], tol)) for d in (+1, -1))
    queries = sum(r["queries"] for r in results)
    speed = {"poses": len(rows), "fcl_queries": queries, "elapsed_s": elapsed, "poses_per_s": len(rows) / elapsed,
             "fcl_queries_per_s": queries / elapsed, "task_seconds": [float(r["seconds"]) for r in results],
             "task_cpu_seconds": [float(r["cpu_seconds"]) for r in results]}
    speed["poses_per_cpu_s"] = len(rows) / sum(speed["task_cpu_seconds"])
    speed["fcl_queries_per_cpu_s"] = queries / sum(speed["task_cpu_seconds"])

    summary = {
        **plus,
        "model_disengage_angle_deg": model.disengage_deg,
        "paper_disengage_angle_deg": P["disengage_deg"],
        "paper_adams_disengage_angle_deg": P["adams_disengage_deg"],
        "paper_test_disengage_angle_deg": P["test_disengage_deg"],
        "model_rack_travel_at_disengage_mm": model.stand_mm,
        "paper_rack_travel_at_disengage_mm": P["travel_disengage_mm"],
        "paper_adams_rack_travel_mm": P["adams_travel_mm"],
        "paper_test_rack_travel_mm": P["test_travel_mm"],
        "model_grazing_span_deg": model.graze_deg,
        "model_reengage_angle_deg": model.reengage_deg,
        "model_continuous_angle_deg": model.continuous_deg,
        "model_continuous_towing_deg": model.towing_drive_deg,
        "model_continuous_power_deg": model.power_drive_deg,
        "continuous_drive_deg": _least(model.towing_drive_deg, model.power_drive_deg,
                                      *(s["geom_continuous_angle_deg"] for s in (plus, minus)),
                                      *(s["geom_towing_conjugate_end_deg"] for s in (plus, minus))),
        "model_contact_ratio": model.contact_ratio,
        "paper_continuous_angle_deg": P["phi_S6_deg"],
        "paper_test_continuous_angle_deg": P["test_continuous_deg"],
        "max_towing_curve_deviation_mm": max(towing_dev.values()),
        "min_signed_clearance_mm": min(plus["min_signed_clearance_mm"], minus["min_signed_clearance_mm"]),
        "contact_tolerance_mm": tol,
        "mesh_error_bound_mm": bound,
        "minus": minus,
        "poses": speed["poses"],
        "fcl_queries": speed["fcl_queries"],
        **mesh_info,
    }
    if not paper:  # the paper's printed figures stand only beside the paper's own design
        summary = {k: v for k, v in summary.items() if not k.startswith("paper_")}

    out_deg = np.degrees(tow[1]["angles_out"])
    travel_at_adams = float(tow[1]["travel_out"][int(np.argmin(np.abs(out_deg - P["adams_disengage_deg"])))])
    over = model.stop_by.replace(" grazes ", " over ")
    worst_poses = [
        WorstPose(f"towing {sign(d)}: closest approach past the disengage ({over})", PINION, RACK,
                  kin.pinion(w["angle"]).tolist(), kin.rack(w["travel"]).tolist(), float(w["distance"]))
        for d in (+1, -1) if (w := tow[d]["worst"])
    ]
    data = SteeringSweep(rows, tow, power, curves, plus, minus, model, tol, bound, mesh_info, speed, travel_at_adams,
                         summary["continuous_drive_deg"])
    timings = {k: v for k, v in speed.items() if k not in ("poses", "fcl_queries")}
    return SweepOutcome(summary, worst_poses, None, timings, data)
