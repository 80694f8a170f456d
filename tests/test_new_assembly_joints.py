"""``gearcheck new assembly`` guesses each part's joint from its shape, and leaves what a shape
cannot tell as a placeholder that does not validate.

Before: the commented example made the first part (a 120 × 12.5 × 10 mm bar) ``revolute`` about
the origin with ``ratio = -0.5``; uncommented as written it was accepted and then failed with no
hint that the joint was wrong.
"""

from __future__ import annotations

import re
import tomllib

import pytest

from gearcheck.cli import main
from gearcheck.mechanisms.assembly.design import guess_joint


def test_a_bar_slides_along_its_length():
    g = guess_joint(((0, 0, 0), (120, 12.5, 10)), 120 * 12.5 * 10, (60, 6.25, 5))
    assert g.kind == "prismatic" and g.axis == (1.0, 0.0, 0.0)


def test_a_round_part_turns_about_its_axis_through_its_centre():
    d, h = 40.0, 8.0
    g = guess_joint(((50 - d / 2, -d / 2, 3), (50 + d / 2, d / 2, 3 + h)), 0.9 * 3.14159 / 4 * d * d * h, (50, 0, 7))
    assert g.kind == "revolute" and g.axis == (0.0, 0.0, 1.0) and g.point == (50.0, 0.0, 7.0)


def test_a_square_block_is_not_round():
    """A 10 × 10 × 5 box has two equal extents but more volume than their cylinder."""
    assert guess_joint(((0, 0, 0), (10, 10, 5)), 500.0, (5, 5, 2.5)).kind is None


def _uncommented(text: str) -> str:
    head, _, tail = text.partition("# [[joint]]")
    tail = "# [[joint]]" + tail
    return head + "\n".join(re.sub(r"^# ?", "", line) for line in tail.splitlines()) + "\n"


def test_every_part_gets_a_joint_and_the_ratio_is_a_placeholder(tmp_path, capsys):
    import cadquery as cq

    step = tmp_path / "rack_pinion.step"
    a = cq.Assembly(name="root")
    a.add(cq.Workplane().box(120, 12.5, 10).translate((0, -25, 0)), name="rack")
    a.add(cq.Workplane().circle(20).extrude(10).translate((0, 0, -5)), name="pinion")
    a.export(str(step))
    out = tmp_path / "rp.toml"
    assert main(["new", "assembly", "--step", str(step), "--out", str(out)]) == 0
    text = out.read_text(encoding="utf-8")
    data = tomllib.loads(_uncommented(text))
    joints = {j["part"]: j for j in data["joint"]}
    assert set(joints) == {"rack", "pinion"}  # every part, not the first only
    assert joints["rack"]["kind"] == "prismatic" and joints["rack"]["axis"] == [1.0, 0.0, 0.0]
    assert joints["pinion"]["kind"] == "revolute" and joints["pinion"]["axis"] == [0.0, 0.0, 1.0]
    assert joints["pinion"]["point"] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)
    # uncommented as written, it is refused, naming the placeholder a shape cannot fill
    full = tmp_path / "rp_full.toml"
    full.write_text(_uncommented(text), encoding="utf-8")
    capsys.readouterr()
    assert main(["calc", str(full)]) == 2
    err = capsys.readouterr().err
    assert re.search(r"couple\.0\.(ratio|mm_per_rad|rad_per_mm)", err), err


def test_the_shipped_pair_reads_as_two_gears(tmp_path):
    from conftest import TEMPLATES

    out = tmp_path / "sp.toml"
    assert main(["new", "assembly", "--step", str(TEMPLATES / "assembly_spur_pair.step"), "--out", str(out)]) == 0
    data = tomllib.loads(_uncommented(out.read_text(encoding="utf-8")))
    points = [j["point"] for j in data["joint"]]
    assert [j["kind"] for j in data["joint"]] == ["revolute", "revolute"]
    # the wheel's axis at the pair's centre distance, m (z1 + z2) / 2 + 0.1 = 42.1 mm
    assert points[1] == pytest.approx([42.1, 0.0, 0.0], abs=1e-3) and points[0] == pytest.approx([0, 0, 0], abs=1e-3)
