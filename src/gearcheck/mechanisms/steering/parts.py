"""Steering parts for `gearcheck build`: the pinion (end teeth topped to RS1) and the trimmed rack
at angle 0, pinion centre H above the rack datum."""

from __future__ import annotations

from gearcheck.cad.placement import Part
from gearcheck.cad.rack_pinion import steering_parts


def build_parts(params) -> list[Part]:
    return steering_parts(params).parts
