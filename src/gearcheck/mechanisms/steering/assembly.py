"""The steering parts as data (numpy only): the pinion and the trimmed rack at angle 0 (φ = 0,
L = 0: pinion centre at (0, H, 0), rack tooth k = 0 centred under it, tight mesh), their solids
as specs, their motions, and the layout the sweep works from.

Frame, angle 0 and tooth numbering: :mod:`gearcheck.geometry.rack_pinion`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import rack_pinion as rp
from gearcheck.mechanism import Assembly, PartSpec
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import layout as lay
from gearcheck.sweep.motion import Rotation, Translation

PINION, RACK = "pinion", "rack"


@dataclass(frozen=True)
class SteeringLayout:
    """What the sweep works from, derived from the parameters once: the drawing, the towing swing
    and the corner the power-mode limit is measured at."""

    geometry: rp.RackPinionGeometry
    towing_max_angle_deg: float
    s6_corner: np.ndarray  # S6 of the first rack tooth as drawn (rack frame, travel 0)

    @property
    def overlap_limit_mm(self) -> float:
        """Deepest rack shift searched when an overlap is measured: half a pitch."""
        return 0.5 * self.geometry.pitch


def assembly(params) -> Assembly:
    """Pinion (turns about z through (0, H + Δa, 0)) and rack (slides along x), posed at angle 0."""
    g = an.geometry_from_params(params)
    H = g.centre_height
    pinion = PartSpec(PINION, PINION, lay.PINION_MATERIAL, rp.pinion_pose(g, 0.0),
                      motion=Rotation.about((0.0, 0.0, 1.0), (0.0, float(H), 0.0)))
    rack = PartSpec(RACK, RACK, lay.RACK_MATERIAL, rp.rack_pose(0.0), motion=Translation.along((1.0, 0.0, 0.0)))
    solids = {
        PINION: rp.PinionSpec(g, lay.FACE_WIDTH_MM, lay.PINION_BORE_DIAMETER_MM),
        RACK: rp.RackSpec(g, lay.FACE_WIDTH_MM),
    }
    layout = SteeringLayout(g, float(params.towing.max_angle_deg), np.asarray(g.trim_corners(0.0)["S6"], float))
    return Assembly("steering", (pinion, rack), solids, layout)
