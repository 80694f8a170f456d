"""The bevel-gear differential of the Zhurong Mars rover as a :class:`gearcheck.mechanism.Mechanism`:
the paper's cold-backlash model (:func:`.calc`), the parts (:mod:`.assembly`, :mod:`.parts`), the
play sweep over temperature against the exact-flank model (:mod:`.sweep`, :mod:`.reduce`,
:mod:`.temperature`), the thinning solved from a measured backlash (:mod:`.calibration`), the verdicts
and the report (:mod:`.verdicts`, :mod:`.report`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from gearcheck.drafting import NewInput
from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.differential import MESH_TOL_MM, calc
from gearcheck.mechanisms.differential.params import Params as DifferentialParams

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.drafting import Draft
    from gearcheck.figures import Figure
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body

# The fuzz sweeps at reduced sampling: this many drive angles over the play period, its own shim.
FUZZ_ANGLES_PER_CYCLE = 4


class Differential(Mechanism):
    name = "differential"
    section = "differential"
    title = "bevel-gear differential: backlash lost on cooling, shims"
    Params = DifferentialParams
    mesh_tol_mm = MESH_TOL_MM
    template = "zhurong_differential.toml"
    nan_figures = frozenset()
    new_inputs: ClassVar[tuple[NewInput, ...]] = (
        NewInput("module", "outer (transverse) module, mm, e.g. 3"),
        NewInput("teeth", "small/big tooth counts, e.g. 14/30"),
    )

    def analyse(self, params: DifferentialParams) -> list[Figure]:
        return calc(params)

    def assembly(self, params: DifferentialParams) -> Assembly:
        from gearcheck.mechanisms.differential.assembly import build_assembly

        return build_assembly(params)

    def display_frames(self, params: Any, assembly: Assembly) -> tuple[list[Any], str]:
        from gearcheck.mechanisms.differential.display import display_frames

        return display_frames(params, assembly)

    def smallest_clearance(self, params: DifferentialParams) -> Clearance | None:
        """The least play per side (exact flanks, cycle minimum) at the template's shim over the
        meshed temperatures (warm, the cold design point, the operating range's ends, the storage
        minimum) nearest zero but not zero — an overlap by its depth — as the arc it spans on
        d1/2 (mm); the sweep decides a verdict on each of them."""
        from gearcheck.mechanisms.differential.poses import gear_specs
        from gearcheck.mechanisms.differential.temperature import clearance, meshed_plays, meshed_states

        specs = gear_specs(params)
        try:
            plays = meshed_plays(params, specs=specs)
        except RuntimeError:  # no contact within the exact model's reach: the sweep says so itself
            return None
        return clearance(specs, params.shim.thickness_mm, plays, dict(meshed_states(params)))

    def tca(self, params: DifferentialParams) -> dict[str, Any]:
        from gearcheck.mechanisms.differential.tca import design_tca

        return design_tca(params)

    def study_row(self, params: DifferentialParams, level: str) -> dict[str, float]:
        from gearcheck.mechanisms.differential import study

        if level == "contact":
            from gearcheck.mechanisms.differential.poses import gear_specs
            from gearcheck.mechanisms.differential.tca import study_figures

            return study_figures(params, gear_specs(params))
        return study.exact_row(params) if level == "exact" else study.analytical_row(params)

    def study_batch(self, params: DifferentialParams, columns: Mapping[str, Any]) -> dict[str, Any] | None:
        from gearcheck.mechanisms.differential.study import paper_model

        return paper_model(params, columns)

    def parts(self, assembly: Assembly) -> list[Part]:
        from gearcheck.mechanisms.differential.parts import build_parts

        return build_parts(assembly)

    def plan(self, params: DifferentialParams, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        from gearcheck.mechanisms.differential.sweep import make_plan

        return make_plan(params, assembly, bodies, options)

    def verdicts(self, params: DifferentialParams, outcome: SweepOutcome) -> list[Verdict]:
        from gearcheck.mechanisms.differential.verdicts import verdicts

        return verdicts(params, outcome)

    def report(self, params: DifferentialParams, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        from gearcheck.mechanisms.differential.report import report

        return report(params, outcome, verdicts)

    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        """A design from ``--module`` and ``--teeth SMALL/BIG``, every other value derived
        (:mod:`.derive`: cone geometry, the common apex, Gleason's shift, the standard backlash)."""
        from gearcheck.mechanisms.differential.derive import new

        return new(inputs, overrides)

    def sample(self, data: dict, draw: Any) -> None:
        from gearcheck.mechanisms.differential.sampling import sample_differential

        sample_differential(data, draw)

    def fuzz_options(self, params: DifferentialParams) -> dict:
        return {"angles_per_cycle": FUZZ_ANGLES_PER_CYCLE, "shims_mm": [params.shim.thickness_mm]}
