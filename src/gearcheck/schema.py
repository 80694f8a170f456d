"""The JSON Schema of a mechanism's template (draft 2020-12), made from the pydantic model that
validates it, so that a TOML editor (taplo, Even Better TOML) can complete keys, show each
field's meaning, unit and range, and mark a value out of range while it is typed.

The schema says what the model declares field by field (type, range, length, unknown keys
refused) and the top-level keys the loader accepts beside the sections (``mechanism``, ``name``,
``mesh_tol_mm``, :mod:`gearcheck.design`). Rules across fields (an odd tooth count, ISO 606 limits
computed from other inputs, a CAD that can be built) stay with the loader: a file the schema
accepts may still be refused, with one line naming the field, its value and the allowed range.

``gearcheck schema MECHANISM`` prints it; the shipped templates point at a copy of it in
``templates/schema/`` with a ``#:schema`` first line (a test keeps the copies equal to the command).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel

DIALECT = "https://json-schema.org/draft/2020-12/schema"
SCHEMA_FOLDER = "schema"  # beside the templates: templates/schema/MECHANISM.json


def _models(model: type[BaseModel], found: dict[str, type[BaseModel]]) -> dict[str, type[BaseModel]]:
    """Every pydantic model reachable from ``model`` by field annotation, by class name (the
    names pydantic gives the schema's $defs)."""
    import typing

    found.setdefault(model.__name__, model)
    for info in model.model_fields.values():
        stack = [info.annotation]
        while stack:
            tp = stack.pop()
            if isinstance(tp, type) and issubclass(tp, BaseModel):
                if found.setdefault(tp.__name__, tp) is not tp:
                    raise ValueError(f"two template sections are both called {tp.__name__}")
                _models(tp, found)
            else:
                stack.extend(typing.get_args(tp))
    return found


def _not_null(prop: dict) -> dict:
    """A TOML file has no null: an optional field (``float | None = None``) is a key that may be
    left out, so its schema is the non-null branch."""
    options = prop.get("anyOf")
    if not options or {"type": "null"} not in options:  # (a key the loader fills in when left out: no default)
        return {k: v for k, v in prop.items() if not (k == "default" and v is None)}
    rest = [o for o in options if o != {"type": "null"}]
    out = {k: v for k, v in prop.items() if k != "anyOf"}
    if out.get("default", 0) is None:
        del out["default"]
    if len(rest) == 1:
        return {**rest[0], **out}
    return {**out, "anyOf": rest}


def _describe(model: type[BaseModel], name: str, prop: dict) -> dict:
    """The field's description with its unit and allowed range as the loader's errors state them
    (what an editor shows on hover), the unit kept as its own keyword, no generated title."""
    from gearcheck.params.common import field_range

    info = model.model_fields[name]
    extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
    unit = str(extra.get("unit", "") or "")
    text = (info.description or "").strip()
    allowed = field_range(model, (name,))
    if allowed:
        text = f"{text} — {allowed}" if text else allowed
    elif unit:
        text = f"{text} — in {unit}" if text else f"in {unit}"
    if not info.is_required():
        text += " (optional)" if info.default is None else ""
    return _ordered({**_not_null(prop), "description": text} if text else _not_null(prop))


def _ordered(node: dict) -> dict:
    """Keys in reading order (what it is, its type, its limits), pydantic's generated titles
    dropped, docstring line breaks joined."""
    first = [k for k in ("description", "type", "const", "required", "properties") if k in node]
    out = {k: node[k] for k in first}
    out.update((k, v) for k, v in node.items() if k not in first and k != "title")
    if isinstance(out.get("description"), str):
        out["description"] = " ".join(out["description"].split())
    return out


def template_schema(mechanism: str) -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of a template of ``mechanism`` (a registry name)."""
    from gearcheck import mechanism as registry
    from gearcheck.design import TOL_MAX_MM, TOL_MIN_MM
    from gearcheck.names import NAME_RULE, NAME_SCHEMA_PATTERN

    impl = registry.get(mechanism)
    model = impl.Params
    raw = model.model_json_schema(mode="validation")
    models = _models(model, {})
    defs = {}
    for def_name, body in sorted(raw.get("$defs", {}).items()):
        section = models.get(def_name)
        if section is None:
            raise ValueError(f"{mechanism}: schema section {def_name!r} matches no model")
        props = {k: _describe(section, k, v) for k, v in body.get("properties", {}).items()}
        defs[def_name] = _ordered({**body, "properties": props})
    sections = {k: _describe(model, k, v) for k, v in raw.get("properties", {}).items()}
    run_keys = {
        "mechanism": {"const": impl.name, "description": f"which mechanism this template describes: {impl.title}"},
        "name": {"type": "string", "pattern": NAME_SCHEMA_PATTERN,
                 "description": f"result name (default: the file's name without .toml): {NAME_RULE}"},
        "mesh_tol_mm": {"type": "number", "minimum": TOL_MIN_MM, "maximum": TOL_MAX_MM,
                        "description": "chordal tolerance of the meshes, used as given (default: the mechanism's, "
                                       f"refined to resolve the smallest clearance) — allowed {TOL_MIN_MM:g} to "
                                       f"{TOL_MAX_MM:g} mm", "unit": "mm"},
    }
    return {
        "$schema": DIALECT,
        "title": f"gearcheck {impl.name} template",
        "description": f"{impl.title}. Every field's unit and range as the loader checks them; rules across "
                       "fields are checked when the template is loaded (gearcheck calc / check).",
        "type": "object",
        "required": ["mechanism", *raw.get("required", [])],
        "properties": {**run_keys, **sections},
        "additionalProperties": False,
        "$defs": defs,
    }


def schema_text(mechanism: str) -> str:
    """The schema as ``gearcheck schema MECHANISM`` prints it and as it is shipped."""
    return json.dumps(template_schema(mechanism), indent=2, ensure_ascii=False, allow_nan=False) + "\n"


def shipped_schema(mechanism: str) -> Path:
    """Where the package ships the schema of ``mechanism`` (beside its template)."""
    from gearcheck.design import packaged_templates

    return packaged_templates() / SCHEMA_FOLDER / f"{mechanism}.json"


def schema_line(mechanism: str) -> str:
    """The first line of a template in the templates folder: taplo's ``#:schema`` directive."""
    return f"#:schema ./{SCHEMA_FOLDER}/{mechanism}.json"


def write_beside(folder: Path, mechanism: str) -> Path:
    """The mechanism's JSON schema at ``folder/schema/MECHANISM.json``, where a template's
    ``#:schema`` line points (an editor then completes and checks its keys); written when
    missing or different, left alone when it is the same."""
    from gearcheck.output import atomic_write_text, output_error

    target = folder / SCHEMA_FOLDER / f"{mechanism}.json"
    text = schema_text(mechanism)
    try:
        if target.read_text(encoding="utf-8") == text:
            return target
    except (OSError, UnicodeError):
        pass
    try:
        target.parent.mkdir(exist_ok=True)
    except OSError as exc:  # e.g. a file named "schema" there
        raise output_error(exc, target.parent) from None
    atomic_write_text(target, text)
    return target


def schema_of(mechanism_or_template: str) -> str:
    """``gearcheck schema ARG``: the schema text of a mechanism named, or of a template file's
    mechanism; ParamError (one line) for anything else."""
    from gearcheck.mechanism import names
    from gearcheck.params import ParamError
    from gearcheck.params.common import read_toml

    name: Any = mechanism_or_template
    if name not in names() and name.endswith(".toml"):
        name = read_toml(Path(name)).get("mechanism")
    if not isinstance(name, str) or name not in names():
        raise ParamError("MECHANISM", mechanism_or_template,
                         f"allowed one of: {', '.join(names())}, or a template file")
    return schema_text(name)
