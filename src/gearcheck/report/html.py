"""report.html: verdict first, then paper vs model vs geometry, exact confirmations, plots, notes.

One self-contained file (inline SVG plots drawn with matplotlib's Agg backend, inline CSS), so
it can be mailed or archived with the STEP/STL files it describes.
"""

from __future__ import annotations

import html
import io
import math

from gearcheck import __version__
from gearcheck.results import CheckResult, Plot

CSS = """
body { font-family: -apple-system, 'Segoe UI', Helvetica, Arial, sans-serif; margin: 2em auto;
       max-width: 1100px; color: #1d2330; line-height: 1.45; padding: 0 1em; }
h1 { margin-bottom: 0.2em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #dde; }
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


def _fmt(x, digits: int = 4) -> str:
    if x is None:
        return ""
    if isinstance(x, (bool, int)):
        return str(int(x))
    if isinstance(x, float):
        if not math.isfinite(x):
            return "n/a"
        if abs(x) >= 1e5 or (x != 0 and abs(x) < 1e-3):
            return f"{x:.{digits}g}"
        return f"{x:.{digits}f}"
    return html.escape(str(x))


# Neighbouring marker tags closer than this fraction of the x range go on the next row.
MARKER_TAG_SPACING = 0.03
HLINE_COLOURS = ["#b03030", "#7a3db8", "#2f7d32", "#b8860b"]


def _sorted_markers(plot: Plot) -> list[tuple[str, float]]:
    """Markers with a value (a figure that does not apply is None), by position."""
    return sorted(((label, x) for label, x in plot.markers if x is not None and math.isfinite(x)), key=lambda m: m[1])


def marker_key(plot: Plot) -> str:
    """The numbered markers' names under the plot (HTML)."""
    if not _sorted_markers(plot):
        return ""
    items = " · ".join(f"<b>{n}</b> {html.escape(label)} ({x:.4g})"
                       for n, (label, x) in enumerate(_sorted_markers(plot), start=1))
    return f"<p class='key'>{items}</p>"


def plot_svg(plot: Plot) -> str:
    """One plot as inline SVG (matplotlib, Agg backend, no timestamp metadata)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    matplotlib.rcParams["svg.hashsalt"] = "gearcheck"  # stable element ids
    fig, ax = plt.subplots(figsize=(9.5, 4.2), dpi=100)
    for s in plot.series:
        if s.style == "points":
            ax.plot(s.x, s.y, "o", ms=3.5, label=s.label)
        else:
            ax.plot(s.x, s.y, "-", lw=1.6, label=s.label)
    # Event markers: numbered tags on the lines (the key under the plot names them), tags of
    # neighbouring events (a fraction of a degree apart) stepped down so none overlap.
    span = max((max(s.x) - min(s.x) for s in plot.series if s.x), default=1.0) or 1.0
    last_x: list[float] = []  # per tag row, the x of its last tag
    for number, (_label, x) in enumerate(_sorted_markers(plot), start=1):
        ax.axvline(x, ls="--", lw=1.0, color="0.35")
        row = next((r for r, lx in enumerate(last_x) if x - lx >= MARKER_TAG_SPACING * span), len(last_x))
        last_x[row:row + 1] = [x]
        ax.annotate(str(number), (x, 0.97 - 0.08 * row), xycoords=("data", "axes fraction"), fontsize=7,
                    ha="center", va="top", color="0.15",
                    bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "0.45", "lw": 0.6})
    # Horizontal reference lines go into the legend (labels at the axis edge collide).
    hlines = [(label, y) for label, y in plot.hlines if y is not None and math.isfinite(y)]
    for (label, y), colour in zip(hlines, HLINE_COLOURS * (1 + len(hlines) // len(HLINE_COLOURS)), strict=False):
        shown = label if any(c.isdigit() for c in label) else f"{label} ({y:.4g})"  # the value once
        ax.axhline(y, ls=":", lw=1.3, color=colour, label=shown)
    ax.set_title(plot.title, fontsize=11)
    ax.set_xlabel(plot.xlabel)
    ax.set_ylabel(plot.ylabel)
    ax.grid(True, alpha=0.3)
    if plot.series or hlines:
        ax.legend(fontsize=8, loc="best")
    return figure_svg(fig)


def figure_svg(fig) -> str:
    """A matplotlib figure as inline SVG text (closes the figure; no timestamp metadata)."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    buf = io.StringIO()
    fig.savefig(buf, format="svg", metadata={"Date": None})
    plt.close(fig)
    text = buf.getvalue()
    return text[text.index("<svg"):]


def render(result: CheckResult, *, title: str, template: str, build: dict) -> str:
    """The whole page. ``build``: manifest figures (tolerance, triangles, version)."""
    parts = [f"<!doctype html><html lang='en'><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
             f"<style>{CSS}</style></head><body>"]
    parts.append(f"<h1>{html.escape(title)}</h1>")
    parts.append(f"<p class='meta'>template <code>{html.escape(template)}</code> · gearcheck {__version__} · "
                 f"mesh tolerance {build.get('chordal_tolerance_mm', '')} mm · "
                 f"{build.get('triangles', '')} triangles in {build.get('parts', '')} parts</p>")
    level = result.level
    warned = sum(v.level == "warn" for v in result.verdicts)
    parts.append(f"<div class='banner {level}'>{level.upper()}: "
                 f"{sum(v.passed for v in result.verdicts)} of {len(result.verdicts)} verdicts pass"
                 f"{f' ({warned} with a warning)' if warned else ''}</div>")

    parts.append("<h2>Verdicts</h2><table><tr><th>claim</th><th>result</th><th>measured</th>"
                 "<th>decided by</th></tr>")
    for v in result.verdicts:
        word = {"pass": "pass", "warn": "warn", "fail": "FAIL"}[v.level]
        cls = {"pass": "ok", "warn": "warned", "fail": "bad"}[v.level]
        parts.append(f"<tr><td>{html.escape(v.label)}</td><td class='{cls}'>"
                     f"{word}</td><td>{html.escape(v.measured)}</td><td>{html.escape(v.evidence)}</td></tr>")
    parts.append("</table>")

    if result.comparisons:
        parts.append("<h2>Paper, model, geometry</h2><table><tr><th>figure</th><th>unit</th><th>paper</th>"
                     "<th>analytical model</th><th>exact model</th><th>geometry (mesh sweep)</th>"
                     "<th>why they differ</th></tr>")
        for c in result.comparisons:
            parts.append(f"<tr><td>{html.escape(c.label)}</td><td>{html.escape(c.unit)}</td>"
                         f"<td class='num'>{_fmt(c.paper)}</td><td class='num'>{_fmt(c.model)}</td>"
                         f"<td class='num'>{_fmt(c.exact)}</td><td class='num'>{_fmt(c.geometry)}</td>"
                         f"<td>{html.escape(c.note)}</td></tr>")
        parts.append("</table>")

    if result.confirmations:
        parts.append("<h2>Worst poses confirmed on the exact B-rep</h2><p>Mesh distances overstate "
                     "clearance by up to the mesh-error bound (chords lie inside convex flanks); each "
                     "sweep's worst pose is re-measured on the B-rep solids (OCC BRepExtrema).</p>"
                     "<table><tr><th>pose</th><th>parts</th><th>mesh distance mm</th><th>B-rep distance mm</th>"
                     "<th>difference mm</th><th>mesh-error bound mm</th></tr>")
        for k in result.confirmations:
            diff = k.mesh_mm - k.brep_mm
            parts.append(f"<tr><td>{html.escape(k.label)}</td><td>{html.escape(k.parts)}</td>"
                         f"<td class='num'>{k.mesh_mm:.5f}</td><td class='num'>{k.brep_mm:.5f}</td>"
                         f"<td class='num'>{diff:+.5f}</td><td class='num'>{k.bound_mm:.4f}</td></tr>")
        parts.append("</table>")

    if result.plots:
        parts.append("<h2>Plots</h2>")
        for plot in result.plots:
            parts.append(f"<div class='plot'>{plot_svg(plot)}{marker_key(plot)}</div>")

    if result.notes:
        parts.append("<h2>Findings</h2><ul class='notes'>")
        parts.extend(f"<li>{html.escape(n)}</li>" for n in result.notes)
        parts.append("</ul>")
    parts.append("<p class='meta'>Per-pose data: <code>sweep.csv</code>; all figures: <code>summary.json</code>; "
                 "parts: <code>manifest.json</code>, STEP and STL beside this file.</p></body></html>")
    return "\n".join(parts)
