"""The inputs table of a report: every template field as run, with its unit, what it is, the range
the template model allows, the template's own value and any ``--set`` override that replaced it.

Read from the validated parameters (pydantic model: Field descriptions, ``ge``/``le`` bounds and
``json_schema_extra["unit"]``), the resolved data (what was run) and the template file itself (its
values before the overrides, and the comments on its lines: where a value comes from).
"""

from __future__ import annotations

import logging
import math
import re
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import annotated_types as at

from gearcheck.params.common import parse_override, read_toml

if TYPE_CHECKING:
    from gearcheck.design import Design

log = logging.getLogger("gearcheck")

# Top-level keys of a template that are not sections of the mechanism's parameters, with what they are.
RUN_KEYS = {"mesh_tol_mm": ("mm", "meshing tolerance the run uses (chordal deviation of the STL meshes)")}
_HEADER = re.compile(r"^\s*\[([A-Za-z0-9_.-]+)\]\s*(.*)$")
_ASSIGN = re.compile(r"^\s*([A-Za-z0-9_-]+)\s*=(.*)$")


@dataclass(frozen=True)
class InputRow:
    """One template field as run. Values are shown as the template writes them (TOML-like:
    ``0.75``, ``49``, ``[0.0, 0.05]``, ``"7075-T651"``)."""

    key: str  # "section.key" ("mesh_tol_mm" for a top-level key)
    value: str  # the value the run used
    unit: str
    description: str  # what it is (the Field description)
    allowed: str  # the range the template model allows ("0.05 to 5"), "" where the model sets none
    template_value: str  # the value in the template file ("" where it has none: a default or no file)
    overridden: bool  # replaced by a --set override (or an API override)
    note: str = ""  # the template's comment on the field's line (where the value comes from)
    section_note: str = ""  # the template's comment on the field's [section] line
    default: bool = False  # not in the template: the model's default value was used

    @property
    def section(self) -> str:
        return self.key.split(".", 1)[0] if "." in self.key else ""


def show(value: Any) -> str:
    """A value as a template writes it: shortest float form, lists in brackets, strings quoted,
    ``—`` for a field left out (None)."""
    if value is None:
        text = "—"
    elif isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, float):
        text = repr(value) if math.isfinite(value) else str(value)
        text = text[:-2] if text.endswith(".0") and "e" not in text else text
    elif isinstance(value, (list, tuple)):
        text = "[" + ", ".join(show(v) for v in value) + "]"
    elif isinstance(value, str):
        text = f'"{value}"'
    else:
        text = str(value)
    return text


def _bound(x: Any) -> str:
    return show(float(x)) if isinstance(x, (int, float)) and not isinstance(x, bool) else str(x)


def _limits(info) -> dict[str, Any]:
    """A field's constraints: lo/hi (with lo_open/hi_open) and min_len/max_len, where it has them."""
    out: dict[str, Any] = {}
    for meta in info.metadata:
        if isinstance(meta, (at.Ge, at.Gt)):
            out["lo"], out["lo_open"] = (meta.ge, False) if isinstance(meta, at.Ge) else (meta.gt, True)
        elif isinstance(meta, (at.Le, at.Lt)):
            out["hi"], out["hi_open"] = (meta.le, False) if isinstance(meta, at.Le) else (meta.lt, True)
        elif isinstance(meta, at.MinLen):
            out["min_len"] = meta.min_length
        elif isinstance(meta, at.MaxLen):
            out["max_len"] = meta.max_length
    return out


def allowed_range(info) -> str:
    """The range a field's constraints allow, in words: "0.05 to 5", "> 0 to 500", "0 to < 90",
    "≥ 0", "at most 12 values", "1 to 40 characters"; "" where the field has none (cross-field
    rules are checked too, and named in the error a bad value gets)."""
    m = _limits(info)
    lo = f"{'> ' if m.get('lo_open') else ''}{_bound(m['lo'])}" if "lo" in m else ""
    hi = f"{'< ' if m.get('hi_open') else ''}{_bound(m['hi'])}" if "hi" in m else ""
    if lo and hi:
        return f"{lo} to {hi}"
    if lo or hi:
        return (lo if m.get("lo_open") else f"≥ {lo}") if lo else (hi if m.get("hi_open") else f"≤ {hi}")
    things = "characters" if info.annotation is str else "values"
    n_min, n_max = m.get("min_len"), m.get("max_len")
    if n_min is not None and n_max is not None:
        return f"{n_min} to {n_max} {things}"
    if n_min is None and n_max is None:
        return ""
    return f"at most {n_max} {things}" if n_max is not None else f"at least {n_min} {things}"


def _comment(text: str) -> str:
    """The comment at the end of a TOML line ('' if none): the first # outside a string."""
    quote = ""
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch == "#":
            return text[i + 1:].strip()
    return ""


def template_comments(path: Path) -> tuple[dict[str, str], dict[str, str]]:
    """The comments on a template's lines: ``{"section.key": comment}`` and ``{"section": comment}``."""
    fields: dict[str, str] = {}
    sections: dict[str, str] = {}
    section = ""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return fields, sections
    for line in lines:
        if (m := _HEADER.match(line)) is not None:
            section = m.group(1)
            if note := _comment(m.group(2)):
                sections[section] = note
        elif (m := _ASSIGN.match(line)) is not None and (note := _comment(m.group(2))):
            fields[f"{section}.{m.group(1)}" if section else m.group(1)] = note
    return fields, sections


def template_header(design: Design) -> str:
    """The template's own description: the comment lines at the top of its file (which name the
    paper it follows), joined; '' when the design does not come from a file."""
    if design.path is None:
        return ""
    try:
        lines = design.path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return ""
    head = []
    for line in lines:
        if not line.strip().startswith("#"):
            break
        if line.strip().startswith("#:"):  # an editor directive (#:schema ...), not a description
            continue
        head.append(line.strip().lstrip("#").strip())
    return " ".join(h for h in head if h)


def _template_data(design: Design) -> dict | None:
    """The template file's own values (before overrides), or None when there is no file."""
    if design.path is None:
        return None
    try:
        return read_toml(design.path)
    except Exception as exc:  # the run read it a moment ago; a file changed since is shown as unknown
        log.warning("template %s unreadable for the inputs table: %s", design.path, exc)
        return None


def _lookup(data: dict | None, path: tuple[str, ...]) -> tuple[bool, Any]:
    node: Any = data
    for name in path:
        if not isinstance(node, dict) or name not in node:
            return False, None
        node = node[name]
    return True, node


def _overridden_keys(overrides: Sequence[str]) -> set[str]:
    keys = set()
    for text in overrides:
        try:
            path, _ = parse_override(text)
        except Exception:  # the run validated them; anything else is shown as not overridden
            continue
        keys.add(".".join(path))
    return keys


def input_rows(design: Design, overrides: Sequence[str] = ()) -> list[InputRow]:
    """Every field of the design's template model, in the model's order, as the run used it.

    ``overrides``: the ``--set section.key=value`` strings of the run. A field counts as overridden
    when an override names it, or when its value differs from the template file's (an API
    override); the template value is then the file's."""
    params = design.params
    model = type(params)
    # the values as given (a STEP path as the template writes it, never made absolute: a report
    # leaves the user's folders out); a value the run derived (a material's coefficient from its
    # name) from the resolved data
    data = _Values(design.data, design.resolved_data)
    template = _template_data(design)
    named = _overridden_keys(overrides)
    notes, section_notes = template_comments(design.path) if design.path is not None else ({}, {})
    rows: list[InputRow] = []
    for key, (unit, what) in RUN_KEYS.items():
        present, value = _lookup(design.data, (key,))
        if present:
            in_file, file_value = _lookup(template, (key,))
            rows.append(InputRow(key, show(value), unit, what, "", show(file_value) if in_file else "",
                                 key in named or (in_file and file_value != value), notes.get(key, "")))
    for section, info in model.model_fields.items():
        sub = _section_model(info.annotation)
        if sub is None:  # a field of its own (not a section): shown as one row
            rows.append(_row(model, (section,), info, data, template, named, notes, ""))
            continue
        for name, field_info in sub.model_fields.items():
            rows.append(_row(sub, (name,), field_info, data, template, named, notes,
                             section_notes.get(section, ""), prefix=(section,)))
    return rows


def _section_model(annotation: Any) -> Any:
    """The section model of a field (also of an optional section, ``X | None``), else None."""
    if getattr(annotation, "model_fields", None) is not None:
        return annotation
    for arg in typing.get_args(annotation):
        if getattr(arg, "model_fields", None) is not None:
            return arg
    return None


@dataclass(frozen=True)
class _Values:
    """A design's values as given (``given``: the template with its overrides) and as the run
    resolved them (``resolved``: paths made absolute, derived values filled in)."""

    given: dict
    resolved: dict


def _row(model, own: tuple[str, ...], info, data: _Values, template: dict | None, named: set[str],
         notes: dict[str, str], section_note: str, prefix: tuple[str, ...] = ()) -> InputRow:
    """One field: ``own`` its path in ``model`` (its section's model), ``prefix`` the section. A
    row is overridden when a --set names it or its value differs from the file's; a value the
    run derived (absent from what was given) is shown with a note saying so."""
    path = prefix + own
    key = ".".join(path)
    given, value = _lookup(data.given, path)
    present = given
    if not given:
        present, value = _lookup(data.resolved, path)
    in_file, file_value = _lookup(template, path)
    extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
    allowed = allowed_range(info)
    unit = str(extra.get("unit", ""))
    default = not present
    if default:
        value = None if info.is_required() else info.get_default(call_default_factory=True)
    overridden = key in named or (template is not None and present
                                  and ((in_file and file_value != value) or (given and not in_file)))
    note = notes.get(key, "")
    if present and not given:
        note = ("from the material's name (gearcheck's materials table)" if key.endswith("cte_per_K")
                else "derived by the run")
    return InputRow(key, show(value), unit, info.description or "", allowed,
                    show(file_value) if in_file else "", overridden, note, section_note, default)
