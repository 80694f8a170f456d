"""The triangle budget: meshes fine enough to exhaust the machine are never made. Before meshing
finer than the mechanism's default, the triangles are estimated from a probe mesh 8× coarser
(:func:`gearcheck.cad.mesh.estimate_triangles`); the meshing counts too as it goes
(:class:`gearcheck.cad.mesh.TooManyTriangles`). Over :data:`gearcheck.resolution.TRIANGLE_BUDGET`,
a tolerance the user asked for is refused in one line with the finest that fits; one the
resolution rule or the mechanism chose is coarsened to fit (the exact B-rep decides what the
meshes then cannot resolve)."""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Any

from gearcheck.design import TOL_MAX_MM
from gearcheck.params import ParamError

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.design import Design
    from gearcheck.resolution import MeshPlan

log = logging.getLogger("gearcheck")


def within_budget(design: Design, plan: MeshPlan, parts: list[Part], tol_mm: float | None) -> MeshPlan:
    """Before meshing finer than the mechanism's default: the triangles estimated from a coarse
    probe mesh (:func:`gearcheck.cad.mesh.estimate_triangles`, about 1/8 of the fine mesh's work)
    against :data:`gearcheck.resolution.TRIANGLE_BUDGET` (:func:`_over_budget` says what then)."""
    from gearcheck import resolution
    from gearcheck.cad.mesh import estimate_triangles

    if plan.tol_mm >= float(design.impl.mesh_tol_mm):
        return plan
    t0 = time.perf_counter()
    estimated = estimate_triangles(_distinct_solids(parts), plan.tol_mm)
    log.info("stage plan: about %d triangles at %g mm (estimated in %.2f s; budget %d)", estimated, plan.tol_mm,
             time.perf_counter() - t0, resolution.TRIANGLE_BUDGET)
    return plan if estimated <= resolution.TRIANGLE_BUDGET else over_budget(design, plan, parts, tol_mm, estimated)


def _distinct_solids(parts: list[Part]) -> list[Any]:
    return list({id(p.solid): p.solid for p in parts}.values())


# The tolerance named as fitting the budget is one whose estimate holds at most this share of it
# (the estimate can be 0.8 of the real count, gearcheck.cad.mesh).
FIT_SHARE = 0.8


def over_budget(design: Design, plan: MeshPlan, parts: list[Part], tol_mm: float | None, triangles: int) -> MeshPlan:
    """Meshes of more triangles than :data:`gearcheck.resolution.TRIANGLE_BUDGET` (estimated, or
    counted while meshing): the finest tolerance whose estimate fits (searched from the count,
    a few coarse probe meshes). A tolerance the user asked for is refused with it (one line,
    nothing written); one the resolution rule or the mechanism chose is coarsened to it (the
    exact B-rep decides what the meshes cannot resolve)."""
    import dataclasses

    from gearcheck import resolution
    from gearcheck.cad.mesh import estimate_triangles

    budget = resolution.TRIANGLE_BUDGET
    fit, count = plan.tol_mm, triangles
    for _ in range(8):
        fit = min(resolution.fitting_tolerance(fit, count, int(FIT_SHARE * budget)), TOL_MAX_MM)
        count = estimate_triangles(_distinct_solids(parts), fit)
        if count <= FIT_SHARE * budget or fit >= TOL_MAX_MM:
            break
    if plan.explicit:
        field = "--tol" if tol_mm is not None else "mesh_tol_mm"
        raise ParamError(field, plan.tol_mm, f"the meshes of this design would hold about {triangles:,} triangles, "
                         f"over the budget of {budget:,}: allowed {fit:g} mm or coarser")
    log.warning("%s: meshes at %g mm would hold about %d triangles, over the budget of %d: meshing at %g mm "
                "(the exact B-rep decides what the meshes cannot resolve)", design.name, plan.tol_mm, triangles,
                budget, fit)
    return dataclasses.replace(plan, tol_mm=fit, budget_limited=True)
