"""Generic sweep tools, shared by every mechanism's plan: counted probes, contact proven from both
sides, clearing moves and event brackets. Each takes a predicate or a scene and numbers; none
knows a mechanism.

Vocabulary: a *flag* is a predicate on one motion coordinate (``collides(push_mm)``); the
bisection (:func:`gearcheck.geometry.bisect.bisect`) keeps it False at one end of a bracket and
True at the other.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry.bisect import Bracket, bisect
from gearcheck.sweep.engine import Distance, Scene

# A clearing move is sampled upwards in this many steps over its reach for the first free sample.
REACH_SAMPLES = 16


class CountedScene:
    """A :class:`Scene` that counts its FCL queries (a sweep's cost, for the speed figures)."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.queries = 0

    def set_pose(self, name: str, pose: np.ndarray) -> None:
        self.scene.set_pose(name, pose)

    def set_poses(self, poses: dict[str, np.ndarray]) -> None:
        self.scene.set_poses(poses)

    def collide(self, a: str, b: str) -> bool:
        self.queries += 1
        return self.scene.collide(a, b)

    def distance(self, a: str, b: str) -> Distance:
        self.queries += 1
        return self.scene.distance(a, b)


@dataclass(frozen=True)
class ContactProof:
    """A body pushed along ``direction`` (world) from its measured pose: free at
    distance − tolerance, colliding at distance + tolerance, contact bracketed by bisection.
    Contact proven from both sides: a clearance that a mesh distance reports must be where the
    bodies really start to touch."""

    label: str
    measured_mm: float
    tolerance_mm: float
    free_at_minus: bool
    touching_at_plus: bool
    free_mm: float
    touching_mm: float
    direction: np.ndarray

    @property
    def contact_mm(self) -> float:
        return 0.5 * (self.free_mm + self.touching_mm)

    def holds(self, bound_mm: float) -> bool:
        return (self.free_at_minus and self.touching_at_plus
                and abs(self.contact_mm - self.measured_mm) <= bound_mm)


def prove_contact(scene: Scene, fixed: str, moving: str, pose: np.ndarray, direction: np.ndarray,
                  measured_mm: float, tolerance_mm: float, label: str, bisect_tol: float) -> ContactProof:
    """Push ``moving`` (posed at ``pose``) along ``direction`` towards ``fixed``: it must be free
    at ``measured − tolerance``, collide at ``measured + tolerance``, and the contact is then
    bracketed to ``bisect_tol``. The scene is left with ``moving`` at ``pose``."""
    direction = np.asarray(direction, float) / np.linalg.norm(direction)

    def collides(push_mm: float) -> bool:
        moved = pose.copy()
        moved[:3, 3] += push_mm * direction
        scene.set_pose(moving, moved)
        return scene.collide(fixed, moving)

    lo, hi = measured_mm - tolerance_mm, measured_mm + tolerance_mm
    free_lo, touch_hi = not collides(lo), collides(hi)
    free, touching = math.nan, math.nan
    if free_lo and touch_hi:
        bracket = bisect(collides, lo, hi, bisect_tol)
        free, touching = bracket.free, bracket.touching
    scene.set_pose(moving, pose)
    return ContactProof(label, measured_mm, tolerance_mm, free_lo, touch_hi, free, touching, direction)


def smallest_clearing_move(hits_at: Callable[[float], bool], reach: float, predicted: float, tol: float,
                           samples: int = REACH_SAMPLES) -> float | None:
    """Smallest move d in (0, reach] with ``hits_at(d)`` False, given ``hits_at(0)`` True:
    samples the reach upwards (the first free sample bounds the move; a jammed pose has none
    and returns None, so a part never jumps past a tooth), then bisection between the last
    colliding and the first free sample. ``predicted`` (expected from the last step) only
    narrows the first bracket when it holds."""
    if predicted > 0.0:
        near, far = max(0.995 * predicted - 2e-4, 0.0), 1.005 * predicted + 2e-4
        if far <= reach and not hits_at(far) and (near == 0.0 or hits_at(near)):
            return bisect(hits_at, far, near, tol).free
    previous = 0.0
    for i in range(1, samples + 1):
        d = reach * i / samples
        if not hits_at(d):
            return bisect(hits_at, d, previous, tol).free
        previous = d
    return None


def clearing_distance(hits_at: Callable[[float], bool], start: float, limit: float, tol: float) -> float:
    """Smallest move that clears a colliding pose (``hits_at(0)`` True): doubled from ``start``
    until free, then bisected; the free end of the bracket, or ``limit`` if none within it."""
    span = start
    while hits_at(span):
        span *= 2.0
        if span > limit:
            return limit
    return bisect(hits_at, span, 0.0, tol).free


def contact_distance(hits_at: Callable[[float], bool], start: float, limit: float, tol: float) -> float:
    """Smallest move that brings a free pose (``hits_at(0)`` False) to contact: doubled from
    ``start`` until it collides, then bisected; the touching end, or ``limit`` if none within it."""
    span = start
    while not hits_at(span):
        span *= 2.0
        if span > limit:
            return limit
    return bisect(hits_at, 0.0, span, tol).touching


def grid_event(grid: np.ndarray, flags: np.ndarray, flag_at: Callable[[float], bool], tol: float,
               first: bool) -> Bracket | None:
    """Bracket of where ``flag_at`` starts holding (``first``: its first False → True along
    ``grid``) or stops holding (its last True → False), from the flags on the grid, refined by
    bisection to ``tol``. None when the flag never changes inside the grid."""
    hit = np.flatnonzero(flags)
    if first:
        if not hit.size or hit[0] == 0:
            return None
        i = int(hit[0])
        return bisect(flag_at, float(grid[i - 1]), float(grid[i]), tol)
    if not hit.size or hit[-1] == len(grid) - 1:
        return None
    i = int(hit[-1])
    return bisect(flag_at, float(grid[i + 1]), float(grid[i]), tol)


def extrapolated_event(grid: np.ndarray, flags_at: Callable[[float], np.ndarray],
                       flag_at: Callable[[float, float], bool], delta: float, tol: float,
                       first: bool) -> tuple[float, Bracket | None]:
    """An event decided at an offset δ from contact (``flag_at(δ, x)``, flags on the grid
    ``flags_at(δ)``), bracketed at δ and 2δ and extrapolated linearly to δ = 0:
    x = 2·x(δ) − x(2δ). For events at zero clearance, which a mesh decides only within its
    chord error. Returns the extrapolated value and the bracket at δ (NaN, None: no event)."""
    brackets = []
    for d in (delta, 2.0 * delta):
        def at(x: float, d: float = d) -> bool:
            return flag_at(d, x)

        b = grid_event(grid, flags_at(d), at, tol, first)
        if b is None:
            return math.nan, None
        brackets.append(b)
    return 2.0 * brackets[0].value - brackets[1].value, brackets[0]


def meshes_overlap(bodies, worst) -> bool:
    """Whether the two meshes intersect at a worst pose (FCL collide on the whole parts)."""
    names = [n.partition(".")[0] for n in (worst.part_a, worst.part_b)]
    scene = Scene([bodies[names[0]].scaled(worst.scale_a).mesh, bodies[names[1]].scaled(worst.scale_b).mesh])
    scene.set_pose(names[0], np.asarray(worst.pose_a, float))
    scene.set_pose(names[1], np.asarray(worst.pose_b, float))
    return scene.collide(names[0], names[1])


def mesh_nearest_midpoint(bodies, worst) -> np.ndarray | None:
    """Where the meshes come closest at a worst pose (world frame): the exact distance is then
    measured on the faces around it only. None for a feature of a part ("link_03.plate"): the
    whole feature is measured."""
    names = [worst.part_a, worst.part_b]
    if any("." in n for n in names):
        return None
    scene = Scene([bodies[worst.part_a].scaled(worst.scale_a).mesh, bodies[worst.part_b].scaled(worst.scale_b).mesh])
    scene.set_pose(worst.part_a, np.asarray(worst.pose_a, float))
    scene.set_pose(worst.part_b, np.asarray(worst.pose_b, float))
    d = scene.distance(worst.part_a, worst.part_b)
    return 0.5 * (d.point_a + d.point_b)
