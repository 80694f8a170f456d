"""The mesh-resolution rule on its own (no CAD, no FCL): the tolerance follows from the smallest
clearance the design decides (pair bound ≤ c / 10, so c / 20 per part), a user's tolerance is
used as given, and a clearance no practical mesh resolves is left to the exact evidence — never
a refusal."""

from dataclasses import dataclass

import pytest

from gearcheck import resolution
from gearcheck.resolution import FINEST_TOL_MM, MeshPlan, assess, pair_bound, plan_tolerance
from gearcheck.results import Clearance


@dataclass
class FakeBody:
    error_bound_mm: float


BODIES = {"gear_a": FakeBody(0.003), "gear_b": FakeBody(0.0025), "gear_c": FakeBody(0.001)}


def test_pair_bound_sums_the_two_largest_parts():
    assert pair_bound(BODIES) == ("gear_a + gear_b", pytest.approx(0.0055))
    assert pair_bound({"only": FakeBody(0.2)}) == ("only", 0.2)


def test_default_tolerance_is_refined_to_resolve_the_clearance():
    c = Clearance(0.0358, "least cold play")
    plan = plan_tolerance(0.003, False, c)
    assert plan.refined and plan.tol_mm <= 0.0358 / 20 and plan.tol_mm == pytest.approx(0.00179)
    # meshed at that tolerance, both parts: pair bound 2·tol ≤ c / 10
    rule = assess(plan, {"big": FakeBody(plan.tol_mm), "small": FakeBody(plan.tol_mm)})
    assert rule.resolves and rule.pair_bound_mm <= rule.allowed_mm
    figures = rule.summary()
    assert figures["rule_met"] == 1 and plan.manifest()["refined"] and not plan.manifest()["explicit"]
    assert figures["smallest_clearance_mm"] == 0.0358 and figures["allowed_bound_mm"] == pytest.approx(0.00358)
    assert "refined from 0.003 mm" in rule.describe() and "resolves it" in rule.describe()


def test_a_coarse_enough_default_is_kept():
    plan = plan_tolerance(0.008, False, Clearance(0.75, "tip gap"))
    assert plan.tol_mm == 0.008 and not plan.refined


@pytest.mark.parametrize("value", [0.0, -0.01])
def test_a_clearance_to_resolve_is_a_positive_magnitude(value):
    with pytest.raises(ValueError, match="magnitude"):
        plan_tolerance(0.003, False, Clearance(value, "x"))


def test_an_explicit_tolerance_is_used_as_given_and_the_exact_evidence_decides():
    c = Clearance(0.0299, "least cold play per side")
    plan = plan_tolerance(0.003, True, c)
    assert plan.tol_mm == 0.003 and not plan.refined
    rule = assess(plan, {"a": FakeBody(0.003), "b": FakeBody(0.003)})
    assert not rule.resolves  # 0.006 > 0.00299: no exception, no refusal
    text = rule.describe()
    assert "\n" not in text and "fixed at 0.003 mm" in text and "exact B-rep" in text
    assert rule.summary()["rule_met"] == 0


def test_a_clearance_finer_than_any_practical_mesh_keeps_the_default():
    c = Clearance(0.00143, "least cold play per side at shim 0.056 mm")
    plan = plan_tolerance(0.003, False, c)
    assert plan.needed_mm < FINEST_TOL_MM and plan.tol_mm == 0.003
    rule = assess(plan, {"a": FakeBody(0.003), "b": FakeBody(0.003)})
    assert not rule.resolves and "finest practical mesh" in rule.describe()


def test_no_clearance_means_no_rule():
    plan = plan_tolerance(0.5, False, None)
    rule = assess(plan, {"pinion": FakeBody(0.5), "rack": FakeBody(0.5)})
    assert rule.resolves and plan.tol_mm == 0.5
    assert rule.summary()["rule_met"] == 1 and "smallest_clearance_mm" not in rule.summary()
    assert "no non-zero clearance" in rule.describe()


def test_rule_constants():
    assert resolution.BOUND_PER_CLEARANCE == 0.1 and resolution.PARTS_PER_PAIR == 2
    assert isinstance(plan_tolerance(0.01, False, None), MeshPlan)


def test_tol_help_names_each_mechanisms_default():
    """`check --help` spells each registered mechanism's default tolerance out (read from the
    mechanism when the help is shown): the values the build uses."""
    import re

    from gearcheck.arguments import build_parser
    from gearcheck.mechanism import all_mechanisms

    parser = build_parser()
    check = next(a for a in parser._subparsers._group_actions[0].choices.values() if a.prog.endswith("check"))
    text = " ".join(check.format_help().split())
    for mech in all_mechanisms():
        found = re.search(rf"{mech.name} ([0-9.]+)", text)
        assert found and float(found.group(1)) == mech.mesh_tol_mm, mech.name
