"""The differential's report content: one sweep.csv row per (shim, state, drive angle), the paper
vs model vs geometry comparisons, the plots over the cycle, against shim and against temperature
(play and where the least play is decided on the flanks), and the notes in words."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from gearcheck.mechanisms.differential import PAPER, paper_conditions
from gearcheck.mechanisms.differential.reduce import SweepData
from gearcheck.mechanisms.differential.sweep import DIRECTIONS
from gearcheck.mechanisms.differential.tca_report import tca_overlays, tca_plots
from gearcheck.mechanisms.differential.temperature import STATE_TEXT, RangeCheck, shim_text
from gearcheck.mechanisms.differential.thermal import BIG_GEARS
from gearcheck.results import Comparison, Plot, Report, Series, SweepOutcome, Verdict


def report(params, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
    data: SweepData = outcome.data
    return Report(rows(data), comparisons(params, data, outcome.summary), plots(params, data),
                  notes(params, data, outcome.summary), tca_overlays(data.tca, data.specs))


def rows(data: SweepData) -> list[dict]:
    geom_play, exact_play = data.geom_play, data.exact_play
    out = []
    for i, shim in enumerate(data.shims):
        for j, (state, temp) in enumerate(data.states):
            if not data.measured[i, j]:
                continue
            for k, phi in enumerate(data.angles):
                row = {"shim_mm": shim, "state": state, "temperature_C": temp, "drive_angle_deg": math.degrees(phi)}
                for b, big in enumerate(BIG_GEARS):
                    side = big.removeprefix("big_gear_")
                    row.update({
                        f"{side}_geom_plus_arcmin": data.geom_plus[i, j, k, b],
                        f"{side}_geom_minus_arcmin": data.geom_minus[i, j, k, b],
                        f"{side}_geom_play_arcmin": geom_play[i, j, k, b],
                        f"{side}_exact_plus_arcmin": data.exact_plus[i, j, k, b],
                        f"{side}_exact_minus_arcmin": data.exact_minus[i, j, k, b],
                        f"{side}_exact_play_arcmin": exact_play[i, j, k, b],
                        f"{side}_centred_free": int(data.centred_free[i, j, k, b]),
                    })
                row["model_play_arcmin"] = data.model_play(i, temp)
                out.append({key: (float(v) if isinstance(v, (np.floating, float)) else v) for key, v in row.items()})
    return out


def _range_markers(params, r: RangeCheck) -> list[tuple[str, float]]:
    op = params.operating
    out = [("operating min", op.operating_min_C), ("operating max", op.operating_max_C),
           ("storage min", op.storage_min_C), ("storage max", op.storage_max_C)]
    out += [(f"binding starts (exact), {t:.1f} °C", t) for t in r.onsets_C]
    return out


def _spots(r: RangeCheck) -> list:
    """Where the least-play contacts lie at each temperature of a range (empty if not solved)."""
    return list(r.plays.spots) if r.plays is not None and r.plays.spots is not None else []


def _temperature_plots(params, data: SweepData) -> list[Plot]:
    t, r = data.t, data.range
    temps = r.temperatures_C.tolist()
    thinning = params.thinning()
    others = sorted(i for i in data.ranges if i != t)
    meshed = [j for j in range(len(data.states)) if data.measured[t, j]]
    play = Plot(
        "Least play over the cycle against temperature", "temperature (°C)", "least play per side (arcmin)",
        [Series(f"exact flanks, shim {shim_text(data.shims[t])} mm (template)", temps, r.least_arcmin.tolist()),
         Series(f"paper's linear model (eqs 1–11), shim {shim_text(data.shims[t])} mm, thinning "
                f"{thinning.template_min_mm:.4f} mm", temps, [data.model_play(t, x) for x in temps]),
         Series(f"geometry (mesh sweep), shim {shim_text(data.shims[t])} mm", [data.states[j][1] for j in meshed],
                [float(data.geom_min[t, j]) for j in meshed], "points")]
        + [Series(f"exact flanks, shim {shim_text(data.shims[i])} mm", data.ranges[i].temperatures_C.tolist(),
                  data.ranges[i].least_arcmin.tolist()) for i in others],
        markers=_range_markers(params, r), hlines=[("binding", 0.0)])
    out = [play]
    spot_shims = [i for i in [t, *others] if _spots(data.ranges[i])]
    if spot_shims:
        def series(i: int, pick, what: str) -> Series:
            rr = data.ranges[i]
            return Series(f"{what}, shim {shim_text(data.shims[i])} mm", rr.temperatures_C.tolist(),
                          [pick(s) for s in _spots(rr)])

        out.append(Plot(
            "Where the least play is decided: along the face (big gear, exact flanks)", "temperature (°C)",
            "contact cone distance, 0 toe … 1 heel",
            [series(i, lambda s: s[0][0].along, "contact +") for i in spot_shims]
            + [series(i, lambda s: s[1][0].along, "contact −") for i in spot_shims],
            markers=_range_markers(params, r)))
        out.append(Plot(
            "Where the least play is decided: tooth height (exact flanks)", "temperature (°C)",
            "contact height, 0 root … 1 tip (polar angle)",
            [series(i, lambda s: s[0][0].height, "big gear, contact +") for i in spot_shims]
            + [series(i, lambda s: s[0][1].height, "small gear, contact +") for i in spot_shims],
            markers=_range_markers(params, r)))
    return out


def plots(params, data: SweepData) -> list[Plot]:
    t, w, c, shims, models = data.t, data.w, data.c, data.shims, data.models
    geom_play, exact_play, geom_min, exact_min = data.geom_play, data.exact_play, data.geom_min, data.exact_min
    deg = np.degrees(data.angles).tolist()
    meshed = [j for j in range(len(data.states)) if data.measured[t, j]]
    # the two output shafts: one series each where they differ, one for both where they do not
    same = float(np.nanmax(np.abs(geom_play[t, ..., 0] - geom_play[t, ..., 1])))
    shafts = ([(0, "both shafts")] if same < 1e-6
              else [(b, big.removeprefix("big_gear_")) for b, big in enumerate(BIG_GEARS)])
    period_text = f"{math.degrees(data.period_rad):.2f}° of drive"
    return [
        Plot(f"Play of the output shafts over one cycle ({period_text}), shim {shim_text(shims[t])} mm",
             "small-gear drive angle (deg)", "play per side (arcmin)",
             [Series(f"geometry {data.state_label(j)}, {label}", deg, geom_play[t, j, :, b].tolist(), "points")
              for j in meshed for b, label in shafts]
             + [Series(f"exact flanks {data.state_label(j)}", deg, exact_play[t, j, :, 0].tolist()) for j in meshed],
             hlines=[("paper model warm", data.model_play(t, data.states[w][1])),
                     ("paper model cold", data.model_play(t, data.states[c][1])), ("binding", 0.0)]),
        Plot("Least play over the cycle against shim", "shim under each big gear (mm)", "least play per side (arcmin)",
             [Series("geometry warm", list(shims), geom_min[:, w].tolist(), "points"),
              Series("geometry cold", list(shims), geom_min[:, c].tolist(), "points"),
              Series("exact flanks warm", list(shims), exact_min[:, w].tolist()),
              Series("exact flanks cold", list(shims), exact_min[:, c].tolist()),
              Series("paper model warm (eqs 1–11)", list(shims), [m.warm for m in models]),
              Series("paper model cold (eqs 1–11)", list(shims), [m.cold for m in models])],
             markers=[("template shim", data.template_shim_mm)], hlines=[("binding", 0.0)]),
        Plot("Cold drop against shim", "shim under each big gear (mm)",
             "cycle min warm − cycle min cold, per side (arcmin)",
             [Series("geometry", list(shims), (geom_min[:, w] - geom_min[:, c]).tolist(), "points"),
              Series("exact flanks", list(shims), (exact_min[:, w] - exact_min[:, c]).tolist()),
              Series("paper model (printed eq 9)", list(shims), [m.drop for m in models]),
              Series("paper model (clean eq 9)", list(shims), [m.clean_drop for m in models])],
             markers=[("template shim", data.template_shim_mm)]),
        *_temperature_plots(params, data),
        *(tca_plots(data.tca) if data.tca else []),
    ]


def comparisons(params, data: SweepData, summary: dict) -> list[Comparison]:
    """The table's rows: arcmin at 2 decimals (0.6″), °C at 2; the mesh sweep agrees within its
    error bound on each play in the figure (a per-side play: twice the per-contact bound)."""
    out = []
    for row in _comparisons(params, data, summary):
        plays = 4 if ("both sides" in row.label or "total" in row.label) else 2
        out.append(dataclasses.replace(row, digits=2, tolerance=plays * data.bound_arcmin if row.unit == "arcmin"
                                       else 0.0))
    return out


def _comparisons(params, data: SweepData, summary: dict) -> list[Comparison]:
    t, z, w, c, shims, model, models = data.t, data.z, data.w, data.c, data.shims, data.model, data.models
    geom_min, exact_min = data.geom_min, data.exact_min
    at_paper_dT, at_paper_shim = paper_conditions(params)  # the paper's unit, at the paper's conditions
    thinning = params.thinning()
    why = ("displaced apexes make the mesh non-conjugate (docs/differential.md); a net approach is decided at the toe, "
           "an opening at the heel: reported, not tuned")
    warm_note = ("gears built with the thinning solved from this measurement on the exact geometry: agreement by "
                 "construction" if thinning.calibrated else
                 "built with the least thinning; the shim gains less on exact flanks")
    out = [
        Comparison(f"cold backlash drop per side, shim {shim_text(shims[t])} mm", "arcmin",
                   PAPER["cold_drop_per_side_arcmin"] if at_paper_dT else None, model.drop,
                   summary["geom_cold_drop_per_side_arcmin"], why, summary["exact_cold_drop_per_side_arcmin"]),
        Comparison("cold backlash drop, both sides", "arcmin",
                   PAPER["cold_drop_total_arcmin"] if at_paper_dT else None, 2 * model.drop,
                   2 * summary["geom_cold_drop_per_side_arcmin"], "twice the per-side drop",
                   2 * summary["exact_cold_drop_per_side_arcmin"]),
        Comparison("cold drop per side, clean eq (9)", "arcmin", None, model.clean_drop,
                   summary["geom_cold_drop_per_side_arcmin"], "dimensionally clean eq (9) (docs/differential.md)",
                   summary["exact_cold_drop_per_side_arcmin"]),
        Comparison(f"warm backlash total, least, shim {shim_text(shims[t])} mm", "arcmin",
                   PAPER["warm_backlash_total_min_arcmin"] if at_paper_shim else None, 2 * model.warm,
                   float(2 * geom_min[t, w]), warm_note, float(2 * exact_min[t, w])),
        Comparison(f"cold backlash total, least, shim {shim_text(shims[t])} mm", "arcmin",
                   PAPER["cold_backlash_total_min_arcmin"] if (at_paper_shim and at_paper_dT) else None,
                   2 * model.cold, float(2 * geom_min[t, c]),
                   _cold_bound_note(float(2 * exact_min[t, c]), 2 * model.cold) if (at_paper_shim and at_paper_dT)
                   else "", float(2 * exact_min[t, c]),
                   paper_is="min"),
    ]
    if z is not None:
        out.insert(3, Comparison(
            f"shim gain per side, {shim_text(shims[t])} mm", "arcmin", None, summary["model_shim_gain_per_side_arcmin"],
            summary["geom_shim_gain_per_side_arcmin"],
            "eq (11); the shim slides the big gear's apex off the common apex too",
            summary["exact_shim_gain_per_side_arcmin"]))
        out.append(Comparison(
            "cold play per side, no shim", "arcmin", None, models[z].cold, float(geom_min[z, c]),
            "binds cold (negative: overlap as an angle)" if geom_min[z, c] <= 0 else "", float(exact_min[z, c])))
    rng = data.range
    for j, (name, temp) in enumerate(data.states):
        if name in ("warm", "cold") or not data.measured[t, j]:
            continue
        out.append(Comparison(
            f"least play per side at {STATE_TEXT[name]} {temp:g} °C, shim {shim_text(shims[t])} mm", "arcmin", None,
            data.model_play(t, temp), float(geom_min[t, j]),
            "paper model: linear in the temperature; exact: heel-limited warm, toe-limited cold",
            float(exact_min[t, j])))
    linear_onset = data.warm_C - model.warm / data.model_per_K if data.model_per_K > 0 else None
    out.append(Comparison(
        f"binding starts (cooling), shim {shim_text(shims[t])} mm", "°C", None, linear_onset, None,
        "exact: solved on the exact model; model: its linear law extended" if rng.cold_onset_C is not None
        else "the exact model does not bind cold within the ranges", rng.cold_onset_C))
    return out


def _cold_bound_note(exact_total: float, model_total: float) -> str:
    bound = PAPER["cold_backlash_total_min_arcmin"]
    text = f"the paper's figure is a bound (\"still not less than {bound:g}′\")"
    if exact_total < bound <= model_total:
        return text + ("; eqs (1)–(11) meet it, the exact flanks do not: they lose more backlash cold (see the cold "
                       "drop above)")
    return text


def _cycle_note(data: SweepData) -> str:
    pitch_deg = math.degrees(data.specs.small.angular_pitch_rad)
    period_deg = math.degrees(data.period_rad)
    n = len(data.angles)
    text = (f"Cycle: identical teeth, so one small-gear pitch ({pitch_deg:.2f}°) of drive repeats every pose. "
            f"{n} drive angles over {period_deg:.2f}°")
    if period_deg < pitch_deg - 1e-9:
        text += (" (half a pitch: z_big is odd, so each big gear meets its two small gears half a tooth apart and "
                 "its play repeats every half pitch, checked on the poses; its two meshes together pass "
                 f"{2 * n} phases of one full mesh cycle)")
    text += (f". Exact solves: {data.exact_solves}; {data.exact_reused * len(DIRECTIONS)} more contacts are on "
             "pairs congruent to a solved one at the same pose (the other output shaft), checked on the poses, "
             "and get only their own mesh bisection.")
    return text


def _slopes(r: RangeCheck) -> tuple[float, float]:
    """The exact loss per kelvin at the warm end and at the cold end of the grid (arcmin/K)."""
    temps, least = r.temperatures_C, r.least_arcmin
    return (float((least[-1] - least[-2]) / (temps[-1] - temps[-2])),
            float((least[1] - least[0]) / (temps[1] - temps[0])))


def _temperature_note(params, data: SweepData) -> str:
    r, t = data.range, data.t
    op = params.operating
    warm_slope, cold_slope = _slopes(r)
    text = (f"Over temperature (shim {shim_text(data.shims[t])} mm, exact flanks, {len(r.temperatures_C)} "
            f"temperatures): the play falls {warm_slope:.4f}′/K per side near warm (an opening or small approach "
            f"is decided at the heel) and {cold_slope:.4f}′/K at the cold end (the approach is decided at the "
            f"toe); the paper's linear model loses {data.model_per_K:.4f}′/K everywhere. Least play over the "
            f"operating range {r.operating[0]:.3f}′ at {r.operating[1]:g} °C; over the storage range "
            f"{r.storage[0]:.3f}′ at {r.storage[1]:g} °C.")
    if r.cold_onset_C is not None:
        deep = r.at("storage_min")
        text += (f" Cooling, contact starts at {r.cold_onset_C:.2f} °C; at the storage minimum {op.storage_min_C:g} °C "
                 f"the flanks overlap by {-deep:.3f}′ per side ({r.depth_um(deep):.2f} µm on d1/2)" if deep < 0 else
                 f" Cooling, contact starts at {r.cold_onset_C:.2f} °C.")
        text += ("; the paper's linear model, extended, stays free to "
                 f"{data.warm_C - data.model.warm / data.model_per_K:.0f} °C." if data.model_per_K > 0 else ".")
    return text


def _thinning_note(params, data: SweepData) -> str:
    th = params.thinning()
    if not th.calibrated:
        return (f"Tooth thinning {th.min_mm:.4f}–{th.max_mm:.4f} mm per mesh: the design's [backlash], built with the "
                "least (no measured backlash given to calibrate it on the exact geometry).")
    c = params.calibration
    measured = f"{c.measured_backlash_total_min_arcmin:g}–{c.measured_backlash_total_max_arcmin:g}′"
    return (f"Calibration: the measured {measured} (both sides, shim {c.measured_shim_mm:g} mm, "
            f"{c.measured_at_C:g} °C, read as the least over the cycle) needs {th.min_mm:.4f}–{th.max_mm:.4f} mm of "
            "tooth thinning per mesh on the exact geometry; the template's [backlash] "
            f"{th.template_min_mm:.4f}–{th.template_max_mm:.4f} mm gives only "
            f"{th.template_exact_total_min_arcmin:.2f}′ (least) on the exact geometry. The gears are built with the "
            "solved thinning; the warm figures therefore match the measurement by construction, and the cold and "
            "storage figures follow from it.")


def _contact_note(data: SweepData) -> str:
    """Where the least play is decided, by shim, warm and cold, and whether it moves up the tooth
    as the shim grows."""
    parts = []
    for i in sorted(data.ranges):
        r = data.ranges[i]
        spots = _spots(r)
        if not spots:
            continue
        iw = int(np.argmin(np.abs(r.temperatures_C - r.keys["warm"])))
        ic = int(np.argmin(np.abs(r.temperatures_C - r.keys["cold"])))
        parts.append(f"shim {shim_text(data.shims[i])} mm: warm along {spots[iw][0][0].along:.2f}, big height "
                     f"{spots[iw][0][0].height:.2f}, small height {spots[iw][0][1].height:.2f}; cold along "
                     f"{spots[ic][0][0].along:.2f}, big height {spots[ic][0][0].height:.2f}, small height "
                     f"{spots[ic][0][1].height:.2f}")
    if not parts:
        return ""
    return ("Where the least play is decided (exact flanks, contact +; along the face 0 toe … 1 heel, height 0 root … "
            "1 tip): " + "; ".join(parts) + "." + _shim_contact_note(data))


def _shim_contact_note(data: SweepData) -> str:
    """Whether the warm least-play contact moves up the tooth as the shim grows, and whether the
    warm play grows linearly with the shim (shims opening the mesh, at least three)."""
    shims = [i for i in sorted(data.ranges) if _spots(data.ranges[i]) and data.shims[i] > 0.0]
    if len(shims) < 3:
        return ""
    heights, plays = [], []
    for i in shims:
        r = data.ranges[i]
        iw = int(np.argmin(np.abs(r.temperatures_C - r.keys["warm"])))
        heights.append((_spots(r)[iw][0][1].height, _spots(r)[iw][0][0].height))
        plays.append(float(r.least_arcmin[iw]))
    steps = np.diff(plays) / np.diff([data.shims[i] for i in shims])
    small, big = [h[0] for h in heights], [h[1] for h in heights]
    still = max(small) - min(small) < 0.05 and max(big) - min(big) < 0.05
    linear = float(np.ptp(steps)) < 0.02 * float(np.mean(np.abs(steps)))
    text = (f" As the shim grows ({', '.join(f'{data.shims[i]:.2f}' for i in shims)} mm), the warm least-play contact "
            f"stays at small-gear height {min(small):.2f}–{max(small):.2f} and big-gear height "
            f"{min(big):.2f}–{max(big):.2f}" if still else
            f" As the shim grows ({', '.join(f'{data.shims[i]:.2f}' for i in shims)} mm), the warm least-play contact "
            f"moves: small-gear height {' → '.join(f'{h:.2f}' for h in small)}, big-gear height "
            f"{' → '.join(f'{h:.2f}' for h in big)}")
    model = (data.models[shims[-1]].warm - data.models[shims[0]].warm) / (data.shims[shims[-1]] - data.shims[shims[0]])
    text += (f", and the warm play grows {' / '.join(f'{s:.1f}' for s in steps)}′ per mm of shim (the paper's model: "
             f"{model:.1f}′ per mm)"
             + (" — linearly: the geometry shows no contact moving toward the tip that would add backlash at the "
                "larger shims." if still and linear else "."))
    return text


def notes(params, data: SweepData, summary: dict) -> list[str]:
    shims, t, c, geom_min = data.shims, data.t, data.c, data.geom_min
    toe = data.specs.big.outer_cone_distance_mm / data.specs.big.inner_cone_distance_mm
    sm = summary
    out = [
        f"Cold drop per side at shim {shim_text(shims[t])} mm: geometry {sm['geom_cold_drop_per_side_arcmin']:.2f}′, "
        f"exact flanks {sm['exact_cold_drop_per_side_arcmin']:.2f}′, "
        f"paper's model {sm['model_cold_drop_per_side_arcmin']:.2f}′ "
        f"(clean eq 9: {sm['model_clean_cold_drop_per_side_arcmin']:.2f}′). Eqs (1)–(11) look at one tooth pair at the "
        "outer pitch point; the cold state slides each gear's apex off the common apex, so the mesh is no longer "
        "conjugate and neighbouring tooth pairs close up (docs/differential.md). Reported, not tuned.",
        "Where the play is decided: a translation changes the flank gap by the same amount in mm along the whole "
        "face, while the designed backlash tapers with the cone distance. A net opening (the shim) is therefore "
        "limited at the heel, as eq (10) assumes; a net approach (cold, little or no shim) at the toe, where the same "
        f"loss is Re/Ri = {toe:.2f} times the eq (10) angle. Hence the larger drop at small shims.",
        _temperature_note(params, data),
        _thinning_note(params, data),
        "Output-shaft play: each big gear meshes with both small gears; each way it stops at the tighter mesh "
        "(plus = min, minus = max over the two small gears). Per side = one big gear's play, as in the paper.",
        _cycle_note(data),
        f"Meshes pruned to the tooth halves that can touch ({sm['pruned_meshes']} pruned meshes, "
        f"{sm['pruned_triangles_mean']:.0f} triangles each on average); each direction measured on its own flank "
        "halves, so a side that binds gives a negative play instead of a failed bisection.",
        f"Mesh-error bound {sm['mesh_error_bound_mm'] * 1e3:.1f} µm per pair, {data.bound_arcmin:.2f}′ per contact on "
        f"d1/2; the mesh plays differ from the exact ones by at most {sm['max_mesh_exact_play_deviation_arcmin']:.3f}′ "
        "(a chordal mesh can overstate or understate a clearance by up to its bound, depending on the curvature of "
        "the faces; the exact B-rep table shows which way it erred at the worst poses).",
    ]
    contact = _contact_note(data)
    if contact:
        out.append(contact)
    binding = [i for i in range(len(shims)) if geom_min[i, c] <= 0.0]
    if binding:
        where = ", ".join(f"{shim_text(shims[i])} mm" for i in binding)
        out.append(f"Binds cold (geometry) at shim {where}: least cold "
                   f"play {', '.join(f'{geom_min[i, c]:.2f}′' for i in binding)} per side; a shim opens the mesh "
                   "(eq 11).")
    return out
