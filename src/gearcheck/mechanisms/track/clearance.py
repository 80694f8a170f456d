"""The track's smallest clearance to decide, from the exact 2-D model, before anything is meshed
(numpy only): the least tooth–sleeve clearance and the least tip-to-plate distance over the
sweep's poses — the template's chain and, when a wear is declared, the chain at its worn pitch.
The mesh tolerance follows from it (:mod:`gearcheck.resolution`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.track_section import ExactSection
from gearcheck.mechanisms.track import wear as track_wear
from gearcheck.mechanisms.track.assembly import TrackModel
from gearcheck.results import Clearance

# Sprocket angles per engagement cycle β (step β/60 = 0.245°: a seated pin moves 0.50 mm per step,
# far less than the 8 mm sleeve, so no body can pass through another between poses).
STEPS_PER_CYCLE = 60
# The sweep runs this fraction of a cycle before θ = 0 and after θ = β.
CYCLE_MARGIN_FRACTION = 0.125

_EXACT_CACHE: dict = {}


def exact_section(model: TrackModel) -> ExactSection:
    """One exact model per process and template (workers receive the model with every pose)."""
    key = model.section_key()
    if key not in _EXACT_CACHE:
        _EXACT_CACHE.clear()
        _EXACT_CACHE[key] = ExactSection(model.gap, model.link)
    return _EXACT_CACHE[key]


def sweep_angles(wrap: tc.ChainWrap, steps_per_cycle: int = STEPS_PER_CYCLE,
                 margin_fraction: float = CYCLE_MARGIN_FRACTION) -> np.ndarray:
    """θ from −margin to β + margin in steps of β/steps_per_cycle; 0 and β are samples."""
    before = int(math.ceil(margin_fraction * steps_per_cycle))
    k = np.arange(-before, steps_per_cycle + before + 1)
    return k * wrap.cycle_rad / steps_per_cycle


def worn_model(model: TrackModel) -> TrackModel | None:
    """The same chain re-wrapped at the declared worn pitch (pins p·(1 + e) apart), or None."""
    if not model.wear_elongation > 0.0:
        return None
    w = model.wrap
    return dataclasses.replace(model, wrap=track_wear.worn_wrap(w.teeth, w.pitch_mm, model.wear_elongation, w))


# The exact tables of the last few (model, angles) asked for in this process: the plan's smallest
# clearance and the sweep's reduce ask for the same ones (new chain and worn chain).
_TABLE_CACHE: dict = {}
_TABLE_CACHE_SIZE = 4


def exact_table(model: TrackModel, angles: np.ndarray) -> np.ndarray:
    """(angles, links, 2): the exact tooth–sleeve clearance and tip-to-plate distance (mm) of every
    link of the wrap at every sprocket angle, :meth:`ExactSection.link_distances` pose by pose.
    Computed once per process for a model and its angles: the plan's smallest clearance, the
    sweep's comparison with the meshes and its exact figures are all read from the same table."""
    angles = np.asarray(angles, dtype=float)
    key = (model.key(), angles.tobytes())
    table = _TABLE_CACHE.get(key)
    if table is None:
        exact = exact_section(model)
        table = np.empty((len(angles), model.wrap.links, 2))
        for i, a in enumerate(angles):
            sprocket = tc.sprocket_matrix(float(a))
            for j, pose in enumerate(model.wrap.link_matrices(float(a))):
                table[i, j] = exact.link_distances(sprocket, pose)
        table.setflags(write=False)
        if len(_TABLE_CACHE) >= _TABLE_CACHE_SIZE:
            _TABLE_CACHE.pop(next(iter(_TABLE_CACHE)))
        _TABLE_CACHE[key] = table
    return table


def exact_extremes(model: TrackModel, angles: np.ndarray) -> tuple[float, float]:
    """The least exact tooth–sleeve clearance and tip-to-plate distance (mm) over the angles and
    every link of the wrap (negative: the exact sections overlap)."""
    table = exact_table(model, angles)
    return float(table[..., 0].min()), float(table[..., 1].min())


def clearance_of(min_sleeve_mm: float, min_plate_mm: float, where: str = "") -> Clearance | None:
    """The smaller non-zero magnitude of the two (an overlap counts by its depth), labelled."""
    found = [(abs(v), what + (" (overlap)" if v < 0.0 else "")) for v, what in
             ((min_sleeve_mm, "least tooth–sleeve clearance"), (min_plate_mm, "least tip-to-plate distance"))
             if v != 0.0 and math.isfinite(v)]
    if not found:
        return None
    value, what = min(found)
    return Clearance(value, f"{what}{where} (exact 2-D)")


def least_clearance(model: TrackModel) -> Clearance | None:
    """Before meshing: the smallest clearance the sweep decides, over the template's chain and the
    worn one (the sweep's default angles)."""
    angles = sweep_angles(model.wrap)
    found = [c for c in (clearance_of(*exact_extremes(model, angles)),) if c is not None]
    worn = worn_model(model)
    if worn is not None:
        c = clearance_of(*exact_extremes(worn, angles), where=f", chain worn {100 * model.wear_elongation:g} %")
        if c is not None:
            found.append(c)
    return min(found, key=lambda c: c.value_mm) if found else None
