"""Command line: parse, call the pipeline, print. Exit codes: 0 ok, 1 a verdict failed, 2 bad input.

The only module that prints. Everything it runs is the library's (:mod:`gearcheck.design`,
:mod:`gearcheck.pipeline`); progress bars go to stderr when it is a terminal, diagnostics to the
``gearcheck`` logger (``-v`` shows them).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import logging
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearcheck import __version__
from gearcheck.params import ParamError

if TYPE_CHECKING:
    from gearcheck.design import Design
    from gearcheck.pipeline import Bar

TEMPLATE_DIR = Path("templates")

DESCRIPTION = """\
gearcheck turns a parameter file (TOML template) into the design figures, CAD and an
interference proof of a gear mechanism.

Mechanisms: {mechanisms} (one template each in templates/:
  zhurong_differential.toml   bevel-gear differential, cold backlash and shims
  eod_track_drive.toml        roller-chain track sprocket, every other tooth engaging
  nose_wheel_steering.toml    trimmed rack and pinion, continuous drive and disengage angles)

Examples:
  gearcheck calc templates/zhurong_differential.toml
  gearcheck calc templates/zhurong_differential.toml --set operating.cold_C=-130
  gearcheck calc templates/nose_wheel_steering.toml --set trim.min_contact_ratio=1.3 --json
  gearcheck check templates/eod_track_drive.toml --jobs 2
"""

TOL_HELP = ("absolute chordal tolerance of the meshes in mm (default per mechanism: {defaults} — fine enough "
            "that the mesh-error bound is at most 1/10 of the smallest clearance the check decides on; "
            "`check` refuses coarser meshes)")


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # usage errors are bad input: exit 2, one line
        self.exit(2, f"gearcheck: error: {message}\n")


class _Formatter(argparse.HelpFormatter):
    """Fills in the per-mechanism tolerances only when help is shown (it imports the mechanisms)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        if action.dest == "tol" and text is not None:
            from gearcheck.mechanism import all_mechanisms

            defaults = ", ".join(f"{m.name} {m.mesh_tol_mm:g}" for m in all_mechanisms())
            return text.replace("{defaults}", defaults)
        return text


class _MainFormatter(_Formatter, argparse.RawDescriptionHelpFormatter):
    """The top-level help keeps its description's lines (the template list, the examples)."""


def _jobs(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--jobs = {text!r}: allowed a whole number ≥ 1") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"--jobs = {value}: allowed a whole number ≥ 1")
    return value


def _add_template_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("template", type=Path, help="TOML parameter file (see templates/)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one template value, validated like the file (repeatable), "
                        "e.g. --set shim.thickness_mm=0.15")


def _add_jobs_arg(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--jobs", "-j", type=_jobs, default=None, metavar="N",
                   help=f"worker processes for {what} (default: every core; 1 runs in this process). "
                        "Results are identical for any N.")


def _add_cad_args(p: argparse.ArgumentParser, verb: str) -> None:
    """TEMPLATE | --all, --set, --out, --tol, --jobs: shared by `build` and `check`."""
    p.add_argument("template", type=Path, nargs="?", help="TOML parameter file (omit with --all)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one template value (repeatable)")
    p.add_argument("--all", action="store_true", help=f"{verb} every template in templates/ into OUT/NAME")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default out/NAME; with --all, the parent folder, default out)")
    p.add_argument("--tol", type=float, default=None, metavar="MM", help=TOL_HELP)
    _add_jobs_arg(p, "the sweep" if verb == "check" else "building several templates (--all)")


def build_parser() -> argparse.ArgumentParser:
    from gearcheck.mechanism import names

    parser = _Parser(prog="gearcheck", description=DESCRIPTION.format(mechanisms=", ".join(names())),
                     formatter_class=_MainFormatter)
    parser.add_argument("--version", action="version", version=f"gearcheck {__version__}")
    parser.add_argument("--verbose", "-v", action="store_true", help="print diagnostics (timings, workers) to stderr")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    calc = sub.add_parser(
        "calc", formatter_class=_Formatter,
        help="the paper's analytical model: design figures beside the paper's numbers",
        description="Compute the mechanism's design figures from its template with the paper's "
        "analytical model (reconstructed where the paper lost equations), and print them beside "
        "the paper's printed values with the difference and the reason where they differ.",
    )
    _add_template_args(calc)
    calc.add_argument("--json", action="store_true",
                      help="print one JSON object (nested by section) instead of a table")

    build = sub.add_parser(
        "build", formatter_class=_Formatter,
        help="build the CAD: STEP assembly, one STL per part, manifest.json",
        description="Build the mechanism's parts with CadQuery from the template (exact involute "
        "flanks), mesh each part with an absolute chordal tolerance, and write DIR/NAME.step "
        "(named, placed parts), DIR/PART.stl, DIR/params.toml (the resolved parameters) and "
        "DIR/manifest.json (materials, volumes, triangle counts, measured mesh error, file hashes). "
        "Every file is written atomically.",
    )
    _add_cad_args(build, "build")

    check = sub.add_parser(
        "check", formatter_class=_Formatter,
        help="build, mesh and sweep the mechanism; write report.html, summary.json, sweep.csv",
        description="Build the CAD (as `build`), sweep the assembly through its motion with "
        "python-fcl on the meshes (warm and cold for the differential, a full engagement cycle "
        "for the track drive, towing and power modes for the steering), confirm each sweep's "
        "worst pose on the exact B-rep, and write DIR/report.html (verdicts, paper vs model vs "
        "geometry, plots), DIR/summary.json (numbers) and DIR/sweep.csv (one row per pose) beside "
        "the CAD. Exit 0 when every verdict passes, 1 when one fails, 2 on bad input.",
    )
    _add_cad_args(check, "check")

    demo = sub.add_parser("demo", formatter_class=_Formatter,
                          help="every template in templates/: figures and CAD under --out (what `make demo` runs)")
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: out)")
    demo.add_argument("--templates", type=Path, default=TEMPLATE_DIR, help="folder of templates (default: templates)")
    demo.add_argument("--no-cad", action="store_true", help="analytical figures only, no CAD build")
    _add_jobs_arg(demo, "the sweeps")
    return parser


# ------------------------------------------------------------------------------------------
# Progress and printing


@contextlib.contextmanager
def _bars(desc: str, total: int | None = None, unit: str = "") -> Iterator[Bar]:
    """The pipeline's progress factory: a tqdm bar with total and ETA on a terminal, else nothing."""
    from tqdm import tqdm

    with tqdm(desc=desc, total=total, unit=f" {unit}" if unit else "it", file=sys.stderr,
              disable=not sys.stderr.isatty(), dynamic_ncols=True) as bar:
        yield bar


def _print_verdicts(design: Design, folder: Path, result) -> None:
    verdict = "PASS" if result.passed else "FAIL"
    print(f"{verdict} {design.name}: {sum(v.passed for v in result.verdicts)}/{len(result.verdicts)} verdicts; "
          f"report {folder / 'report.html'}")
    for v in result.verdicts:
        word = {"pass": "pass", "warn": "warn", "fail": "FAIL"}[v.level]
        print(f"  [{word}] {v.label}: {v.measured}")


# ------------------------------------------------------------------------------------------
# Commands


def cmd_calc(args) -> int:
    from gearcheck.design import load_template
    from gearcheck.figures import render_table

    design = load_template(args.template, args.overrides)
    calc = design.calc()
    if args.json:
        print(json.dumps(calc.to_dict(), indent=2, allow_nan=False))
    else:
        print(render_table(f"{design.name} ({design.mechanism}) — analytical model", calc.figures))
    return 0


def _templates_or_one(args) -> list[Design]:
    """The validated templates a build/check acts on: one, or --all (all validated first)."""
    from gearcheck.design import load_template
    from gearcheck.pipeline import check_tol

    check_tol(args.tol)
    if args.all == (args.template is not None):
        raise ParamError(args.command, str(args.template), "give one TEMPLATE or --all, not both or neither")
    if args.all:
        return [load_template(t, args.overrides) for t in sorted(TEMPLATE_DIR.glob("*.toml"))]
    return [load_template(args.template, args.overrides)]


def _out_folder(args, design: Design) -> Path:
    if args.all:
        return (args.out or Path("out")) / design.name
    return args.out or Path("out") / design.name


def _prepared_folders(args, designs: list[Design]) -> list[Path]:
    """Every output folder checked (created, writable) before any CAD work starts."""
    from gearcheck.output import ensure_out_dir

    return [ensure_out_dir(_out_folder(args, d)) for d in designs]


def _check_one(design: Design, folder: Path, tol_mm: float | None, jobs: int | None) -> bool:
    from gearcheck import pipeline

    print(f"building {design.name} ({design.mechanism}) ...", file=sys.stderr)
    run = pipeline.check(design, folder, tol_mm=tol_mm, jobs=jobs, progress=_bars)
    print(f"wrote {folder}/ : {len(run.build.parts)} parts, {run.build.manifest['step']['file']}, manifest.json")
    _print_verdicts(design, folder, run.result)
    return run.passed


def cmd_check(args) -> int:
    designs = _templates_or_one(args)
    folders = _prepared_folders(args, designs)
    passed = [_check_one(d, folder, args.tol, args.jobs) for d, folder in zip(designs, folders, strict=True)]
    return 0 if all(passed) else 1


def _build_task(_state: Any, design: Design, folder: Path, tol_mm: float | None) -> tuple[int, str]:
    """One template's build (module-level: --all --jobs N builds templates in worker processes)."""
    from gearcheck import pipeline

    run = pipeline.build(design, folder, tol_mm=tol_mm)
    return len(run.parts), run.manifest["step"]["file"]


def cmd_build(args) -> int:
    from gearcheck.executor import make_executor

    designs = _templates_or_one(args)
    folders = _prepared_folders(args, designs)
    executor = make_executor(args.jobs)
    if executor.jobs > 1 and len(designs) > 1:
        tasks = [(d, f, args.tol) for d, f in zip(designs, folders, strict=True)]
        with _bars("building", len(tasks), "template") as bar:
            built = executor.map(_build_task, tasks, progress=bar.update)
    else:
        built = []
        for d, f in zip(designs, folders, strict=True):
            print(f"building {d.name} ({d.mechanism}) ...", file=sys.stderr)
            built.append(_build_task(None, d, f, args.tol))
    for (n_parts, step), folder in zip(built, folders, strict=True):
        print(f"wrote {folder}/ : {n_parts} parts, {step}, manifest.json")
    return 0


def cmd_demo(args) -> int:
    """Every template: the analytical figures (calc.json, calc.txt), then `check` (CAD, sweep,
    report) unless --no-cad. Exit 1 if any verdict fails, after every template has run."""
    from gearcheck.design import load_template
    from gearcheck.figures import render_table
    from gearcheck.output import atomic_write_text, ensure_out_dir

    templates = sorted(args.templates.glob("*.toml"))
    if not templates:
        raise ParamError("--templates", str(args.templates), "no *.toml templates found there")
    designs = [load_template(path) for path in templates]  # validate every template first
    folders = [ensure_out_dir(args.out / d.name) for d in designs]
    passed = []
    for design, folder in zip(designs, folders, strict=True):
        calc = design.calc()
        atomic_write_text(folder / "calc.json", json.dumps(calc.to_dict(), indent=2, allow_nan=False) + "\n")
        table = render_table(f"{design.name} ({design.mechanism}) — analytical model", calc.figures)
        atomic_write_text(folder / "calc.txt", table + "\n")
        print(table)
        print()
        if not args.no_cad:
            passed.append(_check_one(design, folder, None, args.jobs))
            print()
    print(f"wrote {len(designs)} result folders under {args.out}/ (open NAME/report.html)")
    return 0 if all(passed) else 1


COMMANDS = {"calc": cmd_calc, "build": cmd_build, "check": cmd_check, "demo": cmd_demo}


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="gearcheck: %(message)s", stream=sys.stderr)
    try:
        return COMMANDS[args.command](args)
    except ParamError as exc:
        print(f"gearcheck: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
