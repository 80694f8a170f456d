"""Template model of the nose-wheel steering rack and pinion.

Only inputs: the pinion and rack basic profiles, the sector and rack tooth indices, the centre
height H, the machined trims (hS2…hS8, RS1), the contact-ratio design rule and the two angle
requirements. Everything the paper derives (r, Ra, h, p, s, L, hS4 from ε, …) is computed.
Cross-field rules raise :class:`ParamError` naming the field, its value and the allowed range, one
line for each independent rule broken (:class:`~gearcheck.params.common.Problems`; rules that need
earlier ones to hold come after them).
They include what the CAD needs (no pointed tooth or cutter tip, a rack root space, the pinion
bore inside the root circle: the same RackPinionGeometry properties and layout constants the CAD
builds from), so a set the CAD could not build is rejected before any CAD work. Whether the pinion's
tip lands clear the trimmed tops (hS6, hS8) is a design result, not a rule on the input: the check's
verdicts decide it where the rack really stands (:mod:`.ends`).
"""

from __future__ import annotations

import math
from typing import Any

from pydantic import Field, model_validator

from gearcheck.mechanisms.steering import analysis, layout
from gearcheck.params import ParamError, Section
from gearcheck.params.problems import Problems
from gearcheck.params.common import bisect_boundary, fmt_bound, fmt_range

MM: dict[str, Any] = {"unit": "mm"}
DEG: dict[str, Any] = {"unit": "deg"}
# A tooth whose top land is thinner than this (in modules) is taken as pointed (as for the
# differential's bevel gears); applies to the pinion tip and the rack tooth top.
MIN_TOP_LAND_MODULES = 0.25
ADDENDUM_MIN = 0.5  # least pinion addendum coefficient (field range)
TEETH_MAX = 400  # most pinion teeth (field range)
RACK_ADDENDUM_MIN, RACK_ADDENDUM_MAX = 0.5, 1.5  # rack addendum coefficient (field range)


class Pinion(Section):
    module_mm: float = Field(gt=0, le=50,
        description="Module m", json_schema_extra=MM)
    teeth: int = Field(ge=10, le=TEETH_MAX, description="Tooth count z of the full pinion (the sector is part of it)")
    profile_shift: float = Field(ge=-1.0, le=1.0, description="Profile shift coefficient x")
    pressure_angle_deg: float = Field(ge=10.0, le=35.0, description="Pressure angle α", json_schema_extra=DEG)
    addendum_coefficient: float = Field(ge=ADDENDUM_MIN, le=1.5,
        description="Addendum ha* (tip radius r + (ha* + x)·m)")
    dedendum_coefficient: float = Field(ge=0.5, le=2.0,
        description="Dedendum hf* = addendum of the generating rack cutter (sharp tip)")
    sector_first_tooth: int = Field(ge=-200, le=0,
        description="Index j of G1, the first sector tooth, topped to RS1 (angle-0 convention: tooth j centred at "
                    "(j + 1/2)·360°/z)")
    sector_last_tooth: int = Field(ge=0, le=200,
        description="Index j of the last sector tooth (G1's mirror), topped to RS1")
    topped_radius_mm: float = Field(gt=0, le=5000,
        description="RS1: tip radius of the two topped end teeth, as machined", json_schema_extra=MM)


class Rack(Section):
    first_tooth: int = Field(ge=-200, le=-2,
        description="Index k of the first rack tooth (trimmed at S2/S6); tooth k is centred at k·p at angle 0")
    last_tooth: int = Field(ge=2, le=200, description="Index k of the last rack tooth (mirror trims)")
    addendum_coefficient: float = Field(ge=RACK_ADDENDUM_MIN, le=RACK_ADDENDUM_MAX,
        description="Rack addendum above its reference line, in modules")
    dedendum_coefficient: float = Field(ge=0.5, le=2.0,
        description="Rack dedendum below its reference line, in modules")


class Layout(Section):
    centre_to_datum_mm: float = Field(gt=0, le=10000,
        description="H: pinion centre to the rack datum (mounting face)", json_schema_extra=MM)


class Trim(Section):
    min_contact_ratio: float = Field(ge=1.0, le=3.0,
        description="Design rule that sets hS4: solved, never checked against the machined heights")
    hS2_mm: float = Field(gt=0, le=10000,
        description="Height of S2 above the datum (first rack tooth, drive-side top corner), as machined",
        json_schema_extra=MM)
    hS4_mm: float = Field(gt=0, le=10000,
        description="Height of S4 (second rack tooth, drive-side top corner), as machined", json_schema_extra=MM)
    hS6_mm: float = Field(gt=0, le=10000,
        description="Height of S6 (first rack tooth, other top corner), as machined", json_schema_extra=MM)
    hS8_mm: float = Field(gt=0, le=10000,
        description="Height of S8 (second rack tooth, other top corner), as machined", json_schema_extra=MM)


class Targets(Section):
    renamed = {"continuous_angle_deg": "continuous_drive_deg"}

    continuous_drive_deg: float = Field(gt=0, lt=180,
        description="Power-steering requirement: continuous drive to at least this pinion angle", json_schema_extra=DEG)


class Towing(Section):
    max_angle_deg: float = Field(gt=0, le=180,
        description="Towing swing of the pinion (either way)", json_schema_extra=DEG)


class Params(Section):
    pinion: Pinion
    rack: Rack
    layout: Layout
    trim: Trim
    targets: Targets
    towing: Towing

    @model_validator(mode="after")
    def _physical(self) -> Params:
        _check(self)
        return self


def _check_indexing(p: Params) -> None:
    """Tooth indexing: G1 sits left of the first rack tooth and drives it (paper fig. 5). The three
    pairings are independent (each broken one is named); the sector's size needs them to hold."""
    pin, rack, z = p.pinion, p.rack, p.pinion.teeth
    with Problems() as found:
        if rack.last_tooth != -rack.first_tooth:
            found.add("rack.last_tooth", rack.last_tooth,
                      f"must mirror rack.first_tooth: allowed {-rack.first_tooth} (the trims repeat at both ends)")
        if pin.sector_first_tooth != rack.first_tooth - 1:
            found.add("pinion.sector_first_tooth", pin.sector_first_tooth,
                      f"allowed {rack.first_tooth - 1} = rack.first_tooth - 1 "
                      "(the topped tooth G1 drives the first rack tooth)")
        if pin.sector_last_tooth != rack.last_tooth:
            found.add("pinion.sector_last_tooth", pin.sector_last_tooth,
                      f"allowed {rack.last_tooth} = rack.last_tooth (mirror of G1)")
    sector = pin.sector_last_tooth - pin.sector_first_tooth + 1
    if sector > z:
        raise ParamError("pinion.teeth", z, f"allowed >= {sector} (the {sector}-tooth sector is part of the pinion)")


def _check(p: Params) -> None:
    _check_indexing(p)
    pin, rack, trim = p.pinion, p.rack, p.trim
    m, z, x = pin.module_mm, pin.teeth, pin.profile_shift
    a = math.radians(pin.pressure_angle_deg)
    r = m * z / 2.0
    rb = r * math.cos(a)
    tip = r + (pin.addendum_coefficient + x) * m
    H = p.layout.centre_to_datum_mm

    # Basic profiles: clearances, no undercut, no pointed teeth, the rack root above its datum:
    # independent rules, every one broken is named.
    # (The shift moves the rack's reference line with the pinion, so it cancels in both.)
    found = Problems()
    if rack.dedendum_coefficient <= pin.addendum_coefficient:
        found.add("rack.dedendum_coefficient", rack.dedendum_coefficient,
                  f"allowed > {fmt_bound(pin.addendum_coefficient, 'lower', None)} "
                  "(pinion addendum: the pinion tip must clear the rack root)")
    if pin.dedendum_coefficient <= rack.addendum_coefficient:
        found.add("pinion.dedendum_coefficient", pin.dedendum_coefficient,
                  f"allowed > {fmt_bound(rack.addendum_coefficient, 'lower', None)} "
                  "(rack addendum: the rack tip must clear the pinion root)")
    depth = (pin.dedendum_coefficient - x) * m
    if depth > r * math.sin(a) ** 2:
        found.extend(_undercut_error(p, depth, a))
    found.check()  # the tooth forms below are drawn from these profiles
    g = analysis.geometry_from_params(p)
    _check_tooth_forms(g, found)
    rack_root = H - r - x * m - rack.dedendum_coefficient * m
    if rack_root <= 0:
        def root_above(v: float) -> bool:
            return v - r - x * m - rack.dedendum_coefficient * m > 0

        h_min = fmt_bound(r + x * m + rack.dedendum_coefficient * m, "lower", ok=root_above, strict=True)
        found.add("layout.centre_to_datum_mm", H, f"allowed > {h_min} mm (the rack root must lie above its datum)")
    found.check()

    # Trims: between the rolling line and the rack tooth top; hS4 must keep the contact ratio >= 1.
    h = H - r
    top = H - r - x * m + rack.addendum_coefficient * m
    recess = math.sqrt(tip * tip - rb * rb) - r * math.sin(a)
    base_pitch = math.pi * m * math.cos(a)

    def h_for_ratio(eps: float) -> float:
        return h + math.sin(a) * (eps * base_pitch - recess)

    def untrimmed_ratio(rack_addendum: float) -> float:  # ε with the rack top at this addendum
        return ((H - r - x * m + rack_addendum * m - h) / math.sin(a) + recess) / base_pitch

    eps_top = untrimmed_ratio(rack.addendum_coefficient)
    if eps_top < 1.0:
        raise _untrimmed_ratio_error(g, eps_top, untrimmed_ratio)
    if not top > h:
        raise ParamError("rack.addendum_coefficient", rack.addendum_coefficient,
                         f"allowed > {fmt_bound(x, 'lower', None)} (pinion.profile_shift): the rack tooth top "
                         f"({top:.3f} mm) must lie above the rolling line ({h:.3f} mm), where the trims hS2–hS8 lie")
    rs1 = pin.topped_radius_mm
    rs1_lo = max(H - trim.hS2_mm, _form_radius(r, rb, a, depth))
    # the four trims and the contact-ratio rule are independent: every one broken is named
    _check_trim_ranges(g, h, top, max(h, h_for_ratio(1.0)), found)
    if trim.min_contact_ratio > eps_top:
        found.add("trim.min_contact_ratio", trim.min_contact_ratio,
                  f"allowed 1 to {fmt_bound(eps_top, 'upper')} (the untrimmed rack's contact ratio)")
    hs2_ok = not any(e.field == "trim.hS2_mm" for e in found.errors)

    # RS1: G1's tip circle must reach down to S2 (it is the last corner that drags the rack),
    # and topping only removes material (its lower end needs hS2 in range).
    if hs2_ok and not (rs1_lo < rs1 <= tip):
        found.add("pinion.topped_radius_mm", rs1,
                  f"allowed {fmt_range(rs1_lo, tip, lo_open=True)} mm "
                  "(G1's tip circle must reach S2 at height hS2; at most the tip radius)")
    found.check()


def _undercut_error(p: Params, depth: float, a: float) -> ParamError:
    """Pinion undercut: the least count with no undercut (in the rule's own arithmetic) whose
    root circle also clears the bore (the later rule on the same field)."""
    pin = p.pinion
    m, z = pin.module_mm, pin.teeth
    drawing = analysis.geometry_from_params(p)

    def teeth_ok(n: int) -> bool:
        return (depth <= m * n / 2.0 * math.sin(a) ** 2
                and layout.bore_fits(analysis.with_inputs(drawing, teeth=n).root_radius))

    z_min = max(math.ceil(2.0 * (pin.dedendum_coefficient - pin.profile_shift) / math.sin(a) ** 2), z + 1)
    z_ok = next((n for n in range(z_min, TEETH_MAX + 1) if teeth_ok(n)), None)
    bound = f"allowed >= {z_ok}" if z_ok is not None else f"no count allowed up to {TEETH_MAX}"
    return ParamError("pinion.teeth", z,
                      f"undercut by the generating rack at this shift and dedendum: {bound} (with the root "
                      f"circle clear of the {layout.PINION_BORE_DIAMETER_MM:g} mm bore)")


def _untrimmed_ratio_error(g, eps_top: float, untrimmed_ratio) -> ParamError:
    """Contact ratio 1 needs the rack top at h1: the rack addendum sets the top, and a higher
    top must still leave the rack tooth a top land (both inside the field's range)."""
    m = g.module_mm
    ha_min = max((analysis.trim_height_for_contact_ratio(g, 1.0) - g.rack_reference_height) / m, RACK_ADDENDUM_MIN)
    ha_max = min(_rack_addendum_max(g), RACK_ADDENDUM_MAX)
    why = f"the untrimmed rack's contact ratio is {eps_top:.3f} < 1 (a tooth pair lets go before the next engages)"
    if ha_min > ha_max:
        return ParamError("rack.addendum_coefficient", g.rack_addendum_coefficient,
                          f"no value allowed: {why}; contact ratio 1 needs >= {fmt_bound(ha_min, 'lower')}, a "
                          f"{MIN_TOP_LAND_MODULES}·m top land <= {fmt_bound(ha_max, 'upper')} (raise "
                          "pinion.addendum_coefficient or lower pinion.pressure_angle_deg)")
    ha_range = fmt_range(ha_min, ha_max, lo_ok=lambda v: untrimmed_ratio(v) >= 1.0,
                         hi_ok=lambda v: _rack_top_land_ok(g, v))
    return ParamError("rack.addendum_coefficient", g.rack_addendum_coefficient, f"allowed {ha_range}: {why}")


def _check_trim_ranges(g, h: float, top: float, hs4_min: float, found: Problems) -> None:
    """Each trim height between the rolling line h (hS4: where the contact ratio reaches 1) and
    the rack tooth top: a corner outside that band is no trim of this rack tooth. How high S6 and
    S8 may stand under the tip lands that pass over them depends on where the rack stops, so it is
    a verdict of the check (:mod:`.ends`), not a rule here."""
    for name in ("hS2_mm", "hS4_mm", "hS6_mm", "hS8_mm"):
        value = getattr(g, name)
        lo = hs4_min if name == "hS4_mm" else h
        why = ("contact ratio >= 1 up to the rack tooth top" if name == "hS4_mm"
               else "above the rack pitch line, at most the rack tooth top")
        if not (lo < value <= top):
            found.add(f"trim.{name}", value, f"allowed {fmt_range(lo, top, lo_open=True)} mm ({why})")


def _check_tooth_forms(g, found: Problems) -> None:
    """Teeth the CAD can build: pinion tip land and rack top land >= MIN_TOP_LAND_MODULES·m, a
    root land between the pinion's fillets (the generating cutter's tip is not pointed), a root
    space between adjacent rack teeth, and the pinion bore inside the root circle: each a rule on its own
    feature, every one broken added to ``found``."""
    m, x = g.module_mm, g.profile_shift
    tan_a = math.tan(g.pressure_angle_rad)
    land_min = MIN_TOP_LAND_MODULES * m

    def pinion_tip_land(geo) -> float:
        return 2.0 * geo.tip_radius * float(geo.involute_half_angle(geo.tip_radius))

    if pinion_tip_land(g) < land_min:
        lo = ADDENDUM_MIN
        if pinion_tip_land(analysis.with_inputs(g, pinion_addendum_coefficient=lo)) < land_min:
            def shift_ok(v: float) -> bool:
                return pinion_tip_land(analysis.with_inputs(g, profile_shift=v)) >= land_min

            x_max = bisect_boundary(shift_ok, -1.0, x, steps=60)
            bound = (f"allowed <= {fmt_bound(x_max, 'upper', ok=shift_ok)}" if x_max is not None
                     else "no shift allowed down to -1 at this addendum")
            found.add("pinion.profile_shift", x,
                      f"{bound}: pointed pinion teeth, tip land "
                      f"{pinion_tip_land(g):.3f} mm < {MIN_TOP_LAND_MODULES}·m = {land_min:.3f} mm")
        else:
            def addendum_ok(v: float) -> bool:
                return pinion_tip_land(analysis.with_inputs(g, pinion_addendum_coefficient=v)) >= land_min

            ha_max = _boundary(addendum_ok, lo, g.pinion_addendum_coefficient)
            found.add("pinion.addendum_coefficient", g.pinion_addendum_coefficient,
                      f"allowed <= {fmt_bound(ha_max, 'upper', ok=addendum_ok)} at this shift: pointed pinion "
                      "teeth, tip land "
                      f"{pinion_tip_land(g):.3f} mm < {MIN_TOP_LAND_MODULES}·m = {land_min:.3f} mm")
    w0 = g.rack_half_thickness_at_rolling_line
    if g.cutter_tip_half_width <= 0.0:
        def cutter_ok(v: float) -> bool:
            return analysis.with_inputs(g, pinion_dedendum_coefficient=v).cutter_tip_half_width > 0.0

        hf_max = fmt_bound(x + w0 / (m * tan_a), "upper", ok=cutter_ok, strict=True)
        found.add("pinion.dedendum_coefficient", g.pinion_dedendum_coefficient,
                  f"allowed < {hf_max} at this shift and pressure angle: the generating "
                  "rack's tip comes to a point, leaving no root land between the pinion's fillets")
    rack_top_land = _rack_top_land(g)
    if rack_top_land < land_min:
        rack_ha_max = fmt_bound(_rack_addendum_max(g), "upper", ok=lambda v: _rack_top_land_ok(g, v))
        found.add("rack.addendum_coefficient", g.rack_addendum_coefficient,
                  f"allowed <= {rack_ha_max}: pointed rack teeth, top land "
                  f"{rack_top_land:.3f} mm < {MIN_TOP_LAND_MODULES}·m = {land_min:.3f} mm")
    def root_space_ok(v: float) -> bool:
        at = analysis.with_inputs(g, rack_dedendum_coefficient=v)
        return 2.0 * float(at.rack_half_width(at.rack_root_height)) < at.pitch

    if not root_space_ok(g.rack_dedendum_coefficient):
        hf_max = fmt_bound((g.pitch / 2.0 - w0) / (m * tan_a) - x, "upper", ok=root_space_ok, strict=True)
        found.add("rack.dedendum_coefficient", g.rack_dedendum_coefficient,
                  f"allowed < {hf_max}: adjacent rack teeth would "
                  "meet above the rack root line (no tooth space left)")
    if not layout.bore_fits(g.root_radius):
        z_min = next((n for n in range(g.teeth + 1, TEETH_MAX + 1)
                      if layout.bore_fits(analysis.with_inputs(g, teeth=n).root_radius)), None)
        if z_min is None:
            def module_ok(v: float) -> bool:
                return layout.bore_fits(analysis.with_inputs(g, module_mm=v).root_radius)

            m_min = _boundary(module_ok, 50.0, m)
            found.add("pinion.module_mm", m,
                      f"allowed >= {fmt_bound(m_min, 'lower', ok=module_ok)} mm at z = {g.teeth}: the root "
                      "circle "
                      f"(radius {g.root_radius:.2f} mm) "
                      f"must clear the {layout.PINION_BORE_DIAMETER_MM:g} mm pinion bore")
        else:
            found.add("pinion.teeth", g.teeth,
                      f"allowed >= {z_min} at m = {m:g} mm: the root circle (radius {g.root_radius:.2f} mm) must "
                      f"clear the {layout.PINION_BORE_DIAMETER_MM:g} mm pinion bore")


def _rack_top_land(g) -> float:
    return 2.0 * float(g.rack_half_width(g.rack_top_height))


def _rack_top_land_ok(g, rack_addendum: float) -> bool:
    """The rack top land rule of :func:`_check_tooth_forms` at this rack addendum."""
    return _rack_top_land(analysis.with_inputs(g, rack_addendum_coefficient=rack_addendum)) >= \
        MIN_TOP_LAND_MODULES * g.module_mm


def _rack_addendum_max(g) -> float:
    """Largest rack addendum coefficient that leaves the rack a 0.25·m top land."""
    land_min = MIN_TOP_LAND_MODULES * g.module_mm
    return g.profile_shift + (g.rack_half_thickness_at_rolling_line - land_min / 2.0) / \
        (g.module_mm * math.tan(g.pressure_angle_rad))


def _boundary(ok, good: float, bad: float) -> float:
    """:func:`bisect_boundary`, or ``good`` when there is no boundary in the bracket."""
    found = bisect_boundary(ok, good, bad, steps=60)
    return good if found is None else found


def _form_radius(r: float, rb: float, a: float, depth: float) -> float:
    return math.hypot(rb, max(r * math.sin(a) - depth / math.sin(a), 0.0))
