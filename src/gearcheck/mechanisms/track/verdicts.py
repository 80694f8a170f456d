"""The track drive's verdicts: no interference, the seated tip gap inside the paper's window, the
least tip-to-plate distance over the sweep, contact proven from both sides, the declared chain
wear within the limit at which a link first fails to seat, a warning for an even tooth count (only
then), and the mesh sweep against the exact 2-D model."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.mechanisms.track.certified import CERTIFIED, decided
from gearcheck.mechanisms.track.sweep import WINDOW_ROUNDING_MM, TrackSweep
from gearcheck.mechanisms.track.wear import MODE_TEXT
from gearcheck.results import SweepOutcome, Verdict


def rounded(x: float) -> float:
    """A measured value at report precision, for the comparison with the paper's window."""
    return round(x / WINDOW_ROUNDING_MM) * WINDOW_ROUNDING_MM


def track_verdicts(outcome: SweepOutcome) -> list[Verdict]:
    d: TrackSweep = outcome.data
    x, model, bound = d.x, d.model, d.bound
    min_sleeve, min_plate, seated_gap = x["min_sleeve"], x["min_plate"], x["seated_gap"]
    ex_min_sleeve, ex_min_plate = x["ex_min_sleeve"], x["ex_min_plate"]
    gap_proof, sleeve_proof = d.gap_proof, d.sleeve_proof
    collisions, angles = d.collisions, d.angles

    # a mesh collision at a clearance the meshes cannot resolve is not evidence: the exact model decides
    resolved = outcome.mesh_resolves
    cert = d.certified
    if cert is not None:  # every figure over the continuous motion, not only at the swept angles
        free, cert_sleeve, cert_plate = cert.interference_free(resolved)
        exact_least = min(cert.exact_sleeve.certified_min,
                          (cert.exact_plate_touch or cert.exact_plate).certified_min)
        least_plate = decided(cert.plate, cert.exact_plate, model.required_gap_min_mm - cert.slack_mm, resolved)
    else:
        free, cert_sleeve, cert_plate = True, min_sleeve.value, min_plate.value
        exact_least, least_plate = min(ex_min_sleeve.value, ex_min_plate.value), min_plate.value
    exact_penetration = rounded(exact_least) < 0.0
    no_interference = (collisions == 0 or not resolved) and not exact_penetration and free
    on_mesh = ("mesh sweep (FCL at every link pose: distances, collide within 1 µm), exact 2-D model agrees"
               if resolved else "exact model (2-D section): the meshes cannot resolve the least clearance; "
               "exact B-rep at the worst poses")
    gap_in_window = (rounded(seated_gap.value) >= model.required_gap_min_mm
                     and rounded(d.seated_gap_max) <= model.required_gap_max_mm)
    min_plate_ok = rounded(least_plate) >= model.required_gap_min_mm
    proofs_hold = gap_proof.holds(bound) and sleeve_proof.holds(bound)
    worn_dev = d.worn_mesh.max_dev if d.worn_mesh is not None else 0.0
    agrees = max(d.max_dev, worn_dev) <= bound
    clash = (f"{collisions} colliding link poses, first at θ = {np.degrees(angles[d.colliding_poses[0]]):.3f}°; "
             if collisions else f"no intersection at any of the {len(angles)}×{model.wrap.links} link poses (FCL: "
             "distance > 1 µm, else collide false); ")
    kind = ("a positive clearance beyond the bound" if min_sleeve.value > bound
            else "within the bound: a contact, not a resolved clearance")
    interference = (f"{collisions} colliding link poses" if collisions and resolved else "no mesh collision") + (
        f"; the exact 2-D model overlaps by {-exact_least:.4f} mm, required ≥ 0" if exact_penetration else "") + (
        "" if free else f"; certified over the continuous motion: tooth–sleeve ≥ {cert_sleeve:.4f} mm, tip–plate ≥ "
        f"{cert_plate:.4f} mm, required ≥ 0")
    continuous = ("" if cert is None else f"; certified over the continuous motion: tooth–sleeve ≥ {cert_sleeve:.4f}, "
                  f"tip–plate ≥ {cert_plate:.4f} mm")
    plate_continuous = ("" if cert is None else f" (sampled; certified over the continuous motion ≥ "
                        f"{least_plate:.4f} mm)")
    lo, hi = model.required_gap_min_mm, model.required_gap_max_mm
    gap_short = (f"seated tip gap {seated_gap.value:.4f} mm, required {lo:g}–{hi:g} mm, short by "
                 f"{lo - seated_gap.value:.4f} mm" if rounded(seated_gap.value) < lo else
                 f"seated tip gap up to {d.seated_gap_max:.4f} mm, required {lo:g}–{hi:g} mm, over by "
                 f"{d.seated_gap_max - hi:.4f} mm")
    proof_short = "; ".join(_proof_shortfall(name, p, bound, d.contact_tol)
                            for name, p in (("tip gap", gap_proof), ("seat", sleeve_proof)) if not p.holds(bound))
    return [
        Verdict.of("no_interference", "no interference between sprocket and links over the sweep", no_interference,
                   clash + f"min tooth–sleeve {min_sleeve.value:.4f} mm ({kind}; exact "
                   f"{ex_min_sleeve.value:.4f}), min tip–plate {min_plate.value:.4f} mm{continuous}; "
                   f"bound {bound:.3f} mm",
                   {"collisions": collisions, "min_tooth_sleeve_mm": min_sleeve.value,
                    "exact_min_tooth_sleeve_mm": ex_min_sleeve.value, "min_tip_plate_mm": min_plate.value,
                    "exact_min_tip_plate_mm": ex_min_plate.value, "bound_mm": bound,
                    **({} if cert is None else {"certified_min_tooth_sleeve_mm": cert_sleeve,
                                                "certified_min_tip_plate_mm": cert_plate})},
                   evidence=on_mesh + ("" if cert is None else "; " + CERTIFIED),
                   shortfall=interference),
        Verdict.of("seated_tip_gap_in_window", "seated-link tip gap inside the required window", gap_in_window,
                   f"{seated_gap.value:.4f}–{d.seated_gap_max:.4f} mm over {int(d.links_seated.sum())} seated link "
                   f"poses (template {model.tip_gap_mm:g}), window {model.required_gap_min_mm:g}–"
                   f"{model.required_gap_max_mm:g} mm; bound {bound:.3f} mm",
                   {"seated_tip_gap_mm": seated_gap.value, "seated_tip_gap_max_mm": d.seated_gap_max,
                    "window_min_mm": model.required_gap_min_mm, "window_max_mm": model.required_gap_max_mm},
                   evidence="mesh sweep (seated links), proven from both sides; exact 2-D model agrees",
                   shortfall=gap_short),
        Verdict.of("min_tip_plate_distance", "tip-to-plate distance over the sweep ≥ the required minimum",
                   min_plate_ok,
                   f"min {min_plate.value:.4f} mm at {d.where(min_plate)}{plate_continuous}, limit ≥ "
                   f"{model.required_gap_min_mm:g} mm; bound {bound:.3f} mm",
                   {"min_tip_plate_mm": min_plate.value, "limit_mm": model.required_gap_min_mm,
                    **({} if cert is None else {"certified_min_tip_plate_mm": least_plate})},
                   evidence="mesh sweep (every link pose); exact 2-D model agrees"
                   + ("" if cert is None else "; " + CERTIFIED),
                   shortfall=_plate_short(min_plate.value, least_plate, lo, cert is not None)),
        Verdict.of("contact_proven", "clearances proven from both sides (free at −tol, contact at +tol)", proofs_hold,
                   f"tip gap: contact at {gap_proof.contact_mm:.5f} mm vs measured {gap_proof.measured_mm:.5f}; "
                   f"seat: contact at {sleeve_proof.contact_mm:.5f} mm vs measured {sleeve_proof.measured_mm:.5f}; "
                   f"tol ±{d.contact_tol:.3f} mm",
                   {"tip_gap_contact_mm": gap_proof.contact_mm, "tip_gap_measured_mm": gap_proof.measured_mm,
                    "seat_contact_mm": sleeve_proof.contact_mm, "seat_measured_mm": sleeve_proof.measured_mm,
                    "tolerance_mm": d.contact_tol, "bound_mm": bound},
                   evidence="mesh sweep (FCL: pushed by the gap ∓ tolerance)", shortfall=proof_short),
        *_wear_verdicts(d, resolved),
        *tooth_count_verdicts(model.gap.teeth),
        Verdict.of("mesh_agrees_with_exact", "mesh sweep agrees with the exact 2-D model at every pose and link",
                   agrees, f"max |mesh − exact| = {d.max_dev:.4f} mm"
                   + ("" if d.worn_mesh is None else f" (worn chain: {worn_dev:.4f} mm)") + f", bound {bound:.3f} mm",
                   {"max_mesh_deviation_mm": d.max_dev, "bound_mm": bound,
                    **({} if d.worn_mesh is None else {"worn_max_mesh_deviation_mm": worn_dev})},
                   evidence="mesh sweep against the exact 2-D model",
                   shortfall=f"max |mesh − exact| {max(d.max_dev, worn_dev):.4f} mm, allowed ≤ {bound:.4f} mm, over by "
                             f"{max(d.max_dev, worn_dev) - bound:.4f} mm"),
    ]


def _plate_short(sampled: float, certified: float, lo: float, has_certificate: bool) -> str:
    """Why the least tip-to-plate distance falls short: a swept pose's own figure where one fails
    (a measurement), else the bound over the continuous motion (the shortfall lies between poses)."""
    if rounded(sampled) < lo or not has_certificate:
        return f"least tip–plate distance {sampled:.4f} mm, required ≥ {lo:g} mm, short by {lo - sampled:.4f} mm"
    return (f"least tip–plate distance {certified:.4f} mm between the swept angles (certified over the continuous "
            f"motion; at the angles ≥ {sampled:.4f} mm), required ≥ {lo:g} mm, short by {lo - certified:.4f} mm")


def _proof_shortfall(name: str, proof, bound: float, tol: float) -> str:
    """Why a contact proof does not hold, in words."""
    if not proof.free_at_minus:
        return f"{name}: already colliding {tol:.3f} mm short of the measured {proof.measured_mm:.5f} mm, required free"
    if not proof.touching_at_plus:
        return f"{name}: still free {tol:.3f} mm beyond the measured {proof.measured_mm:.5f} mm, required contact"
    return (f"{name}: contact at {proof.contact_mm:.5f} mm vs measured {proof.measured_mm:.5f} mm, off by "
            f"{abs(proof.contact_mm - proof.measured_mm):.5f} mm, allowed ≤ {bound:.4f} mm")


# The paper's mechanism, named where a message depends on it.
SCOPE = "the paper's articulated track: grooves every half pitch"


def tooth_count_verdicts(teeth: int) -> list[Verdict]:
    """An even z works (the wrap, the CAD and the sweep take any z) but only half the teeth ever
    engage: a warning, not a failure. None for an odd z."""
    if teeth % 2:
        return []
    half = teeth // 2
    return [Verdict.graded(
        "odd_tooth_count", "odd tooth count: every tooth takes its turn to engage", "warn",
        f"even z = {teeth} ({SCOPE}): every other tooth engaging means the same z/2 = {half} teeth take every "
        "engagement; the other half never wear — an odd z lets each tooth take its turn",
        {"teeth": teeth, "engaging_teeth": half},
        evidence="analytical model (the tooth count; pins two grooves apart)",
        shortfall=f"z = {teeth} even: {half} teeth take every engagement, the other {half} none; an odd z "
                  f"({teeth - 1} or {teeth + 1}) shares it among all teeth")]


def _wear_verdicts(d: TrackSweep, resolved: bool = True) -> list[Verdict]:
    """The declared chain wear within the limit at which a link first fails to seat."""
    w = d.wear
    if w is None:
        return []
    seat = "seats" if w.declared_seat.ok else f"does not seat ({MODE_TEXT[w.declared_seat.mode]})"
    sweep = ("worn-pitch sweep clear" if w.declared_sweep.ok else "worn-pitch sweep meets the sprocket")
    m, cert = d.worn_mesh, d.worn_certified
    mesh = ("" if m is None else
            f"; mesh sweep of the worn chain: {m.collisions} collisions, min tooth–sleeve {m.min_sleeve_mm:.4f} mm, "
            f"min tip–plate {m.min_plate_mm:.4f} mm over {m.poses}×{d.model.wrap.links} link poses")
    free, sleeve, plate = (True, math.inf, math.inf) if cert is None else cert.interference_free(resolved)
    if cert is not None:
        mesh += f"; certified over the continuous motion: tooth–sleeve ≥ {sleeve:.4f} mm, tip–plate ≥ {plate:.4f} mm"
    if not w.ok:
        short = (f"declared wear {100 * w.declared:.3f} %, limit {100 * w.limit:.4f} % (a link first fails to seat), "
                 f"over by {100 * (w.declared - w.limit):.4f} %")
    elif m is not None and m.collisions:
        short = f"the worn chain's mesh sweep collides at {m.collisions} poses, required none"
    else:
        short = (f"the worn chain meets the sprocket between the swept angles: certified tooth–sleeve ≥ {sleeve:.4f} "
                 f"mm, tip–plate ≥ {plate:.4f} mm, required ≥ 0")
    return [Verdict.of(
        "chain_wear_within_limit", "declared chain wear ≤ the elongation at which a link first fails to seat",
        w.ok and (m is None or m.collisions == 0) and free,
        f"declared {100 * w.declared:.3f} %, limit {100 * w.limit:.4f} % ({MODE_TEXT[w.mode]}; "
        f"{w.bracket_text()}); at the declared wear the sleeve {seat}, {sweep} "
        f"(exact 2-D model){mesh}",
        {"wear_elongation_pct": 100 * w.declared, "wear_limit_pct": 100 * w.limit,
         "wear_limit_mode": w.mode_code},
        evidence="exact model (2-D section: exact arcs, closed form or bisection on the elongation); mesh sweep at "
                 "the declared wear" + ("" if cert is None else f", {CERTIFIED}"),
        shortfall=short)]
