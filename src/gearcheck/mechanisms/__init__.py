"""The mechanisms gearcheck knows, by the ``mechanism`` key of a template.

Each mechanism is a package exposing ``SECTION`` (its JSON section name), ``Params`` (the pydantic
model of its template) and ``calc(params) -> list[Figure]`` (the paper's analytical model, numpy
only). CAD, poses and checks live in submodules imported only when needed.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

from pydantic import BaseModel

from gearcheck.params import ParamError, apply_overrides, read_toml, validate
from gearcheck.params.common import MISSING

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
        return self.path.stem


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
    body = {k: v for k, v in data.items() if k != "mechanism"}
    params = validate(mechanism_module(mech).Params, body, source)
    return Loaded(path=path, mechanism=mech, params=params, data=data)
