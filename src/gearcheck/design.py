"""A design: one validated template (which mechanism, its parameters, the resolved data), and
what can be done with it from Python — calc, build, check, a CadQuery assembly.

``gearcheck.load(...)`` returns a :class:`Design`. Loading and ``calc`` import neither CadQuery
nor FCL; ``build``/``check``/``assembly_cad`` import them when called.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearcheck import mechanism as registry
from gearcheck.names import name_problem
from gearcheck.params import ParamError, apply_overrides, read_toml, validate
from gearcheck.params.common import MISSING, apply_values

if TYPE_CHECKING:
    from pydantic import BaseModel

    from gearcheck.executor import Executor
    from gearcheck.figures import Figure
    from gearcheck.pipeline import BuildRun, CheckRun

# The meshing tolerances a run may use (mm): --tol, or a template's top-level mesh_tol_mm.
TOL_MIN_MM = 0.0005
TOL_MAX_MM = 0.5
# Top-level keys that are not sections of the mechanism's parameters.
RUN_KEYS = ("mechanism", "name", "mesh_tol_mm")


@dataclass(frozen=True)
class Calc:
    """The analytical model's figures for a design (what ``gearcheck calc`` prints)."""

    section: str
    figures: list[Figure]

    def to_dict(self) -> dict:
        """The object ``gearcheck calc ... --json`` prints."""
        from gearcheck.figures import figures_to_json

        return figures_to_json(self.section, self.figures)

    def __getitem__(self, key: str) -> float:
        for f in self.figures:
            if f.key == key:
                return f.value
        from gearcheck.notebook import missing_key

        raise missing_key(key, self.keys())

    def keys(self) -> list[str]:
        """Every figure's key, in the table's order (``calc[key]`` reads one)."""
        return [f.key for f in self.figures]

    def __contains__(self, key: object) -> bool:
        return any(f.key == key for f in self.figures)

    def figure(self, key: str) -> Figure:
        """The figure itself: label, value, unit, the paper's value where it has one, note."""
        for f in self.figures:
            if f.key == key:
                return f
        from gearcheck.notebook import missing_key

        raise missing_key(key, self.keys())

    def __repr__(self) -> str:
        from gearcheck.notebook import calc_repr

        return calc_repr(self.section, self.figures)

    def _repr_html_(self) -> str:
        from gearcheck.notebook import calc_html

        return calc_html(self.section, self.figures)


@dataclass(frozen=True)
class Design:
    """A validated template: its mechanism, parameters, and the resolved (overridden) data."""

    path: Path | None
    mechanism: str
    params: BaseModel
    data: dict

    def __repr__(self) -> str:
        return f"<Design {self.name} ({self.mechanism}) from {self.source}>"

    @property
    def impl(self) -> registry.Mechanism:
        """The mechanism's implementation (from the registry)."""
        return registry.get(self.mechanism)

    @property
    def source(self) -> str:
        return str(self.path) if self.path is not None else "<data>"

    @property
    def name(self) -> str:
        """Result name: the template's optional top-level ``name``, else the file's stem (so a
        rerun from ``out/NAME/params.toml`` keeps NAME), else the mechanism's name."""
        if self.data.get("name"):
            return str(self.data["name"])
        return _stem(self.path) if self.path is not None else self.mechanism

    @property
    def resolved_data(self) -> dict:
        """The resolved parameters with the result name recorded, as written to params.toml."""
        rest = {k: v for k, v in self.data.items() if k not in RUN_KEYS}
        resolve = getattr(self.params, "resolved", None)  # a template naming files: their absolute paths
        if resolve is not None:
            rest = resolve(rest)
        return {"mechanism": self.mechanism, "name": self.name, **rest}

    def default_tol_mm(self) -> float:
        return self.impl.mesh_tol_mm

    # -- what a user does with a design --------------------------------------------------------
    def calc(self) -> Calc:
        """The analytical model (numpy only)."""
        with registry.calling(self.impl, "analyse"):
            return Calc(self.impl.section, self.impl.analyse(self.params))

    def tca(self) -> Any:
        """Tooth contact analysis (numpy only, no CAD): the curves behind summary.json ``tca`` as
        arrays. The differential: {"aligned", "warm", "cold", ...} → its bevel pair's
        :class:`gearcheck.mechanisms.differential.tca.PairTca` (``.te``: TE of each flank and the
        contact path over two mesh cycles; ``.patterns["drive"|"coast"]``: the contact pattern
        on the developed flank; ``.mounting``). The steering: the towing swing's and the power
        stroke's TE against the pinion angle. The track and the roller chain: the polygon effect
        over an engagement cycle. Raises ValueError for a mechanism without one."""
        if type(self.impl).tca is registry.Mechanism.tca:
            raise ValueError(f"{self.mechanism}: no tooth contact analysis")
        with registry.calling(self.impl, "tca"):
            return self.impl.tca(self.params)

    def build(self, out: str | Path | None = None, *, tol: float | None = None) -> BuildRun:
        """Build the CAD and write what ``gearcheck build`` writes into ``out`` (default out/NAME)."""
        from gearcheck import pipeline

        return pipeline.build(self, Path(out) if out is not None else Path("out") / self.name, tol_mm=tol)

    def check(self, out: str | Path | None = None, *, tol: float | None = None, jobs: int | None = None,
              executor: Executor | None = None, options: Mapping[str, Any] | None = None,
              progress: bool | None = None, budget: float | None = None) -> CheckRun:
        """Build, sweep and report as ``gearcheck check`` does, into ``out`` (default out/NAME).
        ``jobs``: worker processes (default every core; 1 runs in this process). ``progress``: show
        each stage's progress (default: in a Jupyter notebook only, as one table updated in place;
        elsewhere a line per stage and per tenth of its work).
        ``budget``: the most CPU seconds the sweep may be predicted to take (``--budget``)."""
        from gearcheck import pipeline
        from gearcheck.notebook import in_notebook, line_progress, notebook_progress

        inside = in_notebook()
        show = inside if progress is None else progress
        shown = (notebook_progress() if inside else line_progress) if show else pipeline.no_progress
        return pipeline.check(self, Path(out) if out is not None else Path("out") / self.name, tol_mm=tol,
                              jobs=jobs, executor=executor, options=options, progress=shown, budget_cpu_s=budget)

    def assembly_cad(self):
        """A named, coloured ``cadquery.Assembly`` of the parts as built (shows in ocp_vscode)."""
        from gearcheck.cad.export import cad_assembly

        impl = self.impl
        return cad_assembly(impl.parts(impl.assembly(self.params)), self.name)


def _stem(path: Path) -> str:
    """The file name without its last suffix ("my.drive.toml" → "my.drive"; "...toml" → "..")."""
    name = path.name
    return name[: -len(path.suffix)] if path.suffix else name


def _check_run_keys(data: dict, path: Path | None, source: str) -> None:
    """The result name (top-level ``name``, else the file's stem: it names the result files)
    follows the rule for names (:func:`gearcheck.names.name_problem`), and a
    recorded ``mesh_tol_mm`` is a tolerance a run may use."""
    name = data.get("name")
    if name is not None:
        why = name_problem(name)
        if why:
            raise ParamError("name", name, why, source)
    elif path is not None and name_problem(_stem(path)):
        raise ParamError("name", _stem(path), f"{name_problem(_stem(path))}; the file's name names the result "
                         "unless the template sets a top-level name = \"...\"", source)
    tol = data.get("mesh_tol_mm")
    allowed = f"allowed {TOL_MIN_MM:g} to {TOL_MAX_MM:g} mm"
    if tol is None:
        return
    if isinstance(tol, bool) or not isinstance(tol, (int, float)):
        raise ParamError("mesh_tol_mm", tol, f"wrong type: input should be a number; {allowed}", source)
    if isinstance(tol, float) and not math.isfinite(tol):  # (an int of any size compares exactly below)
        raise ParamError("mesh_tol_mm", tol, f"must be a finite number ({allowed})", source)
    if not TOL_MIN_MM <= tol <= TOL_MAX_MM:
        raise ParamError("mesh_tol_mm", tol, f"out of range: {allowed}", source)


def from_data(data: dict, path: Path | None = None) -> Design:
    """Validate template data (the ``mechanism`` key names the mechanism)."""
    source = str(path) if path is not None else "<data>"
    mech = data.get("mechanism")
    known = registry.names()
    if not isinstance(mech, str) or mech not in known:
        raise ParamError("mechanism", mech if mech is not None else MISSING,
                         f"allowed one of: {', '.join(known)}", source)
    _check_run_keys(data, path, source)
    body = {k: v for k, v in data.items() if k not in RUN_KEYS}
    params = validate(registry.get(mech).Params, body, source, path.parent if path is not None else None)
    return Design(path=path, mechanism=mech, params=params, data=data)


def load(template: str | Path | Mapping[str, Any],
         overrides: Mapping[str, Any] | Sequence[str] | None = None) -> Design:
    """Read, override and validate a template: a path to a TOML file, or a dict shaped like one.

    ``overrides``: ``{"shim.thickness_mm": 0.15}`` (Python values) or ``["shim.thickness_mm=0.15"]``
    (``--set`` strings, read as TOML values). Raises :class:`ParamError` (one line naming the
    field, its value and the allowed range) on any bad input."""
    if isinstance(template, Mapping):
        path, source = None, "<data>"
        import copy

        data = copy.deepcopy(dict(template))
    else:
        path = Path(template)
        source = str(path)
        data = read_toml(path)
    try:
        if isinstance(overrides, Mapping):
            data = apply_values(data, dict(overrides))
        elif overrides:
            if isinstance(overrides, str):
                raise ParamError("overrides", overrides, "expected a dict or a list of 'section.key=value'")
            data = apply_overrides(data, list(overrides))
    except ParamError as exc:
        raise exc.with_source(source) from None
    return from_data(data, path)


def load_template(path: str | Path, overrides: list[str] | None = None) -> Design:
    """A template file with ``--set`` overrides (the CLI's form of :func:`load`)."""
    return load(Path(path), overrides or [])


def packaged_templates() -> Path:
    """The folder of the templates shipped in the package."""
    from importlib.resources import files

    return Path(str(files("gearcheck") / "templates"))


def find_templates(folder: Path | None = None) -> tuple[Path, list[Path]]:
    """The templates ``--all`` and ``demo`` run: those in ``folder`` when given, else in
    ./templates when it holds any, else the packaged ones. A given folder without templates is
    bad input: running nothing must never look like a pass."""
    if folder is not None:
        found = sorted(Path(folder).glob("*.toml")) if Path(folder).is_dir() else []
        if not found:
            raise ParamError("--templates", str(folder), "allowed a folder holding *.toml templates (none found there)")
        return Path(folder), found
    local = Path("templates")
    if local.is_dir() and (found := sorted(local.glob("*.toml"))):
        return local, found
    shipped = packaged_templates()
    return shipped, sorted(shipped.glob("*.toml"))
