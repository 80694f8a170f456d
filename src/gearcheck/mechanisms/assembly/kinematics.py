"""The declared motion as numbers (numpy only): every jointed part's coordinate as a linear function
of the driving joint's (coupled outwards from the driver), and the world transform of a part at a
pose. Angles are degrees at the interface (templates, summary.json) and radians inside.

A part's coordinate ``q`` (deg for a revolute joint, mm for a prismatic one) at driver coordinate
``x`` is ``gain·x + offset``: the driver has (1, 0); a couple driver → driven maps the driver's
line through its ratio (converted to the driven joint's unit) plus its phase. A jointed part no
couple reaches keeps q = 0 (it moves only where gearcheck moves it: the play part); a part without
a joint never moves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.sweep.motion import Rotation, Translation


@dataclass(frozen=True)
class JointLine:
    """One jointed part: its motion, the unit of its coordinate and its line in the driver's."""

    part: str
    motion: Rotation | Translation
    unit: str  # "deg" or "mm"
    gain: float  # q per driver unit
    offset: float  # q at driver 0
    coupled: bool  # driven by the motion (the driver, or reached through couples)

    def coordinate(self, x: float) -> float:
        return self.gain * x + self.offset if self.coupled else 0.0

    def matrix(self, q: float) -> np.ndarray:
        """World transform of the part at its own coordinate ``q`` (deg or mm)."""
        return self.motion.matrix(math.radians(q) if self.unit == "deg" else q)

    def matrices(self, q: np.ndarray) -> np.ndarray:
        """:meth:`matrix` at every coordinate of ``q`` at once: (n, 4, 4)."""
        q = np.asarray(q, float)
        return self.motion.matrices(np.radians(q) if self.unit == "deg" else q)


@dataclass(frozen=True)
class Kinematics:
    """Every jointed part's line, the driver and the driver's coordinates at the poses."""

    lines: dict[str, JointLine]
    driver: str
    coordinates: np.ndarray  # the driver's coordinate at each pose (its unit)

    @property
    def unit(self) -> str:
        return self.lines[self.driver].unit

    def moving(self) -> list[str]:
        """Parts the motion moves (the driver and every part coupled to it with a non-zero gain)."""
        return [n for n, line in self.lines.items() if line.coupled and line.gain != 0.0]

    def pose(self, part: str, x: float, extra: float = 0.0) -> np.ndarray:
        """World transform of ``part`` at driver coordinate ``x``, its own coordinate moved by
        ``extra`` more (its unit); identity for a part without a joint."""
        line = self.lines.get(part)
        if line is None:
            return np.eye(4)
        return line.matrix(line.coordinate(x) + extra)

    def poses(self, part: str, xs: np.ndarray) -> np.ndarray:
        """:meth:`pose` at every driver coordinate of ``xs`` at once: (n, 4, 4)."""
        xs = np.asarray(xs, float).reshape(-1)
        line = self.lines.get(part)
        if line is None:
            return np.broadcast_to(np.eye(4), (len(xs), 4, 4)).copy()
        q = line.gain * xs + line.offset if line.coupled else np.zeros_like(xs)
        return line.matrices(q)


def _motion(kind: str, axis, point) -> Rotation | Translation:
    return Rotation.about(axis, point) if kind == "revolute" else Translation.along(axis)


def kinematics(params) -> Kinematics:
    """The lines of :class:`Kinematics` from validated assembly parameters."""
    joints = {j.part: j for j in params.joint}
    driver = params.motion.part
    known: dict[str, tuple[float, float]] = {driver: (1.0, 0.0)}
    pending = list(params.couple)
    while pending:  # couples in any order: follow them outwards from the driver (validated acyclic)
        progressed = False
        for c in list(pending):
            if c.driver not in known:
                continue
            gain, offset = known[c.driver]
            src, dst = joints[c.driver].kind, joints[c.driven].kind
            if src == "revolute" and dst == "revolute":
                k, phase = c.ratio, c.phase_deg
            elif src == "revolute":  # → prismatic: mm per rad, the driver in degrees
                k, phase = c.mm_per_rad * math.pi / 180.0, c.phase_mm
            else:  # prismatic → revolute: rad per mm, the driven in degrees
                k, phase = math.degrees(c.rad_per_mm), c.phase_deg
            known[c.driven] = (k * gain, k * offset + phase)
            pending.remove(c)
            progressed = True
        if not progressed:
            break  # couples not reached from the driver: their joints stay at 0
    lines = {}
    for part, j in joints.items():
        gain, offset = known.get(part, (0.0, 0.0))
        lines[part] = JointLine(part, _motion(j.kind, j.axis, j.point), j.unit, gain, offset, part in known)
    unit = joints[driver].unit
    coordinates = np.asarray(params.motion.coordinates(unit), dtype=float)
    return Kinematics(lines, driver, coordinates)
