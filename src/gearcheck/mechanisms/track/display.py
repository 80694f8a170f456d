"""Key frames of the track drive's motion for the report's 3D view (numpy only): the sprocket
turning through two chain pitches (two engagement cycles β = 2·360°/z) with every link posed by
the wrap (:meth:`gearcheck.geometry.track_chain.ChainWrap.link_matrices`), as the sweep poses
them."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import track_chain as tc
from gearcheck.mechanism import Assembly
from gearcheck.mechanisms.track.assembly import SPROCKET, link_name
from gearcheck.scene import PoseView

CYCLES = 2
FRAMES_PER_CYCLE = 12


def display_frames(params, assembly: Assembly) -> tuple[list[PoseView], str]:
    """(frames, what they step through): drive angle θ from 0 to two cycles."""
    wrap = assembly.layout.wrap
    frames = []
    for theta in np.linspace(0.0, CYCLES * wrap.cycle_rad, CYCLES * FRAMES_PER_CYCLE + 1):
        poses = {SPROCKET: tc.sprocket_matrix(float(theta))}
        for j, m in enumerate(wrap.link_matrices(float(theta))):
            poses[link_name(j)] = m
        frames.append(PoseView(f"θ = {math.degrees(theta):.2f}°", poses))
    return frames, f"sprocket drive angle θ over two chain pitches (0 → {math.degrees(CYCLES * wrap.cycle_rad):.2f}°)"
