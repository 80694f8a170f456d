"""The assembly sweep's results reduced: each pair's least clearance and deepest overlap, the least
play, over the motion and the states; the worst poses for the exact B-rep confirmation."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gearcheck.mechanisms.assembly.assembly import Layout
from gearcheck.mechanisms.assembly.sweep import AS_BUILT, Spec, StateSpec, worst_pose
from gearcheck.results import SweepOutcome, WorstPose
from gearcheck.sweep.bodies import Body


@dataclass(frozen=True)
class StateResult:
    """One state's arrays over the poses (in pose order)."""

    name: str
    clearance: np.ndarray  # (poses, pairs queried: Spec.live) mm; NaN where not measured; −overlap where overlapping
    overlap_mm: np.ndarray  # (poses, pairs) overlap along the motion, mm (NaN: apart; inf: jammed)
    overlap_unit: np.ndarray  # the same in the mover's unit
    points: np.ndarray  # (poses, pairs, 6) nearest points where apart
    play: np.ndarray  # (poses, 4) plus and minus moves to contact, the neighbour touched at each


@dataclass(frozen=True)
class AssemblySweep:
    """What the verdicts and the report read (``SweepOutcome.data``)."""

    layout: Layout
    spec: Spec
    states: list[StateResult]
    bound: dict[str, float]  # pair key → the pair's mesh-error bound (mm)
    queries: int


def _gather(results: list, states: list[StateSpec], n_pairs: int, count: int) -> list[StateResult]:
    per_state = len(results) // len(states)
    out = []
    for s, st in enumerate(states):
        chunk = results[s * per_state:(s + 1) * per_state]
        cl = np.full((count, n_pairs), np.nan)
        ov, ou = cl.copy(), cl.copy()
        pts = np.full((count, n_pairs, 6), np.nan)
        play = np.full((count, 4), np.nan)
        for r in chunk:
            idx = r["indices"]
            cl[idx], ov[idx], ou[idx], pts[idx], play[idx] = (r["clearance"], r["overlap_mm"], r["overlap_unit"],
                                                              r["points"], r["play"])
        out.append(StateResult(st.name, cl, ov, ou, pts, play))
    return out


def _num(v: float) -> float | None:
    return float(v) if v is not None and math.isfinite(v) else None


def reduce_sweep(lay: Layout, spec: Spec, states: list[StateSpec], bodies: Mapping[str, Body],
                 results: list, triangles: Mapping[str, tuple[int, int]]) -> SweepOutcome:
    kin = spec.kin
    count = len(kin.coordinates)
    unit = kin.unit
    data = _gather(results, states, len(spec.live), count)
    queries = int(sum(r["queries"] for r in results))
    bound = {r.key: bodies[r.a].error_bound_mm + bodies[r.b].error_bound_mm for r in spec.pairs}
    by_name = {st.name: st for st in states}
    summary: dict = {"poses": count, "states": [st.name for st in states], "motion_unit": unit,
                     "motion_start": float(kin.coordinates[0]), "motion_end": float(kin.coordinates[-1]),
                     "contact_tolerance_mm": lay.contact_tolerance_mm,
                     "mesh_error_bound_mm": max(bound.values()) if bound else 0.0, "fcl_queries": queries,
                     "pruning_margin_mm": spec.margin, "pairs_checked": len(spec.pairs),
                     "pairs_queried": len(spec.live), "pairs_never_near": len(spec.far)}
    worst: list[WorstPose] = []
    column = {k: c for c, k in enumerate(spec.live)}
    pairs = {rule.key: _pair_entry(column.get(k), rule, lay, spec, data, by_name, bound[rule.key], worst)
             for k, rule in enumerate(spec.pairs)}
    _certificates(spec, states, results, pairs)
    for rule in spec.pairs:
        entry = pairs[rule.key]
        if rule.key in spec.far:  # never within the margin: not queried
            entry["apart_beyond_mm"] = spec.margin
        else:
            a, b = triangles[rule.key]
            entry["triangles_swept"] = [a, b]
            entry["triangles_total"] = [int(bodies[p].mesh.faces.shape[0]) for p in (rule.a, rule.b)]
            if min(entry.get("min_clearance_mm", 0.0), entry.get("sampled_min_mm", math.inf)) > spec.margin:
                entry["apart_beyond_mm"] = spec.margin  # the pruned meshes' distance: only known to exceed it
    summary["pairs"] = pairs
    if spec.play:
        summary.update(_play_summary(spec, data, by_name, worst, unit))
    play_s = [t for r in results for t in r["play_s"]]
    task_s = sum(r["seconds"] for r in results)
    timings: dict = {"fcl_queries": queries, "task_s": task_s, "poses_per_task_s": count * len(states) / task_s,
                     "task_cpu_s": sum(float(r.get("cpu_s", r["seconds"])) for r in results)}
    if play_s:
        timings.update(ms_per_play_measurement=1e3 * float(np.mean(play_s)),
                       ms_per_play_measurement_max=1e3 * float(np.max(play_s)))
    return SweepOutcome(summary, worst, timings,
                        AssemblySweep(lay, spec, data, bound, queries))


def _certificates(spec: Spec, states: list[StateSpec], results: list, pairs: dict) -> None:
    """Each certified pair's figures over the motion and the states, into its entry: the certified
    least clearance (a lower bound over the continuous motion) and the interval it lies in, the
    least clearance measured (poses and refinement points), the refinement's measurements and the
    intervals it left undecided (too short to split: within the meshes' error)."""
    unit = spec.kin.unit
    per_state = len(results) // len(states)
    for s, st in enumerate(states):
        for r in results[s * per_state:(s + 1) * per_state]:
            for key, c in r["certificates"].items():
                entry = pairs[key]
                if c["certified_min"] < entry.get("certified_min_mm", math.inf):
                    entry.update({"certified_min_mm": c["certified_min"], f"certified_min_between_{unit}": c["at"],
                                  "certified_min_state": st.name})
                entry["sampled_min_mm"] = min(entry.get("sampled_min_mm", math.inf), c["sampled_min"])
                entry["intervals_refined"] = entry.get("intervals_refined", 0) + c["refined"]
                entry["undecided_intervals"] = entry.get("undecided_intervals", 0) + c["undecided"]
    for entry in pairs.values():
        for key in ("certified_min_mm", "sampled_min_mm"):
            if key in entry and not math.isfinite(entry[key]):  # an overlap beyond measure: the verdict says so
                entry.pop(key)


def _pair_entry(k: int | None, rule, lay: Layout, spec: Spec, data: list[StateResult],
                by_name: dict[str, StateSpec], bound: float, worst: list[WorstPose]) -> dict:
    """One pair's figures over the motion and the states (its worst poses appended to ``worst``):
    the least clearance where apart, the deepest overlap where not, the poses touching. ``k``: its
    column in the arrays (None: a pair never queried)."""
    kin, unit = spec.kin, spec.kin.unit
    entry: dict = {"rule": rule.kind, "required_mm": rule.min_clearance_mm, "mesh_error_bound_mm": bound,
                   "moving": int(rule.moving)}
    if k is None:
        return {"overlapping_poses": 0, "touching_poses": 0, **entry}
    least, least_at = math.inf, None
    deepest, deepest_at, overlapping, touching = -math.inf, None, 0, 0
    for sr in data:
        col = sr.clearance[:, k]
        measured = np.isfinite(col) | np.isneginf(col)
        if not measured.any():
            continue
        ov = sr.overlap_mm[:, k]
        hit = np.isfinite(ov) | np.isinf(ov)
        overlapping += int(hit.sum())
        touching += int((col[measured] <= lay.contact_tolerance_mm).sum())
        apart = np.where(measured & ~hit, col, np.inf)
        i = int(np.argmin(apart))
        if apart[i] < least:
            least, least_at = float(apart[i]), (sr, i)
        if hit.any():
            depth = np.where(hit, np.nan_to_num(ov, posinf=1e300), -np.inf)
            j = int(np.argmax(depth))
            if depth[j] > deepest:
                deepest, deepest_at = float(ov[j]), (sr, j)
    if least_at is not None:
        sr, i = least_at
        entry.update({"min_clearance_mm": least, "min_clearance_state": sr.name,
                      f"min_clearance_at_{unit}": float(kin.coordinates[i])})
        p = sr.points[i, k]
        worst.append(worst_pose(f"{rule.a} – {rule.b}: least clearance ({sr.name})",
                                f"least_clearance_{rule.key}_{sr.name}", spec, by_name[sr.name], rule.a, rule.b,
                                float(kin.coordinates[i]), least, overlap=False, midpoint=0.5 * (p[:3] + p[3:])))
    entry["overlapping_poses"] = overlapping
    entry["touching_poses"] = touching
    if deepest_at is not None:
        sr, j = deepest_at
        mover_unit = sr.overlap_unit[j, k]
        entry.update({"max_overlap_mm": _num(deepest), "max_overlap_state": sr.name,
                      f"max_overlap_at_{unit}": float(kin.coordinates[j]),
                      "max_overlap_jammed": int(math.isinf(mover_unit))})
        if math.isfinite(mover_unit):
            entry["max_overlap_move"] = float(mover_unit)
        worst.append(worst_pose(f"{rule.a} – {rule.b}: deepest overlap ({sr.name})",
                                f"deepest_overlap_{rule.key}_{sr.name}", spec, by_name[sr.name], rule.a, rule.b,
                                float(kin.coordinates[j]), 0.0, overlap=True))
    return {key: v for key, v in entry.items() if v is not None}


def _play_summary(spec: Spec, data: list[StateResult], by_name: dict[str, StateSpec], worst: list[WorstPose],
                  unit: str) -> dict:
    """The play part's least play (plus + minus) over the motion, per state and overall, and the
    two contacts at the least play as worst poses (touching: the B-rep distance must be ~0)."""
    part = spec.play
    assert part is not None
    pu = spec.kin.lines[part].unit
    out: dict = {"play_part": part, "play_unit": pu, "play_limit": spec.play_limit}
    least, at = math.inf, None
    states: dict = {}
    for sr in data:
        total = sr.play[:, 0] + sr.play[:, 1]
        if not np.isfinite(total).any():
            continue
        i = int(np.nanargmin(total))
        states[sr.name] = {f"play_min_{pu}": float(total[i]), f"play_min_at_{unit}": float(spec.kin.coordinates[i]),
                           f"play_plus_min_{pu}": float(np.nanmin(sr.play[:, 0])),
                           f"play_minus_min_{pu}": float(np.nanmin(sr.play[:, 1])),
                           f"play_max_{pu}": float(np.nanmax(total)),
                           "play_limited_poses": int((sr.play[:, :2] >= spec.play_limit).any(axis=1).sum()),
                           "play_jammed_poses": int((sr.play[:, :2] <= -spec.play_limit).any(axis=1).sum())}
        if total[i] < least:
            least, at = float(total[i]), (sr.name, i)
    out["play"] = states
    if at is not None:
        st, i = at
        out[f"play_min_{pu}"] = least
        out["play_min_state"] = st
        out["play_jammed_poses"] = int(sum(v["play_jammed_poses"] for v in states.values()))
        out[f"play_min_at_{unit}"] = float(spec.kin.coordinates[i])
        sr = next(s for s in data if s.name == st)
        x = float(spec.kin.coordinates[i])
        for sign, col, word in ((1.0, 0, "plus"), (-1.0, 1, "minus")):
            move = float(sr.play[i, col])
            if not 0.0 < move < spec.play_limit:
                continue
            touched = sr.play[i, 2 + col]
            if not math.isfinite(touched):
                continue
            other = spec.play_neighbours[int(touched)]
            worst.append(worst_pose(f"{part} turned {word} to contact at the least play ({st})",
                                    f"play_contact_{word}_{st}", spec, by_name[st], part, other, x, 0.0,
                                    extra=(part, sign * move)))
    return out


__all__ = ["AS_BUILT", "AssemblySweep", "StateResult", "reduce_sweep"]
