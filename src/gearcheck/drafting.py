"""A design from the few numbers that define it: ``gearcheck new MECHANISM`` and :func:`new`.

A mechanism that offers it declares the numbers it takes (:attr:`Mechanism.new_inputs`) and
derives every other value of a complete template from them (:meth:`Mechanism.new`), by the paper's
own design method or the standard, each value written with a comment saying how it was found. This
module holds what every mechanism shares: the inputs' checks, the ``--set`` overrides, the
template's text (a :class:`Draft`) and writing it.

    import gearcheck
    d = gearcheck.new("steering", module=5, teeth=34, out="my_steering.toml")
    d.check(out="out/my_steering").passed
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearcheck.params.common import MISSING, ParamError, parse_override

if TYPE_CHECKING:
    from gearcheck.design import Design

# Column of the comments in a written template (values longer than this push them right).
COMMENT_COLUMN = 31


@dataclass(frozen=True)
class NewInput:
    """One number ``gearcheck new`` takes for a mechanism: the CLI flag ``--NAME`` and the keyword
    of :func:`new`."""

    name: str  # "module", "teeth", "chain", "strands"
    help: str  # what it is, with an example
    required: bool = True


@dataclass
class Entry:
    value: Any
    note: str = ""  # how the value was found (the comment beside it)


@dataclass
class Draft:
    """A template being written: ``mechanism``, ``name``, comment lines on top, and sections of
    keys in the order they are set."""

    mechanism: str
    name: str
    header: list[str] = field(default_factory=list)
    sections: dict[str, dict[str, Entry]] = field(default_factory=dict)
    #: arrays of tables (``[[part]]``), each a list of tables of keys, written after the sections
    tables: dict[str, list[dict[str, Entry]]] = field(default_factory=dict)
    #: lines written last, as comments (examples to fill in)
    footer: list[str] = field(default_factory=list)
    #: False: a template to fill in (``check`` refuses it until it is): written without validation
    complete: bool = True
    #: dotted keys holding a file path: written relative to the template's folder
    paths: tuple[str, ...] = ()

    def set(self, dotted: str, value: Any, note: str = "") -> None:
        """Set ``section.key`` (a new key goes last in its section, a new section last). A float
        is kept to 12 significant digits: 0.91 · 7.85 is written 7.1435, not 7.143500000000001
        (the design is made from the value as written)."""
        section, _, key = dotted.partition(".")
        if not key or "." in key:
            raise ValueError(f"{dotted!r}: expected section.key")
        self.sections.setdefault(section, {})[key] = Entry(_tidy(value), note)

    def get(self, dotted: str, default: Any = None) -> Any:
        section, _, key = dotted.partition(".")
        entry = self.sections.get(section, {}).get(key)
        return default if entry is None else entry.value

    def data(self) -> dict:
        """The template as the loader reads it."""
        out: dict[str, Any] = {"mechanism": self.mechanism, "name": self.name}
        for section, keys in self.sections.items():
            out[section] = {k: e.value for k, e in keys.items()}
        for name, tables in self.tables.items():
            out[name] = [{k: e.value for k, e in table.items()} for table in tables]
        return out

    def relative_to(self, folder: Path) -> None:
        """Write the file paths (:attr:`paths`) relative to ``folder`` (the template's)."""
        import os

        for dotted in self.paths:
            section, _, key = dotted.partition(".")
            entry = self.sections.get(section, {}).get(key)
            if entry is not None and os.path.isabs(str(entry.value)):
                entry.value = os.path.relpath(str(entry.value), folder.resolve())

    def toml(self) -> str:
        """The template's text: the header as comments, then each section with a comment beside
        each value saying how it was found (values written by tomli-w: exact floats, escaped
        strings)."""
        import tomli_w

        def scalar(value: Any) -> str:
            return tomli_w.dumps({"v": value}).strip()[len("v = "):]

        def line(key: str, value: Any, note: str) -> str:
            if isinstance(value, (list, tuple)) and all(not isinstance(v, (dict, list, tuple)) for v in value):
                name = tomli_w.dumps({key: 0}).split(" = ")[0]  # the key as TOML writes it (quoted if it must be)
                text = f"{name} = [{', '.join(scalar(v) for v in value)}]"  # one line: the note stays beside it
            else:
                text = tomli_w.dumps({key: value}).strip()
            if not note:
                return text
            return f"{text.ljust(COMMENT_COLUMN - 1)} # {_one_line(note)}"

        lines = [f"#:schema ./schema/{self.mechanism}.json"]
        lines += [f"# {_one_line(h)}" for h in self.header]
        lines += [line("mechanism", self.mechanism, ""), line("name", self.name, "")]
        for section, keys in self.sections.items():
            lines += ["", f"[{section}]"]
            lines += [line(k, e.value, e.note) for k, e in keys.items()]
        for name, tables in self.tables.items():
            for table in tables:
                lines += ["", f"[[{name}]]"]
                lines += [line(k, e.value, e.note) for k, e in table.items()]
        if self.footer:
            lines.append("")
            lines += [f"# {_one_line(f)}" if f.strip() else "#" for f in self.footer]
        return "\n".join(lines) + "\n"


def _tidy(value: Any) -> Any:
    """A float (also in a list) to 12 significant digits; other values as they are."""
    if isinstance(value, float) and math.isfinite(value):
        return float(f"{value:.12g}")
    if isinstance(value, list):
        return [_tidy(v) for v in value]
    return value


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def teeth_numbers(value: Any, count: int, what: str) -> tuple[int, ...]:
    """``--teeth`` as whole numbers: ``21``, ``"21"``, ``"14/30"`` or ``(14, 30)``; ``count`` of
    them (``what`` names them for the message, e.g. "small/big")."""
    if isinstance(value, str):
        parts = value.replace(" ", "").split("/")
    elif isinstance(value, (list, tuple)):
        parts = list(value)
    else:
        parts = [value]
    try:
        numbers = tuple(int(p) if not isinstance(p, float) or p.is_integer() else math.nan for p in parts)
    except (TypeError, ValueError):
        numbers = ()
    if len(numbers) != count or any(isinstance(n, float) for n in numbers):
        example = "/".join(str(20 + 10 * i) for i in range(count))
        raise ParamError("--teeth", value, f"allowed {count} whole number{'s' if count > 1 else ''} ({what}), "
                                           f"e.g. --teeth {example}")
    return numbers


def positive_number(name: str, value: Any, lo: float, hi: float) -> float:
    """A flag's number within [lo, hi] (one line naming the flag otherwise)."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (lo <= number <= hi):
        raise ParamError(f"--{name}", value, f"allowed a number from {lo:g} to {hi:g}")
    return number


def in_field_range(model: Any, dotted: str, value: float) -> float:
    """``value`` of the template field ``dotted`` (``section.key`` of ``model``, a Params model) if it
    is finite and within the field's own range (its Field ge/gt/le/lt); else :class:`ParamError`
    naming the field, the value and that range. For a ``--set`` value the derivation uses before
    the template is validated."""
    import operator

    import annotated_types as at

    from gearcheck.params.common import field_info, field_range

    path = tuple(dotted.split("."))
    info = field_info(model, path)
    allowed = field_range(model, path) or "allowed a finite number"
    if not math.isfinite(value):
        raise ParamError(dotted, value, f"must be a finite number ({allowed})")
    tests = {at.Ge: ("ge", operator.ge), at.Gt: ("gt", operator.gt), at.Le: ("le", operator.le),
             at.Lt: ("lt", operator.lt)}
    for meta in info.metadata if info is not None else ():
        attr, holds = tests.get(type(meta), ("", None))
        if holds is not None and not holds(value, float(getattr(meta, attr))):
            raise ParamError(dotted, value, f"out of range: {allowed}")
    return value


def _overrides(items: Mapping[str, Any] | Sequence[str] | None) -> dict[str, Any]:
    """``--set`` strings or ``{"section.key": value}`` → {dotted key: value}."""
    if not items:
        return {}
    if isinstance(items, Mapping):
        return {str(k): v for k, v in items.items()}
    if isinstance(items, str):
        raise ParamError("overrides", items, "expected a dict or a list of 'section.key=value'")
    out = {}
    for text in items:
        path, value = parse_override(text)
        if len(path) != 2:
            raise ParamError("--set", text, "expected section.key=value (one section, one key)")
        out[".".join(path)] = value
    return out


def offering() -> list[str]:
    """The mechanisms ``gearcheck new`` can write a design for."""
    from gearcheck.mechanism import get, names

    return [n for n in names() if get(n).new_inputs]


def draft(mechanism: str, overrides: Mapping[str, Any] | Sequence[str] | None = None, **inputs: Any) -> Draft:
    """The template ``mechanism`` derives from ``inputs`` (the numbers of its ``new_inputs``) with
    ``overrides`` applied: each override is an input to the derivation where the mechanism uses it,
    and is written into the template as given. Raises :class:`ParamError` on bad input."""
    from gearcheck.mechanism import get, names

    offered = offering()
    if mechanism not in names() or mechanism not in offered:
        raise ParamError("MECHANISM", mechanism, f"allowed one of: {', '.join(offered)}")
    mech = get(mechanism)
    declared = {i.name: i for i in mech.new_inputs}
    given = {k: v for k, v in inputs.items() if v is not None}
    for name, value in given.items():
        if name not in declared:
            raise ParamError(f"--{name}", value, f"{mechanism} takes "
                             + ", ".join(f"--{i.name}" for i in mech.new_inputs) + " (other values: --set)")
    for i in mech.new_inputs:
        if i.required and i.name not in given:
            raise ParamError(f"--{i.name}", MISSING, f"required for {mechanism}: {i.help}")
    values = _overrides(overrides)
    result = mech.new(given, values)
    for dotted, value in values.items():
        section, _, key = dotted.partition(".")
        entry = result.sections.get(section, {}).get(key)
        if entry is None or entry.value != value:
            result.set(dotted, value, "set with --set")
    return result



def new(mechanism: str, *, out: str | Path | None = None, overrides: Mapping[str, Any] | Sequence[str] | None = None,
        force: bool = False, **inputs: Any) -> Design | None:
    """A complete, validated design from the numbers that define it, e.g.
    ``new("differential", module=3, teeth="14/30")``, ``new("roller_chain", chain="12B", teeth=21)``.

    Every dependent value is derived (see each mechanism's docs); ``overrides`` (``{"section.key":
    value}`` or ``--set`` strings) change any other. With ``out`` the template is written there
    (an existing file only with ``force``) and the Design reads from it. Raises :class:`ParamError`
    (exit 2 on the command line) when the numbers admit no design. A template to fill in (an
    ``assembly``'s: how its parts move is the user's to say) is written unvalidated, and gives None."""
    from gearcheck.design import from_data
    from gearcheck.output import atomic_write_text

    result = draft(mechanism, overrides, **inputs)
    design = from_data(result.data()) if result.complete else None  # every rule, before anything is written
    if out is None:
        return design
    path = Path(out)
    if path.exists() and not force:
        raise ParamError("--out", str(path), "the file exists: choose another name, or --force to replace it")
    if path.suffix != ".toml":
        raise ParamError("--out", str(path), "allowed a file name ending in .toml")
    if not path.parent.is_dir():
        raise ParamError("--out", str(path), "its folder does not exist")
    result.relative_to(path.parent)
    atomic_write_text(path, result.toml())  # an OSError: one OutputError line
    return from_data(result.data(), path) if result.complete else None


def default_name(mechanism: str, inputs: Mapping[str, Any]) -> str:
    """``MECHANISM_NUMBERS.toml`` from the inputs given, e.g. ``differential_m3_z14-30.toml``."""
    parts = [mechanism]
    if inputs.get("step") is not None:
        return f"{mechanism}_{re.sub(r'[^A-Za-z0-9.]+', '-', Path(str(inputs['step'])).stem).strip('-')}.toml"
    for key, tag in (("chain", ""), ("module", "m"), ("teeth", "z"), ("strands", "x")):
        value = inputs.get(key)
        if value is not None:
            parts.append(tag + re.sub(r"[^A-Za-z0-9.]+", "-", str(value)).strip("-"))
    return "_".join(parts) + ".toml"
