"""The steering check's claims, from the sweep's figures of both directions: continuous power
drive to the target, the rack stopping and standing in towing, no interference past the stop, on
the return swing or anywhere, and the mesh towing curve agreeing with the exact push model."""

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
    cont, dis = each("geom_continuous_angle_deg"), each("geom_disengage_angle_deg")
    creep = each("geom_rack_motion_after_disengage_mm")
    past, ret, re = (each("min_clearance_past_disengage_mm"), each("min_clearance_return_swing_mm"),
                     each("geom_reengage_angle_deg"))
    clear, shifts = each("min_signed_clearance_mm"), each("graze_contact_shift_mm")
    dev = each("max_towing_curve_deviation_mm")
    return [
        Verdict.of("continuous_drive",
                   f"power mode drives continuously to ≥ {target:g}° (targets.continuous_angle_deg)",
                   _ok(cont, lambda c: c >= target),
                   f"contact reaches S6 at +{cont[0]:.3f}° / −{cont[1]:.3f}° (model {model.power_limit_deg:.3f}°)",
                   {"plus_deg": cont[0], "minus_deg": cont[1], "target_deg": target}),
        Verdict.of("rack_stops", f"towing: the rack stops before ±{max_deg:g}° and stands to the end of the swing",
                   _ok(dis, lambda d: d < max_deg) and _ok(creep, lambda c: c <= tol),
                   f"stops at +{dis[0]:.3f}° / −{dis[1]:.3f}°, moves ≤ {max(creep):.4f} mm after "
                   f"(contact tolerance {tol:.3f} mm)",
                   {"plus_deg": dis[0], "minus_deg": dis[1], "max_angle_deg": max_deg,
                    "creep_mm": max(creep), "contact_tolerance_mm": tol}),
        Verdict.of("no_interference_past_disengage",
                   "towing: no interference past the disengage (G1's tip land grazes S2)",
                   _ok(past, lambda c: c >= -tol),
                   f"min signed clearance {min(past):.5f} mm ≥ −{tol:.3f} mm; contact reached "
                   f"{max(shifts):.5f} mm of rack shift away",
                   {"min_signed_clearance_mm": min(past), "contact_tolerance_mm": tol,
                    "contact_shift_mm": max(shifts)}),
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
