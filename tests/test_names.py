"""Names that become file names, and the bounds every input is held to: the attacks a hostile
user made on the tool, each a regression test. Each failed on the code before these rules (the
docstring says how):

* an assembly part named ``"/some/where/thesis"`` replaced the user's file at that path with an
  STL (the STL writer joined the run folder with the name);
* ``gearcheck new assembly`` copied product names verbatim and wrote templates its own rules
  refused (spaces from the file name, dots, names over 200 characters);
* a properly encoded non-ASCII product name (``齿轮``) was read as its occurrence id;
* range messages ended in a colon with nothing after it for fields inside lists of tables;
* an axis ``[0, 0, 1e308]`` overflowed;
* ``--jobs`` above the cores was said twice and not applied to a local Dask cluster;
* an unknown field of a study file was reported only after every variant was drawn.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np
import pytest

from conftest import TEMPLATES
from gearcheck.cli import main
from gearcheck.names import OutsideFolderError, as_name, file_in, is_name, name_problem

SPUR_STEP = TEMPLATES / "assembly_spur_pair.step"


# ------------------------------------------------------------------------------------------
# The rule itself


@pytest.mark.parametrize("name", ["gear", "齿轮", "Zahnrad_2", "pinion-1", "v1.2", "_x", "a" * 64])
def test_names_that_can_name_a_file(name):
    assert is_name(name)


@pytest.mark.parametrize("name", ["", "/some/where/thesis", "a/b", "a\\b", "..", ".hidden", "-flag", "a b",
                                  "tab\there", "nl\n", "gear#2", "a~b", "a@b", "a" * 65, "齿" * 67, None, 3])
def test_names_that_cannot(name):
    assert name_problem(name) is not None


def test_a_part_name_takes_no_dot():
    assert is_name("v1.2") and not is_name("v1.2", dots=False)


@pytest.mark.parametrize("text", ["/some/where/thesis", "a.b c", "..", "\x00\x01", "gear#2", "  ", "齿轮 左",
                                  "x" * 500, "😀" * 80, "-lead", ".hidden"])
def test_any_text_becomes_a_valid_unique_name(text):
    name = as_name(text)
    assert is_name(name, dots=False), name
    again = as_name(text, {name})
    assert again != name and is_name(again, dots=False)


def test_a_file_is_written_only_inside_its_folder(tmp_path):
    assert file_in(tmp_path, "gear.stl") == tmp_path / "gear.stl"
    outside = tmp_path.parent / "victim.stl"
    for bad in ["/some/where/thesis.stl", "../victim.stl", "a/b.stl", "..", ".", "", str(outside)]:
        with pytest.raises(OutsideFolderError):
            file_in(tmp_path, bad)
    (tmp_path / "link.stl").symlink_to(outside)
    with pytest.raises(OutsideFolderError):
        file_in(tmp_path, "link.stl")


def test_the_stl_writer_refuses_a_name_outside_the_run(tmp_path):
    """Before: ``export_parts`` wrote ``folder / f"{name}.stl"``, an absolute name anywhere."""
    import cadquery as cq

    from gearcheck.cad.export import export_parts
    from gearcheck.cad.placement import Part

    victim = tmp_path / "thesis"
    victim.write_text("my thesis")
    run = tmp_path / "run"
    run.mkdir()
    part = Part(str(victim), "steel", cq.Workplane().box(1, 1, 1).val())
    with pytest.raises(OutsideFolderError):
        export_parts([part], run, name="x", mechanism="assembly", params_data={}, tol_mm=0.1)
    assert victim.read_text() == "my thesis"
    assert not (tmp_path / "thesis.stl").exists()


# ------------------------------------------------------------------------------------------
# The rule applied at calc, and by `new assembly`


def _assembly(tmp_path: Path, part_a: str, part_b: str, extra: str = "", axis: str = "[0, 0, 1]") -> Path:
    tpl = tmp_path / "pair.toml"
    tpl.write_text(f'''mechanism = "assembly"
[assembly]
step = "{SPUR_STEP}"
[[part]]
name = "{part_a}"
product = "pinion"
[[part]]
name = "{part_b}"
product = "gear"
[[joint]]
part = "{part_a}"
kind = "revolute"
axis = {axis}
point = [0, 0, 0]
[motion]
part = "{part_a}"
start_deg = 0
end_deg = 10
step_deg = 1
{extra}
''', encoding="utf-8")
    return tpl


@pytest.mark.parametrize("bad", ["/some/where/thesis", "sub/thesis", "a.b", ".x", "x" * 201, "g#2"])
def test_calc_refuses_a_part_name_that_is_no_file_name(tmp_path, capsys, bad):
    """Before: ``/some/where/thesis`` passed calc, and check wrote thesis.stl over the user's file."""
    victim = Path("/some/where/thesis.stl")
    tpl = _assembly(tmp_path, bad, "gear")
    assert main(["calc", str(tpl)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    named = [e for e in err if "part.0.name" in e]  # (a long name also breaks the references' length)
    assert len(named) == 1 and "allowed" in named[0] and "letters" in named[0], err
    assert not victim.exists()


def test_a_unicode_part_name_is_a_name(tmp_path, capsys):
    """Before: a template naming a part 齿轮 was refused (the rule allowed ASCII only)."""
    tpl = _assembly(tmp_path, "齿轮", "gear")
    assert main(["calc", str(tpl)]) == 0, capsys.readouterr().err


def test_new_assembly_writes_names_its_own_rules_accept(tmp_path, capsys):
    """Before: a STEP named "my gear box.step" with products "/some/where/thesis", "a.b c", a
    300-character name gave a template its own rules refused (the name with spaces, part names
    with dots and slashes, names over 200 characters: a raw regex as the message)."""
    import tomllib

    import cadquery as cq

    step = tmp_path / "my gear box.step"
    long = "p" * 300
    a = cq.Assembly(name="root")
    for k, name in enumerate(["/some/where/thesis", "a.b c", long, "a_b_c"]):
        a.add(cq.Workplane().box(2, 2, 2).translate((10 * k, 0, 0)), name=name)
    a.export(str(step))
    out = tmp_path / "mine.toml"
    assert main(["new", "assembly", "--step", str(step), "--out", str(out)]) == 0, capsys.readouterr().err
    data = tomllib.loads(out.read_text(encoding="utf-8"))
    assert is_name(data["name"])
    names = [p["name"] for p in data["part"]]
    assert all(is_name(n, dots=False) for n in names) and len(set(names)) == len(names), names
    products = [p.get("product", p["name"]) for p in data["part"]]
    assert products == ["/some/where/thesis", "a.b c", long, "a_b_c"]
    # with its motion filled in, as a user would, the written template validates
    out.write_text(out.read_text(encoding="utf-8") + f'''
[[joint]]
part = "{names[0]}"
kind = "revolute"
axis = [0, 0, 1]
[motion]
part = "{names[0]}"
start_deg = 0
end_deg = 10
step_deg = 5
''', encoding="utf-8")
    assert main(["calc", str(out)]) == 0, capsys.readouterr().err


def _write_cjk_step(path: Path) -> None:
    """A STEP file whose product and occurrence are named 齿轮 as ISO 10303-21 encodes it
    (``\\X2\\9F7F8F6E\\X0\\``), as CAD programs that follow the standard write it."""
    import cadquery as cq

    plain = path.with_suffix(".plain.step")
    a = cq.Assembly(name="root")
    a.add(cq.Workplane().box(4, 4, 4), name="GEARNAME")
    a.add(cq.Workplane().box(2, 2, 2).translate((20, 0, 0)), name="other")
    a.export(str(plain))
    text = plain.read_text(encoding="utf-8").replace("GEARNAME", "\\X2\\9F7F8F6E\\X0\\")
    path.write_text(text, encoding="ascii")


def test_an_encoded_non_ascii_product_keeps_its_name(tmp_path):
    """Before: read as ``1`` (the occurrence's id, which OCCT puts in place of such a name)."""
    from gearcheck.cad.step_import import read_step

    step = tmp_path / "cjk.step"
    _write_cjk_step(step)
    assert read_step(step).names() == ["齿轮", "other"]


def test_a_non_ascii_part_round_trips_through_the_written_step(tmp_path):
    """The run's STEP writes 齿轮 in the standard's encoding (OCCT wrote its UTF-8 bytes as
    Latin-1 characters, é½¿è½®), and reads back as written."""
    import cadquery as cq

    from gearcheck.cad.placement import Part
    from gearcheck.cad.step import step_products, write_step
    from gearcheck.cad.step_import import read_step

    path = tmp_path / "out.step"
    pose = np.eye(4)
    pose[0, 3] = 9.0
    parts = [Part("齿轮", "steel", cq.Solid.makeBox(3, 3, 3)),
             Part("Zahnräder_😀", "steel", cq.Solid.makeBox(2, 2, 2), pose)]
    data = write_step(parts, path, "run")  # verified as written: products and occurrences by name
    assert data.isascii() and b"\\X2\\9F7F8F6E\\X0\\" in data and b"\\X4\\0001F600\\X0\\" in data
    assert step_products(path)[1] == ["齿轮", "Zahnräder_😀"]
    assert read_step(path).names() == ["齿轮", "Zahnräder_😀"]


# ------------------------------------------------------------------------------------------
# Range messages, axes


@pytest.mark.parametrize("extra, field", [
    ('[[joint]]\npart = "gear"\nkind = "revolute"\naxis = [0, 0, 1]\n'
     '[[couple]]\ndriver = "pinion"\ndriven = "gear"\nratio = 1e9', "couple.0.ratio"),
    ('[[joint]]\npart = "gear"\nkind = "revolute"\naxis = [0, 0, 1]\n[play]\npart = "gear"\nlimit_deg = 1000',
     "play.limit_deg"),
    ('[[joint]]\npart = "gear"\nkind = "revolute"\naxis = [0, 0, 1]\n[play]\npart = "gear"\nlimit_mm = 1e9',
     "play.limit_mm"),
    ('[[require]]\nparts = ["pinion", "gear"]\nmin_clearance_mm = 1e9', "require.0.min_clearance_mm"),
    ('[[state]]\nname = "hot"\ntemperature_C = 1e9', "state.0.temperature_C"),
    ("", "part.0.cte_per_K"),
])
def test_every_range_message_names_its_range(tmp_path, capsys, extra, field):
    """Before: "out of range: " and nothing after the colon, for fields inside lists of tables
    and optional sections."""
    tpl = _assembly(tmp_path, "pinion", "gear", extra)
    if field == "part.0.cte_per_K":
        tpl.write_text(tpl.read_text().replace('product = "pinion"', 'product = "pinion"\ncte_per_K = 1.0'))
    assert main(["calc", str(tpl)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    line = next(e for e in err if field in e)
    assert "allowed" in line and not line.rstrip().endswith(":"), line


def test_an_axis_is_a_direction(tmp_path, capsys):
    """Before: [0, 0, 1e308] was accepted with a numpy overflow warning, and its poses differed
    from [0, 0, 1]'s."""
    import gearcheck

    assert main(["calc", str(_assembly(tmp_path, "pinion", "gear", axis="[0, 0, 1e308]"))]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "joint.0.axis" in err[0] and "1e+06" in err[0], err
    long = gearcheck.load(_assembly(tmp_path, "pinion", "gear", axis="[0, 0, 1e5]"))
    unit = gearcheck.load(_assembly(tmp_path, "pinion", "gear", axis="[0, 0, 1]"))
    assert np.allclose(long.params.joint[0].axis, unit.params.joint[0].axis, rtol=0, atol=1e-15)


# ------------------------------------------------------------------------------------------
# Bounded flags and early refusals


def test_the_jobs_cap_is_said_once(caplog, monkeypatch):
    """Before: ``check --jobs 64`` printed the cap's warning twice (the check and its pool)."""
    from gearcheck import executor

    monkeypatch.setattr(executor, "available_cores", lambda: 2)
    monkeypatch.setattr(executor, "_CAPPED_SAID", set())
    with caplog.at_level(logging.WARNING, logger=executor.log.name):
        assert executor.capped_jobs(64) == 2
        assert executor.capped_jobs(64) == 2
    assert sum("--jobs 64" in r.getMessage() for r in caplog.records) == 1


def test_a_local_cluster_is_capped_at_the_cores(monkeypatch):
    """Before: ``study --scheduler local-cluster --jobs 100000`` asked Dask for 100000 workers
    (one process, 447 MB after 150 s, nothing started)."""
    from gearcheck import executor

    monkeypatch.setattr(executor, "available_cores", lambda: 2)
    asked = {}

    def cluster(**kwargs):
        asked.update(kwargs)
        return object()

    executor.DaskExecutor._local_cluster(cluster, 100_000)
    assert asked["n_workers"] == 2


def test_an_unknown_study_field_is_refused_before_any_variant(tmp_path, capsys, monkeypatch):
    """Before: every one of the variants was drawn and evaluated (15 s for 50000) before the
    unknown field was reported, as "every variant was rejected"."""
    from gearcheck.studies import core

    study = (TEMPLATES / "studies" / "steering_tolerances.toml").read_text(encoding="utf-8")
    study = study.replace('field = "trim.hS2_mm"', 'field = "trim.hS2_mmx"').replace(
        'template = "nose_wheel_steering.toml"', f'template = "{TEMPLATES / "nose_wheel_steering.toml"}"')
    path = tmp_path / "st.toml"
    path.write_text(study, encoding="utf-8")

    def drawn(*args, **kwargs):
        raise AssertionError("variants drawn before the study file was checked")

    monkeypatch.setattr(core, "draw", drawn)
    assert main(["study", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "inputs[2].field" in err[0] and "hS2_mm" in err[0], err
    assert not (tmp_path / "out").exists()
    assert os.listdir(tmp_path) == ["st.toml"]
