"""FCL collision engine: meshes + 4×4 poses → contact, clearance, play by bisection.

This module is the only one that imports python-fcl. It never imports CadQuery: sweep workers
receive plain numpy meshes (vertices, faces), so a worker process costs no OpenCASCADE start-up.
FCL objects do not pickle, so each process builds its own :class:`Scene` from the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import fcl
import numpy as np

# Bisection stops when the bracket on the drive coordinate is this narrow (mm or rad, by caller).
DEFAULT_BISECTION_TOL = 1e-6


@dataclass(frozen=True)
class MeshData:
    """A triangle mesh as plain arrays (picklable): float64 (n, 3) vertices, int (m, 3) faces."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class Body:
    """A part as the sweep sees it: its mesh in its own frame, its pose as built (frame → world),
    the mesh-error bound measured when it was meshed, its material and how it may move."""

    mesh: MeshData
    pose: np.ndarray
    error_bound_mm: float
    material: str = ""
    motion: dict | None = None

    @property
    def name(self) -> str:
        return self.mesh.name

    def scaled(self, factor: float, datum_local: np.ndarray | None = None) -> "Body":
        """The part shrunk or grown by ``factor`` about a datum point of its own frame (a thermal
        state: each part by its own material, never the whole assembly by one factor)."""
        datum = np.zeros(3) if datum_local is None else np.asarray(datum_local, float)
        v = datum + (self.mesh.vertices - datum) * factor
        return Body(MeshData(self.mesh.name, v, self.mesh.faces), self.pose, self.error_bound_mm * factor,
                    self.material, self.motion)


def _bvh(mesh: MeshData) -> fcl.BVHModel:
    model = fcl.BVHModel()
    model.beginModel(len(mesh.vertices), len(mesh.faces))
    model.addSubModel(np.ascontiguousarray(mesh.vertices, dtype=np.float64), np.ascontiguousarray(mesh.faces, dtype=np.int32))
    model.endModel()
    return model


def _transform(pose: np.ndarray) -> fcl.Transform:
    pose = np.asarray(pose, dtype=np.float64)
    return fcl.Transform(pose[:3, :3], pose[:3, 3])


@dataclass(frozen=True)
class Distance:
    """Minimum distance between two bodies and the nearest points (world frame, mm).

    FCL's mesh–mesh distance is 0 when the bodies touch or penetrate (it gives no depth), so a
    zero here means "in contact or overlapping"; use :meth:`Scene.collide` to tell them apart.
    """

    distance: float
    point_a: np.ndarray
    point_b: np.ndarray


class Scene:
    """Named rigid bodies, each a BVH mesh, posed by 4×4 homogeneous matrices."""

    def __init__(self, meshes: list[MeshData]):
        self._objects: dict[str, fcl.CollisionObject] = {}
        for mesh in meshes:
            self._objects[mesh.name] = fcl.CollisionObject(_bvh(mesh), fcl.Transform())

    @property
    def names(self) -> list[str]:
        return list(self._objects)

    def set_pose(self, name: str, pose: np.ndarray) -> None:
        self._objects[name].setTransform(_transform(pose))

    def set_poses(self, poses: dict[str, np.ndarray]) -> None:
        for name, pose in poses.items():
            self.set_pose(name, pose)

    def collide(self, a: str, b: str) -> bool:
        """True when the two surfaces intersect. Meshes are surfaces: a body lying wholly inside
        another does not collide, so motion steps must stay small against the tooth size."""
        request = fcl.CollisionRequest(num_max_contacts=1, enable_contact=False)
        result = fcl.CollisionResult()
        return fcl.collide(self._objects[a], self._objects[b], request, result) > 0

    def distance(self, a: str, b: str) -> Distance:
        request = fcl.DistanceRequest(enable_nearest_points=True, enable_signed_distance=False)
        result = fcl.DistanceResult()
        d = fcl.distance(self._objects[a], self._objects[b], request, result)
        return Distance(max(float(d), 0.0), np.array(result.nearest_points[0]), np.array(result.nearest_points[1]))


@dataclass(frozen=True)
class ContactBracket:
    """Where contact is reached along a one-parameter motion: ``free`` does not collide,
    ``touching`` does, and they are within the bisection tolerance of each other."""

    free: float
    touching: float

    @property
    def value(self) -> float:
        return 0.5 * (self.free + self.touching)


def bisect_contact(
    collides: Callable[[float], bool],
    free: float,
    touching: float,
    tol: float = DEFAULT_BISECTION_TOL,
    max_iter: int = 200,
) -> ContactBracket:
    """Bisection on a motion coordinate between a free pose and a colliding pose.

    Raises ValueError when the bracket does not hold (the free end collides or the touching end
    does not): a pair that never touches proves nothing about clearance.
    """
    if collides(free):
        raise ValueError(f"start pose {free!r} already collides")
    if not collides(touching):
        raise ValueError(f"end pose {touching!r} does not reach contact")
    for _ in range(max_iter):
        if abs(touching - free) <= tol:
            break
        mid = 0.5 * (free + touching)
        if collides(mid):
            touching = mid
        else:
            free = mid
    return ContactBracket(free, touching)
