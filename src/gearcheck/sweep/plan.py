"""What a worker runs for a sweep plan (:class:`gearcheck.mechanism.SweepPlan`): the scene it
builds once from the plan's meshes, and the call of one task against it. Module-level, so an
executor can send them to another process by name."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from gearcheck.sweep.bodies import MeshData
from gearcheck.sweep.engine import Scene


def make_scene(meshes: list[MeshData]) -> Scene:
    """A worker's scene: one BVH per mesh, built once."""
    return Scene(meshes)


def run_task(scene: Scene, fn: Callable[..., Any], args: tuple) -> Any:
    """One task of a plan: ``fn(scene, *args)``."""
    return fn(scene, *args)
