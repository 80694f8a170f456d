"""The differential's bevel pair under tooth contact analysis (:mod:`gearcheck.geometry.bevel_tca`):
its transmission error and contact path as designed and under each mounting error alone, and at
each thermal state the check meshes its mounting, TE and contact pattern, for summary.json ``tca``
and the report."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry import bevel_tca as bt
from gearcheck.geometry.bevel_mesh import drive_poses
from gearcheck.mechanisms.differential.poses import GearSpecs, assembly_poses, gear_specs
from gearcheck.mechanisms.differential.temperature import (MESH_DECIDED_STATES, key_temperatures, meshed_states,
                                                           placed_gears)
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


# The states the pattern requirement holds at: the gears run there (storage is not running).
RUNNING_STATES = MESH_DECIDED_STATES
FLANKS = ("drive", "coast")


@dataclass(frozen=True)
class PairTca:
    """The pair at one mounting (as designed, or a thermal state's): TE and contact path over two
    mesh cycles, and the contact pattern of each flank of the big gear's tooth."""

    name: str
    temperature_C: float  # nan: as designed (no thermal state)
    mounting: bt.Mounting
    te: bt.TransmissionError
    patterns: dict[str, bt.ContactPattern]


def pair_tca(specs: GearSpecs, mounting: bt.Mounting, name: str, temperature_C: float = math.nan,
             compound_mm: float = bt.COMPOUND_MM, *, steps: int = bt.PATTERN_STEPS,
             grid: tuple[int, int] = (bt.PATTERN_PROFILE, bt.PATTERN_RULING)) -> PairTca:
    """TE and both flanks' patterns of the pair as ``mounting`` places it (``steps`` drive angles a
    cycle and a ``grid`` of profile × ruling points for the pattern)."""
    te = bt.mounted_transmission_error(specs.big, specs.small, mounting, CYCLES, PER_CYCLE)
    return PairTca(name, temperature_C, mounting, te,
                   {f: bt.contact_pattern(specs.big, specs.small, mounting, te, f, compound_mm, steps, *grid)
                    for f in FLANKS})


def state_tca(params, specs: GearSpecs, shim_mm: float, name: str, temperature_C: float, *,
              steps: int = bt.PATTERN_STEPS, grid: tuple[int, int] = (bt.PATTERN_PROFILE, bt.PATTERN_RULING)
              ) -> PairTca:
    """:func:`pair_tca` at a thermal state's mounting (:func:`state_mounting`) with the template's
    mounting errors (``[tca]``: E/P/G/Σ) on top, under its marking compound."""
    m = state_mounting(params, specs, shim_mm, temperature_C)
    big_error, small_error = bt.Misalignment(*params.tca.mounting_errors).displacements()
    mounting = bt.Mounting.of(bt.Misalignment(m["offset_mm"], m["small_axial_mm"], m["big_axial_mm"],
                                              m["shaft_angle_rad"]), m["big_scale"], m["small_scale"],
                              big_error, small_error)
    return pair_tca(specs, mounting, name, temperature_C, params.tca.compound_um * 1e-3, steps=steps, grid=grid)


def pattern_summary(p: bt.ContactPattern) -> dict[str, float]:
    """One flank's pattern for summary.json: its span (toe 0 … heel 1, root 0 … tip 1), length
    (share of the face width), centre, share of the flank's area, and 1/0 for reaching the toe,
    the heel, the tip and running below the form line."""
    e = p.extent()
    return {"along_min": e["along_min"], "along_max": e["along_max"], "length": e["along_max"] - e["along_min"],
            "centre_along": e["centre_along"], "height_min": e["height_min"], "height_max": e["height_max"],
            "centre_height": e["centre_height"], "area_share": e["area_share"],
            **{f"reaches_{k}": float(e[k]) for k in ("toe", "heel", "tip")}, "below_form": float(e["below_form"])}


def patterns_summary(pairs: list[PairTca]) -> dict[str, dict[str, dict[str, float]]]:
    """summary.json ``tca.patterns``: each pair's (aligned, each state's) patterns of both flanks."""
    return {t.name: {f: pattern_summary(p) for f, p in t.patterns.items()} for t in pairs}


def mounted_summary(pairs: list[PairTca]) -> dict[str, dict[str, float]]:
    """summary.json ``tca.mounted``: each pair's TE figures (:func:`curve_summary`: one big gear
    with one small gear) as designed and at each state with the template's mounting errors."""
    return {t.name: curve_summary(t.te) for t in pairs}


def sensitivity(specs: GearSpecs, pair: PairTca) -> dict[str, dict[str, float]]:
    """Each mounting error of :data:`STEPS` added to a pair's mounting: the TE peak to peak of
    both flanks (µrad) and the least play (arcmin), and their change from the pair's own."""
    base = curve_summary(pair.te)
    out = {}
    for name, step in STEPS.items():
        big, small = step.displacements()
        m = pair.mounting
        mounted = bt.Mounting(big @ m.big_displacement, small @ m.small_displacement, m.big_scale, m.small_scale)
        got = curve_summary(bt.mounted_transmission_error(specs.big, specs.small, mounted, CYCLES, PER_CYCLE))
        out[name] = {**{k: got[k] for k in ("drive_te_pp_urad", "coast_te_pp_urad", "least_play_arcmin")},
                     **{f"{k}_change": got[k] - base[k]
                        for k in ("drive_te_pp_urad", "coast_te_pp_urad", "least_play_arcmin")}}
    return out


# A study's variants: a coarser pattern (its edges to 1/28 of the face, 1/40 of the height).
STUDY_STEPS, STUDY_GRID = 24, (41, 29)
STUDY_KEYS = ("te_pp_urad", "warm_te_pp_urad", "cold_te_pp_urad", "pattern_length", "pattern_reaches_tip",
              "pattern_end_bearing")


def study_figures(params, specs: GearSpecs) -> dict[str, float]:
    """A study variant's tooth contact figures at the template's shim and mounting errors, over the
    running states: the largest TE peak to peak of either flank (one big gear with one small
    gear, µrad), the drive flank's warm and cold, the least pattern length (share of the face,
    either flank), and 1/0: a pattern reaches the tip edge; a pattern bears on one end (reaches
    the toe or the heel but not both)."""
    temps = key_temperatures(params)
    seen: dict[float, PairTca] = {}
    pairs = {}
    for name in RUNNING_STATES:
        t = float(temps[name])
        if t not in seen:
            seen[t] = state_tca(params, specs, params.shim.thickness_mm, name, t, steps=STUDY_STEPS, grid=STUDY_GRID)
        pairs[name] = seen[t]
    extents = [p.extent() for pair in seen.values() for p in pair.patterns.values()]
    return {"te_pp_urad": 1e6 * float(max(max(np.ptp(p.te.drive_rad), np.ptp(p.te.coast_rad)) for p in seen.values())),
            "warm_te_pp_urad": 1e6 * float(np.ptp(pairs["warm"].te.drive_rad)),
            "cold_te_pp_urad": 1e6 * float(np.ptp(pairs["cold"].te.drive_rad)),
            "pattern_length": min(p.length for pair in seen.values() for p in pair.patterns.values()),
            "pattern_reaches_tip": float(any(e["tip"] for e in extents)),
            "pattern_end_bearing": float(any(e["toe"] != e["heel"] for e in extents))}


def design_tca(params) -> dict[str, PairTca]:
    """The pair as designed ("aligned") and at each state the check meshes, at the template's shim
    with its mounting errors: what :meth:`gearcheck.design.Design.tca` returns (the check's
    ``tca`` figures are these)."""
    specs = gear_specs(params)
    out = {"aligned": pair_tca(specs, bt.Mounting.of(), "aligned", compound_mm=params.tca.compound_um * 1e-3)}
    for name, temp in meshed_states(params):
        out[name] = state_tca(params, specs, params.shim.thickness_mm, name, temp)
    return out
