"""The roller-chain drive's figures for a study (numpy only, no mesh): the exact model's wear
limit against the replacement rule, and the seated and engaging clearances over one sweep."""

from __future__ import annotations

import numpy as np

from gearcheck.geometry import roller_chain as rc
from gearcheck.mechanisms.roller_chain.model import build_model

STUDY_STEPS_PER_CYCLE = 12


def exact_row(params) -> dict[str, float]:
    m = build_model(params)
    wear = rc.wear_limit(m.gap, m.roller_radius_mm)
    replacement, _ = rc.replacement_limit_pct(m.teeth, m.fixed_centres)
    wrap = m.wrap
    angles = np.arange(2 * STUDY_STEPS_PER_CYCLE + 1) * wrap.cycle_rad / STUDY_STEPS_PER_CYCLE
    moving = []
    for a in angles:
        c = rc.roller_clearances(m.gap, wrap, float(a), m.roller_radius_mm)
        moving.append(c[~wrap.seated(float(a))].min())
    return {
        "wear_limit_pct": 100.0 * wear.limit,
        "replacement_limit_pct": replacement,
        "wear_margin_pct": 100.0 * wear.limit - replacement,
        "seated_roller_clearance_mm": m.seating_clearance_mm,
        "min_engaging_roller_clearance_mm": float(min(moving)),
        "tip_land_width_mm": m.gap.tip_land_width_mm,
    }
