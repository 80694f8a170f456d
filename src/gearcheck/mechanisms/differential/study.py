"""The differential's figures for a study (numpy only, no mesh): the least play per side at the
template's shim, warm, at the cold design point, over the operating range and over the storage
range — from the paper's first-order model (analytical level, vectorised over any number of
variants) and from the exact spherical-involute flanks (exact level). The tooth contact analysis
over the running states (TE peak to peak, the pattern's length and edges) is the "contact" level,
run only for a study that names one of its figures
(:func:`gearcheck.mechanisms.differential.tca.study_figures`).

The same keys at both levels, so the study report sets the paper's model beside the exact one.
Over a temperature range the least play sits at one of its ends: linear in the paper's model,
concave in temperature on the exact flanks (heel-limited warm, toe-limited cold; the whole-range
grid of the check confirms it), so the ends decide both.

The paper's model of a calibrated design reproduces the measurement: its warm play per side at
the measured shim and temperature is half the least measured total (that is how the paper's
thinning is set), moved to the template's shim by eq (11) and to other temperatures by the
model's linear drop; uncalibrated, the template's least thinning (eq 10) plus the shim gain.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from gearcheck.mechanisms.differential import analysis
from gearcheck.mechanisms.differential import temperature as tp

KEYS = ("warm_play_arcmin", "cold_play_arcmin", "least_play_operating_arcmin", "least_play_storage_arcmin")


def _col(columns: Mapping[str, np.ndarray], key: str, default: float, n: int) -> np.ndarray:
    return np.asarray(columns[key], float) if key in columns else np.full(n, float(default))


def paper_model(params, columns: Mapping[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """The paper's model (eqs 1–11) per side for every variant: ``columns`` the sampled fields
    (``section.key`` → values), the template's value elsewhere. Vectorised: no per-variant
    Python loop (a million variants in well under the bench's 10 s)."""
    columns = dict(columns or {})
    n = len(next(iter(columns.values()))) if columns else 1
    g, d, m, op = params.gears, params.dimensions, params.materials, params.operating
    geom = analysis.cone_geometry(g.module_mm, g.big_teeth, g.small_teeth)  # integers: never sampled here
    alpha = math.radians(g.pressure_angle_deg)

    def col(key: str, default: float) -> Any:  # arrays through the model's scalar-typed formulas
        return _col(columns, key, default, n)

    unit = analysis.thermal_approach(
        geom, a_mm=col("dimensions.a_mm", d.a_mm), b_mm=col("dimensions.b_mm", d.b_mm),
        l11_mm=col("dimensions.l11_mm", d.l11_mm), l12_mm=col("dimensions.l12_mm", d.l12_mm),
        l2_mm=col("dimensions.l2_mm", d.l2_mm),
        housing_cte_per_K=col("materials.housing_cte_per_K", m.housing_cte_per_K),
        shaft_cte_per_K=col("materials.shaft_cte_per_K", m.shaft_cte_per_K),
        gear_cte_per_K=col("materials.gear_cte_per_K", m.gear_cte_per_K), temperature_drop_K=1.0)
    per_k = analysis.backlash_change(geom, alpha, unit.big_approach_mm, unit.small_approach_mm).per_side_arcmin
    shim = col("shim.thickness_mm", params.shim.thickness_mm)
    gain = analysis.shim_gain(geom, alpha, 1.0).per_side_arcmin  # eq (11) is linear in the shim
    warm_c = col("operating.warm_C", op.warm_C)
    c = params.calibration
    if c.given:
        measured = col("calibration.measured_backlash_total_min_arcmin", c.measured_backlash_total_min_arcmin)
        at_c = col("calibration.measured_at_C", c.measured_at_C)
        measured_shim = col("calibration.measured_shim_mm", c.measured_shim_mm)
        warm = measured / 2.0 + per_k * (warm_c - at_c) + gain * (shim - measured_shim)
    else:
        thinning = col("backlash.mesh_thinning_min_mm", params.backlash.mesh_thinning_min_mm)
        warm = analysis.big_gear_arcmin(thinning, geom) + gain * shim

    def play_at(key: str, default: float) -> np.ndarray:
        return warm - per_k * (warm_c - col(key, default))

    return {
        "warm_play_arcmin": warm,
        "cold_play_arcmin": play_at("operating.cold_C", op.cold_C),
        "least_play_operating_arcmin": np.minimum(play_at("operating.operating_min_C", op.operating_min_C),
                                                  play_at("operating.operating_max_C", op.operating_max_C)),
        "least_play_storage_arcmin": np.minimum(play_at("operating.storage_min_C", op.storage_min_C),
                                                play_at("operating.storage_max_C", op.storage_max_C)),
        "drop_per_K_arcmin": np.broadcast_to(per_k, warm.shape).astype(float),
    }


def analytical_row(params) -> dict[str, float]:
    return {k: float(np.asarray(v).ravel()[0]) for k, v in paper_model(params).items()}


def _measured(params, temperatures: dict[str, float]) -> dict[str, float]:
    """The exact least plays per side the calibration already solved: a calibrated design measured
    at the template's shim has its least thinning's exact total at the measured temperature (the
    same exact model at the same specs, shim and temperature — not evaluated twice)."""
    th, c = params.thinning(), params.calibration
    if not (th.calibrated and c.measured_shim_mm == params.shim.thickness_mm):
        return {}
    return {k: th.exact_total_min_arcmin / 2.0 for k, t in temperatures.items() if t == c.measured_at_C}


def exact_row(params) -> dict[str, float]:
    """The exact least plays per side at the template's shim at the named temperatures."""
    keys = tp.key_temperatures(params)
    at = _measured(params, keys)
    names = [k for k in keys if k not in at]
    if names:
        plays = tp.exact_plays(params, params.shim.thickness_mm, [keys[k] for k in names]).least_arcmin
        at.update(zip(names, (float(v) for v in plays), strict=True))
    thinning = params.thinning()
    return {
        "warm_play_arcmin": at["warm"],
        "cold_play_arcmin": at["cold"],
        "least_play_operating_arcmin": min(at["operating_min"], at["operating_max"]),
        "least_play_storage_arcmin": min(at["storage_min"], at["storage_max"]),
        "built_thinning_um": 1e3 * thinning.min_mm,
    }
