"""gearcheck.testing, the pytest plugin users test their designs and their mechanisms with.

- the assertions' messages name each failing verdict with its figure and shortfall, and an unknown
  verdict name with its close matches (on results built here, no check needed);
- outside the repository, under plain ``pytest`` in a fresh process (the plugin loaded by its
  ``pytest11`` entry point, nothing imported from this repository's tests): a user's test file
  against a copied template (the docs' example: check once, assert passed, a verdict, a watertight
  STL, a clearance), and a plugin package's mechanism tested by subclassing MechanismContract.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

from gearcheck.results import Verdict
from gearcheck.testing import assert_passed, assert_verdict, failure_text

ROOT = Path(__file__).resolve().parents[1]


@dataclass
class _Run:
    verdicts: list[Verdict]
    folder: Path = Path("out/x")


RUN = _Run([
    Verdict.of("no_interference", "no interference", True, "min clearance 0.12 mm"),
    Verdict.of("tip_gap", "tip 0.5–1.0 mm below the plate", False, "tip gap 0.31 mm",
               evidence="mesh sweep", shortfall="tip gap 0.31 mm, required ≥ 0.5 mm, short by 0.19 mm"),
    Verdict.graded("wear", "wear within the limit", "warn", "3.1 % of 3 %", shortfall="0.1 % over"),
])


def test_assert_passed_lists_each_failure_with_its_shortfall():
    with pytest.raises(AssertionError) as info:
        assert_passed(RUN)
    text = str(info.value)
    assert text.splitlines()[0] == "1 of 3 verdicts fail (report: out/x/report.html)"
    assert "FAIL tip_gap: tip 0.5–1.0 mm below the plate: tip gap 0.31 mm, required ≥ 0.5 mm, short by 0.19 mm " \
           "[mesh sweep]" in text
    assert "wear" not in text  # a warning does not fail
    assert_passed(_Run(RUN.verdicts[::2]))  # pass and warn: passes
    assert failure_text(RUN) == text


def test_assert_verdict_levels_and_unknown_names():
    assert_verdict(RUN, "no_interference")
    assert_verdict(RUN, "wear", "warn")
    with pytest.raises(AssertionError, match="verdict tip_gap is fail, expected pass"):
        assert_verdict(RUN, "tip_gap")
    with pytest.raises(AssertionError, match=r"no verdict 'tip_gaps' \(did you mean tip_gap\?\); this check has: "
                                             r"no_interference, tip_gap, wear"):
        assert_verdict(RUN, "tip_gaps")
    with pytest.raises(ValueError, match="allowed one of pass, warn, fail"):
        assert_verdict(RUN, "wear", "warning")


USER_TEST = '''
from gearcheck.testing import assert_passed, assert_verdict, assert_watertight, clearance_mm


def test_my_steering(gearcheck_check):
    run = gearcheck_check("designs/nose_wheel_steering.toml")
    assert_passed(run)
    assert_verdict(run, "rack_stops", "pass")
    assert_watertight(run, "pinion")
    assert clearance_mm(run, "pinion", "rack") >= 0.0


def test_same_design_is_checked_once(gearcheck_check):
    assert gearcheck_check("designs/nose_wheel_steering.toml") is gearcheck_check("designs/nose_wheel_steering.toml")


def test_a_failing_design_says_why(gearcheck_check):
    import pytest

    run = gearcheck_check("designs/nose_wheel_steering.toml", overrides=["trim.hS6_mm=26.15"])
    with pytest.raises(AssertionError) as info:
        assert_passed(run)
    assert "FAIL no_interference_anywhere" in str(info.value)
'''

PLUGIN_TEST = '''
from gearcheck.testing import MechanismContract
from spur_plugin import TEMPLATE, SpurPair


class TestSpurPair(MechanismContract):
    mechanism = SpurPair
    template = TEMPLATE
'''


def _plain_pytest(folder: Path, *args: str) -> subprocess.CompletedProcess:
    """``python -m pytest`` in ``folder``, a fresh process: this repository neither on its path nor
    its conftest in reach; gearcheck as installed (its plugin from the entry point)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTEST_ADDOPTS")}
    env["PYTHONPATH"] = os.pathsep.join([str(folder), *[p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                                                        if p and Path(p).resolve() != ROOT / "tests"]])
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", str(folder),
                           *args], cwd=folder, env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.cad
def test_a_users_test_file_runs_under_plain_pytest(tmp_path):
    """The docs' example, against a template copied with `gearcheck templates --copy`."""
    from gearcheck.cli import main

    assert main(["templates", "--copy", str(tmp_path / "designs")]) == 0
    (tmp_path / "test_my_designs.py").write_text(textwrap.dedent(USER_TEST))
    done = _plain_pytest(tmp_path, "test_my_designs.py")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    assert "3 passed" in done.stdout


@pytest.mark.cad
def test_a_plugin_outside_the_repository_keeps_the_contract(tmp_path):
    """A plugin package in a temporary folder (the spur pair of docs/extending.md as its module),
    tested by subclassing MechanismContract: every contract test is collected and passes."""
    package = tmp_path / "spur_plugin"
    package.mkdir()
    shutil.copyfile(ROOT / "tests" / "spur_pair.py", package / "__init__.py")
    (tmp_path / "test_spur_contract.py").write_text(textwrap.dedent(PLUGIN_TEST))
    done = _plain_pytest(tmp_path, "test_spur_contract.py", "-vv", "-W", "error::pytest.PytestUnknownMarkWarning")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    for name in ("test_analyse_gives_finite_figures", "test_calc_and_assembly_need_no_cad_kernel",
                 "test_assembly_poses_are_rigid_and_motions_typed", "test_plan_tasks_pickle_and_run_without_cadquery",
                 "test_check_gives_unique_verdicts_and_a_report"):
        assert f"TestSpurPair::{name} PASSED" in done.stdout, name
