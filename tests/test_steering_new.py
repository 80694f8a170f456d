"""`gearcheck new steering --module M --teeth Z`: the paper's design chain for a pinion of your own.

Each derived value is recomputed here from the closed forms written out afresh (line of action,
rack flank, circle of a tip corner) and compared with what `new` writes: H = r + the rack's rolling
line; hS4 from the contact ratio; RS1 from the S1 engagement at the target; hS2 from equal travel;
hS6/hS8 under the tangent to the tip circle at the stop. The written template loads, the model
drives to the target, `gearcheck check` gives a verdict with no edits (cad), a changed design shows
no paper values, and a pinion the chain has no design for is one line naming the input (exit 2)."""

from __future__ import annotations

import html
import json
import math
import re
from pathlib import Path

import pytest
from scipy.optimize import brentq

import gearcheck
from gearcheck.cli import main
from gearcheck.drafting import draft

ALPHA_DEG, EPS, TARGET_DEG = 25.0, 1.2, 60.0  # the chain's defaults: the paper's α, ε rule and target
RACK_ROOT_MODULES, DEDENDUM = 4.5, 1.25  # rack root above its datum (docs/steering.md); rack dedendum
MARGIN_DEG, TOP_MARGIN = 0.1, 0.02  # RS1 aims this far past the target; hS6/hS8 this many modules under the limit


class Hand:
    """The mechanism's closed forms, written from scratch (x = 0, standard 1 / 1.25 profiles)."""

    def __init__(self, m: float, z: int, first: int, alpha_deg: float = ALPHA_DEG):
        self.m, self.z, self.first = m, z, first
        self.a = math.radians(alpha_deg)
        self.r = m * z / 2.0
        self.rb = self.r * math.cos(self.a)
        self.ra = self.r + m
        self.p = math.pi * m
        self.h = (DEDENDUM + RACK_ROOT_MODULES) * m  # rolling line above the datum
        self.H = self.r + self.h
        self.top = self.h + m
        self.tau = 2.0 * math.pi / z

    def recess(self, radius: float) -> float:
        return math.sqrt(radius ** 2 - self.rb ** 2) - self.r * math.sin(self.a)

    def contact_ratio(self, h_top: float) -> float:
        return ((h_top - self.h) / math.sin(self.a) + self.recess(self.ra)) / (self.p * math.cos(self.a))

    def half_width(self, y: float) -> float:
        return self.p / 4.0 - (y - self.h) * math.tan(self.a)

    def travel(self, k: int, h_corner: float, radius: float) -> float:
        """Rack travel at which tooth k's left top corner lies on the circle of ``radius``."""
        return math.sqrt(radius ** 2 - (self.H - h_corner) ** 2) - k * self.p + self.half_width(h_corner)

    def phi_s1(self, radius: float) -> float:
        """G1's conjugate contact reaches its tip corner at ``radius`` (towing line of action)."""
        t = self.recess(radius)
        x, y = t * math.cos(self.a), self.h - t * math.sin(self.a)

        def inv(u: float) -> float:
            return math.tan(u) - u

        beta = math.pi / (2 * self.z) + inv(self.a) - inv(math.acos(self.rb / radius))
        return math.degrees(math.atan2(x, self.H - y) - beta - (self.first - 1 + 0.5) * self.tau)

    def tangent_top(self, k: int, h_corner: float, radius: float) -> float:
        """Height where the tangent to the circle through tooth k's left corner (on it) meets the
        tooth's right flank, at the travel that puts the corner there."""
        travel = self.travel(k, h_corner, radius)
        qx, qy = k * self.p + travel - self.half_width(h_corner), h_corner
        slope = qx / (self.H - qy)
        centre = k * self.p + travel
        # flank: x = centre + p/4 − (y − h)·tan α; tangent: y = qy + slope·(x − qx)
        lo, hi = self.h - 10 * self.m, self.H

        def miss(y: float) -> float:
            return qy + slope * (centre + self.half_width(y) - qx) - y

        return brentq(miss, lo, hi)


def _data(m: float, z: int, *sets: str) -> dict:
    return draft("steering", list(sets), module=m, teeth=z).data()


@pytest.fixture(scope="module", params=[(5.0, 34), (3.0, 56)], ids=["m5_z34", "m3_z56"])
def made(request):
    m, z = request.param
    return m, z, _data(m, z)


def test_centre_height_and_indexing(made):
    m, z, d = made
    first = d["rack"]["first_tooth"]
    hand = Hand(m, z, first)
    assert d["layout"]["centre_to_datum_mm"] == pytest.approx(hand.H, abs=1e-9)  # H = r + h
    n = math.floor(TARGET_DEG * z / 360.0)  # whole pitches within the target
    assert -first in (n, n + 1)
    assert d["rack"]["last_tooth"] == -first
    assert d["pinion"]["sector_first_tooth"] == first - 1 and d["pinion"]["sector_last_tooth"] == -first


def test_contact_ratio_trim(made):
    m, z, d = made
    hand = Hand(m, z, d["rack"]["first_tooth"])
    hs4 = d["trim"]["hS4_mm"]
    exact = hand.h + math.sin(hand.a) * (EPS * hand.p * math.cos(hand.a) - hand.recess(hand.ra))
    assert exact <= hs4 <= exact + 0.001 + 1e-9  # rounded up to 1 µm
    assert hand.contact_ratio(hs4) >= EPS


def test_topped_radius_meets_the_target(made):
    m, z, d = made
    hand = Hand(m, z, d["rack"]["first_tooth"])
    rs1 = d["pinion"]["topped_radius_mm"]
    aim = TARGET_DEG + MARGIN_DEG
    assert aim <= hand.phi_s1(rs1) <= aim + 0.01
    assert hand.phi_s1(rs1 - 0.001) < aim  # the smallest, to 1 µm
    # the model (every tooth pair, every hand-over, towing and power) drives past the target
    figs = gearcheck.load(d).calc()
    assert figs["continuous_drive_deg"] >= TARGET_DEG


def test_shortest_stroke_and_tangent_tops(made):
    m, z, d = made
    first = d["rack"]["first_tooth"]
    hand = Hand(m, z, first)
    t = d["trim"]
    rs1 = d["pinion"]["topped_radius_mm"]
    stop = hand.travel(first + 1, t["hS4_mm"], hand.ra)  # S3 reaches S4 (eq 3)
    if t["hS2_mm"] < hand.top:  # equal travel (eq 4), S1 at S2 no earlier, within 1 µm of height
        assert 0.0 <= hand.travel(first, t["hS2_mm"], rs1) - stop <= 0.01
        assert hand.travel(first, t["hS2_mm"] - 0.001, rs1) < stop
    else:  # S1 passes even the untrimmed corner before the rack stops: no trim needed
        assert hand.travel(first, hand.top, rs1) < stop
    for key, k, h_corner, radius in (("hS8_mm", first + 1, t["hS4_mm"], hand.ra),
                                     ("hS6_mm", first, t["hS2_mm"], rs1)):
        tangent = hand.tangent_top(k, h_corner, radius)
        if tangent >= hand.top:
            assert t[key] == pytest.approx(hand.top, abs=1e-9), key
        else:  # the design result of the check may lie lower than the tangent, never higher
            assert hand.h < t[key] <= tangent - TOP_MARGIN * m + 1e-9, key


def test_known_figures():
    """m5 z34 needs the rack one tooth longer (no equal travel at ⌊60/τ⌋ = 5: S1 reaches S2 later
    than S3 reaches S4 at every height); m3 z56 is equal travel at ⌊60/τ⌋ = 9."""
    d = _data(5.0, 34)
    assert d["rack"]["first_tooth"] == -6 and d["trim"]["hS2_mm"] == 33.75 and d["trim"]["hS6_mm"] == 33.75
    five = Hand(5.0, 34, -5)
    rs1 = brentq(lambda radius: five.phi_s1(radius) - (TARGET_DEG + MARGIN_DEG), 80.0, five.ra)
    hs4 = d["trim"]["hS4_mm"]
    assert five.travel(-5, five.h + 1e-6, rs1) > five.travel(-4, hs4, five.ra)
    d = _data(3.0, 56)
    assert d["rack"]["first_tooth"] == -9 and d["trim"]["hS2_mm"] < 20.25


def test_the_paper_pinion_gives_the_paper_chain():
    """m4 z42: the chain reproduces the paper's H and its hS4 from ε = 1.2 (printed 25.13) and 60° =
    7 pitches (the tooth indices of its drawing)."""
    d = _data(4.0, 42)
    assert d["layout"]["centre_to_datum_mm"] == 107.0
    assert d["trim"]["hS4_mm"] == pytest.approx(25.13, abs=0.006)
    assert (d["rack"]["first_tooth"], d["pinion"]["sector_first_tooth"], d["pinion"]["sector_last_tooth"]) == (-7, -8, 7)


def test_overrides_are_inputs_of_the_chain():
    base = _data(5.0, 34)
    eps = _data(5.0, 34, "trim.min_contact_ratio=1.3")
    hand = Hand(5.0, 34, eps["rack"]["first_tooth"])
    assert 1.3 <= hand.contact_ratio(eps["trim"]["hS4_mm"]) <= 1.3 + 5e-4  # hS4 rounded up to 1 µm
    assert eps["trim"]["hS4_mm"] > base["trim"]["hS4_mm"]
    alpha = _data(5.0, 34, "pinion.pressure_angle_deg=20")
    hand = Hand(5.0, 34, alpha["rack"]["first_tooth"], alpha_deg=20.0)
    assert alpha["pinion"]["pressure_angle_deg"] == 20.0
    assert EPS <= hand.contact_ratio(alpha["trim"]["hS4_mm"]) <= EPS + 5e-4
    aim = _data(3.0, 56, "targets.continuous_drive_deg=55")
    assert Hand(3.0, 56, aim["rack"]["first_tooth"]).phi_s1(aim["pinion"]["topped_radius_mm"]) == \
        pytest.approx(55.0 + MARGIN_DEG, abs=0.01)
    assert gearcheck.load(aim).calc()["continuous_drive_deg"] >= 55.0


def test_changed_design_calc_has_no_paper_values(made, capsys):
    m, z, d = made
    design = gearcheck.load(d)
    assert all(f.paper is None for f in design.calc().figures)
    assert "paper" not in design.calc().to_dict()["steering"]
    assert not any("ADAMS" in f.label or "paper" in f.note for f in design.calc().figures)


def test_no_design_is_one_line(tmp_path, capsys):
    out = tmp_path / "small.toml"
    assert main(["new", "steering", "--module", "5", "--teeth", "12", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearcheck: error: --teeth = 12: no design by the paper's chain")
    assert not out.exists()
    assert main(["new", "steering", "--module", "5", "--teeth", "34", "--set", "trim.min_contact_ratio=1.6",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearcheck: error: --set trim.min_contact_ratio = 1.6:")
    assert "above the rack top" in err[0]


@pytest.mark.cad
@pytest.mark.parametrize(("m", "z"), [(5, 34), (3, 56)], ids=["m5_z34", "m3_z56"])
def test_new_then_check_gives_a_verdict(tmp_path, capsys, m, z):
    path = tmp_path / f"steering_m{m}_z{z}.toml"
    assert main(["new", "steering", "--module", str(m), "--teeth", str(z), "--out", str(path)]) == 0
    text = path.read_text()
    assert text.startswith("#:schema ./schema/steering.json") and "# ε = trim.min_contact_ratio" in text
    gearcheck.load(path)
    out = tmp_path / "run"
    assert main(["check", str(path), "--out", str(out), "--jobs", "2"]) in (0, 1)
    summary = json.loads((out / "summary.json").read_text())
    assert not any(k.startswith("paper_") for k in summary["steering"])
    assert summary["steering"]["verdicts"]["continuous_drive"] == 1
    page = (Path(out) / "report.html").read_text(encoding="utf-8")
    assert re.search(r"<th[^>]*>\s*paper", page) is None  # no paper column
    shown = " ".join(html.unescape(re.sub(r"<[^>]+>", " ", re.sub(r"<(svg|script|style)\b.*?</\1>", "", page, flags=re.S))).split())
    for printed in ("ADAMS", "75.32", "110.20", "62.11", "test 109.5", "Paper, model"):
        assert printed not in shown, printed


def test_a_derived_value_set_is_kept_and_noted_as_given():
    """--set on a derived value (hS4, RS1, hS2) is an input: written as given, noted so, and the rest
    derived from it (hS6/hS8 under the tip lands of the RS1 given)."""
    design = gearcheck.new("steering", module=5, teeth=34, overrides=["trim.hS4_mm=31.5",
                                                                       "pinion.topped_radius_mm=82",
                                                                       "trim.hS2_mm=33.7"])
    p = design.params
    assert (p.trim.hS4_mm, p.pinion.topped_radius_mm, p.trim.hS2_mm) == (31.5, 82.0, 33.7)
    from gearcheck.drafting import draft

    text = draft("steering", ["trim.hS4_mm=31.5", "pinion.topped_radius_mm=82"], module=5, teeth=34).toml()
    assert re.search(r"hS4_mm = 31.5 +# as given: ε = 1\.20\d\d", text)
    assert re.search(r"topped_radius_mm = 82.0 +# RS1 as given", text)
