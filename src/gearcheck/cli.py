"""Command line: parse, call, print. Exit codes: 0 ok, 1 a verdict failed, 2 bad input."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from gearcheck import __version__
from gearcheck.figures import figures_to_json, render_table
from gearcheck.params import ParamError

TEMPLATE_DIR = Path("templates")

DESCRIPTION = """\
gearcheck turns a parameter file (TOML template) into the design figures, CAD and an
interference proof of a gear mechanism.

Templates (one per mechanism, see templates/):
  zhurong_differential.toml   bevel-gear differential, cold backlash and shims
  eod_track_drive.toml        roller-chain track sprocket, every other tooth engaging
  nose_wheel_steering.toml    trimmed rack and pinion, continuous drive and disengage angles

Examples:
  gearcheck calc templates/zhurong_differential.toml
  gearcheck calc templates/zhurong_differential.toml --set operating.cold_C=-130
  gearcheck calc templates/nose_wheel_steering.toml --set trim.min_contact_ratio=1.3 --json
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # usage errors are bad input: exit 2, one line
        self.exit(2, f"gearcheck: error: {message}\n")


def _add_template_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("template", type=Path, help="TOML parameter file (see templates/)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="override one template value, validated like the file (repeatable), "
        "e.g. --set shim.thickness_mm=0.15",
    )


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="gearcheck",
        description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"gearcheck {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    calc = sub.add_parser(
        "calc",
        help="the paper's analytical model: design figures beside the paper's numbers",
        description="Compute the mechanism's design figures from its template with the paper's "
        "analytical model (reconstructed where the paper lost equations), and print them beside "
        "the paper's printed values with the difference and the reason where they differ.",
    )
    _add_template_args(calc)
    calc.add_argument("--json", action="store_true", help="print one JSON object (nested by section) instead of a table")

    demo = sub.add_parser("demo", help="run every template in templates/ and write results under --out")
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: out)")
    demo.add_argument("--templates", type=Path, default=TEMPLATE_DIR, help="folder of templates (default: templates)")
    return parser


def cmd_calc(args) -> int:
    from gearcheck.mechanisms import load_template

    loaded = load_template(args.template, args.overrides)
    figures = loaded.module.calc(loaded.params)
    if args.json:
        print(json.dumps(figures_to_json(loaded.module.SECTION, figures), indent=2, allow_nan=False))
    else:
        print(render_table(f"{loaded.name} ({loaded.mechanism}) — analytical model", figures))
    return 0


def cmd_demo(args) -> int:
    from gearcheck.mechanisms import load_template
    from gearcheck.output import atomic_write_text, ensure_out_dir

    templates = sorted(args.templates.glob("*.toml"))
    if not templates:
        raise ParamError("--templates", str(args.templates), "no *.toml templates found there")
    for path in templates:
        loaded = load_template(path)
        figures = loaded.module.calc(loaded.params)
        folder = ensure_out_dir(args.out / loaded.name)
        atomic_write_text(folder / "calc.json", json.dumps(figures_to_json(loaded.module.SECTION, figures), indent=2, allow_nan=False) + "\n")
        table = render_table(f"{loaded.name} ({loaded.mechanism}) — analytical model", figures)
        atomic_write_text(folder / "calc.txt", table + "\n")
        print(table)
        print()
    print(f"wrote {len(templates)} result folders under {args.out}/")
    return 0


COMMANDS = {"calc": cmd_calc, "demo": cmd_demo}


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except ParamError as exc:
        print(f"gearcheck: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    raise SystemExit(main())
