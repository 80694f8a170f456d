"""The differential's bevel pair under tooth contact analysis (:mod:`gearcheck.geometry.bevel_tca`):
its transmission error and contact path as designed and under each mounting error alone, for
summary.json ``tca``."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry import bevel_tca as bt
from gearcheck.geometry.bevel_mesh import drive_poses
from gearcheck.mechanisms.differential.poses import GearSpecs, assembly_poses
from gearcheck.mechanisms.differential.temperature import placed_gears
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, thermal_state

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


def state_mounting(params, specs: GearSpecs, shim_mm: float, temperature_C: float) -> dict[str, float]:
    """The first big/small pair's mounting in a thermal state (the shim and the temperature: the
    exact model's placed gears, at drive angle 0) as E/P/G/Σ against its design mounting
    (:func:`gearcheck.geometry.bevel_tca.equivalent_misalignment`), with each gear's scale about its
    apex."""
    built = assembly_poses(specs, shim_mm).as_dict()
    state = thermal_state(params, cold_C=float(temperature_C), specs=specs, shim_mm=shim_mm)
    placed = placed_gears(specs, drive_poses(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small, 0.0), state)
    big, small = placed[BIG_GEARS[0]], placed[SMALL_GEARS[0]]
    rel = np.linalg.solve(big.pose, small.pose)  # the small gear in the big gear's frame
    nominal = bp.nominal_small_pose(specs.big, specs.small)
    m = nominal[:3, :3].T @ rel[:3, :3]  # ≈ the small gear's own turn (the assembly's phasing)
    turn = math.atan2(m[1, 0], m[0, 0])
    mounting = bt.equivalent_misalignment(np.eye(4), rel @ np.linalg.inv(nominal @ bp.rot_z4(turn)))
    return {**mounting, "big_scale": big.scale, "small_scale": small.scale}


def state_summary(params, specs: GearSpecs, shim_mm: float, temperature_C: float, plus_arcmin: np.ndarray,
                  minus_arcmin: np.ndarray) -> dict[str, float]:
    """One thermal state at the template's shim: its mounting as E/P/G/Σ and the TE the check's own
    exact solve gives at its drive angles (``plus``, ``minus``: (angle, big gear) contact turns of
    each output shaft, arcmin), the worst output shaft's: TE_drive = −plus, TE_coast = −minus, and
    the least of TE_coast − TE_drive, which is the check's least play at those angles (one model)."""
    urad = 1e6 * math.pi / 10800.0
    drive, coast = -plus_arcmin, -minus_arcmin
    return {**state_mounting(params, specs, shim_mm, temperature_C),
            "drive_te_pp_urad": urad * float(np.max(np.ptp(drive, axis=0))),
            "coast_te_pp_urad": urad * float(np.max(np.ptp(coast, axis=0))),
            "drive_te_mean_urad": urad * float(np.mean(drive)), "coast_te_mean_urad": urad * float(np.mean(coast)),
            "least_play_arcmin": float(np.min(coast - drive))}
