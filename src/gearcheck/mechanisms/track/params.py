"""Template model of the track-drive sprocket: every input of the paper, nothing derived.

Field ranges are physical limits; the cross-field rules (a tooth left between adjacent grooves,
the ISO 606 seating limits, a tip land left under the tip circle, widths that fit) live in
:class:`Params` and each raise one :class:`ParamError` naming the field, the value and the allowed
range computed from the other inputs. Last, the model builds the layout the CAD
builds from (:mod:`.layout`: sprocket spec with its bore, link section, default chain wrap), so a
set the CAD could not build is rejected before any CAD work. An even tooth count is valid (every
other tooth engaging works with any z); `gearcheck check` warns about it (verdict
``odd_tooth_count``).
"""

from __future__ import annotations

from pydantic import Field, model_validator

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.mechanisms.track import analysis, layout
from gearcheck.params import ParamError, Section
from gearcheck.params.problems import Problems
from gearcheck.params.common import fmt_bound, fmt_range

MIN_TEETH = 7
MAX_TEETH = 301
TIP_GAP_MIN_MM = 0.05
PITCH_MAX_MM = 500


def _f(lo=None, hi=None, *, gt=None, lt=None, unit="", description=""):
    return Field(ge=lo, le=hi, gt=gt, lt=lt, description=description, json_schema_extra={"unit": unit})


# The mechanism's scope, named where a roller-chain-like input is refused on a geometric reason.
SCOPE = "the paper's articulated track: grooves every half pitch"
ROLLER_CHAIN = f"({SCOPE}; for a standard roller chain use mechanism = \"roller_chain\")"

# Rows that leave less than this (mm) for each groove fill the track: a groove, which must be
# wider than 0, has no bound left to meet, so the tooth width is the field to change.
GROOVE_ROOM_MIN_MM = 1e-6

class Robot(Section):
    mass_kg: float = _f(gt=0, hi=100_000, unit="kg", description="total mass incl. payload")
    speed_m_s: float = _f(gt=0, hi=50, unit="m/s", description="design travel speed v")
    slope_deg: float = _f(0, lt=90, unit="°", description="slope the robot is meant to climb, α")
    tracks: int = _f(1, 16, description="tracks sharing the load, n")
    g_m_s2: float = _f(0.1, 30, unit="m/s²", description="gravity")


class Ground(Section):
    adhesion_coefficient: float = _f(gt=0, hi=2, description="adhesion coefficient φ")
    rolling_resistance_coefficient: float = _f(0, 1, description="rolling resistance coefficient f")


class Chain(Section):
    """The paper's articulated track: grooves every half pitch, a link's two pins two grooves apart,
    every other tooth engaging (its dimensions named with the ISO 606 symbols in brackets). Not a
    standard roller chain: for one, use mechanism = "roller_chain"."""

    pitch_mm: float = _f(gt=0, hi=PITCH_MAX_MM, unit="mm",
                         description="track pitch p: a link's pins sit two grooves apart (an articulated track, "
                                     "grooves every half pitch; a standard roller chain is mechanism roller_chain)")
    sleeve_diameter_mm: float = _f(gt=0, hi=200, unit="mm", description="sleeve (roller) diameter dR [d1]")
    pin_diameter_mm: float = _f(gt=0, hi=100, unit="mm", description="track pin diameter d")
    sleeve_inner_width_mm: float = _f(gt=0, hi=500, unit="mm",
                                      description="b1: sleeve length between the supporting lugs [b1]")
    pin_support_span_mm: float = _f(gt=0, hi=500, unit="mm",
                                    description="b2: span of a pin segment between its supports [b2]")
    pin_segments: int = _f(1, 8, description="pin segments, each a simply supported beam (one per tooth row)")
    track_width_mm: float = _f(gt=0, hi=2000, unit="mm", description="track width")
    wear_elongation_pct: float = Field(
        1.5, ge=0, le=25, json_schema_extra={"unit": "%"},
        description="pitch growth by wear the drive must tolerate, in % of p (sprocket unchanged, every link "
                    "p·(1 + e)); default 1.5 %: the usual roller-chain replacement point for drives with up to "
                    "60 teeth (maker practice, e.g. Tsubaki, FB Chain), half the 3 % ceiling of ANSI B29.1 / "
                    "ISO 606 practice; see docs/track.md")


class Sprocket(Section):
    teeth: int = _f(MIN_TEETH, MAX_TEETH,
                    description="teeth z, one groove per tooth, grooves every half track pitch (odd: every other "
                                "tooth engages and each takes its turn; even: accepted with a warning)")
    initial_pitch_diameter_mm: float = _f(gt=0, hi=10_000, unit="mm",
                                          description="first estimate of d that z is solved from")
    tip_over_pitch_mm: float = _f(0, 100, unit="mm", description="short-tooth rule: de = d + this")
    seating_radius_mm: float = _f(gt=0, hi=100, unit="mm", description="chosen seating radius ri (ρf)")
    flank_radius_mm: float = _f(gt=0, hi=100_000, unit="mm", description="chosen flank radius re")
    seating_angle_deg: float = _f(gt=90, lt=180, unit="°", description="chosen seating angle α")
    tooth_width_mm: float = _f(gt=0, hi=500, unit="mm", description="width of one tooth row bf1")
    tooth_rows: int = _f(1, 4, description="rows of teeth")
    middle_groove_width_mm: float = _f(0, 500, unit="mm",
                                       description="annular groove between rows for the guide lugs")


class TrackPlate(Section):
    tip_gap_mm: float = _f(TIP_GAP_MIN_MM, 5, unit="mm",
                           description="chosen gap from tooth tip to a seated link's plate")
    required_gap_min_mm: float = _f(0, 5, unit="mm",
                                    description="required gap from the tooth tip to the track plate, lower end")
    required_gap_max_mm: float = _f(0, 5, unit="mm",
                                    description="required gap from the tooth tip to the track plate, upper end")


class Materials(Section):
    sprocket_E_MPa: float = _f(1_000, 500_000, unit="MPa", description="sprocket modulus E2 (7075-T651)")
    sprocket_poisson: float = _f(0, lt=0.5, description="sprocket Poisson ratio μ2")
    sleeve_E_MPa: float = _f(1_000, 500_000, unit="MPa", description="sleeve modulus E1")
    sleeve_poisson: float = _f(0, lt=0.5, description="sleeve Poisson ratio μ1")


class Strength(Section):
    pin_allowable_shear_MPa: float = _f(gt=0, hi=5_000, unit="MPa", description="pin [τ] (stainless)")
    allowable_crush_stress_MPa: float = _f(gt=0, hi=10_000, unit="MPa",
                                           description="allowable Hertz crush stress of the sprocket groove")
    loaded_tooth_rows: int = _f(1, 4, description="tooth rows assumed to carry the load at one groove")


class Params(Section):
    robot: Robot
    ground: Ground
    chain: Chain
    sprocket: Sprocket
    track_plate: TrackPlate
    materials: Materials
    strength: Strength

    @model_validator(mode="after")
    def _cross_checks(self) -> Params:
        """Independent rules are named together (one line each); a rule that needs earlier ones
        to hold (the ISO ranges need a tooth between the grooves, the tip land needs the ranges, the
        CAD's layout needs all of them) comes after them."""
        s, c = self.sprocket, self.chain
        z, p, dr = s.teeth, c.pitch_mm, c.sleeve_diameter_mm
        with Problems() as found:
            if not c.pin_diameter_mm < dr:
                found.add("chain.pin_diameter_mm", c.pin_diameter_mm,
                          f"allowed < sleeve diameter {fmt_bound(dr, 'upper', None)} mm (the pin runs inside the "
                          "sleeve)")
            if not s.initial_pitch_diameter_mm > p:
                found.add("sprocket.initial_pitch_diameter_mm", s.initial_pitch_diameter_mm,
                          f"allowed > chain pitch {fmt_bound(p, 'lower', None)} mm")
            d = iso606.every_other_tooth_pitch_diameter(p, z)
            chord = iso606.groove_chord(d, z)
            lim = iso606.seating_limits(dr, z)
            before = len(found.errors)
            # No tooth is left when even the smallest ISO seating circles (0.505·dR) of adjacent
            # grooves touch.
            if not lim.seating_radius_min_mm * 2.0 < chord:
                def leaves_tooth(v: float) -> bool:
                    return iso606.seating_limits(v, z).seating_radius_min_mm * 2.0 < chord

                dr_max = fmt_bound(chord / 1.01, "upper", ok=leaves_tooth, strict=True)
                if not float(dr_max) > 0:  # no sleeve fits: the pitch is what is out of range
                    found.extend(_pitch_leaves_no_tooth(z, p, dr, chord))
                else:
                    found.add("chain.sleeve_diameter_mm", dr,
                              f"allowed < {dr_max} mm at z = {z}, p = {p:g} mm: seating circles "
                              f"(0.505·dR) of adjacent grooves {chord:.3f} mm apart must leave a tooth {ROLLER_CHAIN}")
            else:
                self._check_iso_ranges(lim, chord, found)
            if len(found.errors) == before:  # the tip land is drawn from a valid groove form
                try:
                    self._check_tip_land(d)
                except ParamError as exc:
                    found.extend(exc)
            self._check_widths_and_loads(found)
        self._check_buildable()
        return self

    def _check_iso_ranges(self, lim: iso606.SeatingLimits, chord: float, found: Problems) -> None:
        """The chosen ri, re and α within their ISO 606 limits (each on its own)."""
        s, dr, z = self.sprocket, self.chain.sleeve_diameter_mm, self.sprocket.teeth
        ri_hi = min(lim.seating_radius_max_mm, 0.5 * chord)
        if not lim.seating_radius_min_mm <= s.seating_radius_mm <= ri_hi:
            bound = ("" if ri_hi == lim.seating_radius_max_mm
                     else f" (capped at half the groove chord {chord:.3f} mm) {ROLLER_CHAIN}")
            found.add("sprocket.seating_radius_mm", s.seating_radius_mm,
                      f"allowed {fmt_range(lim.seating_radius_min_mm, ri_hi)} mm: ISO 606 limits "
                      f"for dR = {dr:g} mm{bound}")
        if not lim.flank_radius_min_mm <= s.flank_radius_mm <= lim.flank_radius_max_mm:
            found.add("sprocket.flank_radius_mm", s.flank_radius_mm,
                      f"allowed {fmt_range(lim.flank_radius_min_mm, lim.flank_radius_max_mm, 2)} mm: "
                      f"ISO 606 limits for dR = {dr:g} mm, z = {z}")
        if not lim.seating_angle_min_deg <= s.seating_angle_deg <= lim.seating_angle_max_deg:
            found.add("sprocket.seating_angle_deg", s.seating_angle_deg,
                      f"allowed {fmt_range(lim.seating_angle_min_deg, lim.seating_angle_max_deg, 2)}°: "
                      f"ISO 606 limits for z = {z}")

    def _check_widths_and_loads(self, found: Problems) -> None:
        """Tooth width, rows and track width; loaded rows; adhesion; the required gap window (each on
        its own)."""
        s, c = self.sprocket, self.chain
        p = c.pitch_mm
        bf_max = iso606.iso_tooth_width_max(c.sleeve_inner_width_mm, p)
        pitch_named = any(e.field == "chain.pitch_mm" for e in found.errors)  # bf1 max follows from p
        if not pitch_named and not s.tooth_width_mm <= bf_max:
            found.add("sprocket.tooth_width_mm", s.tooth_width_mm,
                      f"allowed <= {fmt_bound(bf_max, 'upper')} mm: ISO 606 bf1 max for "
                      f"b1 = {c.sleeve_inner_width_mm:g} mm")
        if not c.sleeve_inner_width_mm < c.pin_support_span_mm:
            b2 = fmt_bound(c.pin_support_span_mm, "upper", None)
            found.add("chain.sleeve_inner_width_mm", c.sleeve_inner_width_mm,
                      f"allowed < pin support span b2 = {b2} mm")
        total = s.tooth_rows * s.tooth_width_mm + (s.tooth_rows - 1) * s.middle_groove_width_mm
        if not total <= c.track_width_mm:
            found.extend(self._width_error(total))
        if not self.strength.loaded_tooth_rows <= s.tooth_rows:
            found.add("strength.loaded_tooth_rows", self.strength.loaded_tooth_rows,
                      f"allowed 1 to {s.tooth_rows} (sprocket.tooth_rows)")
        g = self.ground
        if not g.adhesion_coefficient > g.rolling_resistance_coefficient:
            f = fmt_bound(g.rolling_resistance_coefficient, "lower", None)
            found.add("ground.adhesion_coefficient", g.adhesion_coefficient,
                      f"allowed > rolling resistance f = {f} (else the track has no drive force)")
        t = self.track_plate
        if not t.required_gap_min_mm <= t.required_gap_max_mm:
            gap_max = fmt_bound(t.required_gap_max_mm, "upper", None)
            found.add("track_plate.required_gap_min_mm", t.required_gap_min_mm,
                      f"allowed <= required_gap_max_mm = {gap_max} mm")

    def _width_error(self, total: float) -> ParamError:
        """Rows and grooves wider than the track: the middle groove's own bound when the rows
        alone leave room for grooves, else the tooth width's (rows that fill the track to a
        rounding leave the grooves, which must be > 0, no bound to meet)."""
        s, width = self.sprocket, self.chain.track_width_mm
        n, bf, groove = s.tooth_rows, s.tooth_width_mm, s.middle_groove_width_mm
        grooves = f"{n - 1} groove{'s' if n > 2 else ''}"
        parts = f"{n} rows and {grooves} span" if n > 1 else "the tooth row spans"
        span = f"{parts} {total:g} mm, more than the track width {width:g} mm"
        if n > 1 and (width - n * bf) / (n - 1) > GROOVE_ROOM_MIN_MM:  # the rows leave room for grooves
            def fits(v: float) -> bool:
                return n * bf + (n - 1) * v <= width

            groove_max = fmt_bound((width - n * bf) / (n - 1), "upper", ok=fits)
            return ParamError("sprocket.middle_groove_width_mm", groove,
                              f"allowed <= {groove_max} mm with {n} rows of {bf:g} mm: {span}")
        if (n - 1) * groove < width:
            def rows_fit(v: float) -> bool:
                return n * v + (n - 1) * groove <= width

            bf_fit = fmt_bound((width - (n - 1) * groove) / n, "upper", ok=rows_fit)
            with_grooves = f" with {n} rows and {groove:g} mm grooves" if n > 1 else ""
            return ParamError("sprocket.tooth_width_mm", bf, f"allowed <= {bf_fit} mm{with_grooves}: {span}")
        return ParamError("sprocket.middle_groove_width_mm", groove,
                          f"allowed < {fmt_bound(width / (n - 1), 'upper', strict=True)} mm: the {grooves} alone "
                          f"span the track width {width:g} mm")

    def _check_buildable(self) -> None:
        """Build the layout `gearcheck build` builds its solids from (:mod:`.layout`, the same
        functions), so a set the CAD cannot build stops here; each failure names its field."""
        s, c = self.sprocket, self.chain
        z, p = s.teeth, c.pitch_mm
        try:
            spec = layout.sprocket_spec(self)
        except iso606.ToothFormError as exc:  # _check_tip_land rejects these first; kept as a guard
            raise ParamError("sprocket.seating_radius_mm", s.seating_radius_mm, f"no valid tooth: {exc}") from None
        except layout.RowsWithoutGroove:
            raise ParamError("sprocket.middle_groove_width_mm", s.middle_groove_width_mm,
                             f"allowed > 0 mm with {s.tooth_rows} tooth rows: the guide-lug groove separates the "
                             "rows (for one wide row, set tooth_rows = 1)") from None
        except layout.BoreTooLarge:
            bore, depth = layout.BORE_DIAMETER_MM, layout.MIDDLE_GROOVE_DEPTH_MM

            def fits(teeth: int) -> bool:
                d = iso606.every_other_tooth_pitch_diameter(p, teeth)
                return layout.hub_radius_mm(d, s.seating_radius_mm) > bore / 2.0

            # (the chain wrap, checked next, needs enough teeth too: the least count passes both)
            allowed = _allowed_teeth(z, lambda n: fits(n) and _wrap_fits(n, p))
            raise ParamError("sprocket.teeth", z,
                             f"{allowed} at p = {p:g} mm: the {bore:g} mm shaft bore must lie under the "
                             f"middle groove floor, {depth:g} mm below the root circle (sprocket too small) "
                             f"{ROLLER_CHAIN}") from None
        try:
            layout.default_wrap(z, p)
        except ValueError as exc:
            allowed = _allowed_teeth(z, lambda n: _wrap_fits(n, p))
            raise ParamError("sprocket.teeth", z,
                             f"{allowed}: the chain segment built at θ = 0 "
                             f"({layout.DEFAULT_WRAP_ANGLE_DEG:g}° wrap plus {layout.DEFAULT_RUN_LINKS} links on "
                             f"each run) does not fit: {exc} {ROLLER_CHAIN}") from None
        try:
            layout.link_geometry(self, spec.gap)
        except ValueError:
            raise self._link_error(spec.gap) from None

    def _link_error(self, gap: iso606.ToothGap) -> ParamError:
        """The plate face (e outside the pin line, set by the tip gap) must cut the sleeve far
        enough for the plate to sit on it: tip gaps between the two e limits of the link."""
        c, t = self.chain, self.track_plate
        e_at_zero_gap = analysis.plate_offset_for_tip_gap(gap, 0.0)
        e_max = _largest_joining_offset(c.pitch_mm, c.sleeve_diameter_mm, c.track_width_mm)
        gap_lo, gap_hi = max(-e_at_zero_gap, TIP_GAP_MIN_MM), e_max - e_at_zero_gap
        if gap_lo < gap_hi:
            def joins(v: float) -> bool:
                return _joins(c.pitch_mm, c.sleeve_diameter_mm, analysis.plate_offset_for_tip_gap(gap, v),
                              c.track_width_mm)

            return ParamError("track_plate.tip_gap_mm", t.tip_gap_mm,
                              f"allowed {fmt_range(gap_lo, gap_hi, lo_ok=joins, hi_ok=joins)} mm: the link plate's "
                              f"face (e = tip gap + "
                              f"{e_at_zero_gap:.3f} mm outside the pin line) must cut the {c.sleeve_diameter_mm:g} mm "
                              "sleeve deep enough to join it")
        # No tip gap works: the sleeve is too thin. Smallest sleeve that joins at the least gap.
        e_needed = e_at_zero_gap + TIP_GAP_MIN_MM
        lo, hi = c.sleeve_diameter_mm, 2.0 * e_needed + 10.0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if _largest_joining_offset(c.pitch_mm, mid, c.track_width_mm) > e_needed else (mid, hi)
        def joins_at_least_gap(v: float) -> bool:
            return _largest_joining_offset(c.pitch_mm, v, c.track_width_mm) > e_needed

        dr_min = fmt_bound(hi, "lower", ok=joins_at_least_gap, strict=True)
        return ParamError("chain.sleeve_diameter_mm", c.sleeve_diameter_mm,
                          f"allowed > {dr_min} mm: a thinner sleeve cannot join the link plate, whose face lies "
                          f"{e_needed:.3f} mm outside the pin line at the least tip gap {TIP_GAP_MIN_MM} mm")


    def _check_tip_land(self, d: float) -> None:
        """The tip circle must cut the flanks below the point where adjacent flanks meet."""
        s = self.sprocket
        limit = iso606.tip_land_limit_diameter(d, s.teeth, s.seating_radius_mm, s.flank_radius_mm,
                                               s.seating_angle_deg)
        if not d + s.tip_over_pitch_mm < limit:
            if limit <= d:
                raise ParamError("sprocket.tip_over_pitch_mm", s.tip_over_pitch_mm,
                                 f"no value >= 0 allowed: the flanks of adjacent grooves meet "
                                 f"{(d - limit) / 2:.3f} mm below the pitch circle (sleeve "
                                 f"{self.chain.sleeve_diameter_mm:g} mm too large for the "
                                 f"{iso606.groove_chord(d, s.teeth):.3f} mm groove chord with this ri, re, α) "
                                 f"{ROLLER_CHAIN}")
            raise ParamError("sprocket.tip_over_pitch_mm", s.tip_over_pitch_mm,
                             f"allowed < {fmt_bound(limit - d, 'upper', ok=lambda v: d + v < limit, strict=True)} mm: "
                             "the flanks of adjacent grooves meet "
                             f"{(limit - d) / 2:.3f} mm above the pitch circle, no tip land above that {ROLLER_CHAIN}")
        try:
            iso606.tooth_gap(d, s.teeth, s.seating_radius_mm, s.flank_radius_mm, s.seating_angle_deg,
                             d + s.tip_over_pitch_mm)
        except iso606.ToothFormError as exc:  # not reachable inside the ISO limits; kept as a guard
            raise ParamError("sprocket.seating_radius_mm", s.seating_radius_mm, f"no valid tooth: {exc}") from None


def _pitch_leaves_no_tooth(z: int, p: float, dr: float, chord: float) -> ParamError:
    """The rejection of a pitch so small that no sleeve diameter leaves a tooth between adjacent
    grooves: the pitch named, with the smallest pitch that leaves one for this sleeve. The groove
    chord grows in proportion to the pitch."""
    needed = iso606.seating_limits(dr, z).seating_radius_min_mm * 2.0

    def leaves_tooth(v: float) -> bool:
        return needed < iso606.groove_chord(iso606.every_other_tooth_pitch_diameter(v, z), z)

    per_mm = iso606.groove_chord(iso606.every_other_tooth_pitch_diameter(1.0, z), z)
    p_min = fmt_bound(needed / per_mm, "lower", ok=leaves_tooth, strict=True)
    return ParamError("chain.pitch_mm", p,
                      f"out of range: allowed >{p_min} to {PITCH_MAX_MM} mm at z = {z}, dR = {dr:g} mm: seating "
                      f"circles (0.505·dR) of adjacent grooves {chord:.3g} mm apart must leave a tooth {ROLLER_CHAIN}")


def _largest_joining_offset(pitch_mm: float, sleeve_diameter_mm: float, track_width_mm: float) -> float:
    """Largest plate offset e for which :func:`track_chain.link_geometry` builds a link (it builds
    for e in (0, e_max)); 0 if none."""

    def joins(e: float) -> bool:
        return _joins(pitch_mm, sleeve_diameter_mm, e, track_width_mm)

    lo, hi = 0.0, sleeve_diameter_mm / 2.0
    if not joins(hi * 1e-9):
        return 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if joins(mid) else (lo, mid)
    return lo


def _joins(pitch_mm: float, sleeve_diameter_mm: float, plate_offset_mm: float, track_width_mm: float) -> bool:
    """Whether :func:`track_chain.link_geometry` builds a link with this plate offset e."""
    try:
        tc.link_geometry(pitch_mm, sleeve_diameter_mm, plate_offset_mm, track_width_mm)
    except ValueError:
        return False
    return True


def _allowed_teeth(z: int, fits) -> str:
    """The tooth counts above ``z`` that ``fits`` (more teeth: a larger sprocket): the least odd
    one, and the least even one where that is smaller (even z is accepted with a warning: the same
    z/2 teeth take every engagement)."""
    odd = next((n for n in range(z + 1, MAX_TEETH + 1) if n % 2 and fits(n)), None)
    even = next((n for n in range(z + 1, MAX_TEETH + 1) if not n % 2 and fits(n)), None)
    if odd is None:
        return f"no count up to {MAX_TEETH} allowed" if even is None else f"allowed even {even} to {MAX_TEETH - 1}"
    also = f" (or even {even} up, with the even-z warning)" if even is not None and even < odd else ""
    return f"allowed odd {odd} to {MAX_TEETH}{also}"


def _wrap_fits(teeth: int, pitch_mm: float) -> bool:
    try:
        layout.default_wrap(teeth, pitch_mm)
    except ValueError:
        return False
    return True
