"""The tooth thinning the gears are built with: the template's reconstruction from the paper's
first-order model, or — when the template gives a measured backlash ([calibration]) — the
thinning that makes the exact geometry reproduce the measurement.

Numpy only. The paper's model (eqs (10), (11)) says warm total = 2·(thinning + shim gain) on
d1/2; the exact geometry gains less from a shim (its apex leaves the common apex, the mesh is no
longer conjugate), so a thinning set through the paper's model builds a unit with less backlash
than the one measured. Calibrated, the measured warm total backlash (both sides: two meshes,
output shaft to output shaft) at the measured shim and temperature is read as twice the exact
least play per side over the cycle: a backlash floor is inspected by turning the output through
a revolution and keeping the least reading, and "backlash ≥ M" holds at every pose only if the
least over the cycle is M. Read so, the solved thinning is the largest a single reading allows (a
reading at the loosest pose would give less: 40.2 µm instead of 43.8 µm for the template, its
storage overlap −0.65′ instead of −0.35′ per side; docs/differential.md). The least measured
value gives the least thinning (the gears are built with it), the largest the largest.

The exact warm total grows with the thinning at very nearly 2/(d1/2) rad per mm (a thinning is a
turn of each flank about its own axis, exact for the big gear's flanks and first order for the
small gear's) and is linear in it to about 1e-5 of that slope, so a Newton step from the template's thinning
(solved at the least-play pose only) gives the slope, a step on it over the whole cycle reaches
the least measured value, and one more over the whole cycle the largest: three whole-cycle exact
evaluations and one of a single pose; each stops at :data:`SOLVE_TOL_ARCMIN`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.mechanisms.differential import temperature
from gearcheck.mechanisms.differential.poses import gear_specs

# The solved thinning reproduces the measured total to this (arcmin, both sides).
SOLVE_TOL_ARCMIN = 1e-4
SOLVE_ITERATIONS = 12
# The thinning may not exceed the template field's limit (mm, one mesh).
THINNING_MAX_MM = 0.5


class CalibrationError(ValueError):
    """The measurement cannot be reproduced: ``which`` is "min" or "max" (the measured value
    that fails), ``bound`` the allowed limit (arcmin) if there is one, ``side`` "lower"/"upper"."""

    def __init__(self, which: str, why: str, bound: float | None = None, side: str = "lower"):
        super().__init__(why)
        self.which, self.why, self.bound, self.side = which, why, bound, side


@dataclass(frozen=True)
class Thinning:
    """The circumferential tooth thinning of one mesh (big + small gear, on the outer pitch
    circle) the gears are built with, and where it comes from."""

    min_mm: float
    max_mm: float
    template_min_mm: float  # the template's [backlash] (the paper-model reconstruction)
    template_max_mm: float
    calibrated: bool
    # when calibrated: the exact warm totals (two meshes, cycle minimum, arcmin) at the measured
    # shim and temperature, at the solved thinning and at the template's
    exact_total_min_arcmin: float = math.nan
    exact_total_max_arcmin: float = math.nan
    template_exact_total_min_arcmin: float = math.nan
    exact_evaluations: int = 0


def template_thinning(params) -> Thinning:
    b = params.backlash
    return Thinning(b.mesh_thinning_min_mm, b.mesh_thinning_max_mm, b.mesh_thinning_min_mm,
                    b.mesh_thinning_max_mm, False)


def exact_warm_total(params, thinning_mm: float, shim_mm: float, at_C: float) -> float:
    """Twice the exact least play per side over the cycle (arcmin): the total backlash between
    the output shafts a measurement at this shim and temperature reads, conservatively."""
    specs = gear_specs(params, thinning_mm=thinning_mm)
    return 2.0 * temperature.least_play(params, shim_mm, at_C, specs=specs)


class _Totals:
    """Exact warm totals at the measured shim and temperature, by thinning (each solved once), and
    the drive angle of the least play of the last whole cycle solved."""

    def __init__(self, params, shim_mm: float, at_C: float):
        self.params, self.shim_mm, self.at_C = params, shim_mm, at_C
        self.known: dict[float, float] = {}
        self.least_angle: float | None = None

    def _plays(self, thinning_mm: float, which: str, angles: list[float] | None = None):
        try:
            return temperature.exact_plays(self.params, self.shim_mm, [self.at_C], angles_rad=angles,
                                           specs=gear_specs(self.params, thinning_mm=thinning_mm))
        except RuntimeError as exc:  # the exact model finds no contact (play beyond its reach)
            raise CalibrationError(which, f"the exact model cannot measure this backlash ({exc})") from None
        except ValueError as exc:  # the gears cannot be made with this thinning (pointed teeth)
            raise CalibrationError(which, f"no gear pair with {thinning_mm:.4f} mm of tooth thinning ({exc})"
                                   ) from None

    def __call__(self, thinning_mm: float, which: str) -> float:
        """The total over the whole cycle (both sides: twice the least play per side at the cycle's
        drive angles)."""
        if thinning_mm not in self.known:
            plays = self._plays(thinning_mm, which)
            play = plays.play_arcmin[0]  # (angle, big gear)
            self.least_angle = float(plays.angles_rad[np.unravel_index(np.argmin(play), play.shape)[0]])
            # at the cycle's drive angles: a measured least backlash is read at the poses measured
            self.known[thinning_mm] = 2.0 * float(plays.sampled_least_arcmin[0])
        return self.known[thinning_mm]

    def at_least_angle(self, thinning_mm: float, which: str) -> float:
        """The total at the drive angle of the last cycle's least play only: a step of the solve,
        never its result (a thinning moves every pose's play alike, so the least stays there; the
        result is always a whole cycle)."""
        assert self.least_angle is not None
        return 2.0 * float(self._plays(thinning_mm, which, [self.least_angle]).sampled_least_arcmin[0])


def _solve(params, totals: _Totals, target: float, which: str, start_mm: float,
           slope: float | None = None) -> tuple[float, float, float]:
    """The thinning whose exact warm total is ``target``: (thinning, its total, the last secant
    slope). The total is linear in the thinning to about 1e-5 of its slope (a thinning turns each
    flank about its own axis). Without a ``slope``: a Newton step from ``start_mm`` on the
    first-order slope, taken at the least-play pose only, gives the slope; then secant steps over
    whole cycles (one or two). With one: secant steps from ``start_mm`` (usually one)."""
    d1_half = params.gears.module_mm * params.gears.big_teeth / 2.0
    first_order = 2.0 * bp.ARCMIN_PER_RAD / d1_half  # arcmin of total per mm of thinning
    s = first_order if slope is None or not slope > 0 else slope
    t0 = min(max(start_mm, 0.0), THINNING_MAX_MM)
    f0 = totals(t0, which) - target
    if abs(f0) <= SOLVE_TOL_ARCMIN:
        return t0, f0 + target, s
    t1 = t0 - f0 / s
    if slope is None and 0.0 < t1 <= THINNING_MAX_MM:
        g1 = totals.at_least_angle(t1, which) - target
        s = (g1 - f0) / (t1 - t0) if (g1 - f0) / (t1 - t0) > 0 else first_order
        t0, f0 = t1, g1
    for _ in range(SOLVE_ITERATIONS):
        t1 = t0 - f0 / s
        if t1 < 0.0:  # below no thinning: the target may be out of reach
            zero = totals(0.0, which)
            if target < zero:
                raise CalibrationError(which, f"the exact geometry with no tooth thinning already has {zero:.3f}′ at "
                                       f"shim {totals.shim_mm:g} mm, {totals.at_C:g} °C (cycle minimum, both sides)",
                                       zero, "lower")
            t1 = 0.0
        if t1 > THINNING_MAX_MM:
            top = totals(THINNING_MAX_MM, which)
            raise CalibrationError(which, f"it needs more than {THINNING_MAX_MM} mm of tooth thinning (the exact "
                                   f"total at {THINNING_MAX_MM} mm is {top:.3f}′)", top, "upper")
        f1 = totals(t1, which) - target
        if abs(f1) <= SOLVE_TOL_ARCMIN:
            return t1, f1 + target, s
        secant = (f1 - f0) / (t1 - t0) if t1 != t0 else 0.0
        s = secant if secant > 0 else first_order
        t0, f0 = t1, f1
    raise CalibrationError(which, f"the thinning solve did not converge (last {t0:.5f} mm, off by {f0:.2e}′)")


def calibrated_thinning(params) -> Thinning:
    """The thinning of the template, solved on the exact geometry from [calibration] when given
    (raises :class:`CalibrationError`), else the template's [backlash] as it is."""
    base = template_thinning(params)
    c = params.calibration
    if not c.given:
        return base
    totals = _Totals(params, c.measured_shim_mm, c.measured_at_C)
    t_min, total_min, slope = _solve(params, totals, c.measured_backlash_total_min_arcmin, "min",
                                     base.template_min_mm)
    t_max, total_max, _ = _solve(params, totals, c.measured_backlash_total_max_arcmin, "max", t_min, slope)
    template_total = totals(base.template_min_mm, "min")
    return Thinning(t_min, t_max, base.template_min_mm, base.template_max_mm, True, total_min, total_max,
                    template_total, len(totals.known))
