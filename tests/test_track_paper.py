"""The track's paper values beside the paper's own design only (the one rule of every mechanism):
a changed design shows no paper value, column, key or wording in calc (table and --json), in the
check's summary and in its report content; and the scope of the mechanism (the paper's articulated
track, not a roller-chain sprocket) named where a roller-chain input is refused."""

from __future__ import annotations

import json

import pytest

from gearcheck import pipeline
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.mechanisms.track import is_paper_design

TEMPLATE = "eod_track_drive"
CHANGED = ("robot.mass_kg=200",)  # an input the paper gives: no longer the paper's design (same solids)
ROLLER_CHAIN_HINT = "for a standard roller chain use mechanism = \"roller_chain\""


def test_the_paper_design_and_what_may_differ(templates_dir):
    def paper(*overrides: str) -> bool:
        return is_paper_design(load_template(templates_dir / f"{TEMPLATE}.toml", list(overrides)).params)

    assert paper()
    # the reading of g and the template's own choices (marked "chosen") are not the paper's inputs
    assert paper("robot.g_m_s2=9.81") and paper("track_plate.tip_gap_mm=0.6") and paper("chain.wear_elongation_pct=2")
    assert not paper(*CHANGED) and not paper("sprocket.teeth=51") and not paper("track_plate.required_gap_min_mm=0.4")


def test_calc_of_a_changed_design_has_no_paper_values(templates_dir, capsys):
    path = str(templates_dir / f"{TEMPLATE}.toml")
    assert main(["calc", path, "--set", CHANGED[0]]) == 0
    table = capsys.readouterr().out
    head = next(line for line in table.splitlines() if line.lstrip().startswith("quantity"))
    assert "paper" not in head and "diff" not in head  # no paper column
    assert "234 N" not in table and "requires" not in table  # no printed value, no note about one
    assert main(["calc", path, "--json", "--set", CHANGED[0]]) == 0
    data = json.loads(capsys.readouterr().out)["track"]
    assert "paper" not in data
    assert main(["calc", path]) == 0
    assert "paper" in capsys.readouterr().out  # beside the paper's own design it is there


@pytest.mark.cad
def test_check_of_a_changed_design_has_no_paper_values(build_bodies):
    run = build_bodies(TEMPLATE, CHANGED)
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": 2})
    assert not any("paper" in k for k in json.dumps(result.summary).split('"'))
    assert all(c.paper is None for c in result.comparisons)
    for c in result.comparisons:
        assert "paper" not in c.label and "paper" not in c.note, c.label
    window = next(c for c in result.comparisons if c.label == "min tip-to-plate over the sweep")
    assert "required ≥ 0.5 mm (track_plate.required_gap_min_mm)" in window.note
    for plot in result.plots:
        assert not any("paper" in label for label, _ in plot.hlines) and "paper" not in plot.caption


def test_roller_chain_input_is_refused_with_the_scope(templates_dir, capsys):
    """An ISO 606 12B chain (p = 19.05 mm, roller 12.07 mm) on z = 21: grooves every half pitch leave
    no tooth; the line names the mechanism's scope and where a roller chain goes."""
    path = str(templates_dir / f"{TEMPLATE}.toml")
    assert main(["calc", path, "--set", "chain.pitch_mm=19.05", "--set", "chain.sleeve_diameter_mm=12.07",
                 "--set", "sprocket.teeth=21", "--set", "sprocket.initial_pitch_diameter_mm=128"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "chain.sleeve_diameter_mm = 12.07" in err[0]
    assert "(the paper's articulated track: grooves every half pitch; " + ROLLER_CHAIN_HINT + ")" in err[0]


def test_independent_rules_are_named_together(templates_dir, capsys):
    path = str(templates_dir / f"{TEMPLATE}.toml")
    assert main(["calc", path, "--set", "chain.pin_diameter_mm=9", "--set", "sprocket.flank_radius_mm=1",
                 "--set", "strength.loaded_tooth_rows=3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert [line.split(".toml: ")[1].split(" = ")[0] for line in err] == [
        "chain.pin_diameter_mm", "sprocket.flank_radius_mm", "strength.loaded_tooth_rows"]


def test_even_tooth_count_is_accepted(templates_dir):
    params = load_template(templates_dir / f"{TEMPLATE}.toml", ["sprocket.teeth=50"]).params
    assert params.sprocket.teeth == 50  # a warning verdict of the check (odd_tooth_count), not a rejection
