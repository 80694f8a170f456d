"""gearcheck in a notebook (src/gearcheck/notebook.py, docs/notebook.ipynb): results show themselves.

- Calc, Verdict, CheckResult/CheckRun and StudyResult have short one-line reprs and HTML tables
  (every text escaped); ``calc.keys()``, ``in``, and a KeyError naming the close matches;
- the example notebook executes headlessly (nbclient, a real IPython kernel): the check prints its
  progress stage by stage, and the outputs hold the HTML tables with the verdict badges.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

import gearcheck
from gearcheck.figures import Figure
from gearcheck.notebook import badge, calc_html, in_notebook, study_html, study_repr
from gearcheck.results import CheckResult, Verdict

ROOT = Path(__file__).resolve().parents[1]


def test_calc_is_a_readable_mapping():
    calc = gearcheck.load(ROOT / "templates" / "nose_wheel_steering.toml").calc()
    assert calc.keys() == [f.key for f in calc.figures] and "continuous_drive_deg" in calc
    assert "no_such_key" not in calc
    with pytest.raises(KeyError, match=r"no figure 'continuous_drive'; did you mean 'continuous_drive_deg'"):
        calc["continuous_drive"]
    assert calc.figure("continuous_drive_deg").unit == "deg"
    text = repr(calc)
    assert text.startswith("<Calc steering: ") and len(text) < 200 and "\n" not in text
    page = calc._repr_html_()
    assert page.count("<tr>") == len(calc.figures) + 1 and "<code>continuous_drive_deg</code>" in page


def test_html_escapes_and_drops_paper_columns_without_paper_values():
    figures = [Figure("a_mm", "<b>a</b> & b", 1.5, "mm", note="x < y")]
    page = calc_html("s", figures)
    assert "&lt;b&gt;a&lt;/b&gt; &amp; b" in page and "x &lt; y" in page and ">paper<" not in page
    with_paper = calc_html("s", [Figure("a_mm", "a", 1.5, "mm", paper=1.25)])
    assert ">paper<" in with_paper and "+0.250" in with_paper


def test_verdicts_and_checks_show_badges():
    result = CheckResult("steering", {}, [
        Verdict.of("ok", "fine", True, "1 mm"),
        Verdict.of("bad", "too close", False, "0.1 mm", evidence="mesh sweep"),
        Verdict.of("exact_confirmation", "confirmed", True, "agrees"),
    ], [])
    assert repr(result.verdicts[1]) == "<Verdict FAIL bad: 0.1 mm>"
    assert badge("fail") in result.verdicts[1]._repr_html_()
    text = repr(result)
    assert text == "<CheckRun steering: FAIL, design 1 of 2 verdicts pass; self-checks 1 of 1 pass; failing: bad>"
    page = result._repr_html_()
    assert page.count(badge("pass")) == 2 + 0 and badge("fail") in page and "evidence: mesh sweep" in page


def test_study_result_shows_probabilities():
    class _Table:
        num_rows = 8

    class _Result:
        spec = None
        table = _Table()
        folder = Path("out/study_x")
        summary = {"study": "wear", "samples": 8, "valid": 6, "rejected": 2, "failures": {
            "rides_up": {"label": "roller rides up", "side": "below", "limit": 0.0, "variants": 6, "failures": 3,
                         "probability": 0.5, "ci95_low": 0.19, "ci95_high": 0.81,
                         "over_drawn": {"variants": 8, "failures": 5, "probability": 0.625}}}}

    page = study_html(_Result())
    assert "6 valid variants, 2 rejected" in page and "50 % (19 % – 81 %)" in page and "5 / 8: 62.5 %" in page
    assert study_repr(_Result()) == "<StudyResult wear: 6 valid of 8 drawn; failure modes seen: rides_up; out/study_x>"


def test_not_a_notebook_here():
    assert not in_notebook()


@pytest.mark.cad
def test_the_example_notebook_runs_headless(tmp_path):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(ROOT / "docs" / "notebook.ipynb", as_version=4)
    first = next(c for c in nb.cells if c.cell_type == "code")
    assert 'OUT = Path("out")' in first.source
    first.source = first.source.replace('Path("out")', f"Path({str(tmp_path)!r})")
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}
                            ).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    html_out = " ".join(o.get("data", {}).get("text/html", "") for o in outputs)
    streams = " ".join(o.get("text", "") for o in outputs if o.get("output_type") == "stream")
    # progress while the check ran: one display updated in place (before: ~40 separate lines)
    boards = [o for o in outputs if "gearcheck-progress" in o.get("data", {}).get("text/html", "")]
    assert len(boards) == 1, len(boards)
    board = boards[0]["data"]["text/html"]
    assert "sweeping nose_wheel_steering" in board and "done in" in board and "100 %" in board
    assert "(100 %)" not in streams and "sweeping nose_wheel_steering …" not in streams
    # the tables: calc's figures, the check's verdicts with their badges
    assert "<code>continuous_drive_deg</code>" in html_out and badge("pass") in html_out
    assert "did you mean 'continuous_drive_deg'" in streams
    assert (tmp_path / "notebook_steering" / "report.html").is_file()
    hs6 = next(o for o in nb.cells[-1].outputs if o.get("output_type") == "execute_result")
    assert math.isfinite(float(hs6["data"]["text/plain"]))


def test_the_notebook_extra_runs_a_notebook_with_nbconvert():
    """Before: nbconvert was in no extra, so ``python -m nbconvert --execute`` (as docs/python.md
    says to run a notebook headlessly) failed with "No module named nbconvert"."""
    import subprocess
    import sys
    import tomllib

    from conftest import ROOT

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert any(d.startswith("nbconvert") for d in extras["notebook"])
    out = subprocess.run([sys.executable, "-m", "nbconvert", "--version"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
