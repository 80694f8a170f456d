"""FCL collision engine: meshes + 4×4 poses → contact, clearance, play by bisection.

This module is the only one that imports python-fcl. It never imports CadQuery: sweep workers
receive plain numpy meshes (vertices, faces), so a worker process costs no OpenCASCADE start-up.
FCL objects do not pickle, so each process builds its own :class:`Scene` from the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from collections.abc import Callable

import fcl
import numpy as np

from gearcheck.geometry.bisect import Bracket as ContactBracket
from gearcheck.geometry.bisect import bisect
from gearcheck.sweep.bodies import Body, MeshData  # noqa: F401  (re-exported: the sweep API)

# Bisection stops when the bracket on the drive coordinate is this narrow (mm or rad, by caller).
DEFAULT_BISECTION_TOL = 1e-6


def _bvh(mesh: MeshData) -> fcl.BVHModel:
    model = fcl.BVHModel()
    model.beginModel(len(mesh.vertices), len(mesh.faces))
    model.addSubModel(np.ascontiguousarray(mesh.vertices, dtype=np.float64),
                      np.ascontiguousarray(mesh.faces, dtype=np.int32))
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
    """Named rigid bodies, each a BVH mesh, posed by 4×4 homogeneous matrices.

    A body's BVH is built when the body is first posed or queried, not before: a worker that
    runs only some of a plan's tasks builds only the meshes those tasks use (a plan orders its
    tasks so that neighbours share meshes)."""

    def __init__(self, meshes: list[MeshData]):
        self._meshes: dict[str, MeshData] = {mesh.name: mesh for mesh in meshes}
        self._objects: dict[str, fcl.CollisionObject] = {}

    @property
    def names(self) -> list[str]:
        return list(self._meshes)

    def mesh(self, name: str) -> MeshData:
        return self._meshes[name]

    def add(self, mesh: MeshData) -> None:
        """One more body (a part cut from another's mesh by a task, say); its BVH is built on first
        use. A name already in the scene must stay its mesh: adding it again changes nothing."""
        self._meshes.setdefault(mesh.name, mesh)

    def discard(self, name: str) -> None:
        """Drop a body added by a task (its mesh and BVH): a cut that is no longer used."""
        self._meshes.pop(name, None)
        self._objects.pop(name, None)

    @property
    def built(self) -> list[str]:
        """The bodies whose BVH exists so far."""
        return list(self._objects)

    def build(self, names: list[str] | None = None) -> None:
        """Build these bodies' BVHs now (default: every body's)."""
        for name in self._meshes if names is None else names:
            self._object(name)

    def _object(self, name: str) -> fcl.CollisionObject:
        obj = self._objects.get(name)
        if obj is None:
            obj = self._objects[name] = fcl.CollisionObject(_bvh(self._meshes[name]), fcl.Transform())
        return obj

    def set_pose(self, name: str, pose: np.ndarray) -> None:
        self._object(name).setTransform(_transform(pose))

    def set_poses(self, poses: dict[str, np.ndarray]) -> None:
        for name, pose in poses.items():
            self.set_pose(name, pose)

    def collide(self, a: str, b: str) -> bool:
        """True when the two surfaces intersect. Meshes are surfaces: a body lying wholly inside
        another does not collide, so motion steps must stay small against the tooth size."""
        request = fcl.CollisionRequest(num_max_contacts=1, enable_contact=False)
        result = fcl.CollisionResult()
        return fcl.collide(self._object(a), self._object(b), request, result) > 0

    def contact_normal(self, a: str, b: str, max_contacts: int = 100_000) -> np.ndarray | None:
        """The mean normal (unit, world; from ``a`` towards ``b``, FCL's convention) of up to
        ``max_contacts`` intersecting triangle pairs, or None where the surfaces do not intersect
        or the normals cancel: the direction in which to push ``b`` off ``a``."""
        request = fcl.CollisionRequest(num_max_contacts=max_contacts, enable_contact=True)
        result = fcl.CollisionResult()
        if fcl.collide(self._object(a), self._object(b), request, result) <= 0:
            return None
        n = np.sum([np.asarray(c.normal, float) for c in result.contacts], axis=0)
        length = float(np.linalg.norm(n))
        return n / length if length > 1e-12 else None

    def distance(self, a: str, b: str) -> Distance:
        request = fcl.DistanceRequest(enable_nearest_points=True, enable_signed_distance=False)
        result = fcl.DistanceResult()
        d = fcl.distance(self._object(a), self._object(b), request, result)
        return Distance(max(float(d), 0.0), np.array(result.nearest_points[0]), np.array(result.nearest_points[1]))


def bisect_contact(collides: Callable[[float], bool], free: float, touching: float,
                  tol: float = DEFAULT_BISECTION_TOL, max_iter: int = 200) -> ContactBracket:
    """Bisection on a motion coordinate between a free pose and a colliding pose.

    Raises ValueError when the bracket does not hold (the free end collides or the touching end
    does not): a pair that never touches proves nothing about clearance."""
    if collides(free):
        raise ValueError(f"start pose {free!r} already collides")
    if not collides(touching):
        raise ValueError(f"end pose {touching!r} does not reach contact")
    return bisect(collides, free, touching, tol, max_iter, check_ends=False)
