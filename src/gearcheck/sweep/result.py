"""What a mechanism's check hands to the report: figures, verdicts, per-pose rows, plots.

Plain data (numpy/stdlib only), so the report layer needs neither CadQuery nor FCL.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Verdict:
    """One pass/fail claim, with the figure that decides it."""

    key: str  # JSON key: "no_interference_warm"
    label: str  # what is claimed, for the report
    passed: bool
    detail: str  # the measured figure(s) and the limit, one line


@dataclass(frozen=True)
class Comparison:
    """One row of the paper vs model vs geometry table (None where a column has no value)."""

    label: str
    unit: str
    paper: float | None
    model: float | None
    geometry: float | None
    note: str = ""
    exact: float | None = None  # an independent exact (non-mesh) model, where there is one


@dataclass(frozen=True)
class Series:
    label: str
    x: list[float]
    y: list[float]
    style: str = "line"  # "line" or "points"


@dataclass(frozen=True)
class Plot:
    title: str
    xlabel: str
    ylabel: str
    series: list[Series]
    markers: list[tuple[str, float]] = field(default_factory=list)  # vertical lines: (label, x)
    hlines: list[tuple[str, float]] = field(default_factory=list)  # horizontal lines: (label, y)


@dataclass(frozen=True)
class WorstPose:
    """A pose to confirm with an exact B-rep distance (the report shows both figures).

    Poses are world transforms of each part's own frame; ``scale_*`` the thermal scale of each
    part about its own frame origin (1 when warm). A scale s about another datum d is the scale
    about the origin followed by the shift (1 − s)·d in the part's frame: fold that shift into
    the pose (pose @ translation((1 − s)·d))."""

    label: str
    part_a: str
    part_b: str
    pose_a: list
    pose_b: list
    mesh_distance_mm: float
    scale_a: float = 1.0
    scale_b: float = 1.0
    key: str = ""  # JSON key in summary.json; default: made from the label

    @property
    def json_key(self) -> str:
        if self.key:
            return self.key
        slug = "".join(c if c.isascii() and c.isalnum() else "_" for c in self.label.lower())
        return "_".join(filter(None, slug.split("_")))[:80]


@dataclass(frozen=True)
class Clearance:
    """The smallest non-zero clearance a check decides a verdict on (from its exact model, not
    the mesh), for the mesh-resolution rule (:mod:`gearcheck.sweep.resolution`)."""

    value_mm: float
    label: str  # what it is, with the figure in the check's own units


@dataclass
class CheckResult:
    """Everything one mechanism's check produced."""

    section: str  # "differential" | "track" | "steering"
    summary: dict  # nested, plain numeric leaves (lists of numbers allowed for study tables)
    verdicts: list[Verdict]
    rows: list[dict]  # one per pose, flat, same keys in every row: sweep.csv
    comparisons: list[Comparison] = field(default_factory=list)
    plots: list[Plot] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # findings in words, for the report
    worst_poses: list[WorstPose] = field(default_factory=list)
    # wall-clock figures (s, poses/s): for benchmarks and the terminal, never in summary.json,
    # which must be byte-identical between runs
    timings: dict = field(default_factory=dict)
    # None: the mechanism checks no non-zero clearance (zero-backlash contact)
    smallest_clearance: Clearance | None = None

    @property
    def passed(self) -> bool:
        return all(v.passed for v in self.verdicts)
