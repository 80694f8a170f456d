"""Command line: parse, call the pipeline, print. Exit codes: 0 ok, 1 a verdict failed, 2 bad
input (or an output that cannot be written), 130 / 143 interrupted by SIGINT / SIGTERM.

The only module that prints. Everything it runs is the library's (:mod:`gearcheck.design`,
:mod:`gearcheck.pipeline`); what it shows is made by :mod:`gearcheck.terminal` (tables and
coloured verdicts on a terminal, plain lines when piped, the JSON of ``--json``); progress bars go
to stderr when it is a terminal, diagnostics to the ``gearcheck`` logger (``-v`` shows them).

Interrupts: SIGINT and SIGTERM are caught from the first lines of this module on (its imports are
the standard library's only; the rest is imported inside :func:`main`), so an interrupt at any
moment unwinds through the run's transaction — its staging folder removed, the output folder as
it was, worker processes stopped — and ends in one line and exit 130 / 143.
"""

from __future__ import annotations

import signal
import sys


class Interrupted(BaseException):
    """SIGINT or SIGTERM arrived: unwind (transactions clean up), then exit 128 + signal."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


_received: list[int] = []


def _on_signal(signum: int, _frame: object) -> None:
    if _received:  # already unwinding: let the cleanup finish
        return
    _received.append(signum)
    raise Interrupted(signum)


if "--multiprocessing-fork" not in sys.argv:  # not in a sweep worker (its executor sets its own)
    signal.signal(signal.SIGINT, _on_signal)
    signal.signal(signal.SIGTERM, _on_signal)

import argparse  # noqa: E402  (after the handlers: an interrupt during start-up is one line too)
import contextlib  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import os  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import TYPE_CHECKING, Any  # noqa: E402

from gearcheck import __version__  # noqa: E402

if TYPE_CHECKING:
    from gearcheck.design import Design
    from gearcheck.pipeline import Bar, CheckRun
    from gearcheck.terminal import Checked, Screen

class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # usage errors are bad input: exit 2, one line
        self.exit(2, f"gearcheck: error: {message}\n")


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


def _add_open_arg(p: argparse.ArgumentParser, what: str) -> None:
    p.add_argument("--open", action="store_true", help=f"open {what} in the web browser when done")


def _add_cad_args(p: argparse.ArgumentParser, verb: str) -> None:
    """TEMPLATE | --all, --set, --out, --tol, --jobs, --json, --open: shared by `build` and `check`."""
    from gearcheck.terminal import TOL_HELP

    p.add_argument("template", type=Path, nargs="?", help="TOML parameter file (omit with --all)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one template value (repeatable)")
    p.add_argument("--all", action="store_true",
                   help=f"{verb} every template into OUT/NAME (those in --templates, else ./templates/, "
                        "else the ones shipped with gearcheck)")
    p.add_argument("--templates", type=Path, default=None, metavar="DIR",
                   help="folder of templates for --all (default: ./templates/ if it holds any, else the shipped ones)")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default out/NAME; with --all, the parent folder, default out)")
    p.add_argument("--tol", type=float, default=None, metavar="MM", help=TOL_HELP)
    _add_jobs_arg(p, "the sweep" if verb == "check" else "building several templates (--all)")
    p.add_argument("--no-cache", action="store_true", help="build the solids and meshes anew, neither reading nor "
                   "writing the CAD cache ($GEARCHECK_CACHE, default ~/.cache/gearcheck; GEARCHECK_CACHE=off: always)")
    what = ("the verdicts, the key figures (paper / model / geometry, exact confirmation)" if verb == "check"
            else "the parts (material, triangles, volume)")
    p.add_argument("--json", action="store_true",
                   help=f"print one JSON object on stdout and nothing else: mechanism, name, folder, {what}, the "
                        "mesh, and every file written with its size (with --all: {\"runs\": [...]})")
    _add_open_arg(p, "report.html" if verb == "check" else "the output folder")


def build_parser() -> argparse.ArgumentParser:
    from gearcheck.mechanism import names
    from gearcheck.terminal import BUILD_EXAMPLES, CHECK_EXAMPLES, DESCRIPTION, HelpFormatter as _Formatter

    parser = _Parser(prog="gearcheck", description=DESCRIPTION.format(mechanisms=", ".join(names())),
                     formatter_class=_Formatter)
    parser.add_argument("--version", action="version", version=f"gearcheck {__version__}")
    parser.add_argument("--verbose", "-v", action="store_true", help="print diagnostics (timings, workers) to stderr")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    calc = sub.add_parser(
        "calc", formatter_class=_Formatter,
        help="the paper's analytical model: design figures beside the paper's numbers",
        description="Compute the mechanism's design figures from its template with the paper's "
        "analytical model (reconstructed where the paper lost equations), and print them beside "
        "the paper's printed values with the difference and the reason where they differ.",
        epilog="Examples:\n  gearcheck calc templates/zhurong_differential.toml --set operating.cold_C=-130\n"
               "  gearcheck calc templates/eod_track_drive.toml --json | jq .track.paper\n"
               "  gearcheck calc templates/nose_wheel_steering.toml | less -S",
    )
    _add_template_args(calc)
    calc.add_argument("--json", action="store_true",
                      help="print one JSON object (nested by section) instead of a table")

    build = sub.add_parser(
        "build", formatter_class=_Formatter, epilog=BUILD_EXAMPLES,
        help="build the CAD: STEP assembly, one STL per part, manifest.json",
        description="Build the mechanism's parts with CadQuery from the template (exact involute "
        "flanks), mesh each part with an absolute chordal tolerance, and write DIR/NAME.step "
        "(named, placed parts), DIR/PART.stl, DIR/params.toml (the resolved parameters) and "
        "DIR/manifest.json (materials, volumes, triangle counts, measured mesh error, file hashes). "
        "Every file is written atomically.",
    )
    _add_cad_args(build, "build")

    check = sub.add_parser(
        "check", formatter_class=_Formatter, epilog=CHECK_EXAMPLES,
        help="build, mesh and sweep the mechanism; write report.html, summary.json, sweep.csv",
        description="Build the CAD (as `build`), sweep the assembly through its motion with "
        "python-fcl on the meshes (warm and cold for the differential, a full engagement cycle "
        "for the track drive, towing and power modes for the steering), confirm each sweep's "
        "worst pose on the exact B-rep, and write DIR/report.html (verdicts, paper vs model vs "
        "geometry, plots), DIR/summary.json (numbers) and DIR/sweep.csv (one row per pose) beside "
        "the CAD. Each verdict is pass, warn or fail and names the evidence that decided it (exact "
        "model, mesh sweep, exact B-rep). Exit 0 when no verdict fails (warnings included), 1 when "
        "one fails, 2 on input no design can meet.",
    )
    _add_cad_args(check, "check")

    demo = sub.add_parser("demo", formatter_class=_Formatter,
                          help="every template in templates/: figures and CAD under --out (what `make demo` runs)",
                          description="Check every template into OUT/NAME: the verdicts of each, and a pointer "
                          "to its analytical figures (OUT/NAME/calc.txt and calc.json, as `gearcheck calc` prints "
                          "them). Exit 1 if a verdict fails, after every template has run.",
                          epilog="Examples:\n  gearcheck demo --open\n  gearcheck demo --no-cad --out /tmp/figures")
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: out)")
    demo.add_argument("--templates", type=Path, default=None, metavar="DIR",
                      help="folder of templates (default: ./templates/ if it holds any, else the shipped ones)")
    demo.add_argument("--no-cad", action="store_true", help="analytical figures only, no CAD build")
    _add_jobs_arg(demo, "the sweeps")
    _add_open_arg(demo, "each report (the output folder with --no-cad)")

    study = sub.add_parser(
        "study", formatter_class=_Formatter,
        help="Monte Carlo over tolerances, temperature and wear: probabilities of failure, sensitivities",
        description="Run a study file: draw variants of its template from the distributions it declares "
        "(seeded Sobol/LHS sequence, reproducible row for row), evaluate every variant on the analytical "
        "model and the exact model (numpy, no mesh), re-check the worst with the full pipeline (CAD, "
        "meshes, sweep, exact B-rep), and write DIR/results.parquet (one row per variant), DIR/summary.json "
        "(distributions, each failure's probability with a 95 % Wilson interval, sensitivities) and "
        "DIR/report.html — one transaction, like `check`. Shipped studies: `gearcheck templates` lists them; "
        "pass a file name or its stem.",
        epilog="Examples:\n  gearcheck study differential_tolerances --samples 256"
        "\n  gearcheck study my_study.toml --scheduler tcp://10.0.0.5:8786\n  gearcheck study track_wear "
        "--scheduler local-cluster --jobs 2",
    )
    study.add_argument("study", type=str, help="study file (TOML), or the name of a shipped study")
    study.add_argument("--samples", type=_jobs, default=None, metavar="N", help="variants (default: the study's)")
    study.add_argument("--seed", type=int, default=None, metavar="S", help="sequence seed (default: the study's)")
    study.add_argument("--exact", type=int, default=None, metavar="N",
                       help="variants evaluated on the exact model (default: the study's; -1 every variant)")
    study.add_argument("--check-worst", type=int, default=None, metavar="K",
                       help="worst variants re-checked on real geometry (default: the study's)")
    study.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="run on a Dask cluster: tcp://HOST:PORT of an existing scheduler (its workers must "
                            "have gearcheck installed), or local-cluster to start one here with --jobs workers "
                            "(default: local processes, no set-up)")
    study.add_argument("--out", type=Path, default=None, help="output folder (default out/study_NAME)")
    _add_jobs_arg(study, "the variants")

    templates = sub.add_parser("templates", formatter_class=_Formatter,
                               help="list the templates shipped with gearcheck, or copy them to a folder",
                               description="List the templates shipped with gearcheck (file, mechanism, what it "
                               "models), or copy them into DIR to edit, with the JSON Schemas their first lines "
                               "point to (DIR/schema/): `gearcheck templates --copy my_designs`.")
    templates.add_argument("--copy", type=Path, default=None, metavar="DIR",
                           help="copy the shipped templates (and their schemas) into DIR (created; an existing "
                                "different file is not overwritten)")

    schema = sub.add_parser(
        "schema", formatter_class=_Formatter,
        help="print the JSON Schema of a mechanism's template (completion and checks in TOML editors)",
        description="Print the JSON Schema (draft 2020-12) of a mechanism's template, made from the model that "
        "validates it: every section and key with its description, unit and allowed range, unknown keys "
        "refused. TOML editors (taplo, VS Code's Even Better TOML) use it through a first line "
        "`#:schema ./schema/MECHANISM.json`, as the shipped templates have (`gearcheck templates --copy DIR` "
        "copies the schemas too). Rules across fields (e.g. an odd tooth count, ISO 606 limits) are checked "
        "when the template is loaded.",
        epilog="Examples:\n  gearcheck schema track > track.schema.json\n"
               "  gearcheck schema templates/zhurong_differential.toml   (the schema of the template's mechanism)\n"
               "  taplo check templates/eod_track_drive.toml   (an editor's checks, from the #:schema line)",
    )
    schema.add_argument("mechanism", metavar="MECHANISM",
                        help=f"a mechanism ({', '.join(names())}) or a template file naming one")
    return parser


# ------------------------------------------------------------------------------------------
# Progress and printing


class _Plain:
    """Progress where stderr is not a terminal: no bars, one line when a template starts."""

    def __enter__(self) -> _Plain:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def wait(self, desc: str) -> None:
        print(f"{desc} ...", file=sys.stderr)

    def __call__(self, desc: str, total: int | None = None, unit: str = "") -> contextlib.AbstractContextManager[Bar]:
        from gearcheck.pipeline import no_progress

        return no_progress(desc, total, unit)


def _display() -> Any:
    """Progress bars on stderr when it is a terminal, else nothing but a line per template."""
    from gearcheck.terminal import Bars

    return Bars() if sys.stderr.isatty() else _Plain()


class _StderrHandler(logging.StreamHandler):
    """Logs to whatever sys.stderr is now (above the progress bars while they show)."""

    @property
    def stream(self) -> Any:
        return sys.stderr

    @stream.setter
    def stream(self, _value: Any) -> None:
        pass


def _screen() -> Screen:
    from gearcheck.terminal import Screen

    return Screen.of(sys.stdout)


def _show(*renderables: Any) -> None:
    from gearcheck.terminal import text

    print(text(_screen(), *renderables))


def _open(path: Path) -> None:
    """Open a report or a folder in the web browser (a line on stderr if none opens)."""
    import webbrowser

    uri = path.absolute().as_uri()
    if not webbrowser.open(uri):
        print(f"gearcheck: no web browser opened {uri}", file=sys.stderr)


# ------------------------------------------------------------------------------------------
# Commands


def cmd_calc(args) -> int:
    from gearcheck.design import load_template
    from gearcheck.terminal import calc_view

    design = load_template(args.template, args.overrides)
    calc = design.calc()
    if args.json:
        print(json.dumps(calc.to_dict(), indent=2, allow_nan=False))
    else:
        _show(*calc_view(f"{design.name} ({design.mechanism}) — analytical model", calc.figures, _screen()))
    return 0


def _templates_or_one(args) -> list[Design]:
    """The validated templates a build/check acts on: one, or --all (all validated first)."""
    from gearcheck.design import find_templates, load_template
    from gearcheck.params import ParamError
    from gearcheck.pipeline import check_tol

    check_tol(args.tol)
    if args.no_cache:  # read by this process and inherited by the workers it spawns
        os.environ["GEARCHECK_CACHE"] = "off"
    if args.all == (args.template is not None):
        raise ParamError(args.command, str(args.template), "give one TEMPLATE or --all, not both or neither")
    if not args.all:
        return [load_template(args.template, args.overrides)]
    _, paths = find_templates(args.templates)
    designs = [load_template(t, args.overrides) for t in paths]
    names = [d.name for d in designs]
    if len(set(names)) != len(names):
        raise ParamError("--set", " ".join(args.overrides) or "name", "allowed only when every template keeps "
                         f"its own result name (--all would write {len(names)} runs into {sorted(set(names))})")
    return designs


def _out_folder(args, design: Design) -> Path:
    return (args.out or Path("out")) / design.name if args.all else args.out or Path("out") / design.name


def _prepared_folders(args, designs: list[Design]) -> list[Path]:
    """Every output folder's name and parent checked (the parent created, writable) before any
    CAD work starts; each folder itself is written as one transaction later."""
    from gearcheck.output import check_out_target

    folders = [_out_folder(args, d) for d in designs]
    for folder in folders:
        check_out_target(folder)
    return folders


def _check_one(design: Design, folder: Path, tol_mm: float | None, jobs: int | None,
               overrides: list[str] | tuple = (), extra_files: dict | None = None) -> CheckRun:
    from gearcheck import pipeline

    with _display() as bars:
        bars.wait(f"building {design.name} ({design.mechanism})")
        return pipeline.check(design, folder, tol_mm=tol_mm, jobs=jobs, progress=bars, overrides=overrides,
                              extra_files=extra_files)


def _show_check(run: CheckRun | Checked, *extra: str) -> None:
    """The verdicts first, then any pointer lines, then what was written."""
    from gearcheck.terminal import Checked, files_line, verdicts_view

    c = run if isinstance(run, Checked) else Checked.of(run)
    _show(*verdicts_view(c.result, c.name, c.folder, _screen()), *extra, files_line(c.folder, c.files, c.parts))


def _print_json(objects: list[dict], every: bool) -> None:
    """One JSON object on stdout: the run's, or {"runs": [...]} for --all."""
    print(json.dumps({"runs": objects} if every else objects[0], indent=2, allow_nan=False))


def _side_by_side(executor: Any, designs: list[Design], fn: Any, args_of: Any, verb: str) -> list:
    """``fn(None, *args_of(i))`` for every template, side by side (one's single-core stages overlap
    another's), in template order. The finest default mesh (the longest run) last in line: this
    process takes it at once, with every core for its sweep; the spawned workers the others."""
    order = sorted(range(len(designs)), key=lambda i: -float(designs[i].impl.mesh_tol_mm))
    with _display() as bars, bars(verb, len(order), "template") as bar:
        done = executor.map(fn, [args_of(i) for i in order], progress=bar.update)
    return [r for _, r in sorted(zip(order, done, strict=True), key=lambda x: x[0])]


def cmd_check(args) -> int:
    from gearcheck.executor import make_executor
    from gearcheck.terminal import Checked, check_task

    designs = _templates_or_one(args)
    folders = _prepared_folders(args, designs)
    executor = make_executor(args.jobs)
    if executor.jobs > 1 and len(designs) > 1:
        runs = _side_by_side(executor, designs, check_task,
                             lambda i: (designs[i], folders[i], args.tol, args.overrides, args.jobs), "checking")
    else:
        runs = [Checked.of(_check_one(d, f, args.tol, args.jobs, args.overrides))
                for d, f in zip(designs, folders, strict=True)]
    for run in runs if not args.json else []:
        _show_check(run)
    if args.json:
        _print_json([r.json for r in runs], args.all)
    for run in runs if args.open else []:
        _open(run.folder / "report.html")
    return 0 if all(r.json["passed"] for r in runs) else 1


def _build_task(_state: Any, design: Design, folder: Path, tol_mm: float | None,
                overrides: list[str], progress: Any = None) -> dict:
    """One template's build, as build --json shows it (module-level: --all --jobs N builds
    templates in worker processes)."""
    from gearcheck import pipeline
    from gearcheck.terminal import build_json

    run = pipeline.build(design, folder, tol_mm=tol_mm, overrides=overrides,
                         progress=progress or pipeline.no_progress)
    return build_json(run)


def cmd_build(args) -> int:
    from gearcheck.executor import make_executor
    from gearcheck.terminal import files_line

    designs = _templates_or_one(args)
    folders = _prepared_folders(args, designs)
    executor = make_executor(args.jobs)
    if executor.jobs > 1 and len(designs) > 1:
        built = _side_by_side(executor, designs, _build_task,
                              lambda i: (designs[i], folders[i], args.tol, args.overrides), "building")
    else:
        built = []
        for d, f in zip(designs, folders, strict=True):
            with _display() as bars:
                bars.wait(f"building {d.name} ({d.mechanism})")
                built.append(_build_task(None, d, f, args.tol, args.overrides, bars))
    if args.json:
        _print_json(built, args.all)
    for b, folder in zip(built, folders, strict=True) if not args.json else []:
        _show(files_line(folder, [Path(b["folder"]) / f["file"] for f in b["files"]], len(b["parts"])))
    for b in built if args.open else []:
        _open(Path(b["folder"]))
    return 0


def cmd_demo(args) -> int:
    """Every template: the analytical figures (calc.json, calc.txt), then `check` (CAD, sweep,
    report) unless --no-cad; the verdicts of each, and a pointer to its figures. Exit 1 if any
    verdict fails, after every template has run."""
    from gearcheck import pipeline
    from gearcheck.design import find_templates, load_template
    from gearcheck.figures import render_table
    from gearcheck.output import check_out_target, ensure_out_dir
    from gearcheck.terminal import calc_pointer

    _, templates = find_templates(args.templates)
    designs = [load_template(path) for path in templates]  # validate every template first
    ensure_out_dir(args.out)
    folders = [args.out / d.name for d in designs]
    for folder in folders:
        check_out_target(folder)
    passed = []
    for design, folder in zip(designs, folders, strict=True):
        calc = design.calc()
        table = render_table(f"{design.name} ({design.mechanism}) — analytical model", calc.figures)
        files = {"calc.json": json.dumps(calc.to_dict(), indent=2, allow_nan=False) + "\n", "calc.txt": table + "\n"}
        pointer = calc_pointer(calc.figures, folder / "calc.txt")
        if args.no_cad:
            pipeline.write_files(design, folder, files)
            _show(f"{design.name} ({design.mechanism}): {pointer}")
        else:
            run = _check_one(design, folder, None, args.jobs, extra_files=files)
            passed.append(run.passed)
            _show_check(run, f"  calc: {pointer}")
            print()
    print(f"wrote {len(designs)} result folders under {args.out}/ (open NAME/report.html)")
    if args.open:
        for folder in ([args.out] if args.no_cad else [f / "report.html" for f in folders]):
            _open(folder)
    return 0 if all(passed) else 1


def cmd_templates(args) -> int:
    """List the shipped templates, or copy them (and the schemas they point to) into --copy DIR."""
    import shutil

    from gearcheck.design import load_template, packaged_templates
    from gearcheck.output import OutputError, ensure_out_dir
    from gearcheck.schema import SCHEMA_FOLDER

    shipped = sorted(packaged_templates().glob("*.toml"))
    schemas = sorted((packaged_templates() / SCHEMA_FOLDER).glob("*.json"))
    if args.copy is None:
        for path in shipped:
            design = load_template(path)
            print(f"{path.name:32s} {design.mechanism:13s} {design.impl.title}")
        print(f"({len(shipped)} templates in {packaged_templates()}; copy them with --copy DIR; "
              f"their JSON Schemas: gearcheck schema MECHANISM)")
        from gearcheck.studies.spec import load_spec, packaged_studies

        studies = sorted(packaged_studies().glob("*.toml"))
        for path in studies:
            spec = load_spec(path)
            print(f"{path.stem:32s} {'study':13s} {spec.title} (template {spec.template})")
        print(f"({len(studies)} studies; run one with `gearcheck study NAME`)")
        return 0
    folder = ensure_out_dir(args.copy)
    copies = [(p, folder / p.name) for p in shipped] + [(p, folder / SCHEMA_FOLDER / p.name) for p in schemas]
    for path, target in copies:
        if target.exists() and target.read_bytes() != path.read_bytes():
            raise OutputError(target, "exists and differs from the shipped file (not overwritten)")
    for path, target in copies:
        target.parent.mkdir(exist_ok=True)
        shutil.copyfile(path, target)
    print(f"copied {len(shipped)} templates to {folder}/ (their schemas to {folder / SCHEMA_FOLDER}/)")
    return 0


def cmd_schema(args) -> int:
    """The JSON Schema of a mechanism's template (by name, or of a template file's mechanism)."""
    from gearcheck.mechanism import names
    from gearcheck.params import ParamError
    from gearcheck.params.common import read_toml
    from gearcheck.schema import schema_text

    name = args.mechanism
    if name not in names() and name.endswith(".toml"):
        name = read_toml(Path(name)).get("mechanism")
    if name not in names():
        raise ParamError("MECHANISM", args.mechanism, f"allowed one of: {', '.join(names())}, or a template file")
    sys.stdout.write(schema_text(name))
    return 0


def cmd_study(args) -> int:
    """A study: headline figures on stdout, the files in --out."""
    from gearcheck.studies.core import study
    from gearcheck.studies.spec import find_study

    path = find_study(args.study)
    out = args.out if args.out is not None else Path("out") / f"study_{path.stem}"
    with _display() as bars:
        result = study(path, samples=args.samples, seed=args.seed, jobs=args.jobs, scheduler=args.scheduler,
                       out=out, exact=args.exact, check_worst=args.check_worst, progress=bars)
    s = result.summary
    print(f"{s['study']}: {s['valid']} valid variants of {s['samples']} ({s['rejected']} rejected), "
          f"exact model on {s['exact_variants']}")
    for name, f in s["failures"].items():
        print(f"  P({name}) = {100 * f['probability']:.3g} % [{100 * f['ci95_low']:.3g}, {100 * f['ci95_high']:.3g}] "
              f"({f['failures']}/{f['variants']}): {f['label']}")
    for target, sens in s["sensitivity"].items():
        top = ", ".join(f"{k} ({sens['srrc'][k]:+.2f})" for k in sens["ranking"][:3])
        print(f"  {target}: most sensitive to {top}")
    for c in s["checks"]:
        print(f"  variant {c['variant']}: check {c['level'].upper()}" + (f" — {c['failed'][0]}" if c["failed"] else ""))
    print(f"wrote {result.folder}/ (report.html, summary.json, results.parquet)")
    return 0


COMMANDS = {"calc": cmd_calc, "study": cmd_study, "build": cmd_build, "check": cmd_check, "demo": cmd_demo,
            "templates": cmd_templates, "schema": cmd_schema}


def _error(text: str) -> int:
    print(f"gearcheck: error: {text}", file=sys.stderr)
    return 2


def _interrupted(signum: int) -> int:
    """One line, exit 128 + signal: what the run folder holds now."""
    from gearcheck.output import RunFolder

    where = RunFolder.abandoned
    what = f"{where} unchanged" if where else "nothing written"
    with contextlib.suppress(OSError):
        sys.stderr.write(f"gearcheck: interrupted ({signal.Signals(signum).name}): {what}\n")
        sys.stderr.flush()
    return 128 + signum


def _quiet_stdout() -> None:
    """After a failed write to stdout: point it at /dev/null, so the interpreter's last flush
    does not fail again with a second message."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except Interrupted as exc:
        return _interrupted(exc.signum)
    except BaseException:
        if _received:  # an interrupt surfaced as another error (e.g. inside an extension's import)
            return _interrupted(_received[0])
        raise


def _main(argv: list[str] | None) -> int:
    for stream in (sys.stdout, sys.stderr):  # a terminal that cannot show "α" gets "\u03b1", not a crash
        with contextlib.suppress(AttributeError, ValueError):
            stream.reconfigure(errors="backslashreplace")  # type: ignore[union-attr]
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, handlers=[_StderrHandler()],
                        format="gearcheck: %(message)s")
    from gearcheck.output import output_error
    from gearcheck.params import ParamError

    try:
        code = COMMANDS[args.command](args)
        sys.stdout.flush()
        return code
    except ParamError as exc:
        return _error(str(exc))
    except OSError as exc:  # an output nobody could write: stdout closed or full, a path too long
        if exc.filename is None:  # no file named: the write that failed was to stdout
            _quiet_stdout()
            return _error(str(output_error(exc, "<stdout>")))
        return _error(str(output_error(exc, verb="access")))


if __name__ == "__main__":
    raise SystemExit(main())
