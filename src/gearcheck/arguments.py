"""The command line's arguments: every command, its options and the help that teaches them (what
``gearcheck --help`` and ``gearcheck COMMAND --help`` print). Parsing only: :mod:`gearcheck.cli`
runs the commands."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from gearcheck import __version__


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


def _budget(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--budget = {text!r}: allowed a number of CPU seconds > 0") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"--budget = {text}: allowed a number of CPU seconds > 0")
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
        "one fails, 2 on input no design can meet, 3 on an internal error.",
    )
    _add_cad_args(check, "check")
    check.add_argument("--budget", type=_budget, default=None, metavar="CPU_S",
                       help="the most CPU seconds the sweep may be predicted to take, every worker's together "
                            "(default 3600). A sweep whose cost grows with what a template declares (an assembly: "
                            "pairs × poses) states its predicted cost before it starts, from its own queries timed "
                            "on a sample; over the budget it is refused in one line naming the setting and the "
                            "value that would fit")

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

    new = sub.add_parser(
        "new", formatter_class=_Formatter,
        help="write a complete template for your design from the few numbers that define it",
        description="Write a complete template for a design of your own from the numbers that define it: "
        "every dependent dimension derived by the paper's own design method or the standard (the "
        "differential's cone distances and shaft lengths, the steering's trim heights and topped radius, "
        "a roller-chain sprocket's ISO 606 tooth form), each value with a comment saying how it was found. "
        "`gearcheck check FILE` then gives its verdict with no edits. Any other value: --set (an input to "
        "the derivation where it is one). The numbers each mechanism takes:\n"
        "  differential  --module M --teeth SMALL/BIG   (side gear / planet bevel gears)\n"
        "  steering      --module M --teeth Z           (pinion teeth)\n"
        "  roller_chain  --chain 12B --teeth Z [--strands 1-3]   (ISO 606 A or B series)\n"
        "  assembly      --step FILE.step   (your own CAD: its products listed as parts; you fill in the joints "
        "and the motion)",
        epilog="Examples:\n  gearcheck new differential --module 3 --teeth 14/30 --out my_diff.toml\n"
               "  gearcheck new steering --module 5 --teeth 34 --out my_steering.toml\n"
               "  gearcheck new roller_chain --chain 16A --teeth 25 --strands 2 --out my_sprocket.toml\n"
               "  gearcheck new differential --module 2 --teeth 16/40 --set operating.cold_C=-120 --out d.toml\n"
               "  gearcheck new assembly --step my_gearbox.step --out my_gearbox.toml\n"
               "  gearcheck check my_diff.toml",
    )
    new.add_argument("mechanism", metavar="MECHANISM", help="differential, steering, roller_chain or assembly")
    new.add_argument("--module", default=None, metavar="M", help="gear module, mm")
    new.add_argument("--teeth", default=None, metavar="Z", help="tooth count(s): Z, or SMALL/BIG for a pair")
    new.add_argument("--chain", default=None, metavar="DESIGNATION", help="ISO 606 chain, e.g. 08B, 12B, 16A")
    new.add_argument("--strands", default=None, metavar="N", help="chain strands, 1 to 3 (default 1)")
    new.add_argument("--step", default=None, metavar="FILE.step", help="assembly: the STEP file whose products "
                     "are the parts")
    new.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                     help="set any other template value (repeatable); an input of the derivation where it is one")
    new.add_argument("--out", type=Path, default=None, metavar="FILE.toml",
                     help="template to write (default: MECHANISM_NUMBERS.toml here; - prints it)")
    new.add_argument("--force", action="store_true", help="replace --out if it exists")
    # a value starting with a minus and a digit is a number (e.g. --teeth -5/20), not an option: `new`
    # names it and its allowed range (argparse's own pattern takes only plain negative numbers)
    new._negative_number_matcher = re.compile(r"^-\d")

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
    # the numbers are checked in cmd_study, against the study file's own limits for them
    study.add_argument("--samples", default=None, metavar="N", help="variants (default: the study's)")
    study.add_argument("--seed", default=None, metavar="S", help="sequence seed (default: the study's)")
    study.add_argument("--exact", default=None, metavar="N",
                       help="variants evaluated on the exact model (default: the study's; -1 every variant)")
    study.add_argument("--check-worst", default=None, metavar="K",
                       help="worst variants re-checked on real geometry (default: the study's)")
    study.add_argument("--scheduler", default=None, metavar="ADDRESS",
                       help="run on a Dask cluster: tcp://HOST:PORT (or tls://) of an existing scheduler (its "
                            "workers must have gearcheck installed; it must answer within 20 s, or "
                            "$GEARCHECK_SCHEDULER_TIMEOUT seconds), or local-cluster to start one here with --jobs "
                            "workers (default: local processes, no set-up)")
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
