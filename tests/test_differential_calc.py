"""The differential's analytical model (the paper's eqs (1)–(11)) through the template and the CLI.

Paper figures are acceptance targets with tolerances: the paper prints one decimal (3.4′, 6.8′),
so ±0.1′ per side and ±0.2′ total are its rounding plus the spread of the reconstructed lost
tables (CTEs and dimensions, docs/differential.md).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.figures import figures_to_json
from gearcheck.mechanism import get as mechanism
from gearcheck.params import ParamError

DIFFERENTIAL = mechanism("differential")
SECTION = DIFFERENTIAL.section

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "zhurong_differential.toml"

REQUIRED_KEYS = [
    "cold_drop_per_side_arcmin",
    "cold_drop_total_arcmin",
    "clean_cold_drop_per_side_arcmin",
    "shim_gain_per_side_arcmin",
    "shim_gain_per_side_arcmin_at_0p05mm",
    "shim_gain_per_side_arcmin_at_0p10mm",
    "shim_gain_per_side_arcmin_at_0p15mm",
    "warm_backlash_total_min_arcmin",
    "warm_backlash_total_max_arcmin",
    "cold_backlash_total_min_arcmin",
    "min_warm_backlash_total_arcmin",
    "big_gear_approach_um",
    "small_gear_approach_um",
    "big_cone_angle_deg",
    "small_cone_angle_deg",
]


def figures(*overrides: str) -> dict:
    loaded = load_template(TEMPLATE, list(overrides))
    return figures_to_json(SECTION, DIFFERENTIAL.analyse(loaded.params))[SECTION]


@pytest.fixture(scope="module")
def base() -> dict:
    return figures()


def test_cold_drop_matches_paper_in_printed_form(base):
    # Paper §2: 25 → −65 °C loses 3.4′ per side, 6.8′ for both sides (one decimal printed).
    assert base["temperature_drop_K"] == pytest.approx(90.0)
    assert base["cold_drop_per_side_arcmin"] == pytest.approx(3.4, abs=0.1)
    assert base["cold_drop_total_arcmin"] == pytest.approx(6.8, abs=0.2)
    assert base["cold_drop_total_arcmin"] == pytest.approx(2.0 * base["cold_drop_per_side_arcmin"], rel=1e-12)
    assert base["paper"]["cold_drop_per_side_arcmin"] == 3.4


def test_clean_form_is_present_and_smaller(base):
    # The clean eq (9) weights the negative slide term (t1 < t2) by 1 instead of 2·tan 20° = 0.73,
    # so it loses less: ≈3.32′; ±0.05′ covers rounding of the reconstruction.
    clean = base["clean_cold_drop_per_side_arcmin"]
    assert clean < base["cold_drop_per_side_arcmin"]
    assert clean == pytest.approx(3.32, abs=0.05)
    # Both forms share r1 + r2: they differ only by (1 − 2tanα)·2tan(θ/2)·(t1 − t2).
    slide_um = base["big_slide_um"] - base["small_slide_um"]
    taper = 2.0 * math.tan(math.radians(base["flank_taper_angle_deg"]) / 2.0)
    expected_diff_um = (1.0 - 2.0 * math.tan(math.radians(20.0))) * taper * slide_um
    got_diff_um = base["clean_circumferential_backlash_drop_um"] - base["circumferential_backlash_drop_um"]
    assert got_diff_um == pytest.approx(expected_diff_um, rel=1e-9)


def test_cone_geometry(base):
    assert base["big_cone_angle_deg"] == pytest.approx(math.degrees(math.atan(33 / 13)), abs=1e-9)
    assert base["big_cone_angle_deg"] + base["small_cone_angle_deg"] == pytest.approx(90.0, abs=1e-9)
    assert base["outer_cone_distance_mm"] == pytest.approx(44.34, abs=0.01)
    assert base["small_virtual_teeth"] == pytest.approx(13.97, abs=0.01)  # < 17: needs profile shift
    # θ: 2tan(θ/2) = πm/(2Re) → 5.07°
    assert base["flank_taper_angle_deg"] == pytest.approx(5.07, abs=0.01)


def test_approach_is_the_common_apex_form(base):
    # With b/2 = l11 + l12 + d2/2 eq (6) must equal [(ξ1−ξ2)l11 + (ξ1−ξ3)(l12 + d2/2)]ΔT, and with
    # a/2 = l2 + d1/2 eq (7) must equal (ξ1−ξ3)(a/2)ΔT: differential expansion only.
    xi1, xi2, xi3, dT = 23.6e-6, 8.8e-6, 10.8e-6, 90.0
    s1 = ((xi1 - xi2) * 12.5 + (xi1 - xi3) * (6.0 + 32.5 / 2.0)) * dT * 1000.0
    s2 = (xi1 - xi3) * (92.5 / 2.0) * dT * 1000.0
    assert base["big_gear_approach_um"] == pytest.approx(s1, rel=1e-9)
    assert base["small_gear_approach_um"] == pytest.approx(s2, rel=1e-9)


def test_one_material_everywhere_loses_no_backlash():
    # A uniform scale changes no angle: every CTE equal → no approach, no drop.
    f = figures("materials.housing_cte_per_K=10.8e-6", "materials.shaft_cte_per_K=10.8e-6")
    assert abs(f["big_gear_approach_um"]) < 1e-9
    assert abs(f["small_gear_approach_um"]) < 1e-9
    assert abs(f["cold_drop_per_side_arcmin"]) < 1e-9


@pytest.mark.parametrize("shim_key, shim_mm, expected",
                         [("0p05", 0.05, 2.92), ("0p10", 0.10, 5.84), ("0p15", 0.15, 8.76)])
def test_shim_gain_per_side(base, shim_key, shim_mm, expected):
    # Eq (11): ≈58.4′ per mm per side; ±0.1′ is the print rounding.
    per_side = base[f"shim_gain_per_side_arcmin_at_{shim_key}mm"]
    assert per_side == pytest.approx(expected, abs=0.1)
    assert base[f"shim_gain_total_arcmin_at_{shim_key}mm"] == pytest.approx(2.0 * per_side, rel=1e-12)
    # Proportional to the shim.
    assert per_side == pytest.approx(shim_mm * base["shim_gain_per_mm_per_side_arcmin"], rel=1e-9)
    assert base["shim_gain_per_side_arcmin_at_0p00mm"] == 0.0


def test_template_shim_gain_and_design_backlash(base):
    assert base["shim_gain_per_side_arcmin"] == pytest.approx(base["shim_gain_per_side_arcmin_at_0p10mm"], rel=1e-12)
    # Warm = thinning + 2·ε(shim); cold = warm − total drop, for every study shim.
    for key in ("0p00", "0p05", "0p10", "0p15"):
        warm = base[f"warm_backlash_total_min_arcmin_at_{key}mm"]
        assert warm == pytest.approx(base["unshimmed_warm_backlash_total_min_arcmin"]
                                     + base[f"shim_gain_total_arcmin_at_{key}mm"], rel=1e-12)
        assert base[f"cold_backlash_total_min_arcmin_at_{key}mm"] == pytest.approx(
            warm - base["cold_drop_total_arcmin"], rel=1e-12)
    # The paper's rule: warm total ≥ total cold drop, and the 0.10 mm design keeps > 0 cold.
    assert base["min_warm_backlash_total_arcmin"] == pytest.approx(base["cold_drop_total_arcmin"], rel=1e-12)
    assert base["warm_backlash_total_min_arcmin"] >= base["min_warm_backlash_total_arcmin"]
    assert base["cold_backlash_total_min_arcmin"] > 0.0
    assert base["cold_backlash_positive"] == 1.0


def test_unshimmed_design_binds_cold():
    # With the reconstructed thinning alone (5.2′ total < 6.8′ drop) the mesh binds: why the paper shims.
    f = figures("shim.thickness_mm=0")
    assert f["warm_backlash_total_min_arcmin"] < f["min_warm_backlash_total_arcmin"]
    assert f["cold_backlash_total_min_arcmin"] < 0.0
    assert f["cold_backlash_positive"] == 0.0
    assert "warm_backlash_total_min_arcmin" not in f.get("paper", {})  # paper's 16.8′ is for 0.10 mm


def test_drop_is_proportional_to_temperature_drop(base):
    f = figures("operating.cold_C=-130")
    assert f["temperature_drop_K"] == pytest.approx(155.0)
    assert f["cold_drop_per_side_arcmin"] == pytest.approx(base["cold_drop_per_side_arcmin"] * 155.0 / 90.0, rel=1e-9)
    assert f["clean_cold_drop_per_side_arcmin"] == pytest.approx(
        base["clean_cold_drop_per_side_arcmin"] * 155.0 / 90.0, rel=1e-9)
    # The storage figure at −130 °C must agree with a cold design point at −130 °C.
    assert base["backlash_total_min_at_storage_min_arcmin"] == pytest.approx(f["cold_backlash_total_min_arcmin"],
                                                                             rel=1e-9)
    assert "cold_drop_per_side_arcmin" not in f.get("paper", {})  # the paper's 3.4′ is for 90 K
    same = figures("operating.cold_C=25")
    assert same["cold_drop_per_side_arcmin"] == 0.0


def test_set_overrides_apply():
    f = figures("shim.thickness_mm=0.15", "gears.small_profile_shift=0.3")
    assert f["shim_gain_per_side_arcmin"] == pytest.approx(f["shim_gain_per_side_arcmin_at_0p15mm"], rel=1e-12)
    assert f["small_tip_thickness_mm"] > figures()["small_tip_thickness_mm"]  # less shift, thicker tip
    g = figures("shim.study_mm=[0.2]")
    assert "shim_gain_per_side_arcmin_at_0p20mm" in g and "shim_gain_per_side_arcmin_at_0p05mm" not in g


@pytest.mark.parametrize(
    "override, field, words",
    [
        ("operating.cold_C=-200", "operating.cold_C", ["-150", "25"]),
        ("operating.warm_C=0", "operating.cold_C", ["warm_C"]),  # cold −65 is fine, so lift it:
        ("gears.teeth=3", "gears.teeth", ["unknown key", "big_teeth"]),
        ('gears.module_mm="abc"', "gears.module_mm", ["wrong type", "0.5 to 10.0 mm"]),
        ("gears.small_profile_shift=0", "gears.small_profile_shift", ["undercut", "0.183"]),
        ("gears.small_profile_shift=0.8", "gears.small_profile_shift", ["pointed", "0.625"]),
        ("gears.face_width_mm=16", "gears.face_width_mm", ["14.77", "cone distance"]),
        ("gears.shaft_angle_deg=80", "gears.shaft_angle_deg", ["90"]),
        ("dimensions.b_mm=75", "dimensions.b_mm", ["69.500", "apex"]),
        ("shim.thickness_mm=2", "shim.thickness_mm", ["0.0 to 1.0 mm"]),
        ("materials.housing_cte_per_K=-1e-6", "materials.housing_cte_per_K", ["1/K"]),
    ],
)
def test_bad_inputs_name_field_and_range(override, field, words):
    overrides = [override]
    if override == "operating.warm_C=0":
        overrides.append("operating.cold_C=10")
    with pytest.raises(ParamError) as info:
        load_template(TEMPLATE, overrides)
    err = info.value
    assert err.field == field
    text = str(err)
    assert "\n" not in text and str(TEMPLATE) in text
    for w in words:
        assert w in text, (w, text)


def test_zero_warm_backlash_rejected():
    with pytest.raises(ParamError) as info:
        load_template(TEMPLATE, ["shim.thickness_mm=0", "backlash.mesh_thinning_min_mm=0"])
    assert info.value.field == "backlash.mesh_thinning_min_mm"


def test_cli_json_has_required_keys(capsys):
    assert main(["calc", str(TEMPLATE), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)[SECTION]
    for key in REQUIRED_KEYS:
        assert isinstance(data[key], float), key
    assert data["paper"]["cold_drop_total_arcmin"] == 6.8


def test_cli_table_and_bad_input(capsys):
    assert main(["calc", str(TEMPLATE), "--set", "operating.cold_C=-130"]) == 0
    out = capsys.readouterr().out
    assert "cold backlash drop per side" in out and "155.0" in out
    assert main(["calc", str(TEMPLATE), "--set", "operating.cold_C=-200"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "operating.cold_C = -200" in err
