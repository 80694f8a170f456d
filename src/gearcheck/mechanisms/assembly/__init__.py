"""Your own CAD: any STEP assembly swept through the motions its template declares (docs/assembly.md).

``calc`` gives what the declaration alone says (numpy only; the file is not read): the poses, each
coupled part's travel over the motion and its ratio to the driver, each temperature state's
growth of every part. The check reads the file, meshes its products and sweeps them.
"""

from __future__ import annotations

import math

from gearcheck.figures import Figure
from gearcheck.mechanisms.assembly.kinematics import kinematics
from gearcheck.mechanisms.assembly.params import Params

MESH_TOL_MM = 0.01


def calc(params: Params) -> list[Figure]:
    kin = kinematics(params)
    unit = kin.unit
    x = kin.coordinates
    figures = [
        Figure("parts", "parts (STEP products)", float(len(params.part)), "", digits=0),
        Figure("moving_parts", "parts the motion moves", float(len(kin.moving())), "", digits=0),
        Figure("poses", "poses of the motion", float(len(x)), "", digits=0),
        Figure(f"motion_extent_{unit}", f"{kin.driver}: extent of the motion", float(x.max() - x.min()), unit),
        Figure(f"motion_step_{unit}", f"{kin.driver}: largest step between poses",
               float(max(abs(b - a) for a, b in zip(x[:-1], x[1:], strict=True))), unit, digits=4),
    ]
    for name, line in kin.lines.items():
        if name == kin.driver or not line.coupled:
            continue
        per = f"{line.unit} per {unit}"
        figures.append(Figure(f"ratio_{name}", f"{name}: {line.unit} per {unit} of {kin.driver}", line.gain, per,
                              digits=6))
        figures.append(Figure(f"travel_{name}_{line.unit}", f"{name}: travel over the motion",
                              float(abs(line.gain) * (x.max() - x.min())), line.unit))
    cte = {p.name: p.cte_per_K if p.cte_per_K is not None else _material_cte(p.material) for p in params.part}
    for s in params.state:
        for p in params.part:
            growth = cte[p.name] * (s.temperature_C - s.reference_C)
            figures.append(Figure(f"{s.name}_growth_{p.name}_ppm", f"{s.name} ({s.temperature_C:g} °C): {p.name} "
                                  "grows by", 1e6 * growth, "ppm", digits=1))
    if params.play is not None:
        line = kin.lines[params.play.part]
        limit = getattr(params.play, f"limit_{line.unit}")
        figures.append(Figure(f"play_search_limit_{line.unit}", f"{params.play.part}: farthest move searched for "
                              "contact", limit, line.unit))
    for r in params.require:
        if r.min_clearance_mm is not None:
            figures.append(Figure(f"required_clearance_{r.parts[0]}__{r.parts[1]}_mm",
                                  f"{r.parts[0]} – {r.parts[1]}: required clearance", r.min_clearance_mm, "mm",
                                  digits=4))
    return [f for f in figures if math.isfinite(f.value)]


def _material_cte(material: str) -> float:
    from gearcheck.geometry import materials

    return materials.cte_per_K(material) or 0.0
