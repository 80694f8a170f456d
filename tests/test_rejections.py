"""Every rejection found by the reliability review, one test each, on the shipped templates with `--set`: the
error is one ParamError line naming the exact field, its value and an allowed range.

The rejections that stand in for a CAD failure also show the failure they prevent: the same set,
built WITHOUT validation, makes the pure layout the CAD builds from (gear specs, sprocket and
link layout, pinion and rack outlines) raise or come out self-intersecting. And where the message
gives a bound, a value just inside it passes that rule.
"""

from __future__ import annotations

import math
import re

import pytest

from gearcheck.design import load_template
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.steering import analysis as steering_analysis
from gearcheck.params import ParamError
from gearcheck.params.common import apply_overrides, read_toml

DIFF = "zhurong_differential.toml"
TRACK = "eod_track_drive.toml"
STEER = "nose_wheel_steering.toml"


def rejected(templates_dir, name: str, *overrides: str) -> ParamError:
    """The ParamError for this template and overrides; checks the one-line form."""
    with pytest.raises(ParamError) as info:
        load_template(templates_dir / name, list(overrides))
    exc = info.value
    text = str(exc)
    assert "\n" not in text
    assert text.startswith(f"{templates_dir / name}: {exc.field} = "), text
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
    assert bound(exc, "<=") == pytest.approx(44.34 / 3, abs=0.01)  # Re = 2.5·√(33² + 13²)/2
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
def test_trim_s8_above_the_tip_circle_tangent(templates_dir):
    exc = assert_rejects(templates_dir, STEER, ["trim.hS8_mm=26.9"], "trim.hS8_mm", "cannot clear")
    calc = {f.key: f.value for f in load_template(templates_dir / STEER).calc().figures
            if f.key == "hS8_max_mm"}
    assert bound(exc, "to") == pytest.approx(calc["hS8_max_mm"], abs=1e-3)  # the figure calc reports
    load_template(templates_dir / STEER, [f"trim.hS8_mm={bound(exc, 'to') - 0.01:.3f}"])


def test_trim_s6_above_the_topped_tip_tangent(templates_dir):
    exc = assert_rejects(templates_dir, STEER, ["trim.hS6_mm=26.5"], "trim.hS6_mm", "cannot clear")
    assert bound(exc, "to") == pytest.approx(26.075, abs=1e-3)


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
