"""Template model of the bevel-gear differential (templates/zhurong_differential.toml).

One pydantic model per section; field names carry units; ranges are physical limits, not the
paper's window. Geometric rules that need no CAD are checked here (undercut, tip interference,
pointed tips, contact ratio, face width, common apex, negative warm backlash); each rejection
is one :class:`ParamError` naming the field, its value and the allowed range. The model also
builds the CAD's own gear specs (poses.gear_specs → BevelGearSpec checks), so a set the CAD could
not build (back faces in front of the roots, bores above the toe roots, a face cone too flat) is
rejected before any CAD work.
"""

from __future__ import annotations

import math
from typing import Any, Literal

from pydantic import Field, PrivateAttr, model_validator

from gearcheck.mechanisms.differential import analysis, poses  # numpy only
from gearcheck.mechanisms.differential import calibration as cal  # numpy only
from gearcheck.geometry import materials
from gearcheck.params.problems import Problems
from gearcheck.params.common import MISSING, ParamError, Section, bisect_boundary, fmt_bound, fmt_range

# The mounting dimensions a, b must put the pitch circles on the common apex (b/2 = l11 + l12 +
# d2/2, a/2 = l2 + d1/2). 0.05 mm is about 3′ of backlash per side (eq 11): within what the
# shim study (0–0.15 mm) adjusts; a larger mismatch is a different, non-conjugate assembly.
APEX_TOLERANCE_MM = 0.05
MAX_STUDY_SHIMS = 12
MATERIAL_NAME_MAX = 40
MATERIAL_MEMBERS = ("housing", "shaft", "gear")  # materials.NAME, with materials.NAME_cte_per_K
SHIFT_MIN, SHIFT_MAX = -1.0, 1.5  # the small gear's profile shift coefficient (field range)


def apex_b_mm(geom: analysis.ConeGeometry, l11_mm: float, l12_mm: float) -> float:
    """b that puts the big gears' pitch circles on the common apex: b/2 = l11 + l12 + d2/2."""
    return 2.0 * (l11_mm + l12_mm + geom.small_pitch_diameter_mm / 2.0)


def apex_a_mm(geom: analysis.ConeGeometry, l2_mm: float) -> float:
    """a that puts the small gears' pitch circles on the common apex: a/2 = l2 + d1/2."""
    return 2.0 * (l2_mm + geom.big_pitch_diameter_mm / 2.0)


# Mounting errors the tooth contact analysis takes (far beyond any assembly tolerance; the contact
# solve needs the gears in mesh).
MOUNTING_ERROR_MAX_MM = 0.5
MOUNTING_ERROR_MAX_DEG = 0.5


def _unit(unit: str) -> dict:
    return {"unit": unit}


class Gears(Section):
    """Two big and two small straight bevel gears, 90° shafts, long/short addendum."""

    module_mm: float = Field(ge=0.5, le=10.0, description="outer (transverse) module m", json_schema_extra=_unit("mm"))
    big_teeth: int = Field(ge=10, le=200, description="teeth of each big (output) gear, z1",
                           json_schema_extra=_unit("teeth"))
    small_teeth: int = Field(ge=6, le=200, description="teeth of each small (cross-axis) gear, z2",
                             json_schema_extra=_unit("teeth"))
    face_width_mm: float = Field(gt=0.0, le=100.0, description="face width along the pitch element",
                                 json_schema_extra=_unit("mm"))
    pressure_angle_deg: float = Field(ge=14.5, le=30.0, description="normal pressure angle α",
                                      json_schema_extra=_unit("deg"))
    shaft_angle_deg: float = Field(description="angle between big and small gear axes; the model needs 90",
                                   json_schema_extra=_unit("deg"))
    small_profile_shift: float = Field(
        ge=SHIFT_MIN, le=SHIFT_MAX,
        description="profile shift coefficient x of the small gear (the big gear gets −x: long/short addendum)",
        json_schema_extra=_unit("× module"),
    )

    @model_validator(mode="after")
    def _rules(self) -> Gears:
        with Problems() as p:  # independent rules: every one broken is named
            if self.shaft_angle_deg != 90.0:
                p.add("gears.shaft_angle_deg", self.shaft_angle_deg,
                      "allowed 90 deg only: eqs (1), (6), (7) assume perpendicular big and small gear axes")
            if self.small_teeth > self.big_teeth:
                p.add("gears.small_teeth", self.small_teeth,
                      f"allowed <= big_teeth = {self.big_teeth}: the shimmed big gears are the output gears")
            geom = analysis.cone_geometry(self.module_mm, self.big_teeth, self.small_teeth)
            max_face = analysis.MAX_FACE_WIDTH_FRACTION * geom.outer_cone_distance_mm
            if self.face_width_mm > max_face:
                p.add("gears.face_width_mm", self.face_width_mm,
                      f"allowed <= {fmt_bound(max_face, 'upper', 2)} mm: one third of the outer cone distance "
                      f"Re = {geom.outer_cone_distance_mm:.2f} mm (teeth too thin at the inner end)")
            shift = self._shift_problem(geom)
            if shift is not None:
                p.extend(shift)
        return self

    def _shift_problem(self, geom: analysis.ConeGeometry) -> ParamError | None:
        """The profile shift's first broken rule (undercut, interference, pointed tips, contact
        ratio) with the range that satisfies all of them, or None."""
        alpha = math.radians(self.pressure_angle_deg)
        mesh = analysis.virtual_mesh(geom, alpha, self.small_profile_shift)
        x = self.small_profile_shift
        min_tip = analysis.MIN_TIP_THICKNESS_MODULES * self.module_mm
        failed = [name for name, ok in _shift_rules(geom, alpha, min_tip).items() if not ok(x)]
        if not failed:
            return None
        shift_range = _shift_range(geom, alpha, min_tip, f"{self.small_teeth}/{self.big_teeth} teeth and "
                                                         f"{self.pressure_angle_deg:g}°")
        why = {
            "undercut": f"the small gear is undercut (virtual tooth count z/cos δ = {geom.small_virtual_teeth:.2f}: "
                        f"no undercut needs x >= 1 − zv·sin²α/2 = {mesh.small_undercut_min_shift:.3f})",
            "interference": "the big gear's tip runs inside the small gear's base circle (tip interference on the "
                            "back-cone virtual pair)",
            "small tip": f"pointed teeth, the small gear's tip is {mesh.small_tip_thickness_mm:.3f} mm thick on the "
                         f"back cone, less than 0.25·m = {min_tip:.3f} mm",
            "big tip": f"pointed teeth, the big gear's tip (shift −x) is {mesh.big_tip_thickness_mm:.3f} mm thick on "
                       f"the back cone, less than 0.25·m = {min_tip:.3f} mm",
            "contact ratio": f"contact ratio of the back-cone virtual pair is {mesh.contact_ratio:.3f} < "
                             f"{analysis.MIN_CONTACT_RATIO}: a tooth pair lets go before the next engages",
        }[failed[0]]
        return ParamError("gears.small_profile_shift", x,
                          f"{shift_range}: {why}; Gleason's rule gives {mesh.gleason_small_shift:.2f}")


class Backlash(Section):
    """The designed backlash before shimming, an input: the tooth thinning of one mesh (the gears are
    built with the least). `gearcheck new` derives it from the standard backlash for the module and
    cone distance; the shipped template's is a reconstruction (the paper lost it)."""

    mesh_thinning_min_mm: float = Field(
        ge=0.0, le=0.5,
        description="least circumferential tooth thinning of one mesh (big + small gear) on the outer pitch circle",
        json_schema_extra=_unit("mm"),
    )
    mesh_thinning_max_mm: float = Field(
        ge=0.0, le=0.5,
        description="largest circumferential tooth thinning of one mesh on the outer pitch circle (tolerance band)",
        json_schema_extra=_unit("mm"),
    )

    @model_validator(mode="after")
    def _band(self) -> Backlash:
        if self.mesh_thinning_max_mm < self.mesh_thinning_min_mm:
            raise ParamError("backlash.mesh_thinning_max_mm", self.mesh_thinning_max_mm,
                             f"allowed >= mesh_thinning_min_mm = {self.mesh_thinning_min_mm} mm")
        return self


def _cte_field(what: str):
    # no default in the file: the material's name gives it (Materials._from_names fills it in)
    return Field(None, ge=0.0, le=100e-6, description=f"mean linear expansion coefficient of the {what} (default: "
                 "the material's, from gearcheck's materials table)", json_schema_extra=_unit("1/K"))


class Materials(Section):
    """Materials and their mean CTE over the warm–cold range (ξ1 housing, ξ2 shaft, ξ3 gears).

    A name sets its coefficient from gearcheck's materials table, the one every mechanism uses
    ("grey cast iron" is cast iron, 10.5e-6/K); a coefficient given beside it wins (a data
    sheet's value). A name the table does not know, without a coefficient, is refused."""

    housing: str = Field(min_length=1, max_length=MATERIAL_NAME_MAX, description="housing material name")
    housing_cte_per_K: float = _cte_field("housing (ξ1)")
    shaft: str = Field(min_length=1, max_length=MATERIAL_NAME_MAX, description="big gear shaft material name")
    shaft_cte_per_K: float = _cte_field("big gear shaft (ξ2)")
    gear: str = Field(min_length=1, max_length=MATERIAL_NAME_MAX, description="gear material name")
    gear_cte_per_K: float = _cte_field("gears (ξ3)")
    # per member: "given" (the template's coefficient) or the table entry's name it came from
    _sources: dict[str, str] = PrivateAttr(default_factory=dict)

    @model_validator(mode="wrap")
    @classmethod
    def _from_names(cls, data: Any, handler: Any) -> Materials:
        sources: dict[str, str] = {}
        if isinstance(data, dict):
            data = dict(data)
            for member in MATERIAL_MEMBERS:
                key = f"{member}_cte_per_K"
                name = data.get(member)
                if data.get(key) is not None:
                    sources[member] = "given"
                elif isinstance(name, str):
                    found = materials.find(name)
                    if found is None:
                        raise ParamError(f"materials.{member}", name,
                                         f"allowed a material gearcheck knows ({', '.join(materials.NAMES)}), "
                                         f"or give materials.{key}")
                    data[key] = found.cte_per_K
                    sources[member] = found.name
        model = handler(data)
        model._sources = sources
        return model

    @property
    def cte_sources(self) -> dict[str, str]:
        """Where each coefficient comes from: ``"given"`` or the materials table's entry."""
        return dict(self._sources)


class Dimensions(Section):
    """Housing and gear mounting lengths of eqs (2)–(7) (the paper's Table 2 is lost: reconstructed)."""

    a_mm: float = Field(gt=0.0, le=1000.0, description="housing: between the small gears' mounting faces",
                        json_schema_extra=_unit("mm"))
    b_mm: float = Field(gt=0.0, le=1000.0, description="housing: between the big gears' mounting faces",
                        json_schema_extra=_unit("mm"))
    l11_mm: float = Field(ge=0.0, le=500.0, description="big gear shaft (Ti) length, mounting face to gear joint",
                          json_schema_extra=_unit("mm"))
    l12_mm: float = Field(ge=0.0, le=500.0,
                          description="big gear body (steel), shaft joint to outer pitch circle plane",
                          json_schema_extra=_unit("mm"))
    l2_mm: float = Field(ge=0.0, le=500.0, description="small gear, mounting face to outer pitch circle plane",
                         json_schema_extra=_unit("mm"))


class Operating(Section):
    """Temperatures: warm_C is where the backlash is set and measured (room temperature)."""

    warm_C: float = Field(ge=-60, le=150,
                          description="assembly / room temperature where thinning and shim set the backlash",
                          json_schema_extra=_unit("°C"))
    cold_C: float = Field(ge=-150, le=25, description="cold design point", json_schema_extra=_unit("°C"))
    operating_min_C: float = Field(ge=-150, le=150, description="lowest operating temperature",
                                   json_schema_extra=_unit("°C"))
    operating_max_C: float = Field(ge=-150, le=150, description="highest operating temperature",
                                   json_schema_extra=_unit("°C"))
    storage_min_C: float = Field(ge=-150, le=150, description="lowest storage temperature",
                                 json_schema_extra=_unit("°C"))
    storage_max_C: float = Field(ge=-150, le=150, description="highest storage temperature",
                                 json_schema_extra=_unit("°C"))

    @model_validator(mode="after")
    def _order(self) -> Operating:
        with Problems() as p:
            if self.cold_C > self.warm_C:
                p.add("operating.cold_C", self.cold_C, f"allowed <= warm_C = {self.warm_C} °C")
            if self.operating_min_C > self.operating_max_C:
                p.add("operating.operating_min_C", self.operating_min_C,
                      f"allowed <= operating_max_C = {self.operating_max_C} °C")
            if self.storage_min_C > self.storage_max_C:
                p.add("operating.storage_min_C", self.storage_min_C,
                      f"allowed <= storage_max_C = {self.storage_max_C} °C")
        return self


def shim_key(shim_mm: float) -> str:
    """JSON key suffix of a study shim: 0.05 → '0p05', 0.1 → '0p10', 0.125 → '0p125'."""
    text = f"{shim_mm:.3f}".rstrip("0")
    whole, frac = text.split(".")
    return f"{whole}p{frac.ljust(2, '0')}"


class Shim(Section):
    """Adjusting shim under each big gear; it moves the gear away from the mesh (eq 11)."""

    thickness_mm: float = Field(ge=0.0, le=1.0, description="shim under each big gear in this design",
                                json_schema_extra=_unit("mm"))
    study_mm: list[float] = Field(
        default_factory=list, max_length=MAX_STUDY_SHIMS,
        description="shim thicknesses to tabulate", json_schema_extra=_unit("mm"),
    )

    @model_validator(mode="after")
    def _study(self) -> Shim:
        seen: dict[str, float] = {}
        with Problems() as p:
            for i, s in enumerate(self.study_mm):
                if not (0.0 <= s <= 1.0) or not math.isfinite(s):
                    p.add(f"shim.study_mm.{i}", s, "out of range: allowed 0 to 1.0 mm")
                    continue
                key = shim_key(s)
                if key in seen:
                    p.add(f"shim.study_mm.{i}", s,
                          f"allowed distinct values at 0.001 mm resolution (same as {seen[key]})")
                seen[key] = s
        return self


CALIBRATION_KEYS = ("measured_backlash_total_min_arcmin", "measured_backlash_total_max_arcmin", "measured_shim_mm",
                    "measured_at_C")
MEASURED_TOTAL_MAX_ARCMIN = 120.0  # both sides; 60′ per side, well within the exact model's reach


class Calibration(Section):
    """Backlash measured on a built unit (optional; all four keys or none): a measurement of the unit
    this template describes, not a design input. When given, the tooth thinning the gears are built
    with is solved on the exact geometry so that it reproduces the measurement (the least measured
    total → the least thinning, read as the cycle minimum); [backlash] stays as the thinning set
    through the paper's first-order model (docs/differential.md)."""

    measured_backlash_total_min_arcmin: float | None = Field(
        default=None, gt=0.0, le=MEASURED_TOTAL_MAX_ARCMIN,
        description="least total backlash measured between the output shafts (both sides, two meshes)",
        json_schema_extra=_unit("arcmin"))
    measured_backlash_total_max_arcmin: float | None = Field(
        default=None, gt=0.0, le=MEASURED_TOTAL_MAX_ARCMIN,
        description="largest total backlash measured between the output shafts (both sides)",
        json_schema_extra=_unit("arcmin"))
    measured_shim_mm: float | None = Field(default=None, ge=0.0, le=1.0,
                                           description="shim under each big gear when it was measured",
                                           json_schema_extra=_unit("mm"))
    measured_at_C: float | None = Field(default=None, ge=-150, le=150, description="temperature of the measurement",
                                        json_schema_extra=_unit("°C"))

    @model_validator(mode="after")
    def _all_or_none(self) -> Calibration:
        given = [k for k in CALIBRATION_KEYS if getattr(self, k) is not None]
        with Problems() as p:
            if given and len(given) < len(CALIBRATION_KEYS):
                for missing in (k for k in CALIBRATION_KEYS if getattr(self, k) is None):
                    p.add(f"calibration.{missing}", MISSING,
                          f"allowed: a value — [calibration] needs all of {', '.join(CALIBRATION_KEYS)} or none")
            lo, hi = self.measured_backlash_total_min_arcmin, self.measured_backlash_total_max_arcmin
            if lo is not None and hi is not None and hi < lo:
                p.add("calibration.measured_backlash_total_max_arcmin", hi,
                      f"allowed >= measured_backlash_total_min_arcmin = {lo}′")
        return self

    @property
    def given(self) -> bool:
        return self.measured_backlash_total_min_arcmin is not None


class Targets(Section):
    """Requirements the design states (optional): each one given is a verdict. The paper requires
    its unit to keep at least 10′ of total backlash cold; a template carries that here."""

    cold_backlash_total_min_arcmin: float | None = Field(
        default=None, ge=0.0, le=MEASURED_TOTAL_MAX_ARCMIN,
        description="least total backlash (both sides) the design must keep at the cold design point, over the "
                    "whole mesh cycle", json_schema_extra=_unit("arcmin"))
    level: Literal["fail", "warn"] = Field(
        default="fail", description="what falling short of a target is: a failed design (default) or a warning")
    reason: str = Field(default="", max_length=400,
                        description="why the level is what it is (shown with the verdict)")


def _mounting_error(description: str, limit: float = MOUNTING_ERROR_MAX_MM, unit: str = "mm") -> Any:
    """One mounting error of ``[tca]``: 0 by default, within ±``limit``."""
    return Field(default=0.0, ge=-limit, le=limit, description=description, json_schema_extra=_unit(unit))


class Tca(Section):
    """Tooth contact analysis of each big/small pair (the report's TE and contact pattern): the
    marking compound, the pair's mounting errors beyond the design (E/P/G/Σ, taken on top of each
    thermal state's own displacements; the play checks take the housing as designed, and what
    the errors cost in play shows as the least TE_coast − TE_drive of ``tca.mounted``), and a
    requirement on the pattern (optional; given, it is a verdict): it must bear over at least
    ``pattern_min_length`` of the face width on both flanks at every running state (warm, cold
    design point, operating minimum and maximum) and stay on the involute."""

    compound_um: float = Field(
        default=6.0, gt=0.0, le=100.0,
        description="marking compound thickness: the flank takes the mark where the gap to the mating flank is "
                    "under it", json_schema_extra=_unit("µm"))
    offset_mm: float = _mounting_error("E: offset of the small gear's axis from the big gear's, along their common "
                                       "perpendicular")
    small_axial_mm: float = _mounting_error("P: the small gear moved along its axis, away from the apex (+ opens the "
                                            "mesh)")
    big_axial_mm: float = _mounting_error("G: the big gear moved along its axis, away from the apex (+ opens the "
                                          "mesh), beyond the shim")
    shaft_angle_deg: float = _mounting_error("Σ: the shaft angle's error (+ opens it beyond 90°)",
                                             MOUNTING_ERROR_MAX_DEG, "°")
    pattern_min_length: float | None = Field(
        default=None, gt=0.0, le=1.0,
        description="least share of the face width (toe to heel) the pattern must cover at each running state")
    level: Literal["fail", "warn"] = Field(
        default="fail", description="what a pattern short of it is: a failed design (default) or a warning")

    @property
    def mounting_errors(self) -> tuple[float, float, float, float]:
        """(E mm, P mm, G mm, Σ rad)."""
        return self.offset_mm, self.small_axial_mm, self.big_axial_mm, math.radians(self.shaft_angle_deg)


class Params(Section):
    """The whole template (less its top-level ``mechanism`` key)."""

    gears: Gears
    backlash: Backlash
    materials: Materials
    dimensions: Dimensions
    operating: Operating
    shim: Shim
    calibration: Calibration = Field(default_factory=Calibration)
    targets: Targets = Field(default_factory=Targets)
    tca: Tca = Field(default_factory=Tca)
    # the thinning solved from [calibration] by the validation (None: the template's [backlash])
    _thinning: cal.Thinning | None = PrivateAttr(default=None)

    def resolved(self, data: dict[str, Any]) -> dict[str, Any]:
        """``data`` with every material's coefficient as the run used it (a name's from the
        materials table where the template gives none): what params.toml records."""
        import copy

        out = copy.deepcopy(data)
        section = out.setdefault("materials", {})
        for member in MATERIAL_MEMBERS:
            section[f"{member}_cte_per_K"] = getattr(self.materials, f"{member}_cte_per_K")
        return out

    def design_thinning(self) -> cal.Thinning | None:
        """The tooth thinning solved from [calibration] (None when not calibrated)."""
        return self._thinning

    def thinning(self) -> cal.Thinning:
        """The thinning the gears are built with and where it comes from."""
        return self._thinning if self._thinning is not None else cal.template_thinning(self)

    @model_validator(mode="after")
    def _assembly(self) -> Params:
        geom = analysis.cone_geometry(self.gears.module_mm, self.gears.big_teeth, self.gears.small_teeth)
        d = self.dimensions
        with Problems() as p:  # independent rules: every one broken is named; the CAD's need them to hold
            b_apex = apex_b_mm(geom, d.l11_mm, d.l12_mm)
            b_lo, b_hi = b_apex - APEX_TOLERANCE_MM, b_apex + APEX_TOLERANCE_MM
            if not b_lo <= d.b_mm <= b_hi:
                p.add("dimensions.b_mm", d.b_mm,
                      f"allowed {fmt_range(b_lo, b_hi)} mm ({b_apex:.3f} ± {APEX_TOLERANCE_MM}): the big pitch "
                      "circles must meet the common apex, b/2 = l11 + l12 + d2/2 (or change l11_mm or l12_mm with it)")
            a_apex = apex_a_mm(geom, d.l2_mm)
            a_lo, a_hi = a_apex - APEX_TOLERANCE_MM, a_apex + APEX_TOLERANCE_MM
            if not a_lo <= d.a_mm <= a_hi:
                p.add("dimensions.a_mm", d.a_mm,
                      f"allowed {fmt_range(a_lo, a_hi)} mm ({a_apex:.3f} ± {APEX_TOLERANCE_MM}): the small "
                      "pitch circles must meet the common apex, a/2 = l2 + d1/2 (or change l2_mm with it)")
            gain = analysis.shim_gain(geom, math.radians(self.gears.pressure_angle_deg), self.shim.thickness_mm)
            warm_min_per_side = (analysis.big_gear_arcmin(self.backlash.mesh_thinning_min_mm, geom)
                                 + gain.per_side_arcmin)
            if warm_min_per_side <= 0.0:
                p.add("backlash.mesh_thinning_min_mm", self.backlash.mesh_thinning_min_mm,
                      f"allowed > 0 mm with shim.thickness_mm = {self.shim.thickness_mm}: the warm backlash "
                      f"would be {warm_min_per_side:.2f}′ per side (the mesh binds at room temperature)")
        why = _cad_blocker(self)
        if why is not None:
            raise _blame(self, why)
        if self.calibration.given:
            self._thinning = _calibrate(self)
        return self


def _calibrate(params: Params) -> cal.Thinning:
    """The thinning solved from the measured backlash; a measurement the exact geometry cannot
    reproduce is rejected on that measured value, with the limit where there is one."""
    c = params.calibration
    try:
        solved = cal.calibrated_thinning(params)
    except cal.CalibrationError as exc:
        key = f"measured_backlash_total_{exc.which}_arcmin"
        if exc.bound is None:
            allowed = "allowed: a backlash the exact geometry can reproduce"
        else:
            allowed = f"allowed {'>=' if exc.side == 'lower' else '<='} {fmt_bound(exc.bound, exc.side)}′"
        raise ParamError(f"calibration.{key}", getattr(c, key), f"{allowed}: {exc.why}") from None
    params._thinning = solved
    why = _cad_blocker(params)
    if why is not None:
        params._thinning = None
        raise ParamError("calibration.measured_backlash_total_min_arcmin", c.measured_backlash_total_min_arcmin,
                         f"allowed: a backlash whose solved tooth thinning ({solved.min_mm:.4f} mm) the CAD can "
                         f"build ({why})")
    return solved


# -- the CAD's own gear specs ----------------------------------------------------------------
# `gearcheck build` makes its gears from poses.gear_specs (BevelGearSpec checks its cones, tip
# land, root space and blank in __post_init__) and places them with poses.assembly_poses. The
# model builds the same specs, so a set the CAD could not build is rejected here, before any CAD
# work; the blame goes to the input that moves the failing check, with its allowed range found
# by bisection on that same check.

def _cad_blocker(params: Params) -> str | None:
    """Why the CAD could not make these gears (BevelGearSpec's message), or None."""
    try:
        specs = poses.gear_specs(params)
        poses.assembly_poses(specs, params.shim.thickness_mm)
    except ValueError as exc:
        return str(exc)
    return None


def _with(params: Params, section: str, **values) -> Params:
    """A copy with some fields of one section replaced (not validated: for probing the specs)."""
    return params.model_copy(update={section: getattr(params, section).model_copy(update=values)})


def _boundary(ok, good: float, bad: float) -> float | None:
    return bisect_boundary(ok, good, bad, steps=50)


def _shift_rules(geom, alpha: float, min_tip: float) -> dict:
    """The small gear's profile shift rules, in the order they are checked: each a test of x.
    Undercut, tip interference and the big gear's tip land bound x from below (the big gear gets
    −x); the small gear's tip land and the contact ratio from above."""

    def at(v: float) -> analysis.VirtualMesh:
        return analysis.virtual_mesh(geom, alpha, v)

    return {
        "undercut": lambda v: v >= at(v).small_undercut_min_shift,
        "interference": lambda v: at(v).big_tip_path_mm <= at(v).big_tip_path_limit_mm,
        "small tip": lambda v: at(v).small_tip_thickness_mm >= min_tip,
        "big tip": lambda v: at(v).big_tip_thickness_mm >= min_tip,
        "contact ratio": lambda v: at(v).contact_ratio >= analysis.MIN_CONTACT_RATIO,
    }


def shift_bounds(geom, alpha: float, min_tip: float) -> tuple[float, float] | None:
    """The small gear's allowed profile shifts under all of :func:`_shift_rules`, unrounded, inside
    the field's own range; None when no shift satisfies them."""
    rules = _shift_rules(geom, alpha, min_tip)
    x_hi: float | None = analysis.max_small_shift_for_tip(geom, alpha)
    x_lo: float | None = max(analysis.virtual_mesh(geom, alpha, 0.0).small_undercut_min_shift,
                             analysis.min_small_shift_for_interference(geom, alpha))
    if x_lo is not None and x_hi is not None and not rules["big tip"](x_lo):
        # the big gear's tip thins as x falls: its least shift, found from the small gear's limit down
        x_lo = _boundary(rules["big tip"], x_hi, x_lo)
    if x_lo is not None and x_hi is not None and not rules["contact ratio"](x_hi):
        # the contact ratio falls as x grows past its peak: the largest shift that keeps it
        x_hi = _boundary(rules["contact ratio"], x_lo, x_hi)
    if x_lo is None or x_hi is None:
        return None
    x_lo, x_hi = max(x_lo, SHIFT_MIN), min(x_hi, SHIFT_MAX)  # inside the field's own range
    return (x_lo, x_hi) if x_lo <= x_hi else None


def shift_ok(geom, alpha: float, min_tip: float, x: float) -> bool:
    """Whether the small gear's profile shift ``x`` passes every rule of :func:`_shift_rules`."""
    return all(ok(x) for ok in _shift_rules(geom, alpha, min_tip).values())


def _shift_range(geom, alpha: float, min_tip: float, where: str) -> str:
    """'allowed lo to hi' for the small gear's profile shift under all of :func:`_shift_rules`
    (each end rounded inward and checked against those rules), or why no shift works."""
    rules = _shift_rules(geom, alpha, min_tip)

    def low_ok(v: float) -> bool:
        return rules["undercut"](v) and rules["interference"](v) and rules["big tip"](v)

    def high_ok(v: float) -> bool:
        return rules["small tip"](v) and rules["contact ratio"](v)

    bounds = shift_bounds(geom, alpha, min_tip)
    if bounds is None:
        return (f"no shift allowed at {where} (no undercut, tip interference or pointed big gear needs x above the "
                "shifts that keep the small gear's tip land and a contact ratio >= 1)")
    return f"allowed {fmt_range(*bounds, lo_ok=low_ok, hi_ok=high_ok)}"


def _blame(params: Params, why: str) -> ParamError:
    g, d = params.gears, params.dimensions
    geom = analysis.cone_geometry(g.module_mm, g.big_teeth, g.small_teeth)

    def cured(section: str, **values) -> bool:
        return cures(_with(params, section, **values))

    def cures(changed: Params) -> bool:
        blocker = _cad_blocker(changed)
        return blocker is None or blocker.split(":")[0] != why.split(":", maxsplit=1)[0]

    if "mounting_distance" in why:  # a back (mounting) face in front of its gear's outer root
        # Probe one gear at a time, the other's face moved far back (both messages read alike).
        far = 500.0
        small_a = lambda v: 2.0 * (v + geom.big_pitch_diameter_mm / 2.0)  # noqa: E731  a/2 = l2 + d1/2
        if not cured("dimensions", l12_mm=far):
            def l2_ok(v: float) -> bool:
                return cured("dimensions", l12_mm=far, a_mm=small_a(v))

            l2 = _boundary(l2_ok, far, d.l2_mm)
            bound = (f"allowed >= {fmt_bound(l2, 'lower', ok=l2_ok)} mm" if l2 is not None
                     else f"no length up to {far:g} mm allowed")
            return ParamError("dimensions.l2_mm", d.l2_mm,
                              f"{bound}: the small gear's mounting face (a/2 = l2 + d1/2 from the apex) must lie "
                              "behind its outer root (change a_mm with it)")
        def l12_ok(v: float) -> bool:
            return cured("dimensions", l12_mm=v)

        l12 = _boundary(l12_ok, far, d.l12_mm)
        bound = (f"allowed >= {fmt_bound(l12, 'lower', ok=l12_ok)} mm" if l12 is not None
                 else f"no length up to {far:g} mm allowed")
        return ParamError("dimensions.l12_mm", d.l12_mm,
                          f"{bound}: the big gear's body must reach behind its outer root "
                          "(back face d2/2 + l12 from the apex; change b_mm with it)")
    if "front_face" in why:  # the bore does not fit under the inner (toe) root
        def module_ok(v: float) -> bool:  # with a and b moved to keep the common apex, as they must
            changed = _with(params, "gears", module_mm=v)
            return cures(_with(changed, "dimensions", a_mm=2.0 * (d.l2_mm + v * g.big_teeth / 2.0),
                               b_mm=2.0 * (d.l11_mm + d.l12_mm + v * g.small_teeth / 2.0)))

        m = _boundary(module_ok, 10.0, g.module_mm)
        bound = (f"allowed >= {fmt_bound(m, 'lower', ok=module_ok)} mm at these tooth counts (a_mm, b_mm moved "
                 "with it)" if m is not None
                 else "no module up to 10 mm allowed")
        return ParamError("gears.module_mm", g.module_mm,
                          f"{bound}: the gear bores ({poses.BIG_GEAR_BORE_MM:g} mm big, "
                          f"{poses.SMALL_GEAR_BORE_MM:g} mm "
                          "small) must lie under the roots at the inner end of the teeth")
    if "face cone" in why:
        z1 = next((n for n in range(g.big_teeth - 1, g.small_teeth - 1, -1) if cured("gears", big_teeth=n)), None)
        bound = f"allowed <= {z1}" if z1 is not None else f"no count allowed down to small_teeth = {g.small_teeth}"
        return ParamError("gears.big_teeth", g.big_teeth,
                          f"{bound} with {g.small_teeth} small teeth: the big gear's face cone is too flat "
                          "(face angle >= 85°) to cut planar tooth sections")
    if "pointed" in why or "root" in why:
        return ParamError("gears.small_profile_shift", g.small_profile_shift,
                          f"allowed: a shift that leaves both gears a tip land and a root space ({why})")
    return ParamError("gears", g.model_dump(), f"allowed: gears the CAD can build ({why})")
