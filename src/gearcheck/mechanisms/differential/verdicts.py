"""The differential's verdicts at the template's shim: no interference warm, play left at the cold
design point over the whole cycle, play over the operating range (binding there fails) and over
the storage range (binding there only warns, with the temperature where contact starts and how
deep the flanks overlap at the storage minimum), and the mesh sweep agreeing with the exact-flank
model.

Evidence. The play verdicts at the meshed states rest on the mesh sweep with the exact model
agreeing — unless the pipeline found that no practical mesh resolves the smallest play decided
(``outcome.mesh_resolves`` False: the pair's mesh-error bound exceeds 1/10 of it); then the sign
of the exact model decides them and the pipeline confirms the worst poses on the exact B-rep. The
range verdicts rest on the exact model over the whole temperature grid (the mesh samples only the
range's ends), with the mesh sweep's agreement at the meshed temperatures stated.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.mechanisms.differential.reduce import AGREEMENT_RELATIVE, SweepData
from gearcheck.mechanisms.differential.tca import RUNNING_STATES
from gearcheck.mechanisms.differential.temperature import ONSET_TOL_K, STATE_TEXT, shim_text
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS
from gearcheck.results import SweepOutcome, Verdict

EXACT = "exact model (spherical-involute flanks, no mesh)"
# The exact least plays are refined between the swept drive angles (reduce._refined, temperature.refined).
CONTINUOUS = ("the exact least play over the continuous cycle (refined between the swept drive angles until its "
              "bracket is below 0.0005′)")


def _unresolved(data: SweepData) -> str:
    return (f"; the mesh (pair bound ±{data.bound_mm * 1e3:.1f} µm = ±{data.bound_arcmin:.2f}′ on d1/2) cannot resolve "
            "the smallest play decided, so the exact model's sign decides, confirmed at the worst poses on the exact "
            "B-rep")


def _play_evidence(data: SweepData, resolves: bool, states: str) -> str:
    if not resolves:
        return f"{EXACT}, {CONTINUOUS}" + _unresolved(data)
    return f"mesh sweep (FCL on the built meshes, {states}), exact model agrees; {CONTINUOUS}"


def verdicts(params, outcome: SweepOutcome) -> list[Verdict]:
    data: SweepData = outcome.data
    resolves = bool(getattr(outcome, "mesh_resolves", True))
    requirement = _cold_requirement(params, data, resolves)
    pattern = _pattern(params, data)
    return [_warm(data, resolves), _cold(data, resolves), *([requirement] if requirement else []),
            *([pattern] if pattern else []), _operating(params, data, resolves), _storage(params, data),
            _agreement(data)]


def _pattern(params, data: SweepData) -> Verdict | None:
    """The template's ``[tca] pattern_min_length``: at every running state the check meshes,
    the pattern of both flanks of the big gear's tooth covers at least that share of the face
    width and stays on the involute (never below the form line). Short: the template's level."""
    spec = params.tca
    required = spec.pattern_min_length
    if required is None:
        return None
    running = [p for p in data.tca if p.name in RUNNING_STATES]
    if not running:
        return None
    worst, where, parts, below = math.inf, "", [], []
    for pair in running:
        ext = {f: p.extent() for f, p in pair.patterns.items()}
        length = min(p.length for p in pair.patterns.values())
        state = f"{STATE_TEXT[pair.name]} {pair.temperature_C:g} °C"
        if length < worst:
            worst, where = length, state
        drive = ext["drive"]
        ends = " and ".join(w for w in ("toe", "heel") if drive[w])
        reach = f", reaches the {ends}" if ends else ""
        parts.append(f"{state} {length:.0%} (centre {drive['centre_along']:.2f}{reach})")
        below += [f"{STATE_TEXT[pair.name]} {f}" for f, e in ext.items() if e["below_form"]]
    met = worst >= required and not below
    measured = (f"least pattern length {worst:.0%} of the face ({where}), both flanks under {spec.compound_um:g} µm "
                "of compound (centre: toe 0 … heel 1): " + "; ".join(parts)
                + (f"; below the form line: {', '.join(below)}" if below
                   else "; on the involute at every running state"))
    short = (f"pattern length {worst:.0%} of the face, required ≥ {required:.0%}" if worst < required
             else f"pattern below the form line ({', '.join(below)})")
    return Verdict.graded("contact_pattern", f"contact pattern bears over ≥ {required:.0%} of the face at "
                          "every running state, on the involute", "pass" if met else spec.level, measured,
                          {"least_length": worst, "required": required},
                          "exact model (the gap to the mating spherical-involute flank over a whole pass of the "
                          "tooth, no mesh)", "" if met else short)


def _cold_requirement(params, data: SweepData, resolves: bool) -> Verdict | None:
    """The template's ``[targets] cold_backlash_total_min_arcmin``: the least total backlash (both
    sides, twice the least play per side) over the whole cycle at the cold design point, from the
    geometry where the meshes resolve it (the exact model beside it; the smaller decides), else
    from the exact model. Below the target: the template's level (fail unless it says warn)."""
    target = params.targets.cold_backlash_total_min_arcmin
    if target is None:
        return None
    t, c = data.t, data.c
    geom, exact = 2.0 * float(data.geom_min[t, c]), 2.0 * float(data.exact_min[t, c])
    least = min(geom, exact) if resolves else exact
    met = least >= target
    cold = data.states[c][1]
    why = f" ({params.targets.reason})" if params.targets.reason and not met else ""
    return Verdict.graded(
        "cold_backlash_target", f"cold total backlash ≥ {target:g}′ at {cold:g} °C (the design's target), shim "
                                f"{shim_text(data.shims[t])} mm", "pass" if met else params.targets.level,
        f"least cold total {geom:.3f}′ (geometry), exact {exact:.3f}′, required ≥ {target:g}′{why}",
        {"geom_cold_backlash_total_min_arcmin": geom, "exact_cold_backlash_total_min_arcmin": exact,
         "target_arcmin": float(target)},
        evidence=_play_evidence(data, resolves, f"{cold:g} °C"),
        shortfall=f"least cold total {least:.3f}′, required ≥ {target:g}′, short by {target - least:.3f}′{why}")


def _warm(data: SweepData, resolves: bool) -> Verdict:
    t, w, angles = data.t, data.w, data.angles
    geom_play, geom_min, exact_min = data.geom_play, data.geom_min, data.exact_min
    warm_free = bool(data.centred_free[t, w].all())
    least = np.unravel_index(np.argmin(geom_play[t, w]), geom_play[t, w].shape)
    n_poses = len(angles) * len(BIG_GEARS) * len(SMALL_GEARS)
    passed = (warm_free and bool(geom_min[t, w] > 0.0)) if resolves else bool(exact_min[t, w] > 0.0)
    return Verdict.of(
        "no_interference_warm", f"no interference warm at shim {shim_text(data.shims[t])} mm", passed,
        f"{n_poses} centred poses (4 meshes × {len(angles)} drive angles) free{'' if warm_free else ' — NOT all'}; "
        f"contact reached both ways at every pose; least warm play {geom_min[t, w]:.3f}′ per side "
        f"({BIG_GEARS[least[1]]}, drive {math.degrees(angles[least[0]]):.2f}°), exact {exact_min[t, w]:.3f}′ "
        "over the continuous cycle, "
        f"mesh bound ±{2 * data.bound_arcmin:.2f}′ on a play",
        {"centred_poses_free": float(warm_free), "geom_play_min_arcmin_at_warm": float(geom_min[t, w]),
         "exact_play_min_arcmin_at_warm": float(exact_min[t, w])},
        evidence=_play_evidence(data, resolves, f"{data.states[w][1]:g} °C"),
        shortfall=_play_shortfall("least warm play", float(geom_min[t, w]), float(exact_min[t, w]), warm_free))


def _cold(data: SweepData, resolves: bool) -> Verdict:
    t, c = data.t, data.c
    geom_min, exact_min = data.geom_min, data.exact_min
    centred_free = bool(data.centred_free[t, c].all())
    if resolves:
        passed = bool(geom_min[t, c] > 0.0 and exact_min[t, c] > 0.0 and centred_free)
    else:
        passed = bool(exact_min[t, c] > 0.0)
    return Verdict.of(
        "cold_play_positive", f"cold play > 0 over the whole cycle at shim {shim_text(data.shims[t])} mm, "
                              f"{data.states[c][1]:g} °C (cold design point)", passed,
        f"least cold play {geom_min[t, c]:.3f}′ per side (geometry), exact {exact_min[t, c]:.3f}′ over the "
        "continuous cycle; "
        f"centred cold poses {'all free' if centred_free else 'COLLIDE'}; worst-case mesh bound "
        f"±{2 * data.bound_arcmin:.2f}′ on a play (the mesh matches the exact flanks to "
        f"{np.nanmax(data.total_dev[t, c]):.3f}′ here)",
        {"centred_poses_free": float(centred_free), "geom_play_min_arcmin_at_cold": float(geom_min[t, c]),
         "exact_play_min_arcmin_at_cold": float(exact_min[t, c])},
        evidence=_play_evidence(data, resolves, f"{data.states[c][1]:g} °C"),
        shortfall=_play_shortfall(f"least cold play at {data.states[c][1]:g} °C", float(geom_min[t, c]),
                                  float(exact_min[t, c]), centred_free))


def _play_shortfall(what: str, geom: float, exact: float, free: bool) -> str:
    """A play verdict's shortfall: the least play against the required > 0 (negative: the flanks
    overlap by that angle)."""
    least = min(geom, exact)
    text = f"{what} {geom:.3f}′ per side (geometry), exact {exact:.3f}′, required > 0"
    if least <= 0:
        text += f", short by {-least:.3f}′ (the flanks overlap)"
    return text + ("" if free else "; centred poses collide")


def _range_shortfall(span: str, least: float, at: float, depth_um: float) -> str:
    text = f"least play over {span} {least:.3f}′ per side at {at:g} °C (exact), required > 0"
    return text + (f", short by {-least:.3f}′ ({depth_um:.2f} µm overlap on d1/2)" if least <= 0 else "")


def _unsolved(r, lo: float, hi: float) -> str:
    out = [t for t in r.unsolved_C if lo - 1e-9 <= t <= hi + 1e-9]
    return (f"; the exact model found no contact within its reach at {', '.join(f'{t:g}' for t in out)} °C"
            if out else "")


def _meshed_within(data: SweepData, lo: float, hi: float) -> list[int]:
    return [j for j, (_, temp) in enumerate(data.states) if lo - 1e-9 <= temp <= hi + 1e-9 and data.measured[data.t, j]]


def _grid_text(data: SweepData, lo: float, hi: float) -> str:
    r = data.range
    n = int(np.sum((r.temperatures_C >= lo - 1e-9) & (r.temperatures_C <= hi + 1e-9)))
    return f"{n} temperatures over {lo:g}…{hi:g} °C in ≤ {np.max(np.diff(r.temperatures_C), initial=0):.0f} K steps"


def _mesh_text(data: SweepData, states: list[int]) -> str:
    t = data.t
    return ", ".join(f"{data.states[j][1]:g} °C geometry {data.geom_min[t, j]:.3f}′ / exact {data.exact_min[t, j]:.3f}′"
                     for j in states)


def _operating(params, data: SweepData, resolves: bool) -> Verdict:
    op = params.operating
    r = data.range
    least, at = r.operating
    meshed = _meshed_within(data, op.operating_min_C, op.operating_max_C)
    mesh_least = min((float(data.geom_min[data.t, j]) for j in meshed), default=math.inf)
    passed = least > 0.0 and (mesh_least > 0.0 or not resolves)
    evidence = f"{EXACT}, {CONTINUOUS} at each temperature, {_grid_text(data, op.operating_min_C, op.operating_max_C)}"
    evidence += f"; mesh sweep agrees at {', '.join(f'{data.states[j][1]:g}' for j in meshed)} °C" if resolves else \
        _unresolved(data)
    figures = {"exact_operating_least_play_arcmin": least, "exact_operating_least_play_at_C": at}
    if math.isfinite(mesh_least):
        figures["geom_operating_least_play_arcmin"] = mesh_least
    return Verdict.of(
        "operating_play_positive",
        f"play > 0 over the operating range {op.operating_min_C:g}…{op.operating_max_C:g} °C at shim "
        f"{shim_text(data.shims[data.t])} mm", passed,
        f"least exact play {least:.3f}′ per side at {at:g} °C"
        + (f" — binds: the flanks overlap by {r.depth_um(least):.2f} µm on d1/2" if least <= 0 else "")
        + _unsolved(r, op.operating_min_C, op.operating_max_C) + f"; meshed: {_mesh_text(data, meshed)}",
        figures, evidence=evidence,
        shortfall=_range_shortfall(f"{op.operating_min_C:g}…{op.operating_max_C:g} °C", least, at, r.depth_um(least))
        + (f"; geometry {mesh_least:.3f}′" if math.isfinite(mesh_least) and mesh_least <= 0 else ""))


def _storage(params, data: SweepData) -> Verdict:
    op = params.operating
    r = data.range
    least, at = r.storage
    onset = r.cold_onset_C if r.cold_onset_C is not None and r.cold_onset_C >= op.storage_min_C else r.hot_onset_C
    figures = {"exact_storage_least_play_arcmin": least, "exact_storage_least_play_at_C": at,
               "exact_storage_min_play_arcmin": r.at("storage_min"),
               "overlap_at_storage_min_um": r.depth_um(r.at("storage_min"))}
    meshed = _meshed_within(data, op.storage_min_C, op.storage_max_C)
    evidence = (f"{EXACT}, {CONTINUOUS} at each temperature, "
                f"{_grid_text(data, op.storage_min_C, op.storage_max_C)}; mesh sweep at "
                f"{', '.join(f'{data.states[j][1]:g}' for j in meshed)} °C beside it")
    if least > 0.0:
        return Verdict.of(
            "storage_play_positive",
            f"play > 0 over the storage range {op.storage_min_C:g}…{op.storage_max_C:g} °C at shim "
            f"{shim_text(data.shims[data.t])} mm", True,
            f"least exact play {least:.3f}′ per side at {at:g} °C; meshed: {_mesh_text(data, meshed)}", figures,
            evidence=evidence)
    if not math.isfinite(least):
        return Verdict.graded(
            "storage_play_positive",
            f"play > 0 over the storage range {op.storage_min_C:g}…{op.storage_max_C:g} °C at shim "
            f"{shim_text(data.shims[data.t])} mm", "warn",
            "not decided" + _unsolved(r, op.storage_min_C, op.storage_max_C), figures, evidence=evidence,
            shortfall="not decided: " + _unsolved(r, op.storage_min_C, op.storage_max_C).removeprefix("; "))
    if onset is not None:
        figures["binding_onset_C"] = onset
    deep = r.at("storage_min")
    where = (f"contact starts at {onset:.2f} °C (exact model, ±{ONSET_TOL_K:g} K)" if onset is not None
             else "binds at every storage temperature checked")
    also = " (and in the operating range: see operating_play_positive)" if r.binds_operating else \
        f"; the operating range stays free (least {r.operating[0]:.3f}′ at {r.operating[1]:g} °C)"
    return Verdict.graded(
        "storage_play_positive",
        f"play > 0 over the storage range {op.storage_min_C:g}…{op.storage_max_C:g} °C at shim "
        f"{shim_text(data.shims[data.t])} mm", "warn",
        f"binds in storage: {where}; at the storage minimum {op.storage_min_C:g} °C the flanks overlap by "
        f"{-deep:.3f}′ per side ({r.depth_um(deep):.2f} µm on d1/2){also}; meshed: {_mesh_text(data, meshed)}",
        figures, evidence=evidence,
        shortfall=(f"play per side required > 0 down to {op.storage_min_C:g} °C; "
                   + (f"binds from {onset:.2f} °C, " if onset is not None else "binds, ")
                   + f"at {op.storage_min_C:g} °C short by {-deep:.3f}′ ({r.depth_um(deep):.2f} µm overlap on d1/2)"))


def _agreement(data: SweepData) -> Verdict:
    total_dev = data.total_dev
    return Verdict.of(
        "mesh_agrees_with_exact", "mesh sweep agrees with the exact-flank model",
        data.contact_ok and data.total_ok,
        f"largest difference {data.contact_dev.max():.3f}′ per contact and {np.nanmax(total_dev):.3f}′ per play over "
        f"{data.contacts} contacts at {int(data.measured.sum())} shim/temperature states; allowed "
        f"{data.bound_arcmin:.2f}′ (bound {data.bound_mm * 1e3:.1f} µm on d1/2) + {AGREEMENT_RELATIVE:.0%} per "
        "contact, twice the bound per play",
        {"max_contact_deviation_arcmin": float(data.contact_dev.max()),
         "max_play_deviation_arcmin": float(np.nanmax(total_dev)), "mesh_error_bound_arcmin": data.bound_arcmin},
        evidence="mesh sweep against the exact model, contact by contact",
        shortfall=_agreement_shortfall(data))


def _agreement_shortfall(data: SweepData) -> str:
    over = [what for what, ok in (("per contact", data.contact_ok), ("per play", data.total_ok)) if not ok]
    return (f"mesh against exact: {data.contact_dev.max():.3f}′ per contact (allowed {data.bound_arcmin:.2f}′ + "
            f"{AGREEMENT_RELATIVE:.0%}), {np.nanmax(data.total_dev):.3f}′ per play (allowed "
            f"{2 * data.bound_arcmin:.2f}′ + {AGREEMENT_RELATIVE:.0%}): beyond the allowance {' and '.join(over)}")
