"""What a run shows of its geometry (numpy only): the parts as display meshes at their built
poses, each worst pose of the sweep with its closest points, and the mechanism's motion as a few
key frames. The GLB file, the report's 3D view and its pictures are all drawn from one
:class:`Scene`, so they show the same thing.

Poses are 4×4 world transforms of each part's own frame (mm); a part a view does not move keeps
its built pose. Scales (thermal) are about each part's own frame origin.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import math

import numpy as np

# A B-rep distance below this (mm) is a touch: the solids meet (OCC's own precision is 1e-7 mm).
TOUCH_MM = 1e-6


def distance_text(mm: float | None) -> str:
    """A worst pose's distance as the 3D view and the pictures print it ("" when unknown)."""
    if mm is None or not math.isfinite(mm):
        return ""
    if abs(mm) < TOUCH_MM:
        return "touching, 0 mm"
    return f"{mm:.4f} mm" if abs(mm) >= 1e-3 else f"{mm:.2e} mm"


@dataclass(frozen=True)
class DisplayPart:
    """One part as drawn: a mesh coarse enough for a browser, in the part's own frame."""

    name: str
    material: str
    color: tuple[float, float, float]  # RGB 0…1
    vertices: np.ndarray  # (n, 3) mm
    faces: np.ndarray  # (m, 3) vertex indices
    pose: np.ndarray  # 4×4, as built

    @property
    def triangles(self) -> int:
        return int(len(self.faces))


@dataclass(frozen=True)
class Overlay:
    """A painted patch on a part (a contact pattern on a gear's flanks): a mesh in the part's own
    frame that moves with it in every view."""

    name: str
    host: str  # the part it is painted on
    color: tuple[float, float, float]  # RGB 0…1
    vertices: np.ndarray  # (n, 3) mm, the host's frame
    faces: np.ndarray  # (m, 3)
    label: str = ""  # what it shows, in words


@dataclass(frozen=True)
class PoseView:
    """A pose of the mechanism worth looking at: the parts it moves (others as built), their
    scales, and — for a worst pose — the two parts' closest points (world, mm) and distance."""

    label: str
    poses: dict[str, np.ndarray]
    scales: dict[str, float] = field(default_factory=dict)
    parts: tuple[str, str] | None = None  # the pair measured (a worst pose)
    point_a: np.ndarray | None = None
    point_b: np.ndarray | None = None
    distance_mm: float | None = None
    note: str = ""  # e.g. "B-rep 0.0961 mm, mesh 0.0958 mm"


@dataclass(frozen=True)
class Scene:
    """Everything drawn of one run: parts, worst poses, motion frames (with what they step)."""

    name: str
    parts: list[DisplayPart]
    worst: list[PoseView] = field(default_factory=list)
    frames: list[PoseView] = field(default_factory=list)
    frames_label: str = ""  # what the frames step through ("towing swing angle, °")
    overlays: list[Overlay] = field(default_factory=list)  # painted on parts (contact patterns)

    def part(self, name: str) -> DisplayPart:
        return next(p for p in self.parts if p.name == name)

    def world_vertices(self, view: PoseView | None = None) -> dict[str, np.ndarray]:
        """Each part's vertices in the world at a view (its built pose where the view is silent)."""
        out = {}
        for p in self.parts:
            pose = p.pose if view is None else np.asarray(view.poses.get(p.name, p.pose), float)
            scale = 1.0 if view is None else float(view.scales.get(p.name, 1.0))
            out[p.name] = (scale * p.vertices) @ pose[:3, :3].T + pose[:3, 3]
        return out
