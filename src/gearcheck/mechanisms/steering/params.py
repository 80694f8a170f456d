"""Template model of the nose-wheel steering rack and pinion (seed 003).

Only inputs: the pinion and rack basic profiles, the sector and rack tooth indices, the centre
height H, the machined trims (hS2…hS8, RS1), the contact-ratio design rule and the two angle
requirements. Everything the paper derives (r, Ra, h, p, s, L, hS4 from ε, …) is computed.
Cross-field rules raise :class:`ParamError` naming one field, its value and the allowed range.
"""

from __future__ import annotations

import math

from pydantic import Field, model_validator

from gearcheck.params import ParamError, Section

MM = {"unit": "mm"}
DEG = {"unit": "deg"}


class Pinion(Section):
    module_mm: float = Field(gt=0, le=50, description="Module m (paper: 4; see docs/steering.md for why not 5)", json_schema_extra=MM)
    teeth: int = Field(ge=10, le=400, description="Tooth count z of the full pinion (the sector is part of it)")
    profile_shift: float = Field(ge=-1.0, le=1.0, description="Profile shift coefficient x")
    pressure_angle_deg: float = Field(ge=10.0, le=35.0, description="Pressure angle α", json_schema_extra=DEG)
    addendum_coefficient: float = Field(ge=0.5, le=1.5, description="Addendum ha* (tip radius r + (ha* + x)·m)")
    dedendum_coefficient: float = Field(ge=0.5, le=2.0, description="Dedendum hf* = addendum of the generating rack cutter (sharp tip)")
    sector_first_tooth: int = Field(ge=-200, le=0, description="Index j of G1, the first sector tooth, topped to RS1 (angle-0 convention: tooth j centred at (j + 1/2)·360°/z)")
    sector_last_tooth: int = Field(ge=0, le=200, description="Index j of the last sector tooth (G1's mirror), topped to RS1")
    topped_radius_mm: float = Field(gt=0, le=5000, description="RS1: tip radius of the two topped end teeth, as machined", json_schema_extra=MM)


class Rack(Section):
    first_tooth: int = Field(ge=-200, le=-2, description="Index k of the first rack tooth (trimmed at S2/S6); tooth k is centred at k·p at angle 0")
    last_tooth: int = Field(ge=2, le=200, description="Index k of the last rack tooth (mirror trims)")
    addendum_coefficient: float = Field(ge=0.5, le=1.5, description="Rack addendum above its reference line, in modules")
    dedendum_coefficient: float = Field(ge=0.5, le=2.0, description="Rack dedendum below its reference line, in modules")


class Layout(Section):
    centre_to_datum_mm: float = Field(gt=0, le=10000, description="H: pinion centre to the rack datum (mounting face)", json_schema_extra=MM)


class Trim(Section):
    min_contact_ratio: float = Field(ge=1.0, le=3.0, description="Design rule that sets hS4 (paper: 1.2); solved, never checked against the machined heights")
    hS2_mm: float = Field(gt=0, le=10000, description="Height of S2 above the datum (first rack tooth, drive-side top corner), as machined", json_schema_extra=MM)
    hS4_mm: float = Field(gt=0, le=10000, description="Height of S4 (second rack tooth, drive-side top corner), as machined", json_schema_extra=MM)
    hS6_mm: float = Field(gt=0, le=10000, description="Height of S6 (first rack tooth, other top corner), as machined", json_schema_extra=MM)
    hS8_mm: float = Field(gt=0, le=10000, description="Height of S8 (second rack tooth, other top corner), as machined", json_schema_extra=MM)


class Targets(Section):
    continuous_angle_deg: float = Field(gt=0, lt=180, description="Power-steering requirement: continuous drive to at least this pinion angle", json_schema_extra=DEG)


class Towing(Section):
    max_angle_deg: float = Field(gt=0, le=180, description="Towing swing of the pinion (either way)", json_schema_extra=DEG)


class Params(Section):
    pinion: Pinion
    rack: Rack
    layout: Layout
    trim: Trim
    targets: Targets
    towing: Towing

    @model_validator(mode="after")
    def _physical(self) -> "Params":
        _check(self)
        return self


def _check(p: Params) -> None:
    pin, rack, trim = p.pinion, p.rack, p.trim
    m, z, x = pin.module_mm, pin.teeth, pin.profile_shift
    a = math.radians(pin.pressure_angle_deg)
    r = m * z / 2.0
    rb = r * math.cos(a)
    tip = r + (pin.addendum_coefficient + x) * m
    H = p.layout.centre_to_datum_mm

    # Tooth indexing: G1 sits left of the first rack tooth and drives it (paper fig. 5).
    if rack.last_tooth != -rack.first_tooth:
        raise ParamError("rack.last_tooth", rack.last_tooth, f"must mirror rack.first_tooth: allowed {-rack.first_tooth} (the trims repeat at both ends)")
    if pin.sector_first_tooth != rack.first_tooth - 1:
        raise ParamError("pinion.sector_first_tooth", pin.sector_first_tooth,
                         f"allowed {rack.first_tooth - 1} = rack.first_tooth - 1 (the topped tooth G1 drives the first rack tooth)")
    if pin.sector_last_tooth != rack.last_tooth:
        raise ParamError("pinion.sector_last_tooth", pin.sector_last_tooth,
                         f"allowed {rack.last_tooth} = rack.last_tooth (mirror of G1)")
    sector = pin.sector_last_tooth - pin.sector_first_tooth + 1
    if sector > z:
        raise ParamError("pinion.teeth", z, f"allowed >= {sector} (the {sector}-tooth sector is part of the pinion)")

    # Basic profiles: clearances, no undercut, no pointed teeth.
    # (The shift moves the rack's reference line with the pinion, so it cancels in both.)
    if rack.dedendum_coefficient <= pin.addendum_coefficient:
        raise ParamError("rack.dedendum_coefficient", rack.dedendum_coefficient,
                         f"allowed > {pin.addendum_coefficient:g} (pinion addendum: the pinion tip must clear the rack root)")
    if pin.dedendum_coefficient <= rack.addendum_coefficient:
        raise ParamError("pinion.dedendum_coefficient", pin.dedendum_coefficient,
                         f"allowed > {rack.addendum_coefficient:g} (rack addendum: the rack tip must clear the pinion root)")
    depth = (pin.dedendum_coefficient - x) * m
    if depth > r * math.sin(a) ** 2:
        z_min = 2.0 * (pin.dedendum_coefficient - x) / math.sin(a) ** 2
        raise ParamError("pinion.teeth", z, f"undercut by the generating rack at this shift and dedendum: allowed >= {math.ceil(z_min)}")
    half_pitch_angle = (math.pi / 2 + 2 * x * math.tan(a)) / z
    alpha_tip = math.acos(rb / tip)
    if half_pitch_angle + _inv(a) - _inv(alpha_tip) <= 0:
        raise ParamError("pinion.addendum_coefficient", pin.addendum_coefficient, "pointed pinion teeth at this shift: lower the addendum or the shift")
    rack_root = H - r - x * m - rack.dedendum_coefficient * m
    if rack_root <= 0:
        raise ParamError("layout.centre_to_datum_mm", H,
                         f"allowed > {r + x * m + rack.dedendum_coefficient * m:g} mm (the rack root must lie above its datum)")

    # Trims: between the rolling line and the rack tooth top; hS4 must keep the contact ratio >= 1.
    h = H - r
    top = H - r - x * m + rack.addendum_coefficient * m
    recess = math.sqrt(tip * tip - rb * rb) - r * math.sin(a)
    base_pitch = math.pi * m * math.cos(a)

    def h_for_ratio(eps: float) -> float:
        return h + math.sin(a) * (eps * base_pitch - recess)

    for name in ("hS2_mm", "hS4_mm", "hS6_mm", "hS8_mm"):
        value = getattr(trim, name)
        lo = max(h, h_for_ratio(1.0)) if name == "hS4_mm" else h
        why = "contact ratio >= 1 up to the rack tooth top" if name == "hS4_mm" else "above the rack pitch line, at most the rack tooth top"
        if not (lo < value <= top):
            raise ParamError(f"trim.{name}", value, f"allowed >{lo:.3f} to {top:.3f} mm ({why})")
    eps_top = ((top - h) / math.sin(a) + recess) / base_pitch
    if trim.min_contact_ratio > eps_top:
        raise ParamError("trim.min_contact_ratio", trim.min_contact_ratio,
                         f"allowed 1 to {eps_top:.3f} (the untrimmed rack's contact ratio)")

    # RS1: G1's tip circle must reach down to S2 (it is the last corner that drags the rack),
    # and topping only removes material.
    rs1 = pin.topped_radius_mm
    rs1_lo = max(H - trim.hS2_mm, _form_radius(r, rb, a, depth))
    if not (rs1_lo < rs1 <= tip):
        raise ParamError("pinion.topped_radius_mm", rs1,
                         f"allowed >{rs1_lo:.3f} to {tip:.3f} mm (G1's tip circle must reach S2 at height hS2; at most the tip radius)")


def _inv(a: float) -> float:
    return math.tan(a) - a


def _form_radius(r: float, rb: float, a: float, depth: float) -> float:
    return math.hypot(rb, max(r * math.sin(a) - depth / math.sin(a), 0.0))
