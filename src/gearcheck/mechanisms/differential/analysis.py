"""Cold backlash of the Zhurong bevel-gear differential: the paper's model, eqs (1)–(11).

Pure numpy. Lengths in mm unless a name says otherwise, angles in radians inside, arcmin and
degrees only in the names that say so. Subscript 1 is the big gear (z = 33, on the output
shaft), 2 the small gear (z = 13, on the cross axis in the housing), as in the paper.

The mechanism
-------------
Two big and two small straight bevel gears at 90° share one cone apex at the housing centre.
Each big gear sits on a titanium shaft (length l11) that bears on a mounting face of the
aluminium housing; its steel body reaches l12 further to the plane of its outer pitch circle.
Each small gear bears on a housing face with its pitch-circle plane l2 from that face. With a
common apex the big gear's outer pitch circle lies d2/2 from the apex along its axis and the
small gear's lies d1/2 along its own, so b/2 = l11 + l12 + d2/2 and a/2 = l2 + d1/2.

Thermal approach, eqs (2)–(7) as printed (ΔT here is the temperature *drop*, warm − cold > 0;
every displacement is positive when the two pitch circles approach):
  (2) ΔL1 = [ξ1·b/2 − (ξ2·l11 + ξ3·l12)]·ΔT      big pitch circle toward the housing centre
  (3) Δd1 = ξ3·d1·ΔT                               big pitch diameter shrink
  (4) ΔL2 = [ξ1·a/2 − ξ3·l2]·ΔT                    small pitch circle toward the centre
  (5) Δd2 = ξ3·d2·ΔT
  (6) ΔS1 = ΔL1 − Δd2/2                            big gear toward the small gear, along its axis
  (7) ΔS2 = ΔL2 − Δd1/2                            small gear toward the big gear, along its axis
ξ1 housing, ξ2 shaft, ξ3 gear CTE. The Δd/2 terms are the shrink of the *other* gear's pitch
radius, which is the axial position of this gear's pitch circle seen from the apex.

Eq (1), lost — reconstructed
----------------------------
Put the apex at the origin, the big gear axis along x and the small gear axis along z. The
common pitch element (the contact line of the pitch cones) runs from the apex to
(d2/2, 0, d1/2) = Re·(cos δ1, 0, sin δ1): it makes δ1 with the big axis and δ2 = 90° − δ1
with the small axis. A shift ΔS1 of the big gear along its own axis toward the apex splits
into a part normal to the pitch element (closing the tooth gap) and a part along it:
  (1)  r1 = ΔS1·sin δ1,   t1 = ΔS1·cos δ1,   r2 = ΔS2·sin δ2,   t2 = ΔS2·cos δ2
with t1, t2 both positive toward the apex. The normal parts add (the gears come together:
r1 + r2); the parts along the element subtract, because moving both gears by the same vector
along the element changes nothing: only t1 − t2 is a relative slide.

Eq (8): the tooth tapers to the apex, so sliding gear 1 by t1 toward the apex brings a thicker
section of its tooth to the contact point. With θ the angle between the two flanks of a tooth
at the pitch cone, the thickness changes by 2·tan(θ/2) per unit slide, and θ follows from the
outer pitch-circle tooth thickness πm/2 shrinking to zero at the apex over Re:
  2·tan(θ/2) = (πm/2) / Re,           Re = ½·√(d1² + d2²)
  (8)  Δjn = r1 + r2 + 2·(t1 − t2)·tan(θ/2)
  (9)  Δjc = 2·Δjn·tan α       (as printed; by analogy with spur gears, jt = 2·Δa·tan α)

Eq (9) as printed multiplies the t-term by 2·tan α too, although 2·(t1 − t2)·tan(θ/2) is
already a circumferential thickness change. The dimensionally clean form is
  Δjc_clean = 2·tan α·(r1 + r2) + 2·tan(θ/2)·(t1 − t2)
Both are computed; the printed form is the one that reproduces the paper's 3.4′.

Eq (10), lost — reconstructed: the circumferential backlash Δjc on the big gear's outer pitch
circle turns into an angle of the big gear (the output shaft):
  (10)  ε = Δjc / (d1/2)   [rad],  ε′ = ε·10800/π   [arcmin]
(The mean pitch diameter would need an implausible housing, b ≈ 130 mm, to give 3.4′.)
The backlash between the two output shafts passes through two meshes (big 1 → small → big 2),
so the total is 2·ε′ ("per side" and "total" in the paper).

Eq (11), lost — reconstructed: a shim of thickness x under each big gear moves it by x along
its axis *away* from the mesh (ΔS1 = x, ΔS2 = 0, sign reversed), so by (1), (8)–(10)
  (11)  ε′ = (10800/π)·2·tan α·x·(sin δ1 + 2·tan(θ/2)·cos δ1) / (d1/2)     per side
and 2·ε′ for both sides.

Scope: eqs (1)–(11) are first order and local (one tooth pair at the pitch point). A slide
along the pitch element moves a gear's apex off the common apex; the exact flank geometry then
loses more backlash than this model says (see docs/differential.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.involute import inv

ARCMIN_PER_RAD = 10800.0 / math.pi
UM_PER_MM = 1000.0

# Tooth-form constants of the virtual spur gears on the back cone (Tredgold's approximation).
ADDENDUM_COEFFICIENT = 1.0  # ha*: full-depth teeth
MIN_TIP_THICKNESS_MODULES = 0.25  # a tip thinner than 0.25·m is taken as pointed
MIN_CONTACT_RATIO = 1.0  # below 1 a tooth pair lets go before the next one takes over
MAX_FACE_WIDTH_FRACTION = 1.0 / 3.0  # face width ≤ Re/3: the usual bevel gear limit


@dataclass(frozen=True)
class ConeGeometry:
    """Pitch cones of the 90° pair and the back-cone virtual spur gears (Tredgold)."""

    module_mm: float
    big_teeth: int
    small_teeth: int
    big_pitch_diameter_mm: float  # d1
    small_pitch_diameter_mm: float  # d2
    big_cone_angle_rad: float  # δ1
    small_cone_angle_rad: float  # δ2
    outer_cone_distance_mm: float  # Re
    big_virtual_teeth: float  # z1 / cos δ1
    small_virtual_teeth: float  # z2 / cos δ2
    flank_taper_angle_rad: float  # θ of eq (8): 2·tan(θ/2) = πm/(2·Re)

    @property
    def flank_taper(self) -> float:
        """2·tan(θ/2): tooth-thickness change per unit slide along the pitch element."""
        return 2.0 * math.tan(self.flank_taper_angle_rad / 2.0)


def cone_geometry(module_mm: float, big_teeth: int, small_teeth: int) -> ConeGeometry:
    """Cone angles, outer cone distance, virtual tooth counts and θ for a 90° shaft angle."""
    d1 = module_mm * big_teeth
    d2 = module_mm * small_teeth
    delta1 = math.atan2(big_teeth, small_teeth)
    delta2 = math.pi / 2.0 - delta1
    cone_distance = 0.5 * math.hypot(d1, d2)
    theta = 2.0 * math.atan((math.pi * module_mm / 2.0) / (2.0 * cone_distance))
    return ConeGeometry(
        module_mm=module_mm,
        big_teeth=big_teeth,
        small_teeth=small_teeth,
        big_pitch_diameter_mm=d1,
        small_pitch_diameter_mm=d2,
        big_cone_angle_rad=delta1,
        small_cone_angle_rad=delta2,
        outer_cone_distance_mm=cone_distance,
        big_virtual_teeth=big_teeth / math.cos(delta1),
        small_virtual_teeth=small_teeth / math.cos(delta2),
        flank_taper_angle_rad=theta,
    )


@dataclass(frozen=True)
class VirtualMesh:
    """The back-cone virtual spur pair with long/short addendum (pinion +x, gear −x)."""

    small_profile_shift: float
    small_undercut_min_shift: float  # x ≥ ha* − zv·sin²α/2
    gleason_small_shift: float  # long-addendum shift from Gleason's straight-bevel rule
    small_tip_thickness_mm: float
    big_tip_thickness_mm: float
    contact_ratio: float
    big_tip_path_mm: float  # contact path from the pitch point to where the big tip leaves
    big_tip_path_limit_mm: float  # beyond this the big tip runs inside the pinion base circle


def _tip_thickness(virtual_radius: float, base_radius: float, tip_radius: float,
                   pitch_thickness: float, pressure_angle_rad: float) -> float:
    # A tip inside the base circle has no involute: take the flank as radial there.
    tip_pressure_angle = math.acos(min(base_radius / tip_radius, 1.0))
    half_angle = pitch_thickness / (2.0 * virtual_radius) + inv(pressure_angle_rad) - inv(tip_pressure_angle)
    return float(2.0 * tip_radius * half_angle)


def virtual_mesh(geom: ConeGeometry, pressure_angle_rad: float, small_profile_shift: float) -> VirtualMesh:
    """Undercut, pointed tips, contact ratio and tip interference on the back-cone virtual pair.

    Tredgold: each bevel gear is replaced by the spur gear of radius rv = r/cos δ on its back
    cone (outer end), tooth count zv = z/cos δ. Thickness and addendum scale with the cone
    distance, so ratios checked at the outer end hold along the face.
    """
    m = geom.module_mm
    alpha = pressure_angle_rad
    x = small_profile_shift
    rv_small = m * geom.small_virtual_teeth / 2.0
    rv_big = m * geom.big_virtual_teeth / 2.0
    rb_small = rv_small * math.cos(alpha)
    rb_big = rv_big * math.cos(alpha)
    ra_small = rv_small + (ADDENDUM_COEFFICIENT + x) * m
    ra_big = rv_big + (ADDENDUM_COEFFICIENT - x) * m
    s_small = m * (math.pi / 2.0 + 2.0 * x * math.tan(alpha))
    s_big = m * (math.pi / 2.0 - 2.0 * x * math.tan(alpha))
    path_small = math.sqrt(max(ra_small**2 - rb_small**2, 0.0))
    path_big = math.sqrt(max(ra_big**2 - rb_big**2, 0.0))
    centre_path = (rv_small + rv_big) * math.sin(alpha)
    contact_ratio = (path_small + path_big - centre_path) / (math.pi * m * math.cos(alpha))
    # Gleason (AGMA 2005) gear addendum 0.54·m + 0.46·m/(equivalent ratio), working depth 2·m.
    equivalent_ratio = geom.big_virtual_teeth / geom.small_virtual_teeth
    gleason_big_addendum_modules = 0.54 + 0.46 / equivalent_ratio
    return VirtualMesh(
        small_profile_shift=x,
        small_undercut_min_shift=ADDENDUM_COEFFICIENT - geom.small_virtual_teeth * math.sin(alpha) ** 2 / 2.0,
        gleason_small_shift=ADDENDUM_COEFFICIENT - gleason_big_addendum_modules,
        small_tip_thickness_mm=_tip_thickness(rv_small, rb_small, ra_small, s_small, alpha),
        big_tip_thickness_mm=_tip_thickness(rv_big, rb_big, ra_big, s_big, alpha),
        contact_ratio=contact_ratio,
        big_tip_path_mm=path_big - rv_big * math.sin(alpha),
        big_tip_path_limit_mm=rv_small * math.sin(alpha),
    )


def max_small_shift_for_tip(geom: ConeGeometry, pressure_angle_rad: float) -> float:
    """Largest small-gear profile shift whose tip stays ≥ 0.25·m thick (tip thins as x grows)."""
    floor = MIN_TIP_THICKNESS_MODULES * geom.module_mm

    def margin(x: float) -> float:
        return virtual_mesh(geom, pressure_angle_rad, x).small_tip_thickness_mm - floor

    lo, hi = -1.0, 1.5  # the template's range of x
    if margin(lo) < 0.0:
        return lo
    if margin(hi) >= 0.0:
        return hi
    return float(_brentq()(margin, lo, hi, xtol=1e-6))


def min_small_shift_for_interference(geom: ConeGeometry, pressure_angle_rad: float) -> float:
    """Least small-gear shift for which the big gear's tip (shift −x) stays off the small gear's
    base circle on the line of action (the big addendum shortens as x grows)."""

    def margin(x: float) -> float:
        mesh = virtual_mesh(geom, pressure_angle_rad, x)
        return mesh.big_tip_path_limit_mm - mesh.big_tip_path_mm

    lo, hi = -1.0, 1.0
    if margin(lo) >= 0.0:
        return lo
    if margin(hi) < 0.0:
        return hi
    return float(_brentq()(margin, lo, hi, xtol=1e-6))


@dataclass(frozen=True)
class ThermalApproach:
    """Eqs (2)–(7): axial approach of the pitch circles for a temperature drop (mm, + = closer)."""

    temperature_drop_K: float  # ΔT = warm − cold
    big_axial_shrink_mm: float  # ΔL1, eq (2)
    big_diameter_shrink_mm: float  # Δd1, eq (3)
    small_axial_shrink_mm: float  # ΔL2, eq (4)
    small_diameter_shrink_mm: float  # Δd2, eq (5)
    big_approach_mm: float  # ΔS1, eq (6)
    small_approach_mm: float  # ΔS2, eq (7)


def thermal_approach(geom: ConeGeometry, *, a_mm: float, b_mm: float, l11_mm: float, l12_mm: float,
                     l2_mm: float, housing_cte_per_K: float, shaft_cte_per_K: float,
                     gear_cte_per_K: float, temperature_drop_K: float) -> ThermalApproach:
    """Eqs (2)–(7) as printed; linear in the drop, so a rise gives negative (opening) values."""
    xi1, xi2, xi3 = housing_cte_per_K, shaft_cte_per_K, gear_cte_per_K
    dT = temperature_drop_K
    big_axial = (xi1 * b_mm / 2.0 - (xi2 * l11_mm + xi3 * l12_mm)) * dT
    big_diameter = xi3 * geom.big_pitch_diameter_mm * dT
    small_axial = (xi1 * a_mm / 2.0 - xi3 * l2_mm) * dT
    small_diameter = xi3 * geom.small_pitch_diameter_mm * dT
    return ThermalApproach(
        temperature_drop_K=dT,
        big_axial_shrink_mm=big_axial,
        big_diameter_shrink_mm=big_diameter,
        small_axial_shrink_mm=small_axial,
        small_diameter_shrink_mm=small_diameter,
        big_approach_mm=big_axial - small_diameter / 2.0,
        small_approach_mm=small_axial - big_diameter / 2.0,
    )


@dataclass(frozen=True)
class BacklashChange:
    """Eqs (1), (8)–(10) for axial shifts ΔS1, ΔS2 of the two gears (mm, + = toward the mesh)."""

    big_normal_mm: float  # r1
    big_along_mm: float  # t1
    small_normal_mm: float  # r2
    small_along_mm: float  # t2
    normal_mm: float  # Δjn, eq (8)
    circumferential_mm: float  # Δjc, eq (9) as printed
    clean_circumferential_mm: float  # 2tanα(r1 + r2) + 2tan(θ/2)(t1 − t2)
    per_side_arcmin: float  # eq (10) applied to the printed Δjc
    clean_per_side_arcmin: float  # eq (10) applied to the clean Δjc


def big_gear_arcmin(circumferential_mm: float, geom: ConeGeometry) -> float:
    """Eq (10): circumferential backlash on the big gear's outer pitch circle → its angle, arcmin."""
    return circumferential_mm / (geom.big_pitch_diameter_mm / 2.0) * ARCMIN_PER_RAD


def backlash_change(geom: ConeGeometry, pressure_angle_rad: float, big_shift_mm: float,
                    small_shift_mm: float) -> BacklashChange:
    """Backlash lost by one mesh when the big gear moves ΔS1 and the small gear ΔS2 toward it."""
    delta1, delta2 = geom.big_cone_angle_rad, geom.small_cone_angle_rad
    r1 = big_shift_mm * math.sin(delta1)
    t1 = big_shift_mm * math.cos(delta1)
    r2 = small_shift_mm * math.sin(delta2)
    t2 = small_shift_mm * math.cos(delta2)
    slide_term = (t1 - t2) * geom.flank_taper
    normal = r1 + r2 + slide_term
    two_tan_alpha = 2.0 * math.tan(pressure_angle_rad)
    circumferential = two_tan_alpha * normal
    clean = two_tan_alpha * (r1 + r2) + slide_term
    return BacklashChange(
        big_normal_mm=r1,
        big_along_mm=t1,
        small_normal_mm=r2,
        small_along_mm=t2,
        normal_mm=normal,
        circumferential_mm=circumferential,
        clean_circumferential_mm=clean,
        per_side_arcmin=big_gear_arcmin(circumferential, geom),
        clean_per_side_arcmin=big_gear_arcmin(clean, geom),
    )


def shim_gain(geom: ConeGeometry, pressure_angle_rad: float, shim_mm: float) -> BacklashChange:
    """Eq (11): a shim x under the big gear moves it x away from the mesh (ΔS1 = x, ΔS2 = 0)."""
    return backlash_change(geom, pressure_angle_rad, shim_mm, 0.0)


@dataclass(frozen=True)
class DesignBacklash:
    """Total backlash between the two output shafts (two meshes, arcmin) for one shim."""

    shim_mm: float
    gain_per_side_arcmin: float  # eq (11)
    clean_gain_per_side_arcmin: float
    warm_total_min_arcmin: float
    warm_total_max_arcmin: float
    cold_total_min_arcmin: float
    cold_total_max_arcmin: float


def design_backlash(geom: ConeGeometry, pressure_angle_rad: float, shim_mm: float,
                    mesh_thinning_min_mm: float, mesh_thinning_max_mm: float,
                    cold_drop_per_side_arcmin: float) -> DesignBacklash:
    """Warm backlash = tooth thinning (eq 10) + shim gain (eq 11) on each side; cold = warm − drop."""
    gain = shim_gain(geom, pressure_angle_rad, shim_mm)
    unshimmed_min = big_gear_arcmin(mesh_thinning_min_mm, geom)
    unshimmed_max = big_gear_arcmin(mesh_thinning_max_mm, geom)
    warm_min = 2.0 * (unshimmed_min + gain.per_side_arcmin)
    warm_max = 2.0 * (unshimmed_max + gain.per_side_arcmin)
    return DesignBacklash(
        shim_mm=shim_mm,
        gain_per_side_arcmin=gain.per_side_arcmin,
        clean_gain_per_side_arcmin=gain.clean_per_side_arcmin,
        warm_total_min_arcmin=warm_min,
        warm_total_max_arcmin=warm_max,
        cold_total_min_arcmin=warm_min - 2.0 * cold_drop_per_side_arcmin,
        cold_total_max_arcmin=warm_max - 2.0 * cold_drop_per_side_arcmin,
    )


@dataclass(frozen=True)
class DifferentialResult:
    """Everything `calc` reports, in the units the names say."""

    geometry: ConeGeometry
    mesh: VirtualMesh
    approach: ThermalApproach
    cold: BacklashChange  # eqs (1), (8)–(10) for the warm → cold drop
    drop_per_side_per_K_arcmin: float  # paper form, for any other temperature
    design: DesignBacklash  # at the template's shim
    study: tuple[DesignBacklash, ...]  # at each shim of the study list
    unshimmed_warm_total_min_arcmin: float
    unshimmed_warm_total_max_arcmin: float

    @property
    def cold_drop_total_arcmin(self) -> float:
        return 2.0 * self.cold.per_side_arcmin

    @property
    def min_warm_backlash_total_arcmin(self) -> float:
        """The paper's rule: room-temperature total backlash ≥ the total cold drop."""
        return self.cold_drop_total_arcmin

    def total_backlash_at(self, temperature_C: float, warm_C: float, warm_total_arcmin: float) -> float:
        """Total backlash at another temperature: linear in the drop from warm_C (eqs 2–10)."""
        return warm_total_arcmin - 2.0 * self.drop_per_side_per_K_arcmin * (warm_C - temperature_C)


def analyse(*, module_mm: float, big_teeth: int, small_teeth: int, pressure_angle_deg: float,
            small_profile_shift: float, mesh_thinning_min_mm: float, mesh_thinning_max_mm: float,
            a_mm: float, b_mm: float, l11_mm: float, l12_mm: float, l2_mm: float,
            housing_cte_per_K: float, shaft_cte_per_K: float, gear_cte_per_K: float,
            warm_C: float, cold_C: float, shim_mm: float,
            shim_study_mm: list[float] | tuple[float, ...] = ()) -> DifferentialResult:
    """The whole model: cone geometry, thermal approach, cold drop, shim gains, design backlash."""
    geom = cone_geometry(module_mm, big_teeth, small_teeth)
    alpha = math.radians(pressure_angle_deg)
    approach = thermal_approach(
        geom, a_mm=a_mm, b_mm=b_mm, l11_mm=l11_mm, l12_mm=l12_mm, l2_mm=l2_mm,
        housing_cte_per_K=housing_cte_per_K, shaft_cte_per_K=shaft_cte_per_K,
        gear_cte_per_K=gear_cte_per_K, temperature_drop_K=warm_C - cold_C,
    )
    cold = backlash_change(geom, alpha, approach.big_approach_mm, approach.small_approach_mm)
    # The model is linear in ΔT: evaluate a 1 K drop for the per-kelvin rate.
    unit = thermal_approach(
        geom, a_mm=a_mm, b_mm=b_mm, l11_mm=l11_mm, l12_mm=l12_mm, l2_mm=l2_mm,
        housing_cte_per_K=housing_cte_per_K, shaft_cte_per_K=shaft_cte_per_K,
        gear_cte_per_K=gear_cte_per_K, temperature_drop_K=1.0,
    )
    per_K = backlash_change(geom, alpha, unit.big_approach_mm, unit.small_approach_mm).per_side_arcmin

    def design_at(shim: float) -> DesignBacklash:
        return design_backlash(geom, alpha, shim, mesh_thinning_min_mm, mesh_thinning_max_mm, cold.per_side_arcmin)

    return DifferentialResult(
        geometry=geom,
        mesh=virtual_mesh(geom, alpha, small_profile_shift),
        approach=approach,
        cold=cold,
        drop_per_side_per_K_arcmin=per_K,
        design=design_at(shim_mm),
        study=tuple(design_at(float(s)) for s in np.asarray(shim_study_mm, dtype=float)),
        unshimmed_warm_total_min_arcmin=2.0 * big_gear_arcmin(mesh_thinning_min_mm, geom),
        unshimmed_warm_total_max_arcmin=2.0 * big_gear_arcmin(mesh_thinning_max_mm, geom),
    )


def analyse_params(params, *, cold_C: float | None = None) -> DifferentialResult:
    """Run the model on a validated template (optionally at another cold temperature)."""
    g, d, m = params.gears, params.dimensions, params.materials
    return analyse(
        module_mm=g.module_mm, big_teeth=g.big_teeth, small_teeth=g.small_teeth,
        pressure_angle_deg=g.pressure_angle_deg, small_profile_shift=g.small_profile_shift,
        mesh_thinning_min_mm=params.backlash.mesh_thinning_min_mm,
        mesh_thinning_max_mm=params.backlash.mesh_thinning_max_mm,
        a_mm=d.a_mm, b_mm=d.b_mm, l11_mm=d.l11_mm, l12_mm=d.l12_mm, l2_mm=d.l2_mm,
        housing_cte_per_K=m.housing_cte_per_K, shaft_cte_per_K=m.shaft_cte_per_K,
        gear_cte_per_K=m.gear_cte_per_K,
        warm_C=params.operating.warm_C,
        cold_C=params.operating.cold_C if cold_C is None else cold_C,
        shim_mm=params.shim.thickness_mm, shim_study_mm=params.shim.study_mm,
    )


@dataclass(frozen=True)
class PerSide:
    """The paper's model per side (one big/small mesh), arcmin, at one shim and the built
    thinning (the template's least): warm and cold play in the printed and the clean form of
    eq (9), and the cold drops."""

    warm: float
    cold: float
    clean_warm: float
    clean_cold: float
    drop: float
    clean_drop: float


def model_per_side(params, shim_mm: float) -> PerSide:
    """Paper's model (eqs 1–11) per side, at the built thinning (the template's least)."""
    r = analyse_params(params)
    geom = r.geometry
    alpha = math.radians(params.gears.pressure_angle_deg)
    gain = shim_gain(geom, alpha, shim_mm)
    thinning = big_gear_arcmin(params.backlash.mesh_thinning_min_mm, geom)
    warm = thinning + gain.per_side_arcmin
    clean_warm = thinning + gain.clean_per_side_arcmin
    return PerSide(warm=warm, cold=warm - r.cold.per_side_arcmin, clean_warm=clean_warm,
                   clean_cold=clean_warm - r.cold.clean_per_side_arcmin, drop=r.cold.per_side_arcmin,
                   clean_drop=r.cold.clean_per_side_arcmin)


def _brentq():
    """scipy's root finder, imported when first needed (sweep workers import this module and never
    call it)."""
    from scipy.optimize import brentq

    return brentq
