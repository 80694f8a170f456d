"""The nose-wheel steering rack and pinion as a :class:`gearcheck.mechanism.Mechanism`: each hook
wired to the module that does its job."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.steering import assembly as _assembly
from gearcheck.mechanisms.steering import calc as _calc
from gearcheck.mechanisms.steering import report as _report
from gearcheck.mechanisms.steering import sampling as _sampling
from gearcheck.mechanisms.steering import sweep as _sweep
from gearcheck.mechanisms.steering import verdicts as _verdicts
from gearcheck.mechanisms.steering.params import Params as SteeringParams
from gearcheck.drafting import NewInput

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.figures import Figure
    from gearcheck.drafting import Draft
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body


class Steering(Mechanism):
    """Trimmed end teeth, continuous power drive, towing disengage and re-engage."""

    name: ClassVar[str] = "steering"
    section: ClassVar[str] = "steering"
    title: ClassVar[str] = "nose-wheel steering rack and pinion: trimmed end teeth, towing disengage"
    Params = SteeringParams
    # Zero backlash: no non-zero clearance is checked, contact is decided within the sum of the
    # two meshes' bounds (0.02 mm at this tolerance).
    mesh_tol_mm: ClassVar[float] = 0.01
    template: ClassVar[str | None] = "nose_wheel_steering.toml"
    fuzz_seed_base: ClassVar[int] = 2_000_000
    nan_figures: ClassVar[frozenset[str]] = _sampling.NAN_FIGURES
    new_inputs: ClassVar[tuple[NewInput, ...]] = (
        NewInput("module", "module m in mm, e.g. --module 5"),
        NewInput("teeth", "pinion teeth z (the full pinion the sector is cut from), e.g. --teeth 34"),
    )

    def smallest_clearance(self, params: SteeringParams) -> Clearance | None:
        """None: the steering check decides no non-zero clearance. Its flanks mesh at zero backlash
        (contact and interference are decided within the contact tolerance), the stop and the
        re-engagement are events bracketed by bisection on the pinion angle, the grazing past the
        stop is at zero clearance, and the continuous drive rests on contact positions (where a
        pair's tangency point leaves a flank), not on a gap between parts."""
        return None

    def analyse(self, params: SteeringParams) -> list[Figure]:
        return _calc.calc(params)

    def tca(self, params: SteeringParams) -> Any:
        from gearcheck.mechanisms.steering import analysis as an
        from gearcheck.mechanisms.steering.tca import steering_tca

        g = an.geometry_from_params(params)
        return steering_tca(g, an.analyse_towing(g, params.towing.max_angle_deg))

    def assembly(self, params: SteeringParams) -> Assembly:
        return _assembly.assembly(params)

    def display_frames(self, params: Any, assembly: Assembly) -> tuple[list[Any], str]:
        from gearcheck.mechanisms.steering.display import display_frames

        return display_frames(params, assembly)

    def parts(self, assembly: Assembly) -> list[Part]:
        from gearcheck.mechanisms.steering.parts import parts

        return parts(assembly)

    def plan(self, params: SteeringParams, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        return _sweep.plan(params, assembly, bodies, options)

    def verdicts(self, params: SteeringParams, outcome: SweepOutcome) -> list[Verdict]:
        return _verdicts.verdicts(params, outcome)

    def report(self, params: SteeringParams, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        return _report.report(params, outcome, verdicts)

    def new(self, inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
        """The paper's design chain from the module and tooth count (:mod:`.derive`)."""
        from gearcheck.mechanisms.steering.derive import new

        return new(inputs, overrides)

    def sample(self, data: dict, draw: Any) -> None:
        _sampling.sample(data, draw)

    def fuzz_options(self, params: SteeringParams) -> dict:
        return {}
