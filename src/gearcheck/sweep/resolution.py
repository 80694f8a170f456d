"""The mesh-resolution rule (issue 11): a sweep proves nothing about a clearance its meshes
cannot resolve, so after meshing and sweeping, a measured mesh-error bound larger than 1/10 of
the smallest non-zero clearance the check decided a verdict on is rejected like a bad
parameter — one line naming ``--tol``, the value used, and the allowed range.

The clearance comes from each check's exact model (CheckResult.smallest_clearance), the bound
from the meshes themselves (Body.error_bound_mm: the larger of the requested chordal tolerance
and the deviation measured on the B-rep). Pure: numpy-free, no CadQuery or FCL.
"""

from __future__ import annotations

from gearcheck.params import ParamError
from gearcheck.sweep.result import CheckResult

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
        return {"mesh_error_bound_mm": bound, "rule_met": 1}
    return {"mesh_error_bound_mm": bound, "smallest_clearance_mm": c.value_mm,
            "allowed_bound_mm": BOUND_PER_CLEARANCE * c.value_mm,
            "rule_met": int(bound <= BOUND_PER_CLEARANCE * c.value_mm)}


def describe(result: CheckResult, bodies: dict) -> str:
    """One sentence for the report."""
    name, bound = largest_bound(bodies)
    c = result.smallest_clearance
    if c is None:
        return (f"Mesh resolution: no non-zero clearance is checked here (zero-backlash contact, "
                f"decided within the contact tolerance); largest mesh-error bound {bound:.4f} mm ({name}).")
    return (f"Mesh resolution: largest mesh-error bound {bound:.4f} mm ({name}) ≤ 1/10 of the smallest "
            f"clearance checked, {c.label} = {c.value_mm:.4f} mm (allowed ≤ {BOUND_PER_CLEARANCE * c.value_mm:.4f} mm).")


def enforce(result: CheckResult, bodies: dict, tol_mm: float, source: str = "") -> None:
    """Raise ParamError when the meshes are too coarse for the smallest clearance checked."""
    c = result.smallest_clearance
    if c is None:
        return
    name, bound = largest_bound(bodies)
    allowed = BOUND_PER_CLEARANCE * c.value_mm
    if bound > allowed:
        raise ParamError(
            "--tol", tol_mm,
            f"allowed ≤ {allowed:.4g} mm: the mesh-error bound, {bound:.4g} mm ({name}), must be at most "
            f"1/10 of the smallest clearance checked, {c.label} = {c.value_mm:.4g} mm", source)
