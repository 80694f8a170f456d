"""What the command line shows: the templates' JSON Schemas (`gearcheck schema`, the shipped
copies, the `#:schema` first lines), `check --json` / `build --json` (one JSON object on stdout,
nothing else), plain output when piped or with NO_COLOR (no escape codes, lines within the width),
colour on a terminal, progress bars with totals, the demo's verdicts before its pointers to the
calc tables, and `--open` (the browser call recorded, never made)."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import shutil
import sys
import tomllib
from pathlib import Path

import pytest

import gearcheck
from gearcheck import cli
from gearcheck.cli import main
from gearcheck.design import TOL_MAX_MM, TOL_MIN_MM, packaged_templates
from gearcheck.names import NAME_SCHEMA_PATTERN
from gearcheck.mechanism import names
from gearcheck.params import ParamError
from gearcheck.schema import DIALECT, schema_line, schema_text, shipped_schema, template_schema
from gearcheck.terminal import Screen, check_json, text, verdicts_view

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "templates"
TRACK = TEMPLATES / "eod_track_drive.toml"
ESCAPE = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


def run_cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


# --------------------------------------------------------------------------------------------
# A small JSON Schema validator (the keywords the template schemas use; any other keyword is an
# error, so a schema cannot grow a rule this test would silently skip)

KNOWN = {"$schema", "title", "description", "type", "required", "properties", "additionalProperties", "$defs",
         "$ref", "const", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minLength", "maxLength",
         "pattern", "items", "maxItems", "minItems", "default", "unit", "anyOf", "enum"}
TYPES = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
}


def schema_errors(schema: dict, value, root: dict | None = None, path: str = "") -> list[str]:  # noqa: PLR0911
    root = root if root is not None else schema
    unknown = set(schema) - KNOWN
    assert not unknown, f"validator does not know {unknown} at {path}"
    if "$ref" in schema:
        target = root
        for part in schema["$ref"].removeprefix("#/").split("/"):
            target = target[part]
        return schema_errors(target, value, root, path)
    if "anyOf" in schema and all(schema_errors(s, value, root, path) for s in schema["anyOf"]):
        return [f"{path}: matches no anyOf branch"]
    if "const" in schema and value != schema["const"]:
        return [f"{path}: {value!r} is not {schema['const']!r}"]
    if "enum" in schema and value not in schema["enum"]:
        return [f"{path}: {value!r} is not one of {schema['enum']!r}"]
    if "type" in schema and not TYPES[schema["type"]](value):
        return [f"{path}: {value!r} is not of type {schema['type']}"]
    if isinstance(value, dict):
        return _object_errors(schema, value, root, path)
    if isinstance(value, list):
        errors = [f"{path}: {len(value)} items"] if not schema.get("minItems", 0) <= len(value) <= schema.get(
            "maxItems", math.inf) else []
        return errors + [e for i, item in enumerate(value) for e in schema_errors(schema.get("items", {}), item, root,
                                                                                  f"{path}.{i}")]
    if isinstance(value, str):
        errors = [] if schema.get("minLength", 0) <= len(value) <= schema.get("maxLength", math.inf) else [
            f"{path}: length {len(value)}"]
        if "pattern" in schema and not re.search(schema["pattern"], value):
            errors.append(f"{path}: {value!r} does not match {schema['pattern']}")
        return errors
    checks = {"minimum": lambda b: value >= b, "maximum": lambda b: value <= b,
              "exclusiveMinimum": lambda b: value > b, "exclusiveMaximum": lambda b: value < b}
    return [f"{path}: {value} fails {k} {schema[k]}" for k, ok in checks.items() if k in schema and not ok(schema[k])]


def _object_errors(schema: dict, value: dict, root: dict, path: str) -> list[str]:
    errors = [f"{path}.{k}: required" for k in schema.get("required", []) if k not in value]
    props = schema.get("properties", {})
    for k, v in value.items():
        if k in props:
            errors += schema_errors(props[k], v, root, f"{path}.{k}".lstrip("."))
        elif schema.get("additionalProperties") is False:
            errors.append(f"{path}.{k}: unknown key".lstrip("."))
    return errors


def field_schema(schema: dict, dotted: str) -> dict:
    section, key = dotted.split(".")
    ref = schema["properties"][section]["$ref"].removeprefix("#/$defs/")
    return schema["$defs"][ref]["properties"][key]


# --------------------------------------------------------------------------------------------
# Schema


@pytest.mark.parametrize("mechanism", names())
def test_the_schema_command_prints_the_shipped_schema(mechanism):
    code, out, err = run_cli(["schema", mechanism])
    assert code == 0 and err == ""
    assert out == schema_text(mechanism) == shipped_schema(mechanism).read_text(encoding="utf-8")
    schema = json.loads(out)
    assert schema["$schema"] == DIALECT == "https://json-schema.org/draft/2020-12/schema"
    assert schema["additionalProperties"] is False and "mechanism" in schema["required"]
    assert schema["properties"]["mechanism"] == {"const": mechanism, "description": schema["properties"][
        "mechanism"]["description"]}
    assert schema["properties"]["mesh_tol_mm"]["minimum"] == TOL_MIN_MM
    assert schema["properties"]["mesh_tol_mm"]["maximum"] == TOL_MAX_MM
    assert schema["properties"]["name"]["pattern"] == NAME_SCHEMA_PATTERN
    # every key of every section has a description that states its range (or says what it is)
    for section in schema["$defs"].values():
        for key, prop in section["properties"].items():
            assert prop.get("description"), key
            assert "title" not in prop and "null" not in json.dumps(prop), key


def test_the_schema_of_a_template_file_and_an_unknown_mechanism():
    assert run_cli(["schema", str(TRACK)])[1] == schema_text("track")
    code, out, err = run_cli(["schema", "gearbox"])
    assert code == 2 and out == ""
    assert err.count("\n") == 1
    assert "MECHANISM = 'gearbox': allowed one of: assembly, differential, roller_chain, steering, track" in err


def test_pinned_fields_type_range_unit_and_description():
    track = template_schema("track")
    pitch = field_schema(track, "chain.pitch_mm")
    assert pitch["type"] == "number" and pitch["exclusiveMinimum"] == 0 and pitch["maximum"] == 500
    assert pitch["unit"] == "mm" and pitch["description"] == (
        "track pitch p: a link's pins sit two grooves apart (an articulated track, grooves every half pitch; a "
        "standard roller chain is mechanism roller_chain) — allowed >0 to 500 mm")
    teeth = field_schema(track, "sprocket.teeth")
    assert teeth["type"] == "integer" and (teeth["minimum"], teeth["maximum"]) == (7, 301)
    assert teeth["description"] == ("teeth z, one groove per tooth, grooves every half track pitch (odd: every other "
                                    "tooth engages and each takes its turn; even: accepted with a warning) — allowed "
                                    "7 to 301")
    diff = template_schema("differential")
    alpha = field_schema(diff, "gears.pressure_angle_deg")
    assert (alpha["type"], alpha["minimum"], alpha["maximum"], alpha["unit"]) == ("number", 14.5, 30.0, "deg")
    shim = field_schema(diff, "calibration.measured_shim_mm")  # optional: a key that may be left out, never null
    assert shim["type"] == "number" and "anyOf" not in shim and "default" not in shim
    assert shim["description"].endswith("(optional)")
    assert "calibration" not in diff["required"] and "gears" in diff["required"]
    study = field_schema(diff, "shim.study_mm")
    assert study["type"] == "array" and study["items"] == {"type": "number"} and study["maxItems"] == 12


@pytest.mark.parametrize("path", sorted(TEMPLATES.glob("*.toml")), ids=lambda p: p.stem)
def test_each_template_points_at_its_schema_and_validates_against_it(path):
    assert TEMPLATES.resolve() == packaged_templates().resolve()  # templates/ is the shipped folder
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first == schema_line(data["mechanism"]) == f"#:schema ./schema/{data['mechanism']}.json"
    linked = path.parent / first.removeprefix("#:schema ")
    assert linked.read_text(encoding="utf-8") == schema_text(data["mechanism"])
    schema = json.loads(linked.read_text(encoding="utf-8"))
    assert schema_errors(schema, data) == []
    gearcheck.load(path)  # the loader reads the line as a comment
    with contextlib.suppress(ImportError):  # a second opinion where jsonschema is installed
        import jsonschema

        jsonschema.Draft202012Validator.check_schema(schema)
        jsonschema.validate(data, schema, cls=jsonschema.Draft202012Validator)


def _bounded_fields(schema: dict):
    for section, ref in schema["properties"].items():
        if "$ref" not in ref:
            continue
        for key, prop in schema["$defs"][ref["$ref"].removeprefix("#/$defs/")]["properties"].items():
            yield f"{section}.{key}", prop


@pytest.mark.parametrize("path", sorted(TEMPLATES.glob("*.toml")), ids=lambda p: p.stem)
def test_the_schema_refuses_what_the_loader_refuses_field_by_field(path):
    """Each bound the schema states is the loader's: a value just past it is refused by both,
    naming the same field; a wrong type and an unknown key too."""
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    schema = template_schema(data["mechanism"])
    tried = 0
    for dotted, prop in _bounded_fields(schema):
        for bound, step in (("minimum", -1), ("exclusiveMinimum", 0), ("maximum", 1), ("exclusiveMaximum", 0)):
            if bound not in prop:
                continue
            value = prop[bound] + step if prop["type"] == "integer" or step else prop[bound]
            if prop["type"] == "number" and step:
                value = prop[bound] + step * max(1e-6, abs(prop[bound]) * 1e-6)
            section, key = dotted.split(".")
            bad = {**data, section: {**data.get(section, {}), key: value}}
            assert schema_errors(schema, bad), (dotted, value)
            with pytest.raises(ParamError) as info:
                gearcheck.load(bad)
            assert info.value.field == dotted, (dotted, value, str(info.value))
            tried += 1
    assert tried >= 20
    section = next(k for k in schema["required"] if k != "mechanism")
    for bad in ({**data, section: {**data[section], "no_such_key": 1}}, {**data, "no_such_section": {}},
                {**data, "name": "../up"}, {**data, "mesh_tol_mm": 1.0}):
        assert schema_errors(schema, bad)
        with pytest.raises(ParamError):
            gearcheck.load(bad)
    integer = next((d for d, p in _bounded_fields(schema) if p["type"] == "integer"), None)
    if integer is None:  # an assembly's template has no whole-number key
        return
    sec, key = integer.split(".")
    bad = {**data, sec: {**data[sec], key: data[sec][key] + 0.5}}
    assert schema_errors(schema, bad)
    with pytest.raises(ParamError):
        gearcheck.load(bad)


def test_templates_copy_takes_the_schemas_along(tmp_path):
    code, out, _ = run_cli(["templates", "--copy", str(tmp_path / "mine")])
    assert code == 0 and "schema" in out
    for path in sorted((tmp_path / "mine").glob("*.toml")):
        first = path.read_text(encoding="utf-8").splitlines()[0]
        linked = path.parent / first.removeprefix("#:schema ")
        assert linked.is_file() and linked.read_text(encoding="utf-8") == shipped_schema(linked.stem).read_text(
            encoding="utf-8")


# --------------------------------------------------------------------------------------------
# Plain and coloured output


def test_calc_piped_is_plain_and_fits_100_columns(monkeypatch):
    """Before: piped, the calc table was 217 columns wide (each note on its figure's line). Now it
    fits 100 columns whatever COLUMNS says: each figure on one line with its value, the note wrapped
    beside it or under it, every word of it kept."""
    monkeypatch.setenv("COLUMNS", "60")  # not a terminal: COLUMNS is no guide
    code, out, _ = run_cli(["calc", str(TEMPLATES / "zhurong_differential.toml")])
    assert code == 0 and "\x1b" not in out
    lines = out.splitlines()
    assert all(line == line.rstrip() and len(line) <= 100 for line in lines)
    figures = gearcheck.load(TEMPLATES / "zhurong_differential.toml").calc().figures
    words = " ".join(out.split())
    for f in figures:  # a figure and its value on one line, its whole note in the table
        assert any(line.startswith(f.label[:40]) and f"{f.value:.{f.digits}f}" in line for line in lines), f.label
        assert " ".join(f.note.split()) in words or all(w in words for w in f.note.split()), f.label


def run_in_terminal(argv: list[str], columns: int, env: dict) -> tuple[int, str]:
    """Run gearcheck in a pseudo-terminal of ``columns`` columns; its exit code and output."""
    import fcntl
    import pty
    import select
    import struct
    import termios

    pid, fd = pty.fork()
    if pid == 0:  # the child: a terminal on stdin, stdout and stderr
        os.execve(sys.executable, [sys.executable, "-m", "gearcheck", *argv], env)
    fcntl.ioctl(fd, termios.TIOCSWINSZ, struct.pack("HHHH", 40, columns, 0, 0))
    chunks = []
    while True:
        ready, _, _ = select.select([fd], [], [], 60)
        if not ready:
            break
        try:
            data = os.read(fd, 65536)
        except OSError:  # the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    os.close(fd)
    _, status = os.waitpid(pid, 0)
    return os.waitstatus_to_exitcode(status), b"".join(chunks).decode("utf-8", "replace").replace("\r\n", "\n")


@pytest.mark.parametrize("no_color, columns", [(False, 90), (True, 90), (True, 72)],
                         ids=["colour-90", "NO_COLOR-90", "NO_COLOR-72"])
def test_calc_on_a_terminal_wraps_to_its_width(no_color, columns):
    env = {k: v for k, v in os.environ.items() if k not in ("NO_COLOR", "FORCE_COLOR")}
    env.update(TERM="xterm-256color", COLUMNS="300")  # a stale COLUMNS: the terminal's own size decides
    if no_color:
        env["NO_COLOR"] = "1"
    code, out = run_in_terminal(["calc", str(TEMPLATES / "nose_wheel_steering.toml")], columns, env)
    assert code == 0
    assert ("\x1b" in out) != no_color  # colour codes on a terminal, none with NO_COLOR
    shown = [ESCAPE.sub("", line) for line in out.splitlines()]
    assert max(len(line) for line in shown) <= columns
    words = " ".join(shown).split()
    for f in gearcheck.load(TEMPLATES / "nose_wheel_steering.toml").calc().figures:
        assert f"{f.value:.{f.digits}f}" in words, f.label
        assert set(f.note.split()) <= set(words), f.label  # every note kept, only wrapped


def test_progress_on_a_terminal(tmp_path):
    """On a terminal the build shows its stages on stderr with their totals, within the width."""
    env = {k: v for k, v in os.environ.items() if k not in ("NO_COLOR", "FORCE_COLOR", "COLUMNS")}
    env["TERM"] = "xterm-256color"
    code, out = run_in_terminal(["build", str(TRACK), "--out", str(tmp_path / "b")], 100, env)
    assert code == 0, out
    shown = [ESCAPE.sub("", line) for line in re.split(r"[\r\n]", out)]
    assert max(len(line) for line in shown) <= 100
    assert any("building eod_track_drive (track)" in line for line in shown)
    final = [line for line in shown if "meshing eod_track_drive" in line and "13/13 part" in line]
    assert final and "100%" in final[-1]
    assert any(line.startswith(f"wrote {tmp_path / 'b'}/ (") for line in shown)  # stdout, after the bars


def test_verdicts_are_whole_one_line_each_piped_and_wrapped_on_a_terminal(track_check):
    """Before: piped verdict lines up to 748 characters (the whole sentence); then one line within
    120 columns, which cut claims on an 80-column terminal ("towing: no interfer…" twice). Now:
    label, key figure and evidence whole, never cut: one line each piped, wrapped under the badge
    on a terminal; the whole sentence is in summary.json."""
    run = track_check["run"]
    result, name, folder = run.result, run.build.design.name, run.folder
    one_line = text(Screen(False, False, None), *verdicts_view(result, name, folder, Screen(False, False, None)))
    lines = one_line.splitlines()
    n, k = len(result.design_verdicts), len(result.self_checks)
    assert lines[0].startswith(f"PASS {name}: design {n} of {n} verdicts pass; self-checks {k} of {k} pass")
    assert len(lines) == 1 + len(result.verdicts)
    for v, line in zip(result.verdicts, lines[1:], strict=True):  # grep finds a verdict and its key figure
        assert line == f"  {v.level.upper()}  {v.whole_line()}"
        assert v.label in line and v.key_figure in line and "…" not in line
    summary = json.loads((folder / "summary.json").read_text())["track"]
    assert summary["verdict_measured"] == {v.name: v.measured for v in result.verdicts}
    for width in (60, 80, 100):
        for screen in (Screen(False, False, width), Screen(True, True, width)):
            wrapped = text(screen, *verdicts_view(result, name, folder, screen))
            plain = [ESCAPE.sub("", line) for line in wrapped.splitlines()]
            assert all(len(line) <= width for line in plain[1:])
            joined = " ".join(line.strip() for line in plain[1:])
            for v in result.verdicts:  # every word of every claim and figure is there, nothing cut
                assert " ".join(v.whole_line().split()) in joined, v.whole_line()
            assert ("\x1b[" in wrapped) == screen.color


def test_a_verdict_line_keeps_the_figure_and_shortens_the_label_last():
    from gearcheck.results import Verdict

    v = Verdict.of("x", "a long label " * 6, False, "measured 1; more", evidence="mesh sweep (FCL)",
                   shortfall="least gap 0.31 mm, required ≥ 0.5 mm, short by 0.19 mm")
    assert v.key_figure == "least gap 0.31 mm, required ≥ 0.5 mm, short by 0.19 mm"
    line = v.line(120, 8)
    assert len(line) <= 112 and line.endswith(v.key_figure) and "…" in line
    ok = Verdict.of("y", "free", True, "60.871°; exact model 60.871° (towing)", evidence="exact model")
    assert ok.key_figure == "60.871°" and ok.line() == "free: 60.871° [exact model]"


# --------------------------------------------------------------------------------------------
# check --json, build --json, progress, --open


class Recorder:
    """Stands in for the CLI's progress display: what the pipeline asked it to show."""

    def __init__(self):
        self.waits: list[str] = []
        self.bars: list[dict] = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return None

    def wait(self, desc):
        self.waits.append(desc)

    @contextlib.contextmanager
    def __call__(self, desc, total=None, unit=""):
        record = {"desc": desc, "total": total, "unit": unit, "done": 0}
        self.bars.append(record)

        class Bar:
            def update(self, n=1):
                record["done"] += n

        yield Bar()


@pytest.fixture(scope="module")
def track_check(tmp_path_factory):
    """One `gearcheck check --json --open` of the track drive, with its progress and browser calls
    recorded and the CheckRun kept."""
    from gearcheck import pipeline

    out = tmp_path_factory.mktemp("cli_output") / "track"
    recorder, opened, runs = Recorder(), [], []
    real_check = pipeline.check

    def keep(*args, **kwargs):
        runs.append(real_check(*args, **kwargs))
        return runs[-1]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(cli, "_display", lambda *a, **k: recorder)
        mp.setattr(pipeline, "check", keep)
        mp.setattr("webbrowser.open", lambda uri, *a, **k: opened.append(uri) or True)
        code, stdout, stderr = run_cli(["check", str(TRACK), "--json", "--open", "--jobs", "2", "--out", str(out)])
    return {"code": code, "stdout": stdout, "stderr": stderr, "out": out, "progress": recorder,
            "opened": opened, "run": runs[0]}


CHECK_KEYS = {"mechanism", "name", "template", "folder", "level", "passed", "counts", "verdicts", "figures",
              "confirmations", "mesh", "files"}


def test_check_json_is_one_object_on_stdout(track_check):
    assert track_check["code"] == 0
    body = json.loads(track_check["stdout"])  # the whole of stdout is one JSON object
    assert set(body) == CHECK_KEYS
    out = track_check["out"]
    assert (body["mechanism"], body["name"], body["folder"]) == ("track", "eod_track_drive", str(out.absolute()))
    assert body == check_json(track_check["run"])  # what the CLI prints is the function's object
    summary = json.loads((out / "summary.json").read_text())["track"]
    assert sorted(v["name"] for v in body["verdicts"]) == sorted(summary["verdict_levels"])
    for v in body["verdicts"]:
        assert set(v) == {"name", "label", "level", "measured", "evidence", "figures"}
        assert v["level"] == summary["verdict_levels"][v["name"]] and v["measured"] and v["evidence"]
    assert body["level"] == "pass" and body["passed"] is True
    assert body["counts"] == {"pass": len(body["verdicts"]), "warn": 0, "fail": 0}
    files = {f["file"]: f["bytes"] for f in body["files"]}
    on_disk = {p.name: p.stat().st_size for p in out.iterdir() if not p.name.startswith(".")}
    assert files == on_disk and {"report.html", "summary.json", "sweep.csv", "manifest.json", "params.toml",
                                 "eod_track_drive.step"} <= set(files)
    manifest = json.loads((out / "manifest.json").read_text())
    assert body["mesh"]["chordal_tolerance_mm"] == manifest["chordal_tolerance_mm"]
    assert body["mesh"]["parts"] == len(manifest["parts"]) == 13
    assert body["confirmations"] and all(c["agrees"] and abs(c["mesh_mm"] - c["brep_mm"]) <= c["bound_mm"]
                                         for c in body["confirmations"])
    assert any(f["label"].startswith("seated tip gap") and f["geometry"] == pytest.approx(0.75, abs=0.01)
               for f in body["figures"])


def test_progress_bars_have_totals_and_reach_them(track_check):
    progress = track_check["progress"]
    assert progress.waits == ["building eod_track_drive (track)"]
    descs = [b["desc"] for b in progress.bars]
    for stage in ("meshing", "sweeping", "exact B-rep"):
        assert any(d.startswith(stage) for d in descs), descs
    for bar in progress.bars:
        assert isinstance(bar["total"], int) and bar["total"] > 0, bar
        assert bar["done"] == bar["total"], bar


def test_open_opens_the_report(track_check):
    assert track_check["opened"] == [(track_check["out"] / "report.html").absolute().as_uri()]


def test_build_json_and_open_the_folder(tmp_path, monkeypatch):
    opened = []
    monkeypatch.setattr("webbrowser.open", lambda uri, *a, **k: opened.append(uri) or True)
    code, out, _ = run_cli(["build", str(TRACK), "--json", "--open", "--out", str(tmp_path / "b")])
    assert code == 0
    body = json.loads(out)
    assert set(body) == {"mechanism", "name", "template", "folder", "mesh", "parts", "files"}
    assert body["folder"] == str((tmp_path / "b").absolute()) and opened == [(tmp_path / "b").absolute().as_uri()]
    manifest = json.loads((tmp_path / "b" / "manifest.json").read_text())
    assert [p["name"] for p in body["parts"]] == [p["name"] for p in manifest["parts"]]
    assert all(set(p) == {"name", "material", "triangles", "brep_volume_mm3", "mesh_error_bound_mm"}
               for p in body["parts"])
    assert {f["file"]: f["bytes"] for f in body["files"]} == {p.name: p.stat().st_size for p in (
        tmp_path / "b").iterdir() if not p.name.startswith(".")}


def test_bad_input_with_json_is_one_line_on_stderr_and_nothing_on_stdout(tmp_path):
    code, out, err = run_cli(["check", str(TRACK), "--json", "--set", "sprocket.teeth=5", "--out", str(tmp_path)])
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "sprocket.teeth = 5" in err


# --------------------------------------------------------------------------------------------
# demo


def test_demo_prints_the_verdicts_first_and_points_at_the_calc_table(tmp_path):
    (tmp_path / "t").mkdir()
    shutil.copy(TRACK, tmp_path / "t" / TRACK.name)
    code, out, _ = run_cli(["demo", "--templates", str(tmp_path / "t"), "--out", str(tmp_path / "o"), "--jobs", "2"])
    assert code == 0 and "\x1b" not in out
    lines = [line for line in out.splitlines() if line]
    calc_txt = tmp_path / "o" / "eod_track_drive" / "calc.txt"
    verdicts = json.loads((calc_txt.parent / "summary.json").read_text())["track"]["verdict_levels"]
    assert lines[0].startswith("PASS eod_track_drive:")
    assert [line.split()[0] for line in lines[1:1 + len(verdicts)]] == ["PASS"] * len(verdicts)
    pointer = lines[1 + len(verdicts)]
    figures = gearcheck.load(TRACK).calc().figures
    assert pointer.startswith(f"  calc: {len(figures)} figures") and pointer.endswith(f"table in {calc_txt}")
    assert len(lines) == len(verdicts) + 4  # headline, verdicts, pointer, files written, the closing line
    assert all(f.label in calc_txt.read_text() for f in figures)  # the full table is where it points


def test_demo_without_cad_points_at_each_table(tmp_path):
    code, out, _ = run_cli(["demo", "--no-cad", "--out", str(tmp_path)])
    assert code == 0
    lines = out.splitlines()
    assert len(lines) == len(list(TEMPLATES.glob("*.toml"))) + 1
    for line in lines[:-1]:
        path = Path(line.rsplit(", table in ", 1)[1])
        design = gearcheck.load(TEMPLATES / f"{path.parent.name}.toml")
        assert line.startswith(f"{design.name} ({design.mechanism}): {len(design.calc().figures)} figures")
        assert path.read_text().startswith(f"{design.name} ({design.mechanism}) — analytical model")


def test_the_help_names_every_shipped_template(capsys):
    """Before: ``gearcheck --help`` named 3 of the 5 templates."""
    from gearcheck.cli import main

    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    shipped = sorted(p.name for p in packaged_templates().glob("*.toml"))
    assert len(shipped) >= 5 and all(name in text for name in shipped), shipped


def test_a_closed_pipe_ends_quietly():
    """Before: ``gearcheck calc … | head -1`` printed "<stdout>: cannot write: Broken pipe
    (EPIPE)" and exited 2."""
    import subprocess
    import sys

    exe = str(Path(sys.executable).parent / "gearcheck")
    proc = subprocess.Popen([exe, "calc", str(TEMPLATES / "zhurong_differential.toml")], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline()
    proc.stdout.close()  # the reader goes away, as head -1 does
    err = proc.stderr.read() if proc.stderr is not None else ""
    assert proc.wait(timeout=60) == 0 and err == "", err


def test_a_closed_pipe_keeps_the_verdicts_exit_code(monkeypatch):
    """A check whose verdict fails still exits 1 when its reader closes the pipe."""
    from gearcheck import cli

    monkeypatch.setattr(cli, "_decided", [1])
    monkeypatch.setattr(cli, "_quiet_stdout", lambda: None)
    assert cli._failed(BrokenPipeError(32, "Broken pipe"), False) == 1


def test_a_key_figure_keeps_its_parenthesis_whole():
    """Before: "short by 1.902′ (the paper's first-order model meets it" — the key figure was cut at
    the "; " inside the parenthesis, which then never closed."""
    from gearcheck.results import Verdict

    shortfall = ("least cold total 8.098′, required ≥ 10′, short by 1.902′ (the paper's first-order model meets "
                 "it; the exact geometry loses more); more words 3")
    v = Verdict.of("x", "cold total", False, "m 1", evidence="mesh sweep", shortfall=shortfall)
    assert v.key_figure == shortfall.split("); ")[0] + ")"
