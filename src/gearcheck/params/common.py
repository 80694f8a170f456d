"""Template loading, ``--set`` overrides and one-line error messages.

A template is a TOML file whose top-level ``mechanism`` key names the mechanism; every other
table is a section validated by that mechanism's pydantic model. Every bad value ends in a
:class:`ParamError` whose text names the file, the field path, the value and the allowed range,
so the CLI can print one line and exit 2.
"""

from __future__ import annotations

import copy
import math
import tomllib
import typing
from pathlib import Path
from typing import Any

import annotated_types as at
from pydantic import BaseModel, ConfigDict, ValidationError

from gearcheck.geometry.bisect import bisect

# Guard against pathological files before any parsing work.
MAX_TEMPLATE_BYTES = 1_000_000
# Deepest nesting a template may have (a template is sections of keys, a key may hold a flat
# list: 3 levels); deeper documents are rejected before anything walks them recursively.
MAX_NESTING = 8
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


def bisect_boundary(ok, good: float, bad: float, steps: int) -> float | None:
    """Where ``ok`` changes between ``good`` (ok) and ``bad`` (not ok), by ``steps`` bisections,
    on the ok side; None if ``ok(good)`` fails (no boundary in the bracket). The models use it to
    say how far a rejected value may go."""
    if not ok(good):
        return None
    return bisect(lambda x: not ok(x), good, bad, tol=None, max_iter=steps, check_ends=False).free


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


def field_range(model: type[BaseModel], path: tuple[str, ...]) -> str:
    """Describe the allowed range of the field at ``path`` from its Field(ge=..., le=...) metadata."""
    current: Any = model
    info = None
    for name in path:
        fields = getattr(current, "model_fields", None)
        if not fields or name not in fields:
            return ""
        info = fields[name]
        current = info.annotation
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
    current: Any = model
    for name in path:
        fields = getattr(current, "model_fields", None)
        if fields and name in fields:
            current = fields[name].annotation
        elif name.isdigit() and typing.get_origin(current) is list:
            current = typing.get_args(current)[0]
        else:
            return ""
    if isinstance(current, type):
        return current.__name__
    return str(current).replace("typing.", "")


def _first_error(model: type[BaseModel], exc: ValidationError, data: dict) -> ParamError:
    err = exc.errors(include_url=False)[0]
    loc = tuple(str(p) for p in err["loc"])
    path = ".".join(loc)
    kind = err["type"]
    value = err.get("input")
    if kind == "extra_forbidden":
        parent: Any = model
        for name in loc[:-1]:
            parent = parent.model_fields[name].annotation if name in getattr(parent, "model_fields", {}) else None
        known = ", ".join(sorted(parent.model_fields)) if parent is not None and hasattr(parent, "model_fields") else ""
        return ParamError(path, value, f"unknown key (allowed keys here: {known})")
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
        return f"out of range: {allowed}"
    if kind == "finite_number":
        return f"must be a finite number ({allowed})" if allowed else "must be a finite number"
    if kind.endswith(("_type", "_parsing")):
        wanted = _field_type(model, loc)
        extra = f"; {allowed}" if allowed else (f"; allowed type: {wanted}" if wanted else "")
        return f"wrong type: {msg.lower()}{extra}"
    return msg + (f" ({allowed})" if allowed else "")


def validate(model: type[BaseModel], data: dict, source: str = "") -> BaseModel:
    """Validate ``data`` against ``model``; any failure becomes one :class:`ParamError`."""
    _reject_non_finite(data, (), source, model)
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise _first_error(model, exc, data).with_source(source) from None
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
    for text in overrides:
        path, value = parse_override(text)
        _set_path(out, path, value)
    return out


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
    return out


def read_toml(path: Path) -> dict:
    """Read a template file; every way it can be unreadable is a ParamError naming the file."""
    source = str(path)
    if not path.exists():
        raise ParamError("", None, "file not found", source)
    if path.is_dir():
        raise ParamError("", None, "is a folder, expected a .toml template", source)
    size = path.stat().st_size
    if size == 0:
        raise ParamError("", None, "empty file, expected a TOML template", source)
    if size > MAX_TEMPLATE_BYTES:
        raise ParamError("", None, f"file is {size} bytes; a template is at most {MAX_TEMPLATE_BYTES}", source)
    try:
        # utf-8-sig: a byte-order mark (some Windows editors write one) is not part of the text
        text = path.read_bytes().decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParamError("", None, f"not UTF-8 text (byte {exc.start}): is this a TOML template?", source) from None
    except OSError as exc:
        raise ParamError("", None, f"cannot read: {exc.strerror}", source) from None
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


def to_toml(data: dict) -> str:
    """Write a template back as TOML (top-level scalars, then one table per section).

    Templates hold scalars, strings and flat lists only, so this small writer is exact for them;
    floats use repr, which round-trips. Used to record the resolved parameters next to results.
    """

    def value(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        raise TypeError(f"cannot write {type(v).__name__} to a template")

    lines = [f"{k} = {value(v)}" for k, v in data.items() if not isinstance(v, dict)]
    for section, body in data.items():
        if isinstance(body, dict):
            lines.append("")
            lines.append(f"[{section}]")
            lines.extend(f"{k} = {value(v)}" for k, v in body.items())
    return "\n".join(lines) + "\n"
