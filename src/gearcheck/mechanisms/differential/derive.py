"""``gearcheck new differential --module M --teeth SMALL/BIG``: a complete template from the module
and the two tooth counts, every other value derived (numpy only; docs/differential.md, "A design
of your own").

The derivation, in order (each written with a note saying how it was found):

- **Tooth form.** Standard 20° straight bevel gears on 90° shafts (``--set`` overrides α); the
  small gear's profile shift by Gleason's long-addendum rule (:func:`analysis.virtual_mesh`),
  rounded to 0.01 and kept inside the shifts that avoid undercut, tip interference, pointed tips and
  a contact ratio below 1 (:func:`params.shift_bounds`).
- **Face width.** The bevel-gear limits: at most a third of the outer cone distance Re and at most
  ten modules, rounded down (to 1 mm from 5 mm up, else to 0.1 mm).
- **Lengths.** The shaft from its mounting face to the gear joint grows with the gear set
  (l11 = :data:`L11_PER_CONE_DISTANCE`·Re); the big gear body behind its outer pitch circle and the
  small gear behind its own grow with the tooth depth (l12 = :data:`L12_PER_MODULE`·m, l2 =
  :data:`L2_PER_MODULE`·m); rounded to 0.5 mm. These are the shipped reconstruction's proportions.
  The housing lengths then follow from the common apex: b/2 = l11 + l12 + d2/2, a/2 = l2 + d1/2
  (an override of l11, l12 or l2 moves them; an override of a or b moves l2 or l11 instead).
- **Materials and temperatures.** Not dimensions: the paper's unit's (the shipped template's
  [materials] and [operating]), so the design is checked in the same environment.
- **Backlash.** The designed warm backlash per mesh is the standard minimum backlash
  (:func:`standard_backlash_mm`, ISO/TR 10064-2's jbn,min = ⅔·(0.06 + 0.0005·a + 0.03·m) mm with
  the outer cone distance for a, turned circumferential on the outer pitch circle by 1/cos α). The
  paper's rule sets the shim: its backlash gain (eq 11) must cover the cold drop to the cold design
  point (eq 10), the least multiple of :data:`SHIM_STEP_MM` that does; the tooth thinning is the
  rest of the allowance (at least :data:`MIN_THINNING_SHARE` of it), its band
  :data:`THINNING_BAND_SHARE` of the allowance wide. No [calibration]: that is a measurement of a
  built unit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import annotated_types as at

from gearcheck.drafting import Draft, positive_number, teeth_numbers
from gearcheck.mechanisms.differential import analysis
from gearcheck.mechanisms.differential import params as P
from gearcheck.mechanisms.differential.paper import shipped_template
from gearcheck.params.problems import ParamErrors
from gearcheck.params.common import ParamError, bisect_boundary, fmt_bound, validate

STANDARD_PRESSURE_ANGLE_DEG = 20.0
MAX_FACE_WIDTH_MODULES = 10.0  # the other bevel-gear face width limit beside Re/3
L11_PER_CONE_DISTANCE = 0.28  # shaft, mounting face → gear joint
L12_PER_MODULE = 2.4  # big gear body, joint → outer pitch circle plane
L2_PER_MODULE = 2.0  # small gear, mounting face → outer pitch circle plane
LENGTH_STEP_MM = 0.5
SHIM_STEP_MM = 0.05  # the paper's shim test steps by 0.05 mm
MIN_THINNING_SHARE = 0.25  # of the backlash allowance, kept in the teeth whatever the shim gives
THINNING_BAND_SHARE = 0.125  # width of the thinning's tolerance band, as a share of the allowance
MODULE_RANGE = (0.5, 10.0)  # gears.module_mm's field range
SECTION_ORDER = ("gears", "backlash", "materials", "dimensions", "operating", "shim")
# the fields `new` takes from its inputs: a rule they break at these numbers is the input's
_INPUT_FIELDS = {"gears.module_mm": "--module", "gears.big_teeth": "--teeth", "gears.small_teeth": "--teeth"}


def standard_backlash_mm(module_mm: float, cone_distance_mm: float) -> float:
    """Least normal backlash of a mesh (mm), ISO/TR 10064-2 (as AGMA 2002):
    jbn,min = ⅔·(0.06 + 0.0005·a + 0.03·m), with the outer cone distance for a bevel pair's a."""
    return 2.0 / 3.0 * (0.06 + 0.0005 * cone_distance_mm + 0.03 * module_mm)


def _limits(dotted: str) -> tuple[float, float] | None:
    """A field's own range (Field ge/gt, le/lt) from the template model; None for no such field."""
    section, _, key = dotted.partition(".")
    info = P.Params.model_fields.get(section)
    fields = getattr(info.annotation, "model_fields", {}) if info is not None else {}
    if key not in fields:
        return None
    lo, hi = -math.inf, math.inf
    for meta in fields[key].metadata:
        if isinstance(meta, (at.Ge, at.Gt)):
            lo = float(meta.ge if isinstance(meta, at.Ge) else meta.gt)  # type: ignore[arg-type]
        elif isinstance(meta, (at.Le, at.Lt)):
            hi = float(meta.le if isinstance(meta, at.Le) else meta.lt)  # type: ignore[arg-type]
    return lo, hi


def _given(overrides: Mapping[str, Any], dotted: str) -> float | None:
    """An override the derivation can use: a finite number in its field's range (else None: the
    template's validation names it, as written)."""
    value = overrides.get(dotted)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        return None
    limits = _limits(dotted)
    return float(value) if limits is not None and limits[0] <= value <= limits[1] else None


def _note(overrides: Mapping[str, Any], dotted: str, derived: str) -> str:
    """The note of a value the derivation took from ``--set`` (when it could use it), else its own."""
    return "set with --set" if _given(overrides, dotted) is not None else derived


def _floor(value: float, step: float) -> float:
    return round(math.floor(value / step + 1e-9) * step, 6)


def _nearest(value: float, step: float) -> float:
    return round(round(value / step) * step, 6)


def _ceil(value: float, step: float) -> float:
    return round(math.ceil(value / step - 1e-9) * step, 6)


def new(inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
    """The differential's draft from ``--module`` and ``--teeth SMALL/BIG`` (see the module's doc).
    A module too small for the gears the CAD builds (bores under the toe roots) is rejected on
    --module with the least module whose derived design passes, found on the derivation itself."""
    m = positive_number("module", inputs["module"], *MODULE_RANGE)
    small, big = teeth_numbers(inputs["teeth"], 2, "small/big")
    _teeth_in_range(inputs["teeth"], small, big)
    if small > big:
        raise ParamError("--teeth", inputs["teeth"], f"allowed small/big with small <= big, e.g. --teeth {big}/{small}")
    for key, flag in _INPUT_FIELDS.items():
        if key in overrides:
            raise ParamError(f"--set {key}", overrides[key], f"allowed: not set here; give it with {flag}")
    d = derive(m, small, big, overrides)
    problem = _problem(d, overrides)
    if problem is None:
        return d
    teeth = ("gears.big_teeth", "gears.small_teeth")
    if problem.field in teeth:
        raise _teeth_error(inputs["teeth"], problem)
    seen: list[ParamError] = []

    def module_ok(v: float) -> bool:
        try:
            found = _problem(derive(v, small, big, overrides), overrides)
        except ParamError as exc:
            found = exc
        if found is not None:
            seen.append(found)
        return found is None

    # the module too small (bores under the toe roots) or too large (a derived dimension out of its
    # range): the nearest module whose derived design passes, found on the derivation itself
    upward = problem.field == "gears.module_mm"
    bound = _module_bound(module_ok, m, upward)
    why = (problem.allowed.partition(": ")[2] if upward
           else f"the derived {problem.field} = {problem.value}: {problem.allowed}")
    if bound is None:  # a rule on the tooth counts (shown at another module), else the first one
        on_teeth = next((e for e in seen if e.field in teeth), None)
        if on_teeth is not None:
            raise _teeth_error(inputs["teeth"], on_teeth)
        raise ParamError("--teeth", inputs["teeth"], f"no module from {MODULE_RANGE[0]:g} to {MODULE_RANGE[1]:g} mm "
                                                     f"allowed at {small}/{big} teeth: {why}")
    side = f">= {fmt_bound(bound, 'lower', 2, ok=module_ok)}" if upward else \
        f"<= {fmt_bound(bound, 'upper', 2, ok=module_ok)}"
    raise ParamError("--module", m, f"allowed {side} mm at {small}/{big} teeth (every value derived from it again): "
                                    f"{why}")


def _teeth_error(given: Any, problem: ParamError) -> ParamError:
    which = problem.field.partition(".")[2].replace("_", " ")  # big teeth / small teeth
    return ParamError("--teeth", given, f"{which}: {problem.allowed}")


def _module_bound(module_ok, m: float, upward: bool, samples: int = 24) -> float | None:
    """Where the modules that pass begin above ``m`` (``upward``) or end below it: the first that
    passes of ``samples`` modules spaced evenly in ratio from ``m`` to the end of the module's
    range, then bisection back towards ``m``; None when none of them passes."""
    end = MODULE_RANGE[1] if upward else MODULE_RANGE[0]
    for k in range(1, samples + 1):
        v = m * (end / m) ** (k / samples)
        if module_ok(v):
            return bisect_boundary(module_ok, v, m, steps=40)
    return None


def _teeth_in_range(given: Any, small: int, big: int) -> None:
    """Each tooth count within its field's range (the cone geometry is derived from them: a count of
    0 has no cone), one line naming both where both are out."""
    out = []
    for count, dotted in ((small, "gears.small_teeth"), (big, "gears.big_teeth")):
        lo, hi = _limits(dotted) or (-math.inf, math.inf)
        if not lo <= count <= hi:
            out.append(f"{dotted.partition('.')[2].replace('_', ' ')} {count}: allowed {lo:g} to {hi:g}")
    if out:
        raise ParamError("--teeth", given, "; ".join(out) + " (small/big)")


def derive(m: float, small: int, big: int, overrides: Mapping[str, Any]) -> Draft:
    """Every value of the template from the module and the tooth counts (no validation)."""
    geom = analysis.cone_geometry(m, big, small)
    re_mm = geom.outer_cone_distance_mm
    d = Draft("differential", f"differential_m{m:g}_z{small}-{big}", [
        f"Bevel-gear differential, module {m:g} mm, {small}/{big} teeth: written by `gearcheck new differential`.",
        "Each value derived by the Zhurong paper's design method or the standard, the note beside it says how "
        "(docs/differential.md, 'A design of your own'). No [calibration] (a built unit's measured backlash) and no "
        "[targets] (add the requirements your unit must meet).",
    ])

    # -- gears
    alpha_deg = _given(overrides, "gears.pressure_angle_deg") or STANDARD_PRESSURE_ANGLE_DEG
    alpha = math.radians(alpha_deg)
    d.set("gears.module_mm", m, "given (--module)")
    d.set("gears.big_teeth", big, "given (--teeth SMALL/BIG): z1, on each output shaft")
    d.set("gears.small_teeth", small, "given: z2, on the cross axis in the housing")
    face_limit = min(re_mm / 3.0, MAX_FACE_WIDTH_MODULES * m)
    face = _floor(face_limit, 1.0 if face_limit >= 5.0 else 0.1)
    d.set("gears.face_width_mm", face,
          f"min(Re/3, 10·m) = {face_limit:.2f} mm rounded down; Re = ½·m·√(z1² + z2²) = {re_mm:.3f} mm")
    d.set("gears.pressure_angle_deg", alpha_deg, _note(overrides, "gears.pressure_angle_deg", "standard involute, 20°"))
    d.set("gears.shaft_angle_deg", 90.0, "the model's perpendicular axes")
    d.set("gears.small_profile_shift", *_shift(geom, alpha, m))

    # -- lengths and the common apex
    l11 = _given(overrides, "dimensions.l11_mm")
    l12 = _given(overrides, "dimensions.l12_mm")
    l2 = _given(overrides, "dimensions.l2_mm")
    a_set = _given(overrides, "dimensions.a_mm")
    b_set = _given(overrides, "dimensions.b_mm")
    l12_note = f"{L12_PER_MODULE:g}·m rounded to {LENGTH_STEP_MM:g} mm (body behind the outer pitch circle)"
    if l12 is None:
        l12 = max(_nearest(L12_PER_MODULE * m, LENGTH_STEP_MM), LENGTH_STEP_MM)
    if l11 is None and b_set is not None:
        l11 = max(b_set / 2.0 - l12 - geom.small_pitch_diameter_mm / 2.0, 0.0)
        l11_note = "from the b_mm set: b/2 − l12 − d2/2 (common apex)"
    else:
        l11_note = f"{L11_PER_CONE_DISTANCE:g}·Re rounded to {LENGTH_STEP_MM:g} mm (shaft grows with the gear set)"
        if l11 is None:
            l11 = _nearest(L11_PER_CONE_DISTANCE * re_mm, LENGTH_STEP_MM)
    if l2 is None and a_set is not None:
        l2 = max(a_set / 2.0 - geom.big_pitch_diameter_mm / 2.0, 0.0)
        l2_note = "from the a_mm set: a/2 − d1/2 (common apex)"
    else:
        l2_note = f"{L2_PER_MODULE:g}·m rounded to {LENGTH_STEP_MM:g} mm (small gear behind its outer pitch circle)"
        if l2 is None:
            l2 = max(_nearest(L2_PER_MODULE * m, LENGTH_STEP_MM), LENGTH_STEP_MM)
    a_mm = round(P.apex_a_mm(geom, l2), 6)
    b_mm = round(P.apex_b_mm(geom, l11, l12), 6)
    d.set("dimensions.a_mm", a_mm, f"common apex: a/2 = l2 + d1/2, d1 = m·z1 = {geom.big_pitch_diameter_mm:g} mm")
    d.set("dimensions.b_mm", b_mm, f"common apex: b/2 = l11 + l12 + d2/2, d2 = m·z2 = "
                                   f"{geom.small_pitch_diameter_mm:g} mm")
    d.set("dimensions.l11_mm", round(l11, 6), _note(overrides, "dimensions.l11_mm", l11_note))
    d.set("dimensions.l12_mm", round(l12, 6), _note(overrides, "dimensions.l12_mm", l12_note))
    d.set("dimensions.l2_mm", round(l2, 6), _note(overrides, "dimensions.l2_mm", l2_note))

    # -- the unit's environment: materials and temperatures (not dimensions)
    template = shipped_template()
    for key, value in template["materials"].items():
        d.set(f"materials.{key}", value, "the paper's unit (literature mean CTE, as the shipped template)"
              if key.endswith("_per_K") else "the paper's unit")
    for key, value in template["operating"].items():
        d.set(f"operating.{key}", value, "the paper's unit's (Mars rover: assembly, cold design point, ranges)")

    # -- backlash: the standard allowance, shared between the shim (the paper's rule) and the teeth
    _backlash(d, geom, alpha, overrides)
    d.sections = {k: d.sections[k] for k in SECTION_ORDER if k in d.sections}  # as the shipped template
    return d


def _shift(geom: analysis.ConeGeometry, alpha: float, m: float) -> tuple[float, str]:
    """Gleason's long-addendum shift for the ratio, kept inside the allowed shifts."""
    gleason = analysis.virtual_mesh(geom, alpha, 0.0).gleason_small_shift
    min_tip = analysis.MIN_TIP_THICKNESS_MODULES * m
    x = round(gleason, 2)
    note = f"Gleason's long-addendum rule, x = {gleason:.3f} (the big gear gets −x)"
    if P.shift_ok(geom, alpha, min_tip, x):
        return x, note
    bounds = P.shift_bounds(geom, alpha, min_tip)
    if bounds is None:
        small, big = geom.small_teeth, geom.big_teeth
        least = next((z for z in range(small + 1, big + 1)
                      if P.shift_bounds(analysis.cone_geometry(m, big, z), alpha, min_tip) is not None), None)
        counts = (f"allowed small teeth >= {least} with {big} big teeth" if least is not None
                  else f"no small tooth count up to {big} allowed with {big} big teeth")
        raise ParamError("--teeth", f"{small}/{big}",
                         f"{counts} at α = {math.degrees(alpha):g}° (a profile shift free of undercut, tip "
                         "interference and pointed teeth; a larger pressure angle, --set gears.pressure_angle_deg, "
                         "allows fewer small teeth)")
    lo, hi = math.ceil(bounds[0] * 100 - 1e-9) / 100, math.floor(bounds[1] * 100 + 1e-9) / 100
    x = min(max(x, lo), hi) if lo <= hi else round((bounds[0] + bounds[1]) / 2.0, 4)
    return x, f"{note}, moved into the allowed {bounds[0]:.3f} to {bounds[1]:.3f}"


def _backlash(d: Draft, geom: analysis.ConeGeometry, alpha: float, overrides: Mapping[str, Any]) -> None:
    """Shim, study shims and tooth thinning from the standard allowance (module doc)."""
    data = d.data()
    for dotted, value in overrides.items():  # the paper model below sees the overrides it can use
        section, _, key = dotted.partition(".")
        if section in data and isinstance(data[section], dict) and _given(overrides, dotted) is not None:
            data[section][key] = float(value)
    dim, mat, op = data["dimensions"], data["materials"], data["operating"]
    jn = standard_backlash_mm(geom.module_mm, geom.outer_cone_distance_mm)
    allowance = jn / math.cos(alpha)  # circumferential on the outer pitch circle
    drop = analysis.backlash_change(geom, alpha, *_approach(geom, dim, mat, op)).per_side_arcmin
    gain_per_mm = analysis.shim_gain(geom, alpha, 1.0)
    shim = _given(overrides, "shim.thickness_mm")
    if shim is None:
        shim = min(_ceil(max(drop, 0.0) / gain_per_mm.per_side_arcmin, SHIM_STEP_MM), 1.0)
        shim_note = (f"the paper's rule: its gain (eq 11, {gain_per_mm.per_side_arcmin:.2f}′/mm per side) covers the "
                     f"cold drop {drop:.2f}′ per side (eq 10, {op['warm_C']:g} → {op['cold_C']:g} °C); next "
                     f"{SHIM_STEP_MM:g} mm up")
    else:
        shim_note = "set with --set"
    gain_mm = gain_per_mm.circumferential_mm * shim
    band = THINNING_BAND_SHARE * allowance
    given = _given(overrides, "backlash.mesh_thinning_min_mm")
    thinning = given if given is not None else round(max(allowance - gain_mm, MIN_THINNING_SHARE * allowance), 4)
    d.set("backlash.mesh_thinning_min_mm", thinning, "set with --set" if given is not None else
          f"standard backlash {allowance * 1e3:.1f} µm (ISO/TR 10064-2 jbn,min = ⅔(0.06 + 0.0005·Re + 0.03·m) = "
          f"{jn * 1e3:.1f} µm normal, /cos α) less the shim's {gain_mm * 1e3:.1f} µm"
          + (f", at least {MIN_THINNING_SHARE:g} of it" if thinning > allowance - gain_mm else ""))
    d.set("backlash.mesh_thinning_max_mm", round(thinning + band, 4),
          f"the least + tolerance band {THINNING_BAND_SHARE:g} of the standard backlash ({band * 1e3:.1f} µm)")
    d.set("shim.thickness_mm", shim, shim_note)
    study = sorted({max(_nearest(shim + k * SHIM_STEP_MM, 0.001), 0.0) for k in (-1, 0, 1)} | {0.0})
    d.set("shim.study_mm", [s for s in study if s <= 1.0],
          f"no shim, and {SHIM_STEP_MM:g} mm either side of the design's (as the paper's shim test)")


def _approach(geom: analysis.ConeGeometry, dim: dict, mat: dict, op: dict) -> tuple[float, float]:
    """Eqs (2)–(7): the two gears' approach from warm to the cold design point (mm)."""
    ap = analysis.thermal_approach(
        geom, a_mm=dim["a_mm"], b_mm=dim["b_mm"], l11_mm=dim["l11_mm"], l12_mm=dim["l12_mm"], l2_mm=dim["l2_mm"],
        housing_cte_per_K=mat["housing_cte_per_K"], shaft_cte_per_K=mat["shaft_cte_per_K"],
        gear_cte_per_K=mat["gear_cte_per_K"], temperature_drop_K=op["warm_C"] - op["cold_C"])
    return ap.big_approach_mm, ap.small_approach_mm


def _problem(d: Draft, overrides: Mapping[str, Any]) -> ParamError | None:
    """The first rule the draft (with the overrides as written) breaks on a gear input (module,
    tooth counts), else on a value derived from them (e.g. a housing length out of its range at a
    large module), or None. A rule broken on an override (a value given with --set) is named by
    the template's own validation when the draft is loaded, as written."""
    data = d.data()
    for dotted, value in overrides.items():
        section, _, key = dotted.partition(".")
        if isinstance(data.get(section), dict):
            data[section][key] = value
    body = {k: v for k, v in data.items() if k not in ("mechanism", "name")}
    try:
        validate(P.Params, body)
    except ParamError as exc:
        errors = exc.errors if isinstance(exc, ParamErrors) else [exc]
        return next((e for e in errors if e.field in _INPUT_FIELDS),
                    next((e for e in errors if e.field not in overrides), None))
    return None
