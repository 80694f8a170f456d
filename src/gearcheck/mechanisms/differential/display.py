"""Key frames of the differential's motion for the report's 3D view (numpy only): the small
gears turned through one play period (the drive angle after which every output shaft's play
repeats, :func:`gearcheck.geometry.bevel_mesh.play_period`), the big gears and their shafts by
the conjugate turn, as the sweep poses them (carrier held, warm, the built shim)."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry.bevel_mesh import play_period
from gearcheck.geometry.bevel_play import conjugate_big_turn
from gearcheck.mechanism import Assembly
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS
from gearcheck.scene import PoseView
from gearcheck.sweep.motion import Rotation

FRAMES = 24


def display_frames(params, assembly: Assembly) -> tuple[list[PoseView], str]:
    """(frames, what they step through): drive angle φ over one play period."""
    specs = assembly.layout.specs
    built = {p.name: p.pose for p in assembly.parts}
    period = play_period(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small)
    frames = []
    for phi in np.linspace(0.0, period, FRAMES + 1):
        big_turn = conjugate_big_turn(specs.big, specs.small, float(phi))
        poses = {}
        for spec in assembly.parts:
            if not isinstance(spec.motion, Rotation):
                continue
            # gears and shafts turn about their gear's axis: the small gears by φ, the big gears'
            # side (gear and shaft) by the conjugate turn
            turn = float(phi) if spec.name in SMALL_GEARS else big_turn
            poses[spec.name] = spec.motion.matrix(turn) @ spec.pose
        frames.append(PoseView(f"φ = {math.degrees(phi):.3f}°", poses))
    return frames, f"drive angle φ of the small gears over one play period (0 → {math.degrees(period):.3f}°)"
