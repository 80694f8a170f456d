"""A large assembly made the way a user's CAD makes one: a CadQuery script writes a grid of small
cubes, each turning about its own vertical axis, every one coupled to the first (alternately +1
and −1, as meshing gears turn), with a least clearance required between grid neighbours.

Neighbours ``pitch`` apart: two cubes of side ``size`` turned by the same angle about parallel
axes come closest when their corners face each other (at 45°: pitch − size·√2) and are farthest
apart when their faces do (pitch − size); cubes a diagonal apart never come within the sweep's
pruning margin, so only the grid neighbours are queried.
"""

from __future__ import annotations

import math
from pathlib import Path

import cadquery as cq  # noqa: TID251 (the user's CAD script)
from cadquery.occ_impl.exporters.assembly import exportAssembly  # noqa: TID251


def centres(count: int, columns: int, pitch: float) -> list[tuple[float, float]]:
    return [((i % columns) * pitch, (i // columns) * pitch) for i in range(count)]


def write_boxes(path: Path, count: int = 200, columns: int = 20, size: float = 4.0, pitch: float = 6.0) -> Path:
    """``count`` cubes of side ``size`` on a grid ``columns`` wide, ``pitch`` apart, named
    box_1 … box_N, as one STEP assembly in mm."""
    cube = cq.Workplane("XY").box(size, size, size)
    assy = cq.Assembly(name="boxes")
    for i, (x, y) in enumerate(centres(count, columns, pitch)):
        assy.add(cube, name=f"box_{i + 1}", loc=cq.Location(cq.Vector(x, y, 0.0)))
    assert exportAssembly(assy, str(path), unit="MM", outputUnit="MM")  # type: ignore[arg-type]
    return path


def neighbours(count: int, columns: int) -> list[tuple[int, int]]:
    """The grid's neighbour pairs (0-based indices): right and up."""
    out = []
    for i in range(count):
        if (i + 1) % columns and i + 1 < count:
            out.append((i, i + 1))
        if i + columns < count:
            out.append((i, i + columns))
    return out


def boxes_template(step: Path, count: int = 200, columns: int = 20, pitch: float = 6.0, end_deg: float = 360.0,
                   step_deg: float = 1.0, min_clearance_mm: float = 0.25, **extra: object) -> dict:
    """Every cube turning about its own z axis, coupled to box_1 (ratio ±1 in a checkerboard), the
    motion box_1 from 0 to ``end_deg`` in ``step_deg``; each neighbour pair at least
    ``min_clearance_mm`` apart."""
    names = [f"box_{i + 1}" for i in range(count)]
    where = centres(count, columns, pitch)

    def sign(i: int) -> float:
        return 1.0 if (i % columns + i // columns) % 2 == 0 else -1.0

    data: dict = {
        "mechanism": "assembly", "name": f"boxes_{count}",
        "assembly": {"step": str(step)},
        "part": [{"name": n} for n in names],
        "joint": [{"part": n, "kind": "revolute", "axis": [0.0, 0.0, 1.0], "point": [x, y, 0.0]}
                  for n, (x, y) in zip(names, where, strict=True)],
        "couple": [{"driver": names[0], "driven": names[i], "ratio": sign(i)} for i in range(1, count)],
        "motion": {"part": names[0], "start_deg": 0.0, "end_deg": end_deg, "step_deg": step_deg},
        "require": [{"parts": [names[a], names[b]], "min_clearance_mm": min_clearance_mm}
                    for a, b in neighbours(count, columns)],
    }
    data.update(extra)
    return data


def least_gap(size: float = 4.0, pitch: float = 6.0) -> float:
    """The least clearance of two neighbours over a turn (corners facing, at 45°)."""
    return pitch - size * math.sqrt(2.0)
