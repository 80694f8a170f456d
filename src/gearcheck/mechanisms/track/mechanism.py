"""The track drive sprocket as a :class:`gearcheck.mechanism.Mechanism`: the hooks wired to the
package's modules (analysis, assembly, CAD hook, sweep plan, verdicts, report, sampler)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from gearcheck.mechanism import Assembly, Mechanism, SweepPlan
from gearcheck.mechanisms.track import MESH_TOL_MM, calc
from gearcheck.mechanisms.track.assembly import track_assembly
from gearcheck.mechanisms.track.params import Params as TrackParams

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.figures import Figure
    from gearcheck.results import Clearance, Report, SweepOutcome, Verdict
    from gearcheck.sweep.bodies import Body


class TrackDrive(Mechanism):
    """Track-drive sprocket of a bomb-disposal robot, for the paper's articulated track (grooves
    every half pitch): ISO 606 groove form, every other tooth engaging, a wrapped segment of track
    links (docs/track.md, docs/sprocket_cad.md)."""

    name = "track"
    section = "track"
    title = ("track drive sprocket for the paper's articulated track (grooves every half pitch, every other tooth "
             "engaging; ISO 606 groove form), not a roller-chain sprocket (that is roller_chain)")
    Params = TrackParams
    mesh_tol_mm = MESH_TOL_MM
    template = "eod_track_drive.toml"
    fuzz_seed_base = 1_000_000

    def analyse(self, params: TrackParams) -> list[Figure]:
        return calc(params)

    def assembly(self, params: TrackParams) -> Assembly:
        return track_assembly(params)

    def tca(self, params: TrackParams) -> Any:
        """The polygon effect over one engagement cycle, measured on the wrap's poses
        (:class:`gearcheck.geometry.track_chain.PolygonEffect`: drive angles, the entry run's
        distance from the axis and its speed over ω·R, as arrays)."""
        from gearcheck.geometry.track_chain import polygon_effect

        return polygon_effect(track_assembly(params).layout.wrap)

    def display_frames(self, params: Any, assembly: Assembly) -> tuple[list[Any], str]:
        from gearcheck.mechanisms.track.display import display_frames

        return display_frames(params, assembly)

    def smallest_clearance(self, params: TrackParams) -> Clearance | None:
        from gearcheck.mechanisms.track.clearance import least_clearance

        return least_clearance(track_assembly(params).layout)

    def parts(self, assembly: Assembly) -> list[Part]:
        from gearcheck.mechanisms.track.parts import build_parts

        return build_parts(assembly)

    def plan(self, params: TrackParams, assembly: Assembly, bodies: Mapping[str, Body],
             options: Mapping[str, Any] | None = None) -> SweepPlan:
        from gearcheck.mechanisms.track.sweep import plan_sweep

        return plan_sweep(assembly, bodies, options)

    def verdicts(self, params: TrackParams, outcome: SweepOutcome) -> list[Verdict]:
        from gearcheck.mechanisms.track.verdicts import track_verdicts

        return track_verdicts(outcome)

    def report(self, params: TrackParams, outcome: SweepOutcome, verdicts: Sequence[Verdict]) -> Report:
        from gearcheck.mechanisms.track import is_paper_design
        from gearcheck.mechanisms.track.report import track_report

        return track_report(outcome, verdicts, paper=is_paper_design(params))

    def study_row(self, params: TrackParams, level: str) -> dict[str, float]:
        if level == "exact":
            from gearcheck.mechanisms.track.study import exact_row

            return exact_row(track_assembly(params).layout)
        return super().study_row(params, level)

    def sample(self, data: dict, draw: Any) -> None:
        from gearcheck.mechanisms.track.sampling import sample_track

        sample_track(data, draw)

    def fuzz_options(self, params: TrackParams) -> dict:
        return {}
