"""Pathological templates are refused BEFORE tomllib parses them, fast and in little memory.

tomllib's time and memory grow with the square of a dotted key's length: an 80 KB template
holding one 40,000-part key (``a.a.a....a = 1``) took 30 s and 6 GB before the nesting check
refused it, and the 1 MB size cap allows 12 times that. The loader's lexical pre-scan
(``_prescan``) refuses such files (keys, tables and brackets nested beyond MAX_NESTING, more
than MAX_TEMPLATE_ENTRIES keys, tables and array items, more than MAX_TEMPLATE_LINES lines) with
one line that names the file, the line, what is wrong and the allowed range. Each hostile file
is read in a fresh interpreter, which reports the time and the growth of its peak memory
(ru_maxrss).

The scan reads strings and comments as such (a "." or "[" inside them is not structure) and
counts nesting as the parsed document nests, so it never refuses a document the post-parse
nesting check accepts: checked on the shipped templates, hand-written corner cases and random
documents.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearcheck.design import load_template
from gearcheck.params import ParamError
from gearcheck.params.common import (
    MAX_NESTING,
    MAX_TEMPLATE_BYTES,
    MAX_TEMPLATE_ENTRIES,
    MAX_TEMPLATE_LINES,
    _check_nesting,
    _prescan,
    parse_override,
    read_toml,
)

TEMPLATES = sorted((Path(__file__).resolve().parents[1] / "templates").glob("*.toml"))
MAX_SECONDS = 1.0
MAX_EXTRA_MB = 200
FILL = MAX_TEMPLATE_BYTES - 100  # a file just under the size cap


def dotted(part: str, count: int) -> str:
    return ".".join([part] * count)


def up_to(unit: str, size: int = FILL, head: str = "", tail: str = "") -> str:
    """head + unit repeated to fill ``size`` bytes + tail."""
    return head + unit * ((size - len(head) - len(tail)) // len(unit)) + tail


HOSTILE = {
    # the reported case: 80 KB, one key of 40,000 parts
    "key_40000_parts_80KB": (dotted("a", 40_000) + " = 1\n", "key 'a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a.a...' "
                             "nested 40000 levels deep; a template allows at most 8"),
    "key_1MB": (dotted("a", FILL // 2) + " = 1\n", "levels deep; a template allows at most 8"),
    "quoted_key_parts_1MB": (dotted('"a"', FILL // 4) + " = 1\n", "levels deep; a template allows at most 8"),
    "spaced_key_parts_1MB": (" . ".join(["a"] * (FILL // 4)) + " = 1\n", "levels deep; a template allows at most 8"),
    "table_header_1MB": ("[" + dotted("a", FILL // 2) + "]\nx = 1\n", "table [a.a.a"),
    "array_of_tables_1MB": ("[[" + dotted("a", FILL // 2) + "]]\nx = 1\n", "table [[a.a.a"),
    "key_in_inline_table_1MB": ("x = {" + dotted("a", FILL // 2) + " = 1}\n", "levels deep; a template allows"),
    "key_deep_in_a_real_template": ("mechanism = \"track\"\n[robot]\nmass_kg = 1.0\n[sprocket]\n"
                                    + dotted("a", FILL // 2) + " = 1\n", "line 5: key"),
    "deep_arrays_1MB": (up_to("[", head="x = "), "arrays / inline tables nested more than 8 levels deep"),
    "deep_inline_tables_1MB": (up_to("{a = ", head="x = "), "nested"),
    "many_keys": ("".join(f"k{i} = 1\n" for i in range(MAX_TEMPLATE_LINES - 1)),
                  f"line {MAX_TEMPLATE_ENTRIES + 1}: more than {MAX_TEMPLATE_ENTRIES} keys, tables and array items"),
    "many_tables": ("".join(f"[t{i}]\n" for i in range(MAX_TEMPLATE_LINES - 1)), "keys, tables and array items"),
    "many_keys_in_one_line_1MB": ("x = {" + ", ".join(f"k{i} = 1" for i in range(FILL // 12)) + "}\n",
                                  "line 1: more than 10000 keys, tables and array items"),
    "many_arrays_1MB": (up_to("[], ", head="x = [", tail="]\n"), "keys, tables and array items"),
    "many_array_items_1MB": (up_to("1, ", head="x = [", tail="]\n"), "keys, tables and array items"),
    "many_array_strings_1MB": (up_to('"a,b", ', head="x = [", tail="]\n"), "keys, tables and array items"),
    "many_lines_1MB": (up_to("#\n"), f"lines; a template has at most {MAX_TEMPLATE_LINES}"),
}

MEASURE = """
import json, resource, sys, time
from pathlib import Path
from gearcheck.params.common import ParamError, read_toml
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
try:
    read_toml(Path(sys.argv[1]))
    error = None
except ParamError as exc:
    error = str(exc)
seconds = time.perf_counter() - start
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"error": error, "seconds": seconds, "extra_mb": (after - before) / 1024}))
"""


@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_template_refused_fast_in_one_line(tmp_path, name):
    text, needle = HOSTILE[name]
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    assert path.stat().st_size <= MAX_TEMPLATE_BYTES  # past the size cap: not this guard's case
    done = subprocess.run([sys.executable, "-c", MEASURE, str(path)], capture_output=True, text=True,
                          timeout=120, check=True)
    result = json.loads(done.stdout)
    error = result["error"]
    assert error is not None, f"{name} was accepted"
    assert "\n" not in error and error.startswith(f"{path}: "), error
    assert needle in error, error
    assert "at most" in error and len(error) < 300, error
    assert result["seconds"] < MAX_SECONDS, result
    assert result["extra_mb"] < MAX_EXTRA_MB, result


@pytest.mark.parametrize("name", ["key_40000_parts_80KB", "deep_arrays_1MB", "many_keys", "many_lines_1MB"])
def test_hostile_template_through_the_loader_and_cli(tmp_path, name):
    """load_template and `gearcheck calc` give the same one line (exit 2)."""
    from test_fuzz_loader import assert_cli_clean, run_cli

    path = tmp_path / f"{name}.toml"
    path.write_text(HOSTILE[name][0], encoding="utf-8")
    with pytest.raises(ParamError) as info:
        load_template(path)
    assert str(info.value).startswith(f"{path}: ")
    code, err = run_cli(["calc", str(path)])
    assert code == 2
    assert_cli_clean(code, err)
    assert str(info.value) in err


# ------------------------------------------------------------------------------ no false refusals
@pytest.mark.parametrize("path", TEMPLATES, ids=lambda p: p.name)
def test_shipped_templates_pass_the_scan_and_load_as_before(path):
    text = path.read_text(encoding="utf-8")
    assert _prescan(text) is None
    assert read_toml(path) == tomllib.loads(text)
    load_template(path)


@pytest.mark.parametrize("text", [
    # structure inside strings and comments is not structure
    '"a.b.c.d.e.f.g.h.i.j" = "k.l.m.n.o.p.q.r.s [[[[[[[[[[ {{{{{{{{{{"\n',
    "'a.b.c.d.e.f.g.h.i.j' = '[[[[[[[[[[[['\n",
    'x = """\n[a.b.c.d.e.f.g.h.i.j]\nk.l.m.n.o.p.q.r.s.t = [[[[[[[[[[\n"""\n',
    "x = '''\n[[a.b.c.d.e.f.g.h.i.j]]\n{{{{{{{{{{{{\n'''\n",
    'x = """ends in two quotes"""""\ny = "\\"[[[[[[[[[["\n',
    "x = '''ends in two quotes'''''\ny = 1\n",
    'x = "escaped backslash \\\\"\ny = 1\n',
    'x = """line \\\n  continued [[[[[[[[[[ \\""" """\ny = 1\n',
    "# [[[[[[[[[[[[ a.b.c.d.e.f.g.h.i.j = {{{{{{{\nx = 1 # ]]]]]]]]] a.b.c.d.e.f.g.h.i.j\n",
    # every level up to MAX_NESTING, counted as _check_nesting counts it
    "[a.b.c]\nd.e.f.g.h = 1\n",
    "[[a.b.c.d.e.f]]\ng = 1\n",
    "a.b.c.d.e.f.g = [1, 2]\n",
    "a.b.c.d.e.f.g.h = []\n",
    "x = [[[[[[[1]]]]]]]\n",
    "x = {a = {b = {c = {d = {e = {f = {g = 1}}}}}}}\n",
    "x = [{a = [{b = [{c = 1}]}]}]\n",
    "x = [\n  1,  # one\n  [2, 3],\n  {a = 1},\n]\n",
    "x = { }\ny = [ ]\n[ t . \"u.v\" . 'w' ]\nz\t=\t1\r\n",
    "dates = [1979-05-27, 1979-05-27T07:32:00Z, 1979-05-27 07:32:00, 07:32:00]\nn = [1.5e3, -0.0, inf, -inf]\n",
    '"" = 1\n\'x\' . "" = 2\n',
    # commas in an array's strings and comments are not items
    'x = ["' + "," * 2 * MAX_TEMPLATE_ENTRIES + '", \'' + "," * 2 * MAX_TEMPLATE_ENTRIES + "', 1]\n",
    "x = [1, # " + "," * 2 * MAX_TEMPLATE_ENTRIES + "\n  2]\n",
])
def test_tricky_but_valid_documents_read_as_tomllib_reads_them(tmp_path, text):
    path = tmp_path / "tricky.toml"
    path.write_text(text, encoding="utf-8", newline="")
    assert _prescan(text) is None
    assert read_toml(path) == tomllib.loads(text)


@pytest.mark.parametrize("text, needle", [
    ("[a.b.c]\nd.e.f.g.h.i = 1\n", "line 2: key 'd.e.f.g.h.i' nested 9 levels deep"),
    ("[[a.b.c.d.e.f.g.h]]\n", "line 1: table [[a.b.c.d.e.f.g.h]] nested 9 levels deep"),
    ("a.b.c.d.e.f.g.h = [[]]\n", "line 1: arrays / inline tables nested more than 8 levels deep"),
    ("x = {a = {b = {c = {d = {e = {f = {g = {h = 1}}}}}}}}\n", "line 1: key 'h' nested 9 levels deep"),
    ('x = 1\n"a.b"."c.d".e.f.g.h.i.j.k = 1\n', "line 2: key '\"a.b\".\"c.d\".e.f.g.h.i.j.k' nested 9 levels deep"),
])
def test_one_level_too_deep_is_refused_by_the_scan(tmp_path, text, needle):
    path = tmp_path / "deep.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParamError) as info:
        read_toml(path)
    assert str(info.value) == f"{path}: {needle}; a template allows at most {MAX_NESTING}"
    assert _check_nesting_refuses(tomllib.loads(text))


def _check_nesting_refuses(data: dict) -> bool:
    try:
        _check_nesting(data, "", 0)
    except ParamError:
        return True
    return False


bare = st.sampled_from(["a", "b", "c1", "x-y", "_", "1", "true", "inf"])
quoted = st.sampled_from(['"a.b"', "'c.d'", '"[e]"', '""', '"q\\"."', "'{'", '"#"', '"x = [1"'])
gaps = st.sampled_from(["", " ", "\t"])


@st.composite
def keys(draw) -> str:
    gap = draw(gaps)
    return f"{gap}.{gap}".join(draw(st.lists(st.one_of(bare, bare, quoted), min_size=1, max_size=4)))


scalars = st.sampled_from([
    "1", "1.5", "-0.0", "1e5", "true", "inf", "nan", "0x1F", "+1_000", "1979-05-27", "1979-05-27T07:32:00Z",
    "1979-05-27 07:32:00", "07:32:00", '"s.t[u]{v}#w"', "'l[it]'", '"""m\nl.\n[[x]]\n"""', "'''a\n]]]\n'''",
    '"""q"""""', "'''q'''''", '"esc\\\\"', '"\\""', '""', "''",
])


def values(depth: int):
    if depth == 0:
        return scalars
    inner = st.deferred(lambda: values(depth - 1))
    return st.one_of(
        scalars, scalars,
        st.lists(inner, max_size=3).map(lambda xs: "[" + ",\n  ".join(xs) + (",]" if len(xs) % 2 else "]")),
        st.lists(st.tuples(keys(), inner), max_size=3).map(
            lambda kv: "{" + ", ".join(f"{k} = {v}" for k, v in kv) + "}"),
    )


lines = st.one_of(
    st.tuples(keys(), gaps, values(4), st.sampled_from(["", " # c[", "\t#x.y.z {"])).map(
        lambda t: f"{t[0]}{t[1]}={t[1]}{t[2]}{t[3]}"),
    st.tuples(keys(), gaps).map(lambda t: f"[{t[1]}{t[0]}{t[1]}]"),
    keys().map(lambda k: f"[[{k}]]"),
    st.sampled_from(["", "# comment [[[", "   ", "\t# x = {"]),
)


@settings(derandomize=True, deadline=None, database=None, max_examples=300,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much])
@given(body=st.lists(lines, max_size=10), crlf=st.booleans())
def test_random_documents_scan_agrees_with_the_parser(body, crlf):
    """For random valid TOML (dotted and quoted keys, headers, arrays of tables, nested arrays and
    inline tables, strings full of brackets and dots): the scan refuses only documents that the
    post-parse nesting check refuses too, and it reads to the end (a too-deep key appended after
    the document is found, on its line)."""
    newline = "\r\n" if crlf else "\n"
    text = newline.join(body) + newline
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        return
    if _prescan(text) is not None:
        assert _check_nesting_refuses(data), text
    deeper = text + "zz_appended." + dotted("a", MAX_NESTING) + " = 1\n"
    try:
        tomllib.loads(deeper)
    except tomllib.TOMLDecodeError:
        return
    found = _prescan(deeper)
    assert found is not None, text
    assert found[0] == deeper.count("\n") or "zz_appended" not in found[1], (text, found)


# -------------------------------------------------------------------------------------- --set
SET_MEASURE = """
import json, resource, sys, time
from gearcheck.params.common import ParamError, parse_override
text = sys.stdin.read()
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
try:
    parse_override(text)
    error = None
except ParamError as exc:
    error = str(exc)
seconds = time.perf_counter() - start
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"error": error, "seconds": seconds, "extra_mb": (after - before) / 1024}))
"""


@pytest.mark.parametrize("override, needle", [
    (dotted("a", 40_000) + "=1", "key nested 40000 levels deep; allowed at most 8"),
    (dotted("a", FILL // 2) + "=1", "levels deep; allowed at most 8"),
    # a long dotted key inside an inline-table value: tomllib is quadratic on it too
    ("gears.module_mm={" + dotted("a", 40_000) + " = 1}", "nested 40002 levels deep"),
    ("gears.module_mm={" + dotted("a", FILL // 2) + " = 1}", "levels deep; a template allows at most 8"),
    ("gears.module_mm=1\n[" + dotted("a", FILL // 2) + "]", "table [a.a.a"),
    ("gears.module_mm=" + "[" * FILL, "nested more than 8 levels deep"),
])
def test_hostile_override_refused_fast_in_one_line(override, needle):
    done = subprocess.run([sys.executable, "-c", SET_MEASURE], input=override, capture_output=True, text=True,
                          timeout=120, check=True)
    result = json.loads(done.stdout)
    error = result["error"]
    assert error is not None and "\n" not in error and len(error) < 600, error
    assert error.startswith("--set"), error
    assert needle in error, error
    assert result["seconds"] < MAX_SECONDS, result
    assert result["extra_mb"] < MAX_EXTRA_MB, result


@pytest.mark.parametrize("text, value", [
    ('a.b="x.y.z.a.b.c.d.e.f [[[[[[[[[["', "x.y.z.a.b.c.d.e.f [[[[[[[[[["),
    ("a.b=[[1, 2], [3]]", [[1, 2], [3]]),
    ("a.b={c = {d = 1}}", {"c": {"d": 1}}),
    ("a.b=x.y", "x.y"),
])
def test_ordinary_overrides_unchanged(text, value):
    assert parse_override(text)[1] == value
