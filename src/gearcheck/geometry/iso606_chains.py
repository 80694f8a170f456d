"""ISO 606 short-pitch transmission roller chains and their sprockets, numpy only: the chain
dimensions by designation (B series, and the A series that is ANSI B29.1) and the standard
sprocket's tooth form, where every tooth engages (pitch diameter d = p / sin(180°/z)).

Chain dimensions (ISO 606, table of chain dimensions), mm: pitch p, roller diameter d1 (max),
width between inner plates b1 (min), pin diameter d2 (max), inner plate depth h2 (max) and
transverse pitch pt (multi-strand chains).

Sprocket tooth form (ISO 606, sprocket tooth form): the tooth gap is a roller seating arc of radius
ri centred on the pitch circle, spanning the roller seating angle α, and on each side a tooth
flank arc of radius re tangent to it, up to the tip circle (the form the track mechanism's
:func:`gearcheck.geometry.iso606.tooth_gap` solves; here with the grooves one chain pitch apart).
The standard bounds the form between a minimum tooth gap (ri min, re max, α max) and a maximum
tooth gap (ri max, re min, α min); ``form`` in [0, 1] picks one in between, each value linear
in it (0: minimum gap, 1: maximum gap).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gearcheck.geometry import iso606


@dataclass(frozen=True)
class ChainSize:
    """One ISO 606 chain (mm)."""

    designation: str
    pitch_mm: float  # p
    roller_diameter_mm: float  # d1 max
    inner_width_mm: float  # b1 min
    pin_diameter_mm: float  # d2 max
    plate_depth_mm: float  # h2 max (inner plate depth)
    transverse_pitch_mm: float  # pt

    @property
    def plate_thickness_mm(self) -> float:
        """Plate thickness of the model, t = (pt − b1)/4: an inner and an outer plate on each side of
        a strand, adjacent strands' outer plates meeting half way (ISO 606 tabulates no thickness)."""
        return (self.transverse_pitch_mm - self.inner_width_mm) / 4.0


# ISO 606 chain dimensions: designation → (p, d1, b1, d2, h2, pt), mm.
_TABLE = {
    "05B": (8.00, 5.00, 3.00, 2.31, 7.11, 5.64),
    "06B": (9.525, 6.35, 5.72, 3.28, 8.26, 10.24),
    "08B": (12.70, 8.51, 7.75, 4.45, 11.81, 13.92),
    "10B": (15.875, 10.16, 9.65, 5.08, 14.73, 16.59),
    "12B": (19.05, 12.07, 11.68, 5.72, 16.13, 19.46),
    "16B": (25.40, 15.88, 17.02, 8.28, 21.08, 31.88),
    "20B": (31.75, 19.05, 19.56, 10.19, 26.42, 36.45),
    "24B": (38.10, 25.40, 25.40, 14.63, 33.40, 48.36),
    "28B": (44.45, 27.94, 30.99, 15.90, 37.08, 59.56),
    "32B": (50.80, 29.21, 30.99, 17.81, 42.29, 58.55),
    "08A": (12.70, 7.92, 7.85, 3.98, 12.07, 14.38),
    "10A": (15.875, 10.16, 9.40, 5.09, 15.09, 18.11),
    "12A": (19.05, 11.91, 12.57, 5.96, 18.10, 22.78),
    "16A": (25.40, 15.88, 15.75, 7.94, 24.13, 29.29),
    "20A": (31.75, 19.05, 18.90, 9.54, 30.17, 35.76),
    "24A": (38.10, 22.23, 25.22, 11.11, 36.20, 45.44),
    "28A": (44.45, 25.40, 25.22, 12.71, 42.23, 48.87),
    "32A": (50.80, 28.58, 31.55, 14.29, 48.26, 58.55),
}
DESIGNATIONS: tuple[str, ...] = tuple(_TABLE)


def chain(designation: str) -> ChainSize:
    """The chain of an ISO 606 designation ("12B", "16A"; case and a strand suffix "-1" ignored).
    KeyError if the table has no such chain."""
    key = str(designation).strip().upper().split("-")[0]
    return ChainSize(key, *_TABLE[key])


def pitch_diameter(pitch_mm: float, teeth: int) -> float:
    """d = p / sin(180°/z)."""
    return pitch_mm / math.sin(math.pi / teeth)


def root_diameter(pitch_mm: float, roller_diameter_mm: float, teeth: int) -> float:
    """df = d − d1 (the seating arcs' bottom at ri = d1/2; a larger ri lowers it by 2(ri − d1/2))."""
    return pitch_diameter(pitch_mm, teeth) - roller_diameter_mm


def tip_diameter_range(pitch_mm: float, roller_diameter_mm: float, teeth: int) -> tuple[float, float]:
    """(da min, da max) = (d + p(1 − 1.6/z) − d1, d + 1.25p − d1)."""
    d = pitch_diameter(pitch_mm, teeth)
    return iso606.iso_tip_diameter_range(d, pitch_mm, roller_diameter_mm, teeth)


def shroud_diameter_max(pitch_mm: float, plate_depth_mm: float, teeth: int) -> float:
    """Largest hub (shroud) diameter under the chain plates, dg = p·cot(180°/z) − 1.04·h2 − 0.76."""
    return pitch_mm / math.tan(math.pi / teeth) - 1.04 * plate_depth_mm - 0.76


def tooth_width_max(inner_width_mm: float, pitch_mm: float, strands: int) -> float:
    """Largest tooth width bf1: simplex 0.93·b1 (p ≤ 12.7 mm) or 0.95·b1; duplex and triplex
    0.91·b1 or 0.93·b1; four strands and more 0.88·b1 or 0.93·b1."""
    small = pitch_mm <= iso606.ISO_TOOTH_WIDTH_PITCH_LIMIT_MM
    if strands == 1:
        factor = 0.93 if small else 0.95
    elif strands <= 3:
        factor = 0.91 if small else 0.93
    else:
        factor = 0.88 if small else 0.93
    return factor * inner_width_mm


@dataclass(frozen=True)
class ToothForm:
    """The seating radius ri, flank radius re and seating angle α (degrees) of one form."""

    seating_radius_mm: float
    flank_radius_mm: float
    seating_angle_deg: float


def tooth_form(roller_diameter_mm: float, teeth: int, form: float) -> ToothForm:
    """The form ``form`` of the way from ISO 606's minimum tooth gap (0: ri min, re max, α max) to
    its maximum tooth gap (1: ri max, re min, α min), each value linear in ``form``."""
    lim = iso606.seating_limits(roller_diameter_mm, teeth)
    f = float(form)
    return ToothForm(
        lim.seating_radius_min_mm + f * (lim.seating_radius_max_mm - lim.seating_radius_min_mm),
        lim.flank_radius_max_mm + f * (lim.flank_radius_min_mm - lim.flank_radius_max_mm),
        lim.seating_angle_max_deg + f * (lim.seating_angle_min_deg - lim.seating_angle_max_deg),
    )


def tooth_gap(pitch_mm: float, roller_diameter_mm: float, teeth: int, form: float,
              tip_diameter_mm: float) -> iso606.ToothGap:
    """The groove (groove 0 on +x, grooves one pitch apart). Raises ToothFormError when the tip
    circle leaves no tip land or lies below the flank's start."""
    f = tooth_form(roller_diameter_mm, teeth, form)
    return iso606.tooth_gap(pitch_diameter(pitch_mm, teeth), teeth, f.seating_radius_mm, f.flank_radius_mm,
                            f.seating_angle_deg, tip_diameter_mm)


def tip_diameter_bounds(pitch_mm: float, roller_diameter_mm: float, teeth: int, form: float) -> tuple[float, float]:
    """The open range of tip diameters that leave a tooth: above the seating arcs' ends (the
    flank's start), below the diameter where adjacent flanks meet (no tip land)."""
    f = tooth_form(roller_diameter_mm, teeth, form)
    d = pitch_diameter(pitch_mm, teeth)
    half = math.radians(f.seating_angle_deg) / 2.0
    junction = (d / 2.0 - f.seating_radius_mm * math.cos(half), f.seating_radius_mm * math.sin(half))
    lo = 2.0 * math.hypot(*junction)
    hi = iso606.tip_land_limit_diameter(d, teeth, f.seating_radius_mm, f.flank_radius_mm, f.seating_angle_deg)
    return lo, hi
