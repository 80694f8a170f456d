"""The roller-chain drive measured on what gearcheck generates: the sprocket solid's faces against
ISO 606's tooth-form limits, and `gearcheck new` designs checked end to end through the command
line, their sweep's polygon effect and wear limit against calculations written here."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from gearcheck.cli import main
from gearcheck.geometry import iso606_chains as iso
from test_roller_chain import _independent_wear_limit

pytestmark = pytest.mark.cad


def _cylinders(shape):
    """(radius, axis location (x, y), angular span) of every cylinder of ``shape``'s faces (a face
    the kernel split at its surface's seam counts once, its pieces' spans added)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools

    out = []
    for face in shape.Faces():
        surf = BRepAdaptor_Surface(face.wrapped)
        if face.geomType() != "CYLINDER":
            continue
        cyl = surf.Cylinder()
        loc = cyl.Location()
        axis = cyl.Axis().Direction()
        assert abs(abs(axis.Z()) - 1) < 1e-12  # parallel to the sprocket axis
        u0, u1, _, _ = BRepTools.UVBounds_s(face.wrapped)
        out.append((cyl.Radius(), (loc.X(), loc.Y()), u1 - u0))
    merged: dict = {}
    for radius, (x, y), span in out:
        key = (round(radius, 6), round(x, 6), round(y, 6))
        merged[key] = (radius, (x, y), merged.get(key, (0, 0, 0.0))[2] + span)
    return list(merged.values())


@pytest.mark.parametrize("form", [0.0, 0.5, 1.0])
def test_sprocket_solid_seating_curve_lies_within_iso_606_limits(form):
    """The seating arcs, flanks and tip measured on the B-rep (their cylinders' radii, axes and
    spans), against the standard's formulas evaluated here."""
    import gearcheck
    from gearcheck.cad.sprocket import build_sprocket

    z, p, d1, b1 = 21, 19.05, 12.07, 11.68
    lo_da, hi_da = iso.tip_diameter_bounds(p, d1, z, form)
    da = min(136.45, hi_da - 0.05 * p)
    design = gearcheck.load("templates/roller_chain_12B_z21.toml",
                            [f"sprocket.form={form}", f"sprocket.tip_diameter_mm={da}"])
    solid = build_sprocket(design.impl.assembly(design.params).solids["sprocket"])
    d = p / math.sin(math.pi / z)
    ri_min, ri_max = 0.505 * d1, 0.505 * d1 + 0.069 * d1 ** (1 / 3)
    re_round, re_flat = 0.12 * d1 * (z + 2), 0.008 * d1 * (z * z + 180)
    a_min, a_max = math.radians(120 - 90 / z), math.radians(140 - 90 / z)
    seats, flanks, tips = [], [], []
    for radius, (x, y), span in _cylinders(solid):
        off = math.hypot(x, y)
        if off < 1e-9:
            if radius > d / 2:
                tips.append(radius)
        elif abs(off - d / 2) < 1e-6:
            seats.append((radius, span, off - radius))
        else:
            flanks.append(radius)
    assert len(seats) == z and len(flanks) == 2 * z and tips
    tol = 1e-7
    for radius, span, bottom in seats:
        assert ri_min - tol <= radius <= ri_max + tol  # the seating curve within ISO 606's limits
        assert radius == pytest.approx(ri_min + form * (ri_max - ri_min), abs=1e-9)
        assert a_min - 1e-9 <= span <= a_max + 1e-9
        assert span == pytest.approx(a_max - form * (a_max - a_min), abs=1e-9)
        # seating bottom: d − 2·ri, between the standard's two forms and at or below df = d − d1
        assert d - 2 * ri_max - tol <= 2 * bottom <= d - 2 * ri_min + tol <= d - d1
    for radius in flanks:
        assert re_round - tol <= radius <= re_flat + tol
        assert radius == pytest.approx(re_flat + form * (re_round - re_flat), abs=1e-7)
    assert max(tips) * 2 == pytest.approx(da, abs=1e-9)
    bb = solid.BoundingBox()
    assert bb.zlen == pytest.approx(design.params.sprocket.tooth_width_mm, abs=1e-9) and bb.zlen <= 0.95 * b1
    assert max(bb.xlen, bb.ylen) <= da + 1e-6


@pytest.fixture(scope="module")
def checked(tmp_path_factory):
    """`gearcheck new` then `gearcheck check` for each design, through the command line."""
    runs = {}

    def run(chain: str, teeth: int, strands: int | None = None):
        key = (chain, teeth, strands)
        if key not in runs:
            folder = tmp_path_factory.mktemp(f"{chain}_{teeth}")
            toml = folder / "design.toml"
            args = ["new", "roller_chain", "--chain", chain, "--teeth", str(teeth), "--out", str(toml)]
            assert main(args + (["--strands", str(strands)] if strands else [])) == 0
            code = main(["check", str(toml), "--out", str(folder / "out"), "--jobs", "2"])
            runs[key] = (code, folder / "out", json.loads((folder / "out" / "summary.json").read_text()))
        return runs[key]

    return run


@pytest.mark.parametrize(("chain", "teeth", "strands"), [("08B", 17, None), ("12B", 21, None), ("16A", 25, 2)])
def test_new_designs_get_a_verdict_with_no_edits(checked, chain, teeth, strands):
    code, out, summary = checked(chain, teeth, strands)
    assert code in (0, 1)
    verdicts = summary["roller_chain"]["verdicts"]
    assert verdicts["mesh_agrees_with_exact"] == 1 and verdicts["exact_confirmation"] == 1
    for name in ("report.html", "summary.json", "sweep.csv", "manifest.json"):
        assert (out / name).is_file()
    assert list(out.glob("*.step")) and list(out.glob("*.glb")) and list(out.glob("*.stl"))


def test_polygon_effect_and_wear_from_the_sweep_match_calculations_written_here(checked):
    code, out, summary = checked("12B", 21)
    assert code == 0
    s = summary["roller_chain"]
    z, p, d1 = 21, 19.05, 12.07
    R = p / (2 * math.sin(math.pi / z))
    # speed ripple and chordal rise measured on the meshes (gauge planes) vs the closed forms
    assert s["speed_ripple_pct"] == pytest.approx(100 * (1 - math.cos(math.pi / z)), rel=1e-6)
    assert s["chordal_rise_mm"] == pytest.approx(R * (1 - math.cos(math.pi / z)), abs=1e-6)
    # the wear limit (bisection on the exact contact) vs the independent calculation
    da = json.loads(json.dumps(s))  # plain copy
    tip = 136.45
    assert da["wear"]["limit_pct"] == pytest.approx(100 * _independent_wear_limit(p, d1, z, 0.5, tip), abs=1e-4)
    assert s["wear"]["replacement_limit_pct"] == 3.0
    # seated rollers: the exact B-rep measures ri − d1/2 between sprocket and roller
    ri = 0.505 * d1 + 0.5 * 0.069 * d1 ** (1 / 3)
    confirm = s["exact_confirmation"]
    assert confirm["least_roller_clearance"]["brep_mm"] == pytest.approx(ri - d1 / 2, abs=1e-6)
    assert abs(s["min_seated_roller_clearance_mm"] - (ri - d1 / 2)) <= s["mesh_error_bound_mm"]
    # plates against the tooth sides: (b1 − bf1)/2 on the B-rep
    assert confirm["least_plate_distance"]["brep_mm"] == pytest.approx((11.68 - 11.09) / 2, abs=1e-6)
    rows = (out / "sweep.csv").read_text().splitlines()
    assert len(rows) == s["poses"] + 1 and "span_speed_ratio" in rows[0]


def test_duplex_plates_clear_the_hub_at_the_iso_606_shroud_diameter(checked):
    _, _, summary = checked("16A", 25, 2)
    s = summary["roller_chain"]
    z, p, h2, b1 = 25, 25.4, 24.13, 15.75
    dg = p / math.tan(math.pi / z) - 1.04 * h2 - 0.76
    hub_gap = p / (2 * math.tan(math.pi / z)) - h2 / 2 - dg / 2  # seated link's chord middle over the hub
    axial = (b1 - math.floor(0.93 * b1 * 100) / 100) / 2
    assert s["exact"]["min_plate_distance_mm"] == pytest.approx(min(hub_gap, axial), abs=1e-9)
    assert abs(s["min_plate_distance_mm"] - min(hub_gap, axial)) <= s["mesh_error_bound_mm"]
    assert Path  # (typing import used)
