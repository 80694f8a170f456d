"""The one pipeline: smallest clearance → mesh tolerance → build → mesh → sweep (through an
executor) → mesh-resolution rule → verdicts → exact B-rep confirmation → files. The CLI, the
Python API, the benchmarks and the tests all call it.

Each stage is a function of the previous stage's output, so a caller can stop anywhere:
:func:`build_parts` (solids, no files), :func:`build` (solids, meshes, STEP/STL/manifest),
:func:`sweep` (a :class:`~gearcheck.results.CheckResult` from meshed bodies, no files),
:func:`check` (everything, with report files). Nothing here prints: progress goes to the
``progress`` factory a caller passes (the CLI's bars), diagnostics to the ``gearcheck`` logger.
"""

from __future__ import annotations

import contextlib
import json
import math
import logging
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from gearcheck.design import TOL_MAX_MM, TOL_MIN_MM
from gearcheck.mechanism import calling
from gearcheck.params import ParamError
from gearcheck.confirmation import confirm, confirmation_verdict  # noqa: F401 - part of the pipeline's API
from gearcheck.results import CheckResult

if TYPE_CHECKING:
    from gearcheck.cad.export import ExportedPart
    from gearcheck.resolution import MeshPlan
    from gearcheck.cad.placement import Part
    from gearcheck.design import Design
    from gearcheck.executor import Executor
    from gearcheck.mechanism import Assembly
    from gearcheck.sweep.bodies import Body

log = logging.getLogger("gearcheck")

REPORT_FILES = ("summary.json", "sweep.csv", "report.html")


class Bar(Protocol):
    def update(self, n: int = 1) -> Any: ...


ProgressFactory = Callable[[str, "int | None", str], contextlib.AbstractContextManager[Bar]]


class _NoBar:
    def update(self, n: int = 1) -> None:
        return None


@contextlib.contextmanager
def no_progress(_desc: str, _total: int | None = None, _unit: str = "") -> Iterator[Bar]:
    yield _NoBar()


def smallest_clearance(design: Design) -> Any:
    """The mechanism's smallest clearance to resolve (its hook), which must be None or > 0 mm."""

    from gearcheck.mechanism import HookError

    with calling(design.impl, "smallest_clearance"):
        clearance = design.impl.smallest_clearance(design.params)
    if clearance is not None and not (math.isfinite(clearance.value_mm) and clearance.value_mm > 0.0):
        raise HookError(design.mechanism, "smallest_clearance", ValueError(
            f"returned Clearance({clearance.value_mm!r} mm): a clearance to resolve must be > 0 mm (None: the "
            "check decides no non-zero clearance)"))
    return clearance


def check_tol(tol_mm: float | None) -> None:
    """``--tol`` within the range a mesh can be made and measured at."""
    if tol_mm is not None and not (TOL_MIN_MM <= tol_mm <= TOL_MAX_MM):
        raise ParamError("--tol", tol_mm, f"out of range: allowed {TOL_MIN_MM:g} to {TOL_MAX_MM:g} mm")


def mesh_plan(design: Design, tol_mm: float | None) -> MeshPlan:
    """The chordal tolerance to mesh at (:mod:`gearcheck.resolution`). ``--tol`` or a
    ``mesh_tol_mm`` key (a params.toml records the tolerance its run used) is used as given;
    otherwise the mechanism's default, refined so the meshes resolve the smallest clearance the
    design asks to decide (from its exact model, before meshing)."""
    from gearcheck import resolution

    given = tol_mm if tol_mm is not None else design.data.get("mesh_tol_mm")
    requested = float(given) if given is not None else float(design.impl.mesh_tol_mm)
    check_tol(requested)
    t0 = time.perf_counter()
    clearance = smallest_clearance(design)
    log.info("stage plan: smallest clearance to decide: %s (%.2f s)",
             "none" if clearance is None else f"{clearance.value_mm:.5g} mm, {clearance.label}",
             time.perf_counter() - t0)
    return resolution.plan_tolerance(requested, given is not None, clearance)


def run_params(design: Design, tol_mm: float) -> dict:
    """What params.toml records: the resolved parameters, the result name and the mesh
    tolerance, so ``gearcheck check out/NAME/params.toml`` reproduces the run."""
    data = design.resolved_data
    return {"mechanism": data["mechanism"], "name": data["name"], "mesh_tol_mm": tol_mm,
            **{k: v for k, v in data.items() if k not in ("mechanism", "name", "mesh_tol_mm")}}


def provenance(design: Design, overrides: Sequence[str] = ()) -> str:
    """The comment heading params.toml: where the parameters came from."""
    from gearcheck import __version__

    text = f"gearcheck {__version__} run {design.name}: the resolved parameters of {design.source}"
    if overrides:
        text += " with " + " ".join(f"--set {o}" for o in overrides)
    return text + ". Re-run: gearcheck check params.toml"


# ------------------------------------------------------------------------------------------
# Build


@dataclass
class BuildRun:
    """What ``build`` made: the assembly as data, the solids, the meshes (as sweep bodies), the
    manifest and the files written."""

    design: Design
    folder: Path
    tol_mm: float
    mesh_plan: MeshPlan
    assembly: Assembly
    parts: list[Part]
    exported: list[ExportedPart]
    bodies: dict[str, Body]
    manifest: dict
    files: list[Path] = field(default_factory=list)  # every file of the run (after the swap)

    def __repr__(self) -> str:
        return (f"<BuildRun {self.design.name}: {len(self.parts)} parts meshed at {self.tol_mm:g} mm, "
                f"{len(self.files)} files in {self.folder}>")


def build_parts(design: Design, progress: ProgressFactory = no_progress,
                assembly: Assembly | None = None) -> tuple[Assembly, list[Part]]:
    """The assembly as data (given, or made from the parameters) and its solids (CadQuery), no
    files."""
    impl = design.impl
    if assembly is None:
        with calling(impl, "assembly"):
            assembly = impl.assembly(design.params)
    with progress(f"solids of {design.name}", len(assembly.names), "part") as bar:
        with calling(impl, "parts"):
            parts = impl.parts(assembly)
        bar.update(len(parts))
    if [p.name for p in parts] != assembly.names:
        raise RuntimeError(f"{impl.name}: parts() must return the assembly's parts in order, "
                           f"got {[p.name for p in parts]} for {assembly.names}")
    return assembly, parts


def sweep_bodies(exported: list[ExportedPart]) -> dict[str, Body]:
    """Meshed parts as the sweep sees them: plain arrays in each part's own frame, its pose as
    built, its measured mesh-error bound (picklable: no CAD kernel needed to use them)."""
    import numpy as np

    from gearcheck.sweep.bodies import Body, MeshData

    return {
        e.part.name: Body(MeshData(e.part.name, e.mesh.vertices, e.mesh.faces), np.asarray(e.part.pose, float),
                          e.mesh.error_bound_mm, e.part.material, e.part.motion)
        for e in exported
    }


def cad_key(design: Design, assembly: Assembly, tol: float) -> str:
    """The CAD cache key of a design's solids, meshes and STEP file: what they are made from
    (its name, the mesh tolerance, the assembly's part and solid specs; not the parameters only
    the sweep, the verdicts or the report read), with this code, the mechanism's own (a plugin's
    package) and this CAD kernel (:func:`gearcheck.cache.key_of`)."""
    from gearcheck import cache

    return cache.key_of(design.name, float(tol), assembly.mechanism, assembly.parts, assembly.solids,
                        cache.code_digest(type(design.impl)))


def _cached_cad(design: Design, assembly: Assembly, tol: float) -> tuple[str | None, Any]:
    """The design's CAD cache key (None with the cache off) and, if the cache holds it, its
    (time made, parts, meshes, STEP bytes); an entry whose content cannot be used is removed."""
    from gearcheck import cache
    from gearcheck.cad.export import cad_from_bytes

    folder = cache.root()
    if folder is None:
        return None, None
    key = cad_key(design, assembly, tol)
    entry = cache.load(folder, key)
    if entry is None:
        return key, None
    try:
        parts, meshed = cad_from_bytes(entry.files["cad.pickle"])
        return key, (entry.created, parts, meshed, entry.files["model.step"])
    except Exception as exc:  # noqa: BLE001 (whatever the entry holds, the CAD can be built)
        log.warning("CAD cache entry %s unreadable (%s: %s): building the CAD", key, type(exc).__name__, exc)
        cache.discard(folder, key)
        return key, None


def _build_into(design: Design, folder: Path, tol_mm: float | None, progress: ProgressFactory,
                overrides: Sequence[str] = (), geometry: bool = False) -> BuildRun:
    """Solids, meshes, STEP/STL/params.toml/manifest.json (and with ``geometry`` NAME.glb)
    written into ``folder`` (a staging folder: the caller commits it). The solids, meshes and
    STEP file come from the CAD cache when it holds this design's (:func:`_cached_cad`), and go
    into it when made."""
    from gearcheck import cache, resolution
    from gearcheck.cad.export import cad_bytes, export_parts
    from gearcheck.cad.mesh import TooManyTriangles
    from gearcheck.mesh_budget import over_budget, within_budget

    plan = mesh_plan(design, tol_mm)
    tol = plan.tol_mm
    with calling(design.impl, "assembly"):
        assembly = design.impl.assembly(design.params)
    key, cached = _cached_cad(design, assembly, tol)
    if cached is not None:
        made, parts, meshed, step = cached
        log.info("stage build: %s (%s), solids and meshes from the CAD cache (made %s)", design.name,
                 design.mechanism, made)
    else:
        made = meshed = step = None
        log.info("stage build: %s (%s), solids", design.name, design.mechanism)
        assembly, parts = build_parts(design, progress, assembly)
        budgeted = within_budget(design, plan, parts, tol_mm)
        if budgeted is not plan:
            plan, tol = budgeted, budgeted.tol_mm
            key = cad_key(design, assembly, tol) if key is not None else None
    log.info("stage mesh: %s, %d parts at %g mm", design.name, len(parts), tol)
    source = {"key": key, "reused": cached is not None, "made": made}
    while True:
        try:
            with progress(f"meshing {design.name}", len(parts), "part") as bar:
                manifest, exported, step_data = export_parts(
                    parts, folder, name=design.name, mechanism=design.mechanism, params_data=run_params(design, tol),
                    tol_mm=tol, extra={"mesh_tolerance": plan.manifest(), "cad_cache": source},
                    progress=lambda _name: bar.update(1), params_comment=provenance(design, overrides),
                    meshed=meshed, step_data=step, max_triangles=resolution.TRIANGLE_BUDGET)
                if meshed is not None:
                    bar.update(len(parts))
            break
        except TooManyTriangles as exc:  # more than the estimate said: counted while meshing
            plan = over_budget(design, plan, parts, tol_mm, exc.triangles)
            tol = plan.tol_mm
            key = source["key"] = cad_key(design, assembly, tol) if key is not None else None
    if cached is None and key is not None:
        meshes = [(e.mesh, e.brep_volume_mm3) for e in exported]
        cache.store(cache.root(), key, {"cad.pickle": cad_bytes(parts, meshes), "model.step": step_data})
    if geometry:
        from gearcheck.views import scene_of, write_geometry

        log.info("stage geometry: %s.glb", design.name)
        write_geometry(folder, scene_of(design, assembly, parts), pictures=False, viewer=False)
    return BuildRun(design, folder, tol, plan, assembly, parts, exported, sweep_bodies(exported), manifest)


def _seal(folder: Path, manifest: dict, extra: Mapping[str, str] | None, shown: Path) -> dict:
    """Write the extra files, list every file of the run (size and sha256) in the manifest,
    rewrite it, and verify the folder against it before it may be swapped in. A file that does
    not read back as written (cut short by a file-size limit or a full disk the writer did not
    report) is a write failure of that file, named as it would be in ``shown``."""
    from gearcheck.output import OutputError, atomic_write_text
    from gearcheck.verify import RunIncomplete, listing, verify_run

    from gearcheck.names import file_in

    for name, text in (extra or {}).items():
        atomic_write_text(file_in(folder, name), text)
    manifest = {**manifest, "files": listing(folder)}
    atomic_write_text(folder / "manifest.json", json.dumps(manifest, indent=2, allow_nan=False) + "\n")
    try:
        return verify_run(folder)
    except RunIncomplete as exc:
        raise OutputError(shown / exc.file if exc.file else shown, f"cannot write: {exc}") from None


def seal(folder: Path, manifest: dict, shown: Path) -> dict:
    """List every file of a staged run in its manifest and verify the folder against it (see
    :func:`_seal`): for runs other than a build or a check (a study)."""
    return _seal(folder, manifest, None, shown)


def write_files(design: Design, folder: Path, files: Mapping[str, str]) -> Path:
    """A run folder holding only the given text files (``demo --no-cad``: the analytical
    figures), written as one transaction like every run."""
    from gearcheck import __version__
    from gearcheck.output import RunFolder

    with RunFolder(folder) as txn:
        manifest = {"gearcheck_version": __version__, "mechanism": design.mechanism, "name": design.name}
        _seal(txn.staging, manifest, files, Path(folder))
        return txn.commit()


def _rooted(run: BuildRun, target: Path, files: list[str]) -> None:
    run.folder = target
    run.files = [target / n for n in files]


def build(design: Design, folder: Path, *, tol_mm: float | None = None,
          progress: ProgressFactory = no_progress, overrides: Sequence[str] = (),
          extra_files: Mapping[str, str] | None = None) -> BuildRun:
    """Build the CAD, mesh each part at ``tol_mm`` (default: the template's, else the
    mechanism's), and write NAME.step, PART.stl, params.toml and manifest.json as one
    transaction: staged beside ``folder``, verified, swapped in (:class:`gearcheck.output.RunFolder`)."""
    from gearcheck.output import RunFolder

    check_tol(tol_mm)
    with RunFolder(folder) as txn:
        run = _build_into(design, txn.staging, tol_mm, progress, overrides, geometry=True)
        run.manifest = _seal(txn.staging, run.manifest, extra_files, Path(folder))
        target = txn.commit()
    _rooted(run, target, ["manifest.json", *run.manifest["files"]])
    return run


# ------------------------------------------------------------------------------------------
# Sweep


def announce(progress: ProgressFactory, text: str) -> None:
    """A line for whoever shows the progress (the CLI's bars or plain lines: its ``announce``),
    before a long stage starts; a progress factory without one shows the stage's description only."""
    said = getattr(progress, "announce", None)
    if callable(said):
        said(text)


def _priced(design: Design, cost: Any, workers: int, budget: float, progress: ProgressFactory) -> str:
    """A plan's predicted cost (:class:`gearcheck.sweep_budget.SweepCost`, or None) against the
    budget: refused over it (:class:`ParamError`), else stated (the log; a line for the progress
    display where it is long); the sweep's progress title."""
    from gearcheck import sweep_budget

    desc = f"sweeping {design.name}"
    if cost is None:
        return desc
    text = cost.describe(workers, budget)
    log.info("stage sweep: %s, predicted %s (measured in %.2f s)", design.name, text, cost.calibration_s)
    refused = cost.refusal(budget, sweep_budget.SWEEP_MEMORY_GB, workers)
    if refused is not None:
        raise refused
    predicted = cost.cpu_s(workers)
    if predicted >= sweep_budget.ANNOUNCE_CPU_S:
        announce(progress, f"sweeping {design.name}: {text}, on {workers} worker(s)")
    return desc + (f" (predicted {predicted:.0f} CPU s)" if predicted >= 1.0 else "")


def sweep(design: Design, assembly: Assembly, bodies: Mapping[str, Body], *, executor: Executor | None = None,
          jobs: int | None = None, options: Mapping[str, Any] | None = None,
          progress: ProgressFactory = no_progress, mesh_plan: MeshPlan | None = None,
          budget_cpu_s: float | None = None) -> CheckResult:
    """Plan the mechanism's sweep on the meshed bodies, run its tasks on ``executor`` (default:
    a local pool of ``jobs`` processes, every core), reduce, check the mesh-resolution rule
    (``mesh_plan``: how the bodies were meshed; default: as they are, for the design's smallest
    clearance), and give verdicts and report content. No files; the exact B-rep confirmation
    comes after. A plan that predicts its cost (:mod:`gearcheck.sweep_budget`) states it before
    the sweep starts and is refused (:class:`ParamError`, nothing run) over ``budget_cpu_s`` CPU
    seconds (default :data:`gearcheck.sweep_budget.SWEEP_BUDGET_CPU_S`) or the memory budget."""
    from gearcheck import resolution, sweep_budget
    from gearcheck.executor import make_executor
    from gearcheck.sweep.plan import run_plan

    impl = design.impl
    check_poses(assembly, bodies)
    if mesh_plan is None:
        tol = max(float(b.error_bound_mm) for b in bodies.values())
        mesh_plan = resolution.MeshPlan(tol, tol, True, smallest_clearance(design))
    executor = executor if executor is not None else make_executor(jobs)
    with calling(impl, "plan"):
        plan = impl.plan(design.params, assembly, bodies, options)
    budget = float(sweep_budget.SWEEP_BUDGET_CPU_S if budget_cpu_s is None else budget_cpu_s)
    workers = max(1, min(executor.jobs, len(plan.tasks)))
    cost = plan.cost
    desc = _priced(design, cost, workers, budget, progress)
    log.info("stage sweep: %s, %d tasks on %d worker(s)", design.name, len(plan.tasks), executor.jobs)
    t0 = time.perf_counter()
    with progress(desc, plan.total, plan.unit) as bar, calling(impl, "plan's sweep task"):
        results = run_plan(executor, plan, bar.update)
    wall_s = time.perf_counter() - t0
    log.info("%s: %d sweep tasks on %d worker(s) in %.2f s", design.name, len(plan.tasks), executor.jobs, wall_s)
    with calling(impl, "plan's reduce"):
        outcome = plan.reduce(results)
    rule = resolution.assess(mesh_plan, bodies)
    outcome.mesh_resolves = rule.resolves
    with calling(impl, "verdicts"):
        verdicts = impl.verdicts(design.params, outcome)
    with calling(impl, "report"):
        report = impl.report(design.params, outcome, verdicts)
    timings = dict(outcome.timings)
    timings.setdefault("workers", executor.jobs)
    summary = dict(outcome.summary)
    summary["mesh_resolution"] = rule.summary()
    notes = [*report.notes, rule.describe()]
    recorded: dict = {}
    if cost is not None:
        actual = timings.get("task_cpu_s")
        actual = float(actual) if isinstance(actual, (int, float)) else None
        recorded = cost.record(workers, budget, actual, wall_s)
        notes.append(cost.note(workers, budget, actual))
    return CheckResult(impl.section, summary, verdicts, report.rows, report.comparisons, report.plots,
                       notes, outcome.worst_poses, timings, mesh_plan.clearance,
                       resolution=rule, overlays=list(report.overlays), sweep_cost=recorded)


def check_poses(assembly: Assembly, bodies: Mapping[str, Body]) -> None:
    """The bodies must be this assembly's parts, posed as it built them (a sweep of meshes built
    from other parameters would prove nothing about this design)."""
    import numpy as np

    for spec in assembly.parts:
        if spec.name not in bodies:
            raise ValueError(f"missing body {spec.name!r}: expected the parts {assembly.names}")
        if not np.allclose(bodies[spec.name].pose, spec.pose, atol=1e-9):
            raise ValueError(f"{spec.name}: pose differs from the assembly's (built with other parameters?)")


# ------------------------------------------------------------------------------------------
# Check


@dataclass
class CheckRun:
    """A finished check: the build, the result, the files written."""

    build: BuildRun
    result: CheckResult
    files: list[Path]
    summary: dict  # summary.json, as written

    @property
    def folder(self) -> Path:
        return self.build.folder

    @property
    def passed(self) -> bool:
        return self.result.passed

    @property
    def verdicts(self):
        return self.result.verdicts

    def __repr__(self) -> str:
        from gearcheck.notebook import check_repr

        return check_repr(self.result, self.build.design.name, self.folder)

    def _repr_html_(self) -> str:
        from gearcheck.notebook import check_html

        return check_html(self.result, self.build.design.name, self.folder)


def write_report(design: Design, folder: Path, result: CheckResult, manifest: dict, *,
                 overrides: Sequence[str] = (), geometry: Any = None,
                 plots: Sequence[str] | None = None) -> tuple[list[Path], dict]:
    """summary.json, sweep.csv and report.html (each atomically, in the run's staging folder);
    the files and summary.json's data. ``geometry``: the run's :class:`gearcheck.views.Geometry`
    (its 3D view and pictures go into the report); ``plots``: the result's plots made in
    advance (:func:`gearcheck.report.html.plots_html`), else made here."""
    from gearcheck.output import atomic_write_text
    from gearcheck.report.files import summary_json, sweep_csv
    from gearcheck.report.html import render
    from gearcheck.report.inputs import input_rows, template_header
    from gearcheck.views import run_files

    log.info("stage report: %s", design.name)
    summary = summary_json(result)
    atomic_write_text(folder / "summary.json", summary)
    atomic_write_text(folder / "sweep.csv", sweep_csv(result))
    build_info = {
        "chordal_tolerance_mm": manifest["chordal_tolerance_mm"],
        "triangles": sum(p["triangles"] for p in manifest["parts"]),
        "parts": len(manifest["parts"]),
        "cad_cache": manifest.get("cad_cache") or {},
    }
    if geometry is not None:
        result.notes.extend(geometry.notes)
    page = render(result, title=f"gearcheck: {design.name} ({design.mechanism})", template=design.source,
                  build=build_info, inputs=input_rows(design, overrides),
                  files=run_files(folder, [*REPORT_FILES, "manifest.json"]),
                  viewer=geometry.viewer if geometry is not None else "",
                  pictures=geometry.pictures if geometry is not None else (), about=template_header(design),
                  plots=plots)
    atomic_write_text(folder / "report.html", page)
    return [folder / n for n in REPORT_FILES], json.loads(summary)


def _built_scene(design: Design, run: BuildRun, drawing: Any) -> Any:
    """The scene as built (display meshes, motion frames), given to the picture process at once:
    it draws the assembly while the worst poses are confirmed."""
    from gearcheck.views import scene_of

    scene = scene_of(design, run.assembly, run.parts)
    if drawing is not None:
        drawing.assembly(scene)
    return scene


def _plots(result: CheckResult, plotting: Any) -> list[str]:
    """The report's plots: drawn by the plot process (given them after the sweep), or, where it
    could not, here (the same HTML either way)."""
    from gearcheck.report.html import plots_html
    from gearcheck.report.plots import PlotsUnavailable

    if plotting is not None:
        try:
            return plotting.result()
        except PlotsUnavailable as exc:
            log.warning("plots drawn in this process: %s", exc)
    return plots_html(result)


def _geometry(design: Design, run: BuildRun, result: CheckResult, progress: ProgressFactory,
              built: Any, drawing: Any, plotting: Any) -> tuple[Any, list[str]]:
    """NAME.glb with the worst poses, the pictures and the report's 3D view of a check, and the
    report's plots (drawn meanwhile by their own processes)."""
    from dataclasses import replace

    from gearcheck.views import worst_views, write_geometry

    log.info("stage geometry: %s.glb, pictures, 3D view", design.name)
    with progress("drawing the geometry", 3, "step") as bar:
        scene = replace(built, worst=worst_views(result), overlays=list(result.overlays))  # as views.scene_of
        if drawing is not None:
            drawing.worst(scene)
        bar.update(1)
        geometry = write_geometry(run.folder, scene, pictures=True, viewer=True, drawing=drawing)
        plots = _plots(result, plotting)
        bar.update(2)
    return geometry, plots


def check(design: Design, folder: Path, *, tol_mm: float | None = None, jobs: int | None = None,
          executor: Executor | None = None, options: Mapping[str, Any] | None = None,
          progress: ProgressFactory = no_progress, overrides: Sequence[str] = (),
          extra_files: Mapping[str, str] | None = None, budget_cpu_s: float | None = None) -> CheckRun:
    """Build (meshes fine enough for the design's smallest clearance), sweep, confirm the worst poses on the exact B-rep
    and write report.html, summary.json and sweep.csv beside the CAD — all as one transaction
    (:class:`gearcheck.output.RunFolder`): ``folder`` ends up holding this whole run, or, if
    anything fails or interrupts it, the previous run untouched."""
    from gearcheck.output import RunFolder

    from gearcheck.views import picture_process, plot_process

    check_tol(tol_mm)
    if executor is None:  # worker processes must be able to load the mechanism: said before the build
        from gearcheck.executor import capped_jobs, check_main_importable

        if capped_jobs(jobs) > 1:
            check_main_importable(type(design.impl), type(design.params))
    # the picture and plot processes start (VTK, matplotlib) while the CAD is built
    with RunFolder(folder) as txn, picture_process() as drawing, plot_process() as plotting:
        run = _build_into(design, txn.staging, tol_mm, progress, overrides)
        result = sweep(design, run.assembly, run.bodies, executor=executor, jobs=jobs, options=options,
                       progress=progress, mesh_plan=run.mesh_plan, budget_cpu_s=budget_cpu_s)
        if plotting is not None:
            plotting.draw(result.plots)
        built = _built_scene(design, run, drawing)
        result.confirmations = confirm(result, run.parts, run.bodies, progress)
        result.verdicts.append(confirmation_verdict(result.confirmations, result.resolution))
        geometry, plots = _geometry(design, run, result, progress, built, drawing, plotting)
        _, summary = write_report(design, txn.staging, result, run.manifest, overrides=overrides, geometry=geometry,
                                  plots=plots)
        if result.sweep_cost:  # predicted against measured: timings, so here, not in summary.json
            run.manifest = {**run.manifest, "sweep_cost": result.sweep_cost}
        run.manifest = _seal(txn.staging, run.manifest, extra_files, Path(folder))
        target = txn.commit()
    _rooted(run, target, ["manifest.json", *run.manifest["files"]])
    return CheckRun(run, result, run.files, summary)
