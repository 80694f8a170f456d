"""`gearcheck new steering --module M --teeth Z`: a complete steering template by the paper's design
chain (numpy/scipy only). docs/steering.md, "A design of your own", gives the rules in words.

The chain, each step from the ones before it (any of its inputs may be given with ``--set``):

1. Basic profiles (α, addenda, dedenda, shift) as given, by default the paper's standard ones.
2. H = r + h: the pinion centre above the rack datum, with the rack's rolling line h at
   ``layout.RACK_ROOT_MODULES``·m + the rack dedendum above the datum.
3. Tooth indexing for the stroke: the first rack tooth n = ⌊target / τ⌋ pitches from the centred
   tooth (the paper's 60° = 7 pitches of 8.571°), G1 one tooth before it; where the chain has no
   solution with n it is tried with n + 1 (G2 then carries the drive past the target).
4. hS4 from ε = ``trim.min_contact_ratio`` (eqs 1–2 inverted), rounded up to 1 µm.
5. RS1: G1's conjugate contact ends at S1 at the target plus ``DRIVE_MARGIN_DEG`` (eq 17 solved),
   rounded up to 1 µm.
6. hS2 for the shortest stroke: the highest S2 for which S1 reaches S2 no later than S3 reaches S4
   (equal travel, eq 4, where it has a solution below the rack top; else the untrimmed top).
7. hS8 and hS6: the tangent constructions (the top from the drive corner under the tangent to the
   tip circle through it at the stop, eqs 8–16) and the check's own rule for the trimmed tops past
   the stop (:mod:`.ends`, which applies them where the rack really stands), the lower of the two
   less ``TOP_MARGIN_MODULES``·m, rounded down to 1 µm.

The result is checked against every rule of the template (:mod:`.params`) and the model's own
verdicts (continuous drive to the target, the rack stopping within the towing swing, no overlap in
the push model, the trimmed tops clear): a design that fails any of them is no design of the chain,
and the one line says which input and why.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, cast

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.geometry.rack_pinion_contact import whole_drive
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import ends, layout, push
from gearcheck.drafting import Draft, in_field_range, positive_number, teeth_numbers
from gearcheck.params import ParamError, validate
from gearcheck.params.bounds import fmt_range

# The basic profiles and design rules when --set gives none: the paper's (its α and ε rule, its
# 60° power-steering and 100° towing requirements; a standard 1 / 1.25 basic rack).
DEFAULTS: dict[str, float] = {
    "pinion.profile_shift": 0.0,
    "pinion.pressure_angle_deg": 25.0,
    "pinion.addendum_coefficient": 1.0,
    "pinion.dedendum_coefficient": 1.25,
    "rack.addendum_coefficient": 1.0,
    "rack.dedendum_coefficient": 1.25,
    "trim.min_contact_ratio": 1.2,
    "targets.continuous_drive_deg": 60.0,
    "towing.max_angle_deg": 100.0,
}
# Values the chain derives; given with --set, each is an input to the steps after it.
DERIVED = ("layout.centre_to_datum_mm", "rack.first_tooth", "rack.last_tooth", "pinion.sector_first_tooth",
           "pinion.sector_last_tooth", "trim.hS4_mm", "pinion.topped_radius_mm", "trim.hS2_mm", "trim.hS6_mm",
           "trim.hS8_mm")
# RS1 is solved for the target plus this (the mesh sweep measures the drive to within its contact
# tolerance, 0.014° on the paper's design: the target must hold beyond it).
DRIVE_MARGIN_DEG = 0.1
# hS6, hS8 stand this far (in modules) below the highest top the tip lands clear.
TOP_MARGIN_MODULES = 0.02
# Machining resolution of the written heights and radii (mm); each rounded the safe way.
RESOLUTION_MM = 0.001
MODULE_RANGE = (0.1, 50.0)
TEETH_RANGE = (10, 400)


@dataclass
class _Chain:
    """One design of the chain: the values and how each was found."""

    values: dict[str, Any]
    notes: dict[str, str]
    drive_deg: float = math.nan
    drive_event: str = ""


class NoDesign(Exception):
    """The chain has no design for these inputs: why (one clause), and the input that decides it
    (a template key of the derivation's inputs, or "--teeth")."""

    def __init__(self, why: str, field: str = "--teeth"):
        super().__init__(why)
        self.field = field


def _up(x: float) -> float:
    return math.ceil(x / RESOLUTION_MM - 1e-6) * RESOLUTION_MM


def _down(x: float) -> float:
    return math.floor(x / RESOLUTION_MM + 1e-6) * RESOLUTION_MM


def _r(x: float) -> float:
    """A written value: rounded to the resolution (a clean float for the TOML)."""
    return round(x, 6)


def _geometry(v: Mapping[str, Any]) -> RackPinionGeometry:
    return RackPinionGeometry(
        module_mm=v["pinion.module_mm"], teeth=v["pinion.teeth"],
        pressure_angle_rad=math.radians(v["pinion.pressure_angle_deg"]), profile_shift=v["pinion.profile_shift"],
        pinion_addendum_coefficient=v["pinion.addendum_coefficient"],
        pinion_dedendum_coefficient=v["pinion.dedendum_coefficient"],
        rack_addendum_coefficient=v["rack.addendum_coefficient"],
        rack_dedendum_coefficient=v["rack.dedendum_coefficient"], centre_to_datum_mm=v["layout.centre_to_datum_mm"],
        rack_first_tooth=v["rack.first_tooth"], rack_last_tooth=v["rack.last_tooth"],
        sector_first_tooth=v["pinion.sector_first_tooth"], sector_last_tooth=v["pinion.sector_last_tooth"],
        topped_radius_mm=v["pinion.topped_radius_mm"], hS2_mm=v["trim.hS2_mm"], hS4_mm=v["trim.hS4_mm"],
        hS6_mm=v["trim.hS6_mm"], hS8_mm=v["trim.hS8_mm"])


def _brentq(f, lo: float, hi: float) -> float:
    from scipy.optimize import brentq

    return float(brentq(f, lo, hi, xtol=1e-12))


def centre_height(m: float, z: int, shift: float, rack_dedendum: float) -> float:
    """H = r + h: the rolling line h lies x·m above the rack's reference line, which lies the rack
    dedendum above its root line, which lies ``layout.RACK_ROOT_MODULES``·m above the datum."""
    return m * z / 2.0 + (shift + rack_dedendum + layout.RACK_ROOT_MODULES) * m


def teeth_to_target(z: int, target_deg: float) -> int:
    """Whole pinion pitches from the centred rack tooth within the target angle, n = ⌊target / τ⌋."""
    return max(math.floor(target_deg * z / 360.0 + 1e-9), 2)


def contact_ratio_height(g: RackPinionGeometry, eps: float) -> float:
    """hS4 for ε (eqs 1–2 inverted), rounded up: ε at the written height is at least the rule."""
    return _up(an.trim_height_for_contact_ratio(g, eps))


def topped_radius_for_angle(g: RackPinionGeometry, angle_deg: float) -> float:
    """RS1 at which G1's conjugate contact ends at S1 at ``angle_deg`` (eq 17 solved), rounded up;
    NaN when no radius between the form circle and the tip circle does."""
    j = g.sector_first_tooth
    target = math.radians(angle_deg)

    def miss(radius: float) -> float:
        return an.phi_towing_conjugate_end(g, j, radius) - target

    lo, hi = g.form_radius + 1e-9, g.tip_radius
    if miss(hi) < 0:
        return math.nan
    if miss(lo) >= 0:
        return _up(lo)
    return min(_up(_brentq(miss, lo, hi)), g.tip_radius)


def shortest_stroke_height(g: RackPinionGeometry) -> tuple[float, str]:
    """hS2 for the shortest stroke, and how: the rack stops at L(S3/S4) at the least (eq 3); the
    highest S2 whose S1 reaches it no later than that keeps it there: equal travel (eq 4), rounded
    up so that G1 lets go of S2 last (as on the paper's machined design, µm later), or the rack top
    when S1 passes even the untrimmed corner earlier. NaN: S1 reaches S2 later at every height."""
    first = g.rack_first_tooth
    travel = an.travel_corner_on_circle(g, first + 1, g.hS4_mm, g.tip_radius)
    rs1 = g.topped_radius_mm
    top, h = g.rack_top_height, g.made_rolling_line_height

    def miss(height: float) -> float:
        return an.travel_corner_on_circle(g, first, height, rs1) - travel

    lo = max(h, g.centre_height - rs1) + 1e-9
    if lo >= top or miss(lo) > 0:
        return math.nan, (f"S1 on the RS1 = {rs1:g} mm circle reaches S2 after the S3/S4 travel "
                          f"{travel:.3f} mm at every height above the rolling line")
    if miss(top) <= 0:
        return top, f"untrimmed (rack top): S1 passes S2 before the rack stops at L(S3/S4) = {travel:.3f} mm"
    return min(_up(_brentq(miss, lo, top)), top), f"equal travel with S3/S4 (eq 4), L = {travel:.3f} mm"


def _chain(base: Mapping[str, Any], given: Mapping[str, Any], n: int) -> _Chain:
    """The chain with the first rack tooth n pitches from the centre (``given``: derived values set
    with --set, used in place of the chain's)."""
    v = dict(base)
    notes: dict[str, str] = {}
    _indexing(v, notes, given, n)
    g = _untrimmed(v, notes, given)
    g = _drive_trims(g, v, notes, given)
    _tops(g, v, notes, given)
    top = g.rack_top_height
    for key, bound in (("trim.hS2_mm", top), ("trim.hS4_mm", top), ("trim.hS6_mm", top), ("trim.hS8_mm", top),
                       ("pinion.topped_radius_mm", g.tip_radius)):
        # rounding never lifts a value past the rack top (the tip circle): an untrimmed top in floats
        # (21.464999999999996 mm) is written on the 1 µm grid below it, not rounded up to 21.465
        rounded = _r(v[key])
        if rounded > bound:
            rounded = _r(math.floor(bound / RESOLUTION_MM) * RESOLUTION_MM)
            notes[key] = f"{notes.get(key, '')}, on the {RESOLUTION_MM * 1000:g} µm grid below it"
        v[key] = rounded
    chain = _Chain(v, notes)
    _verify(chain)
    return chain


def _indexing(v: dict[str, Any], notes: dict[str, str], given: Mapping[str, Any], n: int) -> None:
    """Step 3: the rack and sector tooth indices for the stroke."""
    z, target = v["pinion.teeth"], v["targets.continuous_drive_deg"]
    tau = 360.0 / z
    first = int(given.get("rack.first_tooth", -n))
    v["rack.first_tooth"] = first
    how = ("as given" if "rack.first_tooth" in given else "⌊target/τ⌋" if -first == teeth_to_target(z, target)
           else "⌊target/τ⌋ + 1: G2 carries the drive past the target")
    notes["rack.first_tooth"] = f"k: {-first} pitches of {tau:.3f}° from the centred tooth, {-first * tau:.3f}° ({how})"
    v["rack.last_tooth"] = int(given.get("rack.last_tooth", -first))
    notes["rack.last_tooth"] = "mirror of the first tooth (both ends trimmed alike)"
    v["pinion.sector_first_tooth"] = int(given.get("pinion.sector_first_tooth", first - 1))
    notes["pinion.sector_first_tooth"] = "G1 = rack.first_tooth − 1 (drives the first rack tooth), topped to RS1"
    v["pinion.sector_last_tooth"] = int(given.get("pinion.sector_last_tooth", v["rack.last_tooth"]))
    notes["pinion.sector_last_tooth"] = "= rack.last_tooth (G1's mirror), topped to RS1"
    sector = v["pinion.sector_last_tooth"] - v["pinion.sector_first_tooth"] + 1
    if sector > z:
        raise NoDesign(f"the {sector}-tooth sector for a {target:g}° drive does not fit in z = {z}")


def _untrimmed(v: dict[str, Any], notes: dict[str, str], given: Mapping[str, Any]) -> RackPinionGeometry:
    """Step 2: H, and the drawing with every trim at the rack top and G1 untopped."""
    m, z = v["pinion.module_mm"], v["pinion.teeth"]
    r = m * z / 2.0
    if "layout.centre_to_datum_mm" in given:
        H = float(given["layout.centre_to_datum_mm"])
        notes["layout.centre_to_datum_mm"] = "H as given"
    else:
        H = centre_height(m, z, v["pinion.profile_shift"], v["rack.dedendum_coefficient"])
        notes["layout.centre_to_datum_mm"] = (
            f"H = r + h = {r:g} + {_r(H - r):g}: rolling line x·m + rack dedendum + "
            f"{layout.RACK_ROOT_MODULES:g}·m (rack root) above the datum")
    v["layout.centre_to_datum_mm"] = _r(H)
    probe = dict(v)
    probe.update({"pinion.topped_radius_mm": 1.0, "trim.hS2_mm": 0.0, "trim.hS4_mm": 0.0, "trim.hS6_mm": 0.0,
                  "trim.hS8_mm": 0.0})
    g = _geometry(probe)
    top = g.rack_top_height
    return an.with_inputs(g, topped_radius_mm=g.tip_radius, hS2_mm=top, hS4_mm=top, hS6_mm=top, hS8_mm=top)


def _given(given: Mapping[str, Any], notes: dict[str, str], key: str, note: str = "as given") -> float | None:
    """A derived value the user set with --set (noted as given), or None: derive it."""
    if key not in given:
        return None
    notes[key] = note
    return float(given[key])


def _given_in_drawing(g: RackPinionGeometry, given: Mapping[str, Any]) -> None:
    """Derived values set with --set lie where the chain's constructions exist (the template's
    rules, :mod:`.params`): a trim between the rolling line and the rack top, RS1 between the form
    circle and the tip circle. NoDesign names the value and that range."""
    h, top = g.made_rolling_line_height, g.rack_top_height
    for key in ("trim.hS2_mm", "trim.hS4_mm", "trim.hS6_mm", "trim.hS8_mm"):
        if key in given and not h < given[key] <= top:
            raise NoDesign(f"a trim lies above the rolling line, at most at the rack tooth top: allowed "
                           f"{fmt_range(h, top, lo_open=True)} mm", key)
    key = "pinion.topped_radius_mm"
    if key in given and not g.form_radius < given[key] <= g.tip_radius:
        raise NoDesign(f"RS1 lies above the form circle, at most at the tip radius: allowed "
                       f"{fmt_range(g.form_radius, g.tip_radius, lo_open=True)} mm", key)


def _drive_trims(g: RackPinionGeometry, v: dict[str, Any], notes: dict[str, str],
                 given: Mapping[str, Any]) -> RackPinionGeometry:
    """Steps 4–6: hS4 from ε, RS1 from the target, hS2 for the shortest stroke."""
    top, eps = g.rack_top_height, v["trim.min_contact_ratio"]
    _given_in_drawing(g, given)
    hs4 = _given(given, notes, "trim.hS4_mm")
    if hs4 is not None:
        notes["trim.hS4_mm"] = f"as given: ε = {an.contact_ratio(g, hs4):.4f}"
    else:
        hs4 = contact_ratio_height(g, eps)
        if hs4 > top:
            raise NoDesign(f"ε = {eps:g} needs hS4 = {hs4:.3f} mm, above the rack top {top:.3f} mm",
                           "trim.min_contact_ratio")
        notes["trim.hS4_mm"] = (f"ε = trim.min_contact_ratio = {eps:g} (eqs 1–2 inverted), rounded up: "
                                f"ε = {an.contact_ratio(g, hs4):.4f}")
    g = an.with_inputs(g, hS4_mm=hs4)
    rs1 = _given(given, notes, "pinion.topped_radius_mm", "RS1 as given")
    if rs1 is None:
        aim = v["targets.continuous_drive_deg"] + DRIVE_MARGIN_DEG
        rs1 = topped_radius_for_angle(g, aim)
        if math.isnan(rs1):
            raise NoDesign(f"G1 at the full tip radius {g.tip_radius:g} mm lets go of S1 before {aim:g}°",
                           "targets.continuous_drive_deg")
        notes["pinion.topped_radius_mm"] = (f"RS1: G1's contact reaches S1 at {aim:g}° (target + "
                                            f"{DRIVE_MARGIN_DEG:g}°, eq 17 solved), rounded up")
    g = an.with_inputs(g, topped_radius_mm=rs1)
    hs2 = _given(given, notes, "trim.hS2_mm")
    if hs2 is None:
        hs2, how = shortest_stroke_height(g)
        if math.isnan(hs2):
            raise NoDesign(how)
        notes["trim.hS2_mm"] = f"shortest stroke: {how}"
    if not g.centre_height - hs2 < rs1:
        raise NoDesign(f"G1's tip circle (RS1 = {rs1:g} mm) does not reach S2 at hS2 = {hs2:g} mm")
    v["trim.hS4_mm"], v["pinion.topped_radius_mm"], v["trim.hS2_mm"] = hs4, rs1, hs2
    return an.with_inputs(g, hS2_mm=hs2)


def _tops(g: RackPinionGeometry, v: dict[str, Any], notes: dict[str, str], given: Mapping[str, Any]) -> None:
    """Step 7: hS8 and hS6 under the tip lands that pass over them, less the margin."""
    first, top = g.rack_first_tooth, g.rack_top_height
    travel34 = an.travel_corner_on_circle(g, first + 1, g.hS4_mm, g.tip_radius)
    travel12 = an.travel_corner_on_circle(g, first, g.hS2_mm, g.topped_radius_mm)
    tangent8 = an.tangent_top_height(g, g.trim_corners(travel34)["S4"], first + 1, travel34)
    tangent6 = an.tangent_top_height(g, g.trim_corners(travel12)["S2"], first, travel12)
    tow = an.analyse_towing(g, v["towing.max_angle_deg"])
    if math.isnan(tow.disengage_rad):
        raise NoDesign(f"the rack is still moving at towing.max_angle_deg = {v['towing.max_angle_deg']:g}°",
                       "towing.max_angle_deg")
    rule = {e.field: e for e in ends.end_tops(g, tow)}
    margin = TOP_MARGIN_MODULES * g.module_mm
    for key, corner, tangent, circle in (("trim.hS8_mm", "S4", tangent8, "Ra"), ("trim.hS6_mm", "S2", tangent6, "RS1")):
        limit = rule[key].limit_mm
        if key in given:
            v[key] = float(given[key])
            notes[key] = f"as given (the tip lands clear up to {limit:.3f} mm)"
            continue
        if not math.isfinite(limit):
            raise NoDesign(f"no {key.split('.')[1][:3]} clears the tip land passing over it")
        bound = min(tangent, limit)
        if bound >= top:
            v[key] = top
            notes[key] = f"untrimmed (rack top): the {circle} tip land clears the whole top"
            continue
        value = _down(bound - margin)
        if not value > g.made_rolling_line_height:
            raise NoDesign(f"the tip land leaves no trimmed top above the rolling line at {corner}")
        v[key] = value
        notes[key] = (f"tangent to the {circle} circle at {corner} meets the flank at {tangent:.3f} mm, "
                      f"the tip land clears up to {limit:.3f} mm where the rack stands; less "
                      f"{TOP_MARGIN_MODULES:g}·m = {margin:.3f} mm")


def _verify(chain: _Chain) -> None:
    """The design against the template's rules and the model's verdicts (NoDesign naming the first
    that fails)."""
    from gearcheck.mechanisms.steering.params import Params

    written = Draft("steering", "verify")  # the values as the template will hold them
    for dotted, value in chain.values.items():
        written.set(dotted, value)
    sections = {k: v for k, v in written.data().items() if k not in ("mechanism", "name")}
    try:
        params = cast(Params, validate(Params, sections))  # field ranges and the model's rules, one line each
    except ParamError as exc:  # several: the first (ParamErrors carries its field, value and range)
        raise NoDesign(f"the derived {exc.field} = {exc.value} breaks a rule: {exc.allowed}") from None
    g = an.geometry_from_params(params)
    target = params.targets.continuous_drive_deg
    drive = min(whole_drive(g), key=lambda d: d.angle_rad)
    chain.drive_deg, chain.drive_event = math.degrees(drive.angle_rad), drive.event
    if chain.drive_deg < target:
        raise NoDesign(f"the continuous drive ends at {chain.drive_deg:.3f}° < target {target:g}° ({drive.event})",
                       "targets.continuous_drive_deg")
    eps = an.contact_ratio(g, g.hS4_mm)
    if eps < params.trim.min_contact_ratio:
        raise NoDesign(f"ε = {eps:.4f} at hS4 < trim.min_contact_ratio = {params.trim.min_contact_ratio:g}")
    tow = an.analyse_towing(g, params.towing.max_angle_deg)
    if math.isnan(tow.disengage_rad):
        raise NoDesign(f"the rack is still moving at towing.max_angle_deg = {params.towing.max_angle_deg:g}°",
                       "towing.max_angle_deg")
    overlap = max(tow.forward.max_overlap_mm, tow.back.max_overlap_mm)
    if overlap > push.TRAVEL_TOL_MM:
        raise NoDesign(f"the towing swings jam: teeth overlap by {overlap:.4f} mm in the push model")
    for e in ends.end_tops(g, tow):
        if not e.clears:
            raise NoDesign(f"{e.tooth}'s tip land cuts the trimmed top {e.corner}–{e.far} (limit {e.limit_mm:.3f} mm)")


def _number(values: Mapping[str, Any], key: str) -> float:
    """An input of the derivation set with --set: a number within its template field's range."""
    from gearcheck.mechanisms.steering.params import Params

    value = values[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParamError(key, value, "allowed a number (an input of the derivation)")
    return in_field_range(Params, key, float(value))


def new(inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
    """The steering template for ``inputs`` (module, teeth) by the chain above; ``overrides`` are its
    inputs where it uses them. Raises :class:`ParamError` naming the input when the chain has no
    design."""
    m = positive_number("module", inputs.get("module"), *MODULE_RANGE)
    (z,) = teeth_numbers(inputs.get("teeth"), 1, "pinion teeth")
    if not TEETH_RANGE[0] <= z <= TEETH_RANGE[1]:
        raise ParamError("--teeth", z, f"allowed {TEETH_RANGE[0]} to {TEETH_RANGE[1]} pinion teeth")
    base: dict[str, Any] = {"pinion.module_mm": m, "pinion.teeth": z}
    for key, default in DEFAULTS.items():
        base[key] = _number(overrides, key) if key in overrides else default
    given: dict[str, Any] = {}
    for key in DERIVED:
        if key in overrides:
            given[key] = _number(overrides, key)
    target = base["targets.continuous_drive_deg"]
    n = teeth_to_target(z, target)
    tries = [-int(given["rack.first_tooth"])] if "rack.first_tooth" in given else [n, n + 1]
    failures: list[NoDesign] = []
    chain = None
    for count in tries:
        try:
            chain = _chain(base, given, count)
            break
        except NoDesign as exc:
            failures.append(exc)
    if chain is None:
        raise _no_design(failures, tries, m, z, overrides)
    return _draft(chain, m, z)


def _no_design(failures: list[NoDesign], tries: list[int], m: float, z: int,
               overrides: Mapping[str, Any]) -> ParamError:
    """One line: the input that decides (a --set input of the derivation when the first failure
    names one the user gave, else --teeth) and why, for each indexing tried."""
    whys: list[str] = []
    for count, exc in zip(tries, failures, strict=True):
        text = f"{str(exc)} (first rack tooth {count} pitches out)"
        if str(exc) in [w.split(" (first rack tooth")[0] for w in whys]:
            continue
        whys.append(text)
    field = next((f.field for f in failures if f.field in overrides), failures[0].field)
    sets = [f"{k}={overrides[k]}" for k in overrides if k in DEFAULTS or k in DERIVED]
    with_sets = f" with --set {', '.join(sets)}" if sets else ""
    why = f"no design by the paper's chain at m = {m:g} mm, z = {z}{with_sets}: " + "; ".join(whys)
    if field != "--teeth" and field in overrides:
        return ParamError(f"--set {field}", overrides[field], why)
    return ParamError("--teeth", z, why)


SECTION_ORDER = {
    "pinion": ("module_mm", "teeth", "profile_shift", "pressure_angle_deg", "addendum_coefficient",
               "dedendum_coefficient", "sector_first_tooth", "sector_last_tooth", "topped_radius_mm"),
    "rack": ("first_tooth", "last_tooth", "addendum_coefficient", "dedendum_coefficient"),
    "layout": ("centre_to_datum_mm",),
    "trim": ("min_contact_ratio", "hS2_mm", "hS4_mm", "hS6_mm", "hS8_mm"),
    "targets": ("continuous_drive_deg",),
    "towing": ("max_angle_deg",),
}
INPUT_NOTES = {
    "pinion.module_mm": "m (--module)",
    "pinion.teeth": "z (--teeth): r = m·z/2",
    "pinion.profile_shift": "x",
    "pinion.pressure_angle_deg": "α",
    "pinion.addendum_coefficient": "tip radius r + (ha* + x)·m",
    "pinion.dedendum_coefficient": "generating rack cutter addendum (sharp tip)",
    "rack.addendum_coefficient": "rack top above its reference line, in modules",
    "rack.dedendum_coefficient": "rack root below its reference line, in modules",
    "trim.min_contact_ratio": "design rule that sets hS4",
    "targets.continuous_drive_deg": "power steering drives continuously to at least this angle",
    "towing.max_angle_deg": "towing swing either way",
}


def _draft(chain: _Chain, m: float, z: int) -> Draft:
    v, notes = chain.values, chain.notes
    d = Draft("steering", f"steering_m{m:g}_z{z}".replace(".", "p"), header=[
        f"Nose-wheel steering rack and pinion, m = {m:g} mm, z = {z}, by the paper's design chain "
        "(Meng Bin, Xu Hailiang and Wang Chunhe): written by `gearcheck new steering`, each derived value "
        "commented with how it was found; see docs/steering.md.",
        f"Model: continuous drive to {chain.drive_deg:.3f}° ({chain.drive_event}).",
    ])
    for section, keys in SECTION_ORDER.items():
        for key in keys:
            dotted = f"{section}.{key}"
            value = v[dotted]
            if isinstance(value, float) and value.is_integer() and key in ("teeth", "first_tooth", "last_tooth",
                                                                            "sector_first_tooth", "sector_last_tooth"):
                value = int(value)
            d.set(dotted, value, notes.get(dotted) or INPUT_NOTES.get(dotted, ""))
    return d
