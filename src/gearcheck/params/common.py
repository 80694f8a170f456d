"""Template loading, ``--set`` overrides and one-line error messages.

A template is a TOML file whose top-level ``mechanism`` key names the mechanism; every other
table is a section validated by that mechanism's pydantic model. Every bad value ends in a
:class:`ParamError` whose text names the file, the field path, the value and the allowed range,
so the CLI can print one line and exit 2.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

import annotated_types as at
from pydantic import BaseModel, ConfigDict, ValidationError

# Guard against pathological files before any parsing work.
MAX_TEMPLATE_BYTES = 1_000_000


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
        where = f"{self.source}: " if self.source else ""
        if self.field:
            return f"{where}{self.field} = {_show(self.value)}: {self.allowed}"
        return f"{where}{self.allowed}"

    def with_source(self, source: str) -> "ParamError":
        return ParamError(self.field, self.value, self.allowed, source)


def _show(value: Any) -> str:
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, dict):
        return "{...}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


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
    lo = hi = None
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
        return ParamError(path, value, f"unknown key (known keys here: {known})")
    if kind == "missing":
        return ParamError(path, MISSING, "required key is missing")
    allowed = field_range(model, loc)
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        return ParamError(path, value, f"out of range: {allowed}")
    if kind == "finite_number":
        return ParamError(path, value, f"must be a finite number ({allowed})" if allowed else "must be a finite number")
    if kind.endswith("_type") or kind.endswith("_parsing"):
        detail = err["msg"].lower()
        extra = f"; {allowed}" if allowed else ""
        return ParamError(path, value, f"wrong type: {detail}{extra}")
    return ParamError(path, value, err["msg"] + (f" ({allowed})" if allowed else ""))


def validate(model: type[BaseModel], data: dict, source: str = "") -> BaseModel:
    """Validate ``data`` against ``model``; any failure becomes one :class:`ParamError`."""
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
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return path, value


def apply_overrides(data: dict, overrides: list[str]) -> dict:
    """Return a copy of ``data`` with each ``--set`` override applied (type checks come later)."""
    out = _deepcopy(data)
    for text in overrides:
        path, value = parse_override(text)
        node = out
        for name in path[:-1]:
            child = node.get(name)
            if not isinstance(child, dict):
                # Let validation name the unknown section with its allowed keys.
                child = {}
                node[name] = child
            node = child
        node[path[-1]] = value
    return out


def _deepcopy(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: _deepcopy(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_deepcopy(v) for v in data]
    return data


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
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParamError("", None, f"not UTF-8 text (byte {exc.start}): is this a TOML template?", source) from None
    except OSError as exc:
        raise ParamError("", None, f"cannot read: {exc.strerror}", source) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParamError("", None, f"not valid TOML: {exc}", source) from None
    _reject_non_finite(data, (), source)
    return data


def _reject_non_finite(node: Any, path: tuple[str, ...], source: str) -> None:
    if isinstance(node, dict):
        for k, v in node.items():
            _reject_non_finite(v, path + (k,), source)
    elif isinstance(node, float) and not math.isfinite(node):
        raise ParamError(".".join(path), node, "must be a finite number", source)


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
