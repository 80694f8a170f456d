"""Track drive parts for `gearcheck build`: the sprocket and a wrapped chain segment at θ = 0."""

from __future__ import annotations

from gearcheck.cad.placement import Part
from gearcheck.cad.sprocket import track_drive_parts


def build_parts(params) -> list[Part]:
    return track_drive_parts(params).parts
