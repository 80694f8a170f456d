"""The steering's rack and pinion under tooth contact analysis (numpy only), from the exact model's
motion: the transmission error of the towing swing (the pinion drives; the rack's left flanks bear
going out, its right flanks coming back) and of the power stroke (the rack drives), and where the
towing contact lies on the rack flank.

TE in rack travel (mm): towing, the rack's travel less the conjugate r·φ (negative: the rack lags);
power mode, r·φ less the rack's travel (negative: the pinion lags). Zero while a conjugate pair
drives (at every hand-over too, with the design's contact ratio above 1); it leaves zero where the
drive runs onto a tip corner or a trimmed top (past the continuous drive), and stops changing with
the rack once the rack stands.

Mounting errors (:func:`mounting_te`). A centre-distance error Δa moves the pinion centre Δa farther
from the rack (:attr:`RackPinionGeometry.centre_error_mm`; the rack and the pinion as made are
unchanged). An involute pinion and a straight-flanked rack stay conjugate at any centre distance
(the pitch circle rolls on the line H + Δa − r): the TE over the continuous drive stays flat, only
shifted by the flank offset Δa·tan α (towing, the rack lags by it; power mode, it must run it
ahead), and the backlash opens to 2·Δa·tan α; Δa < 0 closes it below zero: the zero-backlash mesh
binds, the coast flanks overlapping by 2·|Δa|·tan α (reported as ``binds_mm``, the push model's
deepest overlap; the drive-flank figures are then those of teeth forced through). The rack's top
corners meet the line of action later (towing) or sooner (power mode) with Δa > 0: the contact ratio
falls. A tilt ψ of the rack about its travel axis makes the centre distance vary across the face
width b as Δa(w) = w·sin ψ; the exact 2D model is evaluated at both face edges and the middle
(:data:`FACE_SECTIONS`). The rack is one rigid body, so the section that pushes it farthest carries
it: towing, the rack travel is the largest of the sections' exact travels at each angle (the
return swing, the least); power mode, the pinion angle is the largest the sections' flanks drive
it to. Over the conjugate drive every section's TE is flat at −Δa(w)·tan α, so the bearing section
is the face edge with the smaller centre distance throughout (ψ > 0: w = −b/2); beyond it, each
section's own figures would part, and the largest-travel rule holds while each section's travel is
its own push (the others trail within their backlash).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import rack_pinion_clearance as rc
from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import whole_drive
from gearcheck.geometry.rack_pinion_power import power_corner, power_model_angle
from gearcheck.mechanisms.steering import push
from gearcheck.mechanisms.steering.certified import exact_travels
from gearcheck.mechanisms.steering.layout import FACE_WIDTH_MM

# The TE counts as left zero beyond this (mm of rack travel: the push model's touching tolerance).
DEPARTS_MM = push.TRAVEL_TOL_MM
# The mounting errors summary.json ``tca`` reports: centre-distance errors Δa (mm) and tilts ψ (deg).
CENTRE_ERRORS_MM = (("centre_error_0p1mm", 0.1), ("centre_error_m0p1mm", -0.1))
TILTS_DEG = (("tilt_0p1deg", 0.1),)
FACE_SECTIONS = (-0.5, 0.0, 0.5)  # w/b of the sections a tilt is evaluated at: both face edges, the middle


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
    phi = tow.forward.phi_rad
    travel = exact_travels(g, phi, tow.forward.travel_mm, +1)
    back = exact_travels(g, tow.back.phi_rad, tow.back.travel_mm, -1)
    out, driven = _towing_figures(g.pitch_radius, phi, travel, tow.disengage_rad, whole_drive(g)[0].angle_rad,
                                  tow.back.phi_rad, back)
    heights = contact_heights(g, phi[driven], travel[driven])
    found = np.isfinite(heights)
    return {**out, "contact_height_min": float(heights[found].min()) if found.any() else math.nan,
            "contact_height_max": float(heights[found].max()) if found.any() else math.nan}


def _towing_figures(r: float, phi: np.ndarray, travel: np.ndarray, disengage: float, conjugate_end: float,
                    back_phi: np.ndarray, back_travel: np.ndarray) -> tuple[dict[str, float], np.ndarray]:
    """The TE figures of a towing swing's exact travels (forward and return) and the angles driven
    (to the disengage)."""
    te = travel - r * phi
    driven = phi <= (disengage if math.isfinite(disengage) else phi[-1])
    departs = np.flatnonzero(driven & (np.abs(te - te[0]) > DEPARTS_MM))
    conjugate = te[phi <= conjugate_end]  # the exact model's continuous drive
    back = back_travel - r * back_phi
    return {"conjugate_te_pp_mm": float(np.ptp(conjugate)), "conjugate_te_mean_mm": float(np.mean(conjugate)),
            "te_departs_deg": float(np.degrees(phi[departs[0]])) if departs.size else math.nan,
            "te_at_disengage_mm": float(te[driven][-1]), "return_te_at_end_mm": float(back[-1])}, driven


def power_te(g: RackPinionGeometry, samples: int = 400, sections: tuple[RackPinionGeometry, ...] = ()
             ) -> dict[str, float]:
    """The power stroke's TE from the closed form (conjugate to S6, then S6 riding the involute),
    to 99 % of the travel at which S6 leaves the tip circle. ``sections``: the face's sections under
    a mounting error (default ``g`` alone): the pinion is driven to the largest angle any of them
    drives it to, to 99 % of the release of the section that bears at the start (beyond its own
    release a section holds the pinion where it left it). Where the TE first leaves its value at the
    start (the flanks in contact: −Δa·tan α) is given in conjugate pinion angle, travel/r."""
    sections = sections or (g,)
    r = g.pitch_radius
    lead = max(sections, key=lambda s: power_model_angle(s, 0.0))
    travels = np.linspace(0.0, 0.99 * power_corner(lead)[2], samples + 1)
    angles = np.array([[power_model_angle(s, float(t)) for t in travels] for s in sections]).max(axis=0)
    te = r * angles - travels
    departs = np.flatnonzero(np.abs(te - te[0]) > DEPARTS_MM)
    return {"te_departs_deg": float(np.degrees(travels[departs[0]] / r)) if departs.size else math.nan,
            "te_at_stroke_end_mm": float(te[-1]), "stroke_end_deg": float(np.degrees(angles[-1]))}


def mounted(g: RackPinionGeometry, centre_error_mm: float) -> RackPinionGeometry:
    """The same rack and pinion with the pinion centre ``centre_error_mm`` farther from the rack."""
    return dataclasses.replace(g, centre_error_mm=g.centre_error_mm + centre_error_mm)


def _drive_figures(g: RackPinionGeometry) -> dict[str, dict[str, float]]:
    """Per mode: where the continuous drive ends (deg) and its least hand-over overlap (deg: the
    earlier pair's contact end less the next one's start, negative across a gap)."""
    out = {}
    for d in whole_drive(g):
        overlaps = [end - start for end, start in d.handovers]
        out[d.mode] = {"continuous_drive_end_deg": d.angle_deg,
                       "handover_overlap_min_deg": math.degrees(min(overlaps)) if overlaps else math.nan}
    return out


def mounting_te(g: RackPinionGeometry, max_angle_deg: float, centre_error_mm: float = 0.0, tilt_deg: float = 0.0,
                face_width_mm: float = FACE_WIDTH_MM) -> dict:
    """The towing swing's and the power stroke's TE under a centre-distance error Δa and a tilt ψ of
    the rack about its travel axis (module doc): the sections w = :data:`FACE_SECTIONS`·b at
    Δa + w·sin ψ (one section without a tilt), each a push model (to ``max_angle_deg``) started
    with the drive flanks in contact (travel −Δa·tan α) and pushed on to the exact teeth; the rack
    carried by the section whose travel is the largest (return swing: the least). Figures as
    :func:`towing_te` and :func:`power_te`, with the continuous drive of the bearing section,
    the backlash the return swing measures at angle 0 (its TE there less the forward swing's at the
    start), ``binds_mm``, the deepest overlap the push model leaves (0: the mesh runs free), and
    ``fits``: 1 where that is within the push model's touching tolerance, else 0."""
    widths = [f * face_width_mm for f in FACE_SECTIONS] if tilt_deg else [0.0]
    errors = [centre_error_mm + w * math.sin(math.radians(tilt_deg)) for w in widths]
    geoms = [mounted(g, e) for e in errors]
    tows = [push.analyse_towing(s, max_angle_deg, travel_start=-s.flank_offset) for s in geoms]
    phi, back_phi = tows[0].forward.phi_rad, tows[0].back.phi_rad
    forward = np.array([exact_travels(s, phi, t.forward.travel_mm, +1) for s, t in zip(geoms, tows, strict=True)])
    back = np.array([exact_travels(s, back_phi, t.back.travel_mm, -1) for s, t in zip(geoms, tows, strict=True)])
    bearing = int(np.argmax(forward[:, 0]))  # every section meshes conjugate at angle 0
    drive = _drive_figures(geoms[bearing])
    # the rack stops for good where the section that leaves it farthest stops (the travels never fall)
    last = forward[:, -1] >= forward[:, -1].max() - push.TRAVEL_TOL_MM
    dis = [t.disengage_rad for t, on in zip(tows, last, strict=True) if on]
    disengage = math.nan if any(math.isnan(d) for d in dis) else min(dis)
    towing, _ = _towing_figures(g.pitch_radius, phi, forward.max(axis=0), disengage,
                                math.radians(drive["towing"]["continuous_drive_end_deg"]), back_phi, back.min(axis=0))
    te_start = float(forward.max(axis=0)[0] - g.pitch_radius * phi[0])
    binds = max(max(t.forward.max_overlap_mm, t.back.max_overlap_mm) for t in tows)
    return {"centre_error_mm": centre_error_mm, "tilt_deg": tilt_deg, "sections_w_mm": widths,
            "sections_centre_error_mm": errors, "bearing_section_w_mm": widths[bearing],
            "backlash_mm": towing["return_te_at_end_mm"] - te_start,
            "binds_mm": binds, "fits": float(binds <= push.TRAVEL_TOL_MM),
            "towing": {**towing, "disengage_deg": math.degrees(disengage), **drive["towing"]},
            "power": {**power_te(g, sections=tuple(geoms)), **drive["power"]}}


def tca_summary(g: RackPinionGeometry, tow: push.Towing) -> dict[str, dict]:
    """summary.json ``tca``: the towing swing (the push model ``tow``) and the power stroke, and both
    under the mounting errors :data:`CENTRE_ERRORS_MM` and :data:`TILTS_DEG` (:func:`mounting_te`)."""
    max_deg = round(float(np.degrees(tow.forward.phi_rad[-1])), 9)
    errors = {name: mounting_te(g, max_deg, centre_error_mm=e) for name, e in CENTRE_ERRORS_MM}
    tilts = {name: mounting_te(g, max_deg, tilt_deg=t) for name, t in TILTS_DEG}
    return {"towing": towing_te(g, tow), "power": power_te(g), **errors, **tilts}


@dataclass(frozen=True)
class TeCurve:
    """A TE curve: mm of rack travel (the sign of the module doc) against the pinion angle (rad)."""

    label: str
    phi_rad: np.ndarray
    te_mm: np.ndarray


@dataclass(frozen=True)
class SteeringTca:
    """The curves behind summary.json ``tca`` (``summary``): the towing swing out to the
    disengage, the return swing, and the power stroke (to 99 % of S6's release)."""

    towing: TeCurve
    back: TeCurve
    power: TeCurve
    summary: dict


def te_curves(g: RackPinionGeometry, tow: push.Towing, samples: int = 400) -> tuple[TeCurve, TeCurve, TeCurve]:
    """The towing swing's TE out to the disengage and back from it (the push on the exact teeth;
    beyond the disengage the rack stands and nothing drives it), and the power stroke's (the
    closed form), against the pinion angle."""
    r = g.pitch_radius
    phi = tow.forward.phi_rad
    te = exact_travels(g, phi, tow.forward.travel_mm, +1) - r * phi
    driven = phi <= (tow.disengage_rad if math.isfinite(tow.disengage_rad) else phi[-1])
    back_phi = tow.back.phi_rad
    back = exact_travels(g, back_phi, tow.back.travel_mm, -1) - r * back_phi
    travels = np.linspace(0.0, 0.99 * power_corner(g)[2], samples + 1)
    angles = np.array([power_model_angle(g, float(t)) for t in travels])
    held = back_phi <= (tow.disengage_rad if math.isfinite(tow.disengage_rad) else back_phi.max())
    return (TeCurve("towing swing, out (the pinion drives)", phi[driven], te[driven]),
            TeCurve("towing swing, back (from the disengage angle on)", back_phi[held], back[held]),
            TeCurve("power stroke (the rack drives)", angles, r * angles - travels))


def steering_tca(g: RackPinionGeometry, tow: push.Towing) -> SteeringTca:
    """The TE curves and the summary's figures of a rack and pinion (the push model ``tow``)."""
    return SteeringTca(*te_curves(g, tow), tca_summary(g, tow))
