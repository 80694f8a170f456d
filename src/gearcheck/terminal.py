"""What the command line shows, made here and printed by :mod:`gearcheck.cli` (the only module
that prints): the calc table, the verdicts, the one-line pointers, and the JSON object of a build
or a check.

Two looks, one content. On a terminal: tables, coloured PASS / WARN / FAIL, everything wrapped to
the terminal's width (with ``NO_COLOR`` set: the same layout without escape codes). Piped or
redirected: plain text, no escape codes, no trailing blanks, nothing wrapped: one verdict per line
and the calc table as wide as its longest note, so that ``grep`` finds a verdict and its
measurement on one line (``fold -s`` or ``less -S`` to read it narrow).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import math
import os
import re
import sys
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rich.console import Console, RenderableType

    from gearcheck.figures import Figure
    from gearcheck.pipeline import Bar, BuildRun, CheckRun
    from gearcheck.results import CheckResult

UNBOUNDED = 4000  # the width of a "line" when nothing is wrapped (not a terminal)
NOTE_MIN = 16  # the calc table's notes wrap down to this width before its quantities do
NOTE_COLUMN_MIN = 30  # narrower than this, each note goes on its own line under its quantity
NOTE_INDENT = 3
MIN_WIDTH = 40  # narrower terminals are drawn at this width (the terminal wraps the rest)
LEVEL_WORD = {"pass": "PASS", "warn": "WARN", "fail": "FAIL"}
# Longest verdict line, on a terminal and piped (the whole sentence: report.html, summary.json)
# calc's table when piped: this many columns (the notes wrap, or go under their quantity)
CALC_WIDTH = 100
LEVEL_STYLE = {"pass": "bold black on green", "warn": "bold black on yellow", "fail": "bold white on red"}


@dataclass(frozen=True)
class Screen:
    """Where the output goes: a terminal or not, colours or not, the width to wrap at (None: no
    wrapping)."""

    tty: bool
    color: bool
    width: int | None

    @classmethod
    def of(cls, stream: Any, environ: Mapping[str, str] = os.environ) -> Screen:
        """The terminal's width when ``stream`` is one (its real size: a ``COLUMNS`` left in the
        environment by a parent's readline is no guide), else no wrapping."""
        try:
            tty = bool(stream.isatty())
        except (AttributeError, ValueError):
            tty = False
        width = None
        if tty:
            try:
                width = max(os.get_terminal_size(stream.fileno()).columns or 80, MIN_WIDTH)
            except (AttributeError, ValueError, OSError):
                width = 80
        color = tty and not environ.get("NO_COLOR") and environ.get("TERM") != "dumb"
        return cls(tty, color, width)


# ------------------------------------------------------------------------------------------
# Help

DESCRIPTION = """\
gearcheck turns a parameter file (TOML template) into the design figures, CAD and an
interference proof of a gear mechanism.

Mechanisms: {mechanisms}. One template each in templates/ (gearcheck templates --copy DIR):
  zhurong_differential.toml   bevel-gear differential, cold backlash and shims
  eod_track_drive.toml        roller-chain track sprocket, every other tooth engaging
  nose_wheel_steering.toml    trimmed rack and pinion, continuous drive and disengage angles
  roller_chain_12B_z21.toml   ISO 606 sprocket and roller chain: engagement, polygon effect, wear
  assembly_spur_pair.toml     your own CAD: a STEP assembly swept through declared joints
Your own design from a few numbers: gearcheck new MECHANISM (--help lists its inputs).

Examples:
  gearcheck calc templates/zhurong_differential.toml
  gearcheck calc templates/zhurong_differential.toml --set operating.cold_C=-130
  gearcheck calc templates/nose_wheel_steering.toml --set trim.min_contact_ratio=1.3 --json
  gearcheck check templates/eod_track_drive.toml --jobs 2 --open
  gearcheck check templates/eod_track_drive.toml --json > run.json
  gearcheck build --all --out out
  gearcheck schema track > track.schema.json
  gearcheck demo --open

Output: tables and coloured PASS / WARN / FAIL on a terminal, wrapped to its width, nothing cut
(NO_COLOR: the same without colours); plain text when piped: one whole verdict per line (its
claim, key figure and evidence; every sentence in full in report.html and summary.json), calc
100 columns wide. Progress on stderr: bars with totals and the time left on a terminal; piped
(CI, nohup, an IDE), a line per stage and per tenth of it.
Exit codes: 0 no verdict fails (warnings included), 1 a verdict fails, 2 bad input, 3 an internal
error (a worker process killed; -v shows the traceback), 130 / 143 interrupted.
"""

TOL_HELP = ("absolute chordal tolerance of the meshes in mm, used as given (default per mechanism: {defaults}, "
            "refined before meshing so that the two meshes' error bounds together stay within 1/10 of the "
            "smallest clearance the design asks to decide, from its exact model; where a mesh cannot resolve "
            "it, the exact model and the exact B-rep decide, and the report says so)")

CHECK_EXAMPLES = """\
Examples:
  gearcheck check templates/eod_track_drive.toml
  gearcheck check templates/zhurong_differential.toml --set shim.thickness_mm=0.15 --out out/shim015
  gearcheck check templates/eod_track_drive.toml --json | jq '.verdicts[] | [.level, .label]'
  gearcheck check out/eod_track_drive/params.toml --out out/again   (reproduces a run)
  gearcheck check --all --jobs 2 --open

The CAD cache: a design's solids, meshes and STEP file are kept (in $GEARCHECK_CACHE, default
~/.cache/gearcheck) by what they are built from, so a re-check that changes only what the sweep,
the verdicts or the report read (temperatures, targets, tolerances of the sweep) skips the CAD
kernel, with the same figures and files (the manifest and the report say where the CAD came
from). --no-cache builds anew."""

BUILD_EXAMPLES = """\
Examples:
  gearcheck build templates/nose_wheel_steering.toml --open
  gearcheck build templates/eod_track_drive.toml --tol 0.005 --json
  gearcheck build --all --out out --jobs 3"""


class HelpFormatter(argparse.HelpFormatter):
    """Fills in the per-mechanism tolerances only when help is shown (it imports the mechanisms);
    wraps prose paragraphs and keeps those with indented lines (examples, lists) as written."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        if action.dest == "tol" and text is not None:
            from gearcheck.mechanism import all_mechanisms

            defaults = ", ".join(f"{m.name} {m.mesh_tol_mm:g}" for m in all_mechanisms())
            return text.replace("{defaults}", defaults)
        return text

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        paragraphs = []
        for para in text.split("\n\n"):
            if any(line.startswith("  ") for line in para.splitlines()):
                paragraphs.append("\n".join(indent + line for line in para.splitlines()))
            else:
                paragraphs.append(super()._fill_text(para, width, indent))
        return "\n\n".join(paragraphs)



def _box(screen: Screen):
    from rich import box

    if screen.color:
        return box.SIMPLE_HEAD
    # the header underlined with ASCII dashes, columns apart by blanks (as the calc.txt file)
    return box.Box("    \n    \n -  \n    \n    \n    \n    \n    \n", ascii=True)


_TRAILING = re.compile(r"\s+((?:\x1b\[[0-9;]*m)*)$")  # blanks at a line's end, before any closing style codes


def text(screen: Screen, *renderables: RenderableType) -> str:
    """The renderables as the screen shows them: escape codes only with colour, each line's
    trailing blanks cut."""
    from rich.console import Console

    out = io.StringIO()
    console: Console = Console(file=out, width=screen.width or UNBOUNDED, force_terminal=screen.color,
                               color_system="auto" if screen.color else None, no_color=not screen.color,
                               highlight=False, markup=False, emoji=False, legacy_windows=False,
                               force_jupyter=False, force_interactive=False, _environ={})
    for r in renderables:
        console.print(r, crop=screen.width is not None, soft_wrap=screen.width is None)
    return "\n".join(_TRAILING.sub(r"\1", line) for line in out.getvalue().splitlines())


def _fmt(value: float | None, digits: int) -> str:
    if value is None:
        return ""
    return f"{value:.{digits}f}" if math.isfinite(value) else str(value)


def calc_view(title: str, figures: list[Figure], screen: Screen) -> list[RenderableType]:
    """The analytical figures as a table: quantity, value, unit, the paper's value, the
    difference, and the note saying why they differ (the note column wraps on a terminal)."""
    from rich.padding import Padding
    from rich.table import Table
    from rich.text import Text

    from gearcheck.figures import any_paper

    rows = []
    for f in figures:
        diff = f.difference
        rows.append((f.label, _fmt(f.value, f.digits), f.unit, _fmt(f.paper, f.digits),
                     "" if diff is None else f"{diff:+.{f.digits}f}", f.note))
    heads = ("quantity", "value", "unit", "paper", "diff", "note")
    paper = any_paper(figures)  # else no paper and diff columns (no figure stands beside a paper's value)
    longest = [max(len(r[i]) for r in [heads, *rows]) if paper or i not in (3, 4) else 0 for i in range(6)]
    quantity_w = note_w = None
    notes_under = False
    if screen.width is not None:  # the quantity keeps its width while the notes wrap
        room = screen.width - sum(longest[1:5]) - 15  # 15: padding and dividers of six columns
        quantity_w = min(longest[0], max(12, room - NOTE_MIN))
        note_w = max(NOTE_MIN, min(longest[5], room - quantity_w))
        # too narrow for a note column worth reading: each note on its own line under its quantity
        notes_under = note_w < NOTE_COLUMN_MIN and longest[5] > note_w
        if notes_under:
            quantity_w = min(max(longest[0], min(longest[5] + NOTE_INDENT, room + 3)), max(12, room + 3))
    table = Table(box=_box(screen), show_edge=False, pad_edge=False, header_style="bold", padding=(0, 1))
    table.add_column("quantity", width=quantity_w, overflow="fold")
    table.add_column("value", justify="right", no_wrap=True, style="bold")
    table.add_column("unit", no_wrap=True)
    if paper:
        table.add_column("paper", justify="right", no_wrap=True, style="cyan")
        table.add_column("diff", justify="right", no_wrap=True, style="yellow")
    if not notes_under:
        table.add_column("note", width=note_w, overflow="fold", style="dim")
    for row in rows:
        cells = row[:5] if paper else row[:3]
        if not notes_under:
            table.add_row(*cells, row[5])
            continue
        table.add_row(*cells)
        if row[5]:
            table.add_row(Padding(Text(row[5], style="dim italic"), (0, 0, 0, NOTE_INDENT)), *[""] * (len(cells) - 1))
    return [Text(title, style="bold"), table]


def badge(level: str, screen: Screen) -> Any:
    """PASS / WARN / FAIL: on a coloured background on a terminal, the bare word otherwise."""
    from rich.text import Text

    word = LEVEL_WORD[level]
    return Text(f" {word} ", LEVEL_STYLE[level]) if screen.color else Text(word)


def _headline(result: CheckResult, name: str, folder: Path, screen: Screen) -> Any:
    from rich.text import Text

    line = Text()
    line.append_text(badge(result.level, screen))
    line.append(f" {name}: {result.count_text()}; report {folder / 'report.html'}")
    return line


def verdicts_view(result: CheckResult, name: str, folder: Path, screen: Screen) -> list[RenderableType]:
    """The design's level, then each verdict: PASS / WARN / FAIL, what was checked, its key
    figure (the shortfall where it fails or warns) and the evidence that decided it, whole: never
    cut. Piped, one line per verdict (grep finds a verdict and its figure); on a terminal, wrapped
    to its width under its badge. The whole sentence is in report.html and summary.json
    (``verdict_measured``, ``verdict_evidence``)."""
    from rich.padding import Padding
    from rich.table import Table
    from rich.text import Text

    out: list[RenderableType] = [_headline(result, name, folder, screen)]
    if screen.width is None:
        for v in result.verdicts:
            line = Text("  ")
            line.append_text(badge(v.level, screen))
            line.append(f"  {v.whole_line()}")
            out.append(line)
        return out
    grid = Table.grid(padding=(0, 2))
    grid.add_column(no_wrap=True)
    grid.add_column(overflow="fold")
    for v in result.verdicts:
        grid.add_row(badge(v.level, screen), Text(v.whole_line()))
    out.append(Padding(grid, (0, 0, 0, 2)))
    return out


def _indented(renderable: RenderableType) -> RenderableType:
    from rich.padding import Padding

    return Padding(renderable, (0, 0, 0, 2))


def calc_pointer(figures: list[Figure], path: Path) -> str:
    """One line in place of the calc table: how many figures, how many beside the paper's, where
    the table is."""
    paper = sum(f.paper is not None for f in figures)
    beside = f" ({paper} beside the paper's values)" if paper else ""
    return f"{len(figures)} figures{beside}, table in {path}"


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB"):
        if n < 1000 or unit == "GB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1000
    return f"{n:.1f} GB"


def files_line(folder: Path, files: Iterable[Path], parts: int) -> str:
    """"wrote DIR/ (size): N parts; report.html, ..., 2 PNG, 13 STL" for a build or a check."""
    files = [p for p in files if p.is_file()]
    first = ("report.html", "summary.json", "sweep.csv")
    names = sorted((p.name for p in files), key=lambda n: (first.index(n) if n in first else len(first), n))
    counted = {ext: sum(n.endswith(f".{ext.lower()}") for n in names) for ext in ("PNG", "STL")}
    shown = [n for n in names if not n.endswith((".png", ".stl"))]
    shown += [f"{k} {ext}" for ext, k in counted.items() if k]
    total = sum(p.stat().st_size for p in files)
    return f"wrote {folder}/ ({_size(total)}): {parts} parts; {', '.join(shown)}"


# ------------------------------------------------------------------------------------------
# JSON (check --json, build --json)


def _finite(figures: Mapping[str, Any]) -> dict[str, float]:
    return {k: float(v) for k, v in figures.items()
            if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)}


def _files(paths: Iterable[Path]) -> list[dict[str, Any]]:
    return [{"file": p.name, "bytes": p.stat().st_size} for p in paths if p.is_file()]


def _mesh(manifest: Mapping[str, Any]) -> dict[str, Any]:
    plan = manifest.get("mesh_tolerance", {})
    out: dict[str, Any] = {
        "chordal_tolerance_mm": float(manifest["chordal_tolerance_mm"]),
        "parts": len(manifest["parts"]),
        "triangles": int(sum(p["triangles"] for p in manifest["parts"])),
    }
    for key in ("requested_tol_mm", "refined", "explicit", "smallest_clearance_mm", "smallest_clearance"):
        value = plan.get(key)
        if value is not None and (not isinstance(value, float) or math.isfinite(value)):
            out[key] = value
    return out


def build_json(run: BuildRun) -> dict[str, Any]:
    """What ``gearcheck build --json`` prints for one template (plain data: it travels back from
    a worker process when --all builds several)."""
    manifest = run.manifest
    return {
        "mechanism": run.design.mechanism,
        "name": run.design.name,
        "template": run.design.source,
        "folder": str(Path(run.folder).absolute()),
        "mesh": _mesh(manifest),
        "parts": [{"name": p["name"], "material": p["material"], "triangles": p["triangles"],
                   "brep_volume_mm3": p["brep_volume_mm3"], "mesh_error_bound_mm": p["mesh_error_bound_mm"]}
                  for p in manifest["parts"]],
        "files": _files(run.files),
    }


def check_json(run: CheckRun) -> dict[str, Any]:
    """What ``gearcheck check --json`` prints for one template: the design's level, each verdict
    (level, what was measured, the deciding numbers, the evidence), the key figures (paper vs
    model vs geometry, the exact confirmation), the mesh, and every file written with its size."""
    result, build = run.result, run.build
    counts = {level: sum(v.level == level for v in result.verdicts) for level in LEVEL_WORD}
    comparisons = []
    for c in result.comparisons:
        row: dict[str, Any] = {"label": c.label, "unit": c.unit}
        for key in ("paper", "model", "exact", "geometry"):
            value = getattr(c, key)
            if value is not None and math.isfinite(value):
                row[key] = float(value)
        if c.note:
            row["note"] = c.note
        comparisons.append(row)
    return {
        "mechanism": build.design.mechanism,
        "name": build.design.name,
        "template": build.design.source,
        "folder": str(Path(run.folder).absolute()),
        "level": result.level,
        "passed": bool(result.passed),
        "counts": counts,
        "verdicts": [{"name": v.name, "label": v.label, "level": v.level, "measured": v.measured,
                      "evidence": v.evidence, "figures": _finite(v.figures)} for v in result.verdicts],
        "figures": comparisons,
        "confirmations": [{"label": c.label, "parts": c.parts, "agrees": bool(c.agrees),
                           **_finite({"mesh_mm": c.mesh_mm, "brep_mm": c.brep_mm, "bound_mm": c.bound_mm,
                                      "overlap_mm3": c.overlap_mm3})} for c in result.confirmations],
        "mesh": _mesh(build.manifest),
        "files": _files(run.files),
    }


# ------------------------------------------------------------------------------------------
# Progress on a terminal


def clock(seconds: float) -> str:
    """m:ss, or h:mm:ss from an hour on."""
    s = int(round(seconds))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


def _without_size() -> dict[str, str]:
    """The environment less COLUMNS / LINES (a parent's readline leaves them stale): the bars
    follow the terminal's real size."""
    return {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}


class Bars:
    """The pipeline's progress factory (``progress(desc, total, unit)``) on a terminal: one rich
    display on stderr, a line per stage with its count out of the total, the percentage, the time
    taken and the time left. ``wait(desc)`` shows a stage the pipeline reports no progress for
    (the plan and the solids before meshing) until the next bar begins. Use it as a context."""

    def __init__(self, stream: Any = None) -> None:
        import sys

        from rich.console import Console
        from rich.progress import BarColumn, Progress, SpinnerColumn, TaskProgressColumn, TextColumn, TimeElapsedColumn

        self.progress = Progress(
            SpinnerColumn(finished_text="✓"), TextColumn("{task.description}", markup=False),
            BarColumn(bar_width=None), TextColumn("{task.fields[count]}", markup=False), TaskProgressColumn(),
            TimeElapsedColumn(), TextColumn("{task.fields[eta]}", style="cyan", markup=False),
            console=Console(file=stream or sys.stderr, highlight=False, markup=False, emoji=False,
                            _environ=_without_size()),
            redirect_stdout=True, redirect_stderr=True, expand=True, refresh_per_second=8)
        self.pending: Any = None

    def __enter__(self) -> Bars:
        self.progress.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._end_pending()
        self.progress.stop()

    def wait(self, desc: str) -> None:
        self._end_pending()
        self.pending = self.progress.add_task(desc, total=None, count="", eta="")

    def announce(self, text: str) -> None:
        """A line above the bars: what a long stage is about to cost (a sweep's prediction)."""
        self._end_pending()
        self.progress.console.print(text, markup=False, highlight=False)

    def _end_pending(self) -> None:
        if self.pending is not None:
            self.progress.update(self.pending, total=1, completed=1)
            self.progress.stop_task(self.pending)
            self.pending = None

    @contextlib.contextmanager
    def __call__(self, desc: str, total: int | None = None, unit: str = "") -> Iterator[_Task]:
        self._end_pending()
        bar = _Task(self.progress, self.progress.add_task(desc, total=total, count="", eta=""), unit)
        bar.update(0)
        try:
            yield bar
        finally:
            self.progress.update(bar.task, eta="")
            self.progress.stop_task(bar.task)


class _Task:
    """One bar: ``update(n)`` advances it and refreshes its count and time left."""

    def __init__(self, progress: Any, task: Any, unit: str):
        self.progress, self.task, self.unit = progress, task, unit

    def update(self, n: int = 1) -> None:
        self.progress.advance(self.task, n)
        t = self.progress.tasks[self.task]
        total = "?" if t.total is None else f"{t.total:g}"
        left = t.time_remaining
        self.progress.update(self.task, count=f"{t.completed:g}/{total} {self.unit}".rstrip(),
                             eta="" if left is None or t.finished else f"eta {clock(left)}")


@dataclass
class Checked:
    """What the terminal shows of a finished check, as plain data (it comes back from a worker
    process when ``check --all`` runs templates side by side)."""

    result: CheckResult
    name: str
    folder: Path
    files: list[Path]
    parts: int
    json: dict[str, Any]

    @classmethod
    def of(cls, run: CheckRun) -> Checked:
        return cls(run.result, run.build.design.name, run.folder, list(run.files), len(run.build.parts),
                   check_json(run))


def check_task(_state: Any, design: Any, folder: Path, tol_mm: float | None, overrides: list[str],
               jobs: int | None, budget_cpu_s: float | None = None) -> Checked:
    """One template's check for ``check --all`` (an executor task: templates run side by side).
    A pool's worker process may not start processes of its own, so there the sweep runs in it
    (``--jobs 1``); the calling process's template gets ``jobs``."""
    import multiprocessing as mp

    from gearcheck import pipeline

    inner = 1 if mp.current_process().daemon else jobs
    return Checked.of(pipeline.check(design, folder, tol_mm=tol_mm, jobs=inner, overrides=overrides,
                                     budget_cpu_s=budget_cpu_s))


# ------------------------------------------------------------------------------------------
# Progress where stderr is no terminal, and the log handler


def _line(text: str) -> None:
    """One line on this moment's stderr, flushed."""
    sys.stderr.write(text + "\n")
    sys.stderr.flush()


class Plain:
    """Progress where stderr is not a terminal: no bars, one line when a template starts; with
    ``tenths`` (a study, minutes long), a line per stage and per tenth of its work too."""

    def __init__(self, tenths: bool = False, patience_s: float = 0.0) -> None:
        self.tenths, self.patience_s = tenths, patience_s

    def __enter__(self) -> Plain:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def wait(self, desc: str) -> None:
        _line(f"{desc} ...")

    def announce(self, text: str) -> None:
        """A long stage is coming (a sweep's predicted cost): its line, and lines as it goes."""
        _line(text)
        self.next_long = True

    next_long = False

    def __call__(self, desc: str, total: int | None = None, unit: str = "") -> contextlib.AbstractContextManager[Bar]:
        from gearcheck.notebook import line_progress
        from gearcheck.pipeline import no_progress

        long, self.next_long = self.next_long, False
        return (line_progress(desc, total, unit, sys.stderr, 0.0 if long else self.patience_s)
                if self.tenths or long else no_progress(desc, total, unit))


# piped, a check's stage that runs this long gets its lines (a quick one stays quiet)
PIPED_PATIENCE_S = 3.0


def display(tenths: bool = False, patience_s: float = 0.0) -> Any:
    """Progress bars on stderr when it is a terminal, else a line per template (``tenths``: and a
    line per stage and per tenth of its work, once the stage has run ``patience_s``)."""
    return Bars() if sys.stderr.isatty() else Plain(tenths, patience_s)


class StderrHandler(logging.StreamHandler):
    """Logs to whatever sys.stderr is now (above the progress bars while they show)."""

    @property
    def stream(self) -> Any:
        return sys.stderr

    @stream.setter
    def stream(self, _value: Any) -> None:
        pass
