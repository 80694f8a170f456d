"""The mechanism contract, for every registered mechanism (the shipped ones from the entry-point
group, and the spur pair defined in tests/spur_pair.py): a new mechanism is tested by
registering it.

- ``analyse`` gives finite figures (NaN only where the mechanism documents it) without CadQuery
  or FCL;
- the assembly's poses are rigid transforms, its motions typed, its solids specified;
- the plan's tasks pickle and run in a fresh process that never imports CadQuery, with the same
  result as in this process;
- the check's verdict names are unique, levels valid, and the report files render.
"""

from __future__ import annotations

import html
import math
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gearcheck
from gearcheck import mechanism as registry
from gearcheck import pipeline
from gearcheck.sweep.motion import ChainLink, Rotation, Translation
from spur_pair import TEMPLATE as SPUR_TEMPLATE
from spur_pair import SpurPair

# the shipped mechanisms (entry points) and the test-defined spur pair, registered while this
# module's tests run (so other modules see only the installed registry)
NAMES = sorted({*registry.names(), SpurPair.name})


@pytest.fixture(scope="module", autouse=True)
def spur_registered():
    registry.register(SpurPair)
    yield
    registry.unregister(SpurPair.name)
EXAMPLES = {"spur_pair": SPUR_TEMPLATE}
ROOT = Path(__file__).resolve().parents[1]


def design_of(name: str):
    impl = registry.get(name)
    if impl.template:
        return gearcheck.load(ROOT / "templates" / impl.template)
    return gearcheck.load(EXAMPLES[name])


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    cache = {}

    def get(name: str):
        if name not in cache:
            design = design_of(name)
            cache[name] = (design, pipeline.build(design, tmp_path_factory.mktemp(name), tol_mm=0.01
                                                  if name != "spur_pair" else None))
        return cache[name]

    return get


def test_every_shipped_mechanism_is_registered():
    assert {"differential", "track", "steering", "spur_pair"} <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_analyse_gives_finite_figures(name):
    impl = registry.get(name)
    figures = design_of(name).calc().figures
    assert figures and len({f.key for f in figures}) == len(figures)
    for f in figures:
        assert not math.isinf(f.value), f.key
        assert math.isfinite(f.value) or f.key in impl.nan_figures, f.key


def test_analyse_and_assembly_import_no_cad_kernel_nor_fcl():
    """calc and the assemblies of every mechanism (the shipped ones and a test-defined one) run
    with neither OpenCASCADE nor FCL loaded."""
    code = (
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / 'tests')!r})\n"
        "import gearcheck\nfrom gearcheck import mechanism as r\n"
        "from spur_pair import SpurPair, TEMPLATE\nr.register(SpurPair)\n"
        "for n in r.names():\n"
        "    impl = r.get(n)\n"
        f"    d = gearcheck.load({str(ROOT / 'templates')!r} + '/' + impl.template if impl.template else TEMPLATE)\n"
        "    d.calc().to_dict(); impl.assembly(d.params)\n"
        "bad = [m for m in ('cadquery', 'OCP', 'fcl', 'trimesh', 'matplotlib') if m in sys.modules]\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


@pytest.mark.parametrize("name", NAMES)
def test_assembly_poses_are_rigid_and_motions_typed(name):
    design = design_of(name)
    assembly = design.impl.assembly(design.params)
    assert assembly.mechanism == name and assembly.parts
    for part in assembly.parts:
        pose = np.asarray(part.pose, float)
        assert pose.shape == (4, 4), part.name
        r = pose[:3, :3]
        assert np.allclose(r.T @ r, np.eye(3), atol=1e-12), part.name
        assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12), part.name
        assert np.array_equal(pose[3], [0.0, 0.0, 0.0, 1.0]), part.name
        assert part.motion is None or isinstance(part.motion, (Rotation, Translation, ChainLink)), part.name
        assert part.solid in assembly.solids, part.name


RUNNER = """
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


def _timing(key: str) -> bool:
    """Wall-clock figures a task reports (they differ from run to run; never in summary.json)."""
    return key.endswith("_s") or "seconds" in key


def _same(a, b) -> bool:
    if isinstance(a, dict):
        return (isinstance(b, dict) and a.keys() == b.keys()
                and all(_same(a[k], b[k]) for k in a if not _timing(str(k))))
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray):
        return np.array_equal(a, b, equal_nan=True)
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return bool(a == b)


@pytest.mark.cad
@pytest.mark.parametrize("name", NAMES)
def test_plan_tasks_pickle_and_run_without_cadquery(name, built, tmp_path):
    design, run = built(name)
    impl = design.impl
    plan = impl.plan(design.params, run.assembly, run.bodies, impl.fuzz_options(design.params))
    assert plan.tasks and plan.meshes
    assert plan.weights is None or len(plan.weights) == len(plan.tasks)
    path = tmp_path / "task.pkl"
    path.write_bytes(pickle.dumps((plan.meshes, plan.tasks[0])))
    paths = [p for p in sys.path if p]
    subprocess.run([sys.executable, "-c", RUNNER.format(paths=paths, path=str(path))], check=True, cwd=ROOT)
    remote = pickle.loads((tmp_path / "task.pkl.out").read_bytes())
    from gearcheck.sweep.plan import make_scene, run_task

    local = run_task(make_scene(plan.meshes), *plan.tasks[0])
    assert _same(local, remote)


@pytest.mark.cad
@pytest.mark.parametrize("name", NAMES)
def test_check_gives_unique_verdicts_and_a_report(name, built):
    from gearcheck.report.files import summary_json, sweep_csv
    from gearcheck.report.html import render

    design, run = built(name)
    result = pipeline.sweep(design, run.assembly, run.bodies, jobs=1,
                            options=design.impl.fuzz_options(design.params))
    names = [v.name for v in result.verdicts]
    assert names and len(set(names)) == len(names)
    assert all(v.level in ("pass", "warn", "fail") and v.label and v.measured for v in result.verdicts)
    assert result.section == design.impl.section
    assert summary_json(result) == summary_json(result)  # deterministic
    assert sweep_csv(result).count("\n") == len(result.rows) + 1
    page = render(result, title="t", template=design.source, build={})
    assert all(html.escape(v.label) in page for v in result.verdicts)
