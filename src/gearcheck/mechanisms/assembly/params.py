"""Template model of an assembly brought as a STEP file: which products are the parts, how they
move (joints, couples, the driving motion), what is measured (play) and required (clearances,
contact), and optional temperature states.

A template reads::

    mechanism = "assembly"
    [assembly]
    step = "pair.step"                # relative to the template's folder
    [[part]]
    name = "pinion"                   # a product of the file (gearcheck new assembly --step lists them)
    material = "steel"                # or cte_per_K = 11.5e-6
    [[joint]]
    part = "pinion"
    kind = "revolute"                 # or "prismatic"
    axis = [0, 0, 1]
    point = [0, 0, 0]                 # a point of a revolute axis (mm)
    [[couple]]
    driver = "pinion"                 # the parts whose joints are coupled
    driven = "gear"
    ratio = -0.5                      # revolute → revolute: driven angle per driver angle
    [motion]
    part = "pinion"                   # the driving joint
    start_deg = 0.0
    end_deg = 36.0
    step_deg = 0.25
    [play]
    part = "gear"                     # turned both ways to contact at every pose
    [[require]]
    parts = ["pinion", "gear"]
    min_clearance_mm = 0.0            # or contact = true, or ignore = true

Every rule is checked here (numpy only, the file is not read): the file exists and is a STEP
file; names are unique and known; axes are not zero; couples join known joints of the right
kinds without a cycle; the motion has an extent. What needs the file's contents (a product name it
does not have, a file without solids) is refused when the parts are built, with the same one line.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from gearcheck.geometry import materials
from gearcheck.names import PART_RULE, PART_SCHEMA_PATTERN, name_problem
from gearcheck.params import Problems, Section
from gearcheck.params.common import fmt_bound

MAX_PARTS = 200
MAX_POSES = 100_000
AXIS_MAX = 1e6  # largest component of a joint's axis (any length but zero: it is normalised)
# a STEP file opens with this (ISO 10303-21); anything else is not a STEP file
STEP_MAGIC = b"ISO-10303-21"

Vector = list[float]  # three components (TOML arrays are lists)


def _f(lo=None, hi=None, *, gt=None, lt=None, unit="", description="", default: Any = None):
    return Field(default, ge=lo, le=hi, gt=gt, lt=lt, description=description, json_schema_extra={"unit": unit})


def _vector(description: str, default: Any = ...) -> Any:
    return Field(default, min_length=3, max_length=3, description=description)


def _resolve(value: str, info: ValidationInfo) -> str:
    """A STEP path relative to the template's folder (the validation context's ``folder``; the
    working folder for a template given as data), absolute."""
    folder = Path((info.context or {}).get("folder") or os.getcwd())
    path = Path(value).expanduser()
    return str(path if path.is_absolute() else (folder / path).resolve())


def step_problem(path: str) -> str | None:
    """Why ``path`` cannot be a STEP file (missing, a folder, unreadable, not ISO 10303-21), or None."""
    p = Path(path)
    if not p.exists():
        return "no such file"
    if not p.is_file():
        return "not a file"
    try:
        with p.open("rb") as f:
            head = f.read(4096)
    except OSError as exc:
        return f"cannot read it: {exc.strerror or exc}"
    if STEP_MAGIC not in head.lstrip()[:64]:
        return "not a STEP file (no ISO-10303-21 header)"
    return None


class AssemblySection(Section):
    step: str = Field(min_length=1, max_length=4096,
                      description="The STEP file (AP203/AP214/AP242, any length unit), relative to the template")
    contact_tolerance_mm: float = _f(gt=0, hi=1, unit="mm", default=0.01,
                                     description="Parts closer than this are in contact; an overlap shallower than "
                                                 "this, along the parts' motion, is contact, not interference")

    @field_validator("step")
    @classmethod
    def _absolute(cls, value: str, info: ValidationInfo) -> str:
        return _resolve(value, info)


class PartEntry(Section):
    name: str = Field(min_length=1, max_length=400,
                      description="The part's name in gearcheck, which names its files: " + PART_RULE[len("allowed "):]
                                  + "; the product of the file by default",
                      json_schema_extra={"pattern": PART_SCHEMA_PATTERN})
    product: str | None = Field(None, min_length=1, max_length=4096,
                                description="The product (or instance) name in the STEP file, if not `name`")
    step: str | None = Field(None, min_length=1, max_length=4096,
                             description="Another STEP file for this part (default: assembly.step)")
    material: str = Field("steel", min_length=1, max_length=120,
                          description="Material: " + ", ".join(materials.NAMES) + " (or give cte_per_K)")
    cte_per_K: float | None = _f(-50e-6, 500e-6, unit="1/K",
                                 description="Mean linear expansion coefficient, if not the material's")
    datum: Vector | None = _vector("Point (mm, the file's frame) the part grows about when heated (default: the "
                                   "point of its joint, else its bounding-box centre)", None)

    @field_validator("step")
    @classmethod
    def _absolute(cls, value: str | None, info: ValidationInfo) -> str | None:
        return None if value is None else _resolve(value, info)

    @field_validator("name")
    @classmethod
    def _file_name(cls, value: str) -> str:
        why = name_problem(value, dots=False)
        if why:
            raise ValueError(why + " (a product's own name goes in product = \"...\")")
        return value

    @property
    def product_name(self) -> str:
        return self.product or self.name


class Joint(Section):
    part: str = Field(min_length=1, max_length=200, description="The part this joint moves")
    kind: Literal["revolute", "prismatic"] = Field(description="revolute (turns about an axis) or prismatic "
                                                               "(slides along one)")
    axis: Vector = _vector("Direction of the axis (the file's frame; any length but zero)")
    point: Vector = _vector("A point on a revolute axis (mm, the file's frame)", [0.0, 0.0, 0.0])

    @field_validator("axis")
    @classmethod
    def _direction(cls, value: Vector) -> Vector:
        """The axis as a unit vector (a direction: its length does not count); components beyond
        ±1e6 are refused, so no length computed from them can overflow."""
        if any(not abs(c) <= AXIS_MAX for c in value):
            raise ValueError(f"allowed components from {-AXIS_MAX:g} to {AXIS_MAX:g} (a direction: only its "
                             "direction counts, e.g. [0, 0, 1])")
        length = math.hypot(*value)
        return [c / length for c in value] if length > 1e-12 else list(value)

    @property
    def unit(self) -> str:
        return "deg" if self.kind == "revolute" else "mm"


class Couple(Section):
    driver: str = Field(min_length=1, max_length=200, description="The part whose joint drives")
    driven: str = Field(min_length=1, max_length=200, description="The part whose joint follows")
    ratio: float | None = _f(-1e4, 1e4, description="revolute → revolute: driven angle per driver angle "
                                                     "(−z1/z2 for an external pair)")
    mm_per_rad: float | None = _f(-1e5, 1e5, unit="mm/rad",
                                  description="revolute → prismatic: driven travel per driver radian (a rack: "
                                              "± the pinion's pitch radius)")
    rad_per_mm: float | None = _f(-1e3, 1e3, unit="rad/mm",
                                  description="prismatic → revolute: driven angle per driver mm (a rack driving "
                                              "a pinion: ± 1 / pitch radius)")
    phase_deg: float = _f(-360, 360, unit="deg", default=0.0,
                          description="driven angle when the driver is at 0 (revolute driven)")
    phase_mm: float = _f(-1e5, 1e5, unit="mm", default=0.0,
                         description="driven travel when the driver is at 0 (prismatic driven)")


class Motion(Section):
    part: str = Field(min_length=1, max_length=200, description="The part whose joint drives the motion")
    start_deg: float | None = _f(-36_000, 36_000, unit="deg", description="First angle (revolute driver)")
    end_deg: float | None = _f(-36_000, 36_000, unit="deg", description="Last angle (revolute driver)")
    step_deg: float | None = _f(gt=0, hi=360, unit="deg", description="Step between poses (revolute driver)")
    stops_deg: list[float] | None = Field(None, min_length=1, max_length=MAX_POSES,
                                          description="The poses as a list of angles, instead of start/end/step")
    start_mm: float | None = _f(-1e6, 1e6, unit="mm", description="First position (prismatic driver)")
    end_mm: float | None = _f(-1e6, 1e6, unit="mm", description="Last position (prismatic driver)")
    step_mm: float | None = _f(gt=0, hi=1e5, unit="mm", description="Step between poses (prismatic driver)")
    stops_mm: list[float] | None = Field(None, min_length=1, max_length=MAX_POSES,
                                         description="The poses as a list of positions, instead of start/end/step")

    def coordinates(self, unit: str) -> list[float]:
        """The driving joint's coordinate at every pose, in ``unit`` (deg or mm)."""
        stops = getattr(self, f"stops_{unit}")
        if stops is not None:
            return [float(s) for s in stops]
        start, end, step = (getattr(self, f"{k}_{unit}") for k in ("start", "end", "step"))
        n = int(math.floor(abs(end - start) / step + 1e-9))
        sign = 1.0 if end >= start else -1.0
        out = [start + sign * i * step for i in range(n + 1)]
        if abs(out[-1] - end) > 1e-9 * max(1.0, abs(end)):
            out.append(end)
        return out


class Play(Section):
    part: str = Field(min_length=1, max_length=200,
                      description="The part turned (or slid) both ways to contact at every pose, the others held")
    limit_deg: float = _f(gt=0, hi=90, unit="deg", default=5.0,
                          description="Farthest turn searched for contact (revolute)")
    limit_mm: float = _f(gt=0, hi=1000, unit="mm", default=2.0,
                         description="Farthest slide searched for contact (prismatic)")
    min_deg: float | None = _f(-90, 90, unit="deg", description="Requirement: least play over the motion (revolute)")
    min_mm: float | None = _f(-1000, 1000, unit="mm", description="Requirement: least play over the motion "
                                                                  "(prismatic)")


class Require(Section):
    parts: list[str] = Field(min_length=2, max_length=2, description="The two parts")
    min_clearance_mm: float | None = _f(-1000, 1000, unit="mm",
                                        description="Least clearance over the motion (0: no interference)")
    contact: bool = Field(False, description="Contact allowed: touching (within assembly.contact_tolerance_mm "
                                             "along the motion) passes, a deeper overlap fails")
    ignore: bool = Field(False, description="Not checked (parts fastened together, a bearing seat)")


class State(Section):
    name: str = Field(min_length=1, max_length=40, pattern=r"^[A-Za-z0-9_]+$",
                      description="The state's name (letters, digits, _)")
    temperature_C: float = Field(ge=-273.15, le=2000, description="Every part's temperature",
                                 json_schema_extra={"unit": "°C"})
    reference_C: float = _f(-273.15, 2000, unit="°C", default=20.0, description="Temperature the file's geometry is at")


class Params(Section):
    assembly: AssemblySection
    part: list[PartEntry] = Field(min_length=1, max_length=MAX_PARTS)
    joint: list[Joint] = Field(default_factory=list, max_length=MAX_PARTS)
    couple: list[Couple] = Field(default_factory=list, max_length=MAX_PARTS)
    motion: Motion
    play: Play | None = None
    require: list[Require] = Field(default_factory=list, max_length=MAX_PARTS * MAX_PARTS)
    state: list[State] = Field(default_factory=list, max_length=8)

    def resolved(self, data: dict[str, Any]) -> dict[str, Any]:
        """``data`` (the template's sections) with its file paths absolute, as validated: what a
        run's params.toml records, so it reads from anywhere."""
        import copy

        out = copy.deepcopy(data)
        out["assembly"]["step"] = self.assembly.step
        for entry, part in zip(out.get("part", []), self.part, strict=True):
            if part.step is not None:
                entry["step"] = part.step
        return out

    def joint_of(self, part: str) -> Joint | None:
        return next((j for j in self.joint if j.part == part), None)

    @model_validator(mode="after")
    def _cross_checks(self) -> Params:
        with Problems() as problems:
            self._check_files(problems)
            self._check_parts(problems)
            joined = self._check_joints(problems)
            self._check_couples(problems, joined)
            self._check_motion(problems, joined)
            self._check_play(problems, joined)
            self._check_requires(problems)
            states = [s.name for s in self.state]
            for i, s in enumerate(self.state):
                if states.index(s.name) != i or s.name == "as_built":
                    problems.add(f"state[{i}].name", s.name, "unique, and not as_built (the file's own state)")
        return self

    def _check_parts(self, problems: Problems) -> None:
        names = [p.name for p in self.part]
        for i, p in enumerate(self.part):
            if names.index(p.name) != i:
                problems.add(f"part[{i}].name", p.name, "each part once (names must be unique)")
            if p.cte_per_K is None and materials.cte_per_K(p.material) is None:
                problems.add(f"part[{i}].material", p.material,
                             f"allowed one of {', '.join(materials.NAMES)}, or give part[{i}].cte_per_K")

    def _check_joints(self, problems: Problems) -> set[str]:
        """The joints' rules; the parts that have one."""
        known = {p.name for p in self.part}
        joined: set[str] = set()
        for i, j in enumerate(self.joint):
            if j.part not in known:
                problems.add(f"joint[{i}].part", j.part,
                             f"allowed one of the parts: {', '.join(p.name for p in self.part)}")
            if j.part in joined:
                problems.add(f"joint[{i}].part", j.part, "one joint per part")
            joined.add(j.part)
            if not math.hypot(*j.axis) > 1e-12:
                problems.add(f"joint[{i}].axis", list(j.axis), "a direction: not all zero")
        return joined

    def _check_requires(self, problems: Problems) -> None:
        known = {p.name for p in self.part}
        for i, r in enumerate(self.require):
            if any(name not in known for name in r.parts):
                problems.add(f"require[{i}].parts", list(r.parts),
                             f"allowed the parts: {', '.join(p.name for p in self.part)}")
            if r.parts[0] == r.parts[1]:
                problems.add(f"require[{i}].parts", list(r.parts), "two different parts")
            if (r.min_clearance_mm is not None) + r.contact + r.ignore != 1:
                problems.add(f"require[{i}]", list(r.parts),
                             "give exactly one of min_clearance_mm, contact = true, ignore = true")
        seen = [tuple(sorted(r.parts)) for r in self.require]
        for i, pair in enumerate(seen):
            if seen.index(pair) != i:
                problems.add(f"require[{i}].parts", list(pair), "each pair once")

    def _check_files(self, problems: Problems) -> None:
        files = [("assembly.step", self.assembly.step)]
        files += [(f"part[{i}].step", p.step) for i, p in enumerate(self.part) if p.step is not None]
        for field, path in files:
            why = step_problem(path)
            if why:
                problems.add(field, path, why)

    def _check_couples(self, problems: Problems, joined: set[str]) -> None:
        kinds = {j.part: j.kind for j in self.joint}
        parents: dict[str, str] = {}
        for i, c in enumerate(self.couple):
            where = f"couple[{i}]"
            for key in ("driver", "driven"):
                name = getattr(c, key)
                if name not in joined:
                    problems.add(f"{where}.{key}", name,
                                 f"allowed a part with a joint: {', '.join(sorted(joined)) or 'none declared'}")
            if c.driver not in joined or c.driven not in joined:
                continue
            if c.driver == c.driven:
                problems.add(f"{where}.driven", c.driven, "another part than the driver")
                continue
            pair = (kinds[c.driver], kinds[c.driven])
            wanted = {("revolute", "revolute"): "ratio", ("revolute", "prismatic"): "mm_per_rad",
                      ("prismatic", "revolute"): "rad_per_mm"}.get(pair)
            given = [k for k in ("ratio", "mm_per_rad", "rad_per_mm") if getattr(c, k) is not None]
            if wanted is None:
                problems.add(f"{where}.driven", c.driven, "prismatic → prismatic couples are not supported")
            elif given != [wanted]:
                problems.add(f"{where}.{wanted}", getattr(c, wanted),
                             f"a {pair[0]} driver and a {pair[1]} driven joint take {wanted} (only)")
            elif getattr(c, wanted) == 0.0:
                problems.add(f"{where}.{wanted}", 0.0, "allowed a non-zero ratio")
            if c.driven in parents:
                problems.add(f"{where}.driven", c.driven, f"already driven by {parents[c.driven]} (one driver each)")
            parents[c.driven] = c.driver
        # no cycle: following drivers from any part ends
        for start in parents:
            seen, node = {start}, start
            while node in parents:
                node = parents[node]
                if node in seen:
                    problems.add("couple", start, "couples form a loop: one driving motion, coupled outwards")
                    return
                seen.add(node)

    def _check_motion(self, problems: Problems, joined: set[str]) -> None:
        m = self.motion
        j = self.joint_of(m.part)
        if j is None:
            problems.add("motion.part", m.part, f"allowed a part with a joint: {', '.join(sorted(joined)) or 'none'}")
            return
        if any(c.driven == m.part for c in self.couple):
            problems.add("motion.part", m.part, "the driving joint is not itself driven by a couple")
        unit, other = j.unit, ("mm" if j.unit == "deg" else "deg")
        wrong = [f"{k}_{other}" for k in ("start", "end", "step", "stops") if getattr(m, f"{k}_{other}") is not None]
        if wrong:
            problems.add(f"motion.{wrong[0]}", getattr(m, wrong[0]),
                         f"a {j.kind} joint moves in {unit}: give start_{unit}, end_{unit}, step_{unit} "
                         f"or stops_{unit}")
            return
        stops = getattr(m, f"stops_{unit}")
        triple = [getattr(m, f"{k}_{unit}") for k in ("start", "end", "step")]
        if stops is not None and any(v is not None for v in triple):
            problems.add(f"motion.stops_{unit}", stops, f"either stops_{unit} or start/end/step, not both")
        elif stops is None and any(v is None for v in triple):
            missing = [f"{k}_{unit}" for k, v in zip(("start", "end", "step"), triple, strict=True) if v is None]
            problems.add(f"motion.{missing[0]}", None, f"required for a {j.kind} driving joint (or give stops_{unit})")
        elif stops is None:
            start, end, step = triple
            if start == end:
                problems.add(f"motion.end_{unit}", end, f"a motion of some extent: not the start ({start:g} {unit})")
            elif abs(end - start) / step > MAX_POSES:
                problems.add(f"motion.step_{unit}", step,
                             f"allowed ≥ {abs(end - start) / MAX_POSES:.6g} {unit} (at most {MAX_POSES} poses)")
        elif len(set(stops)) < 2:
            problems.add(f"motion.stops_{unit}", stops, "at least two different stops: a motion of some extent")

    def _check_play(self, problems: Problems, joined: set[str]) -> None:
        p = self.play
        if p is None:
            return
        if p.part not in joined:
            problems.add("play.part", p.part, f"allowed a part with a joint: {', '.join(sorted(joined)) or 'none'}")
            return
        if p.part == self.motion.part:
            problems.add("play.part", p.part, "a part other than the driving one (the driver is held at each pose)")
        j = self.joint_of(p.part)
        assert j is not None
        other = "mm" if j.unit == "deg" else "deg"
        if getattr(p, f"min_{other}") is not None:
            problems.add(f"play.min_{other}", getattr(p, f"min_{other}"),
                         f"the {j.kind} joint of {p.part} moves in {j.unit}: give min_{j.unit}")
        limit = getattr(p, f"limit_{j.unit}")
        mins = getattr(p, f"min_{j.unit}")
        if mins is not None and not mins < limit:
            problems.add(f"play.min_{j.unit}", mins, f"allowed < {fmt_bound(limit, 'upper', strict=True)} {j.unit} "
                                                     f"(below play.limit_{j.unit})")

