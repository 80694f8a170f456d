"""The mesh-resolution rule: a sweep proves nothing about a clearance its meshes
cannot resolve, so after meshing and sweeping, a measured mesh-error bound larger than 1/10 of
the smallest non-zero clearance the check decided a verdict on is rejected like a bad
parameter — one line naming ``--tol``, the value used, and the allowed range.

The clearance comes from each check's exact model (CheckResult.smallest_clearance), the bound
from the meshes themselves (Body.error_bound_mm: the larger of the requested chordal tolerance
and the deviation measured on the B-rep). Pure: numpy-free, no CadQuery or FCL.
"""

from __future__ import annotations

from gearcheck.results import CheckResult

# The mesh error may be at most this fraction of the smallest clearance checked.
BOUND_PER_CLEARANCE = 0.1


def largest_bound(bodies: dict) -> tuple[str, float]:
    """The body with the largest mesh-error bound, and that bound (mm)."""
    name = max(sorted(bodies), key=lambda n: bodies[n].error_bound_mm)
    return name, float(bodies[name].error_bound_mm)


def resolution_summary(result: CheckResult, bodies: dict) -> dict:
    """Figures of the rule for summary.json and the report (deterministic)."""
    _, bound = largest_bound(bodies)
    c = result.smallest_clearance
    if c is None:  # nothing to resolve
        return {"largest_part_error_bound_mm": bound, "rule_met": 1}
    return {"largest_part_error_bound_mm": bound, "smallest_clearance_mm": c.value_mm,
            "allowed_bound_mm": BOUND_PER_CLEARANCE * c.value_mm,
            "rule_met": int(bound <= BOUND_PER_CLEARANCE * c.value_mm)}


def describe(result: CheckResult, bodies: dict) -> str:
    """One sentence for the report."""
    name, bound = largest_bound(bodies)
    c = result.smallest_clearance
    if c is None:
        return (f"Mesh resolution: no non-zero clearance is checked here (zero-backlash contact, "
                f"decided within the contact tolerance); largest mesh-error bound {bound:.4f} mm ({name}).")
    allowed = BOUND_PER_CLEARANCE * c.value_mm
    return (f"Mesh resolution: largest mesh-error bound {bound:.4f} mm ({name}) ≤ 1/10 of the smallest "
            f"clearance checked, {c.label} = {c.value_mm:.4f} mm (allowed ≤ {allowed:.4f} mm).")


def violation(result: CheckResult, bodies: dict) -> str | None:
    """Why the meshes are too coarse for the smallest clearance checked (the allowed range of
    ``--tol``, one line), or None when the rule is met."""
    c = result.smallest_clearance
    if c is None:
        return None
    name, bound = largest_bound(bodies)
    allowed = BOUND_PER_CLEARANCE * c.value_mm
    if bound <= allowed:
        return None
    return (f"allowed ≤ {allowed:.4g} mm: the mesh-error bound, {bound:.4g} mm ({name}), must be at most "
            f"1/10 of the smallest clearance checked, {c.label} = {c.value_mm:.4g} mm")
