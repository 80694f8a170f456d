"""The track-drive sprocket as a data spec (numpy only): what :func:`gearcheck.cad.sprocket.build_sprocket`
builds a solid from.

Sprocket frame (as in :mod:`gearcheck.geometry.iso606`): axis +z, mid-plane z = 0, groove k on
polar angle k·2π/z. Each tooth row is an extrusion of the ISO 606 outline (:class:`ToothGap`)
with the bore as inner circle; rows sit symmetric about z = 0, a middle groove of
``middle_groove_width_mm`` between neighbours, whose floor is a hub cylinder of ``hub_radius_mm``.
"""

from __future__ import annotations

from dataclasses import dataclass

from gearcheck.geometry.iso606 import ToothGap


@dataclass(frozen=True)
class SprocketSpec:
    """Everything the sprocket solid needs (mm)."""

    gap: ToothGap
    tooth_width_mm: float
    tooth_rows: int
    middle_groove_width_mm: float
    hub_radius_mm: float
    bore_radius_mm: float

    def row_z_ranges(self) -> list[tuple[float, float]]:
        """(z_low, z_high) of each tooth row, symmetric about z = 0."""
        pitch = self.tooth_width_mm + self.middle_groove_width_mm
        total = self.tooth_rows * self.tooth_width_mm + (self.tooth_rows - 1) * self.middle_groove_width_mm
        return [(-total / 2 + i * pitch, -total / 2 + i * pitch + self.tooth_width_mm)
                for i in range(self.tooth_rows)]
