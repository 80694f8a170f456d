"""Command line: parse, call the pipeline, print. Exit codes: 0 ok, 1 a verdict failed, 2 bad
input (or an output that cannot be written), 3 an internal error (a worker process died, a bug:
one line, the traceback under ``-v``), 130 / 143 interrupted by SIGINT / SIGTERM.

The only module that prints. Everything it runs is the library's (:mod:`gearcheck.design`,
:mod:`gearcheck.pipeline`); what it shows is made by :mod:`gearcheck.terminal` (tables and
coloured verdicts on a terminal, plain lines when piped, the JSON of ``--json``); progress bars go
to stderr when it is a terminal, diagnostics to the ``gearcheck`` logger (``-v`` shows them).

Interrupts: SIGINT and SIGTERM are caught from the first lines of this module on (its imports are
the standard library's only; the rest is imported inside :func:`main`). A command that writes
declares its outputs first (:data:`gearcheck.interrupts.outputs`); each is committed by one
rename, signals deferred across it and the commit recorded before they are delivered. Before
the last output is committed, an interrupt unwinds through the run's transaction (staging folder
removed, workers stopped) and ends in one line and exit 130 / 143: ``interrupted (SIGINT):
nothing written, out/x keeps its previous run`` (with ``--all``, the outputs already written
named in the same line). Once every output is committed, the result stands: the normal outcome
and exit code, and one line more: ``interrupted (SIGINT) after out/x was written: it is
complete``. Once the command has ended, signals are ignored while the interpreter exits.
"""

from __future__ import annotations

import signal
import sys


class Interrupted(BaseException):
    """SIGINT or SIGTERM arrived: unwind (transactions clean up), then exit 128 + signal."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


_received: list[int] = []  # the interrupt that unwinds the command (or came once it had ended)
_after: list[int] = []  # an interrupt that came once every output was committed: the result stands
_said: list[bool] = []  # the line for _after is written
_ended: list[bool] = []  # the command has returned (or raised): an interrupt is only recorded
_decided: list[int] = []  # the exit code the verdicts decided, before they are printed (a closed pipe keeps it)
_in_main: list[bool] = []  # main() is running: an interrupt unwinds through its cleanup


def _outputs() -> Any:
    """The running command's outputs (:data:`gearcheck.interrupts.outputs`), None before that
    module is loaded (nothing written yet). Imports nothing."""
    return getattr(sys.modules.get("gearcheck.interrupts"), "outputs", None)


def _result_stands() -> bool:
    outputs = _outputs()
    return outputs is not None and bool(outputs.complete())


def _on_signal(signum: int, _frame: object) -> None:
    if _received or _after:  # already unwinding (let the cleanup finish), or already recorded
        return
    if _result_stands():  # every output committed: the command goes on to its end, main() says so
        _after.append(signum)
        return
    _received.append(signum)
    if _ended:  # the command has ended: its exit code stands
        return
    if not _in_main:  # before main() runs (this module still importing, the console script's own lines)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        try:  # the standard library's signal and sys only: nothing else is imported yet
            sys.stderr.write(f"gearcheck: interrupted ({signal.Signals(signum).name}): nothing written\n")
            sys.stderr.flush()
        except OSError:
            pass
        raise SystemExit(128 + signum)
    raise Interrupted(signum)


# Not in a spawned worker process: it re-imports the script that started its parent (this one, as
# the console script) with the parent's sys.argv, and its executor sets handlers of its own; its
# own command line (sys.orig_argv) says what it is.
if "--multiprocessing-fork" not in sys.orig_argv:
    signal.signal(signal.SIGINT, _on_signal)
    signal.signal(signal.SIGTERM, _on_signal)


def _at_exit() -> None:
    """The interpreter's last Python step (registered first, run last): SIGINT and SIGTERM
    ignored from here on — Python takes its handlers down next, and a signal then would kill the
    process with no line and another exit code — and the line of an interrupt that came once the
    command's outputs were committed, if main() could not write it yet."""
    if signal.getsignal(signal.SIGINT) is _on_signal:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        if _after:
            _say_after()


if "--multiprocessing-fork" not in sys.orig_argv:
    import atexit

    atexit.register(_at_exit)

try:  # after the handlers: an interrupt during start-up is one line too
    import contextlib
    import json
    import logging
    import os
    from pathlib import Path
    from typing import TYPE_CHECKING, Any

except BaseException:
    # the handler has written the line and raised SystemExit; an import may hand it on wrapped
    # (a class body's __set_name__ turns it into a RuntimeError: ipaddress, under pathlib)
    if not _received:
        raise
    raise SystemExit(128 + _received[0]) from None

if TYPE_CHECKING:
    from gearcheck.design import Design
    from gearcheck.pipeline import CheckRun
    from gearcheck.terminal import Checked, Screen

# ------------------------------------------------------------------------------------------
# Progress and printing


def _display(tenths: bool = False, patient: bool = False) -> Any:
    """The progress display on stderr (``patient``: piped, a stage's lines wait a few seconds)."""
    from gearcheck.terminal import PIPED_PATIENCE_S, display

    return display(tenths, PIPED_PATIENCE_S if patient else 0.0)


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
        import dataclasses

        from gearcheck.terminal import CALC_WIDTH

        screen = _screen()
        if screen.width is None:  # piped: the table fits CALC_WIDTH columns (notes wrap or go under)
            screen = dataclasses.replace(screen, width=CALC_WIDTH)
        _show(*calc_view(f"{design.name} ({design.mechanism}) — analytical model", calc.figures, screen))
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
        given = "(none)" if args.template is None else f"{args.template} with --all"
        raise ParamError("TEMPLATE", given, f"allowed one TEMPLATE or --all for {args.command}, not both or neither")
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
    CAD work starts, and declared as the command's outputs; each folder itself is written as
    one transaction later."""
    from gearcheck.output import check_out_target

    folders = [_out_folder(args, d) for d in designs]
    for folder in folders:
        check_out_target(folder)
    _declare(folders)
    return folders


def _declare(paths: list[Path], noun: str = "run") -> None:
    """The command writes ``paths`` (run folders, or files for another ``noun``): what an
    interrupt's line names, and when the command's result stands (every one committed)."""
    from gearcheck.interrupts import outputs
    from gearcheck.output import RUN_MARKER

    outputs.expect(paths, noun, RUN_MARKER if noun == "run" else None)


def _check_one(design: Design, folder: Path, tol_mm: float | None, jobs: int | None,
               overrides: list[str] | tuple = (), extra_files: dict | None = None,
               budget_cpu_s: float | None = None) -> CheckRun:
    from gearcheck import pipeline

    with _display(tenths=True, patient=True) as bars:  # piped: never quiet for long
        bars.wait(f"building {design.name} ({design.mechanism})")
        return pipeline.check(design, folder, tol_mm=tol_mm, jobs=jobs, progress=bars, overrides=overrides,
                              extra_files=extra_files, budget_cpu_s=budget_cpu_s)


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
    from gearcheck.interrupts import outputs
    from gearcheck.output import remove_leftovers

    outputs.elsewhere = True  # the workers commit theirs: the file system says which are written
    order = sorted(range(len(designs)), key=lambda i: -float(designs[i].impl.mesh_tol_mm))
    tasks = [args_of(i) for i in order]
    try:
        with _display() as bars, bars(verb, len(order), "template") as bar:
            done = executor.map(fn, tasks, progress=bar.update)
    except BaseException:  # the workers were stopped without a chance to clean up: their staging folders
        for task in tasks:
            remove_leftovers(task[1])
        raise
    return [r for _, r in sorted(zip(order, done, strict=True), key=lambda x: x[0])]


def cmd_check(args) -> int:
    from gearcheck.executor import make_executor
    from gearcheck.terminal import Checked, check_task

    designs = _templates_or_one(args)
    folders = _prepared_folders(args, designs)
    executor = make_executor(args.jobs)
    if executor.jobs > 1 and len(designs) > 1:
        runs = _side_by_side(executor, designs, check_task,
                             lambda i: (designs[i], folders[i], args.tol, args.overrides, args.jobs, args.budget),
                             "checking")
    else:
        runs = [Checked.of(_check_one(d, f, args.tol, args.jobs, args.overrides, budget_cpu_s=args.budget))
                for d, f in zip(designs, folders, strict=True)]
    code = 0 if all(r.json["passed"] for r in runs) else 1
    _decided.append(code)
    for run in runs if not args.json else []:
        _show_check(run)
    if args.json:
        _print_json([r.json for r in runs], args.all)
    for run in runs if args.open else []:
        _open(run.folder / "report.html")
    return code


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
            with _display(tenths=True, patient=True) as bars:
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
    _declare(folders)
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
    from gearcheck import shipped

    for line in shipped.listing() if args.copy is None else [shipped.copy_to(args.copy)]:
        print(line)
    return 0


def cmd_schema(args) -> int:
    """The JSON Schema of a mechanism's template (by name, or of a template file's mechanism)."""
    from gearcheck.schema import schema_of

    sys.stdout.write(schema_of(args.mechanism))
    return 0


def cmd_new(args) -> int:
    """Write a complete template from the numbers that define a design (gearcheck.new)."""
    from gearcheck.drafting import default_name, draft
    from gearcheck.new_template import new

    inputs = {"module": args.module, "teeth": args.teeth, "chain": args.chain, "strands": args.strands,
              "step": args.step}
    if args.out is not None and str(args.out) == "-":
        from gearcheck.design import from_data

        result = draft(args.mechanism, args.overrides, **inputs)
        if result.complete:
            from_data(result.data())
        result.relative_to(Path.cwd())
        sys.stdout.write(result.toml())
        return 0
    out = args.out if args.out is not None else Path(default_name(args.mechanism, inputs))
    _declare([out], "version")
    design = new(args.mechanism, out=out, overrides=args.overrides, force=args.force, **inputs)
    if design is None:  # a template to fill in
        from gearcheck.params import read_toml

        parts = read_toml(out).get("part", [])
        print(f"wrote {out}: {len(parts)} parts, one per product of {args.step}: "
              + ", ".join(p["name"] for p in parts[:12]) + (", …" if len(parts) > 12 else ""))
        print(f"  fill in how they move ([[joint]], [[couple]], [motion]: examples at its end), "
              f"then: gearcheck check {out}")
        return 0
    print(f"wrote {out}: {design.impl.title}")
    print(f"  every derived value is commented with how it was found; check it: gearcheck check {out}")
    return 0


def cmd_study(args) -> int:
    """A study: headline figures on stdout, the files in --out."""
    from gearcheck.studies.core import study
    from gearcheck.studies.spec import FLAGS, check_scheduler, find_study, flag_value

    given = {k: None if getattr(args, k) is None else flag_value(k, getattr(args, k)) for k in FLAGS}
    check_scheduler(args.scheduler)
    path = find_study(args.study)
    out = args.out if args.out is not None else Path("out") / f"study_{path.stem}"
    _declare([out])
    with _display(tenths=True) as bars:
        result = study(path, samples=given["samples"], seed=given["seed"], jobs=args.jobs, scheduler=args.scheduler,
                       out=out, exact=given["exact"], check_worst=given["check_worst"], progress=bars)
    s = result.summary
    print(f"{s['study']}: {s['valid']} valid variants of {s['samples']} ({s['rejected']} rejected), "
          f"exact model on {s['exact_variants']}")
    for name, f in s["failures"].items():
        if not f["variants"]:  # its output's level ran on no valid variant (--exact 0)
            print(f"  P({name}): not evaluated ({f['output']} on 0 variants): {f['label']}")
            continue
        d = f["over_drawn"]
        print(f"  P({name}) = {100 * f['probability']:.3g} % [{100 * f['ci95_low']:.3g}, {100 * f['ci95_high']:.3g}] "
              f"({f['failures']}/{f['variants']} valid variants): {f['label']}")
        if d["rejected"]:
            print(f"    over all drawn, the {d['rejected']} out of spec counted as failures: "
                  f"{100 * d['probability']:.3g} % ({d['failures']}/{d['variants']})")
    for target, sens in s["sensitivity"].items():
        if not sens["variants"]:
            continue
        top = ", ".join(f"{k} ({sens['srrc'][k]:+.2f})" for k in sens["ranking"][:3])
        print(f"  {target}: most sensitive to {top}")
    for c in s["checks"]:
        print(f"  variant {c['variant']}: check {c['level'].upper()}" + (f" — {c['failed'][0]}" if c["failed"] else ""))
    print(f"wrote {result.folder}/ (report.html, summary.json, results.parquet)")
    return 0


COMMANDS = {"calc": cmd_calc, "study": cmd_study, "build": cmd_build, "check": cmd_check, "demo": cmd_demo,
            "templates": cmd_templates, "schema": cmd_schema, "new": cmd_new}


def _one_line(exc: BaseException, limit: int = 300) -> str:
    text = " ".join(str(exc).split()) or "(no message)"
    return text if len(text) <= limit else text[: limit - 1] + "…"


def _error(text: str, code: int = 2) -> int:
    for line in text.splitlines() or [""]:  # several broken rules: one line each
        print(f"gearcheck: error: {line}", file=sys.stderr)
    return code


def _interrupted(signum: int) -> int:
    """One line, exit 128 + signal: what the outputs hold now (those committed, and that the
    rest keep what they held). Nothing is imported here: an interrupt inside an import leaves
    that module half-initialised, and importing it again can print C-level warnings of its own
    (the decimal module's libmpdec does); without the interrupts module loaded, nothing was
    declared, nothing written."""
    outputs = _outputs()
    what = outputs.unwound() if outputs is not None else "nothing written"
    _say(f"gearcheck: interrupted ({signal.Signals(signum).name}): {what}")
    return 128 + signum


def _say(line: str) -> None:
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(line + "\n")
        sys.stderr.flush()


def _say_after() -> None:
    """The line of an interrupt that came once every output was committed, once (only main()'s
    end and the exit call this, one after the other; the handler only records)."""
    outputs = _outputs()
    if _after and not _said and outputs is not None:
        _said.append(True)
        _say(f"gearcheck: interrupted ({signal.Signals(_after[0]).name}) {outputs.after()}")


def _quiet_stdout() -> None:
    """After a failed write to stdout: point it at /dev/null, so the interpreter's last flush
    does not fail again with a second message."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def _reset() -> None:
    """No command running: nothing received, nothing declared."""
    for state in (_received, _after, _said, _ended, _decided):
        state.clear()
    outputs = _outputs()
    if outputs is not None:
        outputs.clear()


def main(argv: list[str] | None = None) -> int:
    """The command line (``argv`` None: ``sys.argv``, as the console script calls it); the exit
    code. Called with ``argv`` (in a process that goes on), an interrupt after it is the
    process's own again."""
    _reset()
    _in_main.append(True)
    try:
        code = _run(argv)
    except Interrupted as exc:  # one that came in the instant _run began to handle another error
        code = _interrupted(exc.signum)
    finally:
        _in_main.pop()
    try:
        return _outcome(code)
    finally:
        if argv is not None:
            _reset()


def _run(argv: list[str] | None) -> int:
    """The command's exit code, or the interrupt's (its line written) if one unwound it."""
    try:
        code = _main(argv)
        _ended.append(True)  # from here an interrupt is only recorded
    except Interrupted as exc:
        return _interrupted(exc.signum)
    except BaseException:
        if _received:  # an interrupt surfaced as another error (e.g. inside an extension's import)
            return _interrupted(_received[0])
        _ended.append(True)  # e.g. argparse's SystemExit: on its way out, not to be cut short
        raise
    return code


def _outcome(code: int) -> int:
    """The exit code once the command has ended: its own, and the line of an interrupt that came
    once its outputs were committed (the result stands; one that comes later, while the process
    exits, gets it then); 128 + signal for one that came as a command that commits nothing
    ended (its line written now)."""
    if _after:
        _say_after()
    elif _received and _ended:
        return _interrupted(_received[0])
    return code


def _main(argv: list[str] | None) -> int:
    for stream in (sys.stdout, sys.stderr):  # a terminal that cannot show "α" gets "\u03b1", not a crash
        with contextlib.suppress(AttributeError, ValueError):
            stream.reconfigure(errors="backslashreplace")  # type: ignore[union-attr]
    from gearcheck.arguments import build_parser
    from gearcheck.terminal import StderrHandler

    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING, handlers=[StderrHandler()],
                        format="gearcheck: %(message)s")
    try:
        code = COMMANDS[args.command](args)
        sys.stdout.flush()
        return code
    except Exception as exc:  # noqa: BLE001 - every failure ends in one line (_failed)
        return _failed(exc, args.verbose)


def _unwritable(exc: OSError) -> int:
    """An output that could not be written: a file (named), or stdout (no file named). A closed
    pipe (`gearcheck calc … | head -1`: the reader stopped reading) ends quietly, as every
    command-line tool does, with the code the verdicts decided (a failed check's 1 stays 1)."""
    from gearcheck.output import output_error

    if exc.filename is not None:
        return _error(str(output_error(exc, verb="access")))
    _quiet_stdout()
    if isinstance(exc, BrokenPipeError):
        return _decided[-1] if _decided else 0
    return _error(str(output_error(exc, "<stdout>")))


def _failed(exc: Exception, verbose: bool) -> int:
    """The one line and exit code of a command that raised: 2 for bad input or an output that
    cannot be written, 3 for a worker that died or any other error of gearcheck's own (or a
    plugin's; the traceback under -v)."""
    from gearcheck.executor import WorkerError
    from gearcheck.params import ParamError

    if isinstance(exc, ParamError):
        return _error(str(exc))
    if _received:  # an interrupt surfaced as another error (e.g. inside an extension's import)
        return _interrupted(_received[0])
    if isinstance(exc, WorkerError):  # a worker process died or could not load its task
        logging.getLogger("gearcheck").info("worker failure", exc_info=exc)
        return _error(str(exc), 3)
    if isinstance(exc, OSError):  # an output nobody could write: stdout closed or full, a path too long
        return _unwritable(exc)
    from gearcheck.mechanism import HookError

    logging.getLogger("gearcheck").info("internal error", exc_info=exc)
    where = "" if verbose else " (run with -v for the traceback)"
    # a mechanism's hook (a plugin's, or gearcheck's own) names itself; anything else is gearcheck's
    text = _one_line(exc) if isinstance(exc, HookError) else f"internal error: {type(exc).__name__}: {_one_line(exc)}"
    return _error(text + where, 3)

if __name__ == "__main__":
    raise SystemExit(main())
