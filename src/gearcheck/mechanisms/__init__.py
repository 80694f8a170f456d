"""The mechanisms gearcheck knows, by the ``mechanism`` key of a template.

Each mechanism is a package exposing ``SECTION`` (its JSON section name), ``Params`` (the pydantic
model of its template) and ``calc(params) -> list[Figure]`` (the paper's analytical model, numpy
only). CAD, poses and checks live in submodules imported only when needed.
"""

from __future__ import annotations

import importlib
import re
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from pydantic import BaseModel

from gearcheck.params import ParamError, apply_overrides, read_toml, validate
from gearcheck.params.common import MISSING

# An optional top-level `name` names the result files; it must be a plain folder name.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}")

MECHANISMS = {
    "differential": "gearcheck.mechanisms.differential",
    "track": "gearcheck.mechanisms.track",
    "steering": "gearcheck.mechanisms.steering",
}


def mechanism_module(name: str) -> ModuleType:
    return importlib.import_module(MECHANISMS[name])


@dataclass(frozen=True)
class Loaded:
    """A validated template: which mechanism, its parameters, and the resolved raw data."""

    path: Path
    mechanism: str
    params: BaseModel
    data: dict  # resolved (overrides applied) TOML data, for the manifest / params.toml

    @property
    def module(self) -> ModuleType:
        return mechanism_module(self.mechanism)

    @property
    def parts_module(self) -> ModuleType:
        """``build_parts(params) -> list[Part]``: imports CadQuery, so only loaded on demand."""
        return importlib.import_module(MECHANISMS[self.mechanism] + ".parts")

    @property
    def check_module(self) -> ModuleType:
        """``run_check(params, bodies, progress) -> CheckResult``: FCL sweeps, no CadQuery."""
        return importlib.import_module(MECHANISMS[self.mechanism] + ".check")

    @property
    def name(self) -> str:
        """Result name: the template's optional top-level ``name``, else the file's stem (so a
        rerun from ``out/NAME/params.toml`` keeps NAME)."""
        return self.data.get("name") or self.path.stem

    @property
    def resolved_data(self) -> dict:
        """The resolved parameters with the result name recorded, as written to params.toml."""
        rest = {k: v for k, v in self.data.items() if k not in ("mechanism", "name")}
        return {"mechanism": self.mechanism, "name": self.name, **rest}


def load_template(path: str | Path, overrides: list[str] | None = None) -> Loaded:
    """Read, override and validate a template. Raises ParamError (one line) on any bad input."""
    path = Path(path)
    source = str(path)
    data = read_toml(path)
    try:
        data = apply_overrides(data, overrides or [])
    except ParamError as exc:
        raise exc.with_source(source) from None
    mech = data.get("mechanism")
    if not isinstance(mech, str) or mech not in MECHANISMS:
        raise ParamError("mechanism", mech if mech is not None else MISSING,
                         f"allowed one of: {', '.join(MECHANISMS)}", source)
    name = data.get("name")
    if name is not None and not (isinstance(name, str) and NAME_PATTERN.fullmatch(name)):
        raise ParamError("name", name, "allowed 1 to 64 characters of A-Z a-z 0-9 _ . - (a folder name)", source)
    body = {k: v for k, v in data.items() if k not in ("mechanism", "name")}
    params = validate(mechanism_module(mech).Params, body, source)
    return Loaded(path=path, mechanism=mech, params=params, data=data)
