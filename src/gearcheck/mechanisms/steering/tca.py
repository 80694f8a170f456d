"""The steering's rack and pinion under tooth contact analysis (numpy only), from the exact model's
motion: the transmission error of the towing swing (the pinion drives; the rack's left flanks bear
going out, its right flanks coming back) and of the power stroke (the rack drives), and where the
towing contact lies on the rack flank.

TE in rack travel (mm): towing, the rack's travel less the conjugate r·φ (negative: the rack lags);
power mode, r·φ less the rack's travel (negative: the pinion lags). Zero while a conjugate pair
drives (at every hand-over too, with the design's contact ratio above 1); it leaves zero where the
drive runs onto a tip corner or a trimmed top (past the continuous drive), and stops changing with
the rack once the rack stands.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import rack_pinion_clearance as rc
from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import whole_drive
from gearcheck.geometry.rack_pinion_power import power_corner, power_model_angle
from gearcheck.mechanisms.steering import push
from gearcheck.mechanisms.steering.certified import exact_travels

# The TE counts as left zero beyond this (mm of rack travel: the push model's touching tolerance).
DEPARTS_MM = push.TRAVEL_TOL_MM


def contact_heights(g: RackPinionGeometry, phis: np.ndarray, travels: np.ndarray, side: int = +1) -> np.ndarray:
    """Where the pushing contact lies on its rack flank at each pose (0 root … 1 the flank's top
    corner; NaN where no flank is pushed): the support point of the pushing tooth in the flank's
    direction, of the pair touching (within the push model's tolerance) the farthest."""
    tp = rc.ToothPairs(g, push.tooth_pairs(g))
    edge = 3 if side > 0 else 1
    flank = tp.edges[:, edge]
    top = np.array([g.rack_corner_heights(k)[0 if side > 0 else 1] for _, k in tp.pairs])
    sep = tp.separation(phis, travels, flank[:, None])[..., 0]
    delta = flank - tp.theta(phis)
    height = tp.support_point(phis, delta)[..., 1]
    on = (np.abs(sep) <= DEPARTS_MM) & (height >= g.rack_root_height - 1e-9) & (height <= top + 1e-9)
    frac = (height - g.rack_root_height) / (top - g.rack_root_height)
    return np.where(on.any(axis=-1), np.nanmax(np.where(on, frac, np.nan), axis=-1, initial=-np.inf), np.nan)


def towing_te(g: RackPinionGeometry, tow: push.Towing) -> dict[str, float]:
    """The towing swing's TE figures: the push model's travel pushed on to the exact teeth
    (:func:`.certified.exact_travels`), from angle 0 to the disengage (beyond it the rack stands and
    nothing drives it): its peak to peak and mean over the exact model's continuous drive, where it
    first leaves its start by :data:`DEPARTS_MM`, its value at the disengage; the contact's heights
    on the rack flank; the return swing's TE where it ends, back at angle 0."""
    r = g.pitch_radius
    phi = tow.forward.phi_rad
    travel = exact_travels(g, phi, tow.forward.travel_mm, +1)
    te = travel - r * phi
    driven = phi <= (tow.disengage_rad if math.isfinite(tow.disengage_rad) else phi[-1])
    departs = np.flatnonzero(driven & (np.abs(te - te[0]) > DEPARTS_MM))
    conjugate = te[phi <= whole_drive(g)[0].angle_rad]  # the exact model's continuous drive
    heights = contact_heights(g, phi[driven], travel[driven])
    back = exact_travels(g, tow.back.phi_rad, tow.back.travel_mm, -1) - r * tow.back.phi_rad
    found = np.isfinite(heights)
    return {"conjugate_te_pp_mm": float(np.ptp(conjugate)), "conjugate_te_mean_mm": float(np.mean(conjugate)),
            "te_departs_deg": float(np.degrees(phi[departs[0]])) if departs.size else math.nan,
            "te_at_disengage_mm": float(te[driven][-1]), "return_te_at_end_mm": float(back[-1]),
            "contact_height_min": float(heights[found].min()) if found.any() else math.nan,
            "contact_height_max": float(heights[found].max()) if found.any() else math.nan}


def power_te(g: RackPinionGeometry, samples: int = 400) -> dict[str, float]:
    """The power stroke's TE from the closed form (conjugate to S6, then S6 riding the involute),
    to 99 % of the travel at which S6 leaves the tip circle."""
    r = g.pitch_radius
    travels = np.linspace(0.0, 0.99 * power_corner(g)[2], samples + 1)
    te = np.array([r * power_model_angle(g, float(t)) - t for t in travels])
    departs = np.flatnonzero(np.abs(te) > DEPARTS_MM)
    return {"te_departs_deg": float(np.degrees(travels[departs[0]] / r)) if departs.size else math.nan,
            "te_at_stroke_end_mm": float(te[-1]),
            "stroke_end_deg": float(np.degrees(power_model_angle(g, float(travels[-1]))))}


def tca_summary(g: RackPinionGeometry, tow: push.Towing) -> dict[str, dict[str, float]]:
    """summary.json ``tca``: the towing swing (the push model ``tow``) and the power stroke."""
    return {"towing": towing_te(g, tow), "power": power_te(g)}
