"""Parts as data: a solid in its own frame plus a 4×4 pose (frame → world).

Poses are numpy matrices, so the sweep can move meshes with the same transforms the CAD used;
:func:`place` is the one conversion to a B-rep placement.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import cadquery as cq
import numpy as np
from OCP.gp import gp_Trsf
from OCP.TopLoc import TopLoc_Location


def location(matrix: np.ndarray) -> cq.Location:
    """cq.Location of a rigid 4×4 transform."""
    t = gp_Trsf()
    m = np.asarray(matrix, dtype=float)
    t.SetValues(*(float(m[i, j]) for i in range(3) for j in range(4)))
    return cq.Location(TopLoc_Location(t))


def place(shape: cq.Shape, matrix: np.ndarray) -> cq.Shape:
    """The shape moved by ``matrix`` (shares its geometry)."""
    return shape.moved(location(matrix))


@dataclass(frozen=True)
class Part:
    """One rigid part: its solid in its own frame, its pose, and what it is made of.

    Parts that are copies (the two big gears, the chain links) share one ``solid`` object, so
    it is built and meshed once."""

    name: str
    material: str
    solid: cq.Shape
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    color: tuple[float, float, float] = (0.7, 0.7, 0.75)
    # how the sweep may move it (a gearcheck.sweep.motion Rotation / Translation / ChainLink;
    # cad/ only records it: ``motion.to_dict()`` in the manifest)
    motion: Any = None
    # named sub-solids in the same frame (a link's "plate" and "sleeve"), so a check can confirm
    # a distance to one feature ("link_03.plate") on the exact B-rep
    features: dict = field(default_factory=dict)

    def feature(self, name: str) -> cq.Shape:
        """The whole solid (name "") or one named feature, in the part's own frame."""
        return self.solid if not name else self.features[name]

    def placed(self) -> cq.Shape:
        """The solid in the world frame (shares its geometry)."""
        return place(self.solid, self.pose)
