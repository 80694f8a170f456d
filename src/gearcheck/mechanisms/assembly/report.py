"""Verdicts and report content of an assembly sweep.

One verdict per declared pair (its clearance, or contact within the tolerance), one for every
other pair together (no interference), and the play (at least ``play.min_*``, or free both ways).
Parts that overlap at the first pose fail their pair's verdict like any other pose, named with the
overlap. The sweep on the meshes decides; the exact B-rep confirms the worst poses after.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from gearcheck.mechanisms.assembly.assembly import PairRule
from gearcheck.mechanisms.assembly.reduce import AssemblySweep
from gearcheck.results import Level, Plot, Report, Series, SweepOutcome, Verdict

MESH = "mesh sweep (FCL collide and distance at every pose)"
PLAY = "mesh sweep (bisection to contact both ways at every pose)"


def _value(x: float, unit: str) -> str:
    return f"{x:g}°" if unit == "deg" else f"{x:g} mm"


def _at(entry: dict, prefix: str, unit: str) -> str:
    state = entry.get(f"{prefix}_state", "")
    where = f"at {_value(entry[f'{prefix}_at_{unit}'], unit)}"
    return f"{where}, {state}" if state and state != "as_built" else where


def _overlap_words(entry: dict, unit: str) -> str:
    """The deepest overlap first, in mm, then how it was measured: the figure a terminal line keeps."""
    mm = entry.get("max_overlap_mm")
    where = _at(entry, "max_overlap", unit)
    if entry.get("max_overlap_jammed"):
        head = f"overlap {mm:.4f} mm {where}" if mm is not None else f"overlap beyond reach {where}"
        return head + " (no turn or slide of its joints frees it; the least push does)"
    move = entry.get("max_overlap_move")
    extra = f"; a {move:.4g}° turn frees it" if move is not None and mm is not None and move != mm else ""
    return f"overlap {mm:.4f} mm {where} (along the motion{extra})"


CERTIFIED = "mesh sweep, certified over the continuous motion (each interval's bound from its ends' clearances " \
            "and the largest path of any point; refined where it did not decide)"


def clearance_reading(entry: dict, required: float, unit: str) -> tuple[Level, str, str]:
    """(level, measured, shortfall) of a pair's clearance against ``required`` over the continuous
    motion, from its certificate: pass where the certified bound holds; fail where a pose (sampled
    or added by the refinement) falls short; warn where the bound is below the requirement only
    on intervals too short to split (within the meshes' error)."""
    cert, sampled = entry.get("certified_min_mm"), entry.get("sampled_min_mm")
    refined, undecided = entry.get("intervals_refined", 0), entry.get("undecided_intervals", 0)
    between = entry.get(f"certified_min_between_{unit}")
    where = (f" between {_value(between[0], unit)} and {_value(between[1], unit)}" if between else "")
    state = entry.get("certified_min_state", "as_built")
    where += f", {state}" if state != "as_built" else ""
    if cert is None or sampled is None:
        return "fail", "no certified figure", "an overlap beyond measure"
    head = f"least clearance ≥ {cert:.4f} mm certified over the continuous motion{where}"
    tail = f" (least measured {sampled:.4f} mm, {refined} points added between the poses)"
    if cert >= required:
        return "pass", head + tail, ""
    if sampled < required:
        return ("fail", head + tail, f"a pose between the samples comes to {sampled:.4f} mm against {required:g} mm"
                + where)
    return ("warn", head + tail + f"; {undecided} intervals within the meshes' error of {required:g} mm",
            f"certified {cert:.4f} mm against {required:g} mm on intervals too short to decide (the meshes' error)")


def pair_verdict(rule: PairRule, entry: dict, unit: str, tol: float) -> Verdict:
    name = f"{'contact' if rule.kind == 'contact' else 'clearance'}_{rule.key}"
    overlaps = entry.get("overlapping_poses", 0)
    least = entry.get("min_clearance_mm")
    beyond = entry.get("apart_beyond_mm")
    if beyond is not None and (least is None or least > beyond):
        least_words = f"more than {beyond:g} mm apart over the whole motion"
    elif least is not None:
        least_words = f"least clearance {least:.4f} mm {_at(entry, 'min_clearance', unit)}"
    else:
        least_words = "no pose apart"
    figures = {"min_clearance_mm": least if least is not None else math.nan,
               "overlapping_poses": float(overlaps), "mesh_error_bound_mm": entry["mesh_error_bound_mm"]}
    if entry.get("max_overlap_mm") is not None:
        figures["max_overlap_mm"] = entry["max_overlap_mm"]
    if rule.kind == "contact":
        deep = entry.get("max_overlap_mm")
        jammed = bool(entry.get("max_overlap_jammed"))
        ok = not jammed and (deep is None or deep <= tol)
        measured = (f"{least_words}; touching (≤ {tol:g} mm) at {entry.get('touching_poses', 0)} poses"
                    + (f"; {overlaps} poses overlap, deepest: {_overlap_words(entry, unit)}" if overlaps else ""))
        return Verdict.of(name, f"{rule.a} and {rule.b} may touch, not interfere (overlap ≤ {tol:g} mm)", ok,
                          measured, figures, evidence=MESH + ": overlap as the clearing move along the motion",
                          shortfall=_overlap_words(entry, unit) + f", tolerance {tol:g} mm")
    required = rule.min_clearance_mm
    if overlaps:
        shortfall = f"{_overlap_words(entry, unit)}; {overlaps} poses overlap"
        ok = False
    elif beyond is not None and (least is None or least > beyond):
        ok, shortfall = beyond >= required, ""
    elif "certified_min_mm" in entry or "sampled_min_mm" in entry:
        level, measured, shortfall = clearance_reading(entry, required, unit)
        figures.update({k: entry[k] for k in ("certified_min_mm", "sampled_min_mm") if k in entry})
        return Verdict.graded(name, _label(rule, required), level, measured, figures, evidence=CERTIFIED,
                              shortfall=shortfall)
    else:
        ok = least is not None and least >= required
        shortfall = (f"least clearance {least:.4f} mm against {required:g} mm" if least is not None
                     else "never apart")
    measured = least_words + (f"; {overlaps} poses overlap" if overlaps else "")
    return Verdict.of(name, _label(rule, required), ok, measured, figures, evidence=MESH, shortfall=shortfall)


def _label(rule: PairRule, required: float) -> str:
    return (f"{rule.a} and {rule.b} keep ≥ {required:g} mm apart" if required > 0
            else f"{rule.a} and {rule.b} do not interfere")


def others_verdict(rules: list[PairRule], pairs: dict, unit: str) -> Verdict:
    """Every pair no [[require]] names: no interference anywhere in the motion."""
    readings = {r.key: clearance_reading(pairs[r.key], 0.0, unit) for r in rules
                if not pairs[r.key].get("overlapping_poses", 0) and "certified_min_mm" in pairs[r.key]}
    between = [(r, pairs[r.key]) for r in rules if readings.get(r.key, ("pass",))[0] == "fail"]
    unsure = [(r, pairs[r.key]) for r in rules if readings.get(r.key, ("pass",))[0] == "warn"]
    bad = [(r, pairs[r.key]) for r in rules if pairs[r.key].get("overlapping_poses", 0)]
    free = [pairs[r.key]["min_clearance_mm"] for r in rules if "min_clearance_mm" in pairs[r.key]]
    far = sum("apart_beyond_mm" in pairs[r.key] and "min_clearance_mm" not in pairs[r.key] for r in rules)
    measured = (f"{len(rules)} pairs, least clearance {min(free):.4f} mm" if free else f"{len(rules)} pairs")
    if far:
        beyond = next(pairs[r.key]["apart_beyond_mm"] for r in rules if "apart_beyond_mm" in pairs[r.key])
        measured += f"; {far} never within {beyond:g} mm of each other"
    shortfall = "; ".join([f"{r.a} – {r.b} {_overlap_words(e, unit)}" for r, e in bad[:3]]
                          + [f"{r.a} – {r.b}: {readings[r.key][2]}" for r, _ in (between + unsure)[:3]])
    if len(bad) + len(between) + len(unsure) > 3:
        shortfall += f"; {len(bad) + len(between) + len(unsure) - 3} more pairs"
    level: Level = "fail" if bad or between else "warn" if unsure else "pass"
    certified = [pairs[r.key]["certified_min_mm"] for r in rules if "certified_min_mm" in pairs[r.key]]
    if certified and not bad:
        measured += f"; certified ≥ {min(certified):.4f} mm over the continuous motion"
    return Verdict.graded("no_interference", "no other pair of parts interferes", level, measured,
                          {"pairs": float(len(rules)), "overlapping_pairs": float(len(bad) + len(between))},
                          evidence=CERTIFIED, shortfall=shortfall)


def play_verdict(summary: dict, minimum: float | None) -> Verdict:
    unit = summary["play_unit"]
    part = summary["play_part"]
    least = summary.get(f"play_min_{unit}")
    motion_unit = summary["motion_unit"]
    if least is None:
        return Verdict.of("play", f"{part} has play", False, "no pose measured", evidence=PLAY,
                          shortfall="no pose measured")
    shown = f"{least * 60:.3f}′" if unit == "deg" else f"{least:.4f} mm"
    where = f"at {_value(summary[f'play_min_at_{motion_unit}'], motion_unit)}"
    state = summary.get("play_min_state", "as_built")
    where += f", {state}" if state != "as_built" else ""
    jammed = summary.get("play_jammed_poses", 0)
    if jammed:
        limit = f"{summary['play_limit'] * 60:g}′" if unit == "deg" else f"{summary['play_limit']:g} mm"
        return Verdict.of("play", f"{part} has play", False,
                          f"jammed at {jammed} poses: in contact and not freed within {limit} either way",
                          {f"play_min_{unit}": least, "jammed_poses": float(jammed)}, evidence=PLAY,
                          shortfall=f"jammed at {jammed} of {summary['poses']} poses")
    if minimum is None:
        return Verdict.of("play", f"{part} turns freely both ways (play > 0)" if unit == "deg"
                          else f"{part} slides freely both ways (play > 0)", least > 0,
                          f"least play {shown} {where}", {f"play_min_{unit}": least}, evidence=PLAY,
                          shortfall=f"least play {shown} {where}: binds")
    want = f"{minimum * 60:g}′" if unit == "deg" else f"{minimum:g} mm"
    return Verdict.of("play", f"{part}'s play ≥ {want} over the motion", least >= minimum,
                      f"least play {shown} {where}", {f"play_min_{unit}": least, f"required_{unit}": minimum},
                      evidence=PLAY, shortfall=f"least play {shown} against {want} {where}")


def assembly_verdicts(outcome: SweepOutcome) -> list[Verdict]:
    data: AssemblySweep = outcome.data
    s = outcome.summary
    unit = s["motion_unit"]
    tol = data.layout.contact_tolerance_mm
    declared = [r for r in data.spec.pairs if r.declared]
    others = [r for r in data.spec.pairs if not r.declared]
    out = [pair_verdict(r, s["pairs"][r.key], unit, tol) for r in declared]
    if others:
        out.append(others_verdict(others, s["pairs"], unit))
    if data.spec.play:
        out.append(play_verdict(s, data.layout.play_min))
    return out


def _finite(values: np.ndarray) -> list[float]:
    return [float(v) if math.isfinite(v) else math.nan for v in values]


def assembly_report(outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
    data: AssemblySweep = outcome.data
    s = outcome.summary
    kin, unit = data.spec.kin, s["motion_unit"]
    x = [float(v) for v in kin.coordinates]
    rows: list[dict] = []
    live = data.spec.live_rules
    for sr in data.states:
        for i, xi in enumerate(x):
            row: dict = {"state": sr.name, f"{kin.driver}_{unit}": xi}
            for k, rule in enumerate(live):  # the pairs queried (the others: never within the margin)
                row[f"clearance_{rule.key}_mm"] = float(sr.clearance[i, k])
            if data.spec.play:
                pu = s["play_unit"]
                row[f"play_plus_{pu}"], row[f"play_minus_{pu}"] = float(sr.play[i, 0]), float(sr.play[i, 1])
            rows.append(row)
    plots = []
    shown = [r for r in live if r.declared and r.moving] or [r for r in live if r.moving]
    if shown:
        series = []
        for sr in data.states:
            for rule in shown[:8]:
                k = live.index(rule)
                label = f"{rule.a} – {rule.b}" + ("" if sr.name == "as_built" else f" ({sr.name})")
                series.append(Series(label, x, _finite(sr.clearance[:, k])))
        hl = [(f"required {r.a} – {r.b}", r.min_clearance_mm) for r in shown[:8] if r.kind == "clearance"
              and r.min_clearance_mm > 0]
        plots.append(Plot("Clearance over the motion", f"{kin.driver} ({unit})", "clearance (mm)", series,
                          hlines=hl, caption="FCL distance between the meshes at each pose; below zero, the overlap "
                                             "along the motion (the move that frees the pair)."))
    if data.spec.play:
        pu = s["play_unit"]
        scale = 60.0 if pu == "deg" else 1.0
        series = []
        for sr in data.states:
            tail = "" if sr.name == "as_built" else f" ({sr.name})"
            series.append(Series("play, total" + tail, x, _finite((sr.play[:, 0] + sr.play[:, 1]) * scale)))
            series.append(Series("to contact, +" + tail, x, _finite(sr.play[:, 0] * scale), "points"))
            series.append(Series("to contact, −" + tail, x, _finite(sr.play[:, 1] * scale), "points"))
        hl = [("required", data.layout.play_min * scale)] if data.layout.play_min is not None else []
        plots.append(Plot(f"Play of {data.spec.play} over the motion", f"{kin.driver} ({unit})",
                          "play (arcmin)" if pu == "deg" else "play (mm)", series, hlines=hl,
                          caption="The part turned both ways from its coupled position to contact, the others held "
                                  "(bisection on FCL collide)."))
    notes = [f"{s['poses']} poses of {kin.driver} from {s['motion_start']:g} to {s['motion_end']:g} {unit}"
             + (f", states: {', '.join(s['states'])}" if len(s["states"]) > 1 else "")
             + f"; {len(data.spec.pairs)} pairs checked; {s['fcl_queries']} FCL queries."]
    return Report(rows=rows, plots=plots, notes=notes)
