"""``gearcheck new assembly --step FILE``: a template listing the file's products as parts, to fill
in with how they move (the joints, couples and motion cannot be read from a STEP file: it holds
shapes, not kinematics). The example blocks at the end name the file's own products."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gearcheck.drafting import Draft, Entry
from gearcheck.params.common import ParamError


def _size(bbox) -> str:
    (x0, y0, z0), (x1, y1, z1) = bbox
    return f"{x1 - x0:.4g} × {y1 - y0:.4g} × {z1 - z0:.4g} mm"


def new_template(inputs: Mapping[str, Any], overrides: Mapping[str, Any]) -> Draft:
    from gearcheck.cad.step_import import StepImportError, read_step
    from gearcheck.mechanisms.assembly.params import step_problem

    path = Path(str(inputs["step"])).expanduser().resolve()
    why = step_problem(str(path))
    if why:
        raise ParamError("--step", str(inputs["step"]), why)
    try:
        f = read_step(path)
    except StepImportError as exc:
        raise ParamError("--step", str(inputs["step"]), str(exc)) from None
    d = Draft("assembly", path.stem, complete=False, paths=("assembly.step",))
    d.header = [f"Parts of {path.name} (file unit {f.unit}, read in mm): {len(f.products)} products.",
                "Fill in how they move: a [[joint]] per moving part, [[couple]]s between joints, the [motion];",
                "then `gearcheck check` this file. The commented blocks at the end are examples with your names."]
    d.set("assembly.step", str(path), "the STEP file, relative to this template")
    d.set("assembly.contact_tolerance_mm", 0.01, "closer than this is contact")
    for p in f.products:
        entry = {"name": Entry(p.name, f"{p.solids} solid{'s' if p.solids != 1 else ''}, {p.volume_mm3:.6g} mm³, "
                                       f"{_size(p.bbox)}"),
                 "material": Entry("steel", "or cte_per_K = 11.5e-6")}
        d.tables.setdefault("part", []).append(entry)
    names = f.names()
    a = names[0]
    b = names[1] if len(names) > 1 else names[0]
    centre = [round(0.5 * (lo + hi), 6) for lo, hi in zip(*f.products[0].bbox, strict=True)]
    d.footer = [
        "[[joint]]",
        f'part = "{a}"',
        'kind = "revolute"              # or "prismatic"',
        "axis = [0.0, 0.0, 1.0]          # direction, the file's frame",
        f"point = {centre}   # a point on the axis (here: {a}'s bounding-box centre)",
        "",
        "[[joint]]",
        f'part = "{b}"',
        'kind = "revolute"',
        "axis = [0.0, 0.0, 1.0]",
        "point = [0.0, 0.0, 0.0]",
        "",
        "[[couple]]",
        f'driver = "{a}"',
        f'driven = "{b}"',
        "ratio = -0.5                    # driven angle per driver angle: −z1/z2 for an external pair",
        "",
        "[motion]",
        f'part = "{a}"',
        "start_deg = 0.0",
        "end_deg = 30.0",
        "step_deg = 0.25",
        "",
        "[play]                          # optional: turn this part both ways to contact at every pose",
        f'part = "{b}"',
        "",
        "[[require]]",
        f'parts = ["{a}", "{b}"]',
        "min_clearance_mm = 0.0          # or contact = true, or ignore = true",
    ]
    for dotted, value in overrides.items():
        d.set(dotted, value, "set with --set")
    return d
