"""The steering check's claims, from the sweep's figures of both directions: continuous drive to
the target (towing and power mode, through every hand-over: the least of the exact model and the
mesh), the contact ratio at the machined hS4, the rack stopping and standing in towing, no
interference past the stop (the mesh, and the trimmed tops S2–S6 / S4–S8 against the tip lands
where the rack really stands: exact model, :mod:`.ends`), on the return swing or anywhere, and the
mesh towing curve agreeing with the exact push model."""

from __future__ import annotations

import math

from gearcheck.mechanisms.steering.ends import EndTop
from gearcheck.mechanisms.steering.push import TRAVEL_TOL_MM
from gearcheck.mechanisms.steering.sweep import SteeringSweep, drive_figures, sign, still_moving
from gearcheck.results import SweepOutcome, Verdict

# The mesh towing curve must agree with the exact-polyline push model within this.
TOWING_CURVE_TOL_MM = 0.05
# The pinion flanks are read from the mesh as the involutes through their vertices (exact points of
# the B-rep): no vertex may lie farther than this from its flank's involute (measured ≤ 0.001 µm).
FLANK_FIT_TOL_MM = 1e-4


def _ok(values, test) -> bool:
    return all(math.isfinite(v) and test(v) for v in values)


def verdicts(params, outcome: SweepOutcome) -> list[Verdict]:
    data: SteeringSweep = outcome.data
    plus, minus, tol = data.plus, data.minus, data.tol
    poses = data.speed["poses"]

    def each(key):
        return [s[key] for s in (plus, minus)]

    target, max_deg = params.targets.continuous_drive_deg, params.towing.max_angle_deg
    ret, re = each("min_clearance_return_swing_mm"), each("geom_reengage_angle_deg")
    clear = each("min_signed_clearance_mm")
    bracket = plus["geom_reengage_bracket_deg"]
    # zero-backlash contact: every interference claim is decided within the contact tolerance on
    # the meshes (no clearance for the mesh to resolve); the worst poses are confirmed on the B-rep
    swept = (f"mesh sweep (collisions measured as the rack shift that clears them, accepted within the "
             f"contact tolerance {tol:.3f} mm ≥ the meshes' error bound {data.bound:.3f} mm)")
    if not outcome.mesh_resolves:
        swept += "; the meshes do not resolve the design's clearance: the exact B-rep confirmation decides"
    exact_ok, exact_words, exact_figures, exact_short = _exact(data, "return_swing")
    ret_ok = _ok(ret, lambda c: c >= -tol)
    return [
        _continuous_drive(data, target),
        _contact_ratio(params, data.model.contact_ratio),
        _rack_stops(data, max_deg),
        _past_disengage(data, swept),
        Verdict.of("no_interference_reengage", "towing: no interference on the return swing and re-engagement",
                   ret_ok and exact_ok and _ok(re, lambda x: True),
                   _and(f"min signed clearance {_num(min(ret), 5)} mm ≥ −{tol:.3f} mm; picked up at +{_num(re[0])}° / "
                        f"−{_num(re[1])}° (free at {_num(bracket[0], 6)}°, touching at {_num(bracket[1], 6)}°)",
                        exact_words),
                   {**_finite({"min_signed_clearance_mm": min(ret), "contact_tolerance_mm": tol,
                               "plus_reengage_deg": re[0], "minus_reengage_deg": re[1]}), **exact_figures},
                   f"{EXACT_CERTIFIED}; {swept}; the pick-up bracketed by bisection on the pinion angle",
                   shortfall="; ".join(filter(None, [_clearance_shortfall(ret, tol) if not ret_ok else "",
                                                     exact_short]))
                   or "the return swing does not pick the rack up within the swing (no re-engage angle)"),
        _anywhere(data, clear, poses, swept),
        _mesh_agrees(data),
    ]


# The exact model's clearance between the poses (:mod:`.certified`).
EXACT_CERTIFIED = ("exact model certified over the continuous motion (every tooth pair's clearance in closed form "
                   "at the poses; between them bounded by the conjugate action, the stands and the driving contact, "
                   "intervals split where that does not decide)")


def _and(text: str, first: str) -> str:
    """A verdict's words led by the certified bound, where there is one (it decides: the line the
    command line prints starts with it)."""
    return f"{first}; mesh sweep: {text}" if first else text


def _exact(data: SteeringSweep, scope: str) -> tuple[bool, str, dict, str]:
    """(passes, words, figures, shortfall) of the exact model certified over the continuous motion
    for one claim's scope (all true and empty where the sweep has no such part)."""
    e = data.certified.get(scope)
    if e is None:
        return True, "", {}, ""
    least, req = e["certified_min_mm"], e["requirement_mm"]
    ok = math.isfinite(least) and least >= req
    words = (f"certified ≥ {_num(least, 6)} mm over the continuous motion (exact model: {e['where']}; "
             f"{e['intervals']} intervals, {e['intervals_refined']} refined)")
    figures = _finite({"exact_certified_min_mm": least, "exact_sampled_min_mm": e["sampled_min_mm"],
                       "exact_requirement_mm": req})
    short = "" if ok else (f"exact model: the clearance falls to {_num(least, 6)} mm ({e['where']}; "
                           f"certified over the continuous motion), required ≥ {req:g} mm")
    return ok, words, figures, short


def _anywhere(data: SteeringSweep, clear: list[float], poses: int, swept: str) -> Verdict:
    """Interference at any swept pose (mesh sweep), over the continuous motion (exact model,
    :mod:`.certified`), and a trimmed end tooth caught by its tip tooth (exact model, :mod:`.ends`):
    any decides."""
    tol = data.tol
    exact_ok, exact_words, exact_figures, exact_short = _exact(data, "anywhere")
    mesh_ok = _ok(clear, lambda c: c >= -tol) and exact_ok
    caught = [e for e in data.model.ends if not e.clears]
    measured = _and(f"min signed clearance {_num(min(clear), 5)} mm ≥ −{tol:.3f} mm over {poses} poses", exact_words)
    figures = {**_finite({"min_signed_clearance_mm": min(clear), "contact_tolerance_mm": tol}), **exact_figures}
    shortfall = "; ".join(filter(None, [_clearance_shortfall(clear, tol) if not _ok(clear, lambda c: c >= -tol)
                                        else "", exact_short]))
    evidence = f"{EXACT_CERTIFIED}; {swept}"
    if caught:
        measured += "; " + "; ".join(_end_measured(e) for e in caught)
        figures.update(_end_figures(data.model.ends))
        shortfall = "; ".join(filter(None, [shortfall, *(_end_shortfall(e) for e in caught)]))
        evidence = f"{END_EVIDENCE}; {evidence}"
    return Verdict.of("no_interference_anywhere", "no interference at any pose (towing both ways, power mode)",
                      mesh_ok and not caught, measured, figures, evidence, shortfall=shortfall)


# The exact model's rule for the trimmed end teeth (docs/steering.md, "Trimmed tops past the stop").
END_EVIDENCE = ("exact model (the stands of the push model past S2 and S4 and at the stop; each trimmed top "
                "against the region its tip tooth sweeps while the rack stands; the tooth pair's overlap on "
                "both towing swings)")


def _end_where(e: EndTop) -> str:
    """Where the rack stands while the tip land sweeps over the top, in words."""
    s = e.stand
    if s is None:
        return "no stand of the rack limits it"
    if s.why == "the rack stops for good":
        stand = f"the rack stops for good at {s.travel_mm:.3f} mm at {s.start_deg:.3f}°"
    elif s.final:
        stand = f"{s.why} at {s.start_deg:.3f}° and the rack stops there for good at {s.travel_mm:.3f} mm"
    else:
        stand = (f"{s.why} at {s.start_deg:.3f}° and the rack stands at {s.travel_mm:.3f} mm until it is picked "
                 f"up again at {s.end_deg:.3f}°")
    if e.on_circle:
        return (f"{stand}, with {e.corner} on {e.tooth}'s {e.circle} circle, so the top must lie under the "
                f"circle's tangent at {e.corner}")
    where = "outside" if e.corner_gap_mm > 0 else "inside"
    return f"{stand}, with {e.corner} {abs(e.corner_gap_mm):.3f} mm {where} {e.tooth}'s {e.circle} circle"


def _end_measured(e: EndTop) -> str:
    name = e.field.removeprefix("trim.").removesuffix("_mm")
    limit = f"up to {name} = {e.limit_mm:.3f} mm" if math.isfinite(e.limit_mm) else f"at no {name}"
    text = (f"exact model: {name} = {e.height_mm:g} mm; {e.tooth}'s tip land clears the {e.corner}–{e.far} top "
            f"{limit}: {_end_where(e)}")
    if e.overlap_mm > 0.0:
        text += (f"; {e.tooth} cuts {e.overlap_mm:.4f} mm into the {e.rack_tooth} rack tooth at +{e.overlap_deg:.3f}° "
                 f"(push model, {e.overlap_swing} swing)")
    return text


def _end_shortfall(e: EndTop) -> str:
    name = e.field.removeprefix("trim.").removesuffix("_mm")
    parts = []
    if not math.isfinite(e.limit_mm):
        parts.append(f"no {name} clears {e.tooth}'s tip land ({_end_where(e)})")
    elif e.height_mm > e.limit_mm:
        parts.append(f"{name} = {e.height_mm:.3f} mm, allowed ≤ {e.limit_mm:.3f} mm ({e.tooth}'s tip land over the "
                     f"{e.corner}–{e.far} top), {e.height_mm - e.limit_mm:.3f} mm too high")
    if e.overlap_mm > TRAVEL_TOL_MM:
        parts.append(f"{e.tooth} cuts {e.overlap_mm:.4f} mm into the {e.rack_tooth} rack tooth ({e.overlap_swing} "
                     f"swing, +{e.overlap_deg:.3f}°), allowed ≤ {TRAVEL_TOL_MM:g} mm")
    return "; ".join(parts)


def _end_figures(tops) -> dict:
    out: dict = {}
    for e in tops:
        name = e.field.removeprefix("trim.").removesuffix("_mm")
        out.update({f"{name}_mm": e.height_mm, f"{name}_limit_mm": e.limit_mm, f"{name}_overlap_mm": e.overlap_mm})
    return _finite(out)


def _clearance_shortfall(values: list[float], tol: float) -> str:
    """An interference verdict's shortfall: the deepest overlap against the contact tolerance."""
    least = min(values)
    if not math.isfinite(least):
        return "no clearance figure (a sweep direction gave none)"
    return (f"min signed clearance {least:.5f} mm, required ≥ −{tol:.3f} mm (contact tolerance), overlapping "
            f"{-least - tol:.5f} mm beyond it")


def _mesh_agrees(data: SteeringSweep) -> Verdict:
    """gearcheck against itself: the mesh's towing curve against the exact push model, and the
    contact intervals measured on the meshes against the exact ones (every pair on the way to the
    drive limit, towing and power, both directions)."""
    dev = [data.plus["max_towing_curve_deviation_mm"], data.minus["max_towing_curve_deviation_mm"]]
    hand = [data.drive(m, d).max_deviation_deg for m in ("towing", "power") for d in (+1, -1)]
    compared = [h for h in hand if math.isfinite(h)]
    worst = max(compared) if compared else math.nan
    fit = max(data.drive(m, d).fit_residual_mm for m in ("towing", "power") for d in (+1, -1))
    # contact ends within the angle of one contact tolerance of rack travel (0.014° on the template;
    # measured ≤ 0.003° there and on 16 random designs)
    limit = data.handover_tol_deg
    passed = (_ok(dev, lambda d: d <= TOWING_CURVE_TOL_MM) and bool(compared) and worst <= limit
              and _ok([fit], lambda r: r <= FLANK_FIT_TOL_MM))
    return Verdict.of(
        "mesh_agrees_with_exact",
        f"towing curve within {TOWING_CURVE_TOL_MM:g} mm of the analytic push model, contact intervals within "
        f"{limit:.4f}° (one contact tolerance of rack travel) of the exact model",
        passed,
        f"max |L_mesh − L_model| = {_num(max(dev), 4)} mm (+: {_num(dev[0], 4)}, −: {_num(dev[1], 4)}); contact "
        f"interval ends (every pair on the way to the limit) within {_num(worst, 4)}° of the exact model; mesh "
        f"flank vertices within {_num(fit * 1000.0, 5)} µm of their involutes (≤ {FLANK_FIT_TOL_MM * 1000.0:g} µm)",
        _finite({"max_deviation_mm": max(dev), "tolerance_mm": TOWING_CURVE_TOL_MM,
                 "max_handover_deviation_deg": worst, "handover_tolerance_deg": limit,
                 "max_flank_fit_residual_mm": fit, "flank_fit_tolerance_mm": FLANK_FIT_TOL_MM}),
        "mesh sweep against the exact model (polyline push model; conjugate contact intervals of every pair)",
        shortfall="; ".join(
            text for text, bad in (
                (f"towing curve off by {_num(max(dev), 4)} mm, allowed ≤ {TOWING_CURVE_TOL_MM:g} mm",
                 not _ok(dev, lambda d: d <= TOWING_CURVE_TOL_MM)),
                (f"contact interval ends off by {_num(worst, 4)}°, allowed ≤ {limit:.4f}°",
                 not (compared and worst <= limit)),
                (f"mesh flank vertices {_num(fit * 1000.0, 5)} µm off their involutes, allowed ≤ "
                 f"{FLANK_FIT_TOL_MM * 1000.0:g} µm", not _ok([fit], lambda r: r <= FLANK_FIT_TOL_MM))) if bad))


def _continuous_drive(data: SteeringSweep, target: float) -> Verdict:
    """The least continuous-drive angle of the exact model (contact intervals of every pair, towing
    and power, every hand-over) and of the mesh sweep (the same intervals measured on the swept
    meshes, each direction; the power-mode contact reaching S6; the towed rack falling one contact
    tolerance behind r·φ), with the event that limits it. Fails when either shows the drive ending
    (a hand-over gap, the last pair's end) short of the target. A mesh figure whose event lies
    beyond its sweep (the towing swing, the power stroke) is only a lower bound: it confirms the
    target when it reaches it, and otherwise leaves the question beyond the sweep to the model."""
    plus, minus, model, tol = data.plus, data.minus, data.model, data.tol
    model_c, limits, bounds = drive_figures(model, plus, minus, data.drives, tol)
    model_least, model_event = _least(model_c)
    mesh_least, mesh_event = _least(limits)
    bound_least, bound_event = _least(bounds) if bounds else (math.inf, "")
    least, event = _least([*model_c, *limits])
    passed = math.isfinite(model_least) and least >= target and all(math.isfinite(c[0]) for c in limits)
    beyond = bool(bounds) and bound_least < target  # the mesh sweeps end short of the target

    def both(mode: str) -> str:
        return " / ".join(f"{sign(d)}{'≥ ' if data.drive(mode, d).bounded else ''}"
                          f"{_num(data.drive(mode, d).angle_deg)}°" for d in (+1, -1))

    measured = (f"{_num(least)}°; exact model {_num(model_least)}° ({model_event.split(', ', 1)[-1]}); mesh sweep "
                + (f"{_num(mesh_least)}° ({mesh_event.split(', ', 1)[-1]})" if limits else "—")
                + (f", ≥ {_num(bound_least)}° ({bound_event.split(', ', 1)[-1]})" if beyond else "")
                + f" — exact model: towing {_num(model.towing_drive_deg)}° / power {_num(model.power_drive_deg)}°; "
                f"mesh sweep (contact intervals): towing {both('towing')}, power {both('power')}; power contact "
                f"reaches S6 at {_reach(plus, minus, 'geom_phi_S6_deg', 'geom_power_stroke_end_deg')}; "
                f"towed rack falls {tol:.3f} mm behind r·φ at "
                f"{_reach(plus, minus, 'geom_towing_conjugate_end_deg', 'geom_towing_swing_end_deg')}")
    decides = "exact model" if event.startswith("exact model") else "mesh sweep"
    evidence = (f"exact model and mesh sweep (conjugate contact intervals of every tooth pair, towing and power, "
                f"both directions, the sweep densified at each tight hand-over); the lesser decides: the {decides}"
                + (f"; beyond the mesh sweeps' reach ({_num(bound_least)}°) the exact model alone" if beyond else ""))
    figures = {"continuous_drive_deg": least, "target_deg": target, "model_deg": model_least,
               "mesh_deg": mesh_least if limits else math.nan,
               "mesh_reach_deg": bound_least if beyond else math.nan,
               "model_towing_deg": model.towing_drive_deg, "model_power_deg": model.power_drive_deg,
               "mesh_towing_plus_deg": data.drive("towing", 1).angle_deg,
               "mesh_towing_minus_deg": data.drive("towing", -1).angle_deg,
               "mesh_power_plus_deg": data.drive("power", 1).angle_deg,
               "mesh_power_minus_deg": data.drive("power", -1).angle_deg,
               "plus_deg": plus["geom_phi_S6_deg"], "minus_deg": minus["geom_phi_S6_deg"],
               "geom_towing_plus_deg": plus["geom_towing_conjugate_end_deg"],
               "geom_towing_minus_deg": minus["geom_towing_conjugate_end_deg"]}
    short = (f"continuous drive {_num(least)}° ({event.split(', ', 1)[-1]}), required ≥ {target:g}°"
             + (f", short by {target - least:.3f}°" if math.isfinite(least) else ""))
    return Verdict.of(
        "continuous_drive",
        f"continuous drive (towing and power mode, every hand-over) to ≥ {target:g}° (targets.continuous_drive_deg)",
        passed, measured, _finite(figures), evidence, shortfall=short)


def _reach(plus: dict, minus: dict, key: str, end_key: str) -> str:
    """A mesh figure of both directions in words: '≥ end' where the event lies beyond the sweep."""
    def one(s: dict) -> str:
        x, end = s[key], s[end_key]
        return f"{_num(x)}°" if math.isfinite(x) and x < end else f"≥ {_num(end)}° (not within the sweep)"

    return f"+{one(plus)} / −{one(minus)}"


def _least(candidates: list[tuple[float, str]]) -> tuple[float, str]:
    """The least figure and its event; NaN and 'no figure' unless every figure has a value."""
    if not candidates or not all(math.isfinite(c[0]) for c in candidates):
        missing = [c[1] for c in candidates if not math.isfinite(c[0])]
        return math.nan, f"no figure: {missing[0]}" if missing else "no figure"
    return min(candidates)


def _num(x: float, digits: int = 3) -> str:
    """A figure in a verdict's words: '—' where there is none (never 'nan')."""
    return f"{x:.{digits}f}" if math.isfinite(x) else "—"


def _finite(figures: dict) -> dict:
    """A verdict's figures without the ones that have no value (no NaN in summary.json)."""
    return {k: v for k, v in figures.items() if math.isfinite(v)}


def _contact_ratio(params, eps: float) -> Verdict:
    """ε at the machined hS4 (eqs 1-2) against the design rule trim.min_contact_ratio."""
    rule = params.trim.min_contact_ratio
    return Verdict.of(
        "contact_ratio", f"contact ratio at the machined hS4 ≥ {rule:g} (trim.min_contact_ratio)",
        math.isfinite(eps) and eps >= rule,
        f"ε = {_num(eps, 4)} at hS4 = {params.trim.hS4_mm:g} mm (rule {rule:g})",
        _finite({"contact_ratio": eps, "min_contact_ratio": rule, "hS4_mm": params.trim.hS4_mm}),
        "analytical model (eqs 1-2: approach to the machined S4 corner, recess to the tip circle)",
        shortfall=f"ε = {_num(eps, 4)}, required ≥ {rule:g}"
                  + (f", short by {rule - eps:.4f}" if math.isfinite(eps) else ""))


def _moving(data: SteeringSweep) -> list[str]:
    """Where the rack is still moving at the end of the towing swing: the model (no disengage) and
    each mesh direction (moved more than the contact tolerance over the last degree)."""
    where = ["exact model"] if data.model.moving_at_end else []
    for s, d in ((data.plus, "+"), (data.minus, "−")):
        if still_moving(s, False, data.tol):
            where.append(f"mesh sweep {d}")
    return where


def _rack_stops(data: SteeringSweep, max_deg: float) -> Verdict:
    plus, minus, tol = data.plus, data.minus, data.tol
    label = f"towing: the rack stops before ±{max_deg:g}° and stands to the end of the swing"
    moving = _moving(data)
    last = max(plus["geom_rack_motion_last_degree_mm"], minus["geom_rack_motion_last_degree_mm"])
    if moving:
        return Verdict.of(
            "rack_stops", label, False,
            f"the rack is still moving at the end of the swing ({', '.join(moving)}: the mesh rack moved "
            f"{_num(last)} mm over the last degree): the disengage was not reached within towing.max_angle_deg "
            f"= {max_deg:g}°",
            _finite({"max_angle_deg": max_deg, "motion_last_degree_mm": last, "contact_tolerance_mm": tol}),
            "mesh sweep (rack pushed by the meshed teeth, both directions) and exact model (polyline push model): "
            "either still moving decides",
            shortfall=f"the rack still moves at ±{max_deg:g}° ({', '.join(moving)}; {_num(last)} mm over the last "
                      "degree), required: stopped before the end of the swing")
    dis = [plus["geom_disengage_angle_deg"], minus["geom_disengage_angle_deg"]]
    creep = [plus["geom_rack_motion_after_disengage_mm"], minus["geom_rack_motion_after_disengage_mm"]]
    return Verdict.of(
        "rack_stops", label,
        _ok(dis, lambda d: d < max_deg) and _ok(creep, lambda c: c <= tol),
        f"stops at +{_num(dis[0])}° / −{_num(dis[1])}°, moves ≤ {_num(max(creep), 4)} mm after "
        f"(contact tolerance {tol:.3f} mm)",
        _finite({"plus_deg": dis[0], "minus_deg": dis[1], "max_angle_deg": max_deg,
                 "creep_mm": max(creep), "contact_tolerance_mm": tol}),
        "mesh sweep (rack pushed by the meshed teeth, both directions; the stop extrapolated to zero clearance "
        "from the rack held one and two contact tolerances short)",
        shortfall=f"stops at +{_num(dis[0])}° / −{_num(dis[1])}°, required before {max_deg:g}°; moves "
                  f"{_num(max(creep), 4)} mm after, allowed ≤ {tol:.3f} mm")


def _past_disengage(data: SteeringSweep, swept: str) -> Verdict:
    """Past the disengage: the mesh sweep past the stop, and each trimmed end tooth once its tip
    tooth lets go of its drive corner (exact model, :mod:`.ends`); either decides."""
    plus, minus, tol = data.plus, data.minus, data.tol
    label = f"towing: no interference past the disengage ({data.model.stop_by})"
    caught = [e for e in data.model.ends if not e.clears]
    if caught:
        past = [plus.get("min_clearance_past_disengage_mm", math.nan),
                minus.get("min_clearance_past_disengage_mm", math.nan)]
        mesh = (f"mesh sweep past the stop: min signed clearance {_num(min(past), 5)} mm"
                if _ok(past, lambda c: True) else "mesh sweep: no stop within the swing")
        return Verdict.of(
            "no_interference_past_disengage", label, False,
            "; ".join(_end_measured(e) for e in caught) + f"; {mesh}",
            {**_end_figures(data.model.ends), **_finite({"min_signed_clearance_mm": min(past),
                                                         "contact_tolerance_mm": tol})},
            f"{END_EVIDENCE}; {swept}",
            shortfall="; ".join(_end_shortfall(e) for e in caught))
    if _moving(data):
        return Verdict.graded("no_interference_past_disengage",
                              "towing: no interference past the disengage", "warn",
                              "not checked: the rack is still moving at the end of the swing (no disengage within "
                              "towing.max_angle_deg; see rack_stops)", {},
                              "mesh sweep: no pose past a disengage to check",
                              shortfall="not checked: no disengage within the towing swing (see the rack_stops claim)")
    past = [plus["min_clearance_past_disengage_mm"], minus["min_clearance_past_disengage_mm"]]
    shifts = [plus["graze_contact_shift_mm"], minus["graze_contact_shift_mm"]]
    exact_ok, exact_words, exact_figures, exact_short = _exact(data, "past_disengage")
    past_ok = _ok(past, lambda c: c >= -tol)
    return Verdict.of(
        "no_interference_past_disengage", label,
        past_ok and exact_ok,
        _and(f"min signed clearance {_num(min(past), 5)} mm ≥ −{tol:.3f} mm; contact reached "
             f"{_num(max(shifts), 5)} mm of rack shift away", exact_words),
        {**_finite({"min_signed_clearance_mm": min(past), "contact_tolerance_mm": tol,
                    "contact_shift_mm": max(shifts)}), **_end_figures(data.model.ends), **exact_figures},
        f"{EXACT_CERTIFIED}; {swept}; the closest pose past the stop confirmed on the exact B-rep",
        shortfall="; ".join(filter(None, [_clearance_shortfall(past, tol) if not past_ok else "", exact_short])))
