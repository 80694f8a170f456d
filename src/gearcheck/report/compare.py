"""The paper vs model vs geometry table's figures as text, and their differences flagged by size.

A paper's figure is shown as printed (its shortest form: 3.4, not 3.4000); the computed columns at
the comparison's own precision (:attr:`Comparison.digits`). Each computed column is compared with
the paper's figure, or, where the paper prints none, with the analytical model (else the exact
model):

- a paper's *bound* (``paper_is`` "min"/"max") not met is a major difference, with the shortfall;
- a value differs by its size relative to the reference: within what the shown figures cannot
  tell apart (half a unit of the paper's last printed digit, or of the computed column's last
  shown digit; for the mesh sweep plus the comparison's ``tolerance``, its error bound) it agrees;
  beyond that the difference is shown, marked above :data:`MINOR` and marked strongly above
  :data:`MAJOR` (or of the other sign).
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass

from gearcheck.results import Comparison

MINOR = 0.01  # relative difference above which a figure is flagged
MAJOR = 0.10  # relative difference above which it is flagged as a major difference
COLUMNS = (("model", "analytical model"), ("exact", "exact model"), ("geometry", "geometry"))


def paper_text(x: float | None) -> str:
    """A paper's figure as printed: the shortest form that reads back as the same number."""
    if x is None:
        return ""
    if not math.isfinite(x):
        return "n/a"
    text = f"{x:.15g}"
    return text


def value_text(x: float | None, digits: int | None = None) -> str:
    """A computed figure at ``digits`` decimals (default: 4, or 4 significant for very large/small)."""
    if x is None:
        return ""
    if isinstance(x, (bool, int)):
        return str(int(x))
    if not math.isfinite(x):
        return "n/a"
    if digits is not None:
        return f"{x:.{digits}f}"
    if abs(x) >= 1e5 or (x != 0 and abs(x) < 1e-3):
        return f"{x:.4g}"
    return f"{x:.4f}"


def printed_half_unit(x: float) -> float:
    """Half a unit of the last printed digit of a paper's figure (3.4 → 0.05, 110.2 → 0.05, 10 → 0.5)."""
    text = paper_text(x)
    if "e" in text:
        mantissa, exp = text.split("e")
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        return 0.5 * 10.0 ** (int(exp) - decimals)
    decimals = len(text.split(".")[1]) if "." in text else 0
    return 0.5 * 10.0 ** (-decimals)


@dataclass(frozen=True)
class Difference:
    """How far one computed column lies from the row's reference."""

    column: str  # "model" / "exact" / "geometry"
    level: str  # "" (agrees), "minor", "major"
    text: str  # "+28 %", "short of the paper's ≥ 10 by 1.85"
    size: float  # relative size (for ordering; inf for a bound not met)


def reference(c: Comparison) -> tuple[str, float] | None:
    """The row's reference: the paper's figure, else the analytical model's, else the exact model's."""
    for name, value in (("paper", c.paper), ("model", c.model), ("exact", c.exact)):
        if value is not None and math.isfinite(value):
            return name, value
    return None


def differences(c: Comparison) -> list[Difference]:
    """Each computed column's difference from the row's reference (empty where there is none)."""
    ref = reference(c)
    if ref is None or not c.compared:
        return []
    ref_name, ref_value = ref
    out = []
    for column, _ in COLUMNS:
        value = getattr(c, column)
        if column == ref_name or value is None or not math.isfinite(value):
            continue
        out.append(_difference(c, column, value, ref_name, ref_value))
    return out


def _difference(c: Comparison, column: str, value: float, ref_name: str, ref_value: float) -> Difference:
    d = value - ref_value
    unit = f" {c.unit}" if c.unit else ""
    if ref_name == "paper" and c.paper_is in ("min", "max"):
        short = ref_value - value if c.paper_is == "min" else value - ref_value
        if short > 0:
            sign = "≥" if c.paper_is == "min" else "≤"
            word = "short of" if c.paper_is == "min" else "over"
            return Difference(column, "major", f"{value_text(short, c.digits)}{unit} {word} the paper's {sign} "
                              f"{paper_text(ref_value)}", math.inf)
        return Difference(column, "", "meets the paper's bound", 0.0)
    # what the shown figures cannot tell apart: the paper's printed precision, the computed
    # column's shown precision (and, for the mesh sweep, its error bound)
    allowance = max(printed_half_unit(ref_value) if ref_name == "paper" else 0.0,
                    0.5 * 10.0 ** -c.digits if c.digits is not None else 0.0)
    if column == "geometry":
        allowance += c.tolerance
    if abs(d) <= allowance + 1e-12 * max(1.0, abs(ref_value)):
        return Difference(column, "", "agrees", 0.0)
    rel = abs(d) / abs(ref_value) if ref_value != 0 else math.inf
    flipped = value * ref_value < 0
    level = "major" if (rel > MAJOR or flipped) else ("minor" if rel > MINOR else "")
    if math.isfinite(rel) and not flipped:
        pct = 100 * rel
        text = (f"{'+' if d > 0 else '−'}{pct:.0f}\u00a0%" if pct >= 10 else f"{'+' if d > 0 else '−'}{pct:.1f}\u00a0%"
                if pct >= 0.1 else f"{'+' if d > 0 else '−'}{value_text(abs(d), c.digits)}{unit}")
    else:
        text = f"{'+' if d > 0 else '−'}{value_text(abs(d), c.digits)}{unit}" + (" (other sign)" if flipped else "")
    return Difference(column, level, text, rel)


def worst(c: Comparison) -> str:
    """The row's flag: "major", "minor" or ""."""
    levels = {d.level for d in differences(c)}
    return "major" if "major" in levels else ("minor" if "minor" in levels else "")


def reference_name(c: Comparison) -> str:
    ref = reference(c)
    if ref is None:
        return ""
    return {"paper": "the paper", "model": "the analytical model", "exact": "the exact model"}[ref[0]]


def _grouped(diffs: list[Difference]) -> list[str]:
    """Flagged differences in words, columns with the same text together ("exact model and
    geometry +28 %")."""
    names = dict(COLUMNS)
    texts: dict[str, list[str]] = {}
    for d in diffs:
        texts.setdefault(d.text, []).append(names[d.column])
    return [f"{' and '.join(cols)} {text}" for text, cols in texts.items()]


def difference_cell(c: Comparison) -> str:
    """The table's "difference" cell: each column's difference beyond the reference's precision
    (grouped), against which reference; "agree" when all are within it."""
    diffs = differences(c)
    if not diffs:
        return ""
    beyond = [d for d in diffs if d.text not in ("agrees", "meets the paper's bound")]
    if not beyond:
        return "meet the paper's bound" if any(d.text.startswith("meets") for d in diffs) else "agree"
    ref = reference(c)
    bound = c.paper_is != "value" and ref is not None and ref[0] == "paper"
    tail = "" if bound else f" <span class='vs'>vs {reference_name(c)}</span>"
    return html.escape("; ".join(_grouped(beyond))) + tail


def summary_line(c: Comparison) -> str:
    """One line for the report's list of major differences (HTML)."""
    names = dict(COLUMNS)
    shown = []
    for column, _ in COLUMNS:
        value = getattr(c, column)
        if value is not None and math.isfinite(value):
            shown.append(f"{names[column]} {value_text(value, c.digits)}")
    ref = reference(c)
    if ref is not None and ref[0] == "paper":
        sign = {"min": "≥ ", "max": "≤ ", "value": ""}[c.paper_is]
        shown.append(f"paper {sign}{paper_text(ref[1])}")
    unit = f" {html.escape(c.unit)}" if c.unit else ""
    flagged = "; ".join(_grouped([d for d in differences(c) if d.level == "major"]))
    against = "" if c.paper_is != "value" and ref is not None and ref[0] == "paper" else f" vs {reference_name(c)}"
    why = f" — <i>{html.escape(c.note)}</i>" if c.note else ""
    return (f"<b>{html.escape(c.label)}</b>: {html.escape(', '.join(shown))}{unit} "
            f"(<b>{html.escape(flagged)}</b>{against}){why}")
