"""The roller-chain drive as a :class:`gearcheck.mechanism.Mechanism`: the hooks wired to the
package's modules (model, assembly and CAD hook, sweep, verdicts and report, ``new``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from gearcheck.drafting import NewInput
from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.roller_chain import MESH_TOL_MM, calc
from gearcheck.mechanisms.roller_chain.assembly import chain_assembly
from gearcheck.mechanisms.roller_chain.params import Params as ChainParams

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.drafting import Draft
    from gearcheck.figures import Figure
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body


class RollerChain(Mechanism):
    """A sprocket to ISO 606 (every tooth engaging, the form anywhere between the standard's
    minimum and maximum tooth gap) with a roller chain wrapped on it (docs/roller_chain.md)."""

    name = "roller_chain"
    section = "roller_chain"
    title = "ISO 606 sprocket with a roller chain (B or A series, 1–3 strands): engagement, polygon effect, wear"
    Params = ChainParams
    mesh_tol_mm = MESH_TOL_MM
    template = "roller_chain_12B_z21.toml"
    fuzz_seed_base = 4_000_000
    new_inputs: ClassVar[tuple[NewInput, ...]] = (
        NewInput("chain", "ISO 606 chain number, e.g. 12B or 16A"),
        NewInput("teeth", "sprocket teeth, e.g. 21"),
        NewInput("strands", "strands 1 to 3 (default 1)", required=False),
    )

    def analyse(self, params: ChainParams) -> list[Figure]:
        return calc(params)

    def assembly(self, params: ChainParams) -> Assembly:
        return chain_assembly(params)

    def tca(self, params: ChainParams) -> Any:
        """The polygon effect over two tooth pitches on the exact wrap: {"angle_rad": sprocket
        angles, "speed": the top span's speed over ω·R} as arrays (it dips to cos(180°/z) as each
        roller lands)."""
        import numpy as np

        from gearcheck.mechanisms.roller_chain.model import build_model

        wrap = build_model(params).wrap
        angles = np.linspace(0.0, 2.0 * wrap.cycle_rad, 241)
        return {"angle_rad": angles, "speed": np.array([wrap.top_speed_ratio(float(a)) for a in angles])}

    def display_frames(self, params: Any, assembly: Assembly) -> tuple[list[Any], str]:
        from gearcheck.mechanisms.roller_chain.assembly import display_frames

        return display_frames(assembly.layout)

    def smallest_clearance(self, params: ChainParams) -> Clearance | None:
        from gearcheck.mechanisms.roller_chain.model import build_model
        from gearcheck.results import Clearance

        m = build_model(params)
        found = [(m.seating_clearance_mm, f"seated roller ri − d1/2 = {m.seating_clearance_mm:.4f} mm"),
                 (m.inner_plate_gap_mm, f"inner plate to tooth side (b1 − bf1)/2 = {m.inner_plate_gap_mm:.4f} mm"),
                 (m.hub_gap_mm, f"seated plates over the hub {m.hub_gap_mm:.4f} mm")]
        value, label = min((abs(v), t) for v, t in found if v != 0.0)
        return Clearance(value, label)

    def parts(self, assembly: Assembly) -> list[Part]:
        from gearcheck.mechanisms.roller_chain.assembly import build_parts

        return build_parts(assembly)

    def plan(self, params: ChainParams, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        from gearcheck.mechanisms.roller_chain.sweep import plan_sweep

        return plan_sweep(assembly, bodies, options)

    def verdicts(self, params: ChainParams, outcome: SweepOutcome) -> list[Verdict]:
        from gearcheck.mechanisms.roller_chain.report import chain_verdicts

        return chain_verdicts(outcome)

    def report(self, params: ChainParams, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        from gearcheck.mechanisms.roller_chain.report import chain_report

        return chain_report(outcome, verdicts)

    def study_row(self, params: ChainParams, level: str) -> dict[str, float]:
        if level == "exact":
            from gearcheck.mechanisms.roller_chain.study import exact_row

            return exact_row(params)
        return super().study_row(params, level)

    def sample(self, data: dict, draw: Any) -> None:
        from gearcheck.mechanisms.roller_chain.sampling import sample_chain

        sample_chain(data, draw)

    def fuzz_options(self, params: ChainParams) -> dict:
        return {"steps_per_cycle": 8}

    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        from gearcheck.mechanisms.roller_chain.design import new_design

        return new_design(inputs, overrides)
