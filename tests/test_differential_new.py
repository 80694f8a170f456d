"""`gearcheck new differential --module M --teeth SMALL/BIG`: the derived template against the cone
geometry and the design rules recomputed here, independently of the code (docs/differential.md,
"A design of your own"); the file loads as written with a note beside every value; --set values
are inputs of the derivation; a design of your own shows no paper values anywhere (calc, its
JSON, and — ``cad`` — summary.json and the report), the paper's own unit keeps them; and broken
rules of one kind are named together, one line each."""

from __future__ import annotations

import json
import math
import re
import tomllib

import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.differential import PAPER, is_paper_design
from gearcheck.params import ParamError, ParamErrors

DIFFERENTIAL = mechanism("differential")
DESIGNS = [(3.0, 14, 30), (2.0, 16, 40)]
IDS = ["m3-14-30", "m2-16-40"]
ARCMIN_PER_RAD = 10800.0 / math.pi


def written(tmp_path, m: float, small: int, big: int, *overrides: str) -> tuple[dict, str]:
    out = tmp_path / f"d_m{m:g}_{small}_{big}.toml"
    args = ["new", "differential", "--module", f"{m:g}", "--teeth", f"{small}/{big}", "--out", str(out)]
    for o in overrides:
        args += ["--set", o]
    assert main(args) == 0
    text = out.read_text(encoding="utf-8")
    return tomllib.loads(text), text


def cone(m: float, small: int, big: int) -> dict:
    """The pitch cones of a 90° pair, from the module and the tooth counts."""
    d1, d2 = m * big, m * small
    delta1 = math.atan(big / small)
    re_mm = 0.5 * math.sqrt(d1 * d1 + d2 * d2)
    return {"d1": d1, "d2": d2, "delta1": delta1, "delta2": math.pi / 2 - delta1, "Re": re_mm,
            "taper": math.pi * m / (2.0 * re_mm)}  # 2·tan(θ/2): πm/2 of tooth over Re


@pytest.mark.parametrize("m, small, big", DESIGNS, ids=IDS)
def test_the_derived_dimensions_follow_the_cone_geometry(tmp_path, templates_dir, m, small, big):
    data, _ = written(tmp_path, m, small, big)
    g, dim, bl, shim = data["gears"], data["dimensions"], data["backlash"], data["shim"]
    c = cone(m, small, big)
    assert (g["module_mm"], g["small_teeth"], g["big_teeth"]) == (m, small, big)
    # the common apex: b/2 = l11 + l12 + d2/2, a/2 = l2 + d1/2 (exactly, not within the tolerance)
    assert dim["a_mm"] == pytest.approx(2 * (dim["l2_mm"] + c["d1"] / 2), abs=1e-9)
    assert dim["b_mm"] == pytest.approx(2 * (dim["l11_mm"] + dim["l12_mm"] + c["d2"] / 2), abs=1e-9)
    # lengths: the shaft with the cone distance, the bodies with the module, on a 0.5 mm grid
    assert dim["l11_mm"] == round(0.28 * c["Re"] / 0.5) * 0.5
    assert dim["l12_mm"] == round(2.4 * m / 0.5) * 0.5 and dim["l2_mm"] == round(2 * m / 0.5) * 0.5
    # face width: the largest whole mm within Re/3 and 10·m
    limit = min(c["Re"] / 3, 10 * m)
    assert g["face_width_mm"] == math.floor(limit)
    # Gleason's long addendum: the big gear's addendum 0.54·m + 0.46·m·zv2/zv1 of a 2·m working depth
    zv1, zv2 = big / math.cos(c["delta1"]), small / math.cos(c["delta2"])
    assert g["small_profile_shift"] == round(1 - (0.54 + 0.46 * zv2 / zv1), 2)
    assert (g["pressure_angle_deg"], g["shaft_angle_deg"]) == (20.0, 90.0)
    # the environment is the paper's unit's, as the shipped template holds it; no measurement, no target
    template = tomllib.loads((templates_dir / "zhurong_differential.toml").read_text(encoding="utf-8"))
    assert data["materials"] == template["materials"] and data["operating"] == template["operating"]
    assert "calibration" not in data and "targets" not in data
    # the shim: eq (11)'s gain covers eq (10)'s cold drop, on the 0.05 mm steps of the paper's test
    mat, op = data["materials"], data["operating"]
    xi1, xi2, xi3 = mat["housing_cte_per_K"], mat["shaft_cte_per_K"], mat["gear_cte_per_K"]
    drop_K = op["warm_C"] - op["cold_C"]
    s1 = ((xi1 - xi2) * dim["l11_mm"] + (xi1 - xi3) * (dim["l12_mm"] + c["d2"] / 2)) * drop_K  # eq (6), apex form
    s2 = (xi1 - xi3) * (dim["a_mm"] / 2) * drop_K  # eq (7)
    alpha = math.radians(20.0)
    normal = (s1 * math.sin(c["delta1"]) + s2 * math.sin(c["delta2"])
              + (s1 * math.cos(c["delta1"]) - s2 * math.cos(c["delta2"])) * c["taper"])  # eq (8)
    drop = 2 * math.tan(alpha) * normal / (c["d1"] / 2) * ARCMIN_PER_RAD  # eqs (9), (10)
    gain_mm_per_mm = 2 * math.tan(alpha) * (math.sin(c["delta1"]) + c["taper"] * math.cos(c["delta1"]))  # eq (11)
    gain_per_mm = gain_mm_per_mm / (c["d1"] / 2) * ARCMIN_PER_RAD
    assert shim["thickness_mm"] == pytest.approx(math.ceil(drop / gain_per_mm / 0.05) * 0.05, abs=1e-9)
    around = {round(shim["thickness_mm"] + k * 0.05, 6) for k in (-1, 0, 1)}
    assert shim["study_mm"] == pytest.approx(sorted({0.0} | {s for s in around if s >= 0}))
    # the thinning: the standard backlash (ISO/TR 10064-2's least normal backlash, circumferential) less
    # what the shim gives; its band an eighth of the standard backlash
    allowance = 2 / 3 * (0.06 + 0.0005 * c["Re"] + 0.03 * m) / math.cos(alpha)
    thinning = allowance - gain_mm_per_mm * shim["thickness_mm"]
    assert thinning > allowance / 4
    assert bl["mesh_thinning_min_mm"] == pytest.approx(thinning, abs=5e-5)
    assert bl["mesh_thinning_max_mm"] == pytest.approx(thinning + allowance / 8, abs=1e-4)


@pytest.mark.parametrize("m, small, big", DESIGNS, ids=IDS)
def test_the_file_loads_as_written_with_a_note_beside_every_value(tmp_path, m, small, big):
    data, text = written(tmp_path, m, small, big)
    assert text.splitlines()[0] == "#:schema ./schema/differential.json"
    section, open_array = None, False
    for line in text.splitlines():
        if open_array:  # a list written over several lines: its note follows the closing bracket
            open_array = not line.startswith("]")
            assert open_array or " # " in line, line
        elif line.startswith("["):
            section = line
        elif section and "=" in line and not line.startswith("#"):
            open_array = line.rstrip().endswith("[")
            assert open_array or " # " in line, line  # every value of every section says how it was found
    for needle in ("# common apex: a/2 = l2 + d1/2", "# common apex: b/2 = l11 + l12 + d2/2", "Gleason",
                   "ISO/TR 10064-2", "the paper's rule", "Re/3"):
        assert needle in text, needle
    design = load_template(next(tmp_path.glob("*.toml")))
    assert design.params == gearcheck.new("differential", module=m, teeth=f"{small}/{big}").params
    assert design.params.thinning().calibrated is False  # the design's own backlash, not a measured unit's


def test_the_papers_gear_set_gives_the_shipped_reconstruction(tmp_path, templates_dir):
    """The rules applied to the paper's module and tooth counts give the shipped template's gears and
    lengths (read from the file) and its shim; the thinning is the design's own, not a measurement's."""
    template = tomllib.loads((templates_dir / "zhurong_differential.toml").read_text(encoding="utf-8"))
    g = template["gears"]
    data, _ = written(tmp_path, g["module_mm"], g["small_teeth"], g["big_teeth"])
    assert data["gears"] == g and data["dimensions"] == template["dimensions"]
    assert data["shim"]["thickness_mm"] == template["shim"]["thickness_mm"]
    assert data["shim"]["study_mm"] == template["shim"]["study_mm"]
    assert not is_paper_design(load_template(next(tmp_path.glob("*.toml"))).params)  # no measured unit


def test_set_values_are_inputs_of_the_derivation(tmp_path):
    data, text = written(tmp_path, 3.0, 14, 30, "dimensions.l2_mm=8", "dimensions.b_mm=90",
                         "gears.pressure_angle_deg=25")
    dim, g = data["dimensions"], data["gears"]
    c = cone(3.0, 14, 30)
    assert dim["a_mm"] == pytest.approx(2 * (8 + c["d1"] / 2))  # a from the l2 set
    assert dim["b_mm"] == 90 and dim["l11_mm"] == pytest.approx(90 / 2 - dim["l12_mm"] - c["d2"] / 2)  # l11 from b
    zv1, zv2 = 30 / math.cos(c["delta1"]), 14 / math.cos(c["delta2"])
    assert g["small_profile_shift"] == round(1 - (0.54 + 0.46 * zv2 / zv1), 2)  # Gleason's rule is α-free
    assert "pressure_angle_deg = 25" in text and "standard involute" not in text
    assert "l2_mm = 8" in text and re.search(r"l2_mm = 8\S* +# set with --set", text)
    allowance = 2 / 3 * (0.06 + 0.0005 * c["Re"] + 0.09) / math.cos(math.radians(25))  # α moves the allowance
    assert f"standard backlash {allowance * 1e3:.1f} µm" in text


@pytest.mark.parametrize("args, words", [
    (["--module", "3", "--teeth", "30/14"], ["--teeth = '30/14'", "small <= big"]),
    (["--module", "3", "--teeth", "14"], ["--teeth = '14'", "2 whole numbers (small/big)"]),
    (["--module", "1", "--teeth", "14/30"], ["--module = 1.0: allowed >= ", "gear bores"]),
    (["--module", "3", "--teeth", "14/30", "--set", "gears.big_teeth=31"], ["gears.big_teeth", "--teeth"]),
])
def test_numbers_that_admit_no_design_are_one_line_exit_2(tmp_path, capsys, args, words):
    out = tmp_path / "x.toml"
    assert main(["new", "differential", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    for w in words:
        assert w in err, (w, err)
    assert not out.exists()


def test_the_module_bound_printed_is_a_design():
    with pytest.raises(ParamError) as info:
        gearcheck.new("differential", module=1, teeth="14/30")
    least = float(re.search(r"allowed >= ([\d.]+)", info.value.allowed).group(1))
    assert gearcheck.new("differential", module=least, teeth="14/30").params.gears.module_mm == least


# -- paper values beside the paper's own unit only -------------------------------------------------

def test_a_design_of_your_own_has_no_paper_values_in_calc(tmp_path, capsys):
    written(tmp_path, 3.0, 14, 30)
    path = next(tmp_path.glob("*.toml"))
    design = load_template(path)
    assert not is_paper_design(design.params)
    figures = design.calc().figures
    assert all(f.paper is None for f in figures)
    capsys.readouterr()
    assert main(["calc", str(path), "--json"]) == 0
    body = json.loads(capsys.readouterr().out)[DIFFERENTIAL.section]
    assert not [k for k in body if "paper" in k]  # no `paper` section, no paper-model keys
    assert main(["calc", str(path)]) == 0
    table = capsys.readouterr().out
    header = next(line for line in table.splitlines() if line.lstrip().startswith("quantity"))
    assert "paper" not in header and "diff" not in header
    assert "≥ 10" not in table and "reconstructed thinning" not in table


def test_the_papers_unit_keeps_its_values_and_any_change_drops_them(templates_dir):
    template = load_template(templates_dir / "zhurong_differential.toml")
    assert is_paper_design(template.params)
    shown = {f.key: f.paper for f in template.calc().figures if f.paper is not None}
    assert set(shown.values()) <= set(PAPER.values())
    assert set(PAPER) <= set(shown)  # every printed figure, at the paper's own conditions
    assert all(shown[k] == PAPER[k] for k in PAPER)
    for change in ("gears.face_width_mm=13", "dimensions.l2_mm=6", "materials.gear_cte_per_K=11e-6",
                   "backlash.mesh_thinning_max_mm=0.05", "calibration.measured_at_C=20"):
        overrides = [change] + (["dimensions.a_mm=94.5"] if change.startswith("dimensions.l2") else [])
        other = load_template(templates_dir / "zhurong_differential.toml", overrides)
        assert not is_paper_design(other.params), change
        assert all(f.paper is None for f in other.calc().figures), change
    # the conditions stay each figure's own: another shim drops the warm figures, keeps the drop's
    shimmed = {f.key: f.paper for f in load_template(templates_dir / "zhurong_differential.toml",
                                                       ["shim.thickness_mm=0.15"]).calc().figures}
    assert shimmed["cold_drop_per_side_arcmin"] == PAPER["cold_drop_per_side_arcmin"]
    assert shimmed["warm_backlash_total_min_arcmin"] is None


# -- rules named together -----------------------------------------------------------------------------

def test_two_broken_apex_rules_are_named_together(tmp_path, capsys):
    written(tmp_path, 3.0, 14, 30)
    path = next(tmp_path.glob("*.toml"))
    bad = ["dimensions.b_mm=69.5", "dimensions.a_mm=92.5"]
    with pytest.raises(ParamErrors) as info:
        load_template(path, bad)
    errors = info.value.errors
    assert [e.field for e in errors] == ["dimensions.b_mm", "dimensions.a_mm"]
    c = cone(3.0, 14, 30)
    data = tomllib.loads(path.read_text(encoding="utf-8"))["dimensions"]
    wanted = {"dimensions.b_mm": 2 * (data["l11_mm"] + data["l12_mm"] + c["d2"] / 2),
              "dimensions.a_mm": 2 * (data["l2_mm"] + c["d1"] / 2)}
    fixed = []
    for e in errors:  # each line names the value that satisfies it
        lo, hi = map(float, re.search(r"allowed ([\d.]+) to ([\d.]+) mm", e.allowed).groups())
        assert lo < wanted[e.field] < hi and hi - lo == pytest.approx(0.1)
        fixed.append(f"{e.field}={(lo + hi) / 2}")
    load_template(path, fixed)
    assert main(["check", str(path), *[a for b in bad for a in ("--set", b)], "--out", str(tmp_path / "run")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 2 and "dimensions.b_mm = 69.5" in lines[0] and "dimensions.a_mm = 92.5" in lines[1]


def test_broken_gear_rules_are_named_together(templates_dir):
    with pytest.raises(ParamErrors) as info:
        load_template(templates_dir / "zhurong_differential.toml",
                      ["gears.face_width_mm=20", "gears.small_profile_shift=0.0"])
    assert [e.field for e in info.value.errors] == ["gears.face_width_mm", "gears.small_profile_shift"]
    assert all("allowed" in e.allowed for e in info.value.errors)


# -- the check ---------------------------------------------------------------------------------------

@pytest.mark.cad
def test_new_then_check_gives_a_verdict_and_no_paper_values(tmp_path, capsys):
    written(tmp_path, 3.0, 14, 30)
    path = next(tmp_path.glob("*.toml"))
    run = tmp_path / "run"
    assert main(["check", str(path), "--out", str(run), "--jobs", "2"]) in (0, 1)
    summary = json.loads((run / "summary.json").read_text(encoding="utf-8"))[DIFFERENTIAL.section]

    def keys(node) -> list[str]:
        if isinstance(node, dict):
            return [k for k, v in node.items() for k in (k, *keys(v))]
        return [k for v in node for k in keys(v)] if isinstance(node, list) else []

    assert not [k for k in keys(summary) if k.startswith("paper")]
    report = (run / "report.html").read_text(encoding="utf-8")
    assert "Paper, model, geometry" not in report and "<th>paper</th>" not in report.lower()
    assert "the paper's ≥" not in report and "the paper shims" not in report
