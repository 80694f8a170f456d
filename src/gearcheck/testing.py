"""Test your designs and your mechanisms with pytest: ``gearcheck.testing``, a pytest plugin that
loads by itself once gearcheck is installed (entry point ``pytest11``).

A test file of your own, against a copied template (``gearcheck templates --copy designs``)::

    from gearcheck.testing import assert_passed, assert_verdict, assert_watertight, clearance_mm

    def test_my_sprocket(gearcheck_check):
        run = gearcheck_check("designs/eod_track_drive.toml", overrides=["sprocket.teeth=23"])
        assert_passed(run)                                     # every failing verdict, with its figures
        assert_verdict(run, "seated_tip_gap_in_window", "pass")
        assert_watertight(run, "sprocket")                     # the STL the run wrote
        assert clearance_mm(run, "sprocket", "link_00") > 0.1  # the meshes as built

``gearcheck_check`` checks each (template, overrides) once per test session, into a temporary
folder, with one worker process by default (``jobs=1``: no process pool inside the test run).

A mechanism of your own (a plugin package) is tested against the contract every mechanism keeps by
subclassing :class:`MechanismContract`::

    from gearcheck.testing import MechanismContract
    from my_plugin import MyGear

    class TestMyGear(MechanismContract):
        mechanism = MyGear                 # registered for the test if it is not installed
        template = "templates/my_gear.toml"  # or a dict shaped like one

This module is imported by pytest in every session of an environment where gearcheck is installed:
it imports nothing heavy at import time (CadQuery and FCL load only when a check runs).
"""

from __future__ import annotations

import difflib
import html
import math
import pickle
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import pytest

if TYPE_CHECKING:
    from gearcheck.design import Design
    from gearcheck.mechanism import Mechanism
    from gearcheck.pipeline import CheckRun
    from gearcheck.results import Verdict

__all__ = ["MechanismContract", "assert_passed", "assert_verdict", "assert_watertight", "clearance_mm",
           "failure_text"]

LEVELS = ("pass", "warn", "fail")


# ------------------------------------------------------------------------------------------
# Assertions on a check


def _verdicts(run: Any) -> list[Verdict]:
    return list(run.verdicts if hasattr(run, "verdicts") else run.result.verdicts)


def _line(v: Verdict) -> str:
    figure = v.shortfall or v.measured
    evidence = f" [{v.evidence}]" if v.evidence else ""
    return f"{v.level.upper()} {v.name}: {v.label}: {figure}{evidence}"


def failure_text(run: Any) -> str:
    """Every failing verdict of a run, one line each: name, claim, the deciding figure against
    what is required and by how much it falls short, and the evidence that decided it."""
    failed = [v for v in _verdicts(run) if v.level == "fail"]
    folder = getattr(run, "folder", None)
    head = f"{len(failed)} of {len(_verdicts(run))} verdicts fail" + (f" (report: {folder}/report.html)"
                                                                        if folder else "")
    return "\n".join([head, *("  " + _line(v) for v in failed)])


def assert_passed(run: Any) -> None:
    """No verdict fails (warnings pass, as exit code 0 does). The message lists each failing
    verdict with its measured figure and shortfall."""
    __tracebackhide__ = True
    if any(v.level == "fail" for v in _verdicts(run)):
        raise AssertionError(failure_text(run))


def assert_verdict(run: Any, name: str, level: str = "pass") -> None:
    """The verdict ``name`` has ``level`` (pass / warn / fail). An unknown name lists the close
    matches and every name the check has."""
    __tracebackhide__ = True
    if level not in LEVELS:
        raise ValueError(f"level {level!r}: allowed one of {', '.join(LEVELS)}")
    by_name = {v.name: v for v in _verdicts(run)}
    if name not in by_name:
        close = difflib.get_close_matches(name, list(by_name), n=3)
        hint = f" (did you mean {', '.join(close)}?)" if close else ""
        raise AssertionError(f"no verdict {name!r}{hint}; this check has: {', '.join(by_name)}")
    v = by_name[name]
    if v.level != level:
        raise AssertionError(f"verdict {name} is {v.level}, expected {level}:\n  {_line(v)}")


# ------------------------------------------------------------------------------------------
# The meshes a run wrote


def _stl_path(run: CheckRun, part: str) -> Path:
    parts = {p["name"]: p for p in run.build.manifest["parts"]}
    if part not in parts:
        raise AssertionError(f"no part {part!r}; this run has: {', '.join(parts)}")
    return run.folder / parts[part]["stl"]["file"]


def assert_watertight(run: CheckRun, part: str) -> None:
    """The part's STL, as the run wrote it, is closed: every edge shared by exactly two triangles."""
    __tracebackhide__ = True
    from gearcheck.verify import read_stl, stl_is_watertight

    path = _stl_path(run, part)
    triangles = read_stl(path)
    if not stl_is_watertight(triangles):
        raise AssertionError(f"{path.name}: {len(triangles)} triangles, not watertight (an edge is not shared by "
                             "exactly two triangles)")


def clearance_mm(run: CheckRun, part_a: str, part_b: str, poses: Mapping[str, Any] | None = None) -> float:
    """Least distance between two parts' meshes (the swept ones, mm), at their poses as built or at
    ``poses`` ({part: 4×4 world transform}); 0 where they touch or overlap. Within the pair's
    mesh-error bound of the exact distance (``run.build.bodies[name].error_bound_mm`` each)."""
    import numpy as np

    from gearcheck.sweep.engine import Scene

    bodies = run.build.bodies
    for name in (part_a, part_b):
        if name not in bodies:
            raise AssertionError(f"no part {name!r}; this run has: {', '.join(bodies)}")
    scene = Scene([bodies[part_a].mesh, bodies[part_b].mesh])
    for name in (part_a, part_b):
        pose = (poses or {}).get(name, bodies[name].pose)
        scene.set_pose(name, np.asarray(pose, float))
    return float(scene.distance(part_a, part_b).distance)


# ------------------------------------------------------------------------------------------
# The plugin's hooks and fixture


def pytest_configure(config: pytest.Config) -> None:
    """The ``cad`` mark (tests that build CadQuery solids: select them with ``-m cad``, skip them
    with ``-m "not cad"``)."""
    config.addinivalue_line("markers", "cad: builds CadQuery solids (slower)")


class _Checks:
    """Each (template, overrides, tol, options) checked once per session."""

    def __init__(self, factory: pytest.TempPathFactory):
        self.factory = factory
        self.runs: dict[tuple, CheckRun] = {}

    def __call__(self, template: str | Path | Mapping[str, Any], overrides: Sequence[str] | Mapping[str, Any] = (),
                 *, tol: float | None = None, jobs: int = 1, options: Mapping[str, Any] | None = None) -> CheckRun:
        import gearcheck

        frozen_overrides = tuple(sorted(overrides.items())) if isinstance(overrides, Mapping) else tuple(overrides)
        key = (repr(template) if isinstance(template, Mapping) else str(Path(template).resolve()),
               repr(frozen_overrides), tol, repr(sorted((options or {}).items())))
        if key not in self.runs:
            design = gearcheck.load(template, dict(overrides) if isinstance(overrides, Mapping) else list(overrides))
            folder = self.factory.mktemp(design.name) / design.name
            self.runs[key] = design.check(out=folder, tol=tol, jobs=jobs, options=options)
        return self.runs[key]


@pytest.fixture(scope="session")
def gearcheck_check(tmp_path_factory: pytest.TempPathFactory) -> _Checks:
    """``gearcheck_check(template, overrides=(), *, tol=None, jobs=1, options=None)`` → the
    :class:`gearcheck.pipeline.CheckRun` of that design, checked once per test session into a
    temporary folder (its report, STEP, STL and summary.json are there: ``run.folder``)."""
    return _Checks(tmp_path_factory)


# ------------------------------------------------------------------------------------------
# The mechanism contract


_RUNNER = """
import pickle, sys
sys.path[:0] = {paths!r}
with open({path!r}, "rb") as fh:
    meshes, task = pickle.load(fh)
from gearcheck.sweep.plan import make_scene, run_task
result = run_task(make_scene(meshes), *task)
bad = [m for m in ("cadquery", "OCP") if m in sys.modules]
assert not bad, bad
with open({path!r} + ".out", "wb") as fh:
    pickle.dump(result, fh)
"""

_NO_KERNEL = """
import sys
sys.path[:0] = {paths!r}
import gearcheck
from gearcheck import mechanism as registry
{register}
design = gearcheck.load({template})
design.calc().to_dict()
design.impl.assembly(design.params)
bad = [m for m in ("cadquery", "OCP", "fcl", "matplotlib") if m in sys.modules]
assert not bad, bad
"""


def _timing(key: str) -> bool:
    return key.endswith("_s") or "seconds" in key


def same_result(a: Any, b: Any) -> bool:
    """Two task results are the same (NaN equal to NaN, wall-clock figures ignored)."""
    import numpy as np

    if isinstance(a, dict):
        return (isinstance(b, dict) and a.keys() == b.keys()
                and all(same_result(a[k], b[k]) for k in a if not _timing(str(k))))
    if isinstance(a, (list, tuple)):
        return isinstance(b, (list, tuple)) and len(a) == len(b) and all(
            same_result(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b, equal_nan=True)
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return bool(a == b)


class MechanismContract:
    """What every mechanism keeps, as tests: subclass it (``class TestMine(MechanismContract)``)
    and set ``mechanism`` (the class, or an installed name) and ``template`` (a TOML path or a
    dict shaped like one). pytest collects the subclass's tests:

    - ``analyse`` gives figures with unique keys, finite (NaN only where ``nan_figures`` says);
    - calc and the assembly run with neither the CAD kernel, FCL nor matplotlib imported;
    - the assembly's poses are rigid transforms, its motions typed, its solids specified;
    - the plan's tasks pickle and run in a fresh process without CadQuery, with the same result;
    - the check's verdicts have unique names and valid levels, and the report renders them;
    - a ``model_<key>`` figure in summary.json is calc's ``<key>`` (one name per concept).

    The CAD-building tests carry the ``cad`` mark. ``tol_mm`` sets the meshing tolerance of the
    build the last two use (None: the mechanism's rule)."""

    mechanism: ClassVar[Any] = None
    template: ClassVar[Any] = None
    tol_mm: ClassVar[float | None] = None

    # -- set-up ------------------------------------------------------------------------------
    @pytest.fixture(scope="class")
    @classmethod
    def impl(cls) -> Any:
        from gearcheck import mechanism as registry

        if cls.mechanism is None or cls.template is None:
            pytest.fail(f"{cls.__name__}: set `mechanism` and `template` (see gearcheck.testing)")
        if isinstance(cls.mechanism, str) or cls.mechanism.name in registry.names():
            name = cls.mechanism if isinstance(cls.mechanism, str) else cls.mechanism.name
            try:
                yield registry.get(name)
            except KeyError:
                pytest.fail(f"no mechanism {name!r} is installed (known: {', '.join(registry.names())})")
            return
        impl = registry.register(cls.mechanism)  # a plugin's class, not installed: registered for the tests
        yield impl
        registry.unregister(impl.name)

    @pytest.fixture(scope="class")
    @classmethod
    def design(cls, impl: Mechanism) -> Design:
        import gearcheck

        design = gearcheck.load(cls.template)
        assert design.mechanism == impl.name, f"the template is a {design.mechanism!r}, not a {impl.name!r}"
        return design

    @pytest.fixture(scope="class")
    @classmethod
    def built(cls, design: Design, tmp_path_factory: pytest.TempPathFactory) -> Any:
        from gearcheck import pipeline

        return pipeline.build(design, tmp_path_factory.mktemp(design.mechanism), tol_mm=cls.tol_mm)

    @pytest.fixture(scope="class")
    @classmethod
    def swept(cls, impl: Mechanism, design: Design, built: Any) -> Any:
        from gearcheck import pipeline

        return pipeline.sweep(design, built.assembly, built.bodies, jobs=1, options=impl.fuzz_options(design.params))

    # -- numpy only ---------------------------------------------------------------------------
    def test_analyse_gives_finite_figures(self, impl: Mechanism, design: Design) -> None:
        figures = design.calc().figures
        assert figures, "analyse gave no figures"
        keys = [f.key for f in figures]
        assert len(set(keys)) == len(keys), f"repeated figure keys: {sorted({k for k in keys if keys.count(k) > 1})}"
        for f in figures:
            assert not math.isinf(f.value), f.key
            assert math.isfinite(f.value) or f.key in impl.nan_figures, f"{f.key} is NaN (not in nan_figures)"

    def test_calc_and_assembly_need_no_cad_kernel(self, impl: Mechanism, design: Design) -> None:
        paths = [p for p in sys.path if p]
        module = type(impl).__module__
        register = (f"from {module} import {type(impl).__name__} as M\n"
                    f"if M.name not in registry.names(): registry.register(M)")
        template = repr(str(Path(self.template).resolve())) if not isinstance(self.template, Mapping) \
            else repr(dict(self.template))
        code = _NO_KERNEL.format(paths=paths, register=register, template=template)
        subprocess.run([sys.executable, "-c", code], check=True, timeout=300)

    def test_assembly_poses_are_rigid_and_motions_typed(self, impl: Mechanism, design: Design) -> None:
        import numpy as np

        from gearcheck.sweep.motion import ChainLink, Rotation, Translation

        assembly = impl.assembly(design.params)
        assert assembly.mechanism == impl.name and assembly.parts
        for part in assembly.parts:
            pose = np.asarray(part.pose, float)
            assert pose.shape == (4, 4), part.name
            r = pose[:3, :3]
            assert np.allclose(r.T @ r, np.eye(3), atol=1e-12), f"{part.name}: pose is not a rotation"
            assert abs(np.linalg.det(r) - 1.0) <= 1e-12, f"{part.name}: pose is a reflection"
            assert np.array_equal(pose[3], [0.0, 0.0, 0.0, 1.0]), part.name
            assert part.motion is None or isinstance(part.motion, (Rotation, Translation, ChainLink)), part.name
            assert part.solid in assembly.solids, part.name

    # -- with CAD -----------------------------------------------------------------------------
    @pytest.mark.cad
    def test_plan_tasks_pickle_and_run_without_cadquery(self, impl: Mechanism, design: Design, built: Any,
                                                        tmp_path: Path) -> None:
        plan = impl.plan(design.params, built.assembly, built.bodies, impl.fuzz_options(design.params))
        assert plan.tasks and plan.meshes
        assert plan.weights is None or len(plan.weights) == len(plan.tasks)
        path = tmp_path / "task.pkl"
        path.write_bytes(pickle.dumps((plan.meshes, plan.tasks[0])))
        paths = [p for p in sys.path if p]
        subprocess.run([sys.executable, "-c", _RUNNER.format(paths=paths, path=str(path))], check=True, timeout=600)
        remote = pickle.loads((tmp_path / "task.pkl.out").read_bytes())
        from gearcheck.sweep.plan import make_scene, run_task

        local = run_task(make_scene(plan.meshes), *plan.tasks[0])
        assert same_result(local, remote), "the task gave another result in a fresh process"

    @pytest.mark.cad
    def test_check_gives_unique_verdicts_and_a_report(self, impl: Mechanism, design: Design, swept: Any) -> None:
        from gearcheck.report.files import summary_json, sweep_csv
        from gearcheck.report.html import render

        result = swept
        names = [v.name for v in result.verdicts]
        assert names and len(set(names)) == len(names), f"verdict names repeat: {names}"
        assert all(v.level in LEVELS and v.label and v.measured for v in result.verdicts)
        assert result.section == impl.section
        assert summary_json(result) == summary_json(result), "summary.json differs between two writes"
        assert sweep_csv(result).count("\n") == len(result.rows) + 1
        page = render(result, title="t", template=design.source, build={})
        missing = [v.name for v in result.verdicts if html.escape(v.label) not in page]
        assert not missing, f"verdicts not in the report: {missing}"

    @pytest.mark.cad
    def test_summary_names_the_calc_figures(self, impl: Mechanism, design: Design, swept: Any) -> None:
        """One name per concept: a ``model_<key>`` figure in summary.json is calc's ``<key>``, the
        same number (the other prefixes name other evidence of the same concept: ``geom_`` the
        meshes, ``exact_`` the exact geometry, ``paper_`` the printed figure)."""
        calc = {f.key: f.value for f in design.calc().figures}
        section = swept.summary.get(impl.section, swept.summary)
        model = {k: v for k, v in section.items() if k.startswith("model_") and isinstance(v, (int, float))}
        unnamed = sorted(k for k in model if k.removeprefix("model_") not in calc)
        assert not unnamed, f"summary.json figures with no calc figure of that name: {unnamed}"
        for key, value in model.items():
            mine = calc[key.removeprefix("model_")]
            assert math.isclose(value, mine, rel_tol=1e-6, abs_tol=1e-9), f"{key} = {value}, calc says {mine}"
