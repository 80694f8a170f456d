"""How a part may move, as typed data (numpy only, no FCL): a sweep turns a motion coordinate
into a 4×4 world transform applied on top of the part's pose as built.

- :class:`Rotation` about a world axis through a world point (a gear on its shaft);
- :class:`Translation` along a world axis (a rack on its guide);
- :class:`ChainLink`: link ``index`` of a chain wrapped on a sprocket; its pose at a drive angle
  is the wrap's (:meth:`gearcheck.geometry.track_chain.ChainWrap.link_matrices`), not a rigid
  motion of its own.

``to_dict`` is what manifest.json records.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

Vector3 = tuple[float, float, float]


def _unit(v) -> Vector3:
    a = np.asarray(v, dtype=float)
    n = float(np.linalg.norm(a))
    if not n > 0.0:
        raise ValueError("a motion axis must be a non-zero vector")
    return (float(a[0] / n), float(a[1] / n), float(a[2] / n))


def _vec(v) -> Vector3:
    a = np.asarray(v, dtype=float)
    return (float(a[0]), float(a[1]), float(a[2]))


@dataclass(frozen=True)
class Rotation:
    """Rotation about ``axis`` (unit, world) through ``origin`` (world, mm), right-handed."""

    axis: Vector3
    origin: Vector3 = (0.0, 0.0, 0.0)
    kind: str = "rotation"

    @classmethod
    def about(cls, axis, origin=(0.0, 0.0, 0.0)) -> Rotation:
        return cls(_unit(axis), _vec(origin))

    def matrix(self, angle_rad: float) -> np.ndarray:
        """World transform turning by ``angle_rad`` about the axis (Rodrigues)."""
        k = np.asarray(self.axis, float)
        kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        r = np.eye(3) + math.sin(angle_rad) * kx + (1.0 - math.cos(angle_rad)) * kx @ kx
        m = np.eye(4)
        m[:3, :3] = r
        o = np.asarray(self.origin, float)
        m[:3, 3] = o - r @ o
        return m

    def matrices(self, angles_rad: np.ndarray) -> np.ndarray:
        """:meth:`matrix` at every angle of ``angles_rad`` at once: (n, 4, 4)."""
        a = np.asarray(angles_rad, float).reshape(-1)
        k = np.asarray(self.axis, float)
        kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        r = np.eye(3) + np.sin(a)[:, None, None] * kx + (1.0 - np.cos(a))[:, None, None] * (kx @ kx)
        m = np.broadcast_to(np.eye(4), (len(a), 4, 4)).copy()
        m[:, :3, :3] = r
        o = np.asarray(self.origin, float)
        m[:, :3, 3] = o - r @ o
        return m

    def to_dict(self) -> dict:
        return {"kind": self.kind, "axis": list(self.axis), "origin": list(self.origin)}


@dataclass(frozen=True)
class Translation:
    """Translation along ``axis`` (unit, world)."""

    axis: Vector3
    kind: str = "translation"

    @classmethod
    def along(cls, axis) -> Translation:
        return cls(_unit(axis))

    def matrix(self, distance_mm: float) -> np.ndarray:
        m = np.eye(4)
        m[:3, 3] = np.asarray(self.axis, float) * distance_mm
        return m

    def matrices(self, distances_mm: np.ndarray) -> np.ndarray:
        """:meth:`matrix` at every distance of ``distances_mm`` at once: (n, 4, 4)."""
        d = np.asarray(distances_mm, float).reshape(-1)
        m = np.broadcast_to(np.eye(4), (len(d), 4, 4)).copy()
        m[:, :3, 3] = np.asarray(self.axis, float)[None, :] * d[:, None]
        return m

    def to_dict(self) -> dict:
        return {"kind": self.kind, "axis": list(self.axis)}


@dataclass(frozen=True)
class ChainLink:
    """Link ``index`` of a chain wrap: posed by the wrap at each drive angle."""

    index: int
    kind: str = "chain_link"

    def to_dict(self) -> dict:
        return {"kind": self.kind, "index": self.index}


Motion = Rotation | Translation | ChainLink
