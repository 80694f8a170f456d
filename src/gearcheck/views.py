"""What a run shows of its geometry, assembled and written: the :class:`gearcheck.scene.Scene` of a
build or a check (display meshes, each worst pose with the exact B-rep's closest points, the
mechanism's motion frames), NAME.glb beside the STEP, the static pictures, and the report's 3D
view. One scene feeds all of them, so the GLB, the pictures and the viewer show the same thing.
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from gearcheck.results import CheckResult
from gearcheck.scene import DisplayPart, PoseView, Scene

log = logging.getLogger("gearcheck")


def worst_views(result: CheckResult) -> list[PoseView]:
    """Each worst pose of the sweep as a view: its two parts posed (and scaled) as measured, the
    exact B-rep's closest points and distance where the pose was confirmed."""
    confirmed = list(result.confirmations)  # pipeline.confirm: one per worst pose, in order
    out = []
    for i, w in enumerate(result.worst_poses):
        a, b = w.part_a.partition(".")[0], w.part_b.partition(".")[0]
        c = confirmed[i] if i < len(confirmed) and confirmed[i].label == w.label else None
        note = f"mesh {w.mesh_distance_mm:.5f} mm"
        distance = w.mesh_distance_mm
        point_a = point_b = None
        if c is not None:
            distance = c.brep_mm
            note = f"exact B-rep {c.brep_mm:.5f} mm, mesh {c.mesh_mm:.5f} mm"
            if c.point_a is not None and c.point_b is not None:
                point_a, point_b = np.asarray(c.point_a, float), np.asarray(c.point_b, float)
        out.append(PoseView(w.label, {a: np.asarray(w.pose_a, float), b: np.asarray(w.pose_b, float)},
                            {a: float(w.scale_a), b: float(w.scale_b)}, (w.part_a, w.part_b), point_a, point_b,
                            float(distance), note))
    return out


def scene_of(design: Any, assembly: Any, parts: list, result: CheckResult | None = None) -> Scene:
    """The scene of a run: display meshes of its parts, its worst poses (a check), and the
    mechanism's motion frames (:meth:`gearcheck.mechanism.Mechanism.display_frames`)."""
    from gearcheck.cad.display import display_parts

    shown: list[DisplayPart] = display_parts(parts)
    from gearcheck.mechanism import calling

    with calling(design.impl, "display_frames"):
        frames, label = design.impl.display_frames(design.params, assembly)
    return Scene(design.name, shown, worst_views(result) if result is not None else [], list(frames), label,
                 list(result.overlays) if result is not None else [])


@dataclass
class Geometry:
    """The geometry files written for a run and what the report shows of them."""

    files: list[str] = field(default_factory=list)  # names written beside the report
    pictures: list[tuple[str, str, bytes]] = field(default_factory=list)  # (caption, file name, PNG)
    viewer: str = ""  # the report's 3D view (HTML)
    notes: list[str] = field(default_factory=list)  # what could not be drawn, and why


def picture_captions(scene: Scene) -> dict[str, str]:
    """What each picture shows (by file name)."""
    out = {"assembly.png": f"{scene.name}: the assembly as built"}
    for n, view in enumerate(scene.worst, start=1):
        pair = " / ".join(view.parts) if view.parts else ""
        out[f"worst_{n}.png"] = f"worst pose {n}: {view.label} ({pair}; {view.note})"
    return out


def write_geometry(folder: Path, scene: Scene, *, pictures: bool, viewer: bool, drawing: Any = None) -> Geometry:
    """NAME.glb (always), the pictures and the 3D view (a check's report) into ``folder``.
    ``drawing``: a :class:`gearcheck.report.pictures.Drawing` already given this scene (its
    pictures are collected from it); else the pictures are drawn now."""
    from gearcheck.names import file_in
    from gearcheck.output import atomic_write_bytes
    from gearcheck.report.glb import glb_bytes

    out = Geometry()
    name = f"{scene.name}.glb"
    atomic_write_bytes(file_in(folder, name), glb_bytes(scene))
    out.files.append(name)
    if viewer:  # made while the picture process draws
        from gearcheck.report.viewer import viewer_html

        out.viewer = viewer_html(scene)
    if pictures:
        from gearcheck.report.pictures import PicturesUnavailable, render_pictures

        try:
            drawn = drawing.result() if drawing is not None else render_pictures(scene)
        except PicturesUnavailable as exc:
            log.warning("no pictures: %s", exc)
            out.notes.append(f"The static pictures could not be drawn on this machine ({exc}); the 3D view and "
                             f"{name} show the geometry.")
        else:
            captions = picture_captions(scene)
            for file, data in drawn.items():
                atomic_write_bytes(file_in(folder, file), data)
                out.files.append(file)
                out.pictures.append((captions.get(file, file), file, data))
    return out


def _started(factory: Any, what: str) -> Iterator[Any]:
    try:
        process = factory()
    except OSError as exc:
        log.warning("%s process not started early: %s", what, exc)
        yield None
        return
    with process:
        yield process


@contextlib.contextmanager
def picture_process() -> Iterator[Any]:
    """A :class:`gearcheck.report.pictures.Drawing` started now (None where no process can be
    started: the pictures are then drawn, or their absence explained, as without it), ended on
    leaving the block."""
    from gearcheck.report.pictures import Drawing

    yield from _started(Drawing, "picture")


@contextlib.contextmanager
def plot_process() -> Iterator[Any]:
    """A :class:`gearcheck.report.plots.Plotting` started now (None where no process can be
    started: the plots are then drawn in this process), ended on leaving the block."""
    from gearcheck.report.plots import Plotting

    yield from _started(Plotting, "plot")


def run_files(folder: Path, also: Sequence[str] = ()) -> list[str]:
    """The names of every file of a run as the report lists them: what is in the staging folder
    now and what will be written after the report (``also``), sorted."""
    return sorted({p.name for p in folder.iterdir() if p.is_file()} | set(also))
