"""Fuzz the template loader and `gearcheck calc`: whatever the file or the `--set`, the loader
returns or raises ParamError as ONE line naming the file, and the CLI exits 0 or 2 with at most
one line on stderr. Nothing else may escape (no traceback).

Inputs: every byte prefix of every shipped template (truncation, cut UTF-8 sequences), random
bytes, binary garbage and a BOM, random TOML documents built from the real section and key
names with values of every TOML type (strings, huge integers such as 10**400, floats including
nan/inf, booleans, dates, arrays, nested and deeply nested tables), unknown keys, long dotted
keys (refused before parsing), and random `--set` overrides. Seeded (derandomized) so CI runs the same cases every time.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import json
import math
import shutil
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.params import ParamError
from gearcheck.params.common import MAX_NESTING

TEMPLATES = sorted((Path(__file__).resolve().parents[1] / "templates").glob("*.toml"))
TEXTS = {p.name: p.read_bytes() for p in TEMPLATES}
DATA = {p.name: tomllib.loads(p.read_text(encoding="utf-8")) for p in TEMPLATES}
SECTIONS = sorted({s for d in DATA.values() for s, body in d.items() if isinstance(body, dict)})
KEYS = sorted({k for d in DATA.values() for body in d.values() if isinstance(body, dict) for k in body})
DOTTED = sorted({f"{s}.{k}" for d in DATA.values() for s, body in d.items() if isinstance(body, dict) for k in body})

FUZZ = settings(derandomize=True, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The templates' copies go here, beside the STEP files an assembly template names."""
    out = tmp_path_factory.mktemp("fuzz")
    for step in TEMPLATES[0].parent.glob("*.step"):
        shutil.copyfile(step, out / step.name)
    return out


def assert_loads_or_one_line(path: Path) -> None:
    """load_template(path) returns, or raises ParamError: one line per broken rule, each naming
    the file."""
    try:
        load_template(path)
    except ParamError as exc:
        lines = str(exc).split("\n")
        for text in lines:
            assert "\r" not in text and text.startswith(f"{path}: "), text
            assert len(text) < 600, text


def run_cli(argv: list[str]) -> tuple[int, str]:
    """gearcheck's exit code and stderr (argparse usage errors exit through SystemExit)."""
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    return code, err.getvalue()


def assert_cli_clean(code: int, err: str) -> None:
    assert code in (0, 2), (code, err)
    if code == 0:
        assert err == ""
    else:
        assert err.endswith("\n") and all(line.startswith("gearcheck: error: ") for line in err.splitlines()), err
    assert "Traceback" not in err


# ---------------------------------------------------------------------------------- files
@pytest.mark.parametrize("name", sorted(TEXTS))
def test_every_prefix_of_every_template(folder, name):
    """Each byte prefix (cut anywhere, also inside a multi-byte character) loads (a cut in a
    trailing comment, or one that leaves a shorter valid number) or is one line."""
    text = TEXTS[name]
    path = folder / f"prefix_{name}"
    accepted = []
    # every 3rd length, and every length next to a line break or inside a multi-byte character
    special = {i + d for i, b in enumerate(text) if b >= 0x80 or b == 0x0A for d in (0, 1)}
    for n in sorted({*range(0, len(text) + 1, 3), *special, len(text)} & set(range(len(text) + 1))):
        path.write_bytes(text[:n])
        try:
            load_template(path)
            accepted.append(n)
        except ParamError as exc:  # one line per broken rule, each naming the file
            assert all(line.startswith(f"{path}: ") for line in str(exc).split("\n")), str(exc)
    assert len(text) in accepted


@FUZZ
@given(data=st.binary(max_size=400))
def test_random_bytes(folder, data):
    path = folder / "bytes.toml"
    path.write_bytes(data)
    assert_loads_or_one_line(path)


@pytest.mark.parametrize(
    "content",
    [
        b"",
        b"\xef\xbb\xbf",  # a BOM alone
        b"\x00" * 64,
        bytes(range(256)),
        b"\x89PNG\r\n\x1a\n" + bytes(200),
        b"\xef\xbb\xbf\xff\xfe",  # BOM, then invalid UTF-8
        b"[" * 10_000,
        b"x = " + b"[" * 5_000 + b"]" * 5_000,
        b"x = " + b"{a = " * 3_000 + b"1" + b"}" * 3_000,
        b"[" + b".".join([b"a"] * 3_000) + b"]\nx = 1\n",
        # long dotted keys: tomllib is quadratic on them (40,000 parts took 30 s, 6 GB), so the
        # loader's pre-scan refuses them before parsing (tests/test_loader_limits.py times it)
        b".".join([b"a"] * 40_000) + b" = 1\n",
        b"x = {" + b".".join([b'"a"'] * 20_000) + b" = 1}\n",
        b"mechanism = \"track\"\n[[" + b".".join([b"a"] * 20_000) + b"]]\n",
        b"x = \"\"\"\n" + b".".join([b"a"] * 20_000) + b" = [[[[[[[[[[\n\"\"\"\n",  # in a string: not structure
        b"x = [" + b"[], " * 20_000 + b"]\n",
        b"k = 1\n" * 30_000,
        b"mechanism = \"differential\"\n[gears]\nmodule_mm = " + b"9" * 5_000 + b"\n",
        b"mechanism = \"differential\"\n[materials]\nhousing = \"" + b"x" * 100_000 + b"\"\n",
        b"mechanism = \"track\"\n" * 3,
        b"mechanism = [\"track\"]\n",
        b"mechanism = {name = \"track\"}\n",
        b"mechanism = 1979-05-27\n",
    ],
)
def test_garbage_files(folder, content):
    path = folder / "garbage.toml"
    path.write_bytes(content)
    assert_loads_or_one_line(path)
    assert_cli_clean(*run_cli(["calc", str(path)]))


def test_too_large_file_is_rejected_unread(folder):
    path = folder / "large.toml"
    path.write_bytes(b"# " + b"x" * 1_100_000 + b"\n")
    with pytest.raises(ParamError, match="at most"):
        load_template(path)


@pytest.mark.parametrize("name", sorted(TEXTS))
def test_byte_order_mark_is_not_part_of_the_template(folder, name):
    """Some editors start UTF-8 files with a BOM: the template still loads, to the same values."""
    path = folder / f"bom_{name}"
    path.write_bytes(b"\xef\xbb\xbf" + TEXTS[name])
    # the same values as read (a file a template names is found beside each: the same relative path)
    assert load_template(path).data == load_template(TEMPLATES[0].parent / name).data


def test_too_deep_nesting_is_one_line(folder):
    """Nesting beyond MAX_NESTING is refused before anything walks it recursively."""
    path = folder / "deep.toml"
    path.write_text("[" + ".".join(["a"] * (MAX_NESTING + 2)) + "]\nx = 1\n")
    with pytest.raises(ParamError, match="nested"):
        load_template(path)


# ------------------------------------------------------------------- random TOML documents
def toml_value(v) -> str:
    """A TOML literal for v (inline tables and arrays for nesting; nan/inf are TOML words)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string (json's escapes are TOML's)
    if isinstance(v, (datetime.date, datetime.datetime)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_document(doc: dict) -> str:
    lines = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    for section, body in doc.items():
        if isinstance(body, dict):
            lines.append(f"[{json.dumps(section)}]")
            lines += [f"{json.dumps(k)} = {toml_value(v)}" for k, v in body.items()]
    return "\n".join(lines) + "\n"


names = st.one_of(st.sampled_from(KEYS), st.sampled_from(SECTIONS), st.text(min_size=1, max_size=12))
scalars = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(),
    st.sampled_from([10**400, -(10**400), 2**63, -(2**63) - 1, 0, -1]),
    st.booleans(),
    st.text(max_size=30),
    st.dates(),
    st.sampled_from([1e308, 5e-324, -0.0, 0.5, 2.5, 14.0, 33, 13, 90.0, 20.0, -65.0]),
)
values = st.recursive(scalars, lambda inner: st.one_of(
    st.lists(inner, max_size=4), st.dictionaries(names, inner, max_size=4)), max_leaves=12)
mechanisms = st.one_of(st.sampled_from(["differential", "track", "steering"]), scalars)


@st.composite
def documents(draw) -> dict:
    """A real template with some values replaced by random ones and random keys added, or a
    document made only of real names with random values."""
    if draw(st.booleans()):
        doc = json.loads(json.dumps(DATA[draw(st.sampled_from(sorted(DATA)))]))
        for _ in range(draw(st.integers(1, 4))):
            section = draw(st.sampled_from(sorted(doc)))
            if isinstance(doc[section], dict) and doc[section] and draw(st.booleans()):
                key = draw(st.sampled_from(sorted(doc[section])))
                doc[section][key] = draw(values)
            elif isinstance(doc[section], dict):
                doc[section][draw(names)] = draw(values)
            else:
                doc[section] = draw(values)
        if draw(st.booleans()):
            doc[draw(names)] = draw(st.dictionaries(names, values, max_size=3))
        return doc
    doc = {"mechanism": draw(mechanisms)}
    for section in draw(st.lists(st.sampled_from(SECTIONS), max_size=4, unique=True)):
        doc[section] = draw(st.dictionaries(names, values, max_size=5))
    return doc


@settings(FUZZ, max_examples=150)
@given(doc=documents())
def test_random_documents_from_real_keys(folder, doc):
    path = folder / "doc.toml"
    path.write_text(toml_document(doc), encoding="utf-8")
    assert_loads_or_one_line(path)


@settings(FUZZ, max_examples=40)
@given(doc=documents())
def test_cli_calc_on_random_documents(folder, doc):
    path = folder / "cli.toml"
    path.write_text(toml_document(doc), encoding="utf-8")
    assert_cli_clean(*run_cli(["calc", str(path)]))


# -------------------------------------------------------------------------------- --set
set_keys = st.one_of(st.sampled_from(DOTTED), st.sampled_from(SECTIONS), st.sampled_from(KEYS),
                     st.text(max_size=20), st.just("mechanism"),
                     st.builds(lambda a, b: f"{a}.{b}", st.sampled_from(SECTIONS), st.text(max_size=8)))
set_values = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "1e999", str(10**400), "true", "[1, 2]", "{a = 1}", '"12 mm"',
                     "12 mm", "", "=", "[[[[", "0x1F", "1979-05-27", "-0.0", '"x"', "'", '"""']),
    scalars.map(toml_value),
    st.text(max_size=20),
)
FAST_TEMPLATES = sorted(n for n in TEXTS if "steering" not in n)  # steering's calc takes ~1 s


@settings(FUZZ, max_examples=120)
@given(name=st.sampled_from(FAST_TEMPLATES), key=set_keys, value=set_values)
def test_set_overrides(name, key, value):
    """Random `--set KEY=VALUE` on a real template: exit 0 (calc ran) or 2 with one line."""
    path = str(TEMPLATES[0].parent / name)
    assert_cli_clean(*run_cli(["calc", path, f"--set={key}={value}"]))


@settings(FUZZ, max_examples=15)
@given(key=set_keys, value=set_values)
def test_set_overrides_steering(key, value):
    path = str(TEMPLATES[0].parent / "nose_wheel_steering.toml")
    assert_cli_clean(*run_cli(["calc", path, "--set", f"{key}={value}"]))


@pytest.mark.parametrize("override", [
    "gears.module_mm=" + str(10**400),
    "gears.module_mm=" + "9" * 5000,
    "gears.module_mm=nan",
    "gears.module_mm=inf",
    "gears.module_mm=" + "[" * 3000,
    "gears.module_mm=" + "[" * 600 + "]" * 600,
    ".".join(["a"] * 500) + "=1",
    ".".join(["a"] * 40_000) + "=1",
    "gears.module_mm={" + ".".join(["a"] * 40_000) + " = 1}",
    "gears.module_mm=1\n[" + ".".join(["a"] * 40_000) + "]",
    "mechanism=track",
    "mechanism.x=1",
    "gears=1",
    "gears.module_mm.x=1",
    "gears.module_mm={a = {b = 1}}",
    "gears.module_mm=\n",
])
def test_hostile_overrides(override):
    path = str(TEMPLATES[0].parent / "zhurong_differential.toml")
    code, err = run_cli(["calc", path, "--set", override])
    assert code == 2
    assert_cli_clean(code, err)
