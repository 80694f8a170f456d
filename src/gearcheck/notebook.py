"""How gearcheck's results show themselves in a notebook: ``_repr_html_`` tables (Jupyter, VS Code,
Colab render them) and short ``__repr__`` lines, for :class:`gearcheck.design.Calc`,
:class:`gearcheck.results.Verdict`, :class:`gearcheck.results.CheckResult`,
:class:`gearcheck.pipeline.CheckRun` and :class:`gearcheck.studies.core.StudyResult`.

Plain HTML with inline styles (a notebook strips ``<style>`` blocks and scripts in some viewers),
every text escaped. Numpy and the standard library only.
"""

from __future__ import annotations

import difflib
import html
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

# badge colours: the report's (pass green, warn amber, fail red), white text
BADGE = {"pass": "#1a7f37", "warn": "#9a6700", "fail": "#cf222e"}
_TABLE = "border-collapse:collapse;font-size:0.9em;text-align:left"
_CELL = "padding:2px 8px;border-bottom:1px solid #ddd;vertical-align:top;text-align:left"
_NUM = _CELL.replace("text-align:left", "text-align:right") + ";font-variant-numeric:tabular-nums"
_DIM = "color:#666"


def _e(text: Any) -> str:
    return html.escape(str(text))


def badge(level: str) -> str:
    """PASS / WARN / FAIL on the level's colour."""
    colour = BADGE.get(level, "#57606a")
    return (f'<span style="background:{colour};color:#fff;border-radius:3px;padding:0 6px;'
            f'font-weight:bold;font-size:0.85em">{_e(level.upper())}</span>')


def _fmt(value: float | None, digits: int) -> str:
    if value is None:
        return ""
    return f"{value:.{digits}f}" if math.isfinite(value) else str(value)


def _table(heads: Sequence[str], rows: Iterable[Sequence[str]], numeric: Sequence[bool]) -> str:
    head = "".join(f'<th style="{_NUM if n else _CELL}">{_e(h)}</th>' for h, n in zip(heads, numeric, strict=True))
    body = "".join("<tr>" + "".join(f'<td style="{_NUM if n else _CELL}">{c}</td>'
                                    for c, n in zip(row, numeric, strict=True)) + "</tr>" for row in rows)
    return f'<table style="{_TABLE}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


# ------------------------------------------------------------------------------------------
# Calc


def calc_html(section: str, figures: Sequence[Any]) -> str:
    """The analytical figures: quantity, key (what ``calc[key]`` reads), value, unit, and the
    paper's value and the difference where any figure has one, the note dimmed."""
    paper = any(f.paper is not None for f in figures)
    heads = ["quantity", "key", "value", "unit", *(["paper", "diff"] if paper else []), "note"]
    numeric = [False, False, True, False, *([True, True] if paper else []), False]
    rows = []
    for f in figures:
        diff = f.difference
        cells = [_e(f.label), f"<code>{_e(f.key)}</code>", f"<b>{_e(_fmt(f.value, f.digits))}</b>", _e(f.unit)]
        if paper:
            cells += [_e(_fmt(f.paper, f.digits)), "" if diff is None else _e(f"{diff:+.{f.digits}f}")]
        rows.append([*cells, f'<span style="{_DIM}">{_e(f.note)}</span>'])
    return f"<div><b>{_e(section)}</b>: {len(figures)} figures{_table(heads, rows, numeric)}</div>"


def calc_repr(section: str, figures: Sequence[Any], shown: int = 4) -> str:
    first = ", ".join(f"{f.key}={_fmt(f.value, f.digits)}" for f in figures[:shown])
    more = f", … {len(figures) - shown} more" if len(figures) > shown else ""
    return f"<Calc {section}: {len(figures)} figures: {first}{more}; .keys() lists them>"


def missing_key(key: str, keys: Sequence[str], renamed: dict[str, str] | None = None) -> KeyError:
    """A KeyError naming the close matches (and a renamed key's new name)."""
    if renamed and key in renamed:
        return KeyError(f"{key!r} is called {renamed[key]!r} here")
    close = difflib.get_close_matches(key, list(keys), n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
    return KeyError(f"no figure {key!r}{hint} (.keys() lists all {len(keys)})")


# ------------------------------------------------------------------------------------------
# Verdicts and checks


def verdict_rows(verdicts: Sequence[Any]) -> list[list[str]]:
    return [[badge(v.level), f"<b>{_e(v.label)}</b><br>{_e(v.measured)}"
             + (f'<br><span style="{_DIM}">evidence: {_e(v.evidence)}</span>' if v.evidence else ""),
             f"<code>{_e(v.name)}</code>"] for v in verdicts]


def verdicts_table(verdicts: Sequence[Any]) -> str:
    return _table(["", "verdict", "name"], verdict_rows(verdicts), [False, False, False])


def verdict_html(v: Any) -> str:
    return verdicts_table([v])


def verdict_repr(v: Any, limit: int = 100) -> str:
    text = f"<Verdict {v.level.upper()} {v.name}: {v.measured}"
    return (text if len(text) <= limit else text[: limit - 1] + "…") + ">"


def check_html(result: Any, name: str = "", folder: Path | None = None) -> str:
    """The design's level and counts, a link to the report, and every verdict."""
    title = f" <b>{_e(name)}</b>:" if name else ""
    link = ""
    if folder is not None:
        report = Path(folder) / "report.html"
        link = f' — <a href="{_e(report.as_uri() if report.is_absolute() else report)}" target="_blank">' \
               f'{_e(report)}</a>'
    head = f"<div>{badge(result.level)}{title} {_e(result.count_text())}{link}</div>"
    return f"<div>{head}{verdicts_table(result.verdicts)}</div>"


def check_repr(result: Any, name: str = "", folder: Path | None = None) -> str:
    where = f"; {folder}" if folder is not None else ""
    failing = [v.name for v in result.verdicts if v.level == "fail"]
    fails = f"; failing: {', '.join(failing)}" if failing else ""
    return f"<CheckRun {name}: {result.level.upper()}, {result.count_text()}{fails}{where}>"


# ------------------------------------------------------------------------------------------
# Studies


def _pct(p: Any) -> str:
    return f"{100 * p:.3g} %" if isinstance(p, (int, float)) and math.isfinite(p) else ""


def _probability_rows(summary: dict) -> list[list[str]]:
    rows = []
    for name, f in (summary.get("failures") or {}).items():
        d = f.get("over_drawn") or {}
        level = "fail" if f.get("failures") else "pass"
        rows.append([badge(level), f"{_e(f.get('label', name))}<br><code>{_e(name)}</code>",
                     _e(f"{f.get('side', '')} {f.get('limit', '')}"),
                     _e(f"{f.get('failures')} / {f.get('variants')}"),
                     _e(f"{_pct(f.get('probability'))} ({_pct(f.get('ci95_low'))} – {_pct(f.get('ci95_high'))})"),
                     _e(f"{d.get('failures')} / {d.get('variants')}: {_pct(d.get('probability'))}") if d else ""])
    return rows


def study_html(result: Any) -> str:
    """The study's title, its valid and rejected variants, and each failure mode's probability
    with its 95 % Wilson interval, over the valid variants and over all drawn (rejected counted as
    failures of their own kind)."""
    s = result.summary
    where = f' — <span style="{_DIM}">{_e(result.folder)}</span>' if result.folder else ""
    counts = f"{s.get('valid')} valid variants, {s.get('rejected')} rejected by the template (out of spec)"
    rows = _probability_rows(s)
    table = _table(["", "failure", "limit", "failed / valid", "P(fail), 95 % interval", "over all drawn"], rows,
                   [False, False, False, True, True, True]) if rows else "<div>no failure mode declared</div>"
    return f"<div><b>{_e(s.get('study', 'study'))}</b>{where}<div>{_e(counts)}</div>{table}</div>"


def study_repr(result: Any) -> str:
    s = result.summary
    failing = [name for name, f in (s.get("failures") or {}).items() if f.get("failures")]
    where = f"; {result.folder}" if result.folder else ""
    return (f"<StudyResult {s.get('study', 'study')}: {s.get('valid')} valid of {s.get('samples')} drawn; "
            f"failure modes seen: {', '.join(failing) or 'none'}{where}>")


# ------------------------------------------------------------------------------------------
# Progress in a notebook


def in_notebook() -> bool:
    """Whether this process is a Jupyter kernel (IPython's kernel app is running)."""
    import sys

    shell = sys.modules.get("IPython")
    if shell is None:
        return False
    try:
        ip = shell.get_ipython()
    except AttributeError:
        return False
    return ip is not None and "IPKernelApp" in getattr(ip, "config", {})


def _say(line: str, stream: Any = None) -> None:
    """One progress line on ``stream`` (default: this moment's stdout, which a notebook shows in
    the cell's output as it comes), flushed at once. A progress display, as the terminal's bars
    are; diagnostics go to the ``gearcheck`` logger."""
    import sys

    out = stream if stream is not None else sys.stdout
    out.write(line + "\n")
    out.flush()


class _LineBar:
    """Prints ``desc: k/n unit (p %)`` each time another tenth of the work is done."""

    def __init__(self, desc: str, total: int | None, unit: str, stream: Any = None):
        self.desc, self.total, self.unit, self.stream = desc, total, unit, stream
        self.done = 0
        self.tenth = 0

    def update(self, n: int = 1) -> None:
        self.done += n
        if not self.total:
            return
        tenth = min(10, (10 * self.done) // self.total)
        if tenth > self.tenth:
            self.tenth = tenth
            _say(f"  {self.desc}: {self.done}/{self.total} {self.unit} ({10 * tenth} %)", self.stream)


class _PatientBar(_LineBar):
    """A :class:`_LineBar` that says nothing until its stage has run ``patience_s`` seconds:
    then the stage's line, and a line per tenth from there on."""

    def __init__(self, desc: str, total: int | None, unit: str, stream: Any, patience_s: float):
        super().__init__(desc, total, unit, stream)
        import time

        self.start, self.patience_s, self.started = time.monotonic(), patience_s, False

    def speak(self) -> bool:
        """True once the stage has run long enough to be worth lines (its first line said now)."""
        import time

        if not self.started and time.monotonic() - self.start >= self.patience_s:
            self.started = True
            _say(f"{self.desc} …", self.stream)
        return self.started

    def update(self, n: int = 1) -> None:
        if self.speak():
            super().update(n)
        else:
            self.done += n
            if self.total:
                self.tenth = min(10, (10 * self.done) // self.total)


def line_progress(desc: str, total: int | None = None, unit: str = "", stream: Any = None,
                  patience_s: float = 0.0) -> Any:
    """A progress factory (``pipeline.ProgressFactory``) that prints plain lines to ``stream``
    (default stdout): the stage when it starts, every tenth of its work, its time when done. What a
    notebook cell (or a piped run's log) shows while the work goes on. ``patience_s``: a stage
    shorter than this says nothing (its lines begin once it has run that long)."""
    import contextlib
    import time

    @contextlib.contextmanager
    def stage() -> Any:
        start = time.monotonic()
        bar = _PatientBar(desc, total, unit, stream, patience_s)
        bar.speak()  # the stage's first line now, unless it must first run patience_s
        yield bar
        if bar.speak():
            _say(f"{desc}: done in {time.monotonic() - start:.1f} s", stream)

    return stage()


class NotebookProgress:
    """One progress display in a notebook cell, updated in place (not a line per step): a table
    of the run's stages, each with its count, percentage and time. A progress factory
    (``pipeline.ProgressFactory``) for ``Design.check()`` in Jupyter; where IPython's display is
    missing it falls back to :func:`line_progress`."""

    REFRESH_S = 0.25  # at most this often between two redraws (and at every stage's end)

    def __init__(self) -> None:
        self.stages: list[dict[str, Any]] = []
        self.handle: Any = None
        self.drawn = 0.0

    def html(self) -> str:
        rows = []
        for st in self.stages:
            total = st["total"]
            count = f"{st['done']}/{total} {st['unit']}".strip() if total else (f"{st['done']}" if st["done"] else "")
            pct = f"{min(100, 100 * st['done'] // total)} %" if total else ""
            state = f"done in {st['seconds']:.1f} s" if st["seconds"] is not None else "…"
            rows.append(f"<tr><td>{_esc(st['desc'])}</td><td>{_esc(count)}</td><td>{pct}</td><td>{state}</td></tr>")
        return ("<table class='gearcheck-progress'><tr><th>stage</th><th>done</th><th></th><th>time</th></tr>"
                + "".join(rows) + "</table>")

    def draw(self, force: bool = False) -> None:
        import time

        now = time.monotonic()
        if not force and now - self.drawn < self.REFRESH_S:
            return
        self.drawn = now
        from IPython.display import HTML, display

        if self.handle is None:
            self.handle = display(HTML(self.html()), display_id=True)
        else:
            self.handle.update(HTML(self.html()))

    def __call__(self, desc: str, total: int | None = None, unit: str = "") -> Any:
        import contextlib
        import time

        board = self

        class _Bar:
            def __init__(self, stage: dict[str, Any]):
                self.stage = stage

            def update(self, n: int = 1) -> None:
                self.stage["done"] += n
                board.draw()

        @contextlib.contextmanager
        def stage() -> Any:
            start = time.monotonic()
            entry: dict[str, Any] = {"desc": desc, "total": total, "unit": unit, "done": 0, "seconds": None}
            self.stages.append(entry)
            self.draw(force=True)
            yield _Bar(entry)
            entry["seconds"] = time.monotonic() - start
            self.draw(force=True)

        return stage()


def _esc(text: str) -> str:
    import html

    return html.escape(str(text))


def notebook_progress() -> Any:
    """The progress factory for a notebook: one display updated in place when IPython can show
    it, else a line per stage and per tenth (:func:`line_progress`)."""
    try:
        import IPython.display  # noqa: F401
    except ImportError:
        return line_progress
    return NotebookProgress()
