"""The roller chain's clearances certified over the continuous motion, not only at the swept angles.

As on the track (:mod:`gearcheck.geometry.wrap_path`): in the sprocket's frame a seated roller stands
in its seat and each span turns rigidly about its anchor (the first or last seated roller) by the
sprocket's turn, the other way; the anchors change where a roller seats or leaves
(:func:`anchor_events`). So over an interval a roller's points move at most the turn times (its
pitches to the anchor · p + its radius), a link's plates the turn times (pitches to the anchor ·
p + the plates' farthest point from the link's first roller), and not at all while seated.

Each roller's clearance to the teeth and each link's plates' distance to the sprocket are certified
on the meshes (distance queries in the reducing process where an interval does not decide, down
to the meshes' error bound) and each roller's on the exact model (the tooth outline's exact arcs),
sharpened to 1e-4 mm of the figure. The exact plate distance needs no refinement: the plates glide
in slabs beside the tooth row, so its least over the motion is the least axial (or hub) gap
(:func:`exact_plates`). Each mesh bound is at least the exact one less the meshes' error bound (the
meshes lie within it of the exact surfaces at every pose).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from gearcheck.geometry import roller_chain as rc
from gearcheck.geometry.wrap_path import wrap_path_mm
from gearcheck.sweep.certify import FigureCertificate, certify_figure

# Rollers sharpened at most, per figure: each roller landing in the sweep holds a loose bound (it
# swings about the anchor until it seats) until its own landing is split fine.
SHARPEN_ROLLERS = 12
# The exact model's resolution (mm): its arcs are exact; a piece this short is left undecided.
EXACT_RESOLUTION_MM = 1e-6
CERTIFIED = ("certified over the continuous motion (each interval between swept angles bounded by its ends' "
             "clearances and the longest path of a roller or plate point relative to the sprocket, refined by "
             "distance queries; the exact model the same way)")


def anchor_events(wrap: rc.RollerWrap, a0: float, a1: float) -> list[float]:
    """The drive angles inside (a0, a1) where an anchor changes (a roller seats or leaves):
    u(θ) − 0.75z − 0.5 or u(θ) − 0.25z + 0.5 crosses a whole number (:meth:`RollerWrap.anchors`)."""
    z, out = wrap.teeth, []
    for c in (0.75 * z + 0.5 + rc.ANCHOR_EPS, 0.25 * z - 0.5 - rc.ANCHOR_EPS):
        n = math.floor(wrap.u(a0) - c)
        while True:
            theta = (n + c - wrap.u0) * 2.0 * math.pi / z
            if theta >= a1:
                break
            if theta > a0:
                out.append(theta)
            n += 1
    return sorted(out)


def path_mm(wrap: rc.RollerWrap, index: int, a0: float, a1: float, reach_mm: float, link: bool,
            round_mm: float | None = None) -> float:
    """The longest path (mm) of a point of roller ``index`` (``link`` False; ``reach_mm`` its
    radius) or of link ``index``'s plates (``reach_mm``: their farthest point from the link's first
    roller axis) relative to the sprocket over [a0, a1] (rad). A roller turns with its inner link:
    seated while the link's other roller swings, it turns about its own axis, where ``round_mm``
    (how far it is from round: the mesh's error, 0 for the exact circle) stands for its path."""
    lo, hi = sorted((a0, a1))
    partner = None if link else (index + 1 if index % 2 == 0 else index - 1)
    return wrap_path_mm(wrap.seated, [lo, *anchor_events(wrap, lo, hi), hi], index, wrap.pitch_mm, reach_mm,
                        round_mm, link=link, partner=partner)


@dataclass(frozen=True)
class ChainCertificates:
    """The roller–tooth clearance and the plate–sprocket distance certified on the meshes and on the
    exact model."""

    rollers: FigureCertificate
    plates: FigureCertificate
    exact_rollers: FigureCertificate
    exact_plates: FigureCertificate
    seconds: float

    def summary(self) -> dict:
        return {**self.rollers.as_dict("roller_"), **self.plates.as_dict("plate_"),
                **self.exact_rollers.as_dict("exact_roller_"), **self.exact_plates.as_dict("exact_plate_")}

    def least(self, resolved: bool) -> tuple[float, float]:
        """(roller clearance, plate distance) over the continuous motion, as the verdicts read them:
        the meshes' certified bounds where the meshes resolve the clearances, else the exact model's."""
        if resolved:
            return self.rollers.certified_min, self.plates.certified_min
        return self.exact_rollers.certified_min, self.exact_plates.certified_min


def certify_chain(wrap: rc.RollerWrap, angles: np.ndarray, mesh: tuple[np.ndarray, np.ndarray],
                  exact: tuple[np.ndarray, np.ndarray], mesh_measure: Callable[[int, int, float], float],
                  exact_measure: Callable[[int, int, float], float], reach_mm: tuple[float, float],
                  resolution_mm: float, plate_floor_mm: float, plate_gaps_mm: np.ndarray) -> ChainCertificates:
    """Both figures (0: rollers, values (poses, rollers); 1: plates, (poses, links)) certified against
    no interference, on the meshes (``mesh``, refined by ``mesh_measure(figure, index, angle)``, to
    ``resolution_mm``) and on the exact model (``exact``, ``exact_measure``); ``reach_mm``: the
    roller's radius, the plates' reach; ``plate_floor_mm``: a lower bound of a plate distance the
    values do not give; ``plate_gaps_mm``: each link's gap to the teeth beside it (:func:`exact_plates`)."""
    t0 = time.perf_counter()
    out = {}
    for label, values, measure, resolution in (("", mesh, mesh_measure, resolution_mm),
                                               ("exact_", exact, exact_measure, EXACT_RESOLUTION_MM)):
        for figure, name, item in ((0, "rollers", "roller"), (1, "plates", "link")):
            if (label, figure) == ("exact_", 1):
                continue  # the exact plates: from the slabs (:func:`exact_plates`)
            out[label + name] = certify_figure(
                angles, values[figure], 0.0, functools.partial(_figure, measure, figure),
                functools.partial(_path, wrap, reach_mm[figure], figure == 1, None if figure == 1 else
                                  (resolution_mm if label == "" else 0.0)), resolution,
                plate_floor_mm if figure == 1 else 0.0, item=item,
                sharpen_items=0 if figure == 1 else SHARPEN_ROLLERS)  # the plates: sharp from the exact slabs
    out["exact_plates"] = exact_plates(angles, exact[1], plate_gaps_mm)
    # the meshes lie within their error bound of the exact surfaces at every pose: the exact bound
    # less it holds for the meshes too (the path bound is loose for plates gliding past the tooth
    # sides, and for a seated roller turning about its own axis, round only to the mesh's error)
    for name in ("rollers", "plates"):
        exact_cert = out[f"exact_{name}"]
        floor = exact_cert.certified_min - resolution_mm
        if floor > out[name].certified_min:
            out[name] = replace(out[name], certified_min=floor, between_rad=exact_cert.between_rad,
                                link=exact_cert.link)
    return ChainCertificates(seconds=time.perf_counter() - t0, **out)


def _figure(measure: Callable[[int, int, float], float], figure: int, i: int, a: float) -> float:
    return measure(figure, i, a)


def _path(wrap: rc.RollerWrap, reach: float, link: bool, round_mm: float | None, i: int, a0: float,
          a1: float) -> float:
    return path_mm(wrap, i, a0, a1, reach, link, round_mm)


def exact_plates(angles: np.ndarray, sampled: np.ndarray, gaps_mm: np.ndarray) -> FigureCertificate:
    """The exact plate distance over the continuous motion, from the geometry alone: each link's
    plates lie in slabs beside the tooth row, ``gaps_mm[j]`` (the axial gap, or with several
    strands the hub gap under a seated chord, if smaller) from it, so no motion in the plane brings
    them nearer than that, and a seated link (at every angle some are) faces the teeth across it:
    the least over the motion is the least gap, exactly. ``sampled``: the exact distances at the
    swept angles (NaN where a plate does not face the teeth)."""
    j = int(np.argmin(gaps_mm))
    finite = sampled[np.isfinite(sampled)]
    return FigureCertificate(certified_min=float(gaps_mm[j]),
                             sampled_min=float(finite.min()) if finite.size else math.inf, link=j,
                             between_rad=(float(angles[0]), float(angles[-1])), item="link")
