"""Simple solids of revolution as data (numpy-free specs): what a mechanism's assembly hands to
:mod:`gearcheck.cad.primitives` for shafts, collars, shims and housing walls.

Every spec lives in a part's own frame, about its +z axis; lengths in mm.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Ring:
    """An annulus about +z between heights ``z0_mm`` < ``z1_mm``: inner radius ``inner_mm``
    (0: a full cylinder) to outer radius ``outer_mm``."""

    inner_mm: float
    outer_mm: float
    z0_mm: float
    z1_mm: float

    def __post_init__(self) -> None:
        if not (0.0 <= self.inner_mm < self.outer_mm):
            raise ValueError(f"ring radii must satisfy 0 <= inner < outer, got {self.inner_mm}, {self.outer_mm}")
        if not self.z0_mm < self.z1_mm:
            raise ValueError(f"ring heights must satisfy z0 < z1, got {self.z0_mm}, {self.z1_mm}")

    @property
    def height_mm(self) -> float:
        return self.z1_mm - self.z0_mm


@dataclass(frozen=True)
class RingStack:
    """Rings on one axis fused into one solid (a shaft with its collar), in the order given."""

    rings: tuple[Ring, ...]

    def __post_init__(self) -> None:
        if not self.rings:
            raise ValueError("a ring stack needs at least one ring")
