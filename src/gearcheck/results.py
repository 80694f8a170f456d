"""Typed results: what a mechanism's check hands to the report and to Python callers.

Plain data (stdlib only): the report layer, the CLI and the Python API read these without
CadQuery or FCL. ``summary`` stays a nested dict of plain numbers because it *is* summary.json;
everything with a meaning of its own (a verdict, a comparison row, a plot, a pose to confirm)
is a dataclass.
"""

from __future__ import annotations

import math

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

Level = Literal["pass", "warn", "fail"]
LEVELS: tuple[Level, ...] = ("pass", "warn", "fail")
#: the kinds of evidence a verdict can rest on, most exact first
EVIDENCE = ("exact B-rep", "exact model", "mesh sweep", "analytical model")
# a verdict's one line keeps at least this much of its key figure (and half the line) before it shortens it
KEY_FIGURE_MIN = 48
# Verdicts about gearcheck's own evidence, not about the design: the mesh sweep agreeing with the
# exact model, the worst poses confirmed on the exact B-rep. Counted apart from the design's.
SELF_CHECKS = frozenset({"mesh_agrees_with_exact", "exact_confirmation"})


@dataclass(frozen=True)
class Verdict:
    """One claim about the design or about the evidence, with the figures that decide it.

    ``name`` is its key in summary.json (``verdicts.NAME``: 1 unless the level is "fail"), unique
    within a check; ``label`` says what is claimed, ``measured`` what was measured against which
    limit, in one line; ``figures`` the deciding numbers, for a program; ``evidence`` which
    evidence decided it, in a few words (one of :data:`EVIDENCE` first: "exact model", "mesh
    sweep", "exact B-rep", then any detail)."""

    name: str
    label: str
    level: Level
    measured: str
    figures: Mapping[str, float] = field(default_factory=dict)
    evidence: str = ""
    # for a verdict that fails or warns: the deciding figure against what is required and by how
    # much it falls short, in words ("least tip–plate distance 0.0500 mm, required ≥ 0.5 mm, short
    # by 0.4500 mm"); the report's banner names it. Empty on a pass. Not in summary.json.
    shortfall: str = ""

    def __post_init__(self) -> None:
        if self.level not in LEVELS:
            raise ValueError(f"verdict {self.name!r}: level {self.level!r} is not one of {LEVELS}")

    @classmethod
    def of(cls, name: str, label: str, passed: bool, measured: str,
           figures: Mapping[str, float] | None = None, evidence: str = "", shortfall: str = "") -> Verdict:
        """A pass/fail verdict (``shortfall`` is kept only when it fails)."""
        return cls(name, label, "pass" if passed else "fail", measured, dict(figures or {}), evidence,
                   "" if passed else shortfall)

    @classmethod
    def graded(cls, name: str, label: str, level: Level, measured: str,
               figures: Mapping[str, float] | None = None, evidence: str = "", shortfall: str = "") -> Verdict:
        """A verdict at any level (pass / warn / fail; ``shortfall`` is kept unless it passes)."""
        return cls(name, label, level, measured, dict(figures or {}), evidence, "" if level == "pass" else shortfall)

    @property
    def passed(self) -> bool:
        """True unless the level is "fail" (a warning does not fail a design)."""
        return self.level != "fail"

    @property
    def key_figure(self) -> str:
        """The deciding figure in a few words: the shortfall where it fails or warns, else the
        first clause of ``measured`` that has a figure in it (the whole sentence stays in
        ``measured``)."""
        text = self.shortfall if self.level != "pass" and self.shortfall else self.measured
        for cut in ("; ", " — "):
            head = _first_clause(text, cut)
            if any(c.isdigit() for c in head):
                text = head
        return text

    def whole_line(self) -> str:
        """``label: key figure [evidence]``, nothing cut (what the terminal shows, wrapped)."""
        kind = next((e for e in EVIDENCE if self.evidence.startswith(e)), "")
        return f"{self.label}: {self.key_figure}" + (f" [{kind}]" if kind else "")

    def line(self, width: int = 120, indent: int = 8) -> str:
        """``label: key figure [evidence]`` in at most ``width − indent`` characters (the terminal's
        one line per verdict): the evidence kind goes first; then the label is shortened while
        the figure keeps at least half the line, then the figure."""
        room = width - indent
        kind = next((e for e in EVIDENCE if self.evidence.startswith(e)), "")
        label, figure = self.label, self.key_figure
        if kind and len(label) + len(figure) + len(kind) + 5 <= room:
            return f"{label}: {figure} [{kind}]"
        if len(label) + len(figure) + 2 <= room:
            return f"{label}: {figure}"
        keep = max(room - len(label) - 2, min(len(figure), max(KEY_FIGURE_MIN, room // 2)))
        figure = figure if len(figure) <= keep else figure[: keep - 1] + "…"
        if len(label) + len(figure) + 2 > room:
            label = label[: room - len(figure) - 3] + "…"
        return f"{label}: {figure}"

    def __repr__(self) -> str:
        from gearcheck.notebook import verdict_repr

        return verdict_repr(self)

    def _repr_html_(self) -> str:
        from gearcheck.notebook import verdict_html

        return verdict_html(self)


def _first_clause(text: str, cut: str) -> str:
    """``text`` up to the first ``cut`` outside brackets (a clause in parentheses stays whole:
    "short by 1.9′ (the model meets it; the geometry does not)")."""
    depth = 0
    for i, c in enumerate(text):
        if c in "([":
            depth += 1
        elif c in ")]":
            depth = max(0, depth - 1)
        elif depth == 0 and text.startswith(cut, i):
            return text[:i]
    return text


@dataclass(frozen=True)
class Comparison:
    """One row of the paper vs model vs geometry table (None where a column has no value).

    The report flags the difference of each computed column from the paper (else from the
    analytical model) by its size; ``note`` says why they differ. ``paper_is``: the paper's figure
    is a value, or a bound the design must meet ("min": the figure must be ≥ it, "max": ≤ it).
    ``digits``: decimals of the computed columns (the paper's figure is shown as printed);
    ``tolerance``: the mesh sweep's differences up to this (in ``unit``: its error bound) are
    agreement; ``compared`` False: the columns hold different quantities side by side (a declared
    value and its limit), not estimates of one figure, so no difference is flagged."""

    label: str
    unit: str
    paper: float | None
    model: float | None
    geometry: float | None
    note: str = ""
    exact: float | None = None  # an independent exact (non-mesh) model, where there is one
    digits: int | None = None
    paper_is: Literal["value", "min", "max"] = "value"
    tolerance: float = 0.0
    compared: bool = True


@dataclass(frozen=True)
class Series:
    label: str
    x: list[float]
    y: list[float]
    style: Literal["line", "points"] = "line"


@dataclass(frozen=True)
class FieldMap:
    """A scalar field a plot draws under its lines: ``values[i][j]`` at the point (``x[i][j]``,
    ``y[i][j]``) of a structured grid, coloured from 0 (darkest) to ``vmax``; beyond ``vmax`` and
    NaN are left blank. The axes keep x and y to one scale (a map)."""

    x: list[list[float]]
    y: list[list[float]]
    values: list[list[float]]
    label: str  # the colour bar's label, with its unit
    vmax: float


@dataclass(frozen=True)
class Plot:
    title: str
    xlabel: str
    ylabel: str
    series: list[Series]
    markers: list[tuple[str, float]] = field(default_factory=list)  # vertical lines: (label, x)
    hlines: list[tuple[str, float]] = field(default_factory=list)  # horizontal lines: (label, y)
    ylim: tuple[float, float] | None = None  # a zoom on the values a verdict decides (None: all data)
    caption: str = ""  # what the plot shows and what to read from it, under the plot
    field: FieldMap | None = None  # a map drawn under the series (x and y to one scale)


@dataclass(frozen=True)
class WorstPose:
    """A pose to confirm with an exact B-rep distance (the report shows both figures).

    Poses are world transforms of each part's own frame; ``scale_*`` the thermal scale of each
    part about its own frame origin (1 when warm). A scale s about another datum d is the scale
    about the origin followed by the shift (1 − s)·d in the part's frame: fold that shift into
    the pose (pose @ translation((1 − s)·d)). A part name may name one feature of a part
    ("link_03.plate")."""

    label: str
    part_a: str
    part_b: str
    pose_a: list
    pose_b: list
    mesh_distance_mm: float
    scale_a: float = 1.0
    scale_b: float = 1.0
    key: str = ""  # JSON key in summary.json; default: made from the label
    # what the sweep's own whole meshes said at the pose, when it measured there (None: the
    # confirmation asks the meshes itself): whether they intersect, and the midpoint of their
    # nearest points (world, mm)
    mesh_overlap: bool | None = None
    mesh_nearest_midpoint: tuple[float, float, float] | None = None

    @property
    def json_key(self) -> str:
        if self.key:
            return self.key
        label = self.label.lower().replace("+", " plus ").replace("−", " minus ")  # "towing +" ≠ "towing −"
        slug = "".join(c if c.isascii() and c.isalnum() else "_" for c in label)
        return "_".join(filter(None, slug.split("_")))[:80]


@dataclass(frozen=True)
class Clearance:
    """The smallest non-zero clearance a check decides a verdict on (from its exact model, not
    the mesh), for the mesh-resolution rule (:mod:`gearcheck.resolution`)."""

    value_mm: float
    label: str  # what it is, with the figure in the check's own units


@dataclass(frozen=True)
class Confirmation:
    """A worst pose re-measured on the exact B-rep."""

    label: str
    key: str  # JSON key under exact_confirmation
    parts: str  # "a / b"
    mesh_mm: float
    brep_mm: float
    bound_mm: float
    # where the meshes overlap at the pose: the exact solids' common volume (mm³); None when free
    overlap_mm3: float | None = None
    # the exact solids' closest points at the pose (world, mm; one common point where they touch)
    point_a: tuple[float, ...] | None = None
    point_b: tuple[float, ...] | None = None
    # where the exact distance is within the bound of zero: "clear", "touching" or "overlapping"
    # (a zero distance alone cannot tell the last two apart: the common volume, else a sampled
    # penetration depth, decides); "" where the distance is beyond the bound
    contact: str = ""
    depth_mm: float = math.nan  # the sampled penetration depth, where the volume could not be had

    @property
    def meshes_overlap(self) -> bool:
        return self.overlap_mm3 is not None

    @property
    def agrees(self) -> bool:
        """Mesh and B-rep tell the same story within the pair's mesh-error bound: at a free pose
        the two distances agree; where the meshes overlap, the exact solids are in contact or
        overlap too (their distance is within the bound)."""
        if self.meshes_overlap:
            return self.brep_mm <= self.bound_mm
        return abs(self.mesh_mm - self.brep_mm) <= self.bound_mm

    def figures(self) -> dict[str, float | str]:
        out: dict[str, float | str] = {"mesh_mm": self.mesh_mm, "brep_mm": self.brep_mm, "bound_mm": self.bound_mm,
                                       "agrees": float(self.agrees)}
        if self.overlap_mm3 is not None:
            out["overlap_mm3"] = self.overlap_mm3
        if self.contact:
            out["contact"] = self.contact
        if math.isfinite(self.depth_mm):
            out["depth_mm"] = self.depth_mm
        return out


@dataclass
class SweepOutcome:
    """What a mechanism's sweep reduced to, before verdicts: the figures (summary.json's
    section, plain numbers), the poses to confirm exactly, wall-clock figures (never in
    summary.json) and anything the mechanism's verdicts and report need (``data``,
    mechanism-specific). The smallest clearance to resolve comes before meshing, from
    :meth:`gearcheck.mechanism.Mechanism.smallest_clearance`."""

    summary: dict
    worst_poses: list[WorstPose] = field(default_factory=list)
    timings: dict = field(default_factory=dict)
    data: Any = None
    # set by the pipeline before the verdicts: False when the meshes' pair bound exceeds 1/10 of
    # the smallest clearance the design asks to decide (Mechanism.smallest_clearance) and no
    # practical mesh resolves it; the verdicts on that clearance then rest on the exact model,
    # confirmed at the worst poses on the exact B-rep, not on the mesh's sign
    mesh_resolves: bool = True


@dataclass
class Report:
    """A mechanism's report content: per-pose rows (sweep.csv), comparison rows, plots, notes."""

    rows: list[dict] = field(default_factory=list)
    comparisons: list[Comparison] = field(default_factory=list)
    plots: list[Plot] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    # patches painted on parts in the 3D view (gearcheck.scene.Overlay: a contact pattern)
    overlays: list[Any] = field(default_factory=list)


@dataclass
class CheckResult:
    """Everything one mechanism's check produced."""

    section: str  # the mechanism's JSON section ("differential", "track", "steering", ...)
    summary: dict  # nested, plain numeric leaves (lists of numbers allowed for study tables)
    verdicts: list[Verdict]
    rows: list[dict]  # one per pose, flat, same keys in every row: sweep.csv
    comparisons: list[Comparison] = field(default_factory=list)
    plots: list[Plot] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # what the check found, in words, for the report
    worst_poses: list[WorstPose] = field(default_factory=list)
    # wall-clock figures (s, poses/s): for benchmarks and the terminal, never in summary.json,
    # which must be byte-identical between runs
    timings: dict = field(default_factory=dict)
    # None: the mechanism checks no non-zero clearance (zero-backlash contact)
    smallest_clearance: Clearance | None = None
    confirmations: list[Confirmation] = field(default_factory=list)
    # the mesh-resolution rule as checked on this run's meshes (gearcheck.resolution.Resolution)
    resolution: Any = None
    # patches painted on parts in the 3D view (gearcheck.scene.Overlay), from the report
    overlays: list[Any] = field(default_factory=list)
    # the sweep's cost predicted before it and measured after (gearcheck.sweep_budget.SweepCost.record;
    # timings: manifest.json, never summary.json); empty where the mechanism predicts none
    sweep_cost: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        names = [v.name for v in self.verdicts]
        if len(set(names)) != len(names):
            raise ValueError(f"verdict names must be unique: {names}")

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts)

    @property
    def level(self) -> Level:
        """The design's level: "fail" if any verdict fails, else "warn" if any warns, else "pass"."""
        levels = {v.level for v in self.verdicts}
        return "fail" if "fail" in levels else ("warn" if "warn" in levels else "pass")

    @property
    def failed(self) -> list[Verdict]:
        return [v for v in self.verdicts if not v.passed]

    @property
    def design_verdicts(self) -> list[Verdict]:
        """The verdicts about the design (every one but gearcheck's self-checks)."""
        return [v for v in self.verdicts if v.name not in SELF_CHECKS]

    @property
    def self_checks(self) -> list[Verdict]:
        """gearcheck's checks of its own evidence (:data:`SELF_CHECKS`)."""
        return [v for v in self.verdicts if v.name in SELF_CHECKS]

    def counts(self) -> dict[str, dict[str, int]]:
        """``{"design": {"pass": n, "warn": n, "fail": n}, "self_checks": {...}}``: how many
        verdicts of each kind are at each level (what the banner, the CLI and summary.json say)."""
        return {kind: {level: sum(v.level == level for v in group) for level in LEVELS}
                for kind, group in (("design", self.design_verdicts), ("self_checks", self.self_checks))}

    def count_text(self) -> str:
        """"design 4 of 5 verdicts pass (1 with a warning); self-checks 2 of 2 pass": the one
        phrase every place that counts verdicts uses."""
        c = self.counts()
        design, checks = c["design"], c["self_checks"]
        n, k = sum(design.values()), sum(checks.values())
        warned = f" ({design['warn']} with a warning)" if design["warn"] else ""
        text = f"design {n - design['fail']} of {n} verdicts pass{warned}"
        if k:
            text += f"; self-checks {k - checks['fail']} of {k} pass" + (
                f" ({checks['warn']} with a warning)" if checks["warn"] else "")
        return text

    def __repr__(self) -> str:
        from gearcheck.notebook import check_repr

        return check_repr(self, self.section)

    def _repr_html_(self) -> str:
        from gearcheck.notebook import check_html

        return check_html(self, self.section)
