"""Template model of the roller-chain drive: the chain by its ISO 606 designation and strands, the
sprocket by its teeth, its place between ISO 606's minimum and maximum tooth form, its tip
diameter, tooth width and bore. Nothing derived: the chain's dimensions come from the ISO 606
table (:mod:`gearcheck.geometry.iso606_chains`), the tooth form from ``form``.

The rules across fields are collected with :class:`~gearcheck.params.common.Problems`: every one
broken is named at once, each line giving the field, the value and the allowed range. A rule is
broken only where no design can meet it (an unknown chain, a tip circle that leaves no tooth, tooth
rows that overlap, a bore through the teeth); what a design *does* (a tip diameter outside ISO 606's
range, a wear limit below the replacement rule, plates on the teeth) is a verdict of ``check``.
"""

from __future__ import annotations

from pydantic import Field, model_validator

from gearcheck.geometry import iso606, iso606_chains
from gearcheck.params import Problems, Section
from gearcheck.params.common import fmt_bound, fmt_range

MIN_TEETH = 9
MAX_TEETH = 150
MAX_STRANDS = 3


def _f(lo=None, hi=None, *, gt=None, lt=None, unit="", description=""):
    return Field(ge=lo, le=hi, gt=gt, lt=lt, description=description, json_schema_extra={"unit": unit})


class Chain(Section):
    designation: str = Field(min_length=2, max_length=8,
                             description="ISO 606 chain number: " + ", ".join(iso606_chains.DESIGNATIONS)
                             + " (B series; A series = ANSI B29.1)")
    strands: int = _f(1, MAX_STRANDS, description="strands (1 simplex, 2 duplex, 3 triplex)")
    fixed_centres: bool = Field(False, description="shaft centres fixed (no tensioner): the wear limit is 1.5 % "
                                                   "instead of 3 %")


class Sprocket(Section):
    teeth: int = _f(MIN_TEETH, MAX_TEETH, description="teeth z (every tooth engages; odd or even)")
    form: float = _f(0, 1, description="tooth form between ISO 606's minimum tooth gap (0: ri min, re max, α max) "
                                       "and its maximum tooth gap (1: ri max, re min, α min), linear in between")
    tip_diameter_mm: float = _f(gt=0, hi=10_000, unit="mm",
                                description="tip diameter da (ISO 606: d + p(1 − 1.6/z) − d1 to d + 1.25p − d1)")
    tooth_width_mm: float = _f(gt=0, hi=500, unit="mm", description="tooth width bf1 of each row (ISO 606 max: "
                                                                    "0.93·b1 / 0.95·b1 simplex, 0.91·b1 / 0.93·b1 "
                                                                    "duplex and triplex, for p ≤ / > 12.7 mm)")
    bore_diameter_mm: float = _f(0, 10_000, unit="mm", description="shaft bore (below the hub diameter dg)")


class Drive(Section):
    speed_rpm: float = _f(gt=0, hi=20_000, unit="rpm", description="sprocket speed n")
    power_kW: float = _f(0, 10_000, unit="kW", description="power the chain transmits P")
    service_factor: float = _f(1, 5, description="service factor on the chain pull (1 smooth drive, up to 3 heavy "
                                                 "shock)")
    max_speed_ripple_pct: float = _f(gt=0, hi=50, unit="%",
                                     description="chain speed ripple the application allows (the polygon effect "
                                                 "1 − cos(180°/z); 2 % ≈ 16 teeth)")


class Params(Section):
    chain: Chain
    sprocket: Sprocket
    drive: Drive

    @model_validator(mode="after")
    def _cross_checks(self) -> Params:
        c, s = self.chain, self.sprocket
        with Problems() as problems:
            try:
                size = iso606_chains.chain(c.designation)
            except KeyError:
                problems.add("chain.designation", c.designation,
                             "allowed one of " + ", ".join(iso606_chains.DESIGNATIONS) + " (ISO 606)")
                return self
            z, p, d1 = s.teeth, size.pitch_mm, size.roller_diameter_mm
            lo, hi = iso606_chains.tip_diameter_bounds(p, d1, z, s.form)
            if not lo < s.tip_diameter_mm < hi:
                problems.add("sprocket.tip_diameter_mm", s.tip_diameter_mm,
                             f"allowed {fmt_range(lo, hi, lo_open=True, hi_open=True)} mm for {size.designation}, "
                             f"z = {z}, form {s.form:g}: above the seating arcs' ends, below where adjacent "
                             "flanks meet (no tip land)")
            else:
                try:
                    iso606_chains.tooth_gap(p, d1, z, s.form, s.tip_diameter_mm)
                except iso606.ToothFormError as exc:
                    problems.add("sprocket.tip_diameter_mm", s.tip_diameter_mm, f"no tooth left: {exc}")
            row_pitch = size.transverse_pitch_mm
            if c.strands > 1 and not s.tooth_width_mm < row_pitch:
                problems.add("sprocket.tooth_width_mm", s.tooth_width_mm,
                             f"allowed < {fmt_bound(row_pitch, 'upper', strict=True)} mm: the transverse pitch pt of "
                             f"{size.designation} (tooth rows must not overlap)")
            if c.strands == 1 and not s.tooth_width_mm < row_pitch + size.inner_width_mm:
                problems.add("sprocket.tooth_width_mm", s.tooth_width_mm,
                             f"allowed < {fmt_bound(row_pitch + size.inner_width_mm, 'upper', strict=True)} mm "
                             "(pt + b1: wider than the whole strand)")
            dg = iso606_chains.shroud_diameter_max(p, size.plate_depth_mm, z)
            if not s.bore_diameter_mm < dg:
                problems.add("sprocket.bore_diameter_mm", s.bore_diameter_mm,
                             f"allowed < {fmt_bound(dg, 'upper', strict=True)} mm: the hub diameter dg = "
                             "p·cot(180°/z) − 1.04·h2 − 0.76 (ISO 606)")
        return self
