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
from gearcheck.report.plots import RC
from gearcheck.studies import stats
from gearcheck.studies.spec import StudySpec

EXTRA_CSS = """
.plot svg { max-width: 100%; height: auto; }
.info { background: #eef3fb; color: #1d3a66; border: 1px solid #b7c9e6; }
.banner.info ul { font-size: 0.72em; }
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
    import matplotlib.pyplot as plt

    # the check report's plot settings (same fonts, text stays text, a fixed hash salt), and 1.656 on
    # an axis, never "+1.656" and an offset
    settings: dict[Any, Any] = {**RC, "axes.formatter.useoffset": False}
    plt.rcParams.update(settings)
    return plt


_UNIT_SUFFIX = {"_pct": "%", "_mm": "mm", "_deg": "°", "_arcmin": "′", "_um": "µm", "_C": "°C", "_K": "K",
                "_mm3": "mm³"}
_LEVEL_WORD = {"analytical": "paper's model", "exact": "exact model", "contact": "tooth contact analysis",
               "check": "check", "in": "input"}


def label_of(key: str, labels: dict[str, str] | None = None) -> str:
    """A column key as an axis label: the figure's own label where the template's calc has it, else
    its words, with the unit from the key's suffix and the level in words:
    "exact.wear_margin_pct" → "wear margin (%), exact model"."""
    level, _, name = key.partition(".") if "." in key else ("", "", key)
    unit = next((u for suffix, u in _UNIT_SUFFIX.items() if name.endswith(suffix)), "")
    bare = name[: -len(next(sfx for sfx, u in _UNIT_SUFFIX.items() if u == unit and name.endswith(sfx)))] \
        if unit else name
    words = (labels or {}).get(name) or bare.replace("_", " ")
    text = f"{words} ({unit})" if unit and f"({unit})" not in words else words
    return f"{text}, {_LEVEL_WORD.get(level, level)}" if level else text


def _legend_below(ax) -> None:
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.28), ncol=2, frameon=False, fontsize=8.5)


def _column(tab, name: str) -> np.ndarray:
    return np.asarray(tab.column(name).to_numpy(zero_copy_only=False), float)


def _histograms(spec: StudySpec, summary: dict, tab, labels: dict[str, str]) -> list[str]:
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
        ax.set_title(f"{label_of(key, labels)}: {v.size} valid variants")
        ax.set_xlabel(label_of(key, labels))
        ax.set_ylabel("variants")
        ax.grid(True, alpha=0.3)
        if limits.get(key):
            _legend_below(ax)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out


# A P(fail)-against-input curve is drawn only from this many variants with an output (equal-count
# bins of at least 40: each bin's 95 % interval then spans at most about ±0.15 around p = 0.5);
# below it the curve would be noise, and the sensitivity table ranks the inputs instead.
CURVE_MIN_VARIANTS = 200


def _failure_curves(spec: StudySpec, summary: dict, tab) -> tuple[list[str], list[str]]:
    """The plots, and a line for each failure too sparse to draw."""
    valid = np.asarray(tab.column("valid").to_numpy(zero_copy_only=False), bool)
    out, skipped = [], []
    plt = _plt()
    for name, f in summary["failures"].items():
        if f["failures"] == 0:
            continue
        if f["variants"] < CURVE_MIN_VARIANTS:
            skipped.append(f"P({name}) against each input: {f['variants']} variants, fewer than the "
                           f"{CURVE_MIN_VARIANTS} a curve needs (see the ranking above)")
            continue
        y = _column(tab, f["output"])
        seen = valid & np.isfinite(y)
        failed = (y < f["limit"]) if f["side"] == "below" else (y > f["limit"])
        inputs = [i.key for i in spec.inputs]
        cols = min(3, len(inputs))
        rows = math.ceil(len(inputs) / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(9.5, 2.6 * rows), dpi=100, squeeze=False)
        for ax, field in zip(axes.flat, inputs, strict=False):
            x = _column(tab, f"in.{field}")[seen]
            c, frac, counts = stats.failure_curve(x, failed[seen])
            bounds = np.array([stats.wilson(int(round(p * n)), int(n))[1:] for p, n in zip(frac, counts, strict=True)])
            ax.errorbar(c, frac, yerr=[frac - bounds[:, 0], bounds[:, 1] - frac], fmt="o-", ms=3, lw=1.2,
                        capsize=2, color="#3d6fb6")
            unit = next((i.unit for i in spec.inputs if i.key == field), "")
            ax.set_xlabel(f"{field} ({unit})" if unit else field, fontsize=9)
            ax.set_ylim(-0.02, 1.02)
            ax.grid(True, alpha=0.3)
        for ax in list(axes.flat)[len(inputs):]:
            ax.axis("off")
        axes.flat[0].set_ylabel(f"P({name})")
        fig.suptitle(f"P({name}) against each input: equal-count bins, 95 % Wilson intervals", fontsize=10.5)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out, skipped


def _paper_vs_exact(tab, labels: dict[str, str]) -> tuple[list[str], list[str]]:
    """Where the paper's model and the exact model give the same figure: a histogram of their
    difference (exact − paper) over the variants (an identity plot shows nothing at this scale); a
    line for each figure on which they agree to 1e-9 everywhere."""
    names = tab.column_names
    pairs = sorted(k[len("analytical."):] for k in names
                   if k.startswith("analytical.") and f"exact.{k[len('analytical.'):]}" in names)
    out, same = [], []
    plt = _plt()
    for key in pairs:
        a, e = _column(tab, f"analytical.{key}"), _column(tab, f"exact.{key}")
        both = np.isfinite(a) & np.isfinite(e)
        if both.sum() < 2:
            continue
        d = e[both] - a[both]
        scale = max(float(np.max(np.abs(a[both]))), 1e-12)
        if float(np.max(np.abs(d))) <= 1e-9 * scale:
            same.append(f"{label_of(key, labels)}: the exact model equals the paper's on all {int(both.sum())} "
                        "variants")
            continue
        fig, ax = plt.subplots(figsize=(9.0, 3.0), dpi=100)
        ax.hist(d, bins=min(40, max(8, int(math.sqrt(d.size)))), color="#8a6bc7", edgecolor="white")
        ax.axvline(0.0, color="0.35", lw=1.0)
        ax.set_xlabel(f"exact model − paper's model: {label_of(key, labels)}")
        ax.set_ylabel("variants")
        ax.set_title(f"{label_of(key, labels)}: exact − paper, mean {float(np.mean(d)):.4g}, "
                     f"range {float(d.min()):.4g} to {float(d.max()):.4g} ({int(both.sum())} variants)")
        ax.grid(True, alpha=0.3)
        out.append(f"<div class='plot'>{figure_svg(fig, fit_width=True)}</div>")
    return out, same


def _drawn(summary: dict) -> str:
    """What the study draws, in words: each input's distribution."""
    out = []
    for key, i in summary["inputs"].items():
        unit = f" {i['unit']}" if i.get("unit") else ""
        if i["distribution"] == "uniform":
            shape = f"uniform {_fmt(i.get('low'))} to {_fmt(i.get('high'))}{unit}"
        else:
            centre = f"mean {_fmt(i['mean'])}, " if "mean" in i else ""
            shape = f"{i['distribution']} {centre}sd {_fmt(i.get('sd'))}{unit}"
        out.append(f"{key} {shape}")
    return "; ".join(out)


def _headline(summary: dict) -> str:
    """The failure counts against what the study draws: a study measures how often each failure
    happens over its inputs' distributions (one drawn past a limit on purpose finds it), so the
    headline states the counts and the inputs, not a pass or a fail."""
    n = summary["valid"]
    items = []
    for name, f in summary["failures"].items():
        if not f["variants"]:
            items.append(f"<li><code>{html.escape(name)}</code>: not evaluated</li>")
            continue
        items.append(f"<li><code>{html.escape(name)}</code> ({html.escape(f['label'])}): {f['failures']} of "
                     f"{f['variants']} valid variants, {_pct(f['probability'])} ({_pct(f['ci95_low'])} – "
                     f"{_pct(f['ci95_high'])})</li>")
    seen = sum(1 for f in summary["failures"].values() if f["failures"])
    return (f"<div class='banner info'>{seen} of {len(summary['failures'])} failure modes occur in {n} valid "
            f"variants drawn from: {html.escape(_drawn(summary))}<ul>{''.join(items)}</ul></div>")


def render(spec: StudySpec, summary: dict, tab, *, study_file: str, labels: dict[str, str] | None = None) -> str:
    """The page. ``labels``: the template's calc figure labels by key (the plots' axis labels)."""
    labels = labels or {}
    title = f"gearcheck study: {spec.title}"
    parts = ["<!doctype html><html lang='en'><head><meta charset='utf-8'>",
             "<meta name='viewport' content='width=device-width, initial-scale=1'>",
             f"<title>{html.escape(title)}</title><style>{CSS}{EXTRA_CSS}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>",
             f"<p class='meta'>study <code>{html.escape(study_file)}</code> · template "
             f"<code>{html.escape(summary['template'])}</code> · {summary['samples']} variants ({summary['sampler']}, "
             f"seed {summary['seed']}) · {summary['valid']} valid, {summary['rejected']} rejected by validation · "
             f"exact model on {summary['exact_variants']} · gearcheck {__version__}</p>"]
    parts.append(_headline(summary))
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
    parts += _histograms(spec, summary, tab, labels)
    curves, sparse = _failure_curves(spec, summary, tab)
    if curves or sparse:
        parts.append("<h2>Probability of failure against each input</h2>")
        parts += curves
        parts += [f"<p class='meta'>{html.escape(line)}.</p>" for line in sparse]
    comparisons, same = _paper_vs_exact(tab, labels)
    if comparisons or same:
        parts.append("<h2>The paper's model against the exact model</h2>")
        parts += comparisons
        parts += [f"<p class='meta'>{html.escape(line)}.</p>" for line in same]
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
