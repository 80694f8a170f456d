"""The steering report: the paper vs model vs mesh table, the towing and power-mode plots and the
notes in words, from the sweep's outcome."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering.sweep import SteeringSweep, sign, still_moving
from gearcheck.mechanisms.steering.verdicts import TOWING_CURVE_TOL_MM
from gearcheck.results import Comparison, Plot, Report, Series, SweepOutcome, Verdict


def paper_figures(params) -> dict:
    """The paper's figures for the paper's design, else all None (:func:`an.is_paper_design`)."""
    return dict(an.PAPER) if an.is_paper_design(params) else dict.fromkeys(an.PAPER)


def report(params, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
    """sweep.csv rows (made by the reduce), comparisons, plots and notes."""
    data: SteeringSweep = outcome.data
    paper = paper_figures(params)
    comparisons = _comparisons(paper, data)
    if paper["disengage_deg"] is None:  # another design: no printed figures, no rows only about them
        comparisons = [c if not any(w in c.note for w in ("paper", "ADAMS", "S1 rounded")) else
                       dataclasses.replace(c, note="")
                       for c in comparisons if not any(w in c.label for w in ("ADAMS", "test"))]
    return Report(data.rows, comparisons, [_drop_none(p) for p in _plots(paper, data)], _notes(paper, data))


def _drop_none(plot: Plot) -> Plot:
    """Markers and lines without a value (the paper's beside another design; the stop while the rack
    is still moving) are left out."""
    return dataclasses.replace(plot, markers=[m for m in plot.markers if m[1] is not None and math.isfinite(m[1])],
                               hlines=[h for h in plot.hlines if h[1] is not None and math.isfinite(h[1])])


def _value(x: float) -> float | None:
    """A table cell: None (shown empty) where there is no value."""
    return float(x) if math.isfinite(x) else None


def _comparisons(P: dict, data: SteeringSweep) -> list[Comparison]:
    """The rows at 3 decimals (0.001° and 1 µm; a deviation in mm at 4)."""
    rows = _rows(P, data)
    return [dataclasses.replace(c, model=None if c.model is None else _value(c.model),
                                geometry=None if c.geometry is None else _value(c.geometry),
                                digits=4 if "deviation" in c.label else 3) for c in rows]


def _drive_note(data: SteeringSweep, mode: str) -> str:
    """The events of one mode's continuous drive: the exact model's and the mesh's, each direction."""
    model = data.model.towing_drive_event if mode == "towing" else data.model.power_drive_event
    mesh = "; ".join(f"mesh {sign(d)}: {data.drive(mode, d).event.split(': ', 1)[-1]}" for d in (+1, -1))
    return f"exact model: {model.split(': ', 1)[-1]}; {mesh}"


def _least(*values: float) -> float:
    """The least of the values that are numbers (NaN where none is)."""
    known = [v for v in values if not math.isnan(v)]
    return min(known) if known else math.nan


def _rows(P: dict, data: SteeringSweep) -> list[Comparison]:
    plus, model, travel_at_adams = data.plus, data.model, data.travel_at_adams_mm
    max_dev = max(plus["max_towing_curve_deviation_mm"], data.minus["max_towing_curve_deviation_mm"])
    dis, stand = plus["geom_disengage_angle_deg"], plus["geom_rack_travel_at_disengage_mm"]
    if still_moving(plus, model.moving_at_end, data.tol):  # no stop: the 'disengage' is the swing's end
        dis = stand = math.nan
    cont = plus["geom_phi_S6_deg"]
    return [
        Comparison("disengage angle (rack stops), theory", "deg", P["disengage_deg"], model.disengage_deg, dis,
                   "paper adds −(hS2 − h)·tanα/r to the angle (75.33 with it)"),
        Comparison("disengage angle, ADAMS simulation", "deg", P["adams_disengage_deg"], model.disengage_deg, dis,
                   f"ADAMS's point lies on the curve (mesh L(75.89°) = {travel_at_adams:.3f}); its 'stop' is a "
                   "threshold on a flattening curve"),
        Comparison("disengage angle, test", "deg", P["test_disengage_deg"], model.disengage_deg, dis,
                   "backlash, deflection and build errors are not in the model (expect ±2–3°)"),
        Comparison("rack travel at disengage, theory (eq 22)", "mm", P["travel_disengage_mm"], model.stand_mm, stand,
                   "S1 rounded in the paper: RS1 = 84.298 gives 110.20 (dL/dRS1 = 4.2)"),
        Comparison("rack travel at disengage, ADAMS", "mm", P["adams_travel_mm"], model.stand_mm, stand,
                   f"at ADAMS's own angle the mesh curve gives {travel_at_adams:.3f}"),
        Comparison("rack travel at disengage, test", "mm", P["test_travel_mm"], model.stand_mm, stand,
                   "test rig: backlash and deflection"),
        Comparison(f"{model.stop_by} for", "deg", None, model.graze_deg, plus["geom_grazing_span_deg"],
                   "S2 lies on the RS1 circle by design (2·β(RS1))" if model.stop_by.startswith("G1")
                   else "the corner lies on the tip circle that passes over it"),
        Comparison("re-engage angle (return swing picks the rack up)", "deg", None, model.reengage_deg,
                   plus["geom_reengage_angle_deg"], "next tooth's trailing flank meets S6; the paper prints no value"),
        Comparison("continuous drive (power mode, contact reaches S6), theory", "deg", P["phi_S6_deg"],
                   model.power_limit_deg, cont, "paper used hS6 = 25.38 from its own lines (62.10° with it)"),
        Comparison("continuous drive, towing (conjugate contact intervals of every pair, + direction)", "deg",
                   None, model.towing_drive_deg, data.drive("towing", 1).angle_deg, _drive_note(data, "towing")),
        Comparison("continuous drive, power (conjugate contact intervals of every pair, + direction)", "deg", None,
                   model.power_drive_deg, data.drive("power", 1).angle_deg, _drive_note(data, "power")),
        Comparison("towed rack falls a contact tolerance behind r·φ (diagnostic)", "deg", None, None,
                   plus["geom_towing_conjugate_end_deg"],
                   "a hand-over gap leaves the rack behind only with the square of the overshoot, so this lags the "
                   "contact intervals; linear between poses"),
        Comparison("continuous drive, whole drive (least of model and mesh, both directions)", "deg", None,
                   min(model.towing_drive_deg, model.power_drive_deg), data.least_drive_deg,
                   "the continuous_drive verdict's figure"),
        Comparison("continuous drive (the lesser of the towing S1 end and the power S6), test", "deg",
                   P["test_continuous_deg"], model.continuous_deg,
                   _least(plus["geom_towing_conjugate_end_deg"], cont), "test includes backlash and deflection"),
        Comparison("raw FCL nearest point reaches S6 (diagnostic)", "deg", None, model.power_limit_deg,
                   plus["geom_raw_corner_contact_angle_deg"],
                   "vertex/flank and corner/chord contacts swap within the mesh error near the corner: ±1° ambiguity"),
        Comparison("max towing-curve deviation, mesh vs push model", "mm", None, None, max_dev,
                   f"limit {TOWING_CURVE_TOL_MM:g} mm; mesh chords lie inside the flanks"),
    ]


def _plots(P: dict, data: SteeringSweep) -> list[Plot]:
    tow, power, curves, plus, model = data.tow, data.power, data.curves, data.plus, data.model
    dis, stand = plus["geom_disengage_angle_deg"], plus["geom_rack_travel_at_disengage_mm"]
    out, back = np.degrees(tow[1]["angles_out"]), np.degrees(tow[1]["angles_back"])
    stops = [("mesh stop", dis), ("model stop", model.disengage_deg), ("paper theory", P["disengage_deg"]),
             ("ADAMS", P["adams_disengage_deg"]), ("test", P["test_disengage_deg"]),
             ("mesh re-engage", plus["geom_reengage_angle_deg"])]
    near_out = (out >= dis - 16.0) & (out <= dis + 8.0)
    near_back = (back >= dis - 16.0) & (back <= dis + 8.0)
    return [
        Plot("Towing: rack travel against pinion angle (+ swing; − swing mirrored)", "pinion angle (deg)",
             "rack travel (mm)",
             [Series("mesh, out", list(out), list(tow[1]["travel_out"])),
              Series("mesh, back", list(back), list(tow[1]["travel_back"])),
              Series("model, out", list(out), list(curves[1]["out"]), "points"),
              Series("model, back", list(back), list(curves[1]["back"]), "points"),
              Series("mesh, − swing out (mirrored)", list(-np.degrees(tow[-1]["angles_out"])),
                     list(-tow[-1]["travel_out"]))],
             markers=stops, hlines=[("mesh stand", stand), ("paper 110.20", P["travel_disengage_mm"])]),
        Plot("Towing near the stop (+ swing): rack travel against pinion angle", "pinion angle (deg)",
             "rack travel (mm)",
             [Series("mesh, out", list(out[near_out]), list(tow[1]["travel_out"][near_out])),
              Series("mesh, back", list(back[near_back]), list(tow[1]["travel_back"][near_back])),
              Series("model, out", list(out[near_out]), list(curves[1]["out"][near_out]), "points"),
              Series("model, back", list(back[near_back]), list(curves[1]["back"][near_back]), "points")],
             markers=stops + [("S1 engages (model)", model.s1_deg)],
             hlines=[("mesh stand", stand), ("paper theory 110.20", P["travel_disengage_mm"]),
                     ("ADAMS 110.05", P["adams_travel_mm"]), ("test 109.5", P["test_travel_mm"])]),
        Plot("Towing: mesh travel minus model travel, along the swing's travel", "pinion angle magnitude (deg)",
             "deviation (mm)",
             [Series(f"{sign(d)} {swing}", list(np.abs(np.degrees(tow[d][f"angles_{swing}"]))),
                     list(d * (tow[d][f"travel_{swing}"] - curves[d][swing])))
              for d in (1, -1) for swing in ("out", "back")],
             hlines=[("+tolerance", TOWING_CURVE_TOL_MM), ("−tolerance", -TOWING_CURVE_TOL_MM)]),
        Plot("Power mode: driving contact position on the first rack tooth, from S6 (tangency from the mesh)",
             "pinion angle magnitude (deg)", "contact − S6 along the flank (mm)",
             [Series(f"{sign(d)} direction", list(np.abs(np.degrees(power[d]["angles"]))), list(power[d]["offsets"]),
                     "points")
              for d in (1, -1)],
             markers=[("mesh limit", plus["geom_phi_S6_deg"]), ("model", model.power_limit_deg),
                      ("paper theory", P["phi_S6_deg"]), ("test", P["test_continuous_deg"]),
                      ("raw FCL corner contact", plus["geom_raw_corner_contact_angle_deg"])],
             hlines=[("S6", 0.0)]),
        *_te_plot(data),
    ]


def _te_plot(data: SteeringSweep) -> list[Plot]:
    """The towing swing's and the power stroke's transmission error on the exact teeth."""
    if data.tca is None:
        return []
    t = data.tca
    drive = t.summary["towing"]
    return [Plot("Transmission error: towing swing and power stroke (exact teeth)", "pinion angle (deg)",
                 "TE (mm of rack travel)",
                 [Series(c.label, np.degrees(c.phi_rad).tolist(), c.te_mm.tolist())
                  for c in (t.towing, t.back, t.power)],
                 markers=[("towing: continuous drive ends (model)", data.model.towing_drive_deg),
                          ("power: continuous drive ends (model)", data.model.power_drive_deg),
                          ("towing TE leaves zero", drive["te_departs_deg"]),
                          ("disengage (model)", data.model.disengage_deg)],
                 hlines=[("conjugate", 0.0)],
                 caption=("The rack's travel less the conjugate r·φ while the pinion tows it (negative: the rack "
                          "lags), and r·φ less the travel while the rack drives the pinion. Zero through every "
                          "hand-over of the continuous drive (the flanks are conjugate); it leaves zero where a tip "
                          "corner or a trimmed top takes the drive, and the towed rack stands still from the "
                          "disengage on."))]


def _notes(P: dict, data: SteeringSweep) -> list[str]:
    plus, minus, model, speed, info = data.plus, data.minus, data.model, data.speed, data.mesh_info
    printed = (f"; paper {P['disengage_deg']}°/{P['travel_disengage_mm']} theory, {P['adams_disengage_deg']}°/"
               f"{P['adams_travel_mm']} ADAMS, {P['test_disengage_deg']:g}°/{P['test_travel_mm']} test"
               if P["disengage_deg"] is not None else "")
    if still_moving(plus, model.moving_at_end, data.tol):
        stop = [f"Towing: the rack is still moving at the end of the swing (it moved "
                f"{plus['geom_rack_motion_last_degree_mm']:.3f} mm over the last degree): no disengage within "
                "towing.max_angle_deg."]
    else:
        stop = [
            f"Towing: the rack stops at +{plus['geom_disengage_angle_deg']:.3f}° / "
            f"−{minus['geom_disengage_angle_deg']:.3f}° at {plus['geom_rack_travel_at_disengage_mm']:.3f} mm "
            f"(model {model.disengage_deg:.3f}°, {model.stand_mm:.3f} mm{printed}).",
            f"Past the stop {model.stop_by} (closest {plus['graze_distance_mm']:.2e} mm at "
            f"{plus['graze_angle_deg']:.2f}°; the rack reaches contact {plus['graze_contact_shift_mm']:.5f} mm "
            f"further back) for {plus['geom_grazing_span_deg']:.2f}° (model {model.graze_deg:.2f}°); the standing "
            f"rack creeps ≤ {plus['geom_rack_motion_after_disengage_mm']:.4f} mm as the tip land's chord vertices "
            f"pass {model.stop_by.rsplit(' ', 1)[-1]}.",
        ]
    return [
        f"Contact tolerance {data.tol:.3f} mm (≥ the meshes' error bound {data.bound:.3f} mm): zero-backlash flanks "
        "touch at zero clearance, so a collision is measured (the rack shift that clears it) and accepted up to this "
        "depth.",
        *stop,
        f"The return swing picks the rack up at {plus['geom_reengage_angle_deg']:.3f}° "
        f"(model {model.reengage_deg:.3f}°).",
        _handover_note(data),
        f"Power mode: the contact reaches S6 at {plus['geom_phi_S6_deg']:.3f}° / "
        f"{minus['geom_phi_S6_deg']:.3f}° (model {model.power_limit_deg:.3f}°). The raw FCL nearest point "
        f"reaches the corner at {plus['geom_raw_corner_contact_angle_deg']:.2f}° / "
        f"{minus['geom_raw_corner_contact_angle_deg']:.2f}°: a polygonal flank's vertex/chord ambiguity, which the "
        "tangency estimate removes.",
        f"Speed: {speed['poses']} poses, {speed['fcl_queries']} FCL queries in {speed['elapsed_s']:.1f} s "
        f"({speed['poses_per_s']:.0f} poses/s, {speed['fcl_queries_per_s']:.0f} queries/s wall; "
        f"{speed['poses_per_cpu_s']:.0f} poses and {speed['fcl_queries_per_cpu_s']:.0f} queries per CPU-second); "
        f"pinion walls swept {info['pinion_triangles_swept']} of {info['pinion_triangles_total']} triangles.",
    ]


def _handover_note(data: SteeringSweep) -> str:
    """The hand-overs in words: the exact model's limit of each mode beside the mesh's."""
    parts = []
    for mode in ("towing", "power"):
        exact = data.model.towing_drive_deg if mode == "towing" else data.model.power_drive_deg
        mesh = " / ".join(f"{sign(d)}{data.drive(mode, d).angle_deg:.3f}°" for d in (+1, -1))
        parts.append(f"{mode} {exact:.3f}° (exact) vs {mesh} (mesh; {_drive_note(data, mode)})")
    dev = [data.drive(m, d).max_deviation_deg for m in ("towing", "power") for d in (+1, -1)]
    dev = [x for x in dev if math.isfinite(x)]
    fit = max(data.drive(m, d).fit_residual_mm for m in ("towing", "power") for d in (+1, -1))
    return ("Continuous drive through every hand-over, from each tooth pair's conjugate contact interval (on the "
            "meshes: where the tangency point of the pinion flank — the involute through its mesh vertices, "
            f"which lie within {fit * 1000.0:.2g} µm of it — with the rack flank at the swept travel leaves either "
            "flank, between poses added around every tight hand-over): " + "; ".join(parts)
            + (f". Contact ends within {max(dev):.4f}° of the exact model." if dev else ".")
            + " A hand-over gap leaves the towed rack behind r·φ only with the square of the overshoot (well under a "
              "µm through a 0.1° gap), so the rack's lag cannot show one; the contact positions do.")
