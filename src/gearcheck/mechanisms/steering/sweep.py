"""The steering sweep as a plan (towing both ways, power mode both ways, on the built meshes) and
its reduction: per-pose rows against the push model and the power-mode model, the figures of
each direction, every tooth pair's conjugate contact interval measured at the swept poses and the
continuous drive they give (:mod:`.handover`; poses are added around every tight hand-over the
exact model predicts), the summary and the poses to confirm exactly.

What each task does: :mod:`.tasks`. The + direction is the paper's (φ > 0, the first rack tooth
k = rack.first_tooth comes under the pinion); the − direction is its mirror image, swept on the
same meshes (their triangulations are not mirror images).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import stop_phrase, whole_drive
from gearcheck.geometry.rack_pinion_power import power_corner, power_model_travel
from gearcheck.mechanism import Assembly, SweepPlan, Task
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import certified as ce
from gearcheck.mechanisms.steering import handover as ho
from gearcheck.mechanisms.steering import meshes as ms
from gearcheck.mechanisms.steering.ends import EndTop, end_tops
from gearcheck.mechanisms.steering.tca import SteeringTca, steering_tca
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
# A step given in ``options`` is cut to at most this share of the angular pitch: a tooth that moves
# most of a pitch between two poses is pushed past a rack tooth, and the sweep loses the mesh (the
# defaults are below it for every tooth count the template allows).
MAX_STEP_PITCHES = 1.0 / 3.0
# Reach of one towing push: the push model's bound (tip radius / PUSH_NORMAL_MIN per radian) times
# the angle step, plus the contact tolerance (a pose that starts in contact). Power mode: the
# rack turns the pinion at most REACH_MARGIN / (centre height − rack top) rad per mm.
REACH_MARGIN = 1.5
# The power stroke reaches at least this far past the model's power-drive limit (deg of pinion
# angle), and at most this share of the travel at which S6 leaves the tip circle (the release).
POWER_PAST_LIMIT_DEG = 1.0
POWER_RELEASE_SHARE = 0.99


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
    # the trimmed end teeth past the tooth that drove them last (hS6, hS8 against the stands, :mod:`.ends`)
    ends: tuple[EndTop, ...] = ()

    @classmethod
    def of(cls, g: RackPinionGeometry, tow: an.Towing) -> ModelFigures:
        deg = math.degrees
        towing, power = whole_drive(g)
        return cls(deg(tow.disengage_rad), tow.travel_at_disengage_mm, deg(tow.grazing_end_rad - tow.disengage_rad),
                   deg(tow.reengage_rad), deg(min(an.continuous_towing_angle(g), an.continuous_power_angle(g))),
                   deg(an.continuous_power_angle(g)), deg(an.phi_towing_conjugate_end(g, g.sector_first_tooth)),
                   towing.angle_deg, towing.event, power.angle_deg, power.event,
                   an.contact_ratio(g, g.hS4_mm), stop_phrase(g, tow.last_pusher), math.isnan(tow.disengage_rad),
                   end_tops(g, tow))


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
    # (mode, direction) → the mesh's continuous drive from the contact intervals it measured
    drives: dict = field(default_factory=dict)
    # how far the mesh's contact ends may lie from the exact model's (deg): the angle of one contact
    # tolerance of rack travel, r·Δφ = tol (the meshed rack lags the exact one by up to the chord sag)
    handover_tol_deg: float = math.nan
    # scope ("anywhere", "return_swing", "past_disengage") → the exact model's clearance certified over
    # the continuous motion (:func:`.certified.summary_entry`; + direction, the − one is its mirror)
    certified: dict = field(default_factory=dict)
    # the transmission error's curves (:class:`.tca.SteeringTca`; None when not computed)
    tca: SteeringTca | None = None

    def drive(self, mode: str, direction: int) -> ho.MeshDrive:
        return self.drives[(mode, direction)]


def plan(params, assembly: Assembly, bodies: Mapping[str, Body], options: Mapping[str, Any] | None = None
         ) -> SweepPlan:
    """Towing (both swings, both directions) and power mode on the built meshes; ``options``:
    ``towing_step_deg``, ``power_step_deg`` (grid steps, degrees of pinion angle)."""
    from gearcheck.mechanisms.steering.tasks import (  # the tasks import FCL
        Kinematics,
        power_task,
        rest_meshes,
        towing_task,
    )

    t_start = time.perf_counter()
    opts = dict(OPTIONS)
    unknown = sorted(set(options or {}) - set(OPTIONS))
    if unknown:
        raise ValueError(f"steering sweep: unknown options {unknown}; known: {sorted(OPTIONS)}")
    opts.update(options or {})
    layout = assembly.layout
    g = layout.geometry
    for key in ("towing_step_deg", "power_step_deg"):
        opts[key] = min(float(opts[key]), MAX_STEP_PITCHES * math.degrees(g.angular_pitch))
    paper = an.is_paper_design(params)
    # a pose at the angle of the paper's ADAMS stop, for the comparison beside the paper's own design
    adams = (an.PAPER["adams_disengage_deg"],) if paper else ()
    tow_model = an.analyse_towing(g, layout.towing_max_angle_deg,
                                  extra_deg=an.CHECK_ANGLES_DEG + adams)
    model = ModelFigures.of(g, tow_model)

    pinion, rack = bodies[PINION], bodies[RACK]
    bound = pinion.error_bound_mm + rack.error_bound_mm
    tol = max(CONTACT_TOL_MM, bound)
    limit = layout.overlap_limit_mm
    kin = Kinematics.of(assembly)
    centre_height = kin.centre_height_mm
    flanks = ms.rack_flank_faces(g, rack.mesh)
    meshes, mesh_info = ms.sweep_meshes(pinion, rack, centre_height, flanks)
    meshes += rest_meshes(next(m for m in meshes if m.name == RACK), g)
    tip = float(np.hypot(pinion.mesh.vertices[:, 0], pinion.mesh.vertices[:, 1]).max())
    rack_top = float(rack.mesh.vertices[:, 1].max())
    corner = layout.s6_corner
    normal, up = ms.driving_flank(g, rack.mesh, flanks[1], corner)
    bore = assembly.solids[PINION].bore_diameter_mm / 2.0
    profile = ms.pinion_profile(pinion.mesh, g.root_radius, bore)

    # extra poses around every tight hand-over the exact model predicts (and inside any gap)
    angles = an.towing_grid(layout.towing_max_angle_deg, opts["towing_step_deg"],
                            an.CHECK_ANGLES_DEG + adams
                            + tuple(ho.extra_angles_deg(g, "towing", layout.towing_max_angle_deg)))
    # power mode over the towing stroke of the model (past the S6 limit, short of the release), and at
    # least a little past the model's power-drive limit when the towing swing is short of it
    beyond_limit = g.pitch_radius * math.radians(model.power_drive_deg + POWER_PAST_LIMIT_DEG)
    stroke = max(float(tow_model.forward.travel_mm[-1]), min(beyond_limit, POWER_RELEASE_SHARE * power_corner(g)[2]))
    n_power = max(int(math.ceil(math.degrees(stroke / g.pitch_radius) / opts["power_step_deg"])), 2)
    extra_travels = [g.pitch_radius * math.radians(a) for a in ho.extra_angles_deg(g, "power", math.inf)]
    travels = np.unique(np.concatenate([np.linspace(0.0, stroke, n_power + 1),
                                        [t for t in extra_travels if t < stroke]]))
    rack_points = ms.rack_profile(rack.mesh)
    flank_pairs = {(mode, d): ho.flank_pairs(g, profile, rack_points, kin.rack(0.0), mode, d)
                   for mode in ho.MODES for d in (+1, -1)}
    reach_travel_per_rad = tip * an.PUSH_RATE_PER_TIP_RADIUS
    reach_angle_per_mm = REACH_MARGIN / (centre_height - rack_top)

    mirror = np.array([-1.0, 1.0])
    # One task per mode and direction (the swings of one towing direction follow each other: one
    # task), in the order towing +, power +, power −, towing −: two processes end up with one towing
    # and one power task each (the spawned worker is sent the first two, this process takes the
    # last ones in line), the work split about evenly; reduce gets them in the order towing +,
    # towing −, power +, power −.
    power = [(power_task, (kin, d, travels, tol, reach_angle_per_mm, limit, profile, corner * m, normal * m, up * m,
                           g.pitch)) for d, m in ((+1, np.ones(2)), (-1, mirror))]
    towing = [(towing_task, (kin, d, angles, tol, reach_travel_per_rad, limit)) for d in (+1, -1)]
    tasks: list[Task] = [towing[0], *power, towing[1]]
    weights = [2 * len(angles), len(travels), len(travels), 2 * len(angles)]  # poses per task

    def reduce(sent: list) -> SweepOutcome:
        results = [sent[0], sent[3], sent[1], sent[2]]
        drives = _mesh_drives(g, kin, flank_pairs, results)
        return _reduce(g, kin, model, results, tol, bound, mesh_info, t_start, paper, drives,
                       steering_tca(g, tow_model))

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
        out_phis, back_phis = np.asarray(r["angles_out"], float), np.asarray(r["angles_back"], float)
        if np.array_equal(back_phis, out_phis[::-1]):  # the return swing retraces the poses: intervals once
            pairs, whole, left, right = an.all_intervals(g, out_phis)
            push_out, push_back = (left, right) if d > 0 else (right, left)
            out = an.sweep(g, out_phis, 0.0, d, (pairs, *push_out, *whole))
            back = an.sweep(g, back_phis, float(out.travel_mm[-1]), -d,
                            (pairs, push_back[0][:, ::-1], push_back[1][:, ::-1], whole[0][:, ::-1], whole[1][:, ::-1]))
        else:
            out = an.sweep(g, out_phis, 0.0, d)
            back = an.sweep(g, back_phis, float(out.travel_mm[-1]), -d)
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


def _direction_summary(r: dict, p: dict, towing_dev: float, power_dev: float, towing_end: float,
                       towing: ho.MeshDrive, power: ho.MeshDrive) -> dict:
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
        "geom_phi_S6_deg": abs(deg(p["limit_angle"])),
        "geom_rack_travel_at_continuous_limit_mm": abs(p["limit_travel"]),
        "geom_raw_corner_contact_angle_deg": abs(deg(p["raw_corner_angle"])),
        "geom_towing_conjugate_end_deg": deg(towing_end),
        # how far each sweep reaches: a drive figure there is only a lower bound (nothing ended within it)
        "geom_towing_swing_end_deg": abs(deg(float(out[-1]))),
        "geom_power_stroke_end_deg": abs(deg(float(p["angles"][-1]))),
        # continuous drive from the conjugate contact intervals of every pair measured on the meshes
        "geom_towing_drive_deg": towing.angle_deg,
        "geom_power_drive_deg": power.angle_deg,
        **({"geom_towing_gap_deg": list(towing.gap_deg), "geom_towing_gap_poses": towing.gap_poses}
           if towing.gap_deg else {}),
        **({"geom_power_gap_deg": list(power.gap_deg), "geom_power_gap_poses": power.gap_poses}
           if power.gap_deg else {}),
        "max_handover_deviation_deg": _largest(towing.max_deviation_deg, power.max_deviation_deg),
        "max_flank_fit_residual_mm": _largest(towing.fit_residual_mm, power.fit_residual_mm),
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


def _mesh_drives(g: RackPinionGeometry, kin: Kinematics, flank_pairs: dict, results: list) -> dict:
    """(mode, direction) → the mesh's continuous drive from the contact intervals measured at the
    swept poses (towing: the forward swing; power: the rack's stroke)."""
    axis = np.asarray(kin.rack_motion.axis, float)
    out = {}
    for r in results:
        mode = "towing" if "angles_out" in r else "power"
        angles, travels = (r["angles_out"], r["travel_out"]) if mode == "towing" else (r["angles"], r["travels"])
        poses = np.array([kin.pinion(float(a)) for a in angles])
        d = r["direction"]
        measured, covered = ho.measured_pairs(g, mode, flank_pairs[(mode, d)], angles, travels, poses, axis)
        out[(mode, d)] = ho.mesh_drive(g, mode, d, measured, angles, covered, flank_pairs[(mode, d)])
    return out


# Figures of the stop, which mean nothing while the rack is still moving at the end of the swing.
STOP_KEYS = ("geom_disengage_angle_deg", "geom_rack_travel_at_disengage_mm", "geom_rack_motion_after_disengage_mm",
             "geom_grazing_span_deg", "geom_disengage_bracket_at_tol_deg", "min_clearance_past_disengage_mm",
             "graze_distance_mm", "graze_angle_deg", "graze_contact_shift_mm")


def still_moving(s: dict, model_moving: bool, tol: float) -> bool:
    """The rack is still moving at the end of the towing swing: in the model (no disengage) or in
    this direction of the mesh (it moved more than the contact tolerance over the last degree)."""
    return model_moving or not s["geom_rack_motion_last_degree_mm"] <= tol


def _stated(s: dict, model_moving: bool, tol: float) -> dict:
    """One direction's figures for summary.json: without the stop's while the rack is still moving
    (the 'disengage' found there is only the end of the swing)."""
    if not still_moving(s, model_moving, tol):
        return dict(s)
    return {k: v for k, v in s.items() if k not in STOP_KEYS}


def _finite(tree: dict) -> dict:
    """summary.json has no null: a figure without a value (NaN; a list holding one) is left out."""
    out: dict = {}
    for k, v in tree.items():
        if isinstance(v, dict):
            out[k] = _finite(v)
        elif isinstance(v, (list, tuple)):
            if all(isinstance(x, (int, float)) and math.isfinite(x) for x in v):
                out[k] = v
        elif not (isinstance(v, float) and not math.isfinite(v)):
            out[k] = v
    return out


Figure = tuple[float, str]  # a continuous-drive angle (deg) and the event that ends it


def drive_figures(model: ModelFigures, plus: dict, minus: dict, drives: dict, tol: float
                  ) -> tuple[list[Figure], list[Figure], list[Figure]]:
    """The continuous-drive figures: the exact model's (towing, power), the mesh sweep's limits (the
    contact intervals of every pair, towing and power; the power-mode contact reaching S6; the towed
    rack falling ``tol`` behind r·φ; each direction) and the mesh figures that are only lower bounds
    (the event lies beyond the sweep: the towing swing, the power stroke)."""
    model_c = [(model.towing_drive_deg, f"exact model, {model.towing_drive_event}"),
               (model.power_drive_deg, f"exact model, {model.power_drive_event}")]
    limits: list[Figure] = []
    bounds: list[Figure] = []
    for s, d in ((plus, +1), (minus, -1)):
        for mode in ("towing", "power"):
            drive = drives[(mode, d)]
            (bounds if drive.bounded else limits).append(
                (drive.angle_deg, f"mesh sweep, {sign(d)} direction, {drive.event}"))
        s6, stroke = s["geom_phi_S6_deg"], s["geom_power_stroke_end_deg"]
        if math.isfinite(s6):
            limits.append((s6, f"mesh sweep, {sign(d)} direction: power-mode contact reaches S6 (tangency)"))
        else:
            bounds.append((stroke, f"mesh sweep, {sign(d)} direction: power-mode contact short of S6 to the end "
                                   "of the stroke"))
        lag, swing = s["geom_towing_conjugate_end_deg"], s["geom_towing_swing_end_deg"]
        if lag < swing:
            limits.append((lag, f"mesh sweep, {sign(d)} direction: towed rack falls {tol:.3f} mm behind r·φ"))
        else:
            bounds.append((swing, f"mesh sweep, {sign(d)} direction: towed rack never falls {tol:.3f} mm behind "
                                  "r·φ within the swing"))
    return model_c, limits, bounds


def _least(*values: float) -> float:
    """The least finite value (NaN when there is none)."""
    finite = [v for v in values if math.isfinite(v)]
    return min(finite) if finite else math.nan


def _largest(*values: float) -> float:
    """The largest finite value (NaN when there is none)."""
    finite = [v for v in values if math.isfinite(v)]
    return max(finite) if finite else math.nan


def _deepest_overlap(kin: Kinematics, rows: list[dict], tol: float) -> list[WorstPose]:
    """The pose where the sweep found the pinion deepest in the rack, when deeper than the contact
    tolerance (an interference the verdicts fail on): confirmed on the exact B-rep like the closest
    approach, so a failed interference verdict rests on the exact solids too."""
    if not rows:
        return []
    row = min(rows, key=lambda r: r["signed_clearance_mm"])
    if not row["signed_clearance_mm"] < -tol:
        return []
    swing = {"out": "forward", "back": "return", "drive": "drive"}[row["swing"]]
    label = (f"{row['mode']} {sign(row['direction'])}: deepest overlap of the sweep ({swing} swing, "
             f"{row['pinion_angle_deg']:.3f}°)")
    return [WorstPose(label, PINION, RACK, kin.pinion(math.radians(row["pinion_angle_deg"])).tolist(),
                      kin.rack(row["rack_travel_geom_mm"]).tolist(), 0.0, key="deepest_overlap_of_the_sweep",
                      mesh_overlap=True)]


def _reduce(g: RackPinionGeometry, kin: Kinematics, model: ModelFigures, results: list, tol: float, bound: float,
            mesh_info: dict, t_start: float, paper: bool = True, drives: dict | None = None,
            tca: SteeringTca | None = None) -> SweepOutcome:
    P = an.PAPER
    tow = {r["direction"]: r for r in results[:2]}
    power = {r["direction"]: r for r in results[2:]}
    elapsed = time.perf_counter() - t_start

    rows, towing_dev, curves = _towing_rows(g, tow)
    power_rows, power_dev = _power_rows(g, power)
    rows += power_rows
    t_cert = time.process_time()
    exact = ce.certify_exact(g, tow[1]["angles_out"], curves[1]["out"], tow[1]["angles_back"], curves[1]["back"],
                             power[1]["travels"], math.radians(model.disengage_deg))
    certify_cpu_s = time.process_time() - t_cert
    drives = drives or {}
    plus, minus = (_direction_summary(tow[d], power[d], towing_dev[d], power_dev[d],
                                      towing_conjugate_end(g, tow[d], tol), drives[("towing", d)],
                                      drives[("power", d)]) for d in (+1, -1))
    model_c, limits, _ = drive_figures(model, plus, minus, drives, tol)
    queries = sum(r["queries"] for r in results)
    speed = {"poses": len(rows), "fcl_queries": queries, "elapsed_s": elapsed, "poses_per_s": len(rows) / elapsed,
             "fcl_queries_per_s": queries / elapsed, "task_seconds": [float(r["seconds"]) for r in results],
             "task_cpu_seconds": [float(r["cpu_seconds"]) for r in results]}
    speed["poses_per_cpu_s"] = len(rows) / sum(speed["task_cpu_seconds"])
    speed["certify_cpu_s"] = certify_cpu_s
    speed["fcl_queries_per_cpu_s"] = queries / sum(speed["task_cpu_seconds"])

    scopes = (("anywhere", ce.PARTS, ("min_signed_clearance_mm",)),
              ("return_swing", ("back",), ("min_clearance_return_swing_mm",)),
              ("past_disengage", ("past",), ("min_clearance_past_disengage_mm",)))
    certified = {scope: ce.summary_entry(g, exact.scope(*parts), _least(plus[key], minus[key]))
                 for scope, parts, (key,) in scopes if any(p in exact.parts for p in parts)}
    summary = {
        **_stated(plus, model.moving_at_end, tol),
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
        "model_continuous_drive_deg": min(model.towing_drive_deg, model.power_drive_deg),
        "model_towing_drive_deg": model.towing_drive_deg,
        "model_power_drive_deg": model.power_drive_deg,
        "continuous_drive_deg": _least(*(f[0] for f in model_c + limits)),
        "geom_continuous_drive_deg": _least(*(f[0] for f in limits)),
        "model_contact_ratio": model.contact_ratio,
        "paper_phi_S6_deg": P["phi_S6_deg"],
        "paper_test_continuous_drive_deg": P["test_continuous_deg"],
        "max_towing_curve_deviation_mm": max(towing_dev.values()),
        "min_signed_clearance_mm": min(plus["min_signed_clearance_mm"], minus["min_signed_clearance_mm"]),
        "contact_tolerance_mm": tol,
        "mesh_error_bound_mm": bound,
        "certified": {scope: {k: v for k, v in e.items() if k != "where"} for scope, e in certified.items()},
        **({"tca": tca.summary} if tca is not None else {}),
        "minus": _stated(minus, model.moving_at_end, tol),
        "poses": speed["poses"],
        "fcl_queries": speed["fcl_queries"],
        **mesh_info,
    }
    if not paper:  # the paper's printed figures stand only beside the paper's own design
        summary = {k: v for k, v in summary.items() if not k.startswith("paper_")}
    summary = _finite(summary)

    out_deg = np.degrees(tow[1]["angles_out"])
    travel_at_adams = float(tow[1]["travel_out"][int(np.argmin(np.abs(out_deg - P["adams_disengage_deg"])))])
    over = model.stop_by.replace(" grazes ", " over ")
    worst_poses = [
        WorstPose(f"towing {sign(d)}: closest approach past the disengage ({over})", PINION, RACK,
                  kin.pinion(w["angle"]).tolist(), kin.rack(w["travel"]).tolist(), float(w["distance"]))
        for d, s in ((+1, plus), (-1, minus))
        if (w := tow[d]["worst"]) and not still_moving(s, model.moving_at_end, tol)  # no stop: nothing past it
    ]
    worst_poses += _deepest_overlap(kin, rows, tol)
    data = SteeringSweep(rows, tow, power, curves, plus, minus, model, tol, bound, mesh_info, speed, travel_at_adams,
                         summary["continuous_drive_deg"], drives, math.degrees(tol / g.pitch_radius), certified, tca)
    timings = {k: v for k, v in speed.items() if k not in ("poses", "fcl_queries")}
    return SweepOutcome(summary, worst_poses, timings, data)
