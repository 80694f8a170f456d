"""The track drive's report content: one sweep.csv row per sprocket angle, the comparison of the
analytical model, the mesh sweep and the exact 2-D model, the two distance plots and the notes."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from gearcheck.geometry import track_chain as tc
from gearcheck.mechanisms.track.sweep import COLLIDE_SKIP_MM, TrackSweep, finite, rowmin
from gearcheck.mechanisms.track.wear import MODE_TEXT
from gearcheck.results import Comparison, Plot, Report, Series, SweepOutcome, Verdict


def rows(d: TrackSweep) -> list[dict]:
    """sweep.csv: per sprocket angle the least distances over all links, over links off their
    seats, and in the exact 2-D model."""
    row_sleeve, row_plate = d.sleeve_d.min(axis=1), d.plate_d.min(axis=1)
    off_s, off_p = rowmin(d.sleeve_d, ~d.sleeve_seated), rowmin(d.plate_d, ~d.links_seated)
    ex_row_s, ex_row_p = d.ex_sleeve.min(axis=1), d.ex_plate.min(axis=1)
    seated_counts = d.seated_counts
    return [
        {
            "angle_deg": float(np.degrees(a)),
            "min_tooth_sleeve_clearance_mm": float(row_sleeve[i]),
            "min_tip_plate_distance_mm": float(row_plate[i]),
            "seated_links": int(seated_counts[i]),
            "collide": int(d.hits[i].any()),
            "unseated_min_tooth_sleeve_mm": finite(off_s[i]),
            "unseated_min_tip_plate_mm": finite(off_p[i]),
            "exact_min_tooth_sleeve_mm": float(ex_row_s[i]),
            "exact_min_tip_plate_mm": float(ex_row_p[i]),
        }
        for i, a in enumerate(d.angles)
    ]


def comparisons(d: TrackSweep, paper: bool = True) -> list[Comparison]:
    """The table's rows at 4 decimals (0.1 µm), the mesh sweep within its error bound agreeing.
    ``paper``: the design is the paper's own (its gap window then stands in the paper column)."""
    rows = [dataclasses.replace(c, digits=4 if c.unit == "mm" else 3, tolerance=d.bound) for c in _comparisons(d)]
    return rows if paper else [_without_paper(c) for c in rows]


def _without_paper(c: Comparison) -> Comparison:
    """A row beside another design: the window is the template's requirement, not a paper figure."""
    if c.paper is None:
        return dataclasses.replace(c, note=c.note.replace("paper window", "required window"))
    sign = "≥" if c.paper_is == "min" else "≤"
    what = ("min tip-to-plate over the sweep" if c.paper_is == "min" else "largest seated tip gap")
    key = "required_gap_min_mm" if c.paper_is == "min" else "required_gap_max_mm"
    note = f"required {sign} {c.paper:g} mm (track_plate.{key})" + (f"; {c.note}" if c.note else "")
    return dataclasses.replace(c, label=what, paper=None, paper_is="value", note=note)


def _comparisons(d: TrackSweep) -> list[Comparison]:
    x, model = d.x, d.model
    return [
        Comparison("seated tip gap (tip to plate face)", "mm", None, d.model_gap, x["seated_gap"].value,
                   f"template gap {model.tip_gap_mm:g} mm; model: 2-D outline at the plate offset e; "
                   f"paper window {model.required_gap_min_mm:g}–{model.required_gap_max_mm:g} mm",
                   exact=x["ex_seated_gap"].value),
        Comparison("seating clearance ri − R (seated sleeve)", "mm", None, model.seating_clearance_mm,
                   x["seated_sleeve"].value, "sleeve concentric with its seating arc; mesh within the bound",
                   exact=x["ex_seated_sleeve"].value),
        Comparison("paper's window, lower limit vs min tip-to-plate over the sweep", "mm",
                   model.required_gap_min_mm, None, x["min_plate"].value,
                   "links swinging in/out lift away: the minimum is at seated links", exact=x["ex_min_plate"].value,
                   paper_is="min"),
        Comparison("paper's window, upper limit vs largest seated tip gap", "mm", model.required_gap_max_mm,
                   None, d.seated_gap_max, "", exact=float(np.where(d.links_seated, d.ex_plate, -np.inf).max()),
                   paper_is="max"),
        Comparison("closest sampled tip-to-plate distance of links off their seats", "mm", None, None,
                   finite(x["off_plate"].value), "swinging in/out: falls steadily to the seated gap as the pin "
                   "seats, never below it",
                   exact=finite(x["ex_off_plate"].value)),
        Comparison("closest sampled tooth–sleeve clearance of sleeves off their seats", "mm", None, None,
                   finite(x["off_sleeve"].value), "approaching / leaving: falls steadily to ri − R as the pin seats",
                   exact=finite(x["ex_off_sleeve"].value)),
        *_wear_comparisons(d),
        *_polygon_comparisons(d),
    ]


def _polygon_comparisons(d: TrackSweep) -> list[Comparison]:
    """The polygon effect on the entry run: the closed forms of a chain on every other tooth (a
    polygon of z/2 sides) beside the figures measured on the wrap's own poses over a cycle."""
    p, wrap = d.polygon, d.model.wrap
    if p is None:
        return []
    note = "entry run over one engagement cycle, measured on the wrap's poses; model: z/2-sided polygon"
    return [Comparison("chain speed ripple (polygon effect): 1 − cos(360°/z)", "%", None,
                       100.0 * tc.speed_ripple(wrap.teeth), None, note, exact=100.0 * p.ripple),
            Comparison("chordal rise of the run: R·(1 − cos(360°/z))", "mm", None,
                       tc.chordal_rise(wrap.pitch_mm, wrap.teeth), None, note, exact=p.rise_mm)]


def _wear_comparisons(d: TrackSweep) -> list[Comparison]:
    w = d.wear
    if w is None:
        return []
    return [Comparison("chain wear: declared elongation vs the limit at which a link first fails to seat", "%",
                       None, 100.0 * w.declared, None,
                       f"limit: {MODE_TEXT[w.mode]}; exact 2-D model (the mesh sweep confirms the worn wrap's "
                       "clearances at the declared wear)",
                       exact=100.0 * w.limit, compared=False)]


def _wear_notes(d: TrackSweep) -> list[str]:
    w = d.wear
    if w is None:
        return []
    seat, sweep = w.declared_seat, w.declared_sweep
    at_declared = (f"the driving-flank contact at radius {seat.contact_radius_mm:.4f} mm (tip circle "
                   f"{d.model.gap.tip_radius_mm:.4f} mm)" if seat.ok else f"the sleeve fails: {MODE_TEXT[seat.mode]}")
    return [
        f"Chain wear: every link pitch p·(1 + e), the sprocket unchanged, the pins on the larger circle "
        f"R·(1 + e). Limit {100 * w.limit:.4f} % ({w.bracket_text()}; {MODE_TEXT[w.mode]}); declared "
        f"{100 * w.declared:.3f} %: "
        f"{at_declared}; the worn chain re-wrapped at p' and swept over {sweep.poses} poses × {sweep.links} links "
        f"keeps sleeves ≥ {finite(sweep.min_sleeve_mm):.4f} mm and plates ≥ {finite(sweep.min_plate_mm):.4f} mm "
        "from the outline. The exact 2-D model decides the seat (where the driving-flank contact lies); "
        + (f"the mesh sweep confirms the worn wrap: the same link meshes posed at p' over {d.worn_mesh.poses} poses, "
           f"{d.worn_mesh.collisions} collisions, min tooth–sleeve {d.worn_mesh.min_sleeve_mm:.4f} mm, min "
           f"tip–plate {d.worn_mesh.min_plate_mm:.4f} mm, |mesh − exact| ≤ {d.worn_mesh.max_dev:.4f} mm."
           if d.worn_mesh is not None else "no worn-pitch mesh sweep at zero declared wear."),
    ]


def plots(d: TrackSweep, paper: bool = True) -> list[Plot]:
    model = d.model
    x = [float(np.degrees(a)) for a in d.angles]
    row_sleeve, row_plate = d.sleeve_d.min(axis=1), d.plate_d.min(axis=1)
    off_s, off_p = rowmin(d.sleeve_d, ~d.sleeve_seated), rowmin(d.plate_d, ~d.links_seated)
    ex_row_s, ex_row_p = d.ex_sleeve.min(axis=1), d.ex_plate.min(axis=1)
    cycle_marks = [("cycle start θ = 0", 0.0), (f"one cycle β = {d.cycle_deg:.3f}°", d.cycle_deg)]
    floor = "paper's minimum" if paper else "required minimum"
    seat = model.seating_clearance_mm
    sleeve_series = [Series("min over all sleeves (mesh)", x, [float(v) for v in row_sleeve]),
                     Series("min over sleeves off their seats (mesh)", x, [finite(v) for v in off_s]),
                     Series("min over all sleeves (exact 2-D)", x, [float(v) for v in ex_row_s], "points")]
    # the zoom: the seated clearance ri − R and the mesh's band of error around it, which the
    # no-interference verdict decides (the least mesh clearance against the bound)
    least = float(min(row_sleeve.min(), ex_row_s.min()))
    zoom = (min(least, seat - d.bound) - 1.5 * d.bound, seat + 2.5 * d.bound)
    return [
        Plot("Track: tip-to-plate distance against sprocket angle", "sprocket angle θ (°)", "distance (mm)",
             [Series("min over all links (mesh)", x, [float(v) for v in row_plate]),
              Series("min over links off their seats (mesh)", x, [finite(v) for v in off_p]),
              Series("min over all links (exact 2-D)", x, [float(v) for v in ex_row_p], "points")],
             markers=cycle_marks,
             hlines=[(f"{'paper' if paper else 'required'} minimum {model.required_gap_min_mm:g} mm",
                      model.required_gap_min_mm),
                     (f"template gap {model.tip_gap_mm:g} mm", model.tip_gap_mm)],
             caption="The least distance sits at seated links, flat at the template gap; links swinging in or "
                     f"out lift away from the tip (the peaks), so the {floor} is decided at the seat."),
        Plot("Track: tooth–sleeve clearance against sprocket angle", "sprocket angle θ (°)", "clearance (mm)",
             sleeve_series, markers=cycle_marks, hlines=[(f"ri − R = {seat:.3f} mm", seat)],
             caption="Whole range: sleeves approaching and leaving their seats (the peaks) stay well clear; the "
                     "least clearance is at the seated sleeves — see the zoom below."),
        Plot("Track: tooth–sleeve clearance near the seat (zoom)", "sprocket angle θ (°)", "clearance (mm)",
             sleeve_series, markers=cycle_marks,
             hlines=[(f"ri − R = {seat:.4f} mm (exact seated clearance)", seat),
                     (f"ri − R − mesh-error bound = {seat - d.bound:.4f} mm", seat - d.bound)],
             ylim=zoom,
             caption=f"Zoom on what the no-interference verdict decides: the least mesh clearance "
                     f"{float(row_sleeve.min()):.4f} mm against the exact {float(ex_row_s.min()):.4f} mm; the mesh "
                     f"may lie up to its error bound ({d.bound:.4f} mm) on either side of the exact value, and must "
                     "stay positive beyond the bound."),
    ]


def notes(d: TrackSweep) -> list[str]:
    x, model, angles, wrap = d.x, d.model, d.angles, d.model.wrap
    deg = np.degrees
    n_poses = len(angles)
    swept = n_poses + (d.worn_mesh.poses if d.worn_mesh is not None else 0)
    worn = ", the new chain's and the worn chain's" if d.worn_mesh is not None else ""
    seated_counts = d.seated_counts
    min_plate, min_sleeve, off_plate = x["min_plate"], x["min_sleeve"], x["off_plate"]
    gap_proof, sleeve_proof, tol = d.gap_proof, d.sleeve_proof, d.contact_tol
    return [
        f"Sweep: θ from {deg(angles[0]):.3f}° to {deg(angles[-1]):.3f}° in {n_poses} poses "
        f"({(angles[-1] - angles[0]) / wrap.cycle_rad:.2f} engagement cycles of β = {d.cycle_deg:.3f}°), "
        f"{wrap.links} links each ({seated_counts.min()}–{seated_counts.max()} seated). After one cycle every "
        "pose repeats shifted by one pin and two grooves (a symmetry of the sprocket), so the links "
        "together pass every point of the path: entry run, swinging in, seated, swinging out, exit run.",
        f"The fused link mesh is split by position in the link frame: {d.sleeve_triangles} sleeve triangles "
        f"(within R of the pin axis) and {d.plate_triangles} plate triangles.",
        f"Minimum tip-to-plate distance {min_plate.value:.4f} mm at {d.where(min_plate)}; links off their "
        f"seats stay ≥ {finite(off_plate.value):.4f} mm at the sampled poses (closest at θ = "
        f"{deg(angles[off_plate.pose_index]):.3f}°, just before a pin seats: a swinging link's distance falls "
        "steadily to the seated gap at the seating instant, so the off-seat minimum is the sample nearest "
        "that instant and the overall minimum is at seated links). "
        f"Seated gap nearest point on the plate at x = {d.gap_point_link[0]:.3f}, y = {d.gap_point_link[1]:.4f} mm "
        "in the link frame: the plate face above the tip corner.",
        f"Minimum tooth–sleeve clearance {min_sleeve.value:.4f} mm at {d.where(min_sleeve, sleeve=True)} (whole "
        f"link: {d.whole_link_at_sleeve:.4f} mm); sleeves off their seats stay ≥ "
        f"{finite(x['off_sleeve'].value):.4f} mm.",
        f"Contact from both sides: {gap_proof.label}: free at {gap_proof.measured_mm - tol:.4f} mm, "
        f"collides at {gap_proof.measured_mm + tol:.4f} mm, contact bracket "
        f"[{gap_proof.free_mm:.6f}, {gap_proof.touching_mm:.6f}] mm. {sleeve_proof.label}: contact bracket "
        f"[{sleeve_proof.free_mm:.6f}, {sleeve_proof.touching_mm:.6f}] mm (ri − R = {model.seating_clearance_mm:.4f}).",
        f"Exact 2-D model (ISO 606 outline at {d.outline_step_mm} mm, no mesh): largest |mesh − exact| "
        f"over all {n_poses * wrap.links} link poses {d.max_dev:.4f} mm (bound {d.bound:.3f} mm).",
        *_wear_notes(d),
        f"Speed: {swept} poses ({swept * wrap.links} link poses{worn}, each 2 FCL distances, and the FCL "
        f"collision test where one is within {1000 * COLLIDE_SKIP_MM:g} µm: farther, the surfaces cannot meet) "
        f"in {d.sweep_s:.2f} s = {swept / d.sweep_s:.0f} poses/s; the exact 2-D distances computed once, with the "
        f"smallest clearance before meshing; contact proofs {d.proof_s:.2f} s.",
    ]


def track_report(outcome: SweepOutcome, verdicts: Sequence[Verdict], paper: bool = True) -> Report:
    """``paper``: the design is the paper's own (:func:`gearcheck.mechanisms.track.is_paper_design`):
    only then does the paper's gap window stand as a paper figure."""
    d: TrackSweep = outcome.data
    return Report(rows(d), comparisons(d, paper), plots(d, paper), notes(d))
