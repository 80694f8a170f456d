"""The differential's sweep results reduced (in the parent process): contact turns per pose into
plays per output shaft, cycle minima per shim and state, the paper's model beside them, the
deviations of the mesh from the exact flanks, the exact model over the temperature ranges (with
the onset of binding solved), the worst pose to confirm on the exact B-rep, the least play
decided on (for the mesh-resolution rule) and the speed figures."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel_mesh import drive_poses
from gearcheck.mechanisms.differential.analysis import PerSide, analyse_params, model_per_side
from gearcheck.mechanisms.differential.params import shim_key
from gearcheck.mechanisms.differential.tca import (PairTca, design_tca, mounted_summary, patterns_summary,
                                                   sensitivity, state_summary, tca_summary)
from gearcheck.mechanisms.differential.poses import GearSpecs
from gearcheck.mechanisms.differential.sweep import DIRECTIONS, SweepSetup, normalised_poses, whole_name
from gearcheck.mechanisms.differential.temperature import (GRID_STEP_K, STATE_TEXT, RangeCheck, merge_plays,
                                                           range_check, refine_cycles)
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.certify import Refined

# Mesh vs exact: within the mesh-error bound (as an angle on d1/2) plus this fraction.
AGREEMENT_RELATIVE = 0.02
# The states whose least play decides a fail (the storage minimum only warns): the worst pose to
# confirm on the exact B-rep is the least play among them.
FAIL_STATES = ("warm", "cold", "operating_min", "operating_max")


@dataclass(frozen=True)
class SweepData:
    """The reduced sweep, for the verdicts and the report. Arrays indexed (shim, state, drive
    angle, big gear), arcmin, NaN where a state was not measured at a shim (the extra states are
    measured at the template's shim only); ``*_min`` the cycle minima (shim, state). ``ranges``:
    the exact model over the temperature grid, per shim index (the template's at least)."""

    specs: GearSpecs
    shims: list[float]
    template_shim_mm: float
    t: int  # index of the template's shim
    z: int | None  # index of shim 0, if swept
    states: list[tuple[str, float]]  # (name, °C)
    index: dict[str, int]  # state name → index (a name sharing another's temperature shares its index)
    measured: np.ndarray  # (shim, state) bool
    angles: np.ndarray
    period_rad: float
    geom_plus: np.ndarray
    geom_minus: np.ndarray
    exact_plus: np.ndarray
    exact_minus: np.ndarray
    centred_free: np.ndarray
    models: list[PerSide]
    model_per_K: float  # the paper's linear model: play per side lost per kelvin of cooling
    warm_C: float
    contact_dev: np.ndarray  # |geometry − exact| per contact
    contact_ok: bool
    total_ok: bool
    contacts: int
    bound_mm: float
    bound_arcmin: float
    exact_solves: int
    exact_reused: int
    ranges: dict[int, RangeCheck]
    # per (shim, state) measured: the exact least play over the continuous cycle, refined between
    # the swept angles (:func:`_refined`)
    refined: dict[tuple[int, int], Refined] = field(default_factory=dict)
    # tooth contact analysis: the pair as designed ("aligned"), then each state meshed at the
    # template's shim (:class:`gearcheck.mechanisms.differential.tca.PairTca`)
    tca: list[PairTca] = field(default_factory=list)

    @property
    def w(self) -> int:
        return self.index["warm"]

    @property
    def c(self) -> int:
        return self.index["cold"]

    @property
    def geom_play(self) -> np.ndarray:
        return self.geom_plus - self.geom_minus

    @property
    def exact_play(self) -> np.ndarray:
        return self.exact_plus - self.exact_minus

    def _cycle_min(self, play: np.ndarray) -> np.ndarray:
        least = np.min(np.where(self.measured[:, :, None, None], play, np.inf), axis=(2, 3))
        return np.where(self.measured, least, np.nan)

    @property
    def geom_min(self) -> np.ndarray:
        return self._cycle_min(self.geom_play)

    @property
    def exact_sampled_min(self) -> np.ndarray:
        """The exact least play at the swept drive angles only."""
        return self._cycle_min(self.exact_play)

    @property
    def exact_min(self) -> np.ndarray:
        """The exact least play over the continuous cycle: the lower end of the refined bracket
        (within the refinement's precision of the least value found), else the sampled one."""
        out = self.exact_sampled_min.copy()
        for (i, j), r in self.refined.items():
            if math.isfinite(r.lower):
                out[i, j] = min(out[i, j], r.lower)
        return out

    @property
    def total_dev(self) -> np.ndarray:
        """|geometry − exact| per play (NaN where not measured)."""
        return np.abs(self.geom_play - self.exact_play)

    @property
    def model(self) -> PerSide:
        return self.models[self.t]

    @property
    def range(self) -> RangeCheck:
        """The exact range at the template's shim."""
        return self.ranges[self.t]

    def model_play(self, i: int, temperature_C: float) -> float:
        """The paper's linear model (eqs 1–11) per side at shim i and any temperature."""
        return self.models[i].warm - self.model_per_K * (self.warm_C - temperature_C)

    def state_label(self, j: int) -> str:
        name, temp = self.states[j]
        return f"{STATE_TEXT[name]} {temp:g} °C"


def reduce_sweep(setup: SweepSetup, results: list[dict]) -> SweepOutcome:
    range_index = {task for _, task in setup.range_tasks}
    mesh_results = [r for n, r in enumerate(results) if n not in range_index]
    by_key = {}
    for result, keys in zip(mesh_results, setup.owners, strict=True):
        for key, mesh in zip(keys, result["mesh"], strict=True):
            by_key[key] = {**mesh, "exact_rad": result["exact_rad"]}
    t0 = time.perf_counter()
    ranges = _ranges(setup, results)
    onset_s = time.perf_counter() - t0 + sum(results[task]["onset_s"] for _, task in setup.range_tasks)
    wall_s = time.perf_counter() - setup.started
    data = _arrays(setup, by_key, ranges)
    summary = _summary(setup, data, by_key)
    t, specs = data.t, setup.layout.specs
    measured = [(j, name, temp) for j, (name, temp) in enumerate(setup.states) if data.measured[t, j]]
    pairs = list(design_tca(setup.params).values())  # as designed, then each meshed state
    data = replace(data, tca=pairs)
    summary["tca"] = {**tca_summary(specs),
                      "states": {name: state_summary(setup.params, specs, data.template_shim_mm, temp,
                                                     data.exact_plus[t, j], data.exact_minus[t, j])
                                 for j, name, temp in measured},
                      "patterns": {"compound_um": setup.params.tca.compound_um, **patterns_summary(pairs)},
                      "mounted": mounted_summary(pairs),
                      "sensitivity": {p.name: sensitivity(specs, p) for p in pairs if p.name in ("warm", "cold")}}
    worst = _worst_poses(setup, data, by_key)
    range_s = sum(results[task]["exact_s"] for _, task in setup.range_tasks)
    return SweepOutcome(summary, worst, _timings(setup, by_key, wall_s, range_s, onset_s), data)


def _ranges(setup: SweepSetup, results: list[dict]) -> dict[int, RangeCheck]:
    """The exact range per shim from its chunks, with the onset of binding solved."""
    chunks: dict[int, list] = {}
    solved: dict[int, dict] = {}
    for i, task in setup.range_tasks:
        chunks.setdefault(i, []).append(results[task]["plays"])
        solved.setdefault(i, {}).update(results[task]["onsets"])
    return {i: range_check(setup.params, setup.shims[i], specs=setup.layout.specs, plays=merge_plays(parts),
                           solved=solved[i]) for i, parts in chunks.items()}


def _arrays(setup: SweepSetup, by_key: dict, ranges: dict[int, RangeCheck]) -> SweepData:
    arcmin = bp.ARCMIN_PER_RAD
    shims, angles, names = setup.shims, setup.angles, [n for n, _ in setup.states]
    shape = (len(shims), len(names), len(angles), len(BIG_GEARS))
    geom_plus, geom_minus = np.full(shape, np.nan), np.full(shape, np.nan)
    exact_plus, exact_minus = np.full(shape, np.nan), np.full(shape, np.nan)
    centred_free = np.ones(shape, dtype=bool)
    measured = np.zeros(shape[:2], dtype=bool)
    deviation = []  # per contact: (|geom − exact|, allowed)
    for (i, state, k, big, _small, _d), r in by_key.items():
        j, b = names.index(state), BIG_GEARS.index(big)
        measured[i, j] = True
        geom = 0.5 * (r["free_rad"] + r["touching_rad"]) * arcmin
        exact = r["exact_rad"] * arcmin
        deviation.append((abs(geom - exact), setup.bound_arcmin + AGREEMENT_RELATIVE * abs(exact)))
        centred_free[i, j, k, b] &= not r["centred_collides"]
    for i in range(len(shims)):
        for j in setup.shim_states[i]:
            state = names[j]
            for k in range(len(angles)):
                for b, big in enumerate(BIG_GEARS):
                    rs = [(by_key[(i, state, k, big, s, 1)], by_key[(i, state, k, big, s, -1)]) for s in SMALL_GEARS]
                    geom_plus[i, j, k, b] = min(0.5 * (p["free_rad"] + p["touching_rad"]) for p, _ in rs) * arcmin
                    geom_minus[i, j, k, b] = max(0.5 * (m["free_rad"] + m["touching_rad"]) for _, m in rs) * arcmin
                    exact_plus[i, j, k, b] = min(p["exact_rad"] for p, _ in rs) * arcmin
                    exact_minus[i, j, k, b] = max(m["exact_rad"] for _, m in rs) * arcmin
    geom_play = geom_plus - geom_minus
    exact_play = exact_plus - exact_minus
    m4 = measured[:, :, None, None] & np.ones(shape, dtype=bool)
    total_dev = np.abs(geom_play - exact_play)[m4]
    total_ok = bool(np.all(total_dev <= 2.0 * setup.bound_arcmin + AGREEMENT_RELATIVE * np.abs(exact_play[m4])))
    template_shim = setup.layout.template_shim_mm
    params = setup.params
    index = {name: names.index(name) for name in names}
    for name, temp in (("warm", params.operating.warm_C), ("cold", params.operating.cold_C)):
        index.setdefault(name, int(np.argmin([abs(temp - tt) for _, tt in setup.states])))
    return SweepData(
        specs=setup.layout.specs, shims=shims, template_shim_mm=template_shim,
        t=shims.index(template_shim), z=shims.index(0.0) if 0.0 in shims else None,
        states=list(setup.states), index=index, measured=measured,
        angles=angles, period_rad=setup.period_rad, geom_plus=geom_plus, geom_minus=geom_minus,
        exact_plus=exact_plus, exact_minus=exact_minus, centred_free=centred_free,
        models=[model_per_side(params, s) for s in shims],
        model_per_K=analyse_params(params).drop_per_side_per_K_arcmin, warm_C=params.operating.warm_C,
        contact_dev=np.array([dv for dv, _ in deviation]),
        contact_ok=all(dv <= allowed for dv, allowed in deviation), total_ok=total_ok, contacts=len(by_key),
        bound_mm=setup.bound_mm, bound_arcmin=setup.bound_arcmin, exact_solves=setup.exact_solves,
        exact_reused=setup.exact_reused, ranges=ranges, refined=_refined(setup, measured, exact_play))


def _refined(setup: SweepSetup, measured: np.ndarray, exact_play: np.ndarray) -> dict[tuple[int, int], Refined]:
    """Each measured state's exact least play over the continuous cycle: the swept drive angles'
    plays (the tighter output shaft's at each), refined between them on the exact model
    (:func:`.temperature.refine_cycles`: the same thermal states, new angles only), a shim's
    states together."""
    out: dict[tuple[int, int], Refined] = {}
    for i, shim in enumerate(setup.shims):
        states = [j for j in setup.shim_states[i] if measured[i, j]]
        found = refine_cycles(setup.params, shim, [setup.states[j][1] for j in states], setup.angles,
                              exact_play[i, states].min(axis=2), setup.period_rad, specs=setup.layout.specs)
        out.update({(i, j): r for j, r in zip(states, found, strict=True)})
    return out


def _range_summary(data: SweepData, r: RangeCheck, i: int) -> dict:
    """The exact model over the temperature ranges at shim i, as plain numbers."""
    op, st = r.operating, r.storage
    out: dict[str, Any] = {
        "grid_step_max_K": GRID_STEP_K,
        "temperatures_C": r.temperatures_C.tolist(),
        "exact_least_play_per_side_arcmin": r.least_arcmin.tolist(),
        "model_play_per_side_arcmin": [data.model_play(i, float(tc)) for tc in r.temperatures_C],
        "operating_least_play_arcmin": op[0],
        "operating_least_play_at_C": op[1],
        "storage_least_play_arcmin": st[0],
        "storage_least_play_at_C": st[1],
        "binds_in_operating_range": int(r.binds_operating),
        "binds_in_storage_range": int(r.binds_storage),
        "storage_min_play_arcmin": r.at("storage_min"),
        "storage_min_overlap_um": r.depth_um(r.at("storage_min")),
        "storage_max_play_arcmin": r.at("storage_max"),
    }
    for name in ("warm", "cold", "operating_min", "operating_max"):
        out[f"{name}_play_arcmin"] = r.at(name)
    if r.cold_onset_C is not None:
        out["binding_onset_C"] = r.cold_onset_C
    if r.hot_onset_C is not None:
        out["binding_onset_hot_C"] = r.hot_onset_C
    if r.plays is not None and r.plays.spots is not None:
        spots = r.plays.spots  # (T, plus/minus, big/small)
        out["contact"] = {
            "big_along_toe_to_heel_plus": [s[0][0].along for s in spots],
            "big_height_root_to_tip_plus": [s[0][0].height for s in spots],
            "small_height_root_to_tip_plus": [s[0][1].height for s in spots],
            "big_along_toe_to_heel_minus": [s[1][0].along for s in spots],
            "big_height_root_to_tip_minus": [s[1][0].height for s in spots],
            "small_height_root_to_tip_minus": [s[1][1].height for s in spots],
        }
    return out


def _refined_summary(data: SweepData, i: int, j: int) -> dict:
    """The exact least play's refinement over the continuous cycle at shim i, state j."""
    r = data.refined.get((i, j))
    if r is None:
        return {}
    return {"exact_play_sampled_min_arcmin": float(data.exact_sampled_min[i, j]),
            "exact_play_refined_least_arcmin": r.least, "exact_play_refined_at_deg": math.degrees(r.at),
            "exact_play_rate_bound_arcmin_per_deg": r.rate * math.pi / 180.0,
            "exact_play_points_added": r.refined, "exact_play_bracket_arcmin": r.bracket}


def _summary(setup: SweepSetup, data: SweepData, by_key: dict) -> dict:
    t, z, w, c = data.t, data.z, data.w, data.c
    geom_min, exact_min, models, model = data.geom_min, data.exact_min, data.models, data.model
    summary: dict[str, Any] = {
        "template_shim_mm": data.template_shim_mm,
        "geom_cold_drop_per_side_arcmin": float(geom_min[t, w] - geom_min[t, c]),
        "exact_cold_drop_per_side_arcmin": float(exact_min[t, w] - exact_min[t, c]),
        "model_cold_drop_per_side_arcmin": model.drop,
        "model_clean_cold_drop_per_side_arcmin": model.clean_drop,
        "geom_play_min_arcmin_at_warm": float(geom_min[t, w]),
        "geom_play_min_arcmin_at_cold": float(geom_min[t, c]),
        "exact_play_min_arcmin_at_warm": float(exact_min[t, w]),
        "exact_play_min_arcmin_at_cold": float(exact_min[t, c]),
        "model_play_min_arcmin_at_warm": model.warm,
        "model_play_min_arcmin_at_cold": model.cold,
        "geom_cold_backlash_total_min_arcmin": float(2.0 * geom_min[t, c]),
        "exact_cold_backlash_total_min_arcmin": float(2.0 * exact_min[t, c]),
        "geom_warm_backlash_total_min_arcmin": float(2.0 * geom_min[t, w]),
        "exact_warm_backlash_total_min_arcmin": float(2.0 * exact_min[t, w]),
        "mesh_error_bound_mm": data.bound_mm,
        "mesh_error_bound_arcmin": data.bound_arcmin,
        "max_mesh_exact_contact_deviation_arcmin": float(data.contact_dev.max()),
        "max_mesh_exact_play_deviation_arcmin": float(np.nanmax(data.total_dev)),
        "angles_per_cycle": len(data.angles),
        "contact_brackets": len(by_key),
        "fcl_queries": int(sum(r["calls"] for r in by_key.values())),
        "contact_brackets_by_estimate": {how: sum(r["found_by"] == how for r in by_key.values())
                                         for how in ("hint", "distance", "bisection")},
        "exact_solves": data.exact_solves,
        "exact_solves_reused_by_congruence": data.exact_reused * len(DIRECTIONS),
        "cycle_deg": math.degrees(data.period_rad),
        "brackets_widened": int(sum(r["widened"] > 0 for r in by_key.values())),
        "pruned_meshes": setup.pruned_meshes,
        "pruned_triangles_mean": setup.pruned_triangles_mean,
    }
    summary["states"] = {
        name: {"temperature_C": temp, "geom_play_min_arcmin": float(geom_min[t, j]),
               "exact_play_min_arcmin": float(exact_min[t, j]), "model_play_min_arcmin": data.model_play(t, temp),
               "max_mesh_exact_play_deviation_arcmin": float(np.nanmax(data.total_dev[t, j])),
               **_refined_summary(data, t, j)}
        for j, (name, temp) in enumerate(data.states)}
    if z is not None:
        summary["geom_shim_gain_per_side_arcmin"] = float(geom_min[t, w] - geom_min[z, w])
        summary["exact_shim_gain_per_side_arcmin"] = float(exact_min[t, w] - exact_min[z, w])
        summary["model_shim_gain_per_side_arcmin"] = model.warm - models[z].warm
    summary["shim_study"] = {
        "shims_mm": list(data.shims),
        "geom_play_min_arcmin_at_warm": geom_min[:, w].tolist(),
        "geom_play_min_arcmin_at_cold": geom_min[:, c].tolist(),
        "exact_play_min_arcmin_at_warm": exact_min[:, w].tolist(),
        "exact_play_min_arcmin_at_cold": exact_min[:, c].tolist(),
        "model_play_min_arcmin_at_warm": [m.warm for m in models],
        "model_play_min_arcmin_at_cold": [m.cold for m in models],
        "model_clean_play_min_arcmin_at_warm": [m.clean_warm for m in models],
        "model_clean_play_min_arcmin_at_cold": [m.clean_cold for m in models],
        "geom_cold_drop_per_side_arcmin": (geom_min[:, w] - geom_min[:, c]).tolist(),
        "exact_cold_drop_per_side_arcmin": (exact_min[:, w] - exact_min[:, c]).tolist(),
        "model_cold_drop_per_side_arcmin": [m.drop for m in models],
    }
    summary["exact_range"] = _range_summary(data, data.range, t)
    others = sorted(i for i in data.ranges if i != t)
    if others:
        summary["exact_range_by_shim"] = {f"shim_{shim_key(data.shims[i])}mm": _range_summary(
            data, data.ranges[i], i) for i in others}
    return summary


def _worst_poses(setup: SweepSetup, data: SweepData, by_key: dict) -> list[WorstPose]:
    """The pose with the least play at the template's shim among the states that decide a fail
    (warm, the cold design point, the operating range's ends), on the side with the smaller
    margin: the big gear at the free side of its contact bracket, and at the centred pose; mesh
    distances on the whole (unpruned) meshes in that state."""
    t = data.t
    geom_play = data.geom_play
    cands = sorted({data.index[n] for n in FAIL_STATES if n in data.index})
    j = min(cands, key=lambda jj: float(np.min(geom_play[t, jj])))
    state = data.states[j][0]
    kk, bb = np.unravel_index(np.argmin(geom_play[t, j]), geom_play[t, j].shape)
    big = BIG_GEARS[bb]
    plus_margin, minus_margin = data.geom_plus[t, j, kk, bb], -data.geom_minus[t, j, kk, bb]
    d = 1 if plus_margin <= minus_margin else -1
    pairs = [(s, by_key[(t, state, kk, big, s, d)]) for s in SMALL_GEARS]
    small, rec = (min if d == 1 else max)(pairs, key=lambda p: p[1]["free_rad"])

    layout, bodies = setup.layout, setup.bodies
    shim, phi = data.shims[t], data.angles[kk]
    thermal = setup.thermal_at[(shim, state)]
    built = {n: bodies[n].pose for n in layout.big_gears + layout.small_gears}
    poses = drive_poses(built, layout.big_gears, layout.small_gears, layout.specs.big, layout.specs.small, phi,
                        shim - layout.template_shim_mm)
    tb, ts = thermal[big], thermal[small]
    # the whole meshes as built, in the world scaled by 1 / (the small gear's factor)
    scene = setup.whole
    big_mesh, small_mesh = (whole_name(bodies, layout, big, tb.scale / ts.scale),
                            whole_name(bodies, layout, small, 1.0))
    out = []
    way = "+" if d > 0 else "−"
    text = "cold" if state == "cold" else STATE_TEXT[state]
    for label, turn in ((f"{text} least play, contact {way} (free side), {math.degrees(phi):.2f}°", rec["free_rad"]),
                        (f"{text} least play, centred, {math.degrees(phi):.2f}°", 0.0)):
        big_pose = poses[big] @ bp.rot_z4(turn)
        pose_b, pose_s = normalised_poses(thermal, big, small, big_pose, poses[small])
        scene.set_pose(big_mesh, pose_b)
        scene.set_pose(small_mesh, pose_s)
        near = scene.distance(big_mesh, small_mesh)
        midpoint = ts.scale * 0.5 * (near.point_a + near.point_b)
        out.append(WorstPose(label, big, small, tb.cold_pose_about_origin(big_pose).tolist(),
                             ts.cold_pose_about_origin(poses[small]).tolist(), float(ts.scale * near.distance),
                             tb.scale, ts.scale, mesh_overlap=scene.collide(big_mesh, small_mesh),
                             mesh_nearest_midpoint=(float(midpoint[0]), float(midpoint[1]), float(midpoint[2]))))
    return out


def _timings(setup: SweepSetup, by_key: dict, wall_s: float, range_s: float, onset_s: float) -> dict:
    """Speed of the sweep: FCL queries per second (over the time spent on the meshes, per worker),
    mesh contacts (one pair, one way, bracketed) per second of the sweep's wall time, one play
    measurement (one big gear against one small gear, both ways, on the meshes), one exact
    contact solve (the vectorised batch), the exact range (worker time) and its onset solves (in the
    range tasks, and here for a crossing between two tasks' temperatures), wall time of the sweep."""
    calls = sum(r["calls"] for r in by_key.values())  # FCL queries: collisions and distances
    mesh_s = sum(r["mesh_s"] for r in by_key.values())
    pair_play_s = [by_key[key]["mesh_s"] + by_key[key[:5] + (-1,)]["mesh_s"] for key in by_key if key[5] == 1]
    return {
        "fcl_queries": int(calls),
        "fcl_queries_per_s_per_worker": calls / mesh_s,
        "contacts": len(by_key),
        "contacts_per_s": len(by_key) / wall_s,
        "ms_per_play_measurement": 1e3 * float(np.mean(pair_play_s)),
        "ms_per_play_measurement_max": 1e3 * float(np.max(pair_play_s)),
        "ms_per_exact_contact": 1e3 * setup.exact_s / max(setup.exact_solves, 1),
        "exact_contacts_s": setup.exact_s,
        "exact_range_worker_s": range_s,
        "exact_onset_s": onset_s,
        "sweep_wall_s": wall_s,
    }
