"""A STEP assembly as a :class:`gearcheck.mechanism.Mechanism`: the hooks wired to the package's
modules (declared kinematics, the STEP products as solids, the pose sweep, verdicts and report)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from gearcheck.drafting import NewInput
from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.assembly import MESH_TOL_MM, calc
from gearcheck.mechanisms.assembly.params import Params as AssemblyParams

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.drafting import Draft
    from gearcheck.figures import Figure
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body

DISPLAY_FRAMES = 48


def motion_setting(params: AssemblyParams) -> tuple[str, float, str, float]:
    """The template field that sets the poses (``motion.step_deg``, or ``motion.stops_deg`` as a
    count), its value, its unit and the motion's extent (0 for stops): what a refusal names."""
    joint = params.joint_of(params.motion.part)
    unit = joint.unit if joint is not None else "deg"
    stops = getattr(params.motion, f"stops_{unit}")
    if stops is not None:
        return f"motion.stops_{unit}", float(len(stops)), unit, 0.0
    start, end = getattr(params.motion, f"start_{unit}"), getattr(params.motion, f"end_{unit}")
    return f"motion.step_{unit}", float(getattr(params.motion, f"step_{unit}")), unit, abs(float(end) - float(start))


class StepAssembly(Mechanism):
    """Any STEP assembly: parts by their products, joints, couples and a driving motion declared
    in the template (docs/assembly.md)."""

    name = "assembly"
    section = "assembly"
    title = "your own STEP assembly: declared joints, couples and motion; clearances, contact and play"
    Params = AssemblyParams
    mesh_tol_mm = MESH_TOL_MM
    template = "assembly_spur_pair.toml"
    consistency_verdicts: ClassVar[tuple[str, ...]] = ()
    new_inputs: ClassVar[tuple[NewInput, ...]] = (
        NewInput("step", "the STEP file whose products are the parts, e.g. pair.step"),
    )

    def analyse(self, params: AssemblyParams) -> list[Figure]:
        return calc(params)

    def assembly(self, params: AssemblyParams) -> Assembly:
        from gearcheck.mechanisms.assembly.assembly import step_assembly

        return step_assembly(params, self.name)

    def smallest_clearance(self, params: AssemblyParams) -> Clearance | None:
        """The smallest positive clearance a [[require]] asks for, the contact tolerance where a
        pair may touch, the least play in mm where one is required: the meshes must resolve it."""
        from gearcheck.results import Clearance

        found = [(r.min_clearance_mm, f"required clearance {r.parts[0]} – {r.parts[1]} "
                                      f"{r.min_clearance_mm:g} mm") for r in params.require
                 if r.min_clearance_mm is not None and r.min_clearance_mm > 0]
        if any(r.contact for r in params.require):
            tol = params.assembly.contact_tolerance_mm
            found.append((tol, f"contact tolerance {tol:g} mm"))
        if params.play is not None and params.play.min_mm is not None and params.play.min_mm > 0:
            found.append((params.play.min_mm, f"required play of {params.play.part} {params.play.min_mm:g} mm"))
        if not found:
            return None
        value, label = min(found)
        return Clearance(value, label)

    def display_frames(self, params: AssemblyParams, assembly: Assembly) -> tuple[list[Any], str]:
        from gearcheck.scene import PoseView

        kin = assembly.layout.kin
        x = kin.coordinates
        moving = kin.moving()
        step = max(1, len(x) // DISPLAY_FRAMES)
        frames = [PoseView(f"{kin.driver} {x[i]:g} {kin.unit}", {p: kin.pose(p, float(x[i])) for p in moving})
                  for i in range(0, len(x), step)]
        return frames, f"{kin.driver} from {x[0]:g} to {x[-1]:g} {kin.unit}"

    def parts(self, assembly: Assembly) -> list[Part]:
        from gearcheck.mechanisms.assembly.assembly import build_parts

        return build_parts(assembly)

    def plan(self, params: AssemblyParams, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        from gearcheck.mechanisms.assembly.sweep import plan_sweep

        return plan_sweep(assembly, bodies, options, motion_setting(params))

    def verdicts(self, params: AssemblyParams, outcome: SweepOutcome) -> list[Verdict]:
        from gearcheck.mechanisms.assembly.report import assembly_verdicts

        return assembly_verdicts(outcome)

    def report(self, params: AssemblyParams, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        from gearcheck.mechanisms.assembly.report import assembly_report

        return assembly_report(outcome, verdicts)

    def fuzz_options(self, params: AssemblyParams) -> dict:
        return {"stride": 4}

    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        from gearcheck.mechanisms.assembly.design import new_template

        return new_template(inputs, overrides)
