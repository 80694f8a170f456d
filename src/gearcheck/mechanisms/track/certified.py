"""The track's clearances certified over the continuous motion, not only at the swept angles.

Between two sprocket angles θ0 < θ1 the sweep measures nothing; :mod:`gearcheck.sweep.certify`
bounds each link's clearance there from its ends' clearances and the longest path any point of the
link takes *relative to the sprocket* over the interval. The wrap (:class:`ChainWrap`) makes that
path simple. In the sprocket's frame:

* a seated pin does not move (it sits in its groove);
* the entry run is a straight line of pins through the last seated pin with a fixed direction in
  the world, so in the sprocket's frame the whole run turns rigidly about that pin by −(θ1 − θ0);
  the exit run the same about the first seated pin; the link swinging in or out turns with its run
  about that pin.

So a link seated at both ends of the interval (then throughout: its grooves' polar angles move
monotonically through the seated span) does not move at all, and any other link's points move at
most |θ1 − θ0|·ρ, ρ the farthest any of its points lies from the pivot: the pivot-to-own-pin
distance (a whole number of pitches along the run) plus the farthest point of the link from its own
pin axis in the plane. A seating within the interval changes the pivot; each piece of the motion
is a turn about its own pivot, so the largest ρ over the pivots of both ends (and those between)
bounds the whole path.

Each link's two figures (tooth–sleeve clearance, tip-to-plate distance) are certified over the
swept range on the meshes (distance queries in the reducing process where an interval does not
decide) and on the exact 2-D model (which also decides the intervals too short for the meshes to
resolve). The refinement stops at each model's own error: the meshes' error bound, the exact
outline's sagitta.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.wrap_path import wrap_path_mm
from gearcheck.sweep.certify import FigureCertificate, certify_figure

# The figures, their index in the sweep's (and the exact table's) last axis.
SLEEVE_FIGURE, PLATE_FIGURE = 0, 1
# How a verdict read from the certificates names its evidence.
CERTIFIED = ("certified over the continuous motion (each interval between swept angles bounded by its ends' "
             "clearances and the longest path of a link point relative to the sprocket, refined by distance "
             "queries; the exact 2-D model decides the intervals too short for the meshes)")


def _events(wrap: tc.ChainWrap, a0: float, a1: float) -> list[float]:
    """The drive angles inside (a0, a1) where a pin seats or leaves its groove (its groove's polar
    angle crosses ψ_in − β/2 or ψ_out + β/2)."""
    beta, two_pi = wrap.cycle_rad, 2.0 * math.pi
    lo = wrap.entry_angle_rad - beta / 2.0
    edges = (lo, wrap.exit_angle_rad + beta / 2.0)
    out = []
    for k in wrap.pin_grooves():
        offset = two_pi * float(k) / wrap.teeth
        for edge in edges:  # θ = edge − offset + 2πn
            base = edge - offset
            n = math.ceil((a0 - base) / two_pi)
            while base + n * two_pi < a1:
                if base + n * two_pi > a0:
                    out.append(base + n * two_pi)
                n += 1
    return sorted(out)


def link_path_mm(wrap: tc.ChainWrap, link: int, a0: float, a1: float, reach_mm: float,
                 round_mm: float | None = None) -> float:
    """The longest path (mm) any point of link ``link`` takes relative to the sprocket while the
    drive turns from ``a0`` to ``a1`` (rad); ``reach_mm``: the farthest point of the link (or of the
    part of it certified) from its own pin axis, in the plane. The interval is cut where a pin seats
    or leaves (:func:`_events`); on each piece the link stands still (seated) or turns with its run
    about the run's seated pin.

    ``round_mm``: the part is round about its own pin axis (the sleeve) to within this (mm; 0 for
    the exact circle, the tessellation's error for a mesh): where it turns about that very axis (the
    link swinging in about its seated pin) its points move but the part does not — it stays within
    ``round_mm`` of itself, which counts as a path of 2·round_mm (c ≥ c_end − round_mm, a weaker
    use of the same bound)."""
    lo, hi = sorted((a0, a1))
    return wrap_path_mm(wrap.seated_pins, [lo, *_events(wrap, lo, hi), hi], link, wrap.pitch_mm, reach_mm,
                        round_mm)


def reach_xy(vertices: np.ndarray) -> float:
    """The farthest vertex from the link's own pin axis (the link frame's z axis), in the plane."""
    return float(np.hypot(vertices[:, 0], vertices[:, 1]).max())


@dataclass(frozen=True)
class TrackCertificates:
    """Both figures certified on the meshes and on the exact 2-D model, each against its own
    requirement (the sleeve: no interference; the plate: the least tip gap) and, where a swept
    plate distance falls short of the least tip gap, the plate again against no interference
    (``*_touch``: the first certificate leaves the intervals of a failing end unrefined)."""

    sleeve: FigureCertificate
    plate: FigureCertificate
    exact_sleeve: FigureCertificate
    exact_plate: FigureCertificate
    seconds: float
    plate_touch: FigureCertificate | None = None
    exact_plate_touch: FigureCertificate | None = None
    slack_mm: float = 0.0  # a requirement holds to within this (half the report precision)

    def summary(self) -> dict:
        out = {**self.sleeve.as_dict("sleeve_"), **self.plate.as_dict("plate_"),
               **self.exact_sleeve.as_dict("exact_sleeve_"), **self.exact_plate.as_dict("exact_plate_")}
        for name, f in (("plate_touch_", self.plate_touch), ("exact_plate_touch_", self.exact_plate_touch)):
            if f is not None:
                out.update(f.as_dict(name))
        return out  # its time is a timing (sweep timings' certify_s), never in summary.json

    def interference_free(self, resolved: bool) -> tuple[bool, float, float]:
        """(no interference over the continuous motion, the least certified sleeve clearance and
        plate distance the decision read): each figure's certified bound on the meshes, and where
        the meshes leave intervals too short to decide (or cannot resolve the clearance at all) the
        exact model's; the exact model's bound must hold too."""
        plate = self.plate_touch or self.plate
        exact_plate = self.exact_plate_touch or self.exact_plate
        floor = -self.slack_mm
        sleeve_v = decided(self.sleeve, self.exact_sleeve, floor, resolved)
        plate_v = decided(plate, exact_plate, floor, resolved)
        ok = min(sleeve_v, plate_v, self.exact_sleeve.certified_min, exact_plate.certified_min) >= floor
        return ok, sleeve_v, plate_v


def decided(mesh: FigureCertificate, exact: FigureCertificate, requirement: float, resolved: bool = True) -> float:
    """The least value over the continuous motion a verdict on ``requirement`` reads: the meshes'
    certified bound where it decides; where it does not but no swept pose fails (its failing
    intervals are those too short for the meshes to resolve) or the meshes cannot resolve the
    clearance at all, the exact model's certified bound."""
    if mesh.certified_min >= requirement:
        return mesh.certified_min
    if not resolved or mesh.sampled_min >= requirement:
        return exact.certified_min
    return mesh.certified_min


def certify_track(wrap: tc.ChainWrap, angles: np.ndarray, mesh: tuple[np.ndarray, np.ndarray],
                  exact: tuple[np.ndarray, np.ndarray], least_gap_mm: float,
                  mesh_measure: Callable[[int, int, float], float], exact_measure: Callable[[int, int, float], float],
                  reach_mm: tuple[float, float], resolution_mm: tuple[float, float], floor_mm: float,
                  link_error_mm: float, slack_mm: float = 0.0) -> TrackCertificates:
    """The tooth–sleeve clearance (against 0) and the tip-to-plate distance (against
    ``least_gap_mm``) of every link certified over the swept range: on the meshes (``mesh`` =
    (sleeve, plate) values per angle and link, refined by ``mesh_measure(figure, link, angle)``, to
    ``resolution_mm[0]``) and on the exact model (to ``resolution_mm[1]``); ``reach_mm``: each
    figure's part of the link, its farthest point from the pin axis; ``link_error_mm``: the link
    mesh's own error bound (how far its sleeve is from round); ``slack_mm``: a requirement holds
    to within this (the verdicts compare at report precision: half of it)."""
    t0 = time.perf_counter()
    out: dict[str, FigureCertificate] = {}
    for label, values, measure, resolution in (("", mesh, mesh_measure, resolution_mm[0]),
                                               ("exact_", exact, exact_measure, resolution_mm[1])):
        def run(figure: int, requirement: float, measure=measure, values=values, resolution=resolution,
                label=label) -> FigureCertificate:
            # the sleeve is round about its pin: the model's own error (the exact circle: none)
            round_mm = (link_error_mm if label == "" else 0.0) if figure == SLEEVE_FIGURE else None
            return certify_figure(angles, values[figure], requirement, lambda link, a: measure(figure, link, a),
                                  lambda link, a0, a1: link_path_mm(wrap, link, a0, a1, reach_mm[figure], round_mm),
                                  resolution, floor_mm)

        out[f"{label}sleeve"] = run(SLEEVE_FIGURE, -slack_mm)
        out[f"{label}plate"] = run(PLATE_FIGURE, least_gap_mm - slack_mm)
        if out[f"{label}plate"].sampled_min < least_gap_mm - slack_mm and least_gap_mm > 0.0:
            out[f"{label}plate_touch"] = run(PLATE_FIGURE, -slack_mm)
    return TrackCertificates(seconds=time.perf_counter() - t0, slack_mm=slack_mm, **out)
