"""Verdicts about the design are counted apart from gearcheck's checks of its own evidence, and a
requirement a template states is a verdict: banner, terminal, summary.json and exit code agree."""

from __future__ import annotations

import json

import gearcheck
from conftest import TEMPLATES
from gearcheck.results import CheckResult, Verdict


def _result(*levels: tuple[str, str]) -> CheckResult:
    return CheckResult("x", {}, [Verdict.graded(n, n, lv, "m") for n, lv in levels], [])  # type: ignore[arg-type]


def test_counts_keep_the_design_apart_from_the_self_checks():
    r = _result(("a", "pass"), ("b", "warn"), ("mesh_agrees_with_exact", "pass"), ("exact_confirmation", "fail"))
    assert r.counts() == {"design": {"pass": 1, "warn": 1, "fail": 0}, "self_checks": {"pass": 1, "warn": 0, "fail": 1}}
    assert r.count_text() == "design 2 of 2 verdicts pass (1 with a warning); self-checks 1 of 2 pass"
    assert [v.name for v in r.design_verdicts] == ["a", "b"]


def test_the_papers_cold_backlash_requirement_is_a_verdict_at_the_templates_level():
    """Before: the banner said WARN "6 of 6 verdicts pass" while a box under it said the exact
    model and the geometry were 1.9′ short of the paper's ≥ 10′ cold requirement."""
    d = gearcheck.load(TEMPLATES / "zhurong_differential.toml")
    assert d.params.targets.cold_backlash_total_min_arcmin == 10.0 and d.params.targets.level == "warn"
    mine = gearcheck.load(TEMPLATES / "zhurong_differential.toml", overrides={"targets.level": "fail"})
    assert mine.params.targets.level == "fail"
    none = gearcheck.load(TEMPLATES / "zhurong_differential.toml", overrides={"targets.cold_backlash_total_min_arcmin": 0})
    assert none.params.targets.cold_backlash_total_min_arcmin == 0.0


def test_the_target_verdict_from_the_sweep_data(template_check):
    run = template_check("zhurong_differential")
    v = next(v for v in run.verdicts if v.name == "cold_backlash_target")
    geom, exact = v.figures["geom_cold_backlash_total_min_arcmin"], v.figures["exact_cold_backlash_total_min_arcmin"]
    cold = next(v for v in run.verdicts if v.name == "cold_play_positive").figures
    assert geom == 2 * cold["geom_play_min_arcmin_at_cold"] and exact == 2 * cold["exact_play_min_arcmin_at_cold"]
    assert v.level == "warn" and min(geom, exact) < 10.0 and "short by" in v.shortfall
    summary = json.loads((run.folder / "summary.json").read_text())["differential"]
    assert summary["verdict_levels"]["cold_backlash_target"] == "warn"
    assert summary["verdict_counts"]["design"]["warn"] >= 1 and summary["verdict_counts"]["self_checks"]["fail"] == 0
    page = (run.folder / "report.html").read_text()
    assert "WARN: design " in page and "cold total backlash ≥ 10′" in page


def test_a_target_at_the_default_level_fails_the_design(template_check):
    """A design of one's own states its target without a level: falling short fails it (exit 1)."""
    run = template_check("zhurong_differential", ("targets.level=fail",))
    v = next(v for v in run.verdicts if v.name == "cold_backlash_target")
    assert v.level == "fail" and not run.passed and run.result.level == "fail"
    assert json.loads((run.folder / "summary.json").read_text())["differential"]["verdict_pass"] == 0
