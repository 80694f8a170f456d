"""The assembly mechanism: a user's own STEP file, swept through the motion its template declares.

The pair is an involute spur pair drawn by a CadQuery script (tests/step_pairs.py), not by
gearcheck: at a centre distance opened by Δa its play must be the involute formula's
j' = 2a'(inv α' − inv α) over r2', within the pair's mesh bound; closed by Δa the check fails with
the overlap; written in inches it gives the same figures. Bad input is one line, exit 2, nothing
written; ``gearcheck new assembly --step`` lists the products.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

import gearcheck
from gearcheck.cli import main
from gearcheck.mechanisms.assembly.sweep import BISECT_DEG
from gearcheck.params import ParamError
from step_pairs import backlash, template, write_pair

pytestmark = pytest.mark.cad

M, Z1, Z2, ALPHA, DA = 2.0, 18, 24, 20.0, 0.1


@pytest.fixture(scope="module")
def steps(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("steps")
    return {"open": write_pair(folder / "open.step", M, Z1, Z2, ALPHA, DA),
            "open_inch": write_pair(folder / "open_inch.step", M, Z1, Z2, ALPHA, DA, unit="INCH"),
            "closed": write_pair(folder / "closed.step", M, Z1, Z2, ALPHA, -DA)}


@pytest.fixture(scope="module")
def opened(steps, tmp_path_factory):
    design = gearcheck.load(template(steps["open"], M, Z1, Z2, DA))
    return design.check(out=tmp_path_factory.mktemp("open") / "run", jobs=2)


def test_an_opened_pair_has_the_involute_backlash(opened):
    s = opened.summary["assembly"]
    j, play_rad = backlash(M, Z1, Z2, ALPHA, DA)
    a2 = M * (Z1 + Z2) / 2 + DA
    alpha_w = math.acos(M * (Z1 + Z2) / 2 * math.cos(math.radians(ALPHA)) / a2)
    r2w = a2 * Z2 / (Z1 + Z2)
    bound = s["pairs"]["pinion__wheel"]["mesh_error_bound_mm"]
    # the meshes are inscribed in the solids: their teeth are thinner by at most the bound, along
    # the normal; the wheel's turn to contact grows by at most twice that over r2'·cos α'
    allowed_deg = math.degrees(2 * bound / (r2w * math.cos(alpha_w))) + 2 * BISECT_DEG
    exact_deg = math.degrees(play_rad)
    assert exact_deg - 2 * BISECT_DEG <= s["play_min_deg"] <= exact_deg + allowed_deg, (s["play_min_deg"], exact_deg)
    assert abs(s["play_min_deg"] - exact_deg) * 60 < 0.2  # arcmin: well inside the bound on this mesh
    assert opened.passed and {v.name for v in opened.verdicts} == {"clearance_pinion__wheel", "play",
                                                                   "exact_confirmation"}
    pair = s["pairs"]["pinion__wheel"]
    assert pair["overlapping_poses"] == 0 and 0 < pair["min_clearance_mm"] < j
    # the least clearance confirmed on the exact B-rep within the pair's bound
    conf = s["exact_confirmation"]
    key = next(k for k in conf if k.startswith("least_clearance_pinion__wheel"))
    assert abs(conf[key]["mesh_mm"] - conf[key]["brep_mm"]) <= conf[key]["bound_mm"]


def test_the_run_folder_holds_every_file(opened):
    files = json.loads((opened.folder / "manifest.json").read_text())["files"]
    for name in ("spur_pair.step", "pinion.stl", "wheel.stl", "summary.json", "sweep.csv", "report.html",
                 "spur_pair.glb", "params.toml"):
        assert name in files, name
    rows = (opened.folder / "sweep.csv").read_text().splitlines()
    assert len(rows) == 1 + opened.summary["assembly"]["poses"]
    page = (opened.folder / "report.html").read_text(encoding="utf-8")
    assert "Play of wheel over the motion" in page and "Clearance over the motion" in page


def test_the_same_pair_in_inches_gives_the_same_figures(steps, opened, tmp_path):
    text = (steps["open_inch"]).read_text()
    assert "CONVERSION_BASED_UNIT('INCH'" in text
    inch = gearcheck.load(template(steps["open_inch"], M, Z1, Z2, DA)).check(out=tmp_path / "run", jobs=2)
    a, b = opened.summary["assembly"], inch.summary["assembly"]
    assert b["play_min_deg"] == pytest.approx(a["play_min_deg"], abs=2 * BISECT_DEG)
    pa, pb = a["pairs"]["pinion__wheel"], b["pairs"]["pinion__wheel"]
    assert pb["min_clearance_mm"] == pytest.approx(pa["min_clearance_mm"], abs=1e-5)
    assert inch.passed


def test_a_closed_pair_fails_with_the_overlap(steps, tmp_path, capsys):
    path = tmp_path / "closed.toml"
    _write(path, template(steps["closed"], M, Z1, Z2, -DA))
    assert main(["check", str(path), "--out", str(tmp_path / "run"), "--jobs", "2"]) == 1
    s = json.loads((tmp_path / "run" / "summary.json").read_text())["assembly"]
    pair = s["pairs"]["pinion__wheel"]
    assert s["verdict_levels"]["clearance_pinion__wheel"] == "fail" and pair["overlapping_poses"] == s["poses"]
    # no turn of the wheel frees teeth that overlap on both flanks; the least push that does is
    # about the centre distance's shortfall
    assert pair["max_overlap_jammed"] == 1
    assert pair["max_overlap_mm"] == pytest.approx(DA, abs=0.03)
    assert s["verdict_levels"]["play"] == "fail" and s["play_jammed_poses"] == s["poses"]
    out = capsys.readouterr().out
    assert re.search(r"FAIL +pinion and wheel do not interfere: overlap 0\.\d+ mm at", out), out
    conf = s["exact_confirmation"]
    deepest = next(v for k, v in conf.items() if k.startswith("deepest_overlap"))
    assert deepest["overlap_mm3"] > 0.01  # the solids overlap, by the B-rep's common volume


def _write(path: Path, data: dict) -> Path:
    import tomli_w

    path.write_text(tomli_w.dumps(data))
    return path


def _wire_step(path: Path) -> Path:
    import cadquery as cq  # noqa: TID251

    cq.exporters.export(cq.Workplane("XY").polyline([(0, 0), (10, 0), (10, 5)]), str(path))
    return path


BAD = {
    "missing file": (lambda d, tmp: d["assembly"].update(step=str(tmp / "nowhere.step")),
                     r"assembly\.step = .*nowhere\.step.*no such file"),
    "not a STEP file": (lambda d, tmp: d["assembly"].update(step=str(_text(tmp / "notes.step"))),
                        r"assembly\.step = .*not a STEP file"),
    "a STEP without solids": (lambda d, tmp: d["assembly"].update(step=str(_wire_step(tmp / "wire.step"))),
                              r"assembly\.step = .*wire\.step.*no solids"),
    "a product not in the file": (lambda d, tmp: d["part"][1].update(product="gear"),
                                  r"part\[1\]\.product = 'gear'.*no product named 'gear'; the file has .*pinion.*wheel"),
    "a zero axis": (lambda d, tmp: d["joint"][0].update(axis=[0.0, 0.0, 0.0]), r"joint\[0\]\.axis = .*not all zero"),
    "a couple of an unknown joint": (lambda d, tmp: d["couple"][0].update(driven="idler"),
                                     r"couple\[0\]\.driven = 'idler'.*part with a joint"),
    "a motion of no extent": (lambda d, tmp: d["motion"].update(end_deg=0.0), r"motion\.end_deg = 0\.0.*some extent"),
}


def _text(path: Path) -> Path:
    path.write_text("this is not a STEP file\n")
    return path


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_is_one_line_exit_2_and_nothing_written(case, steps, tmp_path, capsys):
    data = template(steps["open"], M, Z1, Z2, DA)
    change, pattern = BAD[case]
    change(data, tmp_path)
    path = _write(tmp_path / "t.toml", data)
    out = tmp_path / "run"
    assert main(["check", str(path), "--out", str(out), "--jobs", "1"]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("gearcheck:")]
    assert len(err) == 1 and re.search(pattern, err[0]), err
    assert not out.exists()


def test_new_lists_the_products_and_writes_a_template_to_fill_in(steps, tmp_path, capsys):
    out = tmp_path / "sub" / "mine.toml"
    out.parent.mkdir()
    assert main(["new", "assembly", "--step", str(steps["open"]), "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "2 parts" in said and "pinion, wheel" in said
    text = out.read_text()
    assert re.search(r'^step = "\.\./.*open\.step"', text, re.M), text  # relative to the template
    assert re.search(r'^\[\[part\]\]\nname = "pinion" +# 1 solid', text, re.M), text
    with pytest.raises(ParamError, match=r"motion"):  # to fill in: no motion yet
        gearcheck.load(out)
    # the examples at the end name the file's own products; uncommented, the one thing a shape
    # cannot tell (the ratio) is a placeholder that is refused, and once given the template loads
    out.write_text(_uncomment(text))
    with pytest.raises(ParamError, match=r"couple.0.ratio"):
        gearcheck.load(out)
    out.write_text(re.sub(r'^ratio = "\?".*$', "ratio = -0.75", _uncomment(text), flags=re.M))
    design = gearcheck.load(out)
    assert [p.name for p in design.params.part] == ["pinion", "wheel"]


def _uncomment(text: str) -> str:
    head, _, examples = text.partition("\n# [[joint]]")
    body = "# [[joint]]" + examples
    return head + "\n" + re.sub(r"^# ?", "", body, flags=re.M)
