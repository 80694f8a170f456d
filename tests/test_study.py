"""`gearcheck study`: reproducible variants on any executor, zero-width distributions give the
deterministic figures, a closed-form probability is recovered within its interval, rejected
variants are counted, and the folder is one transaction."""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy import stats as sps

import gearcheck
from gearcheck.cli import main
from gearcheck.params import ParamError
from gearcheck.studies import stats

TRACK_STUDY = """
title = "test study"
template = "eod_track_drive.toml"
samples = {samples}
seed = 11
exact = {exact}
check_worst = 0
rank_by = "analytical.wear_limit_tip_pct"

[[inputs]]
field = "chain.wear_elongation_pct"
distribution = "uniform"
low = 0.0
high = 3.0
unit = "%"
reason = "service life: new to beyond the usual replacement point"

[[inputs]]
field = "sprocket.seating_radius_mm"
distribution = "{dist}"
{shape}
unit = "mm"
reason = "grinding tolerance of the groove radius"

[[failures]]
name = "seat_large"
label = "seating radius above mean + 1 sd"
output = "analytical.seating_radius_mm"
above = 4.15
"""


def write(tmp_path: Path, samples=256, exact=0, dist="normal", shape="sd = 0.05") -> Path:
    path = tmp_path / "s.toml"
    path.write_text(TRACK_STUDY.format(samples=samples, exact=exact, dist=dist, shape=shape))
    return path


def test_wilson_interval_is_honest_at_zero_and_matches_a_textbook_case():
    p, lo, hi = stats.wilson(0, 100)
    assert p == 0 and lo == 0 and hi == pytest.approx(0.0370, abs=2e-4)  # ≈ 3.8 / n
    p, lo, hi = stats.wilson(10, 100)
    assert (lo, hi) == (pytest.approx(0.0552, abs=2e-4), pytest.approx(0.1744, abs=2e-4))


def test_src_recovers_known_linear_sensitivities():
    rng = np.random.default_rng(0)
    x = {"a": rng.normal(size=4000), "b": rng.normal(size=4000), "flat": np.zeros(4000)}
    y = 3 * x["a"] + 1 * x["b"]
    coef, r2 = stats.src(x, y)
    assert r2 == pytest.approx(1.0) and coef["flat"] == 0.0
    assert coef["a"] == pytest.approx(3 / math.sqrt(10), abs=0.02) and coef["b"] == pytest.approx(1 / math.sqrt(10), abs=0.02)


def test_closed_form_probability_and_rejections(tmp_path):
    """Seating radius ~ N(4.1, 0.05), validation allows the ISO 606 range 4.040–4.178 mm: the
    rejected count is exactly the number of draws outside it, and P(r > 4.15 | valid) matches the
    truncated normal's closed form within the Wilson interval."""
    res = gearcheck.study(write(tmp_path, samples=1024), jobs=1, out=tmp_path / "study")
    s = res.summary
    r = np.asarray(res.table.column("in.sprocket.seating_radius_mm").to_numpy())
    assert s["rejected"] == int(np.sum((r > 4.178) | (r < 4.04))) > 0
    assert all("sprocket.seating_radius_mm" in x["reason"] and "allowed" in x["reason"] for x in s["rejections"])
    f = s["failures"]["seat_large"]
    nd = sps.norm(4.1, 0.05)
    exact = (nd.cdf(4.178) - nd.cdf(4.15)) / (nd.cdf(4.178) - nd.cdf(4.04))
    assert f["ci95_low"] <= exact <= f["ci95_high"]
    assert f["probability"] == pytest.approx(exact, abs=0.02)
    assert f["variants"] == s["valid"] == 1024 - s["rejected"]
    # the report reads at phone width: viewport, plots that scale to the page (no fixed pixel width)
    page = (tmp_path / "study" / "report.html").read_text()
    svgs = re.findall(r"<svg[^>]*>", page)
    assert "name='viewport'" in page and svgs
    assert all("width=\"100%\"" in t and "viewBox" in t and "pt\"" not in t for t in svgs)


def test_zero_width_distributions_reproduce_calc_exactly(tmp_path):
    res = gearcheck.study(write(tmp_path, samples=4, dist="uniform", shape="low = 4.12\nhigh = 4.12"), jobs=1)
    calc = gearcheck.load("templates/eod_track_drive.toml", {"sprocket.seating_radius_mm": 4.12}).calc().to_dict()["track"]
    t = res.table
    for i in range(4):
        wear = float(t.column("in.chain.wear_elongation_pct")[i].as_py())
        calc_i = gearcheck.load("templates/eod_track_drive.toml", {"sprocket.seating_radius_mm": 4.12,
                                                                  "chain.wear_elongation_pct": wear}).calc().to_dict()["track"]
        for key in ("wear_limit_tip_pct", "sleeve_flank_clearance_at_tip_mm", "tip_land_width_mm"):
            assert t.column(f"analytical.{key}")[i].as_py() == calc_i[key] == calc[key]


@pytest.mark.parametrize("jobs", [2])
def test_same_rows_on_every_executor(tmp_path, jobs):
    """One process, local processes and a 2-worker Dask LocalCluster: the same table, row for row."""
    path = write(tmp_path, samples=96)
    serial = gearcheck.study(path, jobs=1).table
    pool = gearcheck.study(path, jobs=jobs).table
    dask = gearcheck.study(path, jobs=jobs, scheduler="local-cluster").table
    assert serial.equals(pool) and serial.equals(dask)
    other = gearcheck.study(path, jobs=1, seed=12).table
    assert not serial.equals(other)


def test_cli_writes_one_transaction_and_bad_input_is_one_line(tmp_path, capsys):
    path = write(tmp_path, samples=32)
    out = tmp_path / "out"
    assert main(["study", str(path), "--out", str(out), "--jobs", "1"]) == 0
    # piped (stderr not a terminal): a line per stage and per tenth of its work, not minutes of silence
    err = capsys.readouterr().err
    assert "study: analytical model …" in err and "analytical model: 32/32 variant (100 %)" in err
    assert "done in" in err
    names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == ["manifest.json", "report.html", "results.parquet", "summary.json"]
    manifest = json.loads((out / "manifest.json").read_text())
    assert set(manifest["files"]) == {"report.html", "results.parquet", "summary.json"}
    page = (out / "report.html").read_text()
    assert "<meta name='viewport'" in page and "Wilson" in page and "http://" not in page.split("<svg", 1)[0]
    bad = tmp_path / "bad.toml"
    bad.write_text(path.read_text().replace('distribution = "uniform"', 'distribution = "weibull"'))
    assert main(["study", str(bad), "--out", str(tmp_path / "o2")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "distribution" in err[0] and "weibull" in err[0]
    assert not (tmp_path / "o2").exists()


def test_study_spec_rejects_inconsistent_distributions(tmp_path):
    path = write(tmp_path, dist="truncnorm", shape="sd = 0.05")
    with pytest.raises(ParamError, match="truncated normal needs low, high or both"):
        gearcheck.study(path, jobs=1)


def test_shipped_studies_validate_and_name_shipped_templates():
    from gearcheck.studies.spec import load_spec, packaged_studies, template_path

    files = sorted(packaged_studies().glob("*.toml"))
    assert files
    for path in files:
        spec = load_spec(path)
        tpl = template_path(spec, path)
        design = gearcheck.load(tpl)
        for i in spec.inputs:
            node = design.data
            for part in i.field.split("."):
                node = node[part]
            assert isinstance(node, (int, float)), (path.name, i.field)
        assert spec.failures and all(i.reason for i in spec.inputs)


def test_track_wear_study_exact_level_finds_the_jump_where_the_wear_passes_the_limit(tmp_path):
    """The exact level of the shipped track study: a link jumps exactly when the chain's
    elongation (wear + pitch tolerance) passes the tooth form's limit (the closed form, 1.656 %)."""
    res = gearcheck.study("src/gearcheck/templates/studies/track_wear.toml", samples=16, jobs=1, check_worst=0)
    t = res.table.to_pydict()
    for e, limit, jumps in zip(t["exact.wear_pct"], t["exact.wear_limit_tip_pct"], t["exact.link_jumps"], strict=True):
        assert limit == pytest.approx(1.6564, abs=2e-3)  # seating radius varies by a few µm
        assert jumps == float(e > limit)
    elong = np.asarray(t["field.chain.wear_elongation_pct"])
    assert np.allclose(elong, np.asarray(t["in.wear"]) + np.asarray(t["in.pitch_tolerance"]))
    assert np.allclose(elong, t["exact.wear_pct"])


def test_differential_paper_model_vectorised_equals_variant_by_variant():
    """The analytical level over arrays (study_batch) gives each variant's own figures exactly."""
    base = gearcheck.load("templates/zhurong_differential.toml")
    cols = {"materials.housing_cte_per_K": np.array([23.6e-6, 24.4e-6, 22.9e-6]),
            "shim.thickness_mm": np.array([0.10, 0.104, 0.097]),
            "calibration.measured_shim_mm": np.array([0.10, 0.104, 0.097]),
            "calibration.measured_backlash_total_min_arcmin": np.array([16.8, 17.9, 18.8]),
            "operating.storage_min_C": np.array([-130.0, -127.0, -136.0])}
    batch = base.impl.study_batch(base.params, cols)
    for i in range(3):
        one = gearcheck.load("templates/zhurong_differential.toml", {k: float(v[i]) for k, v in cols.items()})
        row = one.impl.study_row(one.params, "analytical")
        for k, v in row.items():
            assert batch[k][i] == pytest.approx(v, rel=1e-12, abs=1e-12), k


def test_differential_exact_row_reproduces_the_calibration_and_binds_in_storage_only():
    d = gearcheck.load("templates/zhurong_differential.toml")
    row = d.impl.study_row(d.params, "exact")
    assert 2 * row["warm_play_arcmin"] == pytest.approx(16.8, abs=1e-3)  # solved to reproduce it
    # the warm play is the calibration's own last solve (not evaluated twice): the exact model's figure
    from gearcheck.mechanisms.differential import temperature as tp
    op = d.params.operating
    independent = tp.exact_plays(d.params, d.params.shim.thickness_mm, [op.warm_C, op.cold_C]).least_arcmin
    assert (row["warm_play_arcmin"], row["cold_play_arcmin"]) == (independent[0], independent[1])
    assert row["least_play_operating_arcmin"] > 0 > row["least_play_storage_arcmin"]
    paper = d.impl.study_row(d.params, "analytical")
    assert paper["warm_play_arcmin"] == pytest.approx(8.4)
    assert paper["least_play_storage_arcmin"] > 0  # the linear model misses the storage binding


@pytest.mark.cad
def test_zero_width_study_checks_exactly_what_check_checks(tmp_path):
    """Level 3 on a zero-width variant (every input at its template value) writes the same
    summary.json, byte for byte, as `gearcheck check` of the template; its folder is linked."""
    path = write(tmp_path, samples=2, exact=-1, dist="uniform", shape="low = 4.1\nhigh = 4.1")
    path.write_text(path.read_text().replace("low = 0.0\nhigh = 3.0", "low = 1.5\nhigh = 1.5")
                    .replace("check_worst = 0", "check_worst = 1"))
    res = gearcheck.study(path, jobs=1, out=tmp_path / "study")
    (check,) = res.summary["checks"]
    assert check["level"] == "pass" and check["folder"] == f"checks/variant_{check['variant']:05d}"
    variant = tmp_path / "study" / check["folder"]
    assert main(["check", "templates/eod_track_drive.toml", "--jobs", "1", "--out", str(tmp_path / "direct")]) == 0
    assert (variant / "summary.json").read_bytes() == (tmp_path / "direct" / "summary.json").read_bytes()
    page = (tmp_path / "study" / "report.html").read_text()
    assert f"href='{check['folder']}/report.html'" in page
    t = res.table.to_pydict()
    assert t["check.level"][check["variant"]] == "pass"


def test_templates_lists_the_shipped_studies_and_study_runs_one_by_name(capsys, tmp_path):
    assert main(["templates"]) == 0
    out = capsys.readouterr().out
    for name in ("differential_tolerances", "track_wear", "steering_tolerances"):
        assert name in out
    assert main(["study", "no_such_study", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no_such_study" in err[0] and "track_wear" in err[0]


def test_study_report_reads_like_the_check_report(tmp_path):
    """Before: raw keys as axis labels, offset notation ("+1.656"), legends inside the axes, a
    paper-vs-exact identity plot with nothing to see, P(fail) curves of noise at 64 variants, and a
    red "1 of 3 failure modes seen" headline for a study that draws wear past the limit on purpose.
    Now: labels in words with their unit and level, no offsets, the headline sets each failure's
    count against the distributions drawn (neutral, not a verdict), curves only from 200 variants,
    and the two models' difference (or one line where they agree everywhere)."""
    import re

    from gearcheck.studies.report import CURVE_MIN_VARIANTS, label_of

    assert label_of("exact.wear_margin_pct") == "wear margin (%), exact model"
    assert label_of("analytical.seating_radius_mm", {"seating_radius_mm": "seating radius ri"}) == \
        "seating radius ri (mm), paper's model"
    res = gearcheck.study(write(tmp_path, samples=64), jobs=1, out=tmp_path / "out")
    page = (tmp_path / "out" / "report.html").read_text()
    banner = re.search(r"<div class='banner (\w+)'>(.*?)</div>", page, re.S)
    assert banner.group(1) == "info" and "drawn from: chain.wear_elongation_pct uniform 0 to 3 %" in banner.group(2)
    assert "seat_large</code> (seating radius above mean + 1 sd): " in banner.group(2)
    assert res.summary["failures"]["seat_large"]["variants"] < CURVE_MIN_VARIANTS
    assert "fewer than the 200 a curve needs" in page
    svg_text = " ".join(re.findall(r"<text[^>]*>([^<]*)</text>", page))
    assert "analytical.seating_radius_mm" not in svg_text and "paper&#x27;s model" in page or "paper's model" in page
    assert not re.search(r"[+−-]\d\.\d+e?[+−-]?\d*\s*$", svg_text)  # no offset text on an axis
