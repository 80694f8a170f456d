"""report.html of a study: the failure probabilities with their intervals, the distributions, the
probability of failure against each input, the sensitivity ranking, the paper's model against
the exact model, the worst variants with their checks (linked), and the rejected variants."""

from __future__ import annotations

import html
import math
from typing import Any

import numpy as np

from gearcheck import __version__
from gearcheck.report.html import CSS, figure_svg
from gearcheck.studies import stats
from gearcheck.studies.spec import StudySpec

EXTRA_CSS = """
.plot svg { max-width: 100%; height: auto; }
td.p { font-weight: 600; }
"""


def _fmt(x: Any, digits: int = 4) -> str:
    if x is None:
        return "—"
    if isinstance(x, float):
        if not math.isfinite(x):
            return "—"
        return f"{x:.{digits}g}"
    return html.escape(str(x))


def _pct(p: float) -> str:
    return "—" if p is None or not math.isfinite(p) else f"{100 * p:.3g} %"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["svg.hashsalt"] = "gearcheck"
    matplotlib.rcParams["svg.fonttype"] = "none"  # text stays text: searchable
    import matplotlib.pyplot as plt

    return plt


def _column(tab, name: str) -> np.ndarray:
    return np.asarray(tab.column(name).to_numpy(zero_copy_only=False), float)


def _histograms(spec: StudySpec, summary: dict, tab) -> list[str]:
    valid = np.asarray(tab.column("valid").to_numpy(zero_copy_only=False), bool)
    limits: dict[str, list[tuple[str, float]]] = {}
    for name, f in summary["failures"].items():
        limits.setdefault(f["output"], []).append((f"{name} limit", f["limit"]))
    for p in summary.get("paper", []):
        limits.setdefault(p["output"], []).append((f"paper: {p['label']}", p["value"]))
    shown = [k for k in dict.fromkeys([spec.rank_by, *limits]) if k in tab.column_names]
    out = []
    plt = _plt()
    for key in shown:
        v = _column(tab, key)[valid]
        v = v[np.isfinite(v)]
        if v.size == 0 or len(np.unique(v)) <= 2:  # an indicator (0/1): its probability is in the table
            continue
        fig, ax = plt.subplots(figsize=(9.0, 3.4), dpi=100)
        ax.hist(v, bins=min(60, max(10, int(math.sqrt(v.size)))), color="#6b8fc7", edgecolor="white")
        for (label, x), colour in zip(limits.get(key, []), ("#b03030", "#2f7d3a", "#7a5200", "#444"), strict=False):
            ax.axvline(x, color=colour, ls="--", lw=1.4, label=f"{label} ({x:.4g})")
        ax.set_title(f"{key}: {v.size} variants")
        ax.set_xlabel(key)
        ax.set_ylabel("variants")
        ax.grid(True, alpha=0.3)
        if limits.get(key):
            ax.legend(fontsize=8)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out


def _failure_curves(spec: StudySpec, summary: dict, tab) -> list[str]:
    valid = np.asarray(tab.column("valid").to_numpy(zero_copy_only=False), bool)
    out = []
    plt = _plt()
    for name, f in summary["failures"].items():
        if f["failures"] == 0:
            continue
        y = _column(tab, f["output"])
        seen = valid & np.isfinite(y)
        failed = (y < f["limit"]) if f["side"] == "below" else (y > f["limit"])
        inputs = [i.key for i in spec.inputs]
        cols = min(3, len(inputs))
        rows = math.ceil(len(inputs) / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(9.5, 2.4 * rows), dpi=100, squeeze=False)
        for ax, field in zip(axes.flat, inputs, strict=False):
            x = _column(tab, f"in.{field}")[seen]
            c, frac, _counts = stats.failure_curve(x, failed[seen])
            ax.plot(c, frac, "o-", ms=3)
            ax.set_title(field, fontsize=8)
            ax.set_ylim(-0.02, 1.02)
            ax.grid(True, alpha=0.3)
        for ax in list(axes.flat)[len(inputs):]:
            ax.axis("off")
        fig.suptitle(f"P({name}) against each input (equal-count bins)", fontsize=10)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out


def _paper_vs_exact(tab) -> list[str]:
    names = tab.column_names
    pairs = sorted(k[len("analytical."):] for k in names
                   if k.startswith("analytical.") and f"exact.{k[len('analytical.'):]}" in names)
    out = []
    plt = _plt()
    for key in pairs:
        a, e = _column(tab, f"analytical.{key}"), _column(tab, f"exact.{key}")
        both = np.isfinite(a) & np.isfinite(e)
        if both.sum() < 2:
            continue
        fig, ax = plt.subplots(figsize=(5.5, 4.6), dpi=100)
        ax.plot(a[both], e[both], "o", ms=3, alpha=0.7)
        lo, hi = float(min(a[both].min(), e[both].min())), float(max(a[both].max(), e[both].max()))
        ax.plot([lo, hi], [lo, hi], "-", color="0.5", lw=1, label="exact = paper model")
        ax.set_xlabel(f"paper's model: {key}")
        ax.set_ylabel(f"exact model: {key}")
        ax.set_title(f"{key}: {int(both.sum())} variants; mean difference {float(np.mean(e[both] - a[both])):.4g}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out


def render(spec: StudySpec, summary: dict, tab, *, study_file: str) -> str:
    title = f"gearcheck study: {spec.title}"
    parts = ["<!doctype html><html lang='en'><head><meta charset='utf-8'>",
             "<meta name='viewport' content='width=device-width, initial-scale=1'>",
             f"<title>{html.escape(title)}</title><style>{CSS}{EXTRA_CSS}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>",
             f"<p class='meta'>study <code>{html.escape(study_file)}</code> · template "
             f"<code>{html.escape(summary['template'])}</code> · {summary['samples']} variants ({summary['sampler']}, "
             f"seed {summary['seed']}) · {summary['valid']} valid, {summary['rejected']} rejected by validation · "
             f"exact model on {summary['exact_variants']} · gearcheck {__version__}</p>"]
    failing = [f for f in summary["failures"].values() if f["failures"] > 0]
    level = "fail" if failing else "pass"
    parts.append(f"<div class='banner {level}'>{len(failing)} of {len(summary['failures'])} failure modes "
                 f"seen in {summary['valid']} valid variants</div>")
    parts.append("<h2>Probability of each failure</h2><p class='meta'>Over the valid variants (those the "
                 "template accepts: in spec), as the headline counts; beside it, over every variant drawn, the ones "
                 "rejected as out of spec counted as failures of their own kind.</p><table><tr><th>failure</th>"
                 "<th>output</th><th>limit</th><th>failures / valid variants</th><th>probability</th>"
                 "<th>95 % interval (Wilson)</th><th>over all drawn (out of spec = failure)</th></tr>")
    for name, f in summary["failures"].items():
        d = f.get("over_drawn") or {}
        drawn = (f"{d['failures']} / {d['variants']}: {_pct(d['probability'])} ({_pct(d['ci95_low'])} – "
                 f"{_pct(d['ci95_high'])})") if d.get("variants") else "—"
        parts.append(f"<tr><td>{html.escape(f['label'])} (<code>{name}</code>)</td><td><code>{html.escape(f['output'])}"
                     f"</code></td><td>{f['side']} {_fmt(f['limit'])}</td><td class='num'>{f['failures']} / "
                     f"{f['variants']}</td><td class='num p'>{_pct(f['probability'])}</td><td class='num'>"
                     f"{_pct(f['ci95_low'])} – {_pct(f['ci95_high'])}</td><td class='num'>{drawn}</td></tr>")
    parts.append("</table>")

    parts.append("<h2>Inputs</h2><table><tr><th>input</th><th>template field</th><th>distribution</th>"
                 "<th>unit</th><th>sampled mean</th><th>sampled sd</th><th>why this width</th></tr>")
    for key, i in summary["inputs"].items():
        shape = ", ".join(f"{k} {_fmt(i[k])}" for k in ("mean", "sd", "low", "high") if k in i) or ""
        how = "added to" if i["mode"] == "offset" else "sets"
        parts.append(f"<tr><td><code>{html.escape(key)}</code></td><td>{how} "
                     f"<code>{html.escape(i['field'])}</code></td>"
                     f"<td>{i['distribution']} {shape}</td><td>{html.escape(i['unit'])}</td>"
                     f"<td class='num'>{_fmt(i['sampled'].get('mean'))}</td><td class='num'>"
                     f"{_fmt(i['sampled'].get('sd'))}</td><td>{html.escape(i['reason'])}</td></tr>")
    parts.append("</table>")

    parts.append("<h2>Which inputs matter</h2><p>Standardised regression coefficients (SRC) and their rank "
                 "version (SRRC): the change of the output, in its standard deviations, per standard deviation "
                 "of the input. R² says how much of the output's variance the linear (rank) model explains.</p>")
    for target, s in summary["sensitivity"].items():
        k = len(s["ranking"])
        few = (f" — {s['variants']} variants for {k} inputs: indicative only (a stable ranking wants ≥ {10 * k})"
               if s["variants"] < 10 * k else f" — {s['variants']} variants")
        parts.append(f"<h3><code>{html.escape(target)}</code>: R² {_fmt(s['r2'], 3)}, rank R² {_fmt(s['r2_rank'], 3)}"
                     f"<small>{html.escape(few)}</small></h3><table><tr><th>rank</th><th>input</th><th>SRC</th>"
                     "<th>SRRC</th></tr>")
        for r, k in enumerate(s["ranking"], start=1):
            parts.append(f"<tr><td>{r}</td><td><code>{html.escape(k)}</code></td><td class='num'>{_fmt(s['src'][k], 3)}"
                         f"</td><td class='num'>{_fmt(s['srrc'][k], 3)}</td></tr>")
        parts.append("</table>")

    parts.append("<h2>Distributions</h2>")
    parts += _histograms(spec, summary, tab)
    curves = _failure_curves(spec, summary, tab)
    if curves:
        parts.append("<h2>Probability of failure against each input</h2>")
        parts += curves
    comparisons = _paper_vs_exact(tab)
    if comparisons:
        parts.append("<h2>The paper's model against the exact model</h2>")
        parts += comparisons
    if summary["paper"]:
        parts.append("<h2>The paper's measurements beside the distributions</h2><table><tr><th>measured</th>"
                     "<th>output</th><th>paper</th><th>study p05 – p50 – p95</th></tr>")
        for p in summary["paper"]:
            o = summary["outputs"].get(p["output"], {})
            parts.append(f"<tr><td>{html.escape(p['label'])}</td><td><code>{html.escape(p['output'])}</code></td>"
                         f"<td class='num'>{_fmt(p['value'])}</td><td class='num'>{_fmt(o.get('p05'))} – "
                         f"{_fmt(o.get('p50'))} – {_fmt(o.get('p95'))}</td></tr>")
        parts.append("</table>")

    if summary["checks"]:
        parts.append(f"<h2>Worst variants, checked on real geometry</h2><p>The {len(summary['checks'])} valid "
                     f"variants with the lowest <code>{html.escape(spec.rank_by)}</code>, each built, meshed, swept "
                     "and confirmed on the exact B-rep by the full check.</p><table><tr><th>variant</th>"
                     f"<th>{html.escape(spec.rank_by)}</th><th>check</th><th>failing claims</th></tr>")
        key = _column(tab, spec.rank_by) if spec.rank_by in tab.column_names else None
        for c in summary["checks"]:
            link = (f"<a href='{html.escape(c['folder'])}/report.html'>variant {c['variant']}</a>" if c["folder"]
                    else f"variant {c['variant']}")
            value = _fmt(float(key[c["variant"]])) if key is not None else "—"
            parts.append(f"<tr><td>{link}</td><td class='num'>{value}</td><td class='{c['level']}'>"
                         f"{c['level'].upper()}</td><td>{html.escape('; '.join(c['failed'])) or '—'}</td></tr>")
        parts.append("</table>")

    if summary["rejections"]:
        parts.append(f"<h2>Rejected variants ({summary['rejected']})</h2><p>Variants whose parameters validation "
                     "refuses, with the reason (all of them are in results.parquet, column <code>rejection</code>)."
                     "</p><ul class='notes'>")
        for r in summary["rejections"][:30]:
            parts.append(f"<li>variant {r['variant']}: {html.escape(r['reason'])}</li>")
        parts.append("</ul>")
    parts.append("<h2>Files</h2><ul><li><a href='results.parquet'>results.parquet</a>: one row per variant</li>"
                 "<li><a href='summary.json'>summary.json</a></li></ul></body></html>")
    return "\n".join(parts)
