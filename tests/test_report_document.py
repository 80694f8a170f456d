"""report.html as a design-review document, read back from a real failing run: the track template
with the tip gap overridden to 0.05 mm (below the paper's 0.5–1.0 mm window), one check shared by
every test here (about 40–60 s).

Checked on the page: the run's template and override in its header; the inputs table (every
template field with value, unit, description, allowed range, the template's value, the override
marked); the banner naming each failing claim with its shortfall; paper figures as printed and the
missed bound flagged; plots that scale (viewBox, no fixed size) with their text as <text>; the
B-rep table reading each pose the right way; links to the run's files; no internal labels."""

from __future__ import annotations

import base64
import html
import json
import re
from pathlib import Path

import pytest

from gearcheck.report import compare
from gearcheck.report.html import render
from gearcheck.report.inputs import input_rows, template_header
from gearcheck.report.plots import spread
from gearcheck.results import CheckResult, Comparison, Verdict

TEMPLATE = "eod_track_drive"
OVERRIDE = "track_plate.tip_gap_mm=0.05"


@pytest.fixture(scope="module")
def run(template_check):
    return template_check(TEMPLATE, (OVERRIDE,))


@pytest.fixture(scope="module")
def page(run) -> str:
    """The report the check wrote (read back from disk)."""
    return (Path(run.folder) / "report.html").read_text(encoding="utf-8")


@pytest.fixture(scope="module")
def summary(run) -> dict:
    return json.loads((Path(run.folder) / "summary.json").read_text())["track"]


def text_of(fragment: str) -> str:
    """Visible text of an HTML fragment (tags dropped, entities decoded, spaces collapsed)."""
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", fragment)).split())


def section(page: str, ident: str) -> str:
    """The HTML from the heading with this id to the next h2."""
    start = page.index(f"id='{ident}'")
    end = page.find("<h2", start + 1)
    return page[start:end if end > 0 else None]


def table_rows(fragment: str) -> list[list[str]]:
    """The cells' visible text of each <tr> of a fragment."""
    return [[text_of(c) for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row, re.S)]
            for row in re.findall(r"<tr[^>]*>(.*?)</tr>", fragment, re.S)]


# --- inputs --------------------------------------------------------------------------------------

def test_inputs_list_every_field_with_the_override_marked(run, page):
    design = run.build.design
    rows = input_rows(design, [OVERRIDE])
    model = type(design.params)
    fields = [f"{s}.{k}" for s, info in model.model_fields.items() for k in info.annotation.model_fields]
    assert [r.key for r in rows] == fields  # every field of the template model, in order, once
    by_key = {r.key: r for r in rows}
    gap = by_key["track_plate.tip_gap_mm"]
    assert (gap.value, gap.template_value, gap.overridden, gap.unit) == ("0.05", "0.75", True, "mm")
    assert gap.allowed == "0.05 to 5"
    assert gap.description == model.model_fields["track_plate"].annotation.model_fields["tip_gap_mm"].description
    assert [r.key for r in rows if r.overridden] == ["track_plate.tip_gap_mm"]
    teeth = by_key["sprocket.teeth"]
    assert (teeth.value, teeth.template_value, teeth.allowed) == ("49", "49", "7 to 301")
    assert by_key["robot.slope_deg"].allowed == "0 to < 90" and by_key["chain.pitch_mm"].allowed == "> 0 to 500"

    # the page as written: the header says the template was overridden, and how
    head = text_of(page[page.index("<h1"):page.index("id='summary'")])
    assert "templates/eod_track_drive.toml with overrides: track_plate.tip_gap_mm = 0.05 (template 0.75)" in head
    table = table_rows(section(page, "inputs"))
    shown = {r[0]: r for r in table if len(r) == 6}
    assert set(shown) >= set(fields)
    assert shown["track_plate.tip_gap_mm"][1] == "0.05" and "0.75 — overridden" in shown["track_plate.tip_gap_mm"][5]
    assert shown["sprocket.teeth"][1:3] == ["49", ""] and shown["sprocket.teeth"][4] == "7 to 301"
    assert sum("overridden" in r[5] for r in shown.values()) == 1


def test_template_header_names_the_paper(run):
    about = template_header(run.build.design)
    assert "Qiao Shuguang and Dong Cunxian" in about and "SIASUN" in about and not about.startswith(":")


# --- banner, differences ---------------------------------------------------------------------

def test_banner_names_each_failing_claim_with_its_shortfall(page, run):
    banner = page[page.index("id='summary'"):page.index("</div>", page.index("id='summary'"))]
    assert "class='banner fail'" in page
    failed = [v for v in run.result.verdicts if v.level == "fail"]
    assert {v.name for v in failed} >= {"seated_tip_gap_in_window", "min_tip_plate_distance"}
    items = re.findall(r"<li>(.*?)</li>", banner, re.S)
    assert len(items) == len(failed)  # every failing claim, nothing else
    by_name = {v.name: v for v in failed}
    least = by_name["min_tip_plate_distance"].figures["min_tip_plate_mm"]
    tip = text_of(next(i for i in items if html.escape(by_name["min_tip_plate_distance"].label) in i))
    assert f"least tip–plate distance {least:.4f} mm, required ≥ 0.5 mm, short by {0.5 - least:.4f} mm" in tip
    gap = by_name["seated_tip_gap_in_window"].figures["seated_tip_gap_mm"]
    window = text_of(next(i for i in items if html.escape(by_name["seated_tip_gap_in_window"].label) in i))
    assert f"seated tip gap {gap:.4f} mm, required 0.5–1 mm, short by {0.5 - gap:.4f} mm" in window
    assert abs(0.5 - gap - 0.45) < 0.01  # the override, measured


def test_paper_figures_as_printed_and_the_missed_bound_flagged(page, run):
    rows = table_rows(section(page, "comparisons"))
    lower = next(r for r in rows if r[0].startswith("paper's window, lower limit"))
    assert lower[2] == "≥ 0.5"  # as printed, and a bound
    assert not any(r[2] == "0.5000" for r in rows) and not any(r[2].endswith(".0000") for r in rows)
    comp = next(c for c in run.result.comparisons if c.label.startswith("paper's window, lower limit"))
    short = 0.5 - comp.geometry
    assert f"geometry {short:.4f} mm short of the paper's ≥ 0.5" in lower[6]
    row_html = next(r for r in re.findall(r"<tr>(.*?)</tr>", section(page, "comparisons"), re.S)
                    if "paper&#x27;s window, lower limit" in r)
    assert "class='major'" in row_html and "class='num major'" in row_html
    notice = text_of(page[page.index("class='notice'"):page.index("</div>", page.index("class='notice'"))])
    assert "paper's window, lower limit vs min tip-to-plate over the sweep" in notice and "≥ 0.5" in notice


def test_difference_sizes_and_printed_precision():
    assert [compare.paper_text(x) for x in (3.4, 110.2, 10.0, 6.8, 0.1)] == ["3.4", "110.2", "10", "6.8", "0.1"]
    assert compare.printed_half_unit(3.4) == pytest.approx(0.05) and compare.printed_half_unit(78.0) == 0.5
    # the differential's cold total at the paper's design: a bound (≥ 10′) not met by the geometry
    cold = Comparison("cold backlash total", "arcmin", 10.0, 10.07, 8.15, "a bound", exact=8.10, digits=2,
                      paper_is="min")
    assert compare.worst(cold) == "major"
    assert "geometry 1.85 arcmin short of the paper's ≥ 10" in text_of(compare.difference_cell(cold))
    drop = Comparison("cold drop", "arcmin", 3.4, 3.39, 4.36, "apexes", exact=4.35, digits=2)
    diffs = {d.column: d for d in compare.differences(drop)}
    assert diffs["model"].level == "" and diffs["model"].text == "agrees"  # within the printed 3.4 ± 0.05
    assert diffs["geometry"].level == "major" and diffs["geometry"].text == "+28\u00a0%"
    near = Comparison("disengage", "deg", 78.0, 76.011, None, digits=3)
    assert compare.worst(near) == "minor" and "−2.6" in text_of(compare.difference_cell(near))
    page = render(CheckResult("demo", {}, [Verdict.of("v", "claim", True, "ok")], [], comparisons=[cold, drop]),
                  title="t", template="x.toml", build={})
    cells = table_rows(section(page, "comparisons"))
    assert [r[2] for r in cells[1:]] == ["≥ 10", "3.4"] and cells[1][5] == "8.15"
    assert "2 figures differ from the paper" in text_of(page)


# --- plots, layout ---------------------------------------------------------------------------

def test_plots_scale_and_keep_their_text(page, run):
    svgs = re.findall(r"<svg\b[^>]*>", section(page, "plots"))
    assert len(svgs) == len(run.result.plots) >= 3
    for tag in svgs:
        assert re.search(r'viewBox="0 0 [\d.]+ [\d.]+"', tag) and 'width="100%"' in tag
        assert not re.search(r'\s(width|height)="[\d.]+(pt|px)?"', tag)
    assert "<meta name='viewport' content='width=device-width, initial-scale=1'>" in page
    assert "@media print" in page and "@media (max-width: 640px)" in page
    texts = [text_of(t) for t in re.findall(r"<text\b[^>]*>(.*?)</text>", section(page, "plots"), re.S)]
    assert "Track: tooth–sleeve clearance near the seat (zoom)" in texts
    assert "sprocket angle θ (°)" in texts
    assert 'id="DejaVuSans-' not in page  # no glyph outlines: the text is text


def test_zoom_shows_what_the_verdict_decides(run):
    zoom = next(p for p in run.result.plots if "zoom" in p.title)
    lo, hi = zoom.ylim
    mesh = min(min(s.y) for s in zoom.series if "mesh" in s.label and "off their seats" not in s.label)
    exact = min(min(s.y) for s in zoom.series if "exact" in s.label)
    seat = dict(zoom.hlines)[next(k for k in dict(zoom.hlines) if k.startswith("ri − R ="))]
    assert lo < mesh < hi and lo < exact < hi and lo < seat < hi
    assert hi - lo < 0.1  # against the full plot's 0–3.8 mm
    decided = next(v for v in run.result.verdicts if v.name == "no_interference").figures
    assert mesh == pytest.approx(decided["min_tooth_sleeve_mm"]) and exact == pytest.approx(
        decided["exact_min_tooth_sleeve_mm"])


def test_event_tags_spread_apart_in_order():
    # the steering plot's six events within 74–78° on a 0–100° axis
    xs = sorted([74.06, 75.32, 75.89, 76.01, 76.01, 78.0])
    wanted = [x / 100 for x in xs]
    placed = spread(wanted, 0.035, 0.01, 0.99)
    assert all(b - a >= 0.035 - 1e-9 for a, b in zip(placed, placed[1:], strict=False))
    assert abs(sum(placed) / len(placed) - sum(wanted) / len(wanted)) < 1e-9  # centred on the events
    assert spread([0.0, 0.001], 0.05, 0.01, 0.99)[0] >= 0.01 and spread([0.998, 1.0], 0.05, 0.0, 0.99)[-1] <= 0.99


# --- exact B-rep, files, words ---------------------------------------------------------------

def test_brep_table_reads_each_pose_the_right_way(page, summary):
    fragment = section(page, "exact")
    assert "overstate or understate the clearance by up to the pair's mesh-error bound" in text_of(fragment)
    assert "Mesh distances overstate clearance" not in page
    rows = table_rows(fragment)[1:]
    confirmed = summary["exact_confirmation"]
    assert len(rows) == len(confirmed)
    for r in rows:
        mesh, brep = float(r[2]), float(r[3])
        if abs(mesh - brep) < 5e-6:
            assert r[6] == "mesh and B-rep agree"
        else:
            assert r[6].startswith("mesh overstates" if mesh > brep else "mesh understates")


def test_every_file_of_the_run_is_linked(page, run):
    folder = Path(run.folder)
    names = sorted(p.name for p in folder.iterdir() if p.is_file() and not p.name.startswith(".")
                   and p.name != "report.html")
    links = set(re.findall(r"<a href='([^'#]+)'", section(page, "files")))
    assert set(names) <= links
    assert {"params.toml", "summary.json", "sweep.csv", f"{TEMPLATE}.step"} <= links


def test_no_internal_labels_in_the_page(page):
    words = text_of(re.sub(r"<svg.*?</svg>", " ", re.sub(r"<style>.*?</style>", " ", page, flags=re.S), flags=re.S))
    for pattern in (r"seed \d", r"\bissue \d", r"reference §", r"\bfinding \d", r"\btask \d", r"\.\./"):
        assert not re.search(pattern, words, re.I), pattern


def test_pictures_are_shown_with_their_captions(page, run):
    pngs = sorted(p.name for p in Path(run.folder).glob("*.png"))
    figures = re.findall(r"<figure><a href='([^']+)'><img src='([^']+)' alt='([^']*)'></a>"
                         r"<figcaption>(.*?)</figcaption></figure>", page, re.S)
    assert sorted(f[0] for f in figures) == pngs  # every picture beside the report, and only those
    for href, src, alt, caption in figures:
        # inlined (the page stands alone, no request beyond itself), the very bytes of the file it links
        assert src == "data:image/png;base64," + base64.b64encode((Path(run.folder) / href).read_bytes()).decode()
        assert alt and html.unescape(alt) == html.unescape(caption) and "{" not in caption
    if pngs:  # in print the pictures stand in for the interactive view
        assert "class='viewer screen-only'" in page and "nav.toc, .screen-only { display: none; }" in page


def test_events_beyond_the_data_widen_the_plot(recwarn):
    """A towing swing that ends short of the paper's events (50° against 74–78°): the events still
    show, each tag inside the figure (no layout warning), and the key names them with their unit."""
    from gearcheck.report.plots import plot_html
    from gearcheck.results import Plot, Series

    events = [("mesh re-engage", 74.06), ("paper theory", 75.32), ("ADAMS", 75.89), ("test", 78.0)]
    out = plot_html(Plot("towing", "pinion angle (deg)", "rack travel (mm)", [Series("mesh", [0, 25, 50], [0, 40, 80])],
                         markers=events))
    assert not [w for w in recwarn if "ight layout" in str(w.message)]
    svg = out[:out.index("</svg>")]
    view = [float(v) for v in re.search(r'viewBox="([^"]+)"', svg).group(1).split()]
    tags = re.findall(r"<text\b[^>]*\bx=\"([\d.]+)\"[^>]*>\s*([1-4])\s*</text>", svg)
    assert [t for _, t in tags] == ["1", "2", "3", "4"]
    xs = [float(x) for x, _ in tags]
    assert all(0 < x < view[2] for x in xs) and all(b - a > 5 for a, b in zip(xs, xs[1:], strict=False))
    assert "paper theory (75.32°)" in text_of(out) and "test (78°)" in text_of(out)
