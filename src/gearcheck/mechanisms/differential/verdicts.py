"""The differential's verdicts at the template's shim: no interference warm, play left cold over
the whole cycle, and the mesh sweep agreeing with the exact-flank model."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.mechanisms.differential.reduce import AGREEMENT_RELATIVE, C, W, SweepData
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS
from gearcheck.results import SweepOutcome, Verdict


def verdicts(params, outcome: SweepOutcome) -> list[Verdict]:
    data: SweepData = outcome.data
    t, shims, angles = data.t, data.shims, data.angles
    geom_play, geom_min, exact_min = data.geom_play, data.geom_min, data.exact_min
    bound_arcmin, total_dev = data.bound_arcmin, data.total_dev
    warm_free = bool(data.centred_free[t, W].all())
    least_warm = np.unravel_index(np.argmin(geom_play[t, W]), geom_play[t, W].shape)
    n_poses = len(angles) * len(BIG_GEARS) * len(SMALL_GEARS)
    cold_centred_free = bool(data.centred_free[t, C].all())
    cold_ok = bool(geom_min[t, C] > 0.0 and exact_min[t, C] > 0.0 and cold_centred_free)
    return [
        Verdict.of(
            "no_interference_warm", f"no interference warm at shim {shims[t]:.2f} mm",
            warm_free and bool(geom_min[t, W] > 0.0),
            f"{n_poses} centred poses (4 meshes × {len(angles)} drive angles) free"
            f"{'' if warm_free else ' — NOT all'}; contact reached both ways at every pose; least warm play "
            f"{geom_min[t, W]:.3f}′ per side ({BIG_GEARS[least_warm[1]]}, "
            f"drive {math.degrees(angles[least_warm[0]]):.2f}°), "
            f"exact {exact_min[t, W]:.3f}′, mesh bound ±{2 * bound_arcmin:.2f}′ on a play",
            {"centred_poses_free": float(warm_free), "geom_warm_play_min_arcmin": float(geom_min[t, W]),
             "exact_warm_play_min_arcmin": float(exact_min[t, W])}),
        Verdict.of(
            "cold_play_positive", f"cold play > 0 over the whole cycle at shim {shims[t]:.2f} mm", cold_ok,
            f"least cold play {geom_min[t, C]:.3f}′ per side (geometry), exact {exact_min[t, C]:.3f}′; "
            f"centred cold poses {'all free' if cold_centred_free else 'COLLIDE'}; worst-case mesh bound "
            f"±{2 * bound_arcmin:.2f}′ on a play (the mesh matches the exact flanks to "
            f"{total_dev[t, C].max():.3f}′ here)",
            {"centred_poses_free": float(cold_centred_free), "geom_cold_play_min_arcmin": float(geom_min[t, C]),
             "exact_cold_play_min_arcmin": float(exact_min[t, C])}),
        Verdict.of(
            "mesh_agrees_with_exact", "mesh sweep agrees with the exact-flank model",
            data.contact_ok and data.total_ok,
            f"largest difference {data.contact_dev.max():.3f}′ per contact and {total_dev.max():.3f}′ per play over "
            f"{data.contacts} contacts; allowed {bound_arcmin:.2f}′ (bound {data.bound_mm * 1e3:.1f} µm on d1/2) + "
            f"{AGREEMENT_RELATIVE:.0%} per contact, twice the bound per play",
            {"max_contact_deviation_arcmin": float(data.contact_dev.max()),
             "max_play_deviation_arcmin": float(total_dev.max()), "mesh_error_bound_arcmin": bound_arcmin}),
    ]
