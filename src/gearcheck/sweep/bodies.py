"""Meshes and bodies as the sweep sees them: plain numpy arrays (picklable, no FCL, no CadQuery),
so a plan can be built, pickled and handed to any executor."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.sweep.motion import Motion


@dataclass(frozen=True)
class MeshData:
    """A triangle mesh as plain arrays (picklable): float64 (n, 3) vertices, int (m, 3) faces."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray


def submesh(mesh: MeshData, name: str, keep: np.ndarray) -> MeshData:
    """The triangles ``keep`` (a boolean mask or index array) of ``mesh`` with only the vertices
    they use, renumbered: a smaller BVH for a sweep that can only touch part of a body."""
    faces = mesh.faces[keep]
    used = np.unique(faces)
    index = np.full(len(mesh.vertices), -1, dtype=np.int64)
    index[used] = np.arange(len(used))
    return MeshData(name, np.ascontiguousarray(mesh.vertices[used]), index[faces])


@dataclass(frozen=True)
class Body:
    """A part as the sweep sees it: its mesh in its own frame, its pose as built (frame → world),
    the mesh-error bound measured when it was meshed, its material and how it may move."""

    mesh: MeshData
    pose: np.ndarray
    error_bound_mm: float
    material: str = ""
    motion: Motion | None = None

    @property
    def name(self) -> str:
        return self.mesh.name

    def scaled(self, factor: float, datum_local: np.ndarray | None = None) -> Body:
        """The part shrunk or grown by ``factor`` about a datum point of its own frame (a thermal
        state: each part by its own material, never the whole assembly by one factor)."""
        datum = np.zeros(3) if datum_local is None else np.asarray(datum_local, float)
        v = datum + (self.mesh.vertices - datum) * factor
        return Body(MeshData(self.mesh.name, v, self.mesh.faces), self.pose, self.error_bound_mm * factor,
                    self.material, self.motion)


def pair_error_bound(bodies: dict[str, Body], a: str, b: str) -> float:
    """The mesh-error bound of a clearance between two meshed parts: both meshes' bounds."""
    return bodies[a].error_bound_mm + bodies[b].error_bound_mm
