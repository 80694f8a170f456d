"""The differential's sweep results reduced (in the parent process): contact turns per pose into
plays per output shaft, cycle minima per shim and state, the paper's model beside them, the
deviations of the mesh from the exact flanks, the worst pose to confirm on the exact B-rep, the
least play decided on (for the mesh-resolution rule) and the speed figures."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel_mesh import drive_poses
from gearcheck.mechanisms.differential.analysis import PerSide, model_per_side
from gearcheck.mechanisms.differential.poses import GearSpecs
from gearcheck.mechanisms.differential.sweep import DIRECTIONS, STATES, SweepSetup
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS
from gearcheck.results import Clearance, SweepOutcome, WorstPose
from gearcheck.sweep.engine import Scene

# Mesh vs exact: within the mesh-error bound (as an angle on d1/2) plus this fraction.
AGREEMENT_RELATIVE = 0.02
W, C = STATES.index("warm"), STATES.index("cold")


@dataclass(frozen=True)
class SweepData:
    """The reduced sweep, for the verdicts and the report. Arrays indexed (shim, state, drive
    angle, big gear), arcmin; ``*_min`` the cycle minima (shim, state)."""

    specs: GearSpecs
    shims: list[float]
    template_shim_mm: float
    t: int  # index of the template's shim
    z: int | None  # index of shim 0, if swept
    angles: np.ndarray
    period_rad: float
    geom_plus: np.ndarray
    geom_minus: np.ndarray
    exact_plus: np.ndarray
    exact_minus: np.ndarray
    centred_free: np.ndarray
    models: list[PerSide]
    contact_dev: np.ndarray  # |geometry − exact| per contact
    contact_ok: bool
    total_ok: bool
    contacts: int
    bound_mm: float
    bound_arcmin: float
    exact_solves: int
    exact_reused: int

    @property
    def geom_play(self) -> np.ndarray:
        return self.geom_plus - self.geom_minus

    @property
    def exact_play(self) -> np.ndarray:
        return self.exact_plus - self.exact_minus

    @property
    def geom_min(self) -> np.ndarray:
        return self.geom_play.min(axis=(2, 3))

    @property
    def exact_min(self) -> np.ndarray:
        return self.exact_play.min(axis=(2, 3))

    @property
    def total_dev(self) -> np.ndarray:
        """|geometry − exact| per play."""
        return np.abs(self.geom_play - self.exact_play)

    @property
    def model(self) -> PerSide:
        return self.models[self.t]


def reduce_sweep(setup: SweepSetup, results: list[dict]) -> SweepOutcome:
    by_key = {}
    for result, keys in zip(results, setup.owners, strict=True):
        for key, mesh in zip(keys, result["mesh"], strict=True):
            by_key[key] = {**mesh, "exact_rad": result["exact_rad"], "exact_s": result["exact_s"] / len(keys)}
    wall_s = time.perf_counter() - setup.started
    data = _arrays(setup, by_key, len(results))
    summary = _summary(setup, data, by_key)
    worst = _worst_poses(setup, data, by_key)
    t = data.t
    clearance = smallest_clearance(data.specs, data.shims[t], data.exact_min[t, W], data.exact_min[t, C])
    return SweepOutcome(summary, worst, clearance, _timings(by_key, results, wall_s), data)


def _arrays(setup: SweepSetup, by_key: dict, solves: int) -> SweepData:
    arcmin = bp.ARCMIN_PER_RAD
    shims, angles = setup.shims, setup.angles
    shape = (len(shims), len(STATES), len(angles), len(BIG_GEARS))
    geom_plus, geom_minus = np.empty(shape), np.empty(shape)
    exact_plus, exact_minus = np.empty(shape), np.empty(shape)
    centred_free = np.ones(shape, dtype=bool)
    deviation = []  # per contact: (|geom − exact|, allowed)
    for (i, state, k, big, _small, _d), r in by_key.items():
        j, b = STATES.index(state), BIG_GEARS.index(big)
        geom = 0.5 * (r["free_rad"] + r["touching_rad"]) * arcmin
        exact = r["exact_rad"] * arcmin
        deviation.append((abs(geom - exact), setup.bound_arcmin + AGREEMENT_RELATIVE * abs(exact)))
        centred_free[i, j, k, b] &= not r["centred_collides"]
    for i in range(len(shims)):
        for j, state in enumerate(STATES):
            for k in range(len(angles)):
                for b, big in enumerate(BIG_GEARS):
                    rs = [(by_key[(i, state, k, big, s, 1)], by_key[(i, state, k, big, s, -1)]) for s in SMALL_GEARS]
                    geom_plus[i, j, k, b] = min(0.5 * (p["free_rad"] + p["touching_rad"]) for p, _ in rs) * arcmin
                    geom_minus[i, j, k, b] = max(0.5 * (m["free_rad"] + m["touching_rad"]) for _, m in rs) * arcmin
                    exact_plus[i, j, k, b] = min(p["exact_rad"] for p, _ in rs) * arcmin
                    exact_minus[i, j, k, b] = max(m["exact_rad"] for _, m in rs) * arcmin
    geom_play = geom_plus - geom_minus
    exact_play = exact_plus - exact_minus
    total_dev = np.abs(geom_play - exact_play)
    total_ok = bool(np.all(total_dev <= 2.0 * setup.bound_arcmin + AGREEMENT_RELATIVE * np.abs(exact_play)))
    template_shim = setup.layout.template_shim_mm
    return SweepData(
        specs=setup.layout.specs, shims=shims, template_shim_mm=template_shim,
        t=shims.index(round(template_shim, 9)), z=shims.index(0.0) if 0.0 in shims else None,
        angles=angles, period_rad=setup.period_rad, geom_plus=geom_plus, geom_minus=geom_minus,
        exact_plus=exact_plus, exact_minus=exact_minus, centred_free=centred_free,
        models=[model_per_side(setup.params, s) for s in shims],
        contact_dev=np.array([dv for dv, _ in deviation]),
        contact_ok=all(dv <= allowed for dv, allowed in deviation), total_ok=total_ok, contacts=len(by_key),
        bound_mm=setup.bound_mm, bound_arcmin=setup.bound_arcmin, exact_solves=solves,
        exact_reused=setup.exact_reused)


def _summary(setup: SweepSetup, data: SweepData, by_key: dict) -> dict:
    t, z = data.t, data.z
    geom_min, exact_min, models, model = data.geom_min, data.exact_min, data.models, data.model
    summary: dict[str, Any] = {
        "template_shim_mm": data.template_shim_mm,
        "geom_cold_drop_per_side_arcmin": float(geom_min[t, W] - geom_min[t, C]),
        "exact_cold_drop_per_side_arcmin": float(exact_min[t, W] - exact_min[t, C]),
        "model_cold_drop_per_side_arcmin": model.drop,
        "clean_model_cold_drop_per_side_arcmin": model.clean_drop,
        "geom_warm_play_min_arcmin": float(geom_min[t, W]),
        "geom_cold_play_min_arcmin": float(geom_min[t, C]),
        "exact_warm_play_min_arcmin": float(exact_min[t, W]),
        "exact_cold_play_min_arcmin": float(exact_min[t, C]),
        "model_warm_play_min_arcmin": model.warm,
        "model_cold_play_min_arcmin": model.cold,
        "geom_cold_backlash_total_min_arcmin": float(2.0 * geom_min[t, C]),
        "exact_cold_backlash_total_min_arcmin": float(2.0 * exact_min[t, C]),
        "geom_warm_backlash_total_min_arcmin": float(2.0 * geom_min[t, W]),
        "exact_warm_backlash_total_min_arcmin": float(2.0 * exact_min[t, W]),
        "mesh_error_bound_mm": data.bound_mm,
        "mesh_error_bound_arcmin": data.bound_arcmin,
        "max_mesh_exact_contact_deviation_arcmin": float(data.contact_dev.max()),
        "max_mesh_exact_play_deviation_arcmin": float(data.total_dev.max()),
        "angles_per_cycle": len(data.angles),
        "poses": int(sum(r["calls"] for r in by_key.values())),
        "exact_solves": data.exact_solves,
        "exact_solves_reused_by_congruence": data.exact_reused * len(DIRECTIONS),
        "cycle_deg": math.degrees(data.period_rad),
        "brackets_widened": int(sum(r["widened"] > 0 for r in by_key.values())),
        "pruned_meshes": setup.pruned_meshes,
        "pruned_triangles_mean": setup.pruned_triangles_mean,
    }
    if z is not None:
        summary["geom_shim_gain_per_side_arcmin"] = float(geom_min[t, W] - geom_min[z, W])
        summary["exact_shim_gain_per_side_arcmin"] = float(exact_min[t, W] - exact_min[z, W])
        summary["model_shim_gain_per_side_arcmin"] = model.warm - models[z].warm
    summary["shim_study"] = {
        "shims_mm": list(data.shims),
        "geom_warm_play_min_arcmin": geom_min[:, W].tolist(),
        "geom_cold_play_min_arcmin": geom_min[:, C].tolist(),
        "exact_warm_play_min_arcmin": exact_min[:, W].tolist(),
        "exact_cold_play_min_arcmin": exact_min[:, C].tolist(),
        "model_warm_play_min_arcmin": [m.warm for m in models],
        "model_cold_play_min_arcmin": [m.cold for m in models],
        "clean_model_warm_play_min_arcmin": [m.clean_warm for m in models],
        "clean_model_cold_play_min_arcmin": [m.clean_cold for m in models],
        "geom_cold_drop_per_side_arcmin": (geom_min[:, W] - geom_min[:, C]).tolist(),
        "exact_cold_drop_per_side_arcmin": (exact_min[:, W] - exact_min[:, C]).tolist(),
        "model_cold_drop_per_side_arcmin": [m.drop for m in models],
    }
    return summary


def _worst_poses(setup: SweepSetup, data: SweepData, by_key: dict) -> list[WorstPose]:
    """The cold pose with the least play at the template's shim (the side with the smaller margin):
    the big gear at the free side of its contact bracket, and at the centred pose; mesh distances
    on the whole (unpruned) cold meshes."""
    t = data.t
    geom_play = data.geom_play
    kk, bb = np.unravel_index(np.argmin(geom_play[t, C]), geom_play[t, C].shape)
    big = BIG_GEARS[bb]
    plus_margin, minus_margin = data.geom_plus[t, C, kk, bb], -data.geom_minus[t, C, kk, bb]
    d = 1 if plus_margin <= minus_margin else -1
    cands = [(s, by_key[(t, "cold", kk, big, s, d)]) for s in SMALL_GEARS]
    small, rec = (min if d == 1 else max)(cands, key=lambda c: c[1]["free_rad"])

    layout, bodies = setup.layout, setup.bodies
    shim, phi = data.shims[t], data.angles[kk]
    thermal = setup.thermal_at[shim]
    built = {n: bodies[n].pose for n in layout.big_gears + layout.small_gears}
    poses = drive_poses(built, layout.big_gears, layout.small_gears, layout.specs.big, layout.specs.small, phi,
                        shim - layout.template_shim_mm)
    tb, ts = thermal[big], thermal[small]
    scene = Scene([bodies[big].scaled(tb.scale, tb.datum_local).mesh,
                   bodies[small].scaled(ts.scale, ts.datum_local).mesh])
    scene.set_pose(small, ts.cold_pose(poses[small]))
    out = []
    way = "+" if d > 0 else "−"
    for label, turn in ((f"cold least play, contact {way} (free side), {math.degrees(phi):.2f}°", rec["free_rad"]),
                        (f"cold least play, centred, {math.degrees(phi):.2f}°", 0.0)):
        big_pose = poses[big] @ bp.rot_z4(turn)
        scene.set_pose(big, tb.cold_pose(big_pose))
        distance = scene.distance(big, small).distance
        out.append(WorstPose(label, big, small, tb.cold_pose_about_origin(big_pose).tolist(),
                             ts.cold_pose_about_origin(poses[small]).tolist(), float(distance), tb.scale, ts.scale))
    return out


def smallest_clearance(specs: GearSpecs, shim_mm: float, warm_arcmin: float, cold_arcmin: float) -> Clearance | None:
    """The least positive play per side at the template's shim (exact flanks, warm or cold) as the
    arc it spans on the big gear's outer pitch circle: the radius the check converts its mesh
    bound with, so the rule reads bound ≤ play/10 in the verdicts' own terms."""
    plays = [(v, state) for v, state in ((cold_arcmin, "cold"), (warm_arcmin, "warm")) if v > 0.0]
    if not plays:
        return None
    play, state = min(plays)
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    return Clearance(float(play) / bp.ARCMIN_PER_RAD * d1_half,
                     f"least {state} play per side at shim {shim_mm:.2f} mm (exact flanks, {play:.3f}′ on d1/2)")


def _timings(by_key: dict, results: list, wall_s: float) -> dict:
    """Speed of the sweep: collide calls per second (over the time spent bisecting, per worker,
    and over the wall time of the whole sweep), one play measurement (one big gear against one
    small gear, both ways, on the meshes), one exact contact solve, wall time of the sweep."""
    calls = sum(r["calls"] for r in by_key.values())
    mesh_s = sum(r["mesh_s"] for r in by_key.values())
    exact_s = sum(r["exact_s"] for r in results)
    pair_play_s = [by_key[key]["mesh_s"] + by_key[key[:5] + (-1,)]["mesh_s"] for key in by_key if key[5] == 1]
    return {
        "collide_calls": int(calls),
        "collide_calls_per_s_per_worker": calls / mesh_s,
        "poses_per_s": calls / wall_s,
        "ms_per_play_measurement": 1e3 * float(np.mean(pair_play_s)),
        "ms_per_play_measurement_max": 1e3 * float(np.max(pair_play_s)),
        "ms_per_exact_contact": 1e3 * exact_s / len(results),
        "sweep_wall_s": wall_s,
    }
