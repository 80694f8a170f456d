"""report.html: a design-review document of one check.

Order: what was checked (template, overrides, the run's files) and the verdict, with every failing
or warning claim named with its shortfall and the large differences from the paper listed; the
geometry (interactive 3-D view, pictures for print); the verdicts; paper vs model vs geometry with
each difference flagged by its size beside its reason; the worst poses on the exact B-rep; the
plots; the notes; the inputs as run; the files.

One self-contained file (inline CSS, inline SVG plots, no network): it can be mailed or archived
with the STEP/STL files it describes. It reads on a phone (no sideways scrolling of the page:
plots scale to the width, tables become stacked rows) and prints (the pictures stand in for the
interactive view).
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from urllib.parse import quote

from gearcheck import __version__
from gearcheck.report import compare
from gearcheck.report.inputs import InputRow
from gearcheck.report.plots import figure_svg, marker_key, plot_html, plot_svg
from gearcheck.results import CheckResult, Comparison, Confirmation, Verdict

__all__ = ["CSS", "figure_svg", "marker_key", "plot_svg", "render"]

CSS = """
body { font-family: -apple-system, 'Segoe UI', Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 1100px; color: #1d2330; line-height: 1.45; padding: 0 1em; }
h1 { margin-bottom: 0.2em; overflow-wrap: anywhere; } h2 { margin-top: 1.6em; border-bottom: 1px solid #dde; }
.banner { padding: 0.8em 1.2em; border-radius: 6px; font-size: 1.25em; font-weight: 600; }
.pass { background: #e3f5e6; color: #17612a; border: 1px solid #9fd3a9; }
.fail { background: #fbe6e6; color: #8a1c1c; border: 1px solid #e3a3a3; }
.warn { background: #fdf3dc; color: #7a5200; border: 1px solid #e6c77a; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.93em; }
th, td { border: 1px solid #d6d9e0; padding: 0.3em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f4f8; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.ok { color: #17612a; font-weight: 600; } td.bad { color: #8a1c1c; font-weight: 600; }
td.warned { color: #7a5200; font-weight: 600; }
.meta { color: #5a6275; font-size: 0.9em; } .plot { margin: 1em 0; }
.key { font-size: 0.82em; color: #3a4255; margin: 0.2em 0 0 4em; max-width: 60em; }
.notes li { margin: 0.3em 0; } code { background: #f2f4f8; padding: 0 0.25em; }
"""

# The review document's own styles (on top of CSS, which the study report shares).
PAGE_CSS = """
code { overflow-wrap: anywhere; }
.banner ul { margin: 0.5em 0 0 0; padding-left: 1.2em; font-size: 0.78em; font-weight: 400; }
.banner li { margin: 0.25em 0; }
.notice { margin: 0.8em 0; padding: 0.6em 1.2em; border-radius: 6px; background: #fff4f0; font-size: 0.95em;
          border: 1px solid #e8b4a0; color: #6b2412; }
.notice ul { margin: 0.3em 0 0 0; padding-left: 1.2em; } .notice li { margin: 0.3em 0; }
nav.toc { font-size: 0.9em; margin: 0.8em 0; } nav.toc a { margin-right: 0.9em; white-space: nowrap; }
.scroll { overflow-x: auto; max-width: 100%; }
.scroll table { width: 100%; }
td { overflow-wrap: anywhere; }
td.num, td.val, td.unit, td.nw { overflow-wrap: normal; white-space: nowrap; }
td.key code { white-space: nowrap; overflow-wrap: normal; }
td.minor { background: #fff3cf; } td.major { background: #fbd9d9; font-weight: 600; }
tr.v-fail td { background: #fdf0f0; } tr.v-warn td { background: #fffaf0; }
tr.v-fail td:first-child { border-left: 4px solid #c24040; }
tr.v-warn td:first-child { border-left: 4px solid #d49a1c; }
tr.over td { background: #fff3cf; } tr.section td { background: #f7f8fb; font-weight: 600; }
span.vs { color: #5a6275; font-weight: 400; }
.small { font-size: 0.85em; color: #5a6275; }
.plot svg { width: 100%; max-width: 900px; height: auto; display: block; }
.key { margin-left: 0; } .key .it, .key .ev { display: inline-block; margin: 0.1em 1.1em 0.1em 0; }
.sw { display: inline-block; width: 1.6em; vertical-align: middle; text-align: center; }
.sw.ln { border-top: 2px solid; } .sw.hl { border-top: 2px dotted; } .sw.pt { font-weight: 700; }
.caption { font-size: 0.85em; color: #3a4255; margin: 0.3em 0 0 0; }
.viewer { margin: 0.6em 0; }
.pictures { display: grid; grid-template-columns: repeat(auto-fill, minmax(160px, 1fr)); gap: 0.8em; margin: 0.6em 0; }
.pictures figure { margin: 0; } .pictures img { width: 100%; height: auto; border: 1px solid #d6d9e0; }
.pictures figcaption { font-size: 0.85em; color: #3a4255; }
.print-only { display: none; }
@media (max-width: 640px) {
  body { padding: 0 0.6em; margin: 1em auto; }
  .banner { font-size: 1.08em; padding: 0.6em 0.8em; }
  table.stack, table.stack tbody, table.stack tr, table.stack td { display: block; width: auto; }
  table.stack tr.head { display: none; }
  table.stack tr { border: 1px solid #d6d9e0; border-radius: 4px; margin: 0 0 0.6em 0; }
  table.stack td { border: none; border-bottom: 1px solid #eceef3; text-align: left; white-space: normal; }
  table.stack td[data-h]::before { content: attr(data-h); display: block; font-size: 0.78em; color: #5a6275;
                                   font-weight: 400; }
  table.stack tr.section td::before { content: none; }
  table.stack td.num { display: inline-block; box-sizing: border-box; width: 49%; vertical-align: top;
                       text-align: left; }
  table.stack td.empty, table.stack td.unit { display: none; }
  td.key code { white-space: normal; overflow-wrap: anywhere; }
}
@media print {
  body { max-width: none; margin: 0; padding: 0; font-size: 10pt; }
  .banner, .notice, td.minor, td.major, tr.over td { print-color-adjust: exact;
                                                     -webkit-print-color-adjust: exact; }
  nav.toc, .screen-only { display: none; }
  .print-only { display: block; }
  .scroll { overflow: visible; }
  h2 { break-after: avoid; } tr, .plot, figure, .banner, .notice { break-inside: avoid; }
  .pictures { grid-template-columns: repeat(2, 1fr); }
}
"""

KIND = {".step": "CAD assembly (STEP, exact B-rep)", ".stp": "CAD assembly (STEP, exact B-rep)",
        ".stl": "part mesh (STL, as swept)", ".glb": "3-D scene (glTF binary)", ".csv": "per-pose figures (CSV)",
        ".json": "figures (JSON)", ".toml": "parameters as run (TOML; re-run it with gearcheck check)",
        ".png": "picture (PNG)", ".html": "page (HTML)", ".parquet": "table (Parquet)"}
NAMED = {"summary.json": "every figure and verdict (JSON)", "manifest.json": "the run's parts and files (JSON)",
         "sweep.csv": "per-pose figures of the sweep (CSV)", "params.toml": KIND[".toml"]}


def _e(text: str) -> str:
    return html.escape(str(text), quote=True)


def _td(header: str, body: str, cls: str = "") -> str:
    """A cell that names its column (shown above it when a narrow screen stacks the row; an
    empty cell is left out there)."""
    if not body:
        cls = f"{cls} empty".strip()
    klass = f" class='{cls}'" if cls else ""
    return f"<td data-h='{_e(header)}'{klass}>{body}</td>"


def _table(headers: Sequence[str], rows: Sequence[str], cls: str = "stack") -> str:
    head = "<tr class='head'>" + "".join(f"<th>{_e(h)}</th>" for h in headers) + "</tr>"
    return f"<div class='scroll'><table class='{cls}'>{head}{''.join(rows)}</table></div>"


# --- header and banner ---------------------------------------------------------------------------

def _run_line(template: str, build: dict, inputs: Sequence[InputRow]) -> str:
    over = [r for r in inputs if r.overridden]
    what = f"template <code>{_e(template)}</code>"
    if over:
        items = ", ".join(f"<code>{_e(r.key)} = {_e(r.value)}</code> (template "
                          f"{_e(r.template_value) if r.template_value else 'has none'})" for r in over)
        what += f" <b>with overrides:</b> {items}"
    parts = [what, f"gearcheck {_e(__version__)}"]
    if build.get("chordal_tolerance_mm", "") != "":
        parts.append(f"mesh tolerance {_e(build['chordal_tolerance_mm'])} mm")
    if build.get("triangles", "") != "":
        parts.append(f"{_e(build['triangles'])} triangles in {_e(build.get('parts', ''))} parts")
    if (build.get("cad_cache") or {}).get("reused"):
        made = str(build["cad_cache"].get("made") or "").replace("T", " ").replace("Z", " UTC")
        parts.append(f"solids, meshes and STEP from the CAD cache (made {_e(made)})")
    return "<p class='meta'>" + " · ".join(parts) + "</p>"


def _claim(v: Verdict) -> str:
    word = "FAIL" if v.level == "fail" else "warning"
    why = v.shortfall or v.measured
    return f"<li><b>{word}</b> — {_e(v.label)}: {_e(why)} <a href='#v-{_e(v.name)}'>details</a></li>"


def _banner(result: CheckResult) -> str:
    level = result.level
    warned = [v for v in result.verdicts if v.level == "warn"]
    failed = [v for v in result.verdicts if v.level == "fail"]
    head = f"{level.upper()}: {result.count_text()}"
    items = "".join(_claim(v) for v in [*failed, *warned])
    return f"<div class='banner {level}' id='summary'>{head}{f'<ul>{items}</ul>' if items else ''}</div>"


def _differences_notice(comparisons: Sequence[Comparison]) -> str:
    """The strong differences from the paper, listed with their reason; strong differences between
    the computed columns where the paper prints nothing, counted (they are marked in the table)."""
    major = [c for c in comparisons if compare.worst(c) == "major"]
    paper = [c for c in major if c.paper is not None]
    others = len(major) - len(paper)
    if not major:
        return ""
    without = " without a paper figure" if any(c.paper is not None for c in comparisons) else ""
    more = (f"{'Also ' if paper else ''}{others} row{'s' if others > 1 else ''}{without} where the "
            f"exact model or the geometry differs from the analytical model by more than {compare.MAJOR:.0%}: "
            "marked in the <a href='#comparisons'>table</a>, each with its reason.") if others else ""
    if not paper:
        return f"<div class='notice'>{more}</div>"
    many = len(paper) > 1
    items = "".join(f"<li>{compare.summary_line(c)}</li>" for c in paper)
    return (f"<div class='notice'><b>{len(paper)} figure{'s' if many else ''} differ{'' if many else 's'} from the "
            f"paper by more than {compare.MAJOR:.0%} or miss{'' if many else 'es'} its bound</b> "
            f"(<a href='#comparisons'>table</a>):<ul>{items}</ul>{more}</div>")


# --- sections --------------------------------------------------------------------------------------

def _src(picture: Sequence) -> str:
    """A picture's image source: its PNG inlined (caption, file, bytes: the page stands alone, no
    request beyond itself), else the file beside the page (caption, file)."""
    if len(picture) > 2 and picture[2]:
        return "data:image/png;base64," + base64.b64encode(picture[2]).decode("ascii")
    return _e(quote(picture[1]))


def _geometry(viewer: str, pictures: Sequence[Sequence]) -> str:
    if not viewer and not pictures:
        return ""
    out = ["<h2 id='geometry'>Geometry</h2>"]
    if viewer:
        cls = "viewer screen-only" if pictures else "viewer"
        out.append(f"<div class='{cls}'>{viewer}</div>")
    if pictures:
        figs = "".join(f"<figure><a href='{_e(quote(p[1]))}'><img src='{_src(p)}' alt='{_e(p[0])}'>"
                       f"</a><figcaption>{_e(p[0])}</figcaption></figure>" for p in pictures)
        out.append(f"<div class='pictures'>{figs}</div>")
    elif viewer:
        out.append("<p class='print-only small'>The 3-D view is interactive: open report.html in a browser.</p>")
    return "".join(out)


def _verdicts(result: CheckResult) -> str:
    rows = []
    for v in result.verdicts:
        word = {"pass": "pass", "warn": "warn", "fail": "FAIL"}[v.level]
        cls = {"pass": "ok", "warn": "warned", "fail": "bad"}[v.level]
        measured = _e(v.measured) + (f"<br><b>{_e(v.shortfall)}</b>" if v.shortfall else "")
        rows.append(f"<tr id='v-{_e(v.name)}' class='v-{v.level}'>{_td('claim', _e(v.label))}"
                    f"{_td('result', word, cls)}{_td('measured', measured)}{_td('decided by', _e(v.evidence))}</tr>")
    return "<h2 id='verdicts'>Verdicts</h2>" + _table(["claim", "result", "measured", "decided by"], rows)


def _comparisons_title(comparisons: Sequence[Comparison]) -> str:
    """The table's title: the paper named only when a row stands beside a paper's figure."""
    return "Paper, model, geometry" if any(c.paper is not None for c in comparisons) else "Model, geometry"


def _comparisons(comparisons: Sequence[Comparison]) -> str:
    if not comparisons:
        return ""
    paper = any(c.paper is not None for c in comparisons)  # else no paper column (another design)
    headers = ["figure", "unit", *(["paper"] if paper else []), "analytical model", "exact model",
               "geometry (mesh sweep)", "difference", "why they differ"]
    rows = []
    for c in comparisons:
        flags = {d.column: d.level for d in compare.differences(c)}
        sign = {"min": "≥ ", "max": "≤ ", "value": ""}[c.paper_is] if c.paper is not None else ""
        unit = f" ({c.unit})" if c.unit else ""
        cells = [_td("figure", _e(c.label)), _td("unit", _e(c.unit), "unit")]
        if paper:
            cells.append(_td("paper" + unit, _e(sign + compare.paper_text(c.paper)), "num"))
        for column, header in zip(("model", "exact", "geometry"), headers[-5:-2], strict=True):
            cls = "num" + (f" {flags[column]}" if flags.get(column) else "")
            cells.append(_td(header + unit, compare.value_text(getattr(c, column), c.digits), cls))
        level = compare.worst(c)
        cells.append(_td("difference", compare.difference_cell(c), level))
        cells.append(_td("why they differ", _e(c.note)))
        rows.append(f"<tr>{''.join(cells)}</tr>")
    beyond = (f"beyond that the difference is shown, marked beyond {compare.MINOR:.0%}, and marked strongly beyond "
              f"{compare.MAJOR:.0%}")
    intro = ("<p class='small'>Paper figures as printed (≥/≤: a bound the design must meet). Each computed "
             "column is compared with the paper, or, where it prints none, with the analytical model: within what "
             "the shown figures cannot tell apart (the paper's last printed digit, the column's last shown digit "
             f"and, for the mesh sweep, its error bound) it agrees; {beyond} or on the wrong side of a bound.</p>"
             if paper else
             "<p class='small'>Each computed column is compared with the analytical model (else the exact model): "
             "within what the shown figures cannot tell apart (the column's last shown digit and, for the mesh "
             f"sweep, its error bound) it agrees; {beyond}.</p>")
    return f"<h2 id='comparisons'>{_comparisons_title(comparisons)}</h2>" + intro + _table(headers, rows)


def _reading(k: Confirmation) -> str:
    diff = k.mesh_mm - k.brep_mm
    if k.meshes_overlap:
        return f"meshes overlap ({k.overlap_mm3:.4g} mm³ of the exact solids in common)"
    if abs(diff) < 5e-6:
        return "mesh and B-rep agree"
    word = "overstates" if diff > 0 else "understates"
    within = "within" if abs(diff) <= k.bound_mm else "BEYOND"
    return f"mesh {word} the clearance by {abs(diff):.5f} mm ({within} the bound)"


def _confirmations(confirmations: Sequence[Confirmation]) -> str:
    if not confirmations:
        return ""
    headers = ["pose", "parts", "mesh distance mm", "B-rep distance mm", "mesh − B-rep mm", "mesh-error bound mm",
               "reading"]
    rows = [f"<tr>{_td(headers[0], _e(k.label))}{_td(headers[1], _e(k.parts))}"
            f"{_td(headers[2], f'{k.mesh_mm:.5f}', 'num')}{_td(headers[3], f'{k.brep_mm:.5f}', 'num')}"
            f"{_td(headers[4], f'{k.mesh_mm - k.brep_mm:+.5f}', 'num')}{_td(headers[5], f'{k.bound_mm:.4f}', 'num')}"
            f"{_td(headers[6], _e(_reading(k)))}</tr>" for k in confirmations]
    intro = ("<p>A chordal mesh replaces each curved face by flat triangles whose corners lie on the exact surface, "
             "so a mesh distance can overstate or understate the clearance by up to the pair's mesh-error bound: "
             "chords cut inside a convex face (a tooth flank; the mesh shows more clearance than there is) and stand "
             "outside a concave one (a seat, a groove; the mesh shows less). Each sweep's worst pose is re-measured "
             "between the exact B-rep solids (OCC BRepExtrema); the last column says which way the mesh erred.</p>")
    return "<h2 id='exact'>Worst poses confirmed on the exact B-rep</h2>" + intro + _table(headers, rows)


def plots_html(result: CheckResult) -> list[str]:
    """Each plot of the result as the page shows it (:func:`render` takes them made in advance)."""
    return [plot_html(p) for p in result.plots]


def _plots(result: CheckResult, made: Sequence[str] | None = None) -> str:
    if not result.plots:
        return ""
    made = plots_html(result) if made is None else made
    if len(made) != len(result.plots):
        raise ValueError(f"{len(made)} plots made for the {len(result.plots)} of the result")
    return "<h2 id='plots'>Plots</h2>" + "".join(f"<div class='plot'>{p}</div>" for p in made)


def _notes(notes: Sequence[str]) -> str:
    if not notes:
        return ""
    return "<h2 id='notes'>Notes</h2><ul class='notes'>" + "".join(f"<li>{_e(n)}</li>" for n in notes) + "</ul>"


def _inputs(inputs: Sequence[InputRow], template: str) -> str:
    if not inputs:
        return ""
    headers = ["field", "value", "unit", "what it is", "allowed", "template"]
    rows, section = [], None
    for r in inputs:
        if r.section != section:
            section = r.section
            if section:
                note = f" <span class='vs'>— {_e(r.section_note)}</span>" if r.section_note else ""
                rows.append(f"<tr class='section'><td colspan='6'>[{_e(section)}]{note}</td></tr>")
        what = _e(r.description)
        if r.note and r.note.lower() not in r.description.lower():
            what += f"<br><span class='vs'>template: {_e(r.note)}</span>"
        if r.default:
            template_cell = "default (not in the template)" if r.value != "—" else "not given"
        elif r.overridden:
            template_cell = (f"<b>{_e(r.template_value)}</b> — overridden" if r.template_value
                             else "<b>overridden</b> (not in the template)")
        else:
            template_cell = f"<span class='vs'>{_e(r.template_value)}</span>"
        unit = f" ({r.unit})" if r.unit else ""
        mark = " class='over'" if r.overridden else ""
        rows.append(f"<tr{mark}>{_td('field', f'<code>{_e(r.key)}</code>', 'key')}"
                    f"{_td('value' + unit, _e(r.value), 'val')}{_td('unit', _e(r.unit), 'unit')}"
                    f"{_td('what it is', what)}{_td('allowed' + unit, _e(r.allowed), 'nw')}"
                    f"{_td('template', template_cell)}</tr>")
    over = [r for r in inputs if r.overridden]
    intro = (f"<p class='small'>Every field of <code>{_e(template)}</code> as this run used it"
             + (f"; {len(over)} overridden (highlighted, the template's own value beside it)" if over else
                ", as the template sets it")
             + ". \"allowed\": the range the template model accepts on its own; rules across fields are checked "
               "as well (a value they reject is named with its allowed range).</p>")
    return "<h2 id='inputs'>Inputs</h2>" + intro + _table(headers, rows)


GROUPS = (("CAD", (".step", ".stp")), ("3-D scene", (".glb",)), ("meshes", (".stl",)), ("pictures", (".png",)),
          ("data", (".json", ".csv", ".toml", ".parquet")), ("this report", (".html",)))


def _kind(name: str) -> str:
    base = name.rsplit("/", 1)[-1]
    return NAMED.get(base, KIND.get("." + base.rsplit(".", 1)[-1].lower(), "")) if "." in base else NAMED.get(base, "")


def _link(name: str) -> str:
    kind = NAMED.get(name.rsplit("/", 1)[-1], "")
    title = f" title='{_e(kind)}'" if kind else ""
    return f"<a href='{_e(quote(name))}'{title}>{_e(name)}</a>"


def _files(files: Sequence[str]) -> str:
    shown = [f for f in files if not f.rsplit("/", 1)[-1].startswith(".")]
    if not shown:
        return ("<p class='meta'>Per-pose data: <code>sweep.csv</code>; all figures: <code>summary.json</code>; "
                "parts: <code>manifest.json</code>, STEP and STL beside this file.</p>")
    rows, left = [], list(shown)
    for group, suffixes in (*GROUPS, ("other", ())):
        mine = [f for f in left if not suffixes or f.lower().endswith(suffixes)]
        left = [f for f in left if f not in mine]
        if mine:
            kinds = sorted({KIND.get("." + f.rsplit(".", 1)[-1].lower(), "") for f in mine} - {""})
            what = "" if group in ("data", "this report") else f" <span class='vs'>{_e('; '.join(kinds))}</span>"
            links = ", ".join(_link(f) for f in mine)
            if group == "data":
                links = "; ".join(f"{_link(f)} <span class='vs'>{_e(_kind(f))}</span>" for f in mine)
            rows.append(f"<tr>{_td('kind', _e(group) + what)}{_td('files', links)}</tr>")
    return ("<h2 id='files'>Files of this run</h2><p class='small'>Beside this page in the run's folder.</p>"
            + _table(["kind", "files"], rows))


def _toc(result: CheckResult, geometry: bool, inputs: bool, files: bool) -> str:
    links = [("geometry", "Geometry", geometry), ("verdicts", "Verdicts", True),
             ("comparisons", _comparisons_title(result.comparisons), bool(result.comparisons)),
             ("exact", "Exact B-rep", bool(result.confirmations)), ("plots", "Plots", bool(result.plots)),
             ("notes", "Notes", bool(result.notes)), ("inputs", "Inputs", inputs), ("files", "Files", files)]
    return "<nav class='toc'>" + " ".join(f"<a href='#{i}'>{t}</a>" for i, t, shown in links if shown) + "</nav>"


def render(result: CheckResult, *, title: str, template: str, build: dict, inputs: Sequence[InputRow] = (),
           files: Sequence[str] = (), viewer: str = "", pictures: Sequence[Sequence] = (),
           about: str = "", plots: Sequence[str] | None = None) -> str:
    """The whole page.

    ``build``: manifest figures (chordal_tolerance_mm, triangles, parts); ``inputs``: the inputs
    table (:func:`gearcheck.report.inputs.input_rows`; its overridden rows also head the page);
    ``files``: the run folder's files, relative names, linked; ``viewer``: the interactive 3-D
    view (HTML, self-contained) shown under "Geometry"; ``pictures``: (caption, PNG file name)
    beside the report, shown under it and in print instead of the viewer; ``about``: the
    template's own description (:func:`gearcheck.report.inputs.template_header`); ``plots``: the
    result's plots made in advance (:func:`plots_html`), else made here."""
    parts = ["<!doctype html><html lang='en'><head><meta charset='utf-8'>",
             "<meta name='viewport' content='width=device-width, initial-scale=1'>",
             f"<title>{_e(title)}</title><style>{CSS}{PAGE_CSS}</style></head><body>",
             f"<h1>{_e(title)}</h1>", _run_line(template, build, inputs)]
    if about:
        parts.append(f"<p class='small'>{_e(about)}</p>")
    parts.append(_banner(result))
    parts.append(_differences_notice(result.comparisons))
    geometry = _geometry(viewer, pictures)
    parts.append(_toc(result, bool(geometry), bool(inputs), bool(files)))
    parts += [geometry, _verdicts(result), _comparisons(result.comparisons), _confirmations(result.confirmations),
              _plots(result, plots), _notes(result.notes), _inputs(inputs, template), _files(files), "</body></html>"]
    return "\n".join(p for p in parts if p)
