"""`gearcheck new` and gearcheck.new(): the parts every mechanism shares (src/gearcheck/drafting.py).

A design from a few numbers is each mechanism's own derivation (tested beside each mechanism);
here a test mechanism (the spur pair of docs/extending.md, with a `new` of its own) shows what is
common to all: the inputs a mechanism declares and their one-line errors, --set as an input to the
derivation and written as given, the template's text (every derived value with its note, loadable
as written), the file written once (an existing one only with --force), and every broken rule of a
template named at once."""

from __future__ import annotations

import json
import re
import tomllib
from collections.abc import Mapping
from typing import Any, ClassVar

import pytest

import gearcheck
from gearcheck import mechanism as registry
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.drafting import Draft, NewInput, positive_number, teeth_numbers
from gearcheck.params import ParamError, ParamErrors, Problems
from spur_pair import SpurPair


class NewSpurPair(SpurPair):
    """The spur pair with a `new`: module and teeth given, the face width (10 modules) and the
    thinning (0.025·m per gear) derived."""

    name = section = "spur_new"
    new_inputs: ClassVar[tuple[NewInput, ...]] = (NewInput("module", "gear module, mm"),
                                                  NewInput("teeth", "teeth of gear 1 / gear 2, e.g. 18/24"))

    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        m = positive_number("module", inputs["module"], 0.5, 10.0)
        z1, z2 = teeth_numbers(inputs["teeth"], 2, "gear 1/gear 2")
        d = Draft(self.name, f"spur_m{m:g}_{z1}x{z2}", ["A spur pair from module and teeth."])
        d.set("gears.module_mm", m, "given")
        d.set("gears.teeth_1", z1, "given")
        d.set("gears.teeth_2", z2, "given")
        d.set("gears.pressure_angle_deg", overrides.get("gears.pressure_angle_deg", 20.0), "standard 20°")
        d.set("gears.face_width_mm", 10.0 * m, "10 modules")
        d.set("gears.bore_diameter_mm", 5.0 * m, "5 modules")
        d.set("backlash.thinning_1_mm", round(0.025 * m, 6), "0.025·m")
        d.set("backlash.thinning_2_mm", round(0.025 * m, 6), "0.025·m")
        return d


@pytest.fixture
def spur():
    impl = registry.register(NewSpurPair)
    yield impl
    registry.unregister(impl.name)


def test_python_new_writes_a_template_that_loads_as_written(spur, tmp_path):
    out = tmp_path / "pair.toml"
    design = gearcheck.new("spur_new", module=2, teeth="18/24", out=out)
    assert design.path == out and design.mechanism == "spur_new"
    text = out.read_text()
    assert "face_width_mm = 20.0" in text and "# 10 modules" in text  # each derived value with its note
    assert text.splitlines()[0] == "#:schema ./schema/spur_new.json"
    # the schema it points at is there (before: the line pointed at nothing)
    schema = json.loads((tmp_path / "schema" / "spur_new.json").read_text())
    assert "gears" in schema["properties"]
    data = tomllib.loads(text)
    assert data["gears"]["teeth_2"] == 24 and data["backlash"]["thinning_1_mm"] == pytest.approx(0.05)
    again = load_template(out)
    assert again.params == design.params
    assert gearcheck.new("spur_new", module=2, teeth=(18, 24)).params == design.params  # no file: a Design only


def test_cli_new_then_the_file_is_kept_unless_forced(spur, tmp_path, capsys):
    out = tmp_path / "pair.toml"
    args = ["new", "spur_new", "--module", "2", "--teeth", "18/24", "--out", str(out)]
    assert main(args) == 0
    assert f"gearcheck check {out}" in capsys.readouterr().out
    first = out.read_text()
    assert main(args + ["--set", "gears.face_width_mm=12"]) == 2
    assert "--out" in capsys.readouterr().err and out.read_text() == first
    assert main(args + ["--set", "gears.face_width_mm=12", "--force"]) == 0
    text = out.read_text()
    assert "face_width_mm = 12" in text and "set with --set" in text


def test_set_is_an_input_of_the_derivation(spur):
    d = gearcheck.new("spur_new", module=2, teeth="18/24", overrides=["gears.pressure_angle_deg=25"])
    assert d.params.gears.pressure_angle_deg == 25.0


def test_print_with_dash(spur, capsys):
    assert main(["new", "spur_new", "--module", "1.5", "--teeth", "20/30", "--out", "-"]) == 0
    data = tomllib.loads(capsys.readouterr().out)
    assert data["mechanism"] == "spur_new" and data["gears"]["module_mm"] == 1.5


@pytest.mark.parametrize("args, words", [
    (["--module", "2"], ["--teeth = <missing>", "required for spur_new"]),
    (["--module", "2", "--teeth", "18"], ["--teeth = '18'", "2 whole numbers", "e.g. --teeth 20/30"]),
    (["--module", "abc", "--teeth", "18/24"], ["--module = 'abc'", "allowed a number from 0.5 to 10"]),
    (["--module", "2", "--teeth", "18/24", "--chain", "12B"], ["--chain = '12B'", "spur_new takes --module, --teeth"]),
    (["--module", "2", "--teeth", "18/24", "--set", "gears.teeth_1=5"], ["gears.teeth_1 = 5", "allowed 17 to 80"]),
])
def test_bad_numbers_are_one_line_exit_2(spur, tmp_path, capsys, args, words):
    out = tmp_path / "x.toml"
    assert main(["new", "spur_new", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    for w in words:
        assert w in err, (w, err)
    assert not out.exists()


def test_unknown_mechanism_lists_those_that_offer_new(spur, capsys):
    assert main(["new", "gearbox", "--out", "-"]) == 2
    err = capsys.readouterr().err
    assert "MECHANISM = 'gearbox'" in err and "spur_new" in err and "spur_pair" not in err  # spur_pair has no `new`


def test_every_broken_field_is_named_at_once(spur, tmp_path, capsys):
    """Two out-of-range fields: both named, one line each, in one run (exit 2)."""
    out = tmp_path / "p.toml"
    assert gearcheck.new("spur_new", module=2, teeth="18/24", out=out)
    assert main(["check", str(out), "--set", "gears.teeth_1=5", "--set", "gears.module_mm=100",
                 "--out", str(tmp_path / "run")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 2 and all(line.startswith("gearcheck: error: ") for line in lines)
    assert any("gears.teeth_1 = 5" in line for line in lines) and any("gears.module_mm = 100" in line for line in lines)
    with pytest.raises(ParamErrors) as info:
        load_template(out, ["gears.teeth_1=5", "gears.module_mm=100"])
    assert len(info.value.errors) == 2 and info.value.field in ("gears.teeth_1", "gears.module_mm")


def test_problems_collects_then_raises():
    with pytest.raises(ParamError) as one:
        with Problems() as p:
            p.add("a.b", 1, "allowed 2")
    assert not isinstance(one.value, ParamErrors) and str(one.value) == "a.b = 1: allowed 2"
    with pytest.raises(ParamErrors) as many:
        with Problems() as p:
            p.add("a.b", 1, "allowed 2")
            p.add("a.c", 3, "allowed 4")
    assert str(many.value).splitlines() == ["a.b = 1: allowed 2", "a.c = 3: allowed 4"]
    assert str(many.value.with_source("f.toml")).splitlines()[1] == "f.toml: a.c = 3: allowed 4"
    with Problems():  # nothing broken: nothing raised
        pass


def test_new_writes_floats_as_a_person_would(tmp_path):
    """Before: ``new roller_chain --chain 08A --teeth 21 --strands 2`` wrote
    ``tooth_width_mm = 7.140000000000001``."""
    out = tmp_path / "duplex.toml"
    gearcheck.new("roller_chain", chain="08A", teeth=21, strands=2, out=out)
    text = out.read_text()
    assert "tooth_width_mm = 7.14 " in text
    assert not re.search(r"\d\.\d*(0000000|9999999)\d", text), text
