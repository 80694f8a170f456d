"""The report's plots: one :class:`~gearcheck.results.Plot` as inline SVG (matplotlib, Agg) that
scales to the page's width, with its key (series, reference lines, numbered events) in HTML under
it, readable at any width and never over the data.

- Text stays text (``svg.fonttype = "none"``): a reader can search and copy it.
- Lines are drawn above point series, and point series are hollow rings (then crosses, squares,
  ...): a mesh curve that coincides with a model's points shows through them, and two point
  series at the same places both stay visible.
- Event markers (vertical lines) get numbered tags above the axes, spread apart so that events a
  fraction of a degree apart stay readable, each tag joined to its line by a leader; the key
  names each number with its value and unit.
"""

from __future__ import annotations

import html
import io
import math
import re
import textwrap
from typing import Any

from gearcheck.report.child import ChildOwner
from gearcheck.results import FieldMap, Plot

# Series colours (matplotlib's tab10, in order) and reference-line colours.
COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf"]
HLINE_COLOURS = ["#b03030", "#7a3db8", "#2f7d32", "#b8860b", "#1f5f8b"]
# Point series, in turn: (matplotlib marker, size, hollow, the key's symbol).
POINT_STYLES = [("o", 5.5, True, "○"), ("x", 4.5, False, "×"), ("s", 4.0, True, "□"), ("+", 6.0, False, "+"),
                ("D", 3.8, True, "◇"), ("^", 4.5, True, "△")]
# A point series of many points gets smaller markers (every point is drawn).
DENSE_POINTS = (120, 260)
TITLE_CHARS = 78  # titles wrap at this many characters (the figure's width at its title size)
LABEL_CHARS = 34  # a y-axis label wraps at this many characters (the axes' height)
# Least spacing of neighbouring event tags, as a fraction of the axes' width.
TAG_SPACING = 0.035
TAG_Y = 1.035  # tags sit just above the axes (axes fraction)
FIGSIZE = (6.8, 3.6)  # inches; the SVG scales to the page, the fonts with it
RC: dict[str, Any] = {"svg.hashsalt": "gearcheck", "svg.fonttype": "none", "font.size": 10.0, "axes.titlesize": 11.5,
      "axes.labelsize": 10.5, "xtick.labelsize": 9.5, "ytick.labelsize": 9.5}
_UNITS = {"deg": "°", "arcmin": "′"}


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def axis_unit(label: str) -> str:
    """The unit in an axis label's last parentheses: "pinion angle (deg)" → "°", "distance (mm)" → "mm"."""
    found = re.findall(r"\(([^()]*)\)\s*$", label)
    unit = found[-1].strip() if found else ""
    return _UNITS.get(unit, unit)


def with_unit(x: float, unit: str) -> str:
    """A figure with its unit, as in the key: 75.33°, 0.75 mm, 4.2′."""
    text = f"{x:.4g}".replace("-", "−")
    if not unit:
        return text
    return f"{text}{unit}" if unit in ("°", "′", "%") else f"{text} {unit}"


_STATES_VALUE = re.compile(r"[=≈≥≤]\s*[−-]?\d|\d+\.\d+|\d\s*(?:°|mm|′|%|K\b)")


def states_value(label: str) -> bool:
    """Whether a label already states its value ("one cycle β = 14.694°", "paper 110.20"), so the
    key does not repeat it ("S1 engages (model)" does not)."""
    return _STATES_VALUE.search(label) is not None


def _finite_markers(plot: Plot) -> list[tuple[str, float]]:
    """Markers with a value (a figure that does not apply is None), by position."""
    return sorted(((label, x) for label, x in plot.markers if x is not None and math.isfinite(x)), key=lambda m: m[1])


def _hlines(plot: Plot) -> list[tuple[str, float]]:
    return [(label, y) for label, y in plot.hlines if y is not None and math.isfinite(y)]


def spread(targets: list[float], gap: float, lo: float = 0.0, hi: float = 1.0) -> list[float]:
    """Positions for tags wanted at the sorted ``targets``: each cluster of tags closer than
    ``gap`` is spread evenly around its targets' mean, in order, kept within [lo, hi]."""
    clusters: list[list[float]] = []  # each: [start, count, sum of targets]
    for t in targets:
        clusters.append([t, 1, t])
        while len(clusters) > 1:
            a, b = clusters[-2], clusters[-1]
            if a[0] + a[1] * gap <= b[0] + 1e-12:
                break
            count, total = a[1] + b[1], a[2] + b[2]
            clusters[-2:] = [[total / count - (count - 1) * gap / 2, count, total]]
    out: list[float] = []
    for start, count, _ in clusters:
        out.extend(start + k * gap for k in range(int(count)))
    if out:  # keep inside [lo, hi], shifting the tags at the ends inwards and pushing their neighbours
        for i in range(len(out)):
            out[i] = max(out[i], lo + i * gap)
        for i in range(len(out) - 1, -1, -1):
            out[i] = min(out[i], hi - (len(out) - 1 - i) * gap)
    return out


def _draw_series(ax, plot: Plot) -> list[tuple[str, str]]:
    """Draw the series (lines above points) and return the key's entries (swatch HTML, label)."""
    key = []
    n_points = n_lines = 0
    for i, s in enumerate(plot.series):
        colour = COLOURS[i % len(COLOURS)]
        label = html.escape(s.label)
        if s.style == "points":
            marker, size, hollow, symbol = POINT_STYLES[n_points % len(POINT_STYLES)]
            n_points += 1
            size *= 1.0 if len(s.x) <= DENSE_POINTS[0] else (0.75 if len(s.x) <= DENSE_POINTS[1] else 0.6)
            ax.plot(s.x, s.y, ls="none", marker=marker, ms=size, mew=1.0, color=colour,
                    mfc="none" if hollow else colour, zorder=2, alpha=0.9)
            key.append((f"<span class='sw pt' style='color:{colour}'>{symbol}</span>", label))
        else:
            # each further line a little thinner: a line drawn over an earlier one that coincides with
            # it (a mirrored swing, a mesh curve on its model) leaves the earlier one showing at its edges
            ax.plot(s.x, s.y, "-", lw=max(1.0, 2.2 - 0.3 * n_lines), color=colour, zorder=3)
            n_lines += 1
            key.append((f"<span class='sw ln' style='border-color:{colour}'></span>", label))
    return key


def _draw_field(fig, ax, field: FieldMap) -> None:
    """The map under the series: cells coloured by value (darkest at 0, blank beyond ``vmax``),
    rasterised inside the SVG (a fine grid as vector cells would weigh megabytes), with a colour
    bar; x and y to one scale."""
    import numpy as np

    values = np.asarray(field.values, float)
    shown = np.ma.masked_where(~np.isfinite(values) | (values > field.vmax), values)
    mesh = ax.pcolormesh(np.asarray(field.x, float), np.asarray(field.y, float), shown, cmap="YlOrRd_r",
                         vmin=0.0, vmax=field.vmax * 1.25, shading="gouraud", rasterized=True, zorder=0)
    bar = fig.colorbar(mesh, ax=ax, shrink=0.85, pad=0.02)
    bar.set_label(field.label)
    bar.ax.set_ylim(0.0, field.vmax)
    ax.set_aspect("equal", adjustable="datalim")


def _draw_hlines(ax, plot: Plot, yunit: str) -> list[tuple[str, str]]:
    key = []
    for i, (label, y) in enumerate(_hlines(plot)):
        colour = HLINE_COLOURS[i % len(HLINE_COLOURS)]
        ax.axhline(y, ls=":", lw=1.4, color=colour, zorder=1)
        shown = label if states_value(label) else f"{label}: {with_unit(y, yunit)}"  # the value once
        key.append((f"<span class='sw hl' style='border-color:{colour}'></span>", html.escape(shown)))
    return key


def _draw_markers(ax, plot: Plot) -> None:
    """Dashed vertical lines at the events, numbered tags above the axes joined to them by leaders."""
    markers = _finite_markers(plot)
    if not markers:
        return
    for _, x in markers:  # the lines first: the x range takes them in
        ax.axvline(x, ls="--", lw=0.9, color="0.35", zorder=1)
    x0, x1 = ax.get_xlim()
    ax.set_xlim(x0, x1)  # fixed before placing tags in axes fractions
    span = (x1 - x0) or 1.0
    wanted = [(x - x0) / span for _, x in markers]
    placed = spread(wanted, TAG_SPACING, 0.01, 0.99)
    for number, (fx, tx) in enumerate(zip(wanted, placed, strict=True), start=1):
        ax.annotate(str(number), xy=(fx, 1.0), xycoords="axes fraction", xytext=(tx, TAG_Y),
                    textcoords="axes fraction", fontsize=8, ha="center", va="bottom", color="0.1",
                    annotation_clip=False,
                    bbox={"boxstyle": "round,pad=0.18", "fc": "white", "ec": "0.45", "lw": 0.6},
                    arrowprops={"arrowstyle": "-", "lw": 0.6, "color": "0.45", "shrinkA": 0, "shrinkB": 0})


def marker_key(plot: Plot) -> str:
    """The numbered events' names under the plot, each with its value and unit (HTML)."""
    markers = _finite_markers(plot)
    if not markers:
        return ""
    unit = axis_unit(plot.xlabel)
    items = []
    for n, (label, x) in enumerate(markers, start=1):
        value = "" if states_value(label) else f" ({with_unit(x, unit)})"
        items.append(f"<span class='ev'><b>{n}</b> {html.escape(label)}{html.escape(value)}</span>")
    return f"<p class='key events'>{' '.join(items)}</p>"


def series_key(entries: list[tuple[str, str]]) -> str:
    if not entries:
        return ""
    items = " ".join(f"<span class='it'>{sw} {label}</span>" for sw, label in entries)
    return f"<p class='key series'>{items}</p>"


def scalable(svg: str) -> str:
    """An SVG that scales to its container's width: the root's fixed width/height go, the viewBox
    stays (its aspect ratio sets the height)."""
    head_end = svg.index(">")
    head = re.sub(r'\s(width|height)="[^"]*"', "", svg[:head_end])
    return head + ' width="100%" preserveAspectRatio="xMidYMid meet"' + svg[head_end:]


def figure_svg(fig, *, fit_width: bool = False) -> str:
    """A matplotlib figure as inline SVG text (closes the figure; no timestamp metadata); with
    ``fit_width`` it scales to the page's width (:func:`scalable`)."""
    plt = _plt()
    fig.tight_layout()
    buf = io.StringIO()
    fig.savefig(buf, format="svg", metadata={"Date": None})
    plt.close(fig)
    text = buf.getvalue()
    text = text[text.index("<svg"):]
    return scalable(text) if fit_width else text


def plot_svg(plot: Plot) -> str:
    """One plot as inline SVG that scales to the page (text as <text>, no fixed pixel size)."""
    return plot_html(plot, key=False)


def plot_html(plot: Plot, *, key: bool = True) -> str:
    """One plot: the SVG, then (``key``) its key in HTML: series, reference lines, events, caption."""
    plt = _plt()
    with plt.rc_context(RC):
        fig, ax = plt.subplots(figsize=FIGSIZE, dpi=100)
        if plot.field is not None:
            _draw_field(fig, ax, plot.field)
        entries = _draw_series(ax, plot)
        entries += _draw_hlines(ax, plot, axis_unit(plot.ylabel))
        if plot.ylim is not None:
            ax.set_ylim(*plot.ylim)
        ax.set_xlabel(textwrap.fill(plot.xlabel, 2 * LABEL_CHARS))
        ax.set_ylabel(textwrap.fill(plot.ylabel, LABEL_CHARS))
        ax.grid(True, alpha=0.3)
        _draw_markers(ax, plot)
        ax.set_title(textwrap.fill(plot.title, TITLE_CHARS), pad=22 if _finite_markers(plot) else 6)
        svg = figure_svg(fig, fit_width=True)
    if not key:
        return svg
    caption = f"<p class='caption'>{html.escape(plot.caption)}</p>" if plot.caption else ""
    return svg + series_key(entries) + marker_key(plot) + caption


class PlotsUnavailable(RuntimeError):
    """The plot process gave no plots (it died, hung, or gave something else); the caller draws
    them itself."""


class Plotting(ChildOwner):
    """The report's plots drawn by a process of their own (``python -m gearcheck.report.plots``,
    the plots pickled on its stdin, their HTML on its stdout), started with the run so that
    matplotlib loads while the CAD is built and the plots are drawn while the worst poses are
    confirmed and pictured. The same :func:`plot_html` draws them there as here, with the same
    settings (:data:`RC`: a fixed SVG hash salt, no date), so the HTML is the same text. Use it
    in a ``with`` block: leaving it ends the process if its plots were not collected."""

    def __init__(self, timeout_s: float = 300.0):
        from gearcheck.report.child import ChildProcess

        self.timeout_s = timeout_s
        self._child = ChildProcess("gearcheck.report.plots")
        self._count: int | None = None

    def draw(self, plots: list[Plot]) -> None:
        """Give the process the plots to draw (once)."""
        import pickle

        if self._count is not None:
            raise RuntimeError("the plots were given already")
        self._count = len(plots)
        self._child.send(pickle.dumps(list(plots)))
        self._child.finish()

    def result(self) -> list[str]:
        """Each plot's HTML (:func:`plot_html`), in order; :class:`PlotsUnavailable` otherwise."""
        import pickle

        if self._count is None:
            raise RuntimeError("give the plots first")
        done = self._child.wait(self.timeout_s)
        if done is None:
            raise PlotsUnavailable(f"the plot process did not finish in {self.timeout_s:.0f} s")
        returncode, stdout, stderr = done
        if returncode != 0:
            last = stderr.decode("utf-8", "replace").strip().splitlines()[-1:] or ["no message"]
            raise PlotsUnavailable(f"the plot process ended with status {returncode}: {last[0]}")
        try:
            out = pickle.loads(stdout)
        except (pickle.UnpicklingError, EOFError, ValueError) as exc:
            raise PlotsUnavailable("the plot process gave no plots") from exc
        if not isinstance(out, list) or len(out) != self._count or not all(isinstance(p, str) for p in out):
            raise PlotsUnavailable("the plot process gave something other than the plots asked for")
        return out


def _child() -> int:
    """The plot process: matplotlib loaded while it waits; the plots on stdin, their HTML out."""
    import os
    import pickle
    import sys

    _plt()
    out = os.fdopen(os.dup(1), "wb")  # the HTML goes to the real stdout; prints go to stderr
    sys.stdout.flush()
    os.dup2(2, 1)
    plots = pickle.load(sys.stdin.buffer)
    out.write(pickle.dumps([plot_html(p) for p in plots]))
    out.close()
    return 0


if __name__ == "__main__":
    import sys

    sys.exit(_child())
