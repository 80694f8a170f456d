"""The bevel-gear differential of the Zhurong Mars rover as a :class:`gearcheck.mechanism.Mechanism`:
the paper's cold-backlash model (:func:`.calc`), the parts (:mod:`.assembly`, :mod:`.parts`), the
warm/cold play sweep against the exact-flank model (:mod:`.sweep`, :mod:`.reduce`), the verdicts
and the report (:mod:`.verdicts`, :mod:`.report`)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.differential import MESH_TOL_MM, calc
from gearcheck.mechanisms.differential.params import Params as DifferentialParams

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.figures import Figure
    from gearcheck.results import Report, SweepOutcome, Verdict
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

    def analyse(self, params: DifferentialParams) -> list[Figure]:
        return calc(params)

    def assembly(self, params: DifferentialParams) -> Assembly:
        from gearcheck.mechanisms.differential.assembly import build_assembly

        return build_assembly(params)

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

    def sample(self, data: dict, draw: Any) -> None:
        from gearcheck.mechanisms.differential.sampling import sample_differential

        sample_differential(data, draw)

    def fuzz_options(self, params: DifferentialParams) -> dict:
        return {"angles_per_cycle": FUZZ_ANGLES_PER_CYCLE, "shims_mm": [params.shim.thickness_mm]}
