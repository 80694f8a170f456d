"""What a worker runs for a sweep plan (:class:`gearcheck.mechanism.SweepPlan`): the scene it
builds once from the plan's meshes, and the call of one task against it. Module-level, so an
executor can send them to another process by name."""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

from gearcheck.sweep.bodies import MeshData
from gearcheck.sweep.engine import Scene


def make_scene(meshes: list[MeshData]) -> Scene:
    """A worker's scene: one BVH per mesh, built once, when a task first uses it."""
    return Scene(meshes)


def run_task(scene: Scene, fn: Callable[..., Any], args: tuple) -> Any:
    """One task of a plan: ``fn(scene, *args)``."""
    return fn(scene, *args)


def run_plan(executor: Any, plan: Any, progress: Callable[[int], None] | None = None) -> list:
    """Every task of a plan (:class:`gearcheck.mechanism.SweepPlan`) on ``executor``, in the
    plan's ``order`` if it gives one, its ``first`` work done by this process while the workers
    start; results in task order. An executor whose ``map`` takes no ``first`` (one written
    before it existed) gets the first work done here, before the map."""
    order = plan.order if plan.order is not None else list(range(len(plan.tasks)))
    weights = [plan.weights[i] for i in order] if plan.weights is not None else None
    first: dict[str, Any] = {}
    if plan.first is not None:
        if "first" in inspect.signature(executor.map).parameters:
            first["first"] = plan.first
        else:
            plan.first()
    ran = executor.map(run_task, [plan.tasks[i] for i in order], setup=make_scene, shared=plan.meshes,
                       progress=progress, weights=weights, **first)
    results: list[Any] = [None] * len(order)
    for i, result in zip(order, ran, strict=True):
        results[i] = result
    return results
