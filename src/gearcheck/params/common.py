"""Template loading, ``--set`` overrides and one-line error messages.

A template is a TOML file whose top-level ``mechanism`` key names the mechanism; every other
table is a section validated by that mechanism's pydantic model. Every bad value ends in a
:class:`ParamError` whose text names the file, the field path, the value and the allowed range,
so the CLI can print one line and exit 2.
"""

from __future__ import annotations

import copy
import math
import os
import re
import stat
import tomllib
import types
import typing
from pathlib import Path
from typing import Any, ClassVar, NoReturn

import annotated_types as at
from pydantic import BaseModel, ConfigDict, ValidationError, model_validator

# re-exported: the mechanisms' validators import the range helpers from here
from gearcheck.params.bounds import bisect_boundary, fmt_bound, fmt_range  # noqa: F401

# Guard against pathological files before any parsing work.
MAX_TEMPLATE_BYTES = 1_000_000
# Deepest nesting a template may have (a template is sections of keys, a key may hold a flat
# list: 3 levels); deeper documents are rejected before anything walks them recursively.
MAX_NESTING = 8
# Checked on the text before tomllib parses it (tomllib's time and memory grow with the square of
# a dotted key's length: one 40,000-part key in 80 KB took 30 s and 6 GB to reject). The shipped
# templates hold ~40 keys in ~8 tables on ~60 lines, nested at most 3 deep; these allow 250x that.
MAX_TEMPLATE_LINES = 20_000
MAX_TEMPLATE_ENTRIES = 10_000  # keys, [tables], arrays, inline tables and array items together
# Longest value shown in an error line (strings, e.g. paths, get more room than numbers).
MAX_SHOWN_CHARS = 60
MAX_SHOWN_STRING_CHARS = 300


class _Missing:
    def __repr__(self) -> str:
        return "<missing>"


MISSING = _Missing()  # shown as <missing> in messages about absent keys


class ParamError(Exception):
    """A parameter the user gave is not acceptable. ``str()`` is one line for the terminal."""

    def __init__(self, field: str, value: Any, allowed: str, source: str = ""):
        self.field = field
        self.value = value
        self.allowed = allowed
        self.source = source
        super().__init__(self._text())

    def _text(self) -> str:
        where = f"{_one_line(self.source)}: " if self.source else ""
        if self.field:
            return f"{where}{_one_line(self.field)} = {_show(self.value)}: {_one_line(self.allowed)}"
        return f"{where}{_one_line(self.allowed)}"

    def with_source(self, source: str) -> ParamError:
        return ParamError(self.field, self.value, self.allowed, source)


def _one_line(text: str) -> str:
    """Control characters (a newline in a TOML key or file name) shown escaped: one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


def _show(value: Any) -> str:
    if isinstance(value, dict):
        return "{...}"
    try:
        text = repr(value)
    except ValueError:  # an int too long for repr (Python's digit limit)
        text = f"<integer of about {int(value.bit_length() * 0.30103)} digits>"
    limit = MAX_SHOWN_STRING_CHARS if isinstance(value, str) else MAX_SHOWN_CHARS
    return text if len(text) <= limit else text[:limit - 3] + "..."


class Section(BaseModel):
    """Base of every template section: unknown keys, NaN/inf and silent coercion are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)

    #: keys a section once had, under their present names (old → new): a template written before a
    #: rename still loads, with a warning naming the new key; both at once is an error
    renamed: ClassVar[dict[str, str]] = {}

    @model_validator(mode="before")
    @classmethod
    def _renamed_keys(cls, data: Any) -> Any:
        if not cls.renamed or not isinstance(data, dict):
            return data
        data = dict(data)
        for old, new in cls.renamed.items():
            if old in data:
                if new in data:
                    raise ValueError(f"{old} is the old name of {new}: give {new} only")
                import logging

                logging.getLogger("gearcheck").warning("%s is now called %s: the template still loads; "
                                                       "rename it to silence this", old, new)
                data[new] = data.pop(old)
        return data


def field_info(model: type[BaseModel], path: tuple[str, ...]) -> Any:
    """The FieldInfo at ``path``, through sections, optional sections and lists of sections
    (an item by its index); None where the path leads to no field."""
    current: Any = model
    info = None
    for name in path:
        current = _unwrap(current)
        fields = getattr(current, "model_fields", None)
        if fields and name in fields:
            info = fields[name]
            current = info.annotation
        elif name.isdigit() and typing.get_origin(current) is list:
            current = typing.get_args(current)[0]
        else:
            return None
    return info


def field_range(model: type[BaseModel], path: tuple[str, ...]) -> str:
    """Describe the allowed range of the field at ``path`` from its Field(ge=..., le=...) metadata."""
    info = field_info(model, path)
    if info is None:
        return ""
    lo: Any = None
    hi: Any = None
    lo_open = hi_open = False
    for meta in info.metadata:
        if isinstance(meta, at.Ge):
            lo = meta.ge
        elif isinstance(meta, at.Gt):
            lo, lo_open = meta.gt, True
        elif isinstance(meta, at.Le):
            hi = meta.le
        elif isinstance(meta, at.Lt):
            hi, hi_open = meta.lt, True
    unit = (info.json_schema_extra or {}).get("unit", "") if isinstance(info.json_schema_extra, dict) else ""
    unit = f" {unit}" if unit else ""
    if lo is not None and hi is not None:
        return f"allowed {'>' if lo_open else ''}{lo} to {'<' if hi_open else ''}{hi}{unit}"
    if lo is not None:
        return f"allowed {'>' if lo_open else '>='} {lo}{unit}"
    if hi is not None:
        return f"allowed {'<' if hi_open else '<='} {hi}{unit}"
    return ""


def _field_type(model: type[BaseModel], path: tuple[str, ...]) -> str:
    """The declared type at ``path`` (list items by index), e.g. 'list[float]', 'float'; '' if unknown."""
    current = _annotation_at(model, path, unwrap=False)
    if current is None:
        return ""
    if isinstance(current, type):
        return current.__name__
    return str(current).replace("typing.", "")


def _annotation_at(model: type[BaseModel], path: tuple[str, ...], unwrap: bool) -> Any:
    """The annotation at ``path`` (list items by index; with ``unwrap``, ``Annotated`` and
    ``X | None`` looked through at every step); None where the path leads nowhere."""
    current: Any = model
    for name in path:
        if unwrap:
            current = _unwrap(current)
        fields = getattr(current, "model_fields", None)
        if fields and name in fields:
            current = fields[name].annotation
        elif name.isdigit() and typing.get_origin(current) is list:
            current = typing.get_args(current)[0]
        else:
            return None
    return _unwrap(current) if unwrap else current


def _unwrap(annotation: Any) -> Any:
    """The type inside ``Annotated[...]`` and ``X | None``."""
    while True:
        origin = typing.get_origin(annotation)
        if origin is typing.Annotated:
            annotation = typing.get_args(annotation)[0]
        elif origin in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(annotation) if a is not type(None)]
            if len(args) != 1:
                return annotation
            annotation = args[0]
        else:
            return annotation


def _model_at(model: type[BaseModel], path: tuple[str, ...]) -> type[BaseModel] | None:
    """The model (a section, or an item of a list of sections) at ``path``; None where there is none."""
    current = _annotation_at(model, path, unwrap=True)
    return current if isinstance(current, type) and issubclass(current, BaseModel) else None


def _errors(model: type[BaseModel], exc: ValidationError, data: dict) -> ParamError:
    """Every field pydantic refused, one :class:`ParamError` each (:class:`ParamErrors` for several)."""
    from gearcheck.params.problems import ParamErrors

    found = [_one_error(model, err, data) for err in exc.errors(include_url=False)]
    return found[0] if len(found) == 1 else ParamErrors(found)


def _one_error(model: type[BaseModel], err: Any, data: dict) -> ParamError:
    loc = tuple(str(p) for p in err["loc"])
    path = ".".join(loc)
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        parent = _model_at(model, loc[:-1])
        known = ", ".join(sorted(parent.model_fields)) if parent is not None else ""
        return ParamError(path, value, f"unknown key (allowed keys here: {known})" if known
                          else "unknown key (no keys are allowed here)")
    if kind == "missing":
        return ParamError(path, MISSING, "required key is missing")
    return ParamError(path, value, _value_problem(model, loc, kind, value, err["msg"]))


def _value_problem(model: type[BaseModel], loc: tuple[str, ...], kind: str, value: Any, msg: str) -> str:
    """What is wrong with a present value, with the field's allowed range where it has one."""
    allowed = field_range(model, loc)
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 2 ** 1023:
        # a TOML integer beyond any float: pydantic calls it the wrong type
        return f"out of range (larger than any float): {allowed}" if allowed else "out of range (larger than any float)"
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return f"out of range: {allowed}" if allowed else f"out of range: {msg.lower()}"
    if kind == "finite_number":
        return f"must be a finite number ({allowed})" if allowed else "must be a finite number"
    if kind.endswith(("_type", "_parsing")):
        wanted = _field_type(model, loc)
        extra = f"; {allowed}" if allowed else (f"; allowed type: {wanted}" if wanted else "")
        return f"wrong type: {msg.lower()}{extra}"
    if kind == "value_error":  # a validator's own words, without pydantic's prefix
        msg = msg.removeprefix("Value error, ")
    return msg + (f" ({allowed})" if allowed else "")


def validate(model: type[BaseModel], data: dict, source: str = "", folder: Path | None = None) -> BaseModel:
    """Validate ``data`` against ``model``; any failure becomes one :class:`ParamError`. ``folder``
    (the template's, for a file it names; default the working folder) reaches the validators as
    the validation context's ``folder``."""
    _reject_non_finite(data, (), source, model)
    try:
        return model.model_validate(data, context={"folder": folder})
    except ValidationError as exc:
        raise _errors(model, exc, data).with_source(source) from None
    except ParamError as exc:
        raise exc.with_source(source) from None


def parse_override(text: str) -> tuple[tuple[str, ...], Any]:
    """``section.key=value`` → (path, value); the value is read as a TOML value (4, 0.1, true,
    "text"); a bare word that is not valid TOML is taken as a string."""
    if "=" not in text:
        raise ParamError("--set", text, "expected section.key=value")
    key, raw = text.split("=", 1)
    key = key.strip()
    path = tuple(p.strip() for p in key.split("."))
    if not key or any(not p for p in path):
        raise ParamError("--set", text, "expected section.key=value")
    raw = raw.strip()
    if len(path) > MAX_NESTING:
        raise ParamError("--set", key, f"key nested {len(path)} levels deep; allowed at most {MAX_NESTING}")
    problem = _prescan(f"v = {raw}", len(path) - 1)  # tomllib is quadratic on long dotted keys
    if problem is not None:
        raise ParamError("--set", key, f"value: {problem[1]}")
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except ValueError:  # an integer of more digits than int() reads
        raise ParamError("--set", key, "value is an integer with too many digits to read") from None
    except RecursionError:
        raise ParamError("--set", key, f"value nested too deeply; allowed at most {MAX_NESTING} levels") from None
    _check_nesting(value, "--set " + key, len(path))
    return path, value


def _set_path(node: dict, path: tuple[str, ...], value: Any) -> None:
    for name in path[:-1]:
        child = node.get(name)
        if not isinstance(child, dict):
            # Let validation name the unknown section with its allowed keys.
            child = {}
            node[name] = child
        node = child
    node[path[-1]] = value


def apply_overrides(data: dict, overrides: list[str]) -> dict:
    """Return a copy of ``data`` with each ``--set`` override applied (type checks come later)."""
    out = copy.deepcopy(data)
    paths = []
    for text in overrides:
        path, value = parse_override(text)
        _set_path(out, path, value)
        paths.append(path)
    _drop_companions(out, paths)
    return out


def _companions(key: str) -> tuple[str, ...]:
    """The keys whose value went with ``key``'s: a material's expansion coefficient with its name."""
    return ("cte_per_K",) if key == "material" else (f"{key}_cte_per_K",)


def _drop_companions(data: dict, paths: list[tuple[str, ...]]) -> None:
    """A material's name set anew drops the coefficient the template gave with the old name
    (unless that is set too): the new name's comes from the materials table. Without this,
    ``--set materials.housing="grey cast iron"`` would keep aluminium's expansion."""
    given = set(paths)
    for path in paths:
        parent: Any = data
        for part in path[:-1]:
            parent = parent.get(part) if isinstance(parent, dict) else None
        if not isinstance(parent, dict):
            continue
        for companion in _companions(path[-1]):
            if companion in parent and (*path[:-1], companion) not in given:
                del parent[companion]


def apply_values(data: dict, values: dict[str, Any]) -> dict:
    """Return a copy of ``data`` with ``{"section.key": value}`` applied (Python values, as the
    API takes them; a string is taken as it is). Type and range checks come later, as for
    ``--set``."""
    out = copy.deepcopy(data)
    for key, value in values.items():
        path = tuple(p.strip() for p in str(key).split("."))
        if not key or any(not p for p in path):
            raise ParamError("overrides", key, "expected a key 'section.key'")
        if len(path) > MAX_NESTING:
            raise ParamError("overrides", key, f"key nested {len(path)} levels deep; allowed at most {MAX_NESTING}")
        _check_nesting(value, str(key), len(path))
        _set_path(out, path, copy.deepcopy(value))
    _drop_companions(out, [tuple(p.strip() for p in str(k).split(".")) for k in values])
    return out


# The lexical pre-scan (_prescan) reads TOML's structure only: keys, [table] headers, the brackets
# of arrays and inline tables, commas, line ends; strings and comments are skipped whole (a "." or
# "[" in them is not structure). Possessive quantifiers: no backtracking, linear time.
_BASIC = r'"(?:[^"\\\n]|\\.)*+"'
_LITERAL = r"'[^'\n]*+'"
_ML_BASIC = r'"""(?:[^"\\]|\\[\s\S]|"(?!""))*+"""(?:"{0,2})'  # up to 2 quotes after """ are content
_ML_LITERAL = r"'''[\s\S]*?'''(?:'{0,2})"
_STRING = "(?:" + "|".join((_ML_BASIC, _ML_LITERAL, _BASIC, _LITERAL)) + ")"
_COMMENT = r"#[^\n]*+"
_KEY_PART = r"(?:[A-Za-z0-9_-]++|" + _BASIC + "|" + _LITERAL + ")"
_KEY_PART_RE = re.compile(_KEY_PART)
_KEY_RE = re.compile(_KEY_PART + r"(?:[ \t]*+\.[ \t]*+" + _KEY_PART + ")*+")
_HEADER_RE = re.compile(r"\[(\[?)[ \t]*+(" + _KEY_RE.pattern + r")[ \t]*+\]")
_EQUALS_RE = re.compile(r"[ \t]*+=")
_BLANK_RE = re.compile(r"(?:[ \t\r\n]++|" + _COMMENT + ")*+")
# inside a value, everything up to the next bracket (and line end / comma where they end it)
_SKIP_TOP_RE = re.compile(r"(?:[^\[\]{}\"'#\n]++|" + _STRING + "|" + _COMMENT + ")*+")
_SKIP_ARRAY_RE = re.compile(r"(?:[^\[\]{}\"'#]++|" + _STRING + "|" + _COMMENT + ")*+")
_SKIP_INLINE_RE = re.compile(r"(?:[^\[\]{}\"'#,]++|" + _STRING + "|" + _COMMENT + ")*+")
_STRING_OR_COMMENT_RE = re.compile(_STRING + "|" + _COMMENT)  # cut out before counting an array's commas


def _key_parts(key: str) -> int:
    if '"' in key or "'" in key:
        return sum(1 for _ in _KEY_PART_RE.finditer(key))  # a quoted part may hold dots
    return key.count(".") + 1


def _shown_key(key: str) -> str:
    return repr(key if len(key) <= 40 else key[:37] + "...")


def _prescan(text: str, level: int = 0) -> tuple[int, str] | None:
    """Refuse, before tomllib parses it, a text too deep or too large for a template: keys and
    [table] headers of more than MAX_NESTING levels (counting the table a key sits in and the
    arrays / inline tables around it, as _check_nesting counts them), more than
    MAX_TEMPLATE_ENTRIES keys, tables and array items, more than MAX_TEMPLATE_LINES lines. Returns
    (line, problem) (line 0: the whole text) or None. Linear time, a few regex matches per key
    or bracket. ``level``: the level of the text's top table (0 for a file).

    Nesting is counted as the parsed document nests (``[a.b]`` then ``c = [1]``: 1 at level 4),
    so the scan never refuses what _check_nesting accepts; a ``[x.y]`` under an array of tables
    ``[[x]]`` nests one level deeper than counted here, which _check_nesting still catches after
    parsing. Text that is not valid TOML ends the scan: tomllib stops no later than the scan did
    and names the line."""
    lines = text.count("\n") + 1
    if lines > MAX_TEMPLATE_LINES:
        return 0, f"{lines} lines; a template has at most {MAX_TEMPLATE_LINES}"
    scan = _Scan(text, level)
    want_key: bool | None = True
    try:
        while want_key is not None:
            want_key = scan.key() if want_key else scan.value()
    except _Refused as exc:
        return exc.line, exc.problem
    return None


class _Refused(Exception):
    def __init__(self, line: int, problem: str):
        super().__init__(line, problem)
        self.line, self.problem = line, problem


class _Scan:
    """_prescan's reading position and what encloses it. ``key`` and ``value`` each read one
    step and say what comes next: True a key, False more of a value, None nothing (the text
    ends, or is not TOML there); a limit passed raises _Refused."""

    def __init__(self, text: str, level: int):
        self.text = text
        self.pos = 0
        self.top = level  # level of the text's top table
        self.base = level  # level of the current [table]
        self.stack: list[tuple[str, int]] = []  # open arrays "[" and inline tables "{", with their level
        self.value_level: int | None = None  # level of a value that may start here (None: none may)
        self.entries = 0

    def refuse(self, problem: str) -> NoReturn:
        raise _Refused(self.text.count("\n", 0, self.pos) + 1, problem)

    def count_entries(self, count: int = 1) -> None:
        self.entries += count
        if self.entries > MAX_TEMPLATE_ENTRIES:
            self.refuse(f"more than {MAX_TEMPLATE_ENTRIES} keys, tables and array items; "
                        f"a template allows at most {MAX_TEMPLATE_ENTRIES}")

    def key(self) -> bool | None:
        """A key and its '=', or a [table] / [[array.of.tables]] header."""
        text = self.text
        self.pos = _match_end(_BLANK_RE, text, self.pos)
        if self.pos >= len(text):
            return None
        if self.stack and text[self.pos] == "}":  # {} or a trailing comma: closed by value()
            self.value_level = None
            return False
        header = _HEADER_RE.match(text, self.pos) if not self.stack and text[self.pos] == "[" else None
        found = header or _KEY_RE.match(text, self.pos)
        if found is None:
            return None
        name = found.group(2) if header else found.group()
        if header:
            array = bool(header.group(1))
            depth = self.top + _key_parts(name) + array
            what = f"table {'[[' if array else '['}{_shown_key(name)[1:-1]}{']]' if array else ']'}"
        else:
            depth = (self.stack[-1][1] if self.stack else self.base) + _key_parts(name)
            what = f"key {_shown_key(name)}"
        if depth > MAX_NESTING:
            self.refuse(f"{what} nested {depth} levels deep; a template allows at most {MAX_NESTING}")
        self.count_entries()
        if header:
            self.base, self.pos, self.value_level = depth, header.end(), None
            if array and text.startswith("]", self.pos):
                self.pos += 1
            return False
        equals = _EQUALS_RE.match(text, found.end())
        if equals is None:
            return None
        self.pos, self.value_level = equals.end(), depth
        return False

    def value(self) -> bool | None:
        """A value (skipped whole, strings and comments included) up to the next bracket, comma
        of an inline table or line end."""
        stack = self.stack
        skip = _SKIP_TOP_RE if not stack else _SKIP_ARRAY_RE if stack[-1][0] == "[" else _SKIP_INLINE_RE
        start, self.pos = self.pos, _match_end(skip, self.text, self.pos)
        if skip is _SKIP_ARRAY_RE and self.text.count(",", start, self.pos):  # the items of an array
            self.count_entries(_STRING_OR_COMMENT_RE.sub("", self.text[start:self.pos]).count(","))
        if self.pos >= len(self.text):
            return None
        char = self.text[self.pos]
        want_key: bool | None = False
        if char in "\n,":  # a line end outside brackets, or a comma in an inline table: a key
            want_key = True
        elif char in "[{" and self.value_level is not None:
            if self.value_level > MAX_NESTING:
                self.refuse(f"arrays / inline tables nested more than {MAX_NESTING} levels deep; "
                            f"a template allows at most {MAX_NESTING}")
            self.count_entries()
            stack.append((char, self.value_level))
            self.value_level += 1  # an array's items are one level deeper; a table's keys say
            want_key = char == "{"
        elif stack and char == {"[": "]", "{": "}"}[stack[-1][0]]:
            stack.pop()
            self.value_level = stack[-1][1] + 1 if stack and stack[-1][0] == "[" else None
        else:  # a bracket out of place, a string that does not end: not TOML
            want_key = None
        self.pos += 1
        return want_key


def _match_end(pattern: re.Pattern[str], text: str, pos: int) -> int:
    """Where ``pattern`` (one that matches the empty string too) ends when matched at ``pos``."""
    found = pattern.match(text, pos)
    return found.end() if found is not None else pos


# What a path that is not a regular file is, as a rejection names it.
_FILE_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
               (stat.S_ISFIFO, "a named pipe"), (stat.S_ISSOCK, "a socket"))


def _read_template_bytes(path: Path, source: str) -> bytes:
    """The bytes of a template file: a regular file (a device, a pipe or a socket is refused, not
    read: /dev/urandom never ends, a pipe may never be written) of at most MAX_TEMPLATE_BYTES."""
    try:
        # non-blocking: opening a pipe does not wait for a writer (it is refused just below)
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except OSError as exc:
        raise ParamError("", None, f"cannot read: {exc.strerror}", source) from None
    with os.fdopen(fd, "rb") as f:
        mode = os.fstat(f.fileno()).st_mode
        if stat.S_ISDIR(mode):
            raise ParamError("", None, "is a folder, expected a .toml template", source)
        if not stat.S_ISREG(mode):
            kind = next((name for test, name in _FILE_KINDS if test(mode)), "not a regular file")
            raise ParamError("", None, f"not a TOML text file: {kind} (a template is a regular file of UTF-8 "
                             "text)", source)
        size = os.fstat(f.fileno()).st_size
        if size == 0:
            raise ParamError("", None, "empty file, expected a TOML template", source)
        if size > MAX_TEMPLATE_BYTES:
            raise ParamError("", None, f"file is {size} bytes; a template is at most {MAX_TEMPLATE_BYTES}", source)
        try:
            data = f.read(MAX_TEMPLATE_BYTES + 1)
        except OSError as exc:
            raise ParamError("", None, f"cannot read: {exc.strerror}", source) from None
    if len(data) > MAX_TEMPLATE_BYTES:  # grew since its size was read
        raise ParamError("", None, f"file is more than {MAX_TEMPLATE_BYTES} bytes; a template is at most "
                         f"{MAX_TEMPLATE_BYTES}", source)
    return data


def read_toml(path: Path) -> dict:
    """Read a template file; every way it can be unreadable is a ParamError naming the file."""
    source = str(path)
    if not path.exists():
        raise ParamError("", None, "file not found", source)
    if path.is_dir():
        raise ParamError("", None, "is a folder, expected a .toml template", source)
    raw = _read_template_bytes(path, source)
    try:
        # utf-8-sig: a byte-order mark (some Windows editors write one) is not part of the text
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParamError("", None, f"not a TOML text file: binary data, not UTF-8 text (byte {exc.start})",
                         source) from None
    if "\0" in text:
        raise ParamError("", None, f"not a TOML text file: binary data (a NUL character at {text.index(chr(0))})",
                         source)
    problem = _prescan(text)
    if problem is not None:
        line, what = problem
        raise ParamError("", None, f"line {line}: {what}" if line else what, source)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParamError("", None, f"not valid TOML: {exc}", source) from None
    except ValueError:  # int() refuses integers of more than sys.get_int_max_str_digits() digits
        raise ParamError("", None, "not a template: an integer has too many digits to read", source) from None
    except RecursionError:  # tomllib parses nested arrays / inline tables recursively
        raise ParamError("", None, f"not a template: values nested too deeply (allowed at most {MAX_NESTING} levels)",
                         source) from None
    _check_nesting(data, "", 0, source)
    return data


def _check_nesting(node: Any, where: str, depth: int, source: str = "") -> None:
    """Reject documents nested deeper than MAX_NESTING (walked without recursion)."""
    stack = [(node, depth)]
    while stack:
        item, level = stack.pop()
        if level > MAX_NESTING:
            raise ParamError(where, "{...}", f"nested {level} levels deep; a template allows at most {MAX_NESTING}",
                             source)
        if isinstance(item, dict):
            stack.extend((v, level + 1) for v in item.values())
        elif isinstance(item, list):
            stack.extend((v, level + 1) for v in item)


def _reject_non_finite(node: Any, path: tuple[str, ...], source: str, model: type[BaseModel] | None = None) -> None:
    """NaN/inf anywhere in the document (TOML spells them nan, inf) is one error naming the field
    and, when the model knows it, the field's allowed range."""
    if isinstance(node, dict):
        for k, v in node.items():
            _reject_non_finite(v, path + (k,), source, model)
    elif isinstance(node, float) and not math.isfinite(node):
        allowed = field_range(model, path) if model is not None else ""
        raise ParamError(".".join(path), node, f"must be a finite number ({allowed})" if allowed
                         else "must be a finite number", source)


def to_toml(data: dict, comment: str = "") -> str:
    """A template (or a run's resolved parameters) as TOML, written by a TOML library (tomli-w:
    every string escaped as TOML requires, floats exact), with an optional leading comment
    (one line per line of ``comment``, control characters shown escaped)."""
    import tomli_w

    head = "".join(f"# {_one_line(line)}\n" for line in comment.splitlines())
    return head + tomli_w.dumps(data)
