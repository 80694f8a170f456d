"""Geometric thermal state of the differential: each gear moved and shrunk by its own materials.

Numpy only. A uniform scale of the whole assembly changes no angle and proves nothing, so the
cold state is built part by part along the chain that holds each gear (the paper's mounting
drawing, eqs (2)–(7)):

- the housing (aluminium, ξ1) shrinks about its centre, the common apex, so each mounting face
  on a gear axis moves by ξ1·(distance from the centre)·(T_cold − T_warm) along that axis;
- big gear: the titanium shaft (ξ2, length l11) hangs from the housing face at b/2 to the joint
  with the gear body, and the shim (thickness x, steel: the gear's ξ3, the template names no
  other) holds it x further out, so the joint (the big gear's datum, its back face, z_j = d2/2 +
  l12 from the apex in its own frame) moves by Δ_datum = [ξ1·b/2 + ξ3·x − ξ2·l11]·(T_cold − T_warm);
- small gear: its back face is the datum and bears on the housing face at a/2 (z_j = a/2), so
  Δ_datum = ξ1·(a/2)·(T_cold − T_warm);
- each gear body (steel, ξ3) then scales by f = 1 + ξ3·(T_cold − T_warm) about its datum.

Output per gear: a world translation of the datum along the gear's axis (``pose_change``, 4×4)
and a scale factor about ``datum_local`` (for :meth:`gearcheck.sweep.bodies.Body.scaled`).

Relation to eqs (6)/(7). Scaling about the datum moves the apex toward the datum by
(1 − f)·z_j, so the apex moves along the axis, outward +, by

    Δapex = Δ_datum − ξ3·z_j·(T_cold − T_warm)

With the temperature drop ΔT = T_warm − T_cold this is, for the big gear,

    −Δapex = [ξ1·b/2 − ξ2·l11 − ξ3·(l12 + d2/2)]·ΔT + ξ3·x·ΔT = ΔL1 − Δd2/2 + ξ3·x·ΔT
           = ΔS1 (eq 6) + ξ3·x·ΔT

The "Δd2/2" of (6) *is* the scale effect: the steel body shrinking between the pitch-circle
plane (d2/2 from the apex on a common apex) and the apex. The shim's own shrink (0.1 µm for
0.10 mm) is the only term eq (6) leaves out. For the small gear −Δapex = (ξ1 − ξ3)·(a/2)·ΔT,
which is ΔS2 of eq (7) when a/2 = l2 + d1/2 (the template rule; within its 0.05 mm tolerance
the difference is ξ3·0.05 mm·ΔT < 0.05 µm). With every CTE equal the whole chain is a uniform
scale about the centre: each apex moves by ξ·ΔT times its offset from the centre (the shim).

Besides moving the apex, the scale leaves every flank where it is: the flanks are cones through
the apex, invariant under a scale about it; only the toe and heel (the front and back cones)
move in by the factor f.

Not modelled (far below the mesh-error bound): the housing wall outside the mounting face (the
CAD draws the collar outside the wall; the chain here follows the paper's eqs (2)–(7), datum at
the mounting face b/2), bores and radial fits (the housing shrinks about the centre, so the
axes stay on it). Only the gears get a thermal state: the sweep looks at gear pairs only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.mechanisms.differential.poses import GearSpecs, assembly_poses, axis_of, gear_specs

BIG_GEARS = ("big_gear_right", "big_gear_left")
SMALL_GEARS = ("small_gear_front", "small_gear_back")


@dataclass(frozen=True)
class GearThermal:
    """How one gear moves and shrinks from warm to cold."""

    name: str
    scale: float  # f = 1 + ξ3·(T_cold − T_warm), about datum_local
    datum_local: np.ndarray  # (0, 0, z_j): the back face centre, own frame
    datum_shift_mm: float  # Δ_datum along the axis, outward + (world)
    axis: np.ndarray  # world unit axis (apex → body)

    @property
    def pose_change(self) -> np.ndarray:
        """World 4×4 translation of the datum (applied on the left of the warm pose)."""
        m = np.eye(4)
        m[:3, 3] = self.datum_shift_mm * self.axis
        return m

    @property
    def apex_shift_mm(self) -> float:
        """Δapex along the axis, outward + (= −ΔS of eqs (6)/(7)): datum shift plus the scale
        about the datum, which moves the apex by (1 − f)·z_j toward the datum."""
        return self.datum_shift_mm + (1.0 - self.scale) * float(self.datum_local[2])

    def cold_pose(self, warm_pose: np.ndarray) -> np.ndarray:
        """Pose of the gear's frame, cold, for vertices scaled by ``scale`` about datum_local."""
        return self.pose_change @ np.asarray(warm_pose, float)

    def cold_pose_about_origin(self, warm_pose: np.ndarray) -> np.ndarray:
        """The same cold gear written as a scale about its frame origin (the apex) followed by a
        pose: p → datum + f·(p − datum) = f·p + (1 − f)·datum."""
        shift = np.eye(4)
        shift[:3, 3] = (1.0 - self.scale) * self.datum_local
        return self.cold_pose(warm_pose) @ shift


def thermal_state(params, cold_C: float | None = None, specs: GearSpecs | None = None,
                  shim_mm: float | None = None) -> dict[str, GearThermal]:
    """Warm → cold state of the four gears (warm_C → cold_C and the shim of the template unless
    given)."""
    shim = params.shim.thickness_mm if shim_mm is None else shim_mm
    specs = gear_specs(params) if specs is None else specs
    m, d, op = params.materials, params.dimensions, params.operating
    dT = (op.cold_C if cold_C is None else cold_C) - op.warm_C  # negative when cooling
    housing = m.housing_cte_per_K * dT
    shaft = m.shaft_cte_per_K * dT
    gear = m.gear_cte_per_K * dT
    poses = assembly_poses(specs).as_dict()
    out = {}
    for name in BIG_GEARS:
        out[name] = GearThermal(
            name=name, scale=1.0 + gear,
            datum_local=np.array([0.0, 0.0, specs.big.mounting_distance]),
            # the face moves with the housing, the shim and shaft shrink toward it
            datum_shift_mm=housing * d.b_mm / 2.0 + gear * shim - shaft * d.l11_mm,
            axis=axis_of(poses[name]))
    for name in SMALL_GEARS:
        out[name] = GearThermal(
            name=name, scale=1.0 + gear,
            datum_local=np.array([0.0, 0.0, specs.small.mounting_distance]),
            datum_shift_mm=housing * d.a_mm / 2.0,
            axis=axis_of(poses[name]))
    return out
