"""The steering check's claims, from the sweep's figures of both directions: continuous drive to
the target (towing and power mode, through every hand-over: the least of the exact model and the
mesh), the contact ratio at the machined hS4, the rack stopping and standing in towing, no
interference past the stop, on the return swing or anywhere, and the mesh towing curve agreeing
with the exact push model."""

from __future__ import annotations

import math

from gearcheck.mechanisms.steering.sweep import SteeringSweep
from gearcheck.results import SweepOutcome, Verdict

# The mesh towing curve must agree with the exact-polyline push model within this.
TOWING_CURVE_TOL_MM = 0.05


def _ok(values, test) -> bool:
    return all(math.isfinite(v) and test(v) for v in values)


def verdicts(params, outcome: SweepOutcome) -> list[Verdict]:
    data: SteeringSweep = outcome.data
    plus, minus, model, tol = data.plus, data.minus, data.model, data.tol
    poses = data.speed["poses"]

    def each(key):
        return [s[key] for s in (plus, minus)]

    target, max_deg = params.targets.continuous_angle_deg, params.towing.max_angle_deg
    ret, re = each("min_clearance_return_swing_mm"), each("geom_reengage_angle_deg")
    clear = each("min_signed_clearance_mm")
    dev = each("max_towing_curve_deviation_mm")
    return [
        _continuous_drive(data, target),
        _contact_ratio(params, model.contact_ratio),
        _rack_stops(data, max_deg),
        _past_disengage(data),
        Verdict.of("no_interference_reengage", "towing: no interference on the return swing and re-engagement",
                   _ok(ret, lambda c: c >= -tol) and _ok(re, lambda x: True),
                   f"min signed clearance {min(ret):.5f} mm ≥ −{tol:.3f} mm; picked up at +{re[0]:.3f}° / "
                   f"−{re[1]:.3f}° (free at {plus['geom_reengage_bracket_deg'][0]:.6f}°, touching at "
                   f"{plus['geom_reengage_bracket_deg'][1]:.6f}°)",
                   {"min_signed_clearance_mm": min(ret), "contact_tolerance_mm": tol,
                    "plus_reengage_deg": re[0], "minus_reengage_deg": re[1]}),
        Verdict.of("no_interference_anywhere", "no interference at any pose (towing both ways, power mode)",
                   _ok(clear, lambda c: c >= -tol),
                   f"min signed clearance {min(clear):.5f} mm ≥ −{tol:.3f} mm over {poses} poses",
                   {"min_signed_clearance_mm": min(clear), "contact_tolerance_mm": tol}),
        Verdict.of("mesh_agrees_with_exact",
                   f"towing curve within {TOWING_CURVE_TOL_MM:g} mm of the analytic push model",
                   _ok(dev, lambda d: d <= TOWING_CURVE_TOL_MM),
                   f"max |L_mesh − L_model| = {max(dev):.4f} mm (+: {dev[0]:.4f}, −: {dev[1]:.4f})",
                   {"max_deviation_mm": max(dev), "tolerance_mm": TOWING_CURVE_TOL_MM}),
    ]


def _continuous_drive(data: SteeringSweep, target: float) -> Verdict:
    """The least continuous-drive angle of the model (exact contact intervals of every pair, towing
    and power, every hand-over) and the mesh (power: contact reaching S6; towing: the rack falling
    one contact tolerance behind r·φ), each direction, with the event that limits it."""
    plus, minus, model, tol = data.plus, data.minus, data.model, data.tol
    candidates = [(model.towing_drive_deg, f"model {model.towing_drive_event}"),
                  (model.power_drive_deg, f"model {model.power_drive_event}")]
    for s, d in ((plus, "+"), (minus, "−")):
        candidates.append((s["geom_continuous_angle_deg"], f"mesh, {d} direction: power-mode contact reaches S6"))
        candidates.append((s["geom_towing_conjugate_end_deg"],
                           f"mesh, {d} direction: towed rack falls {tol:.3f} mm behind r·φ"))
    finite = [c for c in candidates if math.isfinite(c[0])]
    least, event = min(finite) if finite else (math.nan, "no figure")
    passed = len(finite) == len(candidates) and least >= target
    measured = (f"{least:.3f}° ({event}); model towing {model.towing_drive_deg:.3f}° / power "
                f"{model.power_drive_deg:.3f}°; mesh power (S6) +{plus['geom_continuous_angle_deg']:.3f}° / "
                f"−{minus['geom_continuous_angle_deg']:.3f}°, mesh towing leaves r·φ at "
                f"+{plus['geom_towing_conjugate_end_deg']:.3f}° / −{minus['geom_towing_conjugate_end_deg']:.3f}°")
    return Verdict.of(
        "continuous_drive",
        f"continuous drive (towing and power mode, every hand-over) to ≥ {target:g}° (targets.continuous_angle_deg)",
        passed, measured,
        {"continuous_drive_deg": least, "target_deg": target,
         "model_towing_deg": model.towing_drive_deg, "model_power_deg": model.power_drive_deg,
         "plus_deg": plus["geom_continuous_angle_deg"], "minus_deg": minus["geom_continuous_angle_deg"],
         "geom_towing_plus_deg": plus["geom_towing_conjugate_end_deg"],
         "geom_towing_minus_deg": minus["geom_towing_conjugate_end_deg"]})


def _contact_ratio(params, eps: float) -> Verdict:
    """ε at the machined hS4 (eqs 1-2) against the design rule trim.min_contact_ratio."""
    rule = params.trim.min_contact_ratio
    return Verdict.of(
        "contact_ratio", f"contact ratio at the machined hS4 ≥ {rule:g} (trim.min_contact_ratio)",
        math.isfinite(eps) and eps >= rule,
        f"ε = {eps:.4f} at hS4 = {params.trim.hS4_mm:g} mm (rule {rule:g})",
        {"contact_ratio": eps, "min_contact_ratio": rule, "hS4_mm": params.trim.hS4_mm})


def _moving(data: SteeringSweep) -> list[str]:
    """Where the rack is still moving at the end of the towing swing: the model (no disengage) and
    each mesh direction (moved more than the contact tolerance over the last degree)."""
    where = ["model"] if data.model.moving_at_end else []
    for s, d in ((data.plus, "+"), (data.minus, "−")):
        if not s["geom_rack_motion_last_degree_mm"] <= data.tol:
            where.append(f"mesh {d}")
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
            f"{last:.3f} mm over the last degree): the disengage was not reached within towing.max_angle_deg "
            f"= {max_deg:g}°",
            {"max_angle_deg": max_deg, "motion_last_degree_mm": last, "contact_tolerance_mm": tol})
    dis = [plus["geom_disengage_angle_deg"], minus["geom_disengage_angle_deg"]]
    creep = [plus["geom_rack_motion_after_disengage_mm"], minus["geom_rack_motion_after_disengage_mm"]]
    return Verdict.of(
        "rack_stops", label,
        _ok(dis, lambda d: d < max_deg) and _ok(creep, lambda c: c <= tol),
        f"stops at +{dis[0]:.3f}° / −{dis[1]:.3f}°, moves ≤ {max(creep):.4f} mm after "
        f"(contact tolerance {tol:.3f} mm)",
        {"plus_deg": dis[0], "minus_deg": dis[1], "max_angle_deg": max_deg,
         "creep_mm": max(creep), "contact_tolerance_mm": tol})


def _past_disengage(data: SteeringSweep) -> Verdict:
    plus, minus, tol = data.plus, data.minus, data.tol
    label = f"towing: no interference past the disengage ({data.model.stop_by})"
    if _moving(data):
        return Verdict("no_interference_past_disengage",
                       "towing: no interference past the disengage", "warn",
                       "not checked: the rack is still moving at the end of the swing (no disengage within "
                       "towing.max_angle_deg; see rack_stops)")
    past = [plus["min_clearance_past_disengage_mm"], minus["min_clearance_past_disengage_mm"]]
    shifts = [plus["graze_contact_shift_mm"], minus["graze_contact_shift_mm"]]
    return Verdict.of(
        "no_interference_past_disengage", label,
        _ok(past, lambda c: c >= -tol),
        f"min signed clearance {min(past):.5f} mm ≥ −{tol:.3f} mm; contact reached "
        f"{max(shifts):.5f} mm of rack shift away",
        {"min_signed_clearance_mm": min(past), "contact_tolerance_mm": tol,
         "contact_shift_mm": max(shifts)})
