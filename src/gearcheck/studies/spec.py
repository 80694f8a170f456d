"""A study file: which template, the distributions over its inputs, the outputs to collect, the
failures to count, how many variants and which seed.

Study files are TOML, like templates, and ship beside them (``gearcheck/studies/``). Each input
names a template field (``section.key``), a distribution centred on the template's value unless a
``mean`` is given, its unit and the reason for its width (an accuracy grade, a drawing tolerance, a
data-sheet spread). Bad input is one line naming the field, its value and the allowed range
(:class:`gearcheck.ParamError`), as for templates.
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import Field, TypeAdapter, ValidationError, model_validator

from gearcheck.params import ParamError, read_toml, validate
from gearcheck.params.common import MISSING, Section, field_range

# A study's size limits: enough for any tolerance study, small enough that a typo cannot ask for
# a week of CPU (the analytical level is vectorised and takes far more: the sampling and level
# functions, which the benchmarks call, take any size). The command line's flags and the API's
# keywords that override them are held to the same limits (:func:`flag_value`).
MAX_SAMPLES = 1_000_000
MAX_EXACT = 100_000
MAX_CHECKS = 20
LEVELS = ("analytical", "exact", "contact", "check")
# the levels whose figures a study's outputs name (``LEVEL.KEY``)
FIGURE_LEVELS = ("analytical", "exact", "contact")

FieldPath = Annotated[str, Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)+$", max_length=120)]
Text = Annotated[str, Field(min_length=1, max_length=400)]
PRINTABLE = "allowed printable text (no control characters: escape sequences, bells, tabs, line breaks)"


def _printable(where: str, text: str | None) -> None:
    """Free text of a study file is shown on the terminal and in report.html as it is: control
    and format characters (an ANSI escape, a bell, a right-to-left override) are refused."""
    if text is not None and any(unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp") for c in text):
        raise ParamError(where, text, PRINTABLE)


class Input(Section):
    """One sampled template field: its value ("value"), or a deviation added to it ("offset":
    centred on 0 unless a mean is given; several offsets may act on one field, e.g. chain wear
    and the pitch tolerance both lengthen the chain's pitch)."""

    field: FieldPath
    name: Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,63}$")] | None = None  # default: the field
    mode: Literal["value", "offset"] = "value"
    # other template fields that take the same value (a shim both built and measured with)
    also: Annotated[list[FieldPath], Field(max_length=8)] = []
    distribution: Literal["normal", "truncnorm", "uniform"]
    unit: Annotated[str, Field(max_length=20)]
    reason: Text
    mean: float | None = None  # default: the template's value
    sd: float | None = None  # ≥ 0, checked with the distribution's shape (the message names the input)
    low: float | None = None
    high: float | None = None
    integer: bool = False  # round each draw to the nearest integer (tooth counts)

    @property
    def key(self) -> str:
        """The input's column: its name, else its field."""
        return self.name or self.field

    @model_validator(mode="after")
    def _shape(self) -> Input:
        d = self.distribution
        where = f"inputs[{self.key}]"
        _printable(f"{where}.unit", self.unit)
        _printable(f"{where}.reason", self.reason)
        if self.sd is not None and self.sd < 0:
            raise ParamError(f"{where}.sd", self.sd, "out of range: allowed ≥ 0 (a standard deviation)")
        if d in ("normal", "truncnorm") and self.sd is None:
            raise ParamError(f"{where}.sd", MISSING, f"required for a {d} distribution: a standard deviation ≥ 0")
        if d == "uniform" and (self.low is None or self.high is None):
            side = "low" if self.low is None else "high"
            raise ParamError(f"{where}.{side}", MISSING, "required for a uniform distribution: low ≤ high")
        if d == "truncnorm" and self.low is None and self.high is None:
            raise ParamError(f"{where}.low/high", MISSING, "a truncated normal needs low, high or both")
        if self.low is not None and self.high is not None and not self.low <= self.high:
            raise ParamError(f"{where}.high", self.high, f"allowed ≥ low = {self.low:g}")
        if d == "uniform" and (self.mean is not None or self.sd is not None):
            raise ParamError(f"{where}.mean/sd", self.mean if self.mean is not None else self.sd,
                             "a uniform distribution takes only low and high")
        return self


class Failure(Section):
    """A failure to count: an output below or above a limit (its probability gets a 95 % interval)."""

    name: Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]{0,63}$")]
    label: Text
    output: Annotated[str, Field(min_length=1, max_length=120)]
    below: float | None = None
    above: float | None = None

    @model_validator(mode="after")
    def _one_side(self) -> Failure:
        where = f"failures[{self.name}]"
        _printable(f"{where}.label", self.label)
        if self.below is None and self.above is None:
            raise ParamError(f"{where}.below/above", MISSING,
                             "required: one limit, below (fails under it) or above (fails over it)")
        if self.below is not None and self.above is not None:
            raise ParamError(f"{where}.above", self.above,
                             f"allowed only one of below or above (below = {self.below:g} is given too)")
        return self

    def failed(self, value: float) -> bool:
        return value < self.below if self.below is not None else value > float(self.above)  # type: ignore[arg-type]


class Paper(Section):
    """A measured figure from the paper, shown beside the study's distribution of that output."""

    output: Annotated[str, Field(min_length=1, max_length=120)]
    value: float
    label: Text

    @model_validator(mode="after")
    def _text(self) -> Paper:
        _printable(f"paper[{self.output}].label", self.label)
        return self


class StudySpec(Section):
    """The whole study file."""

    title: Text
    template: Annotated[str, Field(min_length=1, max_length=200)]
    samples: Annotated[int, Field(ge=2, le=MAX_SAMPLES)]
    seed: Annotated[int, Field(ge=0, le=2**63 - 1)]
    sampler: Literal["sobol", "lhs", "random"] = "sobol"
    # variants evaluated on the exact model (the first N of the sequence), -1: every variant
    exact: Annotated[int, Field(ge=-1, le=MAX_EXACT)] = -1
    # the K worst variants (by rank_by, ascending) re-checked with the full pipeline
    check_worst: Annotated[int, Field(ge=0, le=MAX_CHECKS)] = 0
    rank_by: Annotated[str, Field(min_length=1, max_length=120)]
    inputs: Annotated[list[Input], Field(min_length=1, max_length=64)]
    failures: Annotated[list[Failure], Field(max_length=32)] = []
    paper: Annotated[list[Paper], Field(max_length=32)] = []

    @model_validator(mode="after")
    def _unique(self) -> StudySpec:
        _printable("title", self.title)
        _printable("template", self.template)
        values = [i.field for i in self.inputs if i.mode == "value"]
        for f in values:
            if values.count(f) > 1:
                raise ParamError("inputs.field", f, "a template field takes one value input (offsets may be added)")
        keys = [i.key for i in self.inputs]
        for k in keys:
            if keys.count(k) > 1:
                raise ParamError("inputs.name", k, "input names must be unique (name the offsets)")
        names = [f.name for f in self.failures]
        for n in names:
            if names.count(n) > 1:
                raise ParamError("failures.name", n, "failure names must be unique")
        return self


# The study file's numbers that the command line (and the API's keywords) may override.
FLAGS = {"samples": "--samples", "seed": "--seed", "exact": "--exact", "check_worst": "--check-worst"}
_FLAG_NOTES = {"exact": " (-1: every variant)"}


def flag_value(name: str, value: int | str) -> int:
    """A value given for one of the study file's numbers (``name``: samples, seed, exact or
    check_worst; ``value``: the API's int or the command line's text), checked against the
    limits the study file's own field has: one-line :class:`ParamError` naming the flag."""
    flag = FLAGS[name]
    allowed = f"{field_range(StudySpec, (name,))}{_FLAG_NOTES.get(name, '')}"
    number: object = value
    if isinstance(value, str):
        number = int(value) if re.fullmatch(r"\s*[-+]?[0-9]{1,30}\s*", value) else None
    if not isinstance(number, int) or isinstance(number, bool):
        raise ParamError(flag, value, allowed.replace("allowed ", "allowed a whole number ", 1))
    info = StudySpec.model_fields[name]
    constrained: Any = Annotated[(info.annotation, *info.metadata)]  # the field's type with its bounds
    try:
        TypeAdapter(constrained).validate_python(number)
    except ValidationError:
        raise ParamError(flag, number, allowed) from None
    return number


def with_flags(spec: StudySpec, **values: int | str | None) -> StudySpec:
    """The study with the given overrides (None: the study file's value), each checked by
    :func:`flag_value`."""
    update = {k: flag_value(k, v) for k, v in values.items() if v is not None}
    return spec.model_copy(update=update)


_HOST = r"(?:\[[0-9A-Fa-f:.]{2,45}\]|[A-Za-z0-9](?:[A-Za-z0-9.-]{0,251}[A-Za-z0-9])?)"
SCHEDULERS = "allowed local-cluster, or tcp://HOST:PORT or tls://HOST:PORT of a running Dask scheduler"


def check_scheduler(address: str | None) -> str | None:
    """``--scheduler``: None (local processes), ``local-cluster`` or the address of a Dask
    scheduler (tcp:// or tls://, a host and a port 1 to 65535); anything else is one line."""
    if address is None or address == "local-cluster":
        return address
    m = re.fullmatch(rf"(?:tcp|tls)://{_HOST}:([0-9]{{1,5}})", address)
    if m is None or not 1 <= int(m.group(1)) <= 65535:
        raise ParamError("--scheduler", address, SCHEDULERS)
    return address


def check_fields(spec: StudySpec, model: Any, study_file: str = "") -> None:
    """Every input's ``field`` names a number of the template's mechanism (``model``: its
    parameters' pydantic model), checked before any variant is drawn: an unknown key is one line
    naming the input, the key and the keys allowed where it stops."""
    from gearcheck.params.common import field_info

    for i, inp in enumerate(spec.inputs):
        path = tuple(inp.field.split("."))
        if field_info(model, path) is not None:
            continue
        known = path[:-1]
        while known and field_info(model, known) is None:
            known = known[:-1]
        section = field_info(model, known).annotation if known else model
        keys = sorted(getattr(_unwrap_model(section), "model_fields", {}))
        where = ".".join(known) or "the template"
        raise ParamError(f"inputs[{i}].field", inp.field,
                         f"unknown key: allowed keys in {where}: {', '.join(keys) or 'none'}", study_file)


def _unwrap_model(annotation: Any) -> Any:
    """The section model inside ``X | None``."""
    import types
    import typing

    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        return args[0] if len(args) == 1 else annotation
    return annotation


def check_outputs(spec: StudySpec, figures: set[str], study_file: str = "") -> None:
    """``rank_by``, each failure's and each paper figure's output must be one of ``figures``
    (the mechanism's study figures, ``LEVEL.KEY``); a study that ranks or counts by a figure
    of the exact model must evaluate it (``exact`` not 0)."""
    allowed = f"allowed one of the study's figures: {', '.join(sorted(figures))}"
    named = [("rank_by", spec.rank_by), *((f"failures[{f.name}].output", f.output) for f in spec.failures),
             *((f"paper.{i}.output", p.output) for i, p in enumerate(spec.paper))]
    for where, name in named:
        if name not in figures:
            raise ParamError(where, name, allowed, study_file)
    if spec.exact == 0 and spec.check_worst > 0 and spec.rank_by.startswith("exact."):
        raise ParamError("check_worst", spec.check_worst, f"allowed 0 when exact = 0 (--exact 0): the worst "
                         f"variants are ranked by {spec.rank_by}, a figure of the exact model", study_file)


def load_spec(path: str | Path) -> StudySpec:
    """Read and validate a study file (one-line :class:`ParamError` on bad input)."""
    path = Path(path)
    data = read_toml(path)
    return validate(StudySpec, data, str(path))  # type: ignore[return-value]


def template_path(spec: StudySpec, study_file: Path | None) -> Path:
    """The study's template: beside the study file, else among the shipped templates."""
    from gearcheck.design import packaged_templates

    candidates = []
    if study_file is not None:
        candidates.append(Path(study_file).parent / spec.template)
    candidates += [Path("templates") / spec.template, packaged_templates() / spec.template]
    for c in candidates:
        if c.is_file():
            return c
    raise ParamError("template", spec.template, "no such template beside the study file, in ./templates or shipped "
                     "with gearcheck (see `gearcheck templates`)", str(study_file or "<study>"))


def packaged_studies() -> Path:
    """The folder of the study files shipped in the package (beside the templates)."""
    from gearcheck.design import packaged_templates

    return packaged_templates() / "studies"


def find_study(name: str | Path) -> Path:
    """A study file path, or the name (with or without .toml) of a shipped study."""
    path = Path(name)
    if path.is_file():
        return path
    stem = path.name.removesuffix(".toml")
    shipped = packaged_studies() / f"{stem}.toml"
    if path.parent == Path(".") and shipped.is_file():
        return shipped
    known = ", ".join(sorted(p.stem for p in packaged_studies().glob("*.toml")))
    raise ParamError("study", str(name), f"no such file; shipped studies: {known}")
