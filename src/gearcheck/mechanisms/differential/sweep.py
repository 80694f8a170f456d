"""The differential's sweep plan: angular play of the output shafts, warm and cold, for each
study shim — measured with FCL on the built meshes and checked against the exact-flank model.

Poses are data. At drive angle φ each small gear turns φ about its own axis and each big gear
−φ·z_small/z_big about its own (the pitch cones roll; carrier held), from the poses the build
placed them at (:func:`gearcheck.geometry.bevel_mesh.drive_poses`). Other shims than the built
one translate the big gears along their own axes by the shim difference; nothing else about the
geometry changes. The cold state moves and shrinks every gear by its own materials about its own
datum (:mod:`.thermal`), never a uniform scale of the assembly.

Play of one output shaft: hold the small gears, turn the big gear about its own axis until a
flank touches, both ways (bisection on ``collide``, :func:`gearcheck.sweep.engine.bisect_contact`,
contact proven from both sides). The big gear meshes with *both* small gears, so each way it stops
at the tighter of its two meshes: plus = min over the small gears, minus = max; play = plus −
minus, in arcmin on the big gear's axis. That is the paper's "per side" backlash (one big/small
mesh side of the shaft-to-shaft total, which is twice it).

Cycle. Identical teeth: one small-gear tooth pitch of drive repeats every pose. With z_big odd
(33) each big gear meets its two small gears half a tooth apart, so its play repeats every half
pitch (:func:`gearcheck.geometry.bevel_mesh.play_period` checks this on the poses);
``angles_per_cycle`` drive angles over that period cover the whole cycle, and each big gear's
two meshes together pass twice as many phases of one full mesh cycle. The cold drop is the cycle
minimum warm minus the cycle minimum cold, for geometry, the exact model and the paper's model
alike.

One exact solve per distinct mesh: at a given pose the other output shaft's meshes are congruent
to this one's (the assembly's symmetry, checked on the poses by
:func:`gearcheck.geometry.bevel_mesh.congruent`), so they reuse its exact contact and get only
their own mesh bisection.

Meshes are pruned to the tooth halves that can touch (same triangles, smaller BVH, 3× faster
collide): for each big/small pair and each turning direction, the big gear's and the small gear's
flank halves of that direction (side +1 of each tooth for +, side −1 for −, see
:mod:`gearcheck.geometry.bevel_play`) on the teeth that pass the mesh zone during the cycle, root
lands and the blank left out. A tooth half carries its flank, its tip and heel/toe edges, so every
first contact (face or edge) lies in it; and because the other direction's flanks are not in the
mesh, each direction's contact is measured even where the other side already binds (cold, shim
0), which gives a negative play instead of a failed bisection.

Exact model: for the same poses and scales, :func:`gearcheck.geometry.bevel_play.big_gear_contact`
(analytic spherical-involute flanks, no mesh). Its contact angle brackets the bisection
(:data:`BRACKET_INSIDE_ARCMIN`, :data:`BRACKET_OUTSIDE_ARCMIN`, widened to the mesh-error bound if
the mesh needs it); the bracket is checked from both sides like any other, so the mesh result
stands on its own, and it must agree with the exact one within the mesh-error bound (converted
to an angle on the outer pitch radius d1/2) plus :data:`AGREEMENT_RELATIVE`.

Options: ``angles_per_cycle`` (default :data:`ANGLES_PER_CYCLE`) and ``shims_mm`` (default: the
template's study shims and 0; the template's own shim is always added).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel_mesh import congruent, drive_poses, play_period, tooth_half_mask, zone_azimuth
from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.differential.assembly import Layout
from gearcheck.mechanisms.differential.thermal import GearThermal, thermal_state
from gearcheck.sweep.bodies import Body, MeshData, submesh
from gearcheck.sweep.engine import Scene, bisect_contact
from gearcheck.sweep.tools import CountedScene

# Drive angles over one period of the output shafts' play (the whole cycle, see play_period).
ANGLES_PER_CYCLE = 12
# Bisection stops when the bracket on the big gear's turn is this narrow.
BISECTION_TOL_ARCMIN = 1e-4
# Bracket around the exact contact angle: chords lie inside convex flanks, so the mesh reaches
# contact no earlier than the exact flanks (less a little for the bisection and the exact model's
# sampling); later by its chord error, usually < 0.3′. If the bracket fails it is widened by the
# mesh-error bound, then by three times it.
BRACKET_INSIDE_ARCMIN = 0.05
BRACKET_OUTSIDE_ARCMIN = 0.3
# Pruning: extra teeth kept beyond the exact model's window and the cycle's turn.
PRUNE_EXTRA_TEETH = 1
STATES = ("warm", "cold")
DIRECTIONS = (1, -1)
OPTIONS = ("angles_per_cycle", "shims_mm")


# --------------------------------------------------------------------------------------------
# Meshes

def mesh_name(big: str, small: str, direction: int, part: str, state: str) -> str:
    return f"{big}|{small}|{'+' if direction > 0 else '-'}|{part}|{state}"


def pruned_meshes(bodies: Mapping[str, Body], layout: Layout) -> list[MeshData]:
    """Per big/small pair, direction and state: the two gears' tooth halves that can touch."""
    specs, thermal = layout.specs, layout.thermal
    big_spec, small_spec = specs.big, specs.small
    out = []
    cold = {n: bodies[n].scaled(thermal[n].scale, thermal[n].datum_local).mesh
            for n in layout.big_gears + layout.small_gears}
    for big in layout.big_gears:
        for small in layout.small_gears:
            b, s = bodies[big], bodies[small]
            # teeth near the mesh zone over the cycle: the big gear turns −1 pitch (its zone moves
            # +1 pitch in its own frame), the small gear +1 pitch (its zone moves −1 pitch)
            cb = round(zone_azimuth(b.pose, s.pose) / big_spec.angular_pitch_rad)
            cs = round(zone_azimuth(s.pose, b.pose) / small_spec.angular_pitch_rad)
            wb = ws = bp.teeth_window(big_spec, small_spec) + PRUNE_EXTRA_TEETH
            big_teeth = np.arange(cb - wb, cb + wb + 2)
            small_teeth = np.arange(cs - ws - 1, cs + ws + 1)
            for d in DIRECTIONS:
                mb = tooth_half_mask(b.mesh.vertices, b.mesh.faces, big_spec, d, big_teeth)
                ms = tooth_half_mask(s.mesh.vertices, s.mesh.faces, small_spec, d, small_teeth)
                for state in STATES:
                    big_mesh = b.mesh if state == "warm" else cold[big]
                    small_mesh = s.mesh if state == "warm" else cold[small]
                    out.append(submesh(big_mesh, mesh_name(big, small, d, "big", state), mb))
                    out.append(submesh(small_mesh, mesh_name(big, small, d, "small", state), ms))
    return out


# --------------------------------------------------------------------------------------------
# One measurement (a worker task: numpy + fcl only)

def _bisect_mesh(scene: Scene, big_mesh: str, small_mesh: str, big_pose: np.ndarray, small_pose: np.ndarray,
                 exact_rad: float, direction: int, bound_rad: float, tol_rad: float) -> dict:
    """Mesh contact turn of the big gear one way, bracketed around the exact one (contact proven
    from both sides), and whether the centred pose (turn 0) collides."""
    t0 = time.perf_counter()
    counted = CountedScene(scene)
    counted.set_pose(small_mesh, small_pose)

    def collides(turn: float) -> bool:
        counted.set_pose(big_mesh, big_pose @ bp.rot_z4(turn))
        return counted.collide(big_mesh, small_mesh)

    centred_collides = collides(0.0)
    inside = BRACKET_INSIDE_ARCMIN / bp.ARCMIN_PER_RAD
    outside = BRACKET_OUTSIDE_ARCMIN / bp.ARCMIN_PER_RAD
    bracket, widened = None, 0
    for widen in (0.0, bound_rad, 3.0 * bound_rad):
        try:
            bracket = bisect_contact(collides, exact_rad - direction * (inside + widen),
                                     exact_rad + direction * (outside + widen), tol_rad)
            break
        except ValueError:
            widened += 1
    if bracket is None:
        raise RuntimeError(f"{big_mesh} vs {small_mesh}: no contact bracket within 3× the mesh-error bound of the "
                           f"exact contact ({bp.arcmin(exact_rad):.4f}′): mesh and exact model disagree")
    return {"free_rad": bracket.free, "touching_rad": bracket.touching, "centred_collides": centred_collides,
            "calls": counted.queries, "mesh_s": time.perf_counter() - t0, "widened": widened}


def measure_contact(scene: Scene, big_exact: bp.PlacedGear, small_exact: bp.PlacedGear, direction: int,
                    meshes: list[tuple], tol_rad: float) -> dict:
    """Exact contact turn of the big gear one way (analytic flanks), then the mesh contact of
    each listed pair posed congruently to it: (big_mesh, small_mesh, big_pose, small_pose,
    bound_rad) — the pair itself and its congruent twins."""
    t0 = time.perf_counter()
    exact = bp.big_gear_contact(big_exact, small_exact, direction)
    exact_s = time.perf_counter() - t0
    mesh = [_bisect_mesh(scene, bm, sm, bpose, spose, exact.angle_rad, direction, bound, tol_rad)
            for bm, sm, bpose, spose, bound in meshes]
    return {"exact_rad": exact.angle_rad, "exact_on": exact.on, "exact_s": exact_s, "mesh": mesh}


# --------------------------------------------------------------------------------------------
# The plan

@dataclass(frozen=True)
class SweepSetup:
    """What the reduce step needs besides the task results (lives in the parent process)."""

    params: Any
    layout: Layout
    bodies: Mapping[str, Body]
    thermal_at: dict[float, dict[str, GearThermal]]
    shims: list[float]
    angles: np.ndarray
    period_rad: float
    owners: list[list[tuple]]  # per task: the (shim index, state, angle index, big, small, direction) measured
    exact_reused: int
    bound_mm: float  # the largest pair bound
    bound_arcmin: float  # that bound as an angle on d1/2
    pruned_meshes: int
    pruned_triangles_mean: float
    started: float  # perf_counter when the plan was made (wall time of the sweep)


def _shims(layout: Layout, shims_mm) -> list[float]:
    if shims_mm is None:
        shims_mm = list(layout.study_shims_mm) + [0.0]
    return sorted({round(float(s), 9) for s in list(shims_mm) + [layout.template_shim_mm]})


def make_plan(params, assembly: Assembly, bodies: Mapping[str, Body],
              options: Mapping[str, Any] | None = None) -> SweepPlan:
    """Sweep warm and cold over one cycle of the output shafts' play for each shim; one task per
    distinct exact contact (and direction), with the mesh bisections of every pair congruent to it."""
    from gearcheck.mechanisms.differential.reduce import reduce_sweep

    options = dict(options or {})
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ValueError(f"differential sweep: unknown options {unknown}; known: {list(OPTIONS)}")
    angles_per_cycle = int(options.get("angles_per_cycle", ANGLES_PER_CYCLE))
    layout: Layout = assembly.layout
    specs, template_shim = layout.specs, layout.template_shim_mm
    bigs, smalls = layout.big_gears, layout.small_gears
    shims = _shims(layout, options.get("shims_mm"))
    thermal = layout.thermal  # scales and datums: the same for every shim
    thermal_at = {s: thermal_state(params, specs=specs, shim_mm=s) for s in shims}  # datum shifts
    built = {n: bodies[n].pose for n in bigs + smalls}
    period = play_period(built, bigs, smalls, specs.big, specs.small)
    angles = np.arange(angles_per_cycle) / angles_per_cycle * period
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    tol_rad = BISECTION_TOL_ARCMIN / bp.ARCMIN_PER_RAD

    bound_mm = {}
    for big in bigs:
        for small in smalls:
            bound_mm[(big, small, "warm")] = bodies[big].error_bound_mm + bodies[small].error_bound_mm
            bound_mm[(big, small, "cold")] = (bodies[big].error_bound_mm * thermal[big].scale
                                              + bodies[small].error_bound_mm * thermal[small].scale)
    bound_max_mm = max(bound_mm.values())

    meshes = pruned_meshes(bodies, layout)
    tasks, owners, reused = [], [], 0
    for i, shim in enumerate(shims):
        for state in STATES:
            for k, phi in enumerate(angles):
                poses = drive_poses(built, bigs, smalls, specs.big, specs.small, phi, shim - template_shim)
                placed, mesh_pose = _placed(layout, poses, state, thermal_at[shim])
                groups, twins = _congruent_groups(layout, placed)
                reused += twins
                for gb, gs, members in groups:
                    for d in DIRECTIONS:
                        mesh_list = [(mesh_name(b, s, d, "big", state), mesh_name(b, s, d, "small", state),
                                      mesh_pose[b], mesh_pose[s], bound_mm[(b, s, state)] / d1_half)
                                     for b, s in members]
                        tasks.append((measure_contact, (placed[gb], placed[gs], d, mesh_list, tol_rad)))
                        # the (shim, state, k, big, small, d) measured in this task's mesh list
                        owners.append([(i, state, k, b, s, d) for b, s in members])
    # collide calls per pair, for progress: the centred pose, the two bracket ends, the bisection
    per_pair = 3 + math.ceil(math.log2((BRACKET_INSIDE_ARCMIN + BRACKET_OUTSIDE_ARCMIN) / BISECTION_TOL_ARCMIN))
    setup = SweepSetup(
        params=params, layout=layout, bodies=bodies, thermal_at=thermal_at, shims=shims, angles=angles,
        period_rad=period, owners=owners, exact_reused=reused, bound_mm=bound_max_mm,
        bound_arcmin=bound_max_mm / d1_half * bp.ARCMIN_PER_RAD, pruned_meshes=len(meshes),
        pruned_triangles_mean=float(np.mean([len(m.faces) for m in meshes])), started=time.perf_counter())
    return SweepPlan(meshes=meshes, tasks=tasks, reduce=functools.partial(reduce_sweep, setup),
                     weights=[per_pair * len(o) for o in owners], unit="collide call",
                     options={"angles_per_cycle": angles_per_cycle, "shims_mm": shims})


def _placed(layout: Layout, poses: dict[str, np.ndarray], state: str,
            thermal: dict[str, GearThermal]) -> tuple[dict[str, bp.PlacedGear], dict[str, np.ndarray]]:
    """The exact gears (pose about the apex, scale) and the meshes' poses, warm or cold."""
    placed, mesh_pose = {}, {}
    for name in layout.big_gears + layout.small_gears:
        spec = layout.specs.big if name in layout.big_gears else layout.specs.small
        if state == "warm":
            placed[name] = bp.PlacedGear(spec, poses[name])
            mesh_pose[name] = poses[name]
        else:
            th = thermal[name]
            placed[name] = bp.PlacedGear(spec, th.cold_pose_about_origin(poses[name]), th.scale)
            mesh_pose[name] = th.cold_pose(poses[name])
    return placed, mesh_pose


def _congruent_groups(layout: Layout, placed: dict[str, bp.PlacedGear]) -> tuple[list[tuple[str, str, list]], int]:
    """The big/small pairs at one pose grouped by congruence: one exact solve per distinct mesh. A
    pair congruent to one already listed (the other output shaft, by the assembly's symmetry)
    only gets its own mesh bisection, bracketed by that exact contact. Returns the groups (big,
    small, members) and how many pairs joined an earlier group."""
    big_spec, small_spec = layout.specs.big, layout.specs.small
    groups: list[tuple[str, str, list]] = []
    reused = 0
    for big in layout.big_gears:
        for small in layout.small_gears:
            q = np.linalg.inv(placed[big].pose) @ placed[small].pose
            for g in groups:
                gq = np.linalg.inv(placed[g[0]].pose) @ placed[g[1]].pose
                same_scales = placed[g[0]].scale == placed[big].scale and placed[g[1]].scale == placed[small].scale
                if same_scales and congruent(gq, q, big_spec, small_spec, tol=1e-7):
                    g[2].append((big, small))
                    reused += 1
                    break
            else:
                groups.append((big, small, [(big, small)]))
    return groups, reused
