"""Report files from a CheckResult: deterministic numbers, CSV per pose, a self-contained HTML page."""

import csv
import io
import json
import math

from gearcheck.report.files import summary_json, sweep_csv
from gearcheck.report.html import render
from gearcheck.results import CheckResult, Comparison, Confirmation, Plot, Series, Verdict


def sample(passed=True, confirmed=False):
    return CheckResult(
        section="demo",
        summary={"play_min_arcmin": 1.25, "study": {"shims_mm": [0.0, 0.1]}, "nan_figure": math.nan, "flag": True},
        verdicts=[Verdict.of("no_interference", "no interference", passed, "min clearance 0.012 mm")],
        rows=[{"angle_deg": 0.0, "play": 1.0}, {"angle_deg": 0.5, "play": 1.1, "extra": "x"}],
        comparisons=[Comparison("drop", "arcmin", 3.4, 3.39, None, "paper form", exact=4.1)],
        plots=[Plot("play", "angle", "arcmin", [Series("warm", [0, 1], [1, 2])], markers=[("stop", 0.5)])],
        notes=["a finding"],
        confirmations=[Confirmation("worst pose", "worst", "a / b", 0.1, 0.099, 0.02)] if confirmed else [],
    )


def test_summary_is_plain_numeric_and_deterministic():
    text = summary_json(sample(confirmed=True))
    assert text == summary_json(sample(confirmed=True))
    data = json.loads(text)["demo"]
    assert data["verdict_pass"] == 1 and data["verdicts"] == {"no_interference": 1}
    assert data["nan_figure"] is None and data["flag"] == 1
    assert data["exact_confirmation"]["worst"]["brep_mm"] == 0.099
    assert json.loads(summary_json(sample(passed=False)))["demo"]["verdict_pass"] == 0


def test_sweep_csv_has_one_row_per_pose_and_all_columns():
    rows = list(csv.reader(io.StringIO(sweep_csv(sample()))))
    assert rows[0] == ["angle_deg", "play", "extra"]
    assert len(rows) == 3
    assert rows[1] == ["0", "1", ""] and rows[2] == ["0.5", "1.1", "x"]


def test_html_shows_verdict_tables_and_inline_plots():
    page = render(sample(passed=False, confirmed=True), title="t", template="x.toml", build={})
    assert "FAIL" in page and "design 0 of 1 verdicts pass" in page
    assert page.count("<svg") == 1 and "http://" not in page.split("<svg", 1)[0]
    assert ">3.4<" in page and "4.1000" in page and "a finding" in page
    assert "+0.00100" in page  # mesh − B-rep difference shown
