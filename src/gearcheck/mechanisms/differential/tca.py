"""The differential's bevel pair under tooth contact analysis (:mod:`gearcheck.geometry.bevel_tca`):
its transmission error and contact path as designed and under each mounting error alone, for
summary.json ``tca``."""

from __future__ import annotations

import math

from gearcheck.geometry import bevel_tca as bt
from gearcheck.mechanisms.differential.poses import GearSpecs

# Each mounting error at the size the figures are quoted per: 10 µm of E, P, G, 0.01° of Σ.
STEPS = {"E_10um": bt.Misalignment(offset_mm=0.01), "P_10um": bt.Misalignment(small_axial_mm=0.01),
         "G_10um": bt.Misalignment(big_axial_mm=0.01),
         "sigma_0p01deg": bt.Misalignment(shaft_angle_rad=math.radians(0.01))}
# Two mesh cycles (small-gear tooth pitches), 24 drive angles each.
CYCLES, PER_CYCLE = 2.0, 24


def curve_summary(te: bt.TransmissionError) -> dict[str, float]:
    """One TE curve's figures: peak to peak and mean of each flank (µrad, and arcsec peak to peak),
    the least play over the curve (arcmin) and where the drive flank's contact runs (toe 0 … heel 1,
    root 0 … tip 1 on the big gear's tooth)."""
    micro = 1e6
    return {"drive_te_pp_urad": micro * te.peak_to_peak("drive"), "coast_te_pp_urad": micro * te.peak_to_peak("coast"),
            "drive_te_pp_arcsec": bt.ARCSEC_PER_RAD * te.peak_to_peak("drive"),
            "coast_te_pp_arcsec": bt.ARCSEC_PER_RAD * te.peak_to_peak("coast"),
            "drive_te_mean_urad": micro * te.mean("drive"), "coast_te_mean_urad": micro * te.mean("coast"),
            "least_play_arcmin": float(te.play_rad.min()) * 10800.0 / math.pi,
            "drive_contact_along_min": float(te.drive_along.min()),
            "drive_contact_along_max": float(te.drive_along.max()),
            "drive_contact_height_min": float(te.drive_height.min()),
            "drive_contact_height_max": float(te.drive_height.max())}


def tca_summary(specs: GearSpecs) -> dict[str, dict[str, float]]:
    """The pair as designed (``aligned``) and under each mounting error of :data:`STEPS` alone."""
    out = {"aligned": curve_summary(bt.transmission_error(specs.big, specs.small, cycles=CYCLES, per_cycle=PER_CYCLE))}
    for name, m in STEPS.items():
        out[name] = curve_summary(bt.transmission_error(specs.big, specs.small, m, cycles=CYCLES, per_cycle=PER_CYCLE))
    return out
