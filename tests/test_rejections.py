"""Every rejection found by the reliability review, one test each, on the shipped templates with `--set`: the
error is one ParamError line naming the exact field, its value and an allowed range.

The rejections that stand in for a CAD failure also show the failure they prevent: the same set,
built WITHOUT validation, makes the pure layout the CAD builds from (gear specs, sprocket and
link layout, pinion and rack outlines) raise or come out self-intersecting. And where the message
gives a bound, a value just inside it passes that rule.
"""

from __future__ import annotations

import copy
import math
import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzz_support import draw_set
from gearcheck.design import load_template
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.steering import analysis as steering_analysis
from gearcheck.params import ParamError, validate
from gearcheck.params.common import apply_overrides, fmt_bound, fmt_range, read_toml

DIFF = "zhurong_differential.toml"
TRACK = "eod_track_drive.toml"
STEER = "nose_wheel_steering.toml"


def rejected(templates_dir, name: str, *overrides: str) -> ParamError:
    """The ParamError for this template and overrides; checks the one-line form."""
    with pytest.raises(ParamError) as info:
        load_template(templates_dir / name, list(overrides))
    exc = info.value
    text = str(exc)
    # one line per broken rule (independent rules are named together), the first one's fields on exc
    assert text.startswith(f"{templates_dir / name}: {exc.field} = "), text
    assert all(line.startswith(f"{templates_dir / name}: ") for line in text.splitlines()), text
    assert "allowed" in exc.allowed, text
    return exc


def assert_rejects(templates_dir, name, overrides, field, *needles) -> ParamError:
    exc = rejected(templates_dir, name, *overrides)
    assert exc.field == field, str(exc)
    for needle in needles:
        assert needle in str(exc), str(exc)
    return exc


def bound(exc: ParamError, op: str) -> float:
    """The number after ``allowed <op>`` (or the upper end of ``allowed a to b`` for '<=')."""
    if op == "to":
        return float(re.search(r"allowed >?(-?[\d.]+) to (-?[\d.]+)", exc.allowed).group(2))
    return float(re.search(rf"allowed {re.escape(op)} ?(-?[\d.]+)", exc.allowed).group(1))


def unchecked(templates_dir, name: str, *overrides: str):
    """The Params object of a template and overrides built WITHOUT validation (what the CAD would
    receive if the model did not reject the set)."""
    data = apply_overrides(read_toml(templates_dir / name), list(overrides))
    model = mechanism(data["mechanism"]).Params
    sections = {k: model.model_fields[k].annotation.model_construct(**v) for k, v in data.items() if k != "mechanism"}
    return model.model_construct(**sections)


def differential_set(module_mm=2.5, big=33, small=13, shift=0.39, pressure_deg=20.0, l2=5.0, l11=12.5, l12=6.0,
                     face_width_mm=None) -> list[str]:
    """Overrides for a differential that keeps the common apex (a, b from l2, l11, l12); face
    width 0.3·Re unless given."""
    cone = module_mm * math.hypot(big, small) / 2.0
    face = face_width_mm if face_width_mm is not None else round(0.3 * cone, 3)
    return [f"gears.module_mm={module_mm}", f"gears.big_teeth={big}", f"gears.small_teeth={small}",
            f"gears.small_profile_shift={shift}", f"gears.pressure_angle_deg={pressure_deg}",
            f"gears.face_width_mm={face}",
            f"dimensions.l2_mm={l2}", f"dimensions.a_mm={round(2 * (l2 + module_mm * big / 2), 4)}",
            f"dimensions.l11_mm={l11}", f"dimensions.l12_mm={l12}",
            f"dimensions.b_mm={round(2 * (l11 + l12 + module_mm * small / 2), 4)}"]


# ------------------------------------------------------------------------ undercut
def test_undercut_small_bevel_gear(templates_dir):
    exc = assert_rejects(templates_dir, DIFF, ["gears.small_profile_shift=0.0"], "gears.small_profile_shift",
                         "= 0.0:", "undercut")
    low = float(re.search(r"allowed (-?[\d.]+) to", exc.allowed).group(1))
    load_template(templates_dir / DIFF, [f"gears.small_profile_shift={low + 0.01:.3f}"])


def test_undercut_steering_pinion(templates_dir):
    exc = assert_rejects(templates_dir, STEER, ["pinion.teeth=16", "pinion.pressure_angle_deg=20"], "pinion.teeth",
                         "= 16:", "undercut")
    assert bound(exc, ">=") == 22


# -------------------------------------------------------------------- pointed teeth
def test_pointed_small_bevel_gear(templates_dir):
    exc = assert_rejects(templates_dir, DIFF, ["gears.small_profile_shift=0.8"], "gears.small_profile_shift",
                         "pointed", "0.25·m")
    high = float(re.search(r"to (-?[\d.]+)", exc.allowed).group(1))
    load_template(templates_dir / DIFF, [f"gears.small_profile_shift={high - 0.01:.3f}"])


def test_pointed_steering_pinion(templates_dir):
    overrides = ["pinion.profile_shift=1.0", "pinion.addendum_coefficient=1.5", "rack.dedendum_coefficient=2"]
    exc = assert_rejects(templates_dir, STEER, overrides, "pinion.addendum_coefficient", "pointed", "0.25·m")
    ha = bound(exc, "<=")
    g = steering_analysis.geometry_from_params(unchecked(templates_dir, STEER, *overrides))
    assert 2 * g.tip_radius * float(g.involute_half_angle(g.tip_radius)) < 0.25 * g.module_mm
    # just inside the bound the tip land is at least 0.25·m
    g_ok = steering_analysis.with_inputs(g, pinion_addendum_coefficient=ha - 1e-6)
    assert 2 * g_ok.tip_radius * float(g_ok.involute_half_angle(g_ok.tip_radius)) >= 0.25 * g.module_mm - 1e-9


def test_pointed_rack_teeth(templates_dir):
    assert_rejects(templates_dir, STEER, ["rack.addendum_coefficient=1.45", "pinion.dedendum_coefficient=1.6"],
                   "rack.addendum_coefficient", "pointed rack teeth", "allowed <= 1.416")


# -------------------------------------------------------------------- contact ratio
def test_contact_ratio_below_one_at_the_trim(templates_dir):
    exc = assert_rejects(templates_dir, STEER, ["trim.hS4_mm=24.0"], "trim.hS4_mm", "contact ratio >= 1")
    an = steering_analysis
    g = an.geometry_from_params(unchecked(templates_dir, STEER, "trim.hS4_mm=24.0"))
    assert an.contact_ratio(g, 24.0) < 1.0
    low = float(re.search(r"allowed >([\d.]+) to", exc.allowed).group(1))
    assert an.contact_ratio(g, low) == pytest.approx(1.0, abs=1e-3)


def test_contact_ratio_below_one_untrimmed(templates_dir):
    overrides = ["pinion.addendum_coefficient=0.5", "rack.addendum_coefficient=0.5", "pinion.pressure_angle_deg=35",
                 "pinion.dedendum_coefficient=1.0", "rack.dedendum_coefficient=1.0"]
    assert_rejects(templates_dir, STEER, overrides, "rack.addendum_coefficient", "contact ratio is 0.670 < 1")


# ------------------------------------------------------------------- bevel face width
def test_bevel_face_width_over_a_third_of_the_cone_distance(templates_dir):
    exc = assert_rejects(templates_dir, DIFF, ["gears.face_width_mm=20"], "gears.face_width_mm",
                         "= 20.0:", "one third of the outer cone distance")
    third = 2.5 * math.hypot(33, 13) / 2 / 3  # Re/3, Re = 2.5·√(33² + 13²)/2 = 44.335 mm
    assert third - 0.01 < bound(exc, "<=") <= third  # rounded down (inward): 14.77
    load_template(templates_dir / DIFF, [f"gears.face_width_mm={bound(exc, '<=') - 0.01:.2f}"])


# ------------------------------------------------------------------- sleeve vs pitch
def test_sleeve_too_large_for_the_pitch(templates_dir):
    """No tooth left between adjacent seating arcs: 2·0.505·dR reaches the 15.031 mm groove chord."""
    exc = assert_rejects(templates_dir, TRACK, ["chain.sleeve_diameter_mm=16"], "chain.sleeve_diameter_mm",
                         "= 16.0:", "must leave a tooth")
    assert bound(exc, "<") == pytest.approx(15.031 / 1.01, abs=1e-3)


# --------------------------------------------------------------- negative warm backlash
def test_negative_warm_backlash(templates_dir):
    assert_rejects(templates_dir, DIFF, ["backlash.mesh_thinning_min_mm=0.0", "shim.thickness_mm=0.0"],
                   "backlash.mesh_thinning_min_mm", "warm backlash", "binds")


# ---------------------------------------------------- trims the pinion tip cannot clear
@pytest.mark.parametrize("override", ["trim.hS8_mm=26.9", "trim.hS6_mm=26.5"])
def test_a_trimmed_top_above_its_tangent_is_a_design_to_check_not_bad_input(templates_dir, override):
    """A top G1's tip land would catch is a result of the design: the check's interference
    verdicts fail it (tests/test_steering_stop_rule.py), the template loads."""
    design = load_template(templates_dir / STEER, [override])
    calc = {f.key: f.value for f in design.calc().figures}
    assert calc["hS6_max_mm"] == pytest.approx(26.075, abs=1e-3)  # the limit calc reports, unchanged


# --------------------------------------------------------------------- unknown keys
@pytest.mark.parametrize("name, override, field", [
    (DIFF, "gears.modul_mm=2.5", "gears.modul_mm"),
    (TRACK, "chain.pitch_in=1.2", "chain.pitch_in"),
    (STEER, "gearbox.ratio=3", "gearbox"),
])
def test_unknown_keys_via_set(templates_dir, name, override, field):
    exc = rejected(templates_dir, name, override)
    assert exc.field == field and "unknown key (allowed keys here:" in exc.allowed


def test_unknown_key_in_a_template_file(tmp_path, templates_dir):
    path = tmp_path / "extra.toml"
    path.write_text((templates_dir / DIFF).read_text().replace("[gears]", "[gears]\nface_width_in = 0.55"))
    with pytest.raises(ParamError) as info:
        load_template(path)
    assert info.value.field == "gears.face_width_in"
    assert "face_width_mm" in str(info.value)  # the known keys, with the unit the field wants


# ------------------------------------------------------------ wrong units or types
@pytest.mark.parametrize("override, field, needle", [
    ('gears.module_mm="2.5 mm"', "gears.module_mm", "wrong type"),
    ("gears.module_mm=2.5mm", "gears.module_mm", "wrong type"),
    ("gears.big_teeth=33.0", "gears.big_teeth", "wrong type"),
    ("gears.module_mm=true", "gears.module_mm", "wrong type"),
    ("shim.study_mm=0.1", "shim.study_mm", "wrong type"),
    ("operating.cold_C=nan", "operating.cold_C", "finite"),
    ("gears.module_mm=" + str(10**400), "gears.module_mm", "larger than any float"),
])
def test_wrong_types_via_set(templates_dir, override, field, needle):
    exc = rejected(templates_dir, DIFF, override)
    assert exc.field == field and needle in exc.allowed


@pytest.mark.parametrize("old, new, field", [
    ("module_mm = 2.5", 'module_mm = "2.5 mm"', "gears.module_mm"),
    ("big_teeth = 33", "big_teeth = 33.5", "gears.big_teeth"),
    ("thickness_mm = 0.10", "thickness_mm = 1e-1", None),  # a float spelt differently is fine
    ("cold_C = -65.0", "cold_C = -inf", "operating.cold_C"),
    ("cold_C = -65.0", "cold_C = 208.15", "operating.cold_C"),  # kelvin in a °C field: out of range
])
def test_wrong_units_or_types_in_a_template_file(tmp_path, templates_dir, old, new, field):
    text = (templates_dir / DIFF).read_text()
    assert old in text
    path = tmp_path / "units.toml"
    path.write_text(text.replace(old, new, 1))
    if field is None:
        load_template(path)
        return
    with pytest.raises(ParamError) as info:
        load_template(path)
    assert info.value.field == field
    assert "allowed" in info.value.allowed


# ====================================================================================
# Rejections that stand in for a CAD failure (the same set would stop `gearcheck build`)
def test_big_gear_body_behind_its_root(templates_dir):
    from gearcheck.mechanisms.differential.poses import gear_specs

    overrides = ["dimensions.l12_mm=1.0", "dimensions.b_mm=59.5"]
    exc = assert_rejects(templates_dir, DIFF, overrides, "dimensions.l12_mm", "outer root")
    with pytest.raises(ValueError, match="mounting_distance_mm"):
        gear_specs(unchecked(templates_dir, DIFF, *overrides))
    l12 = bound(exc, ">=") + 0.01
    load_template(templates_dir / DIFF, [f"dimensions.l12_mm={l12}", f"dimensions.b_mm={2 * (12.5 + l12 + 16.25)}"])


def test_small_gear_mounting_face_behind_its_root(templates_dir):
    from gearcheck.mechanisms.differential.poses import gear_specs

    overrides = ["dimensions.l2_mm=0.2", "dimensions.a_mm=82.9"]
    exc = assert_rejects(templates_dir, DIFF, overrides, "dimensions.l2_mm", "outer root")
    with pytest.raises(ValueError, match="mounting_distance_mm"):
        gear_specs(unchecked(templates_dir, DIFF, *overrides))
    l2 = bound(exc, ">=") + 0.01
    load_template(templates_dir / DIFF, [f"dimensions.l2_mm={l2}", f"dimensions.a_mm={2 * (l2 + 41.25)}"])


def test_bevel_gear_bores_under_the_roots(templates_dir):
    from gearcheck.mechanisms.differential.poses import gear_specs

    overrides = differential_set(module_mm=1.5, face_width_mm=7.9)
    exc = assert_rejects(templates_dir, DIFF, overrides, "gears.module_mm", "bores")
    with pytest.raises(ValueError, match="front_face"):
        gear_specs(unchecked(templates_dir, DIFF, *overrides))
    # the bound holds the other inputs (the face width sets the inner end) fixed
    load_template(templates_dir / DIFF, differential_set(module_mm=round(bound(exc, ">=") + 0.005, 3), face_width_mm=7.9))


def test_bevel_face_cone_too_flat(templates_dir):
    from gearcheck.mechanisms.differential.poses import gear_specs

    overrides = differential_set(big=112, small=11, shift=0.3, pressure_deg=25)
    exc = assert_rejects(templates_dir, DIFF, overrides, "gears.big_teeth", "face angle >= 85°")
    with pytest.raises(ValueError, match="face cone"):
        gear_specs(unchecked(templates_dir, DIFF, *overrides))
    assert bound(exc, "<=") == 109


def test_sprocket_too_small_for_its_bore(templates_dir):
    from gearcheck.mechanisms.track import layout

    overrides = ["chain.pitch_mm=10", "sprocket.teeth=17", "chain.sleeve_diameter_mm=3", "chain.pin_diameter_mm=1",
                 "sprocket.seating_radius_mm=1.6", "sprocket.flank_radius_mm=10", "sprocket.seating_angle_deg=125",
                 "sprocket.initial_pitch_diameter_mm=30", "sprocket.tooth_width_mm=10"]
    exc = assert_rejects(templates_dir, TRACK, overrides, "sprocket.teeth", "bore", "allowed odd 25 to 301")
    with pytest.raises(ValueError, match="bore"):
        layout.sprocket_spec(unchecked(templates_dir, TRACK, *overrides))
    assert exc.value == 17


def test_chain_segment_must_not_wrap_round(templates_dir):
    from gearcheck.mechanisms.track import layout

    overrides = ["sprocket.teeth=13", "sprocket.flank_radius_mm=18"]
    assert_rejects(templates_dir, TRACK, overrides, "sprocket.teeth", "allowed odd 15 to 301", "wrap all the way round")
    with pytest.raises(ValueError, match="wrap"):
        layout.default_wrap(13, 30.0)
    layout.default_wrap(15, 30.0)


def test_link_plate_must_join_the_sleeve(templates_dir):
    from gearcheck.mechanisms.track import layout

    exc = assert_rejects(templates_dir, TRACK, ["track_plate.tip_gap_mm=4"], "track_plate.tip_gap_mm", "join")
    with pytest.raises(ValueError, match="plate offset"):
        layout.track_layout(unchecked(templates_dir, TRACK, "track_plate.tip_gap_mm=4"))
    load_template(templates_dir / TRACK, [f"track_plate.tip_gap_mm={bound(exc, 'to') - 0.01:.3f}"])


def test_sleeve_too_thin_for_the_link_plate(templates_dir):
    overrides = ["chain.sleeve_diameter_mm=2.5", "chain.pin_diameter_mm=1", "sprocket.seating_radius_mm=1.3",
                 "sprocket.flank_radius_mm=30", "track_plate.tip_gap_mm=0.05"]
    assert_rejects(templates_dir, TRACK, overrides, "chain.sleeve_diameter_mm", "thinner sleeve cannot join")


def test_pinion_root_circle_must_clear_its_bore(templates_dir):
    from gearcheck.mechanisms.steering import layout

    exc = assert_rejects(templates_dir, STEER, ["pinion.module_mm=1"], "pinion.teeth", "60 mm pinion bore")
    g = steering_analysis.geometry_from_params(unchecked(templates_dir, STEER, "pinion.module_mm=1"))
    assert not layout.bore_fits(g.root_radius)
    assert bound(exc, ">=") == 63  # r − 1.25·m > 30 mm at m = 1: z > 62.5


def test_pinion_root_land_needs_a_blunt_cutter(templates_dir):
    """hf·tan α ≥ π/4: the generating rack's tip is pointed and adjacent fillets cross."""
    from gearcheck.geometry.rack_pinion import pinion_root_land_start

    exc = assert_rejects(templates_dir, STEER, ["pinion.dedendum_coefficient=1.8"], "pinion.dedendum_coefficient",
                         "no root land")
    assert bound(exc, "<") == pytest.approx(math.pi / 4 / math.tan(math.radians(25)), abs=1e-3)
    g = steering_analysis.geometry_from_params(
        unchecked(templates_dir, STEER, "pinion.dedendum_coefficient=1.8"))
    assert pinion_root_land_start(g) > g.angular_pitch / 2  # the root lands of neighbours overlap


def test_rack_teeth_must_leave_a_root_space(templates_dir):
    exc = assert_rejects(templates_dir, STEER, ["rack.dedendum_coefficient=1.8"], "rack.dedendum_coefficient",
                         "no tooth space")
    g = steering_analysis.geometry_from_params(
        unchecked(templates_dir, STEER, "rack.dedendum_coefficient=1.8"))
    left, right = g.rack_tooth_polygon(0), g.rack_tooth_polygon(1)
    assert left[1, 0] > right[0, 0]  # bottom-right of one tooth beyond bottom-left of the next
    assert bound(exc, "<") == pytest.approx(math.pi / 4 / math.tan(math.radians(25)), abs=1e-3)


# ====================================================================================
# Printed bounds are rounded inward: the number a message prints after 'allowed' is itself
# accepted (a closed bound) or has the values just beyond it, towards the range, accepted (an open
# bound ">x", "<x": checked 1e-9 inside) — or, if another rule then fails, that
# rejection names another field.
NUMBER = r"(-?\d+(?:\.\d+)?)"
RANGE = re.compile(rf"allowed (?:odd )?(>?){NUMBER} to (<?){NUMBER}")
ONE_SIDED = re.compile(rf"allowed (>=|<=|>|<) ?{NUMBER}(?![\w.])")


def printed_bounds(allowed: str) -> list[tuple[str, str, bool]]:
    """(number as printed, 'lower' | 'upper', open) for each bound printed after 'allowed'."""
    m = RANGE.search(allowed)
    if m:
        return [(m.group(2), "lower", m.group(1) == ">"), (m.group(4), "upper", m.group(3) == "<")]
    m = ONE_SIDED.search(allowed)
    if m:
        return [(m.group(2), "lower" if m.group(1).startswith(">") else "upper", len(m.group(1)) == 1)]
    return []


def bound_value(text: str, side: str, is_open: bool, integer: bool):
    """The value to try for a printed bound: the bound itself (closed) or, open, a hair inside it
    (1e-9 relative: far below any printed digit, above float underflow: '> 0' is not '> 5e-324')."""
    if integer:
        assert not is_open and "." not in text, text
        return int(text)
    x = float(text)
    if not is_open:
        return x
    step = 1e-9 * max(abs(x), 1.0)
    return x + step if side == "lower" else x - step


def keep_apex(data: dict) -> None:
    """A differential body's housing lengths a, b moved with the gears and lengths they depend on
    (the messages say 'change a_mm / b_mm with it'), in the model's own arithmetic."""
    g, d = data["gears"], data["dimensions"]
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in
               (g.get("module_mm"), g.get("big_teeth"), g.get("small_teeth"), d.get("l11_mm"), d.get("l12_mm"),
                d.get("l2_mm"))):
        return
    d["b_mm"] = 2.0 * (d["l11_mm"] + d["l12_mm"] + g["module_mm"] * g["small_teeth"] / 2.0)
    d["a_mm"] = 2.0 * (d["l2_mm"] + g["module_mm"] * g["big_teeth"] / 2.0)


APEX_INPUTS = {"gears.module_mm", "gears.big_teeth", "gears.small_teeth", "dimensions.l11_mm", "dimensions.l12_mm",
               "dimensions.l2_mm"}


def _set(data: dict, field: str, value) -> None:
    node = data
    *parents, last = field.split(".")
    for name in parents:
        node = node[int(name)] if isinstance(node, list) else node[name]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value


def bounds_hold(mech_model, data: dict, exc: ParamError, source: str = "") -> int:
    """Set the rejected field of ``data`` to each bound ``exc`` prints and validate again: accepted
    or rejected on another field. Returns how many bounds were tried."""

    bounds = printed_bounds(exc.allowed)
    integer = isinstance(exc.value, int) and not isinstance(exc.value, bool)
    for text, side, is_open in bounds:
        trial = copy.deepcopy(data)
        _set(trial, exc.field, bound_value(text, side, is_open, integer))
        if exc.field in APEX_INPUTS:
            keep_apex(trial)
        try:
            validate(mech_model, trial, source)
        except ParamError as again:
            assert again.field != exc.field, f"{exc}\n  at the printed {side} bound {text}: {again}"
    return len(bounds)


@pytest.mark.parametrize("name, overrides, field", [
    (DIFF, ["gears.small_profile_shift=0.0"], "gears.small_profile_shift"),  # undercut: both ends
    (DIFF, ["gears.small_profile_shift=0.8"], "gears.small_profile_shift"),  # pointed small gear
    (DIFF, differential_set(big=10, small=10, shift=-0.6, pressure_deg=30), "gears.small_profile_shift"),  # big tip
    (DIFF, ["gears.face_width_mm=20"], "gears.face_width_mm"),
    (DIFF, ["dimensions.b_mm=70.0"], "dimensions.b_mm"),
    (DIFF, ["dimensions.a_mm=93"], "dimensions.a_mm"),
    (DIFF, ["dimensions.l12_mm=1.0", "dimensions.b_mm=59.5"], "dimensions.l12_mm"),
    (DIFF, ["dimensions.l2_mm=0.2", "dimensions.a_mm=82.9"], "dimensions.l2_mm"),
    (DIFF, differential_set(module_mm=1.5, face_width_mm=7.9), "gears.module_mm"),
    (DIFF, differential_set(big=112, small=11, shift=0.3, pressure_deg=25), "gears.big_teeth"),
    (TRACK, ["sprocket.seating_angle_deg=117"], "sprocket.seating_angle_deg"),
    (TRACK, ["sprocket.seating_angle_deg=139"], "sprocket.seating_angle_deg"),
    (TRACK, ["sprocket.seating_radius_mm=4.2"], "sprocket.seating_radius_mm"),
    (TRACK, ["sprocket.flank_radius_mm=200"], "sprocket.flank_radius_mm"),
    (TRACK, ["sprocket.tooth_width_mm=10.5"], "sprocket.tooth_width_mm"),
    (TRACK, ["sprocket.tip_over_pitch_mm=13"], "sprocket.tip_over_pitch_mm"),
    (TRACK, ["sprocket.middle_groove_width_mm=300"], "sprocket.middle_groove_width_mm"),
    (TRACK, ["sprocket.tooth_width_mm=10", "chain.track_width_mm=19"], "sprocket.tooth_width_mm"),
    (TRACK, ["chain.sleeve_diameter_mm=16"], "chain.sleeve_diameter_mm"),
    (TRACK, ["track_plate.tip_gap_mm=4"], "track_plate.tip_gap_mm"),
    (TRACK, ["chain.sleeve_diameter_mm=2.5", "chain.pin_diameter_mm=1", "sprocket.seating_radius_mm=1.3",
             "sprocket.flank_radius_mm=30", "track_plate.tip_gap_mm=0.05"], "chain.sleeve_diameter_mm"),
    (TRACK, ["chain.pitch_mm=10", "sprocket.teeth=17", "chain.sleeve_diameter_mm=3", "chain.pin_diameter_mm=1",
             "sprocket.seating_radius_mm=1.6", "sprocket.flank_radius_mm=10", "sprocket.seating_angle_deg=125",
             "sprocket.initial_pitch_diameter_mm=30", "sprocket.tooth_width_mm=10"], "sprocket.teeth"),
    (TRACK, ["sprocket.teeth=13", "sprocket.flank_radius_mm=18"], "sprocket.teeth"),
    (STEER, ["pinion.teeth=16", "pinion.pressure_angle_deg=20"], "pinion.teeth"),
    (STEER, ["pinion.profile_shift=1.0", "pinion.addendum_coefficient=1.5", "rack.dedendum_coefficient=2"],
     "pinion.addendum_coefficient"),
    (STEER, ["rack.addendum_coefficient=1.45", "pinion.dedendum_coefficient=1.6"], "rack.addendum_coefficient"),
    (STEER, ["pinion.addendum_coefficient=0.5", "rack.addendum_coefficient=0.5", "pinion.pressure_angle_deg=25",
             "pinion.dedendum_coefficient=1.0", "rack.dedendum_coefficient=1.0"], "rack.addendum_coefficient"),
    (STEER, ["pinion.addendum_coefficient=0.5", "rack.addendum_coefficient=0.5", "pinion.pressure_angle_deg=20",
             "pinion.dedendum_coefficient=1.0", "rack.dedendum_coefficient=1.0"], "rack.addendum_coefficient"),
    (STEER, ["trim.hS4_mm=24.0"], "trim.hS4_mm"),
    (STEER, ["trim.hS2_mm=28"], "trim.hS2_mm"),
    (STEER, ["trim.min_contact_ratio=3"], "trim.min_contact_ratio"),
    (STEER, ["pinion.topped_radius_mm=90"], "pinion.topped_radius_mm"),
    (STEER, ["layout.centre_to_datum_mm=80"], "layout.centre_to_datum_mm"),
    (STEER, ["pinion.module_mm=1"], "pinion.teeth"),
    (STEER, ["pinion.module_mm=0.1"], "pinion.module_mm"),
    (STEER, ["pinion.dedendum_coefficient=1.8"], "pinion.dedendum_coefficient"),
    (STEER, ["rack.dedendum_coefficient=1.8"], "rack.dedendum_coefficient"),
])
def test_printed_bounds_are_accepted(templates_dir, name, overrides, field):
    exc = rejected(templates_dir, name, *overrides)
    assert exc.field == field, str(exc)
    data = apply_overrides(read_toml(templates_dir / name), overrides)
    model = mechanism(data.pop("mechanism")).Params
    assert bounds_hold(model, data, exc) >= 1, str(exc)


def test_seating_angle_bound_of_the_report(templates_dir):
    """The reported case: 120° − 90°/49 = 118.1633° once printed as 118.16, which was rejected."""
    exc = assert_rejects(templates_dir, TRACK, ["sprocket.seating_angle_deg=117"], "sprocket.seating_angle_deg",
                         "allowed 118.17 to 138.16°")
    load_template(templates_dir / TRACK, ["sprocket.seating_angle_deg=118.17"])
    load_template(templates_dir / TRACK, ["sprocket.seating_angle_deg=138.16"])
    with pytest.raises(ParamError):
        load_template(templates_dir / TRACK, ["sprocket.seating_angle_deg=118.16"])
    assert exc.value == 117.0


def test_fmt_bound_rounds_inward():
    assert fmt_bound(120 - 90 / 49, "lower", 2) == "118.17"
    assert fmt_bound(140 - 90 / 49, "upper", 2) == "138.16"
    assert fmt_bound(0.505 * 8, "lower") == fmt_bound(0.505 * 8, "upper") == "4.040"  # on the grid: as it is
    assert fmt_bound(-1e-4, "lower") == "0.000"  # no '-0.000'
    assert fmt_bound(-1e-4, "upper") == "-0.001"
    assert fmt_bound(8.5, "upper", None) == "8.5" and fmt_bound(0.1 + 0.2, "lower", None) == repr(0.1 + 0.2)
    # ok: the rule's own test moves the bound inward
    assert fmt_bound(1.2344, "upper", ok=lambda v: v <= 1.2335) == "1.233"
    assert fmt_bound(1.2344, "upper", ok=lambda v: v < 1.234, strict=True) == "1.234"
    # a range narrower than the printed unit gets more digits, ends still in order
    assert fmt_range(0.1231, 0.1236) == "0.1231 to 0.1236"
    assert fmt_range(1.0, 2.0, lo_open=True) == ">1.000 to 2.000"
    for x in (0.1, 1 / 3, 2.675, 118.16326530612245, -7.0005, 1e-7):
        for digits in (0, 1, 2, 3, 5):
            assert float(fmt_bound(x, "lower", digits)) >= x
            assert float(fmt_bound(x, "upper", digits)) <= x


# ---------------------------------------------------------- the same over random sets
BOUNDS = settings(derandomize=True, deadline=None, database=None,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def _random_bounds_hold(mech: str, data) -> None:
    body = draw_set(mech, data)
    model = mechanism(mech).Params
    try:
        validate(model, body, "fuzz.toml")
    except ParamError as exc:
        # computed bounds only: a field's own Field(ge, le) range is printed exactly (field_range)
        # and knows no cross-field rule
        own_range = exc.allowed.startswith(("out of range", "wrong type", "must be a finite number"))
        if exc.field and not isinstance(exc.value, dict) and not own_range:
            bounds_hold(model, body, exc, "fuzz.toml")


@settings(BOUNDS, max_examples=300)
@given(data=st.data())
def test_printed_bounds_hold_on_random_differential_sets(data):
    _random_bounds_hold("differential", data)


@settings(BOUNDS, max_examples=300)
@given(data=st.data())
def test_printed_bounds_hold_on_random_track_sets(data):
    _random_bounds_hold("track", data)


@settings(BOUNDS, max_examples=300)
@given(data=st.data())
def test_printed_bounds_hold_on_random_steering_sets(data):
    _random_bounds_hold("steering", data)


def test_rows_filling_the_track_blame_the_tooth_width(templates_dir):
    """Three rows of 10.03 mm in a 30.09 mm track fill it to a rounding: the grooves (which must
    be > 0) have no bound left, so the rejection names the tooth width, and its bound holds."""
    data = apply_overrides(read_toml(templates_dir / "eod_track_drive.toml"),
                           ["sprocket.tooth_rows=3", "sprocket.tooth_width_mm=10.03", "chain.track_width_mm=30.09",
                            "sprocket.middle_groove_width_mm=1e-9", "strength.loaded_tooth_rows=1"])
    data.pop("mechanism", None)
    model = mechanism("track").Params
    with pytest.raises(ParamError) as info:
        validate(model, data, "rows.toml")
    assert info.value.field == "sprocket.tooth_width_mm", info.value
    assert bounds_hold(model, data, info.value, "rows.toml") >= 1
