"""The roller-chain drive's verdicts and report (from the reduced sweep, :class:`.sweep.ChainSweep`)."""

from __future__ import annotations

import math
from collections.abc import Sequence


from gearcheck.geometry import iso606_chains
from gearcheck.geometry import roller_chain as rc
from gearcheck.mechanisms.roller_chain.certified import CERTIFIED
from gearcheck.results import Comparison, Level, Plot, Report, Series, SweepOutcome, Verdict

# The sweep's speed ripple and chordal rise must equal the closed forms within these (the gauge
# planes read the span's motion exactly; what is left is the central difference, O(ε²)).
RIPPLE_TOL = 1e-6
RISE_TOL_MM = 1e-6
# A wear limit within this of the replacement rule (relative) warns: little margin for the pitch
# tolerance of a new chain and the sprocket's own wear.
WEAR_MARGIN = 0.10


CERTIFIED_SHORT = "over the continuous motion"


def _where(cert) -> str:
    """Where a roller certificate's least bound lies, in words."""
    a0, a1 = (f"{math.degrees(a):.3f}" for a in cert.between_rad)
    return f"roller {cert.link} at θ = {a0}°" if a0 == a1 else f"roller {cert.link} between θ = {a0}° and {a1}°"


def chain_verdicts(outcome: SweepOutcome) -> list[Verdict]:
    d, s = outcome.data, outcome.summary
    m, ex = d.model, s["exact"]
    resolves = outcome.mesh_resolves
    out = []
    collisions = s["collisions"]
    cert = d.certified
    rollers_c, plates_c = cert.least(resolves)
    ex_rollers_c, ex_plates_c = cert.exact_rollers.certified_min, cert.exact_plates.certified_min
    read = "meshes" if resolves else "exact model (the meshes cannot resolve the clearances)"
    out.append(Verdict.of(
        "no_interference", "no roller, plate or pin meets the sprocket at any pose",
        collisions == 0 and min(rollers_c, plates_c) >= 0 and min(ex_rollers_c, ex_plates_c) > 0,
        f"{collisions} colliding link poses of {s['poses'] * s['links']}; certified over the continuous motion: "
        f"rollers ≥ {rollers_c:.4f} mm, plates ≥ {plates_c:.4f} mm ({read}; exact ≥ {ex_rollers_c:.4f} / "
        f"{ex_plates_c:.4f} mm)",
        {"collisions": collisions, "certified_roller_min_mm": rollers_c, "certified_plate_min_mm": plates_c},
        evidence=f"mesh sweep (FCL collide at every pose and link) and the exact model, {CERTIFIED}",
        shortfall=(f"{collisions} link poses collide, required 0" if collisions else
                   f"certified least clearance {min(rollers_c, plates_c, ex_rollers_c, ex_plates_c):.4f} mm, "
                   "required > 0")))
    engaging = s["min_engaging_roller_clearance_mm"] if resolves else ex["min_engaging_roller_clearance_mm"]
    where = _where(cert.rollers if resolves else cert.exact_rollers)
    out.append(Verdict.of(
        "roller_tooth_clearance", "rollers swing into and out of their seats clear of the teeth",
        rollers_c > 0 and ex_rollers_c > 0,
        f"least roller–tooth clearance {rollers_c:.4f} mm {CERTIFIED_SHORT} ({where}; exact model "
        f"{ex_rollers_c:.4f} mm); off its seat {engaging:.4f} mm at the sweep's poses (a landing roller tends to "
        "ri − d1/2)",
        {"certified_min_roller_clearance_mm": rollers_c, "exact_certified_min_mm": ex_rollers_c,
         "min_engaging_roller_clearance_mm": engaging},
        evidence=("mesh sweep (FCL distance, every roller, every pose)" if resolves
                  else "exact model (exact arcs): the meshes cannot resolve the clearance") + f", {CERTIFIED}",
        shortfall=f"least clearance {min(rollers_c, ex_rollers_c):.4f} mm ({where}), required > 0"))
    seated = s["min_seated_roller_clearance_mm"]
    out.append(Verdict.of(
        "rollers_seat", "every seated roller sits in its seating arc, concentric, ri − d1/2 clear",
        m.seating_clearance_mm >= 0 and (not resolves or abs(seated - m.seating_clearance_mm) <= d.bound),
        f"ri − d1/2 = {m.seating_clearance_mm:.4f} mm; seated rollers measured {seated:.4f} to "
        f"{s['max_seated_roller_clearance_mm']:.4f} mm (bound {d.bound:.4f} mm)",
        {"seating_clearance_mm": m.seating_clearance_mm, "min_seated_mm": seated},
        evidence="exact model (roller on the seating centre), measured on the mesh sweep",
        shortfall=f"seated clearance {seated:.4f} mm against ri − d1/2 = {m.seating_clearance_mm:.4f} mm"))
    out.append(Verdict.of(
        "plates_clear_teeth", "link plates clear the tooth sides (and the hub)", plates_c > 0,
        f"least plate–sprocket distance {plates_c:.4f} mm {CERTIFIED_SHORT} (exact {ex_plates_c:.4f} mm: axial gap "
        f"(b1 − bf1)/2 = {m.inner_plate_gap_mm:.4f} mm" + (f", hub {m.hub_gap_mm:.4f} mm)" if m.strands > 1 else ")"),
        {"min_plate_distance_mm": plates_c},
        evidence=("mesh sweep (FCL distance, every link)" if resolves else "exact model (axial gap, hub)")
        + f", {CERTIFIED}",
        shortfall=f"least plate distance {plates_c:.4f} mm, required > 0"))
    allowed, ripple = m.max_speed_ripple_pct, 100.0 * d.ripple
    out.append(Verdict.graded(
        "speed_ripple", "the polygon effect's speed ripple within what the application allows",
        "pass" if ripple <= allowed else "warn",
        f"speed ripple {ripple:.4f} % (measured on the sweep), allowed {allowed:g} %", {"speed_ripple_pct": ripple},
        evidence="mesh sweep (gauge planes on the top span), equal to 1 − cos(180°/z)",
        shortfall=f"speed ripple {ripple:.4f} %, allowed ≤ {allowed:g} %, over by {ripple - allowed:.4f} % "
                  "(more teeth lower it)"))
    out.append(_iso_form(m))
    out.append(_wear(d))
    roller_ok = d.roller_dev <= d.bound
    plate_ok = d.plate_dev <= d.bound
    ripple_dev = abs(d.ripple - rc.speed_ripple(m.teeth))
    rise_dev = abs(d.rise - rc.chordal_rise(m.size.pitch_mm, m.teeth))
    ok = roller_ok and plate_ok and ripple_dev <= RIPPLE_TOL and rise_dev <= RISE_TOL_MM
    out.append(Verdict.of(
        "mesh_agrees_with_exact", "mesh sweep agrees with the exact model and the polygon effect's closed forms", ok,
        f"roller clearances within {d.roller_dev:.5f} mm, plate distances within {d.plate_dev:.5f} mm (bound "
        f"{d.bound:.5f} mm); speed ripple {100 * d.ripple:.6f} % vs 1 − cos(180°/z) = "
        f"{100 * rc.speed_ripple(m.teeth):.6f} %; chordal rise {d.rise:.6f} mm vs R(1 − cos(180°/z)) = "
        f"{rc.chordal_rise(m.size.pitch_mm, m.teeth):.6f} mm",
        {"roller_deviation_mm": d.roller_dev, "plate_deviation_mm": d.plate_dev, "ripple_deviation": ripple_dev,
         "rise_deviation_mm": rise_dev},
        evidence="mesh sweep against the exact model (exact arcs, axial gaps) and the closed forms",
        shortfall=f"largest deviation: rollers {d.roller_dev:.5f} mm, plates {d.plate_dev:.5f} mm, allowed "
                  f"{d.bound:.5f} mm; ripple {ripple_dev:.2e}, rise {rise_dev:.2e} mm"))
    return out


def _iso_form(m) -> Verdict:
    s, z = m.size, m.teeth
    lo, hi = iso606_chains.tip_diameter_range(s.pitch_mm, s.roller_diameter_mm, z)
    da = 2.0 * m.gap.tip_radius_mm
    bf, bf_max = m.sprocket.tooth_width_mm, iso606_chains.tooth_width_max(s.inner_width_mm, s.pitch_mm, m.strands)
    problems = []
    if not lo <= da <= hi:
        problems.append(f"tip diameter {da:.3f} mm outside ISO 606's {lo:.3f} to {hi:.3f} mm")
    if bf > bf_max:
        problems.append(f"tooth width {bf:.3f} mm above ISO 606's bf1 max {bf_max:.3f} mm")
    return Verdict.graded(
        "tooth_form_iso606", "tip diameter and tooth width within ISO 606 (the seating form is by construction)",
        "warn" if problems else "pass",
        f"da {da:.3f} mm in {lo:.3f} to {hi:.3f} mm; bf1 {bf:.3f} mm ≤ {bf_max:.3f} mm; ri, re, α at form "
        f"{m.form:g} between the minimum and maximum tooth gap",
        {"tip_diameter_mm": da, "tooth_width_mm": bf},
        evidence="exact model (ISO 606 formulas)", shortfall="; ".join(problems))


def _wear(d) -> Verdict:
    w, req = d.wear, d.replacement_pct
    limit = 100.0 * w.limit
    level: Level = "fail" if limit < req else ("warn" if limit < req * (1.0 + WEAR_MARGIN) else "pass")
    return Verdict.graded(
        "wear_limit", "a roller of a chain worn to the replacement limit still seats below the tooth tip", level,
        f"rides to the tip at {limit:.3f} % elongation (closed form {100 * w.closed_form:.3f} %); replaced at "
        f"{req:.2f} % ({d.replacement_rule})",
        {"wear_limit_pct": limit, "replacement_limit_pct": req},
        evidence="exact model (exact arcs: roller on R(1 + e) pushed to its first contact, bisection on e)",
        shortfall=f"wear limit {limit:.3f} %, required ≥ {req:.2f} %"
        + (f" with a {100 * WEAR_MARGIN:.0f} % margin" if level == "warn" else ""))


def chain_report(outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
    d, s = outcome.data, outcome.summary
    m, ex = d.model, s["exact"]
    deg = [float(math.degrees(a)) for a in d.angles]
    rows = []
    for i, a in enumerate(deg):
        seat = d.seated[i]
        rows.append({
            "drive_angle_deg": a,
            "min_roller_clearance_mm": float(d.rollers[i].min()),
            "exact_min_roller_clearance_mm": float(d.ex_rollers[i].min()),
            "min_engaging_roller_clearance_mm": float(d.rollers[i][~seat].min()) if (~seat).any() else -1.0,
            "min_plate_distance_mm": float(d.plates[i].min()),
            "seated_rollers": int(seat.sum()),
            "collisions": int(d.hits[i].sum()),
            "span_height_change_mm": float(d.height[i]),
            "span_speed_ratio": float(d.speed[i]),
            "exact_span_speed_ratio": float(d.ex_speed[i]),
        })
    z, p = m.teeth, m.size.pitch_mm
    comparisons = [
        Comparison("chain speed ripple", "%", None, 100 * rc.speed_ripple(z), 100 * d.ripple,
                   "closed form 1 − cos(180°/z) vs the top span's speed from the gauge planes", digits=5),
        Comparison("chordal rise", "mm", None, rc.chordal_rise(p, z), d.rise,
                   "closed form R(1 − cos(180°/z)) vs the top span's height from the gauge plane", digits=5),
        Comparison("seated roller clearance ri − d1/2", "mm", None, m.seating_clearance_mm,
                   s["min_seated_roller_clearance_mm"], "concentric roller; mesh within its error bound", digits=4,
                   tolerance=d.bound),
        Comparison("least plate–sprocket distance", "mm", None, ex["min_plate_distance_mm"], s["min_plate_distance_mm"],
                   "axial gap (b1 − bf1)/2 (or the hub)", digits=4, tolerance=d.bound),
        Comparison("wear limit (elongation to the tip)", "%", None, 100 * d.wear.closed_form, None,
                   "closed form; bisection on the exact contact beside it", exact=100 * d.wear.limit, digits=4),
    ]
    plots = [
        Plot("Top span speed over two tooth pitches (polygon effect)", "sprocket angle θ (deg)", "v / (ω·R)",
             [Series("exact: sin β of the entry anchor", deg, [float(v) for v in d.ex_speed]),
              Series("mesh sweep (gauge planes)", deg, [float(v) for v in d.speed], "points")],
             hlines=[("cos(180°/z)", math.cos(math.pi / z)), ("1", 1.0)],
             caption="The span's speed dips to cos(180°/z) at each handover, when a roller lands in its groove."),
        Plot("Least roller–tooth clearance", "sprocket angle θ (deg)", "clearance (mm)",
             [Series("exact model", deg, [float(v) for v in d.ex_rollers.min(axis=1)]),
              Series("mesh sweep", deg, [float(v) for v in d.rollers.min(axis=1)], "points")],
             hlines=[("ri − d1/2", m.seating_clearance_mm)],
             caption="Seated rollers sit ri − d1/2 from the seating arc; engaging rollers stay farther."),
    ]
    ripple_pct = 100 * rc.speed_ripple(z)
    notes = [
        f"{m.size.designation}-{m.strands} chain on z = {z} (pitch diameter {2 * m.gap.pitch_radius_mm:.3f} mm), "
        f"form {m.form:g} between ISO 606's minimum and maximum tooth gap: ri = {m.gap.seating_radius_mm:.4f} mm, "
        f"re = {m.gap.flank_radius_mm:.3f} mm, α = {math.degrees(m.gap.seating_angle_rad):.3f}°.",
        f"Polygon effect: the chain's speed varies by {ripple_pct:.4f} % and the span rises and falls by "
        f"{d.rise:.4f} mm each tooth pitch.",
        f"Wear: a roller rides to the tooth tip at {100 * d.wear.limit:.3f} % elongation; the chain is replaced at "
        f"{d.replacement_pct:.2f} % ({d.replacement_rule}).",
    ]
    return Report(rows, comparisons, plots, notes)


