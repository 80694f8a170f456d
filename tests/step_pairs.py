"""An involute spur pair made the way a user's CAD makes it: a CadQuery script, not gearcheck's
mechanisms or geometry. Each gear's outline is drawn tooth by tooth — the two involute flanks as
splines through the exact involute, the tip and root as arcs, radial lines from the base circle to
the root — extruded, and the pair written as one STEP assembly in millimetres or inches.

The teeth have the standard thickness πm/2 on the pitch circle, so at the standard centre
distance a = m(z1 + z2)/2 the pair meshes without backlash; at a' = a + Δa it has the backlash
j' = 2a'(inv α' − inv α), cos α' = a·cos α / a' (circumferential, on the operating pitch circles).
"""

from __future__ import annotations

import math
from pathlib import Path

import cadquery as cq  # noqa: TID251 (the user's CAD script)
import numpy as np
from cadquery.occ_impl.exporters.assembly import exportAssembly  # noqa: TID251

FLANK_POINTS = 24


def inv(a: float) -> float:
    return math.tan(a) - a


def backlash(m: float, z1: int, z2: int, alpha_deg: float, da: float) -> tuple[float, float]:
    """(circumferential backlash j' in mm, play of gear 2 with gear 1 held in rad) at a + Δa."""
    alpha = math.radians(alpha_deg)
    a = m * (z1 + z2) / 2.0
    a2 = a + da
    alpha_w = math.acos(a * math.cos(alpha) / a2)
    j = 2.0 * a2 * (inv(alpha_w) - inv(alpha))
    r2w = a2 * z2 / (z1 + z2)
    return j, j / r2w


def gear(m: float, z: int, alpha_deg: float, width: float, flank_points: int = FLANK_POINTS) -> cq.Workplane:
    """One spur gear, axis z, tooth 0 centred on +x, standard tooth thickness, no backlash."""
    alpha = math.radians(alpha_deg)
    r = m * z / 2.0
    rb, ra, rf = r * math.cos(alpha), r + m, r - 1.25 * m
    assert rf < rb, "the radial line from the base circle to the root needs rf < rb"
    half = math.pi / (2.0 * z) + inv(alpha)  # half tooth angle at the base circle

    def psi(radius: float) -> float:
        return half - inv(math.acos(rb / radius))

    def at(radius: float, angle: float) -> tuple[float, float]:
        return (radius * math.cos(angle), radius * math.sin(angle))

    radii = rb + (ra - rb) * (1.0 - np.cos(np.linspace(0.0, math.pi / 2.0, flank_points)))  # denser at the base
    pitch = 2.0 * math.pi / z
    wp = cq.Workplane("XY").moveTo(*at(rf, -half))
    for k in range(z):
        c = k * pitch
        wp = wp.lineTo(*at(rb, c - half))
        wp = wp.spline([at(float(R), c - psi(float(R))) for R in radii[1:]], includeCurrent=True)
        wp = wp.threePointArc(at(ra, c), at(ra, c + psi(ra)))
        wp = wp.spline([at(float(R), c + psi(float(R))) for R in radii[::-1][1:]], includeCurrent=True)
        wp = wp.lineTo(*at(rf, c + half))
        if k < z - 1:
            wp = wp.threePointArc(at(rf, c + pitch / 2.0), at(rf, c + pitch - half))
        else:
            wp = wp.threePointArc(at(rf, c + pitch / 2.0), at(rf, -half))
    return wp.close().extrude(width / 2.0, both=True)


def write_pair(path: Path, m: float = 2.0, z1: int = 18, z2: int = 24, alpha_deg: float = 20.0,
               da: float = 0.0, width: float = 8.0, unit: str = "MM", flank_points: int = FLANK_POINTS) -> Path:
    """The pair as one STEP assembly ("pinion" at the origin, "wheel" at x = a + Δa turned so a
    tooth space faces the pinion's tooth 0), in ``unit`` ("MM" or "INCH")."""
    a = m * (z1 + z2) / 2.0 + da
    assy = cq.Assembly(name="spur_pair")
    assy.add(gear(m, z1, alpha_deg, width, flank_points), name="pinion", color=cq.Color(0.7, 0.7, 0.75))
    turn = 180.0 - 180.0 / z2
    assy.add(gear(m, z2, alpha_deg, width, flank_points), name="wheel", loc=cq.Location(cq.Vector(a, 0, 0), cq.Vector(0, 0, 1), turn),
             color=cq.Color(0.5, 0.6, 0.8))
    assert exportAssembly(assy, str(path), unit="MM", outputUnit=unit)  # type: ignore[arg-type]
    return path


def template(step: Path, m: float = 2.0, z1: int = 18, z2: int = 24, da: float = 0.0, steps: int = 20,
             **extra: object) -> dict:
    """An assembly template for the pair: the wheel coupled to the pinion (−z1/z2), the pinion
    turned through one pitch, the wheel's play measured."""
    a = m * (z1 + z2) / 2.0 + da
    pitch = 360.0 / z1
    data: dict = {
        "mechanism": "assembly", "name": "spur_pair",
        "assembly": {"step": str(step), "contact_tolerance_mm": 0.005},
        "part": [{"name": "pinion", "material": "steel"}, {"name": "wheel", "material": "steel"}],
        "joint": [{"part": "pinion", "kind": "revolute", "axis": [0.0, 0.0, 1.0], "point": [0.0, 0.0, 0.0]},
                  {"part": "wheel", "kind": "revolute", "axis": [0.0, 0.0, 1.0], "point": [a, 0.0, 0.0]}],
        "couple": [{"driver": "pinion", "driven": "wheel", "ratio": -z1 / z2}],
        "motion": {"part": "pinion", "start_deg": 0.0, "end_deg": pitch, "step_deg": pitch / steps},
        "play": {"part": "wheel", "limit_deg": 2.0},
        "require": [{"parts": ["pinion", "wheel"], "min_clearance_mm": 0.0}],
    }
    for key, value in extra.items():
        data[key] = value
    return data


def write_train(path: Path, gears: int = 6, m: float = 2.0, z: tuple[int, int] = (18, 24), alpha_deg: float = 20.0,
                da: float = 0.1, width: float = 8.0) -> Path:
    """A train of ``gears`` spur gears in a row along x, alternately z[0] and z[1] teeth, each
    meshing the next at a centre distance opened by ``da`` ("gear_1", "gear_2", …): a large file."""
    assy = cq.Assembly(name="train")
    x = 0.0
    for i in range(gears):
        zi = z[i % 2]
        if i:
            x += m * (z[0] + z[1]) / 2.0 + da
        # tooth 0 of an odd gear faces its left neighbour (180°) offset by half a pitch: a space
        # there, and a space to its right for the next gear's tooth 0 (180° + half a pitch: the
        # tooth counts are even, so the opposite side is a space too)
        turn = 180.0 + 180.0 / zi if i % 2 else 0.0
        assy.add(gear(m, zi, alpha_deg, width), name=f"gear_{i + 1}",
                 loc=cq.Location(cq.Vector(x, 0, 0), cq.Vector(0, 0, 1), turn))
    assert exportAssembly(assy, str(path), unit="MM", outputUnit="MM")  # type: ignore[arg-type]
    return path


def train_template(step: Path, gears: int = 6, m: float = 2.0, z: tuple[int, int] = (18, 24), da: float = 0.1,
                   steps: int = 8, tol_mm: float | None = None) -> dict:
    """The train driven by gear_1 through one of its pitches, each gear coupled to the one before
    (−z_before / z_this), the last one's play measured."""
    centres, x = [], 0.0
    for i in range(gears):
        if i:
            x += m * (z[0] + z[1]) / 2.0 + da
        centres.append(x)
    names = [f"gear_{i + 1}" for i in range(gears)]
    pitch = 360.0 / z[0]
    data: dict = {
        "mechanism": "assembly", "name": "train",
        "assembly": {"step": str(step)},
        "part": [{"name": n} for n in names],
        "joint": [{"part": n, "kind": "revolute", "axis": [0.0, 0.0, 1.0], "point": [c, 0.0, 0.0]}
                  for n, c in zip(names, centres, strict=True)],
        "couple": [{"driver": names[i - 1], "driven": names[i], "ratio": -z[(i - 1) % 2] / z[i % 2]}
                   for i in range(1, gears)],
        "motion": {"part": names[0], "start_deg": 0.0, "end_deg": pitch, "step_deg": pitch / steps},
        "play": {"part": names[-1], "limit_deg": 2.0},
    }
    if tol_mm is not None:
        data["mesh_tol_mm"] = tol_mm
    return data
