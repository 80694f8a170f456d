"""Fuzz of `gearcheck new`: every mechanism that offers it (the assembly's needs a STEP file of the
user's: left out), its numbers drawn from a seeded sequence over the whole range its flags take
(and past both ends of it, with words and degenerate numbers among them), run through `new` →
`calc` → a coarse check.

- `new` answers every draw with a template (exit 0) or one line naming the flag, its value and
  the allowed range or why no design exists (exit 2) — never an internal error (exit 3).
- Every template it writes loads, and its analytical model runs with finite figures (NaN only
  where the mechanism documents one).
- One design per mechanism goes through a coarse check on its meshes (the expensive part: one
  process, few poses) and must get a verdict (pass or fail: exit 0 or 1), never an error. It is
  drawn where a check takes seconds (few teeth, one or two strands); the steering's is N12's,
  checked whole (with the exact B-rep confirmation and the report), the others' swept.

Regressions: N12 (`new steering --module 4.5 --teeth 38` wrote a design whose check failed in the
plan hook: G1's flank, topped 0.5 mm above the form circle, is one chord on the mesh) and the
defects the fuzz found beside it (a small pinion's topped corner cut off the mesh outline by a
share of the tip radius; an untrimmed top rounded past the rack top; --set inputs of the design
chain used out of range); N3 (`new differential --teeth 0/0` divided by zero) and the other
degenerate numbers. GEARCHECK_NEW_FUZZ_SEED draws another sequence.
"""

from __future__ import annotations

import math
import os
import random
from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck import pipeline
from gearcheck.cli import main
from gearcheck.drafting import offering
from gearcheck.geometry.iso606_chains import DESIGNATIONS
from gearcheck.geometry.rack_pinion import pinion_local_xy, pinion_pose, pinion_tooth_pieces
from gearcheck.geometry.rack_pinion_contact import pair_contact
from gearcheck.geometry.rack_pinion_mesh import MARGINS, flank_chain, pair_margins
from gearcheck.mechanism import get
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import handover as ho
from gearcheck.mechanisms.steering.layout import PINION_BORE_DIAMETER_MM
from gearcheck.mechanisms.steering.meshes import pinion_profile
from gearcheck.sweep.bodies import MeshData

SEED = int(os.environ.get("GEARCHECK_NEW_FUZZ_SEED", "20240612"))
FLAGS = ("--module", "--teeth", "--chain", "--strands")
# Words and degenerate numbers drawn in place of a number now and then.
ODD = ("0", "-1", "-0.5", "1e-12", "1e9", "nan", "inf", "abc", "")


def _number(rnd: random.Random, lo: float, hi: float, log: bool = False) -> str:
    if rnd.random() < 0.15:
        return rnd.choice(ODD)
    if log:
        return f"{math.exp(rnd.uniform(math.log(lo), math.log(hi))):.4g}"
    return f"{rnd.uniform(lo, hi):.4g}"


def _teeth(rnd: random.Random, lo: int, hi: int) -> str:
    return rnd.choice(ODD) if rnd.random() < 0.1 else str(rnd.randint(lo, hi))


# Each mechanism's flags, drawn past both ends of what it allows (module 0.5–10 mm and 6–200 /
# 10–200 teeth for the differential; 0.1–50 mm and 10–400 teeth for the steering; the ISO 606
# chains, 9–150 teeth and 1–3 strands for the roller chain).
def _differential(rnd: random.Random) -> list[str]:
    small = _teeth(rnd, -2, 60) if rnd.random() < 0.7 else _teeth(rnd, -2, 220)
    return ["--module", _number(rnd, 0.3, 11.0), "--teeth", f"{small}/{_teeth(rnd, 5, 220)}"]


def _steering(rnd: random.Random) -> list[str]:
    if rnd.random() < 0.6:  # in range (the design chain runs, seconds a draw): accepted or refused
        return ["--module", f"{math.exp(rnd.uniform(math.log(0.1), math.log(50.0))):.4g}",
                "--teeth", str(rnd.randint(10, 400))]
    return ["--module", _number(rnd, 0.01, 500.0, log=True), "--teeth", _teeth(rnd, -5, 1000)]


def _roller_chain(rnd: random.Random) -> list[str]:
    chain = rnd.choice(DESIGNATIONS) if rnd.random() < 0.85 else rnd.choice(("12C", "08b", "bogus", "", "12"))
    args = ["--chain", chain, "--teeth", _teeth(rnd, -2, 160)]
    if rnd.random() < 0.6:
        args += ["--strands", rnd.choice(("1", "2", "3", "0", "4", "-1", "1.5", "x"))]
    return args


# mechanism → (draw, draws through new + calc): the steering's `new` runs the paper's design chain
# (seconds for a pinion in range, accepted or not), the others' take milliseconds to a second
DRAWS = {"differential": (_differential, 10), "steering": (_steering, 3), "roller_chain": (_roller_chain, 12)}


# The design checked of each mechanism, drawn where a check takes seconds, not minutes (the
# sweep's cost grows with the teeth and strands); the steering's is N12's (below).
def _checked_differential(rnd: random.Random) -> list[str]:
    small = rnd.randint(12, 16)
    return ["--module", f"{rnd.uniform(1.5, 5.0):.3g}", "--teeth", f"{small}/{rnd.randint(small + 2, 32)}"]


def _checked_roller_chain(rnd: random.Random) -> list[str]:
    return ["--chain", rnd.choice(DESIGNATIONS), "--teeth", str(rnd.randint(9, 25)), "--strands", rnd.choice("12")]


CHECKED = {"differential": _checked_differential, "roller_chain": _checked_roller_chain}


def _new(args: list[str], out: Path, capsys) -> tuple[int, list[str]]:
    code = main(["new", *args, "--out", str(out)])
    return code, capsys.readouterr().err.strip().splitlines()


def _assert_refused(args: list[str], code: int, err: list[str], out: Path) -> None:
    """Exit 2, one line: 'gearcheck: error: FLAG = VALUE: ...' with the allowed range (or, where the
    design chain has none to give, why no design exists); nothing written."""
    assert code == 2, (args, code, err)
    assert len(err) == 1, (args, err)
    line = err[0]
    assert line.startswith("gearcheck: error: "), (args, line)
    named = line.removeprefix("gearcheck: error: ")
    flag = named.partition(" = ")[0]
    assert " = " in named and (flag in FLAGS or flag.startswith("--set ")), (args, line)
    assert flag not in args or args[args.index(flag) + 1] in named, (args, line)  # its value, as given
    assert "allowed" in named or "no design by the paper's chain" in named, (args, line)
    assert "internal error" not in line and "Traceback" not in line, (args, line)
    assert not out.exists(), args


def _assert_calc(path: Path) -> gearcheck.Design:
    design = gearcheck.load(path)
    calc = design.calc()
    impl = design.impl
    bad = [f.key for f in calc.figures
           if math.isinf(f.value) or (math.isnan(f.value) and f.key not in impl.nan_figures)]
    assert not bad, (path.name, bad)
    return design


def test_every_mechanism_offering_new_is_fuzzed():
    ours = {n for n in offering() if type(get(n)).__module__.startswith("gearcheck.mechanisms.")}
    assert ours - {"assembly"} == set(DRAWS)


@pytest.mark.parametrize("mechanism", sorted(DRAWS))
def test_new_gives_a_design_or_one_line(mechanism, tmp_path, capsys):
    """Draws over the whole range through `new`, and each design written through `calc`."""
    draw, count = DRAWS[mechanism]
    rnd = random.Random(f"{SEED}:{mechanism}")
    for i in range(count):
        args = [mechanism, *draw(rnd)]
        out = tmp_path / f"draw{i}.toml"
        code, err = _new(args, out, capsys)
        if code == 0:
            _assert_calc(out)
        else:
            _assert_refused(args, code, err, out)


@pytest.mark.cad
@pytest.mark.parametrize("mechanism", sorted(CHECKED))
def test_a_design_new_writes_gets_a_verdict(mechanism, tmp_path, capsys):
    """A drawn design `new` accepts, built, meshed and swept at the mechanism's fuzz options (fewer
    poses; the hooks where N12 failed: plan, tasks, reduce, verdicts): a verdict (pass or fail), no
    error. The differential meshed at 0.05 mm; the roller chain at its own tolerance (a coarser one
    makes its certification between poses split far more, not less). The exact B-rep confirmation
    and the report, which the whole check adds (half a minute on the differential), run on N12's."""
    rnd = random.Random(f"{SEED}:{mechanism}:check")
    path = tmp_path / "design.toml"
    for _ in range(10):
        args = [mechanism, *CHECKED[mechanism](rnd)]
        code, err = _new(args, path, capsys)
        if code == 0:
            break
        _assert_refused(args, code, err, path)
    assert code == 0, f"no {mechanism} design in 10 draws from seed {SEED}"
    design = _assert_calc(path)
    run = pipeline.build(design, tmp_path / "cad", tol_mm=0.05 if mechanism == "differential" else None)
    result = pipeline.sweep(design, run.assembly, run.bodies, jobs=1, mesh_plan=run.mesh_plan,
                            options=design.impl.fuzz_options(design.params))
    assert result.verdicts and result.passed in (True, False), args


# ------------------------------------------------------------------------------------- regressions

@pytest.fixture(scope="module")
def n12(tmp_path_factory) -> Path:
    """N12's design, as the report wrote it: `gearcheck new steering --module 4.5 --teeth 38`."""
    path = tmp_path_factory.mktemp("n12") / "s.toml"
    assert main(["new", "steering", "--module", "4.5", "--teeth", "38", "--out", str(path)]) == 0
    return path


@pytest.mark.cad
def test_n12_steering_m4p5_z38_gets_a_verdict(n12, tmp_path):
    """N12, as reported: `new steering --module 4.5 --teeth 38` then its check (here coarse: one
    process, 2° steps). The plan hook failed with 'pinion flank ... has 1 chord on the mesh': the
    chain tops G1 to RS1 = 81.278 mm, 0.5 mm above the form circle, and that flank's one chord sags
    less than the mesh tolerance; the contact measurement needed two chords to fit the involute."""
    design = _assert_calc(n12)
    run = design.check(tmp_path / "sout", tol=0.02, jobs=1, options={"towing_step_deg": 2.0, "power_step_deg": 2.0})
    verdicts = {v.name: v.passed for v in run.verdicts}
    assert verdicts["mesh_agrees_with_exact"]  # the one-chord flank is measured as well as the others
    assert run.passed in (True, False)


def test_n12_a_one_chord_flank_is_read_as_its_involute(n12):
    """N12 on the drawing (no CAD): N12's design with the topped teeth's flanks as single chords
    (their two end vertices, as the 0.01 mm mesh has them). Such a flank still gives its involute
    (the base circle, exactly: two exact points of an involute of the pinion's axis determine it),
    and the tangency point on it passes G1's tip corner where the exact model's contact does."""
    g = an.geometry_from_params(gearcheck.load(n12).params)
    topped = (g.sector_first_tooth, g.sector_last_tooth)
    pts = []
    for j in range(g.sector_first_tooth, g.sector_last_tooth + 1):
        for piece in pinion_tooth_pieces(g, j, 2 if j in topped else 10, 6):  # 2 points: one chord
            rho, gam = piece.rho, piece.gamma
            if piece.kind == "tip":
                gam, rho = np.linspace(gam[0], gam[-1], 7), np.full(7, rho[0])
            pts.append(pinion_local_xy(rho, gam + (j + 0.5) * g.angular_pitch))
    pts = np.unique(np.round(np.concatenate(pts), 12), axis=0)
    profile = pts[np.argsort(np.arctan2(pts[:, 0], -pts[:, 1]))]
    corner = g.pinion_tip_corner(g.sector_first_tooth, 0.0, +1) - np.array([0.0, g.centre_height])
    assert len(flank_chain(profile, corner, +1, g.form_radius)) == 2  # N12's one chord
    rack = np.concatenate([g.rack_tooth_polygon(k, 0.0) for k in range(g.rack_first_tooth, g.rack_last_tooth + 1)])
    pairs = ho.flank_pairs(g, profile, rack, np.eye(4), "towing", +1)
    g1 = next(p for p in pairs if p.j == g.sector_first_tooth)
    assert g1.flank.base_radius == pytest.approx(g.base_radius, abs=1e-6)
    # where the tangency point on the fitted involute passes G1's tip corner S1 (the pinion_tip margin
    # changes sign) against the exact model's (G1's conjugate contact reaches S1 there: at the
    # target 60° plus the chain's 0.1°; N12's G1 is topped so far that it meets S2 only later)
    angles = np.radians(np.arange(55.0, 65.0, 0.05))
    poses = np.array([pinion_pose(g, float(a)) for a in angles])
    margins = pair_margins(g1.flank, poses[:, :2, :2], poses[:, :2, 3], g1.rack_top, g1.rack_root,
                           g.pitch_radius * angles, np.array([1.0, 0.0, 0.0]))
    tip = margins[:, MARGINS.index("pinion_tip")]
    i = int(np.flatnonzero((tip[:-1] > 0.0) & (tip[1:] <= 0.0))[0])
    crossing = angles[i] + (angles[i + 1] - angles[i]) * tip[i] / (tip[i] - tip[i + 1])
    assert math.degrees(crossing) == pytest.approx(math.degrees(pair_contact(g, "towing", g1.j, g1.k).end_rad),
                                                   abs=1e-4)


def test_a_small_pinions_topped_corner_stays_on_the_mesh_outline():
    """Found beside N12 (`new steering --module 5.664 --teeth 14`): the outline kept only vertices
    beyond 0.8 of the tip radius, and G1's tip corner at RS1 = 0.79·Ra was cut off ('the mesh has no
    vertex at the pinion tip corner'). The outline is now what lies outside the bore."""
    g = an.geometry_from_params(gearcheck.new("steering", module=5.664, teeth=14).params)
    assert g.topped_radius_mm < 0.8 * g.tip_radius
    outline = g.pinion_blank_outline(0.0) - np.array([0.0, g.centre_height])
    bore = 0.5 * PINION_BORE_DIAMETER_MM * np.stack([np.cos(np.linspace(0, 6, 40)), np.sin(np.linspace(0, 6, 40))], 1)
    ring = np.concatenate([outline, bore])
    vertices = np.concatenate([np.c_[ring, np.full(len(ring), z)] for z in (-15.0, 15.0)])
    profile = pinion_profile(MeshData("pinion", vertices, np.zeros((0, 3), int)), g.root_radius,
                             0.5 * PINION_BORE_DIAMETER_MM)
    assert len(profile) == len(outline)  # the whole outer outline, no bore
    corner = g.pinion_tip_corner(g.sector_first_tooth, 0.0, +1) - np.array([0.0, g.centre_height])
    assert np.min(np.hypot(*(profile - corner).T)) < 1e-9


def test_an_untrimmed_top_is_written_at_the_rack_top(tmp_path, capsys):
    """Found by the fuzz: at m = 3.18, z = 78 the untrimmed S2 (hS2 = the rack top, 21.464999… mm in
    floats) was written rounded to 21.465, above the top, and `new` refused its own design. It is
    written on the 1 µm grid below the top (the chain's machining resolution)."""
    path = tmp_path / "s.toml"
    code, err = _new(["steering", "--module", "3.18", "--teeth", "78"], path, capsys)
    assert code == 0, err
    g = an.geometry_from_params(gearcheck.load(path).params)
    assert g.rack_top_height - 1e-3 < g.hS2_mm <= g.rack_top_height


@pytest.mark.parametrize(("args", "words"), [
    (["differential", "--module", "3", "--teeth", "0/0"],  # N3, as reported
     ["--teeth = '0/0'", "small teeth 0: allowed 6 to 200", "big teeth 0: allowed 10 to 200"]),
    (["differential", "--module", "3", "--teeth", "1/1"], ["--teeth = '1/1'", "small teeth 1: allowed 6 to 200"]),
    (["differential", "--module", "3", "--teeth", "-5/20"], ["--teeth = '-5/20'", "allowed 6 to 200"]),
    (["differential", "--module", "3", "--teeth", "99999999999999999999999/30"], ["allowed 6 to 200"]),
    (["differential", "--module", "3", "--teeth", "6/10"], ["--teeth = '6/10'", "allowed small teeth >= "]),
    (["differential", "--module", "0", "--teeth", "14/30"], ["--module = '0'", "allowed a number from 0.5 to 10"]),
    (["differential", "--module", "9.858", "--teeth", "153/193"],
     ["--module = 9.858: allowed <= ", "dimensions.a_mm", "allowed >0.0 to 1000.0 mm"]),
    (["steering", "--module", "3", "--teeth", "1"], ["--teeth = 1", "allowed 10 to 400"]),
    (["steering", "--module", "0", "--teeth", "34"], ["--module = '0'", "allowed a number from 0.1 to 50"]),
    (["roller_chain", "--chain", "bogus", "--teeth", "21"], ["--chain = 'bogus'", "allowed an ISO 606 chain"]),
    (["roller_chain", "--chain", "12B", "--teeth", "21", "--strands", "0"], ["--strands = '0'", "1 to 3"]),
    (["roller_chain", "--chain", "12B", "--teeth", "0"], ["--teeth = '0'", "allowed 9 to 150"]),
], ids=lambda v: "_".join(v) if isinstance(v, list) and v and v[0] in DRAWS else None)
def test_degenerate_numbers_are_one_line_exit_2(args, words, tmp_path, capsys):
    out = tmp_path / "x.toml"
    code, err = _new(args, out, capsys)
    _assert_refused(args, code, err, out)
    for w in words:
        assert w in err[0], (w, err[0])


@pytest.mark.parametrize(("setting", "words"), [
    ("trim.hS4_mm=0.001", ["--set trim.hS4_mm = 0.001", "allowed >"]),  # was a math domain error (exit 3)
    ("trim.hS4_mm=nan", ["trim.hS4_mm = nan", "must be a finite number"]),
    ("pinion.pressure_angle_deg=0", ["pinion.pressure_angle_deg = 0.0", "allowed 10.0 to 35.0"]),  # was ÷ 0
])
def test_a_set_input_of_the_steering_chain_out_of_its_range_is_one_line(setting, words, capsys):
    assert main(["new", "steering", "--module", "5", "--teeth", "34", "--set", setting, "--out", "-"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "internal error" not in err[0], err
    for w in words:
        assert w in err[0], (w, err[0])
