"""The Python API as docs/python.md documents it: its example block runs as written (in a
scratch folder holding the templates), then its results are checked against the CLI's."""

from __future__ import annotations

import json
import os
import re
import sys

import pytest

import gearcheck
from conftest import ROOT
from gearcheck.cli import main

pytestmark = pytest.mark.cad


def readme_example() -> str:
    text = (ROOT / "docs" / "python.md").read_text(encoding="utf-8")
    match = re.search(r"<!-- api-example -->\s*```python\n(.*?)```", text, re.S)
    assert match, "docs/python.md has no api-example block"
    return match.group(1)


@pytest.fixture(scope="module")
def ran(tmp_path_factory):
    """The README block, executed in a folder where templates/ is the repository's."""
    work = tmp_path_factory.mktemp("api")
    (work / "templates").symlink_to(ROOT / "templates")
    cwd = os.getcwd()
    os.chdir(work)
    try:
        namespace: dict = {}
        exec(compile(readme_example(), "docs/python.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    return work, namespace


def test_readme_example_runs_and_checks(ran):
    work, ns = ran
    d, r, b = ns["d"], ns["r"], ns["b"]
    assert d.mechanism == "differential" and d.params.shim.thickness_mm == 0.15
    assert isinstance(r.passed, bool)
    assert all(isinstance(v, gearcheck.Verdict) for v in r.verdicts)
    written = json.loads((work / "out" / "x" / "summary.json").read_text())
    assert r.summary == written
    assert written["differential"]["template_shim_mm"] == 0.15
    assert {p.name for p in b.files} >= {"zhurong_differential.step", "manifest.json", "params.toml",
                                         "big_gear_left.stl"}
    assert all(p.is_file() for p in b.files)


def test_calc_to_dict_is_what_the_cli_prints(ran, capsys):
    _, ns = ran
    code = main(["calc", str(ROOT / "templates" / "zhurong_differential.toml"), "--set", "shim.thickness_mm=0.15",
                 "--json"])
    assert code == 0
    assert ns["f"].to_dict() == json.loads(capsys.readouterr().out)


def test_assembly_cad_is_a_named_coloured_assembly(ran):
    import cadquery as cq

    asm = ran[1]["asm"]
    assert isinstance(asm, cq.Assembly)
    names = {child.name for child in asm.children}
    assert {"big_gear_left", "big_gear_right", "small_gear_front", "small_gear_back"} <= names
    assert all(child.color is not None for child in asm.children)


def test_bad_input_raises_the_line_the_cli_prints(capsys):
    with pytest.raises(gearcheck.ParamError) as err:
        gearcheck.load(ROOT / "templates" / "zhurong_differential.toml", overrides={"operating.cold_C": -200})
    assert main(["calc", str(ROOT / "templates" / "zhurong_differential.toml"), "--set", "operating.cold_C=-200"]) == 2
    assert capsys.readouterr().err.strip() == f"gearcheck: error: {err.value}"
    assert "\n" not in str(err.value) and "operating.cold_C = -200" in str(err.value)


def test_dict_templates_and_list_overrides(capsys):
    data = {"mechanism": "track", **{k: v for k, v in gearcheck.load(ROOT / "templates" / "eod_track_drive.toml")
                                     .data.items() if k != "mechanism"}}
    a = gearcheck.load(data, overrides={"track_plate.tip_gap_mm": 0.8})
    b = gearcheck.load(ROOT / "templates" / "eod_track_drive.toml", overrides=["track_plate.tip_gap_mm=0.8"])
    assert a.params == b.params and (a.name, b.name) == ("track", "eod_track_drive")
    with pytest.raises(gearcheck.ParamError, match="mechanism"):
        gearcheck.load({"mechanism": "nope"})
    assert "gearcheck" in sys.modules


def test_rerun_from_params_toml_reproduces_the_files(ran, tmp_path):
    """The README's run (a --set-style override of the shim) re-run from its own params.toml:
    summary.json and sweep.csv byte for byte."""
    work, ns = ran
    first = work / "out" / "x"
    # the same verdicts, so the same exit code (the thick shim shortens the contact pattern below the
    # template's requirement: a failed design, exit 1)
    code = 0 if ns["r"].passed else 1
    assert main(["check", str(first / "params.toml"), "--out", str(tmp_path / "again")]) == code
    for name in ("summary.json", "sweep.csv"):
        assert (tmp_path / "again" / name).read_bytes() == (first / name).read_bytes(), name
