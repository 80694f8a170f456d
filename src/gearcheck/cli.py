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


def _add_cad_args(p: argparse.ArgumentParser, verb: str) -> None:
    """TEMPLATE | --all, --set, --out, --tol: shared by `build` and `check`."""
    p.add_argument("template", type=Path, nargs="?", help="TOML parameter file (omit with --all)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="SECTION.KEY=VALUE",
                   help="override one template value (repeatable)")
    p.add_argument("--all", action="store_true", help=f"{verb} every template in templates/ into OUT/NAME")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default out/NAME; with --all, the parent folder, default out)")
    p.add_argument("--tol", type=float, default=None, metavar="MM",
                   help="absolute chordal tolerance of the meshes in mm (default per mechanism: differential "
                        "0.003, track 0.008, steering 0.01 — fine enough that the mesh-error bound is at most "
                        "1/10 of the smallest clearance the check decides on; `check` refuses coarser meshes)")


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

    build = sub.add_parser(
        "build",
        help="build the CAD: STEP assembly, one STL per part, manifest.json",
        description="Build the mechanism's parts with CadQuery from the template (exact involute "
        "flanks), mesh each part with an absolute chordal tolerance, and write DIR/NAME.step "
        "(named, placed parts), DIR/PART.stl, DIR/params.toml (the resolved parameters) and "
        "DIR/manifest.json (materials, volumes, triangle counts, measured mesh error, file hashes). "
        "Every file is written atomically.",
    )
    _add_cad_args(build, "build")

    check = sub.add_parser(
        "check",
        help="build, mesh and sweep the mechanism; write report.html, summary.json, sweep.csv",
        description="Build the CAD (as `build`), sweep the assembly through its motion with "
        "python-fcl on the meshes (warm and cold for the differential, a full engagement cycle "
        "for the track drive, towing and power modes for the steering), confirm each sweep's "
        "worst pose on the exact B-rep, and write DIR/report.html (verdicts, paper vs model vs "
        "geometry, plots), DIR/summary.json (numbers) and DIR/sweep.csv (one row per pose) beside "
        "the CAD. Exit 0 when every verdict passes, 1 when one fails, 2 on bad input.",
    )
    _add_cad_args(check, "check")

    demo = sub.add_parser("demo", help="every template in templates/: figures and CAD under --out (what `make demo` runs)")
    demo.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: out)")
    demo.add_argument("--templates", type=Path, default=TEMPLATE_DIR, help="folder of templates (default: templates)")
    demo.add_argument("--no-cad", action="store_true", help="analytical figures only, no CAD build")
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
    """Every template: the analytical figures (calc.json, calc.txt), then `check` (CAD, sweep,
    report) unless --no-cad. Exit 1 if any verdict fails, after every template has run."""
    from gearcheck.mechanisms import load_template
    from gearcheck.output import atomic_write_text, ensure_out_dir

    templates = sorted(args.templates.glob("*.toml"))
    if not templates:
        raise ParamError("--templates", str(args.templates), "no *.toml templates found there")
    loaded = [load_template(path) for path in templates]  # validate every template first
    folders = [ensure_out_dir(args.out / item.name) for item in loaded]
    passed = []
    for item, folder in zip(loaded, folders):
        figures = item.module.calc(item.params)
        atomic_write_text(folder / "calc.json", json.dumps(figures_to_json(item.module.SECTION, figures), indent=2, allow_nan=False) + "\n")
        table = render_table(f"{item.name} ({item.mechanism}) — analytical model", figures)
        atomic_write_text(folder / "calc.txt", table + "\n")
        print(table)
        print()
        if not args.no_cad:
            passed.append(_check_one(item, folder, None))
            print()
    print(f"wrote {len(loaded)} result folders under {args.out}/ (open NAME/report.html)")
    return 0 if all(passed) else 1


def _templates_or_one(args) -> list:
    """The validated templates a build/check acts on: one, or --all (all validated first)."""
    from gearcheck.mechanisms import load_template

    _check_tol(args.tol)
    if args.all == (args.template is not None):
        raise ParamError(args.command, str(args.template), "give one TEMPLATE or --all, not both or neither")
    if args.all:
        return [load_template(t, args.overrides) for t in sorted(TEMPLATE_DIR.glob("*.toml"))]
    return [load_template(args.template, args.overrides)]


def _out_folder(args, loaded) -> Path:
    if args.all:
        return (args.out or Path("out")) / loaded.name
    return args.out or Path("out") / loaded.name


def _check_one(loaded, folder: Path, tol_mm: float | None) -> bool:
    from tqdm import tqdm

    from gearcheck.cad.confirm import exact_distance
    from gearcheck.cad.export import sweep_bodies
    from gearcheck.output import atomic_write_text
    from gearcheck.report.files import summary_json, sweep_csv
    from gearcheck.report.html import render
    from gearcheck.sweep import resolution

    # the report files of an earlier run would describe other meshes: gone until this run writes its own
    for stale in ("summary.json", "sweep.csv", "report.html"):
        (folder / stale).unlink(missing_ok=True)
    manifest, exported = _build_one(loaded, folder, tol_mm)
    bodies = sweep_bodies(exported)
    with tqdm(desc=f"sweeping {loaded.name}", unit="pose", file=sys.stderr, disable=not sys.stderr.isatty()) as bar:
        result = loaded.check_module.run_check(loaded.params, bodies, progress=bar.update)
    # after meshing, not before: the bound is measured on the meshes, the clearance by the check
    resolution.enforce(result, bodies, mesh_tol(loaded, tol_mm), str(loaded.path))
    result.summary["mesh_resolution"] = resolution.resolution_summary(result, bodies)
    result.notes.append(resolution.describe(result, bodies))
    parts = {e.part.name: e.part for e in exported}
    confirmations = {}
    for worst in tqdm(result.worst_poses, desc="exact B-rep distance at worst poses", file=sys.stderr,
                      disable=not sys.stderr.isatty()):
        confirmations[worst.label] = {
            "parts": f"{worst.part_a} / {worst.part_b}",
            "mesh_mm": worst.mesh_distance_mm,
            "brep_mm": exact_distance(parts, worst, near=_mesh_nearest_midpoint(bodies, worst)),
            "bound_mm": sum(bodies[n.partition(".")[0]].error_bound_mm for n in (worst.part_a, worst.part_b)),
        }
    keys = {w.label: w.json_key for w in result.worst_poses}
    numeric = {keys[k]: {kk: vv for kk, vv in v.items() if kk != "parts"} for k, v in confirmations.items()}
    atomic_write_text(folder / "summary.json", summary_json(result, numeric))
    atomic_write_text(folder / "sweep.csv", sweep_csv(result))
    build = {
        "chordal_tolerance_mm": manifest["chordal_tolerance_mm"],
        "triangles": sum(p["triangles"] for p in manifest["parts"]),
        "parts": len(manifest["parts"]),
    }
    page = render(result, title=f"gearcheck: {loaded.name} ({loaded.mechanism})", template=str(loaded.path),
                  build=build, confirmations=confirmations)
    atomic_write_text(folder / "report.html", page)
    verdict = "PASS" if result.passed else "FAIL"
    print(f"{verdict} {loaded.name}: {sum(v.passed for v in result.verdicts)}/{len(result.verdicts)} verdicts; "
          f"report {folder / 'report.html'}")
    for v in result.verdicts:
        print(f"  [{'pass' if v.passed else 'FAIL'}] {v.label}: {v.detail}")
    return result.passed


def _mesh_nearest_midpoint(bodies, worst):
    """Where the meshes come closest at a worst pose (world frame): the exact distance is then
    measured on the faces around it only."""
    import numpy as np

    from gearcheck.sweep.engine import Scene

    names = [worst.part_a, worst.part_b]
    if any("." in n for n in names):  # a feature of a part: measure the whole feature
        return None
    scene = Scene([bodies[worst.part_a].scaled(worst.scale_a).mesh, bodies[worst.part_b].scaled(worst.scale_b).mesh])
    scene.set_pose(worst.part_a, np.asarray(worst.pose_a, float))
    scene.set_pose(worst.part_b, np.asarray(worst.pose_b, float))
    d = scene.distance(worst.part_a, worst.part_b)
    return 0.5 * (d.point_a + d.point_b)


def _prepared_folders(args, items) -> list[Path]:
    """Every output folder checked (created, writable) before any CAD work starts."""
    from gearcheck.output import ensure_out_dir

    return [ensure_out_dir(_out_folder(args, item)) for item in items]


def cmd_check(args) -> int:
    items = _templates_or_one(args)
    folders = _prepared_folders(args, items)
    passed = [_check_one(item, folder, args.tol) for item, folder in zip(items, folders)]
    return 0 if all(passed) else 1


def _build_one(loaded, folder: Path, tol_mm: float | None):
    from tqdm import tqdm

    from gearcheck.cad.export import export_parts

    print(f"building {loaded.name} ({loaded.mechanism}) ...", file=sys.stderr)
    parts = loaded.parts_module.build_parts(loaded.params)
    with tqdm(total=len(parts), desc=f"meshing {loaded.name}", unit="part", file=sys.stderr,
              disable=not sys.stderr.isatty()) as bar:
        manifest, exported = export_parts(
            parts, folder, name=loaded.name, mechanism=loaded.mechanism, params_data=loaded.resolved_data,
            tol_mm=mesh_tol(loaded, tol_mm),
            progress=lambda _name: bar.update(1),
        )
    print(f"wrote {folder}/ : {len(parts)} parts, {manifest['step']['file']}, manifest.json")
    return manifest, exported


def mesh_tol(loaded, tol_mm: float | None) -> float:
    """--tol, or the mechanism's default (fine enough for the template's smallest clearance)."""
    return tol_mm if tol_mm is not None else loaded.module.MESH_TOL_MM


def _check_tol(tol: float | None) -> None:
    if tol is not None and not (0.0005 <= tol <= 0.5):
        raise ParamError("--tol", tol, "out of range: allowed 0.0005 to 0.5 mm")


def cmd_build(args) -> int:
    items = _templates_or_one(args)
    for item, folder in zip(items, _prepared_folders(args, items)):
        _build_one(item, folder, args.tol)
    return 0


COMMANDS = {"calc": cmd_calc, "build": cmd_build, "check": cmd_check, "demo": cmd_demo}


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
