"""Track drive: the tooth count's parity. Every other tooth engaging works with any z: an even z is
valid (geometry, CAD, sweep), and `gearcheck check` warns that the same z/2 teeth then take every
engagement; an odd z (the template's 49) has no such verdict."""

import json
import subprocess
import sys

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.geometry import iso606
from gearcheck.mechanisms.track import calc, layout
from gearcheck.mechanisms.track.verdicts import SCOPE, tooth_count_verdicts

TEMPLATE = "eod_track_drive"
EVEN = ("sprocket.teeth=50",)
REASON = ("every other tooth engaging means the same z/2 = 25 teeth take every engagement; the other half never "
          "wear — an odd z lets each tooth take its turn")


@pytest.fixture(scope="module")
def template(templates_dir):
    return templates_dir / f"{TEMPLATE}.toml"


def test_even_teeth_are_valid_input(template, capsys):
    """Before: `sprocket.teeth = 50: allowed odd numbers 7 to 301`, exit 2. Now valid; calc says
    which teeth engage."""
    params = load_template(template, list(EVEN)).params
    assert params.sprocket.teeth == 50
    f = {x.key: x for x in calc(params)}
    assert f["pitch_diameter_mm"].value == pytest.approx(30.0 / np.sin(2 * np.pi / 50), rel=1e-12)
    assert "even z: the same 25 teeth take every engagement" in f["pitch_diameter_mm"].note
    assert "(even)" in f["teeth_for_initial_pitch_diameter"].note
    assert "even" not in {x.key: x for x in calc(load_template(template).params)}["pitch_diameter_mm"].note
    assert main(["calc", str(template), "--set", "sprocket.teeth=50"]) == 0
    capsys.readouterr()


def test_even_teeth_verdict_is_a_warning_odd_has_none():
    (v,) = tooth_count_verdicts(50)
    assert v.name == "odd_tooth_count" and v.level == "warn" and v.passed
    assert REASON in v.measured and SCOPE in v.measured and "even z = 50" in v.measured
    assert v.figures == {"teeth": 50, "engaging_teeth": 25} and v.evidence.startswith("analytical model")
    assert v.shortfall  # a warning says what falls short
    assert tooth_count_verdicts(49) == [] and tooth_count_verdicts(51) == []


@pytest.mark.parametrize("z", [49, 50])
def test_wrap_repeats_after_one_cycle_for_odd_and_even_z(template, z):
    """What the sweep's one-cycle plan relies on, for either parity: after β = 2·360°/z every pin
    stands where the pin ahead of it stood; the seated pins lie on the pin circle, p apart, all in
    grooves of one parity (an even z never uses the other half of the grooves)."""
    lay = layout.track_layout(load_template(template, [f"sprocket.teeth={z}"]).params)
    wrap, gap = lay.wrap, lay.sprocket.gap
    assert gap.teeth == z
    for theta in (0.0, 0.3 * wrap.cycle_rad, 0.77 * wrap.cycle_rad):
        now, later = wrap.pin_positions(theta), wrap.pin_positions(theta + wrap.cycle_rad)
        seated = np.flatnonzero(wrap.seated_pins(theta + wrap.cycle_rad) & np.roll(wrap.seated_pins(theta), 1))
        seated = seated[seated > 0]
        assert seated.size >= 4
        assert np.allclose(later[seated], now[seated - 1], atol=1e-9)
    assert len(set(wrap.pin_grooves() % 2)) == 1
    outline = iso606.sprocket_outline(gap)
    assert len(outline) % z == 0  # z identical grooves


@pytest.mark.cad
def test_even_teeth_full_check_passes_with_the_warning(build_bodies):
    """The even sprocket is built (CAD), swept and judged: every verdict passes, the tooth count
    warns; the template (odd z) has no such verdict."""
    run = build_bodies(TEMPLATE, EVEN)
    assert run.design.params.sprocket.teeth == 50
    result = pipeline.sweep(run.design, run.assembly, run.bodies, jobs=1, options={"steps_per_cycle": 12})
    levels = {v.name: v.level for v in result.verdicts}
    assert result.passed and levels.pop("odd_tooth_count") == "warn"
    assert set(levels.values()) == {"pass"}, levels
    assert {"no_interference", "seated_tip_gap_in_window", "chain_wear_within_limit"} <= set(levels)
    odd = build_bodies(TEMPLATE)
    names = {v.name for v in pipeline.sweep(odd.design, odd.assembly, odd.bodies, jobs=1,
                                            options={"steps_per_cycle": 12}).verdicts}
    assert "odd_tooth_count" not in names and "chain_wear_within_limit" in names


@pytest.mark.cad
def test_even_teeth_check_exits_0_and_lists_the_verdicts(template, tmp_path):
    out = tmp_path / "z50"
    proc = subprocess.run([sys.executable, "-m", "gearcheck", "check", str(template), "--set", "sprocket.teeth=50",
                           "--out", str(out), "--jobs", "1"], check=False, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    warn = [ln for ln in proc.stdout.splitlines() if ln.strip().startswith("WARN") and "tooth count" in ln]
    assert len(warn) == 1 and "z = 50 even" in warn[0] and "…" not in warn[0]  # one whole line, its key figure
    s = json.loads((out / "summary.json").read_text())["track"]
    assert REASON in s["verdict_measured"]["odd_tooth_count"]  # the whole sentence
    assert s["verdict_levels"]["odd_tooth_count"] == "warn" and s["verdicts"]["odd_tooth_count"] == 1
    assert s["verdict_pass"] == 1 and s["verdict_warnings"] == 1
    assert all(v == "pass" for k, v in s["verdict_levels"].items() if k != "odd_tooth_count")
