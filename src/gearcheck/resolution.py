"""Mesh resolution by design: a sweep proves nothing about a clearance its meshes cannot
resolve, so the mesh tolerance follows from the smallest clearance the design asks to decide.

Before meshing, each mechanism names that clearance from its exact model
(:meth:`gearcheck.mechanism.Mechanism.smallest_clearance`). A clearance between two parts
carries both meshes' errors, so the rule reads

    pair bound = bound(part A) + bound(part B) ≤ c / 10

and, both parts being meshed at one chordal tolerance, the tolerance is c / 20 (never coarser
than the mechanism's default). After meshing the rule is checked on the bounds the meshes
actually have (Body.error_bound_mm: the larger of the chordal tolerance and the deviation
measured on the B-rep), pairing the two largest — the worst pair any clearance can lie between.

Never a refusal: where no practical mesh resolves the clearance (c / 20 finer than
:data:`FINEST_TOL_MM`), or the user fixed a coarser tolerance (``--tol`` or a ``mesh_tol_mm``
key), the meshes stay as they are, ``mesh_resolves`` is False, and the verdicts on that
clearance rest on the exact model, confirmed at the worst poses on the exact B-rep; the report
says so. A zero or negative clearance is a design's failure (its verdicts say so), never bad
input. Pure: no numpy, CadQuery or FCL.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from gearcheck.design import TOL_MIN_MM
from gearcheck.results import Clearance

# The pair's mesh-error bound may be at most this fraction of the smallest clearance decided.
BOUND_PER_CLEARANCE = 0.1
# Parts per clearance: both sides of a gap are meshed at the same chordal tolerance.
PARTS_PER_PAIR = 2
# The finest tolerance a mesh is made at to resolve a clearance (finer: the exact B-rep decides).
FINEST_TOL_MM = TOL_MIN_MM
# The most triangles one run's meshes may hold (each distinct solid once), estimated before
# meshing: about 0.6 KB each through meshing, the sweep's BVHs on every process and the files,
# so some 2 GB at the budget. A finer tolerance asked for is refused with the finest that fits;
# one the resolution rule would choose stops at the budget (the exact B-rep decides the rest).
TRIANGLE_BUDGET = 3_000_000


@dataclass(frozen=True)
class MeshPlan:
    """The chordal tolerance a run meshes at, and why."""

    tol_mm: float
    requested_mm: float  # --tol / mesh_tol_mm, else the mechanism's default
    explicit: bool  # the user fixed the tolerance: it is used as given
    clearance: Clearance | None  # the smallest clearance to decide (exact model, before meshing)
    budget_limited: bool = False  # the rule's tolerance was coarsened to fit TRIANGLE_BUDGET

    @property
    def needed_mm(self) -> float | None:
        """The tolerance that resolves the clearance: c / 10 per pair, c / 20 per part."""
        if self.clearance is None:
            return None
        return BOUND_PER_CLEARANCE * self.clearance.value_mm / PARTS_PER_PAIR

    @property
    def refined(self) -> bool:
        return self.tol_mm < self.requested_mm

    def manifest(self) -> dict:
        """How the tolerance was chosen, for manifest.json (provenance: summary.json holds only the
        tolerance used, so a re-run from params.toml, which records it, is byte-identical)."""
        out: dict = {"tol_mm": self.tol_mm, "requested_tol_mm": self.requested_mm, "explicit": self.explicit,
                     "refined": self.refined}
        if self.clearance is not None:
            out |= {"smallest_clearance_mm": self.clearance.value_mm, "smallest_clearance": self.clearance.label,
                    "resolving_tol_mm": self.needed_mm}
        if self.budget_limited:
            out["triangle_budget"] = TRIANGLE_BUDGET
        return out


def plan_tolerance(requested_mm: float, explicit: bool, clearance: Clearance | None) -> MeshPlan:
    """The tolerance to mesh at: as given when ``explicit``; otherwise the finer of the request
    and what the clearance needs, unless that is finer than any practical mesh (then the
    request: the exact B-rep decides, a finer mesh that still cannot resolve it buys nothing)."""
    if clearance is not None and not clearance.value_mm > 0.0:
        raise ValueError(f"a clearance to resolve is a magnitude > 0, got {clearance.value_mm!r} ({clearance.label})")
    plan = MeshPlan(requested_mm, requested_mm, explicit, clearance)
    needed = plan.needed_mm
    if explicit or needed is None or needed >= requested_mm or needed < FINEST_TOL_MM:
        return plan
    # a round figure just under what is needed (3 significant digits, rounded down)
    tol = float(f"{needed:.3g}")
    tol = tol if tol <= needed else float(f"{needed * (1 - 5e-3):.3g}")
    return MeshPlan(tol, requested_mm, explicit, clearance)


def fitting_tolerance(tol_mm: float, estimated: int, budget: int,
                      exponent: float = 1.1) -> float:
    """The finest tolerance (2 significant digits, rounded up) at which meshes estimated at
    ``estimated`` triangles for ``tol_mm`` hold at most ``budget`` (triangles ∝ tol^−exponent)."""
    fit = tol_mm * (estimated / budget) ** (1.0 / exponent)
    rounded = float(f"{fit:.2g}")
    return rounded if rounded >= fit else float(f"{fit * 1.05:.2g}")


def pair_bound(bodies: Mapping[str, Any]) -> tuple[str, float]:
    """The two largest mesh-error bounds (parts of one shape counted once per instance) summed:
    no clearance between two meshed parts carries a larger error. Returns "a + b" and the sum."""
    ranked = sorted(bodies, key=lambda n: (-float(bodies[n].error_bound_mm), n))
    if len(ranked) < 2:
        name = ranked[0] if ranked else "—"
        return name, float(bodies[name].error_bound_mm) if ranked else 0.0
    a, b = ranked[:2]
    return f"{a} + {b}", float(bodies[a].error_bound_mm) + float(bodies[b].error_bound_mm)


@dataclass(frozen=True)
class Resolution:
    """The rule as checked on the meshes a run made."""

    plan: MeshPlan
    pair: str  # the parts whose bounds were summed
    pair_bound_mm: float
    largest_part_bound_mm: float

    @property
    def allowed_mm(self) -> float | None:
        c = self.plan.clearance
        return None if c is None else BOUND_PER_CLEARANCE * c.value_mm

    @property
    def resolves(self) -> bool:
        """True when the meshes resolve the smallest clearance (or there is none to resolve)."""
        allowed = self.allowed_mm
        return allowed is None or self.pair_bound_mm <= allowed

    def summary(self) -> dict:
        """summary.json's ``mesh_resolution`` (plain numbers, deterministic)."""
        out: dict[str, float] = {"tol_mm": self.plan.tol_mm, "pair_error_bound_mm": self.pair_bound_mm,
                                 "largest_part_error_bound_mm": self.largest_part_bound_mm,
                                 "rule_met": int(self.resolves)}
        c = self.plan.clearance
        if c is not None:
            out |= {"smallest_clearance_mm": c.value_mm, "allowed_bound_mm": BOUND_PER_CLEARANCE * c.value_mm,
                    "resolving_tol_mm": float(self.plan.needed_mm or 0.0)}
        return out

    def describe(self) -> str:
        """One sentence for the report: the rule, the figures, and which evidence decides."""
        p, c = self.plan, self.plan.clearance
        source = "as given" if p.explicit else ("refined from " f"{p.requested_mm:g} mm" if p.refined
                                                 else "the mechanism's default")
        head = (f"Mesh resolution: meshed at {p.tol_mm:g} mm ({source}); pair mesh-error bound "
                f"{self.pair_bound_mm:.4g} mm ({self.pair})")
        if c is None:
            return (head + "; no non-zero clearance is decided here (zero-backlash contact, decided within the "
                    "contact tolerance).")
        allowed = BOUND_PER_CLEARANCE * c.value_mm
        if self.resolves:
            return head + f" ≤ 1/10 of the smallest clearance decided, {c.label} = {c.value_mm:.4g} mm " \
                          f"(allowed ≤ {allowed:.4g} mm): the mesh sweep resolves it."
        why = (f"the tolerance was fixed at {p.tol_mm:g} mm" if p.explicit else
               f"resolving it needs {p.needed_mm:.2g} mm, finer than the finest practical mesh ({FINEST_TOL_MM:g} mm)")
        return (head + f" > 1/10 of the smallest clearance decided, {c.label} = {c.value_mm:.4g} mm (allowed ≤ "
                f"{allowed:.4g} mm; {why}): the verdicts on it rest on the exact model, confirmed at the worst "
                f"poses on the exact B-rep, not on the mesh's sign.")


def assess(plan: MeshPlan, bodies: Mapping[str, Any]) -> Resolution:
    """The rule on the meshes made under ``plan``."""
    pair, bound = pair_bound(bodies)
    largest = max((float(b.error_bound_mm) for b in bodies.values()), default=0.0)
    return Resolution(plan, pair, bound, largest)
