"""summary.json and sweep.csv: deterministic (same inputs → byte-identical files)."""

from __future__ import annotations

import csv
import io
import json
import math

from gearcheck.results import CheckResult


def _plain(value):
    """JSON-safe plain value: bools as 1/0, non-finite floats as null, numpy scalars as floats."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, bool):
        return int(value)
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def summary_json(result: CheckResult) -> str:
    """``{section: {...summary..., "verdicts": {name: 1/0}, "verdict_levels": {name: "pass" |
    "warn" | "fail"}, "verdict_evidence": {name: text}, "verdict_measured": {name: text}, "verdict_pass": 1/0,
    "verdict_warnings": n,
    "verdict_counts": {"design" | "self_checks": {level: n}},
    "exact_confirmation": {key: {mesh_mm, brep_mm, bound_mm}}}}`` with sorted keys."""
    body = dict(result.summary)
    body["verdicts"] = {v.name: int(v.passed) for v in result.verdicts}
    body["verdict_levels"] = {v.name: v.level for v in result.verdicts}
    body["verdict_evidence"] = {v.name: v.evidence for v in result.verdicts}
    # the whole sentence of each verdict (the terminal shows its key figure only)
    body["verdict_measured"] = {v.name: v.measured for v in result.verdicts}
    body["verdict_pass"] = int(result.passed)
    body["verdict_warnings"] = sum(v.level == "warn" for v in result.verdicts)
    body["verdict_counts"] = result.counts()
    if result.confirmations:
        body["exact_confirmation"] = {c.key: c.figures() for c in result.confirmations}
    return json.dumps({result.section: _plain(body)}, indent=2, sort_keys=True, allow_nan=False) + "\n"


def _cell(value) -> str:
    if isinstance(value, bool):
        return str(int(value))
    if isinstance(value, float):
        return "" if not math.isfinite(value) else f"{value:.9g}"
    if hasattr(value, "item"):
        return _cell(value.item())
    return str(value)


def sweep_csv(result: CheckResult) -> str:
    """One row per pose; columns in order of first appearance across rows."""
    columns: list[str] = []
    for row in result.rows:
        for key in row:
            if key not in columns:
                columns.append(key)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(columns)
    for row in result.rows:
        writer.writerow([_cell(row.get(c, "")) for c in columns])
    return out.getvalue()
