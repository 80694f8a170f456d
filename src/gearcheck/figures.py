"""A computed figure beside the paper's own number, and how figures are shown.

Analytical models return lists of :class:`Figure`; the CLI prints them as a table or as one JSON
object nested by section (plain numeric leaves; the paper's values under ``section.paper``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Figure:
    key: str  # JSON key, with unit suffix: "cold_drop_per_side_arcmin"
    label: str  # what it is, for the table
    value: float
    unit: str
    paper: float | None = None  # the paper's printed value, if it has one
    note: str = ""  # why the tool differs from the paper (or what the figure is)
    digits: int = 3

    @property
    def difference(self) -> float | None:
        return None if self.paper is None else self.value - self.paper


def figures_to_json(section: str, figures: list[Figure]) -> dict:
    """``{section: {key: value, ..., "paper": {key: paper_value}}}``; keys are unique.

    A figure the model cannot give (NaN, e.g. a target angle out of reach) becomes ``null``, so
    the output stays strict JSON."""
    body: dict = {}
    paper: dict = {}
    for f in figures:
        if f.key in body:
            raise ValueError(f"duplicate figure key {section}.{f.key}")
        body[f.key] = float(f.value) if math.isfinite(f.value) else None
        if f.paper is not None:
            paper[f.key] = float(f.paper)
    if paper:
        body["paper"] = paper
    return {section: body}


def _fmt(x: float | None, digits: int) -> str:
    if x is None:
        return ""
    if isinstance(x, float) and not math.isfinite(x):
        return str(x)
    return f"{x:.{digits}f}"


def any_paper(figures: list[Figure]) -> bool:
    """Whether any figure stands beside a paper's value (else the tables show no paper columns)."""
    return any(f.paper is not None for f in figures)


def render_table(title: str, figures: list[Figure]) -> str:
    """A plain-text table: quantity, value, unit, paper, difference, note (no paper and
    difference columns when no figure has a paper value)."""
    rows = [("quantity", "value", "unit", "paper", "diff", "note")]
    for f in figures:
        diff = f.difference
        rows.append(
            (
                f.label,
                _fmt(f.value, f.digits),
                f.unit,
                _fmt(f.paper, f.digits),
                "" if diff is None else f"{diff:+.{f.digits}f}",
                f.note,
            )
        )
    shown = range(5) if any_paper(figures) else range(3)
    widths = [max(len(r[i]) for r in rows) for i in range(5)]
    lines = [title, "=" * len(title)]
    for i, r in enumerate(rows):
        cells = [r[0].ljust(widths[0])] + [r[k].rjust(widths[k]) if k != 2 else r[k].ljust(widths[k])
                                           for k in shown if k > 0]
        lines.append("  ".join(cells) + ("  " + r[5] if r[5] else ""))
        if i == 0:
            lines.append("  ".join("-" * widths[k] for k in shown) + "  ----")
    return "\n".join(lines)
