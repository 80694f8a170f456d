"""Which design is the paper's own: the shipped template (templates/zhurong_differential.toml) holds
it, and the paper's printed figures stand beside a design's only when the inputs that define the
unit equal the template's (:func:`is_paper_design`). Numpy-free; the template is read once.

The inputs that define the unit are its hardware: the gears, the designed tooth thinning, the
materials, the mounting dimensions and the backlash measured on it ([calibration]). The conditions
a figure is taken at are each figure's own (a 90 K drop for the drop figures, the paper's shim for
the warm ones, as before); the shim study, the temperature ranges and [targets] define no unit.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

# The sections of a differential template that define the unit (every key of each).
DESIGN_SECTIONS = ("gears", "backlash", "materials", "dimensions", "calibration")
TEMPLATE = "zhurong_differential.toml"


@lru_cache(maxsize=1)
def shipped_template() -> dict:
    """The shipped template's data as written (read once; the package's own copy)."""
    from importlib.resources import files
    from pathlib import Path

    from gearcheck.params.common import read_toml

    return read_toml(Path(str(files("gearcheck") / "templates" / TEMPLATE)))


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(float(a), float(b), rel_tol=0.0, abs_tol=1e-12)
    return a == b


def is_paper_design(params) -> bool:
    """The design is the paper's unit: every key of :data:`DESIGN_SECTIONS` equals the shipped
    template's (a calibration the template gives must be given, one it lacks must be absent)."""
    template = shipped_template()
    for section in DESIGN_SECTIONS:
        ours = getattr(params, section).model_dump()
        theirs = template.get(section, {})
        for key, value in ours.items():
            if not _same(value, theirs.get(key)):
                return False
    return True
