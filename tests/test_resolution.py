"""The mesh-resolution rule on its own (no CAD, no FCL): bound ≤ clearance / 10, else a one-line
--tol error naming the value and the allowed range."""

from dataclasses import dataclass

import pytest

from gearcheck.params import ParamError
from gearcheck.pipeline import apply_resolution_rule
from gearcheck.resolution import describe, resolution_summary, violation
from gearcheck.results import CheckResult, Clearance


@dataclass
class FakeBody:
    error_bound_mm: float


def result_with(clearance):
    return CheckResult("x", {}, [], [], smallest_clearance=clearance)


@dataclass
class FakeDesign:
    source: str = "t.toml"


BODIES = {"gear_a": FakeBody(0.003), "gear_b": FakeBody(0.0025)}


def test_bound_within_a_tenth_passes():
    result = result_with(Clearance(0.030, "least play"))
    assert violation(result, BODIES) is None  # 0.003 ≤ 0.030 / 10: equality is allowed
    figures = resolution_summary(result, BODIES)
    assert figures == {"largest_part_error_bound_mm": 0.003, "smallest_clearance_mm": 0.030,
                       "allowed_bound_mm": pytest.approx(0.003), "rule_met": 1}
    assert "gear_a" in describe(result, BODIES)


def test_bound_above_a_tenth_is_a_tol_error():
    result = result_with(Clearance(0.0299, "least cold play per side"))
    with pytest.raises(ParamError) as err:
        apply_resolution_rule(FakeDesign(), result, BODIES, 0.003)
    text = str(err.value)
    assert "\n" not in text
    assert text.startswith("t.toml: --tol = 0.003: allowed ≤ 0.00299 mm")
    assert "gear_a" in text and "least cold play per side" in text
    assert err.value.field == "--tol"


def test_no_clearance_checked_means_no_rule():
    result = result_with(None)
    apply_resolution_rule(FakeDesign(), result, {"pinion": FakeBody(0.5)}, 0.5)
    assert result.summary["mesh_resolution"] == {"largest_part_error_bound_mm": 0.5, "rule_met": 1}
    assert "no non-zero clearance" in describe(result, {"pinion": FakeBody(0.5)})


def test_tol_help_names_each_mechanisms_default():
    """`check --help` spells each registered mechanism's default tolerance out (read from the
    mechanism when the help is shown): the values the build uses."""
    import re

    from gearcheck.cli import build_parser
    from gearcheck.mechanism import all_mechanisms

    parser = build_parser()
    check = next(a for a in parser._subparsers._group_actions[0].choices.values() if a.prog.endswith("check"))
    text = " ".join(check.format_help().split())
    for mech in all_mechanisms():
        found = re.search(rf"{mech.name} ([0-9.]+)", text)
        assert found and float(found.group(1)) == mech.mesh_tol_mm, mech.name
