"""The docs a newcomer reads: the README's first screen, its links, and the API reference made from
the docstrings (pdoc, offline) with a page for every hook's types."""

from __future__ import annotations

import re
import subprocess
import sys

from conftest import ROOT


def test_readme_is_a_quick_start_with_a_glossary_and_live_links():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 100
    quick = text.split("## Quick start", 1)[1].split("```sh", 1)[1].split("```", 1)[0].strip().splitlines()
    assert 5 <= len(quick) <= 12 and all(len(line) <= 110 for line in quick)
    for word in ("paper", "lost", "analytical model", "exact model", "exact B-rep", "worst pose", "evidence",
                 "thinning", "calibration"):
        assert f"**{word}**" in text, word
    for path in re.findall(r"docs/[a-z_]+\.(?:md|ipynb)", text):
        assert (ROOT / path).is_file(), path
    assert "../" not in text


def test_api_reference_builds_offline_with_every_hooks_types(tmp_path):
    make = (ROOT / "Makefile").read_text()
    modules = re.search(r"API_MODULES := (.*?)\n\n", make, re.S).group(1).replace("\\\n", " ").split()
    subprocess.run([sys.executable, "-m", "pdoc", "--docformat", "restructuredtext", "-o", str(tmp_path), *modules],
                   check=True, timeout=600, capture_output=True)
    pages = {p.relative_to(tmp_path).as_posix(): p.read_text() for p in tmp_path.rglob("*.html")}
    mechanism, results, testing = pages["gearcheck/mechanism.html"], pages["gearcheck/results.html"], \
        pages["gearcheck/testing.html"]
    for name in ("Mechanism", "SweepPlan", "Assembly", "PartSpec", "HookError", "new_inputs"):
        assert name in mechanism, name
    for name in ("Verdict", "Comparison", "Clearance", "WorstPose", "SweepOutcome", "CheckResult"):
        assert name in results, name
    for name in ("MechanismContract", "assert_passed", "assert_verdict", "gearcheck_check"):
        assert name in testing, name
    assert "gearcheck/drafting.html" in pages and "gearcheck/sweep.html" in pages
    assert not any("http://" in p.split("<body", 1)[-1] and "cdn" in p for p in pages.values())
