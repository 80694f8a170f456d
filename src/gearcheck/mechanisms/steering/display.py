"""Key frames of the steering's motion for the report's 3D view (numpy only): the towing swing,
the pinion turned from 0 out past the disengage angle to the swing's end and back to 0, the rack
at the push model's travel at every frame (:func:`.analysis.analyse_towing`: pushed out, let go
at the disengage angle and left standing, picked up again on the way back)."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import rack_pinion as rp
from gearcheck.mechanism import Assembly
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering.assembly import PINION, RACK
from gearcheck.scene import PoseView

# Frames each way (the disengage and re-engage angles are added to them).
FRAMES_EACH_WAY = 20


def _frame(g: rp.RackPinionGeometry, phi: float, travel: float, label: str) -> PoseView:
    return PoseView(label, {PINION: rp.pinion_pose(g, phi), RACK: rp.rack_pose(travel)})


def display_frames(params, assembly: Assembly) -> tuple[list[PoseView], str]:
    """(frames, what they step through): out and back through the towing swing."""
    g = assembly.layout.geometry
    swing = float(params.towing.max_angle_deg)
    t = an.analyse_towing(g, swing)
    fwd_phi, fwd_travel = t.forward.phi_rad, t.forward.travel_mm
    back_phi, back_travel = t.back.phi_rad[::-1], t.back.travel_mm[::-1]  # ascending angles
    grid = np.linspace(0.0, math.radians(swing), FRAMES_EACH_WAY + 1)
    events_out = {float(t.disengage_rad): "rack let go, stands"} if math.isfinite(t.disengage_rad) else {}
    events_back = {float(t.reengage_rad): "rack picked up"} if math.isfinite(t.reengage_rad) else {}
    frames = []
    standing = float(fwd_travel[-1])  # where the rack is left (the model's travel at the disengage)
    for phi in sorted({*grid.tolist(), *events_out}):
        # at the events the model's own figure, not an interpolation across the grid step they lie in
        travel = standing if phi in events_out else float(np.interp(phi, fwd_phi, fwd_travel))
        note = f": {events_out[phi]}" if phi in events_out else ""
        frames.append(_frame(g, phi, travel, f"out, φ = {math.degrees(phi):.1f}°, rack {travel:.2f} mm{note}"))
    for phi in sorted({*grid[:-1].tolist(), *events_back}, reverse=True):
        travel = standing if phi in events_back else float(np.interp(phi, back_phi, back_travel))
        note = f": {events_back[phi]}" if phi in events_back else ""
        frames.append(_frame(g, phi, travel, f"back, φ = {math.degrees(phi):.1f}°, rack {travel:.2f} mm{note}"))
    return frames, f"towing swing, pinion angle φ 0 → {swing:g}° → 0 (rack by the push model)"
