"""The assembly as data (numpy only) and its CAD hook (the user's STEP products as solids).

Each part's solid is a product of a STEP file, placed as in the file: its own frame *is* the
file's frame, so every pose as built is the identity and a joint's axis and point are read in the
file's coordinates. The solid spec carries the file's SHA-256, so the CAD cache never serves
solids of an edited file.
"""

from __future__ import annotations

import functools
import hashlib
import os
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import materials
from gearcheck.mechanism import Assembly, PartSpec
from gearcheck.mechanisms.assembly.kinematics import Kinematics, kinematics

# display colours, one per part in order (the STEP's own colours are not read)
COLOURS = ((0.72, 0.72, 0.78), (0.55, 0.66, 0.82), (0.85, 0.62, 0.35), (0.55, 0.78, 0.55),
           (0.80, 0.55, 0.70), (0.60, 0.80, 0.85), (0.85, 0.80, 0.45), (0.65, 0.60, 0.85))


@dataclass(frozen=True)
class StepSolid:
    """Which solid a part is: a product of a STEP file (the file by path and content)."""

    path: str
    product: str
    sha256: str
    field: str  # the template field that names the product, for a one-line error
    file_field: str  # the template field that names the file


@dataclass(frozen=True)
class PairRule:
    """What is required of two parts: ``kind`` "clearance" (at least ``min_clearance_mm``),
    "contact" (touching allowed, overlap along the motion up to the contact tolerance) or
    "default" (no interference: clearance ≥ 0); ``moving``: the motion moves one relative to the
    other (else it is checked at the first pose only)."""

    a: str
    b: str
    kind: str
    min_clearance_mm: float
    moving: bool
    declared: bool  # named in a [[require]] (else every pair is checked for interference)

    @property
    def key(self) -> str:
        return f"{self.a}__{self.b}"


@dataclass(frozen=True)
class Layout:
    """The numbers the sweep plan works from: the kinematics, the pair rules, the play part and
    its neighbours, the contact tolerance, each part's CTE and thermal datum, the states."""

    kin: Kinematics
    pairs: tuple[PairRule, ...]
    play: str | None
    play_limit: float
    play_min: float | None
    play_neighbours: tuple[str, ...]
    contact_tolerance_mm: float
    cte_per_K: dict[str, float]
    datum: dict[str, tuple[float, float, float] | None]
    states: tuple[tuple[str, float, float], ...]  # (name, temperature, reference)


@functools.lru_cache(maxsize=32)
def _sha256(path: str, size: int, mtime_ns: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def file_digest(path: str) -> str:
    """SHA-256 of a file (remembered per path, size and modification time)."""
    st = os.stat(path)
    return _sha256(path, st.st_size, st.st_mtime_ns)


def pair_rules(params, kin: Kinematics) -> tuple[PairRule, ...]:
    """Every pair of parts, in part order, with its rule (ignored pairs left out)."""
    names = [p.name for p in params.part]
    declared = {frozenset(r.parts): r for r in params.require}
    moving = set(kin.moving())
    rules = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            r = declared.get(frozenset((a, b)))
            if r is not None and r.ignore:
                continue
            rel = (a in moving) != (b in moving) or (a in moving and b in moving
                                                      and kin.lines[a].motion != kin.lines[b].motion)
            if r is None:
                rules.append(PairRule(a, b, "default", 0.0, rel, False))
            elif r.contact:
                rules.append(PairRule(a, b, "contact", 0.0, rel, True))
            else:
                rules.append(PairRule(a, b, "clearance", float(r.min_clearance_mm), rel, True))
    return tuple(rules)


def layout(params) -> Layout:
    kin = kinematics(params)
    pairs = pair_rules(params, kin)
    play = params.play
    play_part = play.part if play is not None else None
    limit, minimum = 0.0, None
    neighbours: tuple[str, ...] = ()
    if play is not None:
        unit = kin.lines[play.part].unit
        limit, minimum = getattr(play, f"limit_{unit}"), getattr(play, f"min_{unit}")
        neighbours = tuple(r.b if r.a == play.part else r.a for r in pairs if play.part in (r.a, r.b))
    cte = {p.name: float(p.cte_per_K if p.cte_per_K is not None else materials.cte_per_K(p.material) or 0.0)
           for p in params.part}
    datum = {p.name: (tuple(p.datum) if p.datum is not None else
                      tuple(params.joint_of(p.name).point) if params.joint_of(p.name) is not None
                      and params.joint_of(p.name).kind == "revolute" else None) for p in params.part}
    states = tuple((s.name, s.temperature_C, s.reference_C) for s in params.state)
    return Layout(kin, pairs, play_part, float(limit), minimum, neighbours, params.assembly.contact_tolerance_mm,
                  cte, datum, states)


def step_assembly(params, name: str) -> Assembly:
    """Part specs (identity poses: the file's frame), one STEP solid per part, and the layout."""
    lay = layout(params)
    specs, solids = [], {}
    for i, p in enumerate(params.part):
        path = p.step or params.assembly.step
        field = f"part[{i}].product" if p.product else f"part[{i}].name"
        solids[p.name] = StepSolid(path, p.product_name, file_digest(path), field,
                                   f"part[{i}].step" if p.step else "assembly.step")
        line = lay.kin.lines.get(p.name)
        specs.append(PartSpec(p.name, p.name, p.material, np.eye(4), COLOURS[i % len(COLOURS)],
                              line.motion if line is not None else None))
    return Assembly(name, tuple(specs), solids, layout=lay)


def build_parts(assembly: Assembly) -> list:
    """The STEP products as solids, in part order; each file read once. A product the file does
    not have, or a file without solids, is a :class:`ParamError` naming the template field."""
    from gearcheck.cad.placement import Part
    from gearcheck.cad.step_import import StepImportError, part_solid, read_step
    from gearcheck.params import ParamError

    files: dict[str, object] = {}
    out = []
    for spec in assembly.parts:
        solid: StepSolid = assembly.solids[spec.solid]
        try:
            if solid.path not in files:
                files[solid.path] = read_step(solid.path)
            product = files[solid.path].product(solid.product)  # type: ignore[attr-defined]
        except StepImportError as exc:
            if solid.path in files:  # the file is read: the product is not in it
                raise ParamError(solid.field, solid.product, str(exc)) from None
            raise ParamError(solid.file_field, solid.path, str(exc).removeprefix(f"{solid.path}: ")) from None
        out.append(Part(spec.name, spec.material, part_solid(product), spec.pose, spec.color, spec.motion))
    return out
