"""The roller-chain drive's numbers, derived from the parameters once (numpy only): the ISO 606
chain, the sprocket's tooth gap and solid spec, the link specs and the wrap the sweep poses."""

from __future__ import annotations

import math
from dataclasses import dataclass

from gearcheck.geometry import iso606, iso606_chains
from gearcheck.geometry import roller_chain as rc
from gearcheck.geometry.sprocket import SprocketSpec

# Rollers on each horizontal span beyond its anchor (the default segment).
SPAN_ROLLERS = 3


@dataclass(frozen=True)
class RollerChainModel:
    size: iso606_chains.ChainSize
    strands: int
    fixed_centres: bool
    form: float
    tooth: iso606_chains.ToothForm
    gap: iso606.ToothGap
    sprocket: SprocketSpec
    inner: rc.LinkSpec
    outer: rc.LinkSpec
    wrap: rc.RollerWrap
    max_speed_ripple_pct: float = 2.0

    @property
    def teeth(self) -> int:
        return self.gap.teeth

    @property
    def roller_radius_mm(self) -> float:
        return self.size.roller_diameter_mm / 2.0

    @property
    def seating_clearance_mm(self) -> float:
        """ri − d1/2: a roller on its seating centre, concentric with the seating arc."""
        return self.gap.seating_radius_mm - self.roller_radius_mm

    @property
    def inner_plate_gap_mm(self) -> float:
        """Axial gap between a tooth row's side and the inner plates, (b1 − bf1)/2."""
        return (self.size.inner_width_mm - self.sprocket.tooth_width_mm) / 2.0

    @property
    def outer_plate_gap_mm(self) -> float:
        """Axial gap between a tooth row's side and the outer plates, (b1 + 2t − bf1)/2."""
        return self.inner_plate_gap_mm + self.size.plate_thickness_mm

    @property
    def hub_gap_mm(self) -> float:
        """Seated plates over the hub (multi-strand: the floor of the groove between rows): the
        chord's middle R·cos(180°/z) less h2/2, less the hub radius dg/2; inf for one strand."""
        if self.strands == 1:
            return math.inf
        r = self.gap.pitch_radius_mm * math.cos(math.pi / self.teeth)
        return r - self.size.plate_depth_mm / 2.0 - self.sprocket.hub_radius_mm

    def plate_gap_mm(self, link: int) -> float:
        return self.inner_plate_gap_mm if link % 2 == 0 else self.outer_plate_gap_mm


def build_model(params) -> RollerChainModel:
    c, s = params.chain, params.sprocket
    size = iso606_chains.chain(c.designation)
    z, p, d1 = s.teeth, size.pitch_mm, size.roller_diameter_mm
    tooth = iso606_chains.tooth_form(d1, z, s.form)
    gap = iso606_chains.tooth_gap(p, d1, z, s.form, s.tip_diameter_mm)
    dg = iso606_chains.shroud_diameter_max(p, size.plate_depth_mm, z)
    middle = size.transverse_pitch_mm - s.tooth_width_mm
    sprocket = SprocketSpec(gap, s.tooth_width_mm, c.strands, middle, dg / 2.0, s.bore_diameter_mm / 2.0)

    def link(kind: str) -> rc.LinkSpec:
        return rc.LinkSpec(kind, p, d1 / 2.0, size.pin_diameter_mm / 2.0, size.inner_width_mm, size.plate_depth_mm,
                           size.plate_thickness_mm, c.strands, size.transverse_pitch_mm)

    return RollerChainModel(size, c.strands, c.fixed_centres, s.form, tooth, gap, sprocket, link("inner"),
                            link("outer"), rc.RollerWrap.centred(z, p, SPAN_ROLLERS),
                            params.drive.max_speed_ripple_pct)
