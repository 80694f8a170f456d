"""A mechanism defined only in the tests (an involute spur pair, tests/spur_pair.py) goes through
the whole pipeline — build, mesh, sweep on several processes, resolution rule, exact B-rep
confirmation, report files — after one ``register`` call, with no shared file touched. The
worked example of docs/extending.md."""

import json

import pytest

import gearcheck
from gearcheck import mechanism as registry
from conftest import messages
from spur_pair import TEMPLATE, SpurPair

pytestmark = pytest.mark.cad


@pytest.fixture(scope="module")
def spur():
    impl = registry.register(SpurPair)
    yield impl
    registry.unregister(impl.name)


@pytest.fixture(scope="module")
def checked(spur, tmp_path_factory):
    design = gearcheck.load(TEMPLATE)
    out = tmp_path_factory.mktemp("spur")
    return design, design.check(out=out, jobs=2)


def test_registered_mechanism_is_known(spur):
    assert "spur_pair" in gearcheck.mechanism_names()
    assert registry.get("spur_pair") is spur


def test_calc_gives_the_backlash_model(spur):
    f = gearcheck.load(TEMPLATE, overrides={"backlash.thinning_2_mm": 0.1}).calc()
    assert f["circumferential_backlash_mm"] == pytest.approx(0.15)
    assert f["play_gear_2_arcmin"] == pytest.approx(0.15 / 24.0 * 180 / 3.141592653589793 * 60)


def test_bad_input_is_one_line(spur):
    with pytest.raises(gearcheck.ParamError) as err:
        gearcheck.load(TEMPLATE, overrides={"gears.teeth_1": 5})
    assert str(err.value).startswith("<data>: gears.teeth_1 = 5: ") and "17" in str(err.value)


def test_pipeline_checks_it_end_to_end(checked):
    design, run = checked
    assert run.passed, [(v.name, v.measured) for v in run.verdicts]
    assert [v.name for v in run.verdicts] == ["no_interference", "backlash_positive", "mesh_agrees_with_exact",
                                              "exact_confirmation"]
    s = run.summary["spur_pair"]
    # the mesh play is the exact j / r2 within the meshes' bound and the polygon's sag
    assert s["max_mesh_exact_deviation_arcmin"] <= s["allowed_deviation_arcmin"]
    assert s["geom_play_min_arcmin"] == pytest.approx(s["exact_play_arcmin"], rel=0.02)
    # contact from both sides: the worst pose re-measured on the exact B-rep
    (conf,) = s["exact_confirmation"].values()
    assert abs(conf["mesh_mm"] - conf["brep_mm"]) <= conf["bound_mm"]
    assert s["mesh_resolution"]["rule_met"] == 1
    for name in ("report.html", "summary.json", "sweep.csv", "manifest.json", "spur_example.step",
                 "gear_1.stl", "gear_2.stl"):
        assert (run.folder / name).is_file(), name
    manifest = json.loads((run.folder / "manifest.json").read_text())
    assert manifest["parts"][1]["motion"] == {"kind": "rotation", "axis": [0.0, 0.0, 1.0],
                                              "origin": [pytest.approx(42.0), 0.0, 0.0]}


def test_one_worker_gives_the_same_files(checked, tmp_path):
    design, run = checked
    again = design.check(out=tmp_path, jobs=1)
    for name in ("summary.json", "sweep.csv"):
        assert (tmp_path / name).read_bytes() == (run.folder / name).read_bytes(), name


class _BadClearance(SpurPair):
    name = section = "spur_bad_clearance"

    def smallest_clearance(self, params):
        from gearcheck.results import Clearance

        return Clearance(0.0, "no clearance at all")


class _BadAnalyse(SpurPair):
    name = section = "spur_bad_analyse"

    def analyse(self, params):
        raise RuntimeError("boom\nsecond line")


@pytest.mark.parametrize("cls, command, line", [
    (_BadClearance, "check", "the spur_bad_clearance mechanism's smallest_clearance hook failed: ValueError: returned "
                             "Clearance(0.0 mm): a clearance to resolve must be > 0 mm"),
    (_BadAnalyse, "calc", "the spur_bad_analyse mechanism's analyse hook failed: RuntimeError: boom second line"),
])
def test_a_plugins_error_is_exit_3_naming_the_mechanism_and_the_hook(tmp_path, capsys, caplog, cls, command, line):
    """Before: a plugin's exception (a Clearance(0.0)) ended as a traceback with exit 1, the code of
    a failed verdict, so CI read it as a failed design. Now: exit 3, one line naming the mechanism
    and the hook, the traceback under -v."""
    import tomli_w

    from gearcheck.cli import main

    impl = registry.register(cls)
    try:
        path = tmp_path / "t.toml"
        path.write_text(tomli_w.dumps({**TEMPLATE, "mechanism": cls.name}))
        args = [command, str(path)] + (["--out", str(tmp_path / "run"), "--jobs", "1"] if command == "check" else [])
        assert main(args) == 3
        err = messages(capsys.readouterr().err)
        assert len(err) == 1 and err[0].startswith(f"gearcheck: error: {line}"), err
        assert err[0].endswith("(run with -v for the traceback)")
        with caplog.at_level("INFO", logger="gearcheck"):  # -v: the traceback goes to the log (stderr)
            assert main(["-v", *args]) == 3
        assert any(r.exc_info and isinstance(r.exc_info[1], registry.HookError) for r in caplog.records)
        assert not (tmp_path / "run").exists()
    finally:
        registry.unregister(cls.name)
