"""Scenes and pages for looking at the 3D view outside report.html (tests, and by hand):

* :func:`scene_of` — the :class:`gearcheck.scene.Scene` of a build (and, given a check's result,
  its worst poses with the exact closest points): what the pipeline hands the report;
* :func:`worst_view` — one worst pose measured here on the exact B-rep (closest points too);
* :func:`scene_page` — a template's parts (no meshing, no sweep) with one worst pose made up from
  the first two parts as built, measured on the exact B-rep, written as a bare page;
* ``python tests/viewer_page.py TEMPLATE OUT.html [--check]`` writes such a page (``--check`` runs
  the whole check first and shows its real worst poses and the mechanism's motion frames).
"""

from __future__ import annotations

import argparse
import html
import importlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def worst_view(by_name, worst, bodies=None):
    """A worst pose as a :class:`PoseView` with the exact distance and closest points (faces
    around the meshes' nearest points when the sweep bodies are given, as pipeline.confirm)."""
    from gearcheck.cad.confirm import exact_closest, exact_overlap_closest
    from gearcheck.scene import PoseView

    a, b = worst.part_a.partition(".")[0], worst.part_b.partition(".")[0]
    if bodies is not None:
        from gearcheck.sweep.tools import mesh_nearest_midpoint, meshes_overlap

        if worst.mesh_distance_mm <= 0.0 or meshes_overlap(bodies, worst):
            d, _, pa, pb = exact_overlap_closest(by_name, worst)
        else:
            d, pa, pb = exact_closest(by_name, worst, near=mesh_nearest_midpoint(bodies, worst))
    else:
        d, pa, pb = exact_closest(by_name, worst)
    return PoseView(worst.label, {a: np.asarray(worst.pose_a, float), b: np.asarray(worst.pose_b, float)},
                    {a: worst.scale_a, b: worst.scale_b}, (a, b), pa, pb, d,
                    f"B-rep {d:.4f} mm, mesh {worst.mesh_distance_mm:.4f} mm")


def motion_frames(design, assembly):
    """The mechanism's key frames (its display module), or none."""
    try:
        module = importlib.import_module(f"gearcheck.mechanisms.{design.mechanism}.display")
    except ModuleNotFoundError:
        return [], ""
    return module.display_frames(design.params, assembly)


def scene_of(build, result=None, frames: bool = True):
    """The Scene of a pipeline BuildRun (and a CheckResult's worst poses, with the closest points
    pipeline.confirm stored): :func:`gearcheck.views.scene_of`, with the mechanism's display
    frames taken from its display module where its hook gives none."""
    import dataclasses

    from gearcheck.views import scene_of as pipeline_scene

    scene = pipeline_scene(build.design, build.assembly, build.parts, result)
    if frames and not scene.frames:
        views, label = motion_frames(build.design, build.assembly)
        scene = dataclasses.replace(scene, frames=views, frames_label=label)
    elif not frames:
        scene = dataclasses.replace(scene, frames=[], frames_label="")
    return scene


def made_up_scene(name: str, frames: bool = True):
    """A template's parts as built and one worst pose: its first two parts where they are."""
    from gearcheck import pipeline
    from gearcheck.cad.display import display_parts
    from gearcheck.design import load_template
    from gearcheck.results import WorstPose
    from gearcheck.scene import Scene

    design = load_template(ROOT / "templates" / f"{name}.toml", [])
    assembly, parts = pipeline.build_parts(design)
    a, b = parts[0], parts[1]
    worst = WorstPose(f"{a.name} / {b.name} as built", a.name, b.name, a.pose.tolist(), b.pose.tolist(), float("nan"))
    view = worst_view({p.name: p for p in parts}, worst)
    views, label = motion_frames(design, assembly) if frames else ([], "")
    return Scene(design.name, display_parts(parts), [view], views, label)


def page(scene, title: str = "") -> str:
    """A bare HTML page holding the 3D view (the report's CSS, a phone viewport meta tag)."""
    from gearcheck.report.html import CSS
    from gearcheck.report.viewer import viewer_html

    title = html.escape(title or scene.name)
    return ("<!doctype html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>{title}</title><style>{CSS}</style></head><body><h1>{title}</h1>"
            f"{viewer_html(scene)}</body></html>")


def scene_page(name: str, folder: Path, frames: bool = False) -> Path:
    out = Path(folder) / f"{name}_viewer.html"
    out.write_text(page(made_up_scene(name, frames)), encoding="utf-8")
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("template")
    ap.add_argument("out", type=Path)
    ap.add_argument("--check", action="store_true", help="run the check and show its worst poses")
    args = ap.parse_args(argv)
    if args.check:
        import tempfile

        from gearcheck import pipeline
        from gearcheck.design import load_template

        design = load_template(ROOT / "templates" / f"{args.template}.toml", [])
        run = pipeline.check(design, Path(tempfile.mkdtemp()) / "run", jobs=2)
        scene = scene_of(run.build, run.result)
    else:
        scene = made_up_scene(args.template)
    args.out.write_text(page(scene), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
