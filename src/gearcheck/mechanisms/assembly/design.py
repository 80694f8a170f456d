"""``gearcheck new assembly --step FILE``: a template listing the file's products as parts, to fill
in with how they move (the joints, couples and motion cannot be read from a STEP file: it holds
shapes, not kinematics). The example blocks at the end name the file's own products."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gearcheck.drafting import Draft, Entry
from gearcheck.names import as_name
from gearcheck.params.common import ParamError


def _size(bbox) -> str:
    (x0, y0, z0), (x1, y1, z1) = bbox
    return f"{x1 - x0:.4g} × {y1 - y0:.4g} × {z1 - z0:.4g} mm"


_ROUND_TOL = 0.02  # two extents within 2 %: a round section
_SLENDER = 3.0  # the longest extent 3× the next: a bar


@dataclass(frozen=True)
class JointGuess:
    """What a part's shape says about how it may move: ``kind`` revolute (a round part, about
    its axis through its centre), prismatic (a slender part, along its long axis) or None (the
    shape says nothing: the block is a placeholder that does not validate)."""

    kind: str | None
    axis: tuple[float, float, float]
    point: tuple[float, ...]
    why: str


def guess_joint(bbox, volume_mm3: float, centre_of_volume) -> JointGuess:
    """A joint from a part's bounding box (the file's frame), volume and centre of volume:
    round (two extents within 2 % and no more volume than the cylinder they bound) turns about
    the third axis through its centre of volume (on a gear's axis, whatever its tooth count);
    slender (one extent 3× the others) slides along it."""
    lo, hi = (np.asarray(c, float) for c in bbox)
    size = hi - lo
    centre = tuple(round(float(c), 6) + 0.0 for c in centre_of_volume)
    order = np.argsort(size)
    unit: list[tuple[float, float, float]] = [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
    names = "xyz"
    for k in range(3):  # the axis of a round section: the other two extents agree
        a, b = (i for i in range(3) if i != k)
        if size[a] > 0 and abs(size[a] - size[b]) <= _ROUND_TOL * max(size[a], size[b]):
            cylinder = math.pi / 4 * size[a] * size[b] * size[k]
            if volume_mm3 <= 1.02 * cylinder:
                why = f"round about {names[k]} (Ø {size[a]:.4g} mm): turns about its axis through its centre"
                return JointGuess("revolute", unit[k], centre, why)
    if size[order[2]] >= _SLENDER * size[order[1]]:
        k = int(order[2])
        return JointGuess("prismatic", unit[k], centre,
                          f"slender along {names[k]} ({size[k]:.4g} mm long): slides along it")
    return JointGuess(None, (0.0, 0.0, 1.0), centre, "neither round nor slender: say how it moves")


def _examples(names: list[str], guesses: list[JointGuess]) -> list[str]:
    """The commented blocks at the end of the template: a joint per part as its shape suggests
    (a placeholder where the shape says nothing), then a couple, the motion, play and a
    requirement. What no shape can tell (the ratio of a couple) is a placeholder that does not
    validate, so a block uncommented as written names what is missing."""
    lines: list[str] = []
    for name, g in zip(names, guesses, strict=True):
        kind = f'"{g.kind}"' if g.kind else '"revolute or prismatic?"   # placeholder: give one'
        lines += ["[[joint]]", f'part = "{name}"', f"kind = {kind}",
                  f"axis = {list(g.axis)}         # {g.why}", f"point = {list(g.point)}", ""]
    moving = [(n, g) for n, g in zip(names, guesses, strict=True) if g.kind]
    a = moving[0] if moving else (names[0], guesses[0])
    b = next((m for m in moving if m[0] != a[0]), None) or (names[1] if len(names) > 1 else names[0], guesses[-1])
    kinds = f"{a[1].kind}/{b[1].kind}"
    key = {"revolute/prismatic": "mm_per_rad", "prismatic/revolute": "rad_per_mm"}.get(kinds, "ratio")
    what = {"ratio": "driven angle per driver angle: −z1/z2 for an external pair",
            "mm_per_rad": "rack travel per pinion radian: ± the pitch radius",
            "rad_per_mm": "pinion radians per rack mm: ± 1 / pitch radius"}[key]
    unit = "mm" if a[1].kind == "prismatic" else "deg"
    motion = (["start_mm = 0.0", "end_mm = 10.0", "step_mm = 0.1"] if unit == "mm"
              else ["start_deg = 0.0", "end_deg = 30.0", "step_deg = 0.25"])
    lines += ["[[couple]]", f'driver = "{a[0]}"', f'driven = "{b[0]}"',
              f'{key} = "?"                     # placeholder ({what}): a shape cannot tell it', "",
              "[motion]", f'part = "{a[0]}"', *motion, "",
              "[play]                          # optional: turn this part both ways to contact at every pose",
              f'part = "{b[0]}"', "",
              "[[require]]", f'parts = ["{a[0]}", "{b[0]}"]',
              "min_clearance_mm = 0.0          # or contact = true, or ignore = true"]
    return lines


def new_template(inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
    from gearcheck.cad.step_import import StepImportError, centroid, read_step
    from gearcheck.mechanisms.assembly.params import step_problem

    path = Path(str(inputs["step"])).expanduser().resolve()
    why = step_problem(str(path))
    if why:
        raise ParamError("--step", str(inputs["step"]), why)
    try:
        f = read_step(path)
    except StepImportError as exc:
        raise ParamError("--step", str(inputs["step"]), str(exc)) from None
    d = Draft("assembly", as_name(path.stem, dots=True), complete=False, paths=("assembly.step",))
    # the header is the report's description: what stays true once the template is filled in
    d.header = [f"{path.stem}: {len(f.products)} parts from {path.name} (file unit {f.unit}, read in mm).",
                "Replace these lines with what the design is: they are its report's description."]
    d.set("assembly.step", str(path), "the STEP file, relative to this template")
    d.set("assembly.contact_tolerance_mm", 0.01, "closer than this is contact")
    names: list[str] = []
    for p in f.products:
        name = as_name(p.name, set(names))  # a file name; the product's own name kept beside it
        entry = {"name": Entry(name, f"{p.solids} solid{'s' if p.solids != 1 else ''}, {p.volume_mm3:.6g} mm³, "
                                     f"{_size(p.bbox)}")}
        if name != p.name:
            entry["product"] = Entry(p.name, "the product's name in the file")
        entry["material"] = Entry("steel", "or cte_per_K = 11.5e-6")
        d.tables.setdefault("part", []).append(entry)
        names.append(name)
    guesses = [guess_joint(p.bbox, p.volume_mm3, centroid(p.shape)) for p in f.products]
    d.footer = ["Fill in how the parts move: a [[joint]] per moving part, [[couple]]s between joints, the",
                "[motion]; then `gearcheck check` this file. The blocks below are examples with your names,",
                "each joint guessed from the part's shape (docs/assembly.md); uncomment and correct them.", "",
                *_examples(names, guesses)]
    for dotted, value in overrides.items():
        d.set(dotted, value, "set with --set")
    return d
