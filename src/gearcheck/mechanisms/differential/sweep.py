"""The differential's sweep plan: angular play of the output shafts at several temperatures —
warm and the cold design point for each study shim, and at the template's shim also the ends of
the operating range and the storage minimum — measured with FCL on the built meshes and checked
against the exact-flank model; and the exact model alone over the whole operating and storage
ranges (:mod:`.temperature`), as tasks of the same plan.

Poses are data. At drive angle φ each small gear turns φ about its own axis and each big gear
−φ·z_small/z_big about its own (the pitch cones roll; carrier held), from the poses the build
placed them at (:func:`gearcheck.geometry.bevel_mesh.drive_poses`). Other shims than the built
one translate the big gears along their own axes by the shim difference; nothing else about the
geometry changes. A state at temperature T moves and shrinks (or grows) every gear by its own
materials about its own datum (:mod:`.thermal`, from warm to T), never a uniform scale of the
assembly; the meshes as built serve every state, the world scaled by the small gear's factor
(:func:`normalised_poses`). The extra states only at the template's shim: all shims × all states
would triple the mesh work for figures the exact model gives anyway.

Play of one output shaft: hold the small gears, turn the big gear about its own axis until a
flank touches, both ways (the bisection on ``collide`` from a bracket around the exact contact,
contact proven from both sides; found in few queries from a distance query's estimate or a
congruent pair's contact, :func:`_bisect_mesh`, giving the plain bisection's bracket). The big
gear meshes with *both* small gears, so each way it stops at the tighter of its two meshes: plus
= min over the small gears, minus = max; play = plus − minus, in arcmin on the big gear's axis.
That is the paper's "per side" backlash (one big/small mesh side of the shaft-to-shaft total,
which is twice it).

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

Exact model: for the same poses and scales, :func:`gearcheck.geometry.bevel_play.big_gear_contacts`
(analytic spherical-involute flanks, no mesh; all the sweep's contacts in one vectorised solve,
here in the planning process). Its contact angle brackets the bisection
(:data:`BRACKET_INSIDE_ARCMIN`, :data:`BRACKET_OUTSIDE_ARCMIN`, widened to the mesh-error bound if
the mesh needs it); the bracket is checked from both sides like any other, so the mesh result
stands on its own, and it must agree with the exact one within the mesh-error bound (converted
to an angle on the outer pitch radius d1/2) plus :data:`AGREEMENT_RELATIVE`.

Exact range: for each swept shim, the exact least play over the temperature grid of
:func:`.temperature.temperature_grid` (≤ 5 K steps over the operating and storage ranges), with
where its contacts lie, as tasks of :data:`RANGE_CHUNK` temperatures each (they share the workers
with the mesh bisections); the onset of binding is then solved in the reduce step.

Options: ``angles_per_cycle`` (default :data:`ANGLES_PER_CYCLE`), ``shims_mm`` (default: the
template's study shims and 0; the template's own shim is always added) and ``range_shims``
("all" swept shims, the default, or "template": the exact range at the template's shim only).
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
from gearcheck.geometry.bevel import BevelGearSpec
from gearcheck.geometry.bevel_mesh import ToothFaces, drive_poses, play_period, zone_azimuth
from gearcheck.mechanism import Assembly, SweepPlan
from gearcheck.mechanisms.differential.assembly import Layout
from gearcheck.mechanisms.differential.poses import gear_specs
from gearcheck.mechanisms.differential.temperature import (ANGLES_PER_CYCLE, congruent_groups, crossings,
                                                           exact_plays_or_unsolved, meshed_states, placed_gears,
                                                           temperature_grid)
from gearcheck.mechanisms.differential.thermal import GearThermal, thermal_state
from gearcheck.sweep.bodies import Body, MeshData, submesh
from gearcheck.geometry.bisect import bisect_predicted, remembered
from gearcheck.sweep.engine import Scene, bisect_contact
from gearcheck.sweep.tools import CountedScene

# Bisection stops when the bracket on the big gear's turn is this narrow.
BISECTION_TOL_ARCMIN = 1e-4
# Bracket around the exact contact angle: chords lie inside convex flanks, so the mesh reaches
# contact no earlier than the exact flanks (less a little for the bisection and the exact model's
# sampling); later by its chord error, usually < 0.3′. If the bracket fails it is widened by the
# mesh-error bound, then by three times it.
BRACKET_INSIDE_ARCMIN = 0.05
BRACKET_OUTSIDE_ARCMIN = 0.3
# Midpoints within this many bisection tolerances of a distance query's contact estimate are
# asked of the meshes; farther ones are given the side the estimate puts them on, then the final
# bracket is proven from both sides. The estimate is good to about one tolerance where the nearest
# mesh features stay the same up to contact, to about a hundred where they change: a narrow
# margin first, then a wide one (with the narrow try's answers), then the plain bisection.
NEWTON_MARGINS_TOL = (0.5, 160.0)
# Pruning: extra teeth kept beyond the exact model's window and the cycle's turn.
PRUNE_EXTRA_TEETH = 1
# The states measured at every shim (the others at the template's shim only).
EVERY_SHIM_STATES = ("warm", "cold")
DIRECTIONS = (1, -1)
OPTIONS = ("angles_per_cycle", "shims_mm", "range_shims")
# Exact range tasks: temperatures per task; their progress weight per temperature, in contacts
# (one temperature's exact solves take about as long as this many mesh contacts, one pair one way).
RANGE_CHUNK = 6
RANGE_WEIGHT_PER_TEMPERATURE = 2


# --------------------------------------------------------------------------------------------
# Meshes

def mesh_name(big: str, small: str, direction: int, part: str, variant: str) -> str:
    return f"{big}|{small}|{'+' if direction > 0 else '-'}|{part}|{variant}"


def mesh_variant(thermal: Mapping[str, GearThermal], big: str, small: str, state: str) -> str:
    """Which pruned big-gear mesh a state's pair uses: "" (as built) when both gears scale alike,
    else the state's own (scaled by the ratio of the two gears' factors)."""
    return "" if thermal[big].scale == thermal[small].scale else state


def normalised_poses(thermal: Mapping[str, GearThermal], big: str, small: str, big_pose: np.ndarray,
                     small_pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The poses of the pair in a thermal state as meshes *as built* (the big one scaled by the
    ratio r of the two factors about its frame origin, r = 1 when both are steel: see
    :func:`mesh_variant`).

    A gear in a state is its mesh scaled by f about its frame origin, then posed
    (:meth:`.GearThermal.cold_pose_about_origin`): x = R·(f·p) + t = f·(R·p + t/f). Scaling the
    whole world by 1/f_small therefore leaves the small gear as built, posed (R, t/f_small), and
    the big one scaled by r = f_big/f_small, posed (R, t/f_small). A uniform scale of the world
    changes no angle and no contact: the turn to contact is the same, so every state shares the
    meshes as built instead of one scaled copy (and one BVH) per state."""
    tb, ts = thermal[big], thermal[small]
    pb, ps = tb.cold_pose_about_origin(big_pose), ts.cold_pose_about_origin(small_pose)
    pb[:3, 3] /= ts.scale
    ps[:3, 3] /= ts.scale
    return pb, ps


def pruned_meshes(bodies: Mapping[str, Body], layout: Layout, thermal_by_state: Mapping[str, dict[str, GearThermal]]
                  ) -> list[MeshData]:
    """Per big/small pair and direction: the two gears' tooth halves that can touch, as built
    (shared by every state whose gears scale alike, see :func:`normalised_poses`), and for a
    state where they do not, the big gear's scaled by the ratio of the factors."""
    specs = layout.specs
    big_spec, small_spec = specs.big, specs.small
    out = []
    located: dict[str, ToothFaces] = {}
    for n in layout.big_gears + layout.small_gears:  # identical parts share their mesh: located once
        shared = _mesh_owner(bodies, layout, n)
        if shared not in located:
            located[shared] = ToothFaces.of(bodies[n].mesh.vertices, bodies[n].mesh.faces,
                                            big_spec if n in layout.big_gears else small_spec)
        located[n] = located[shared]
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
                mb = located[big].half_mask(d, big_teeth, big_spec)
                ms = located[small].half_mask(d, small_teeth, small_spec)
                variants = dict.fromkeys(mesh_variant(th, big, small, state) for state, th in thermal_by_state.items())
                for variant in variants:
                    mesh = b.mesh
                    if variant:
                        th = thermal_by_state[variant]
                        mesh = b.scaled(th[big].scale / th[small].scale).mesh
                    out.append(submesh(mesh, mesh_name(big, small, d, "big", variant), mb))
                out.append(submesh(s.mesh, mesh_name(big, small, d, "small", ""), ms))
    return out


def whole_meshes(bodies: Mapping[str, Body], layout: Layout, thermal_by_state: Mapping[str, dict[str, GearThermal]]
                 ) -> Scene:
    """The gears' whole (unpruned) meshes as built, one per distinct mesh (the two big gears share
    one, the two small gears another), and for a state whose gears scale differently the big
    gear's scaled by the ratio of the factors (see :func:`normalised_poses`): the reduce step's
    worst-pose distances, in a scene of their own (its BVHs built by the calling process while
    the workers start). Named by :func:`whole_name`."""
    meshes: dict[str, MeshData] = {}
    for big in layout.big_gears:
        for small in layout.small_gears:
            for th in thermal_by_state.values():
                for gear, ratio in ((big, th[big].scale / th[small].scale), (small, 1.0)):
                    name = whole_name(bodies, layout, gear, ratio)
                    if name not in meshes:
                        body = bodies[gear] if ratio == 1.0 else bodies[gear].scaled(ratio)
                        meshes[name] = MeshData(name, body.mesh.vertices, body.mesh.faces)
    return Scene(list(meshes.values()))


def _mesh_owner(bodies: Mapping[str, Body], layout: Layout, gear: str) -> str:
    """The first gear of the layout whose mesh is ``gear``'s (identical parts share the arrays)."""
    mesh = bodies[gear].mesh
    return next(g for g in layout.big_gears + layout.small_gears
                if bodies[g].mesh.vertices is mesh.vertices and bodies[g].mesh.faces is mesh.faces)


def whole_name(bodies: Mapping[str, Body], layout: Layout, gear: str, ratio: float) -> str:
    """The whole mesh of ``gear`` scaled by ``ratio``, named by the gear that owns the mesh
    (:func:`_mesh_owner`)."""
    return f"whole|{_mesh_owner(bodies, layout, gear)}|{ratio!r}"


def tooth_of(pose: np.ndarray, point: np.ndarray, spec: BevelGearSpec) -> int:
    """The tooth of a gear posed at ``pose`` (frame → world) whose faces lie about the world
    ``point``: its azimuth in the gear's frame over the angular pitch, rounded, as
    :class:`ToothFaces` numbers the faces by their centroids."""
    local = pose[:3, :3].T @ (np.asarray(point, float) - pose[:3, 3])
    return int(np.mod(np.round(np.arctan2(local[1], local[0]) / spec.angular_pitch_rad), spec.teeth))


def tooth_name(mesh: str, tooth: int) -> str:
    return f"{mesh}|tooth {tooth}"


def cut_tooth(scene: Scene, mesh: str, tooth: int, spec: BevelGearSpec) -> str | None:
    """The faces of a pruned mesh on one tooth (as :class:`ToothFaces` numbers them), added to the
    scene once (the worker's; its BVH built on first use) as :func:`tooth_name`; None when the
    mesh holds no face of that tooth. A distance query between the two teeth at an exact contact
    costs about half of one between the pruned meshes, and finds the same nearest points
    wherever the contact lies on those teeth."""
    name = tooth_name(mesh, tooth)
    if name not in scene.names:
        whole = scene.mesh(mesh)
        keep = ToothFaces.of(whole.vertices, whole.faces, spec).tooth == tooth
        if not keep.any():
            return None
        scene.add(submesh(whole, name, keep))
    return name


# --------------------------------------------------------------------------------------------
# One measurement (a worker task: numpy + fcl only)

def _newton_turn(scene: CountedScene, big_mesh: str, small_mesh: str, big_pose: np.ndarray, turn: float,
                 direction: int) -> float | None:
    """Where the big gear's turn closes the mesh gap, from one distance query at ``turn``: the
    gap d between the nearest points closes at the rate n·(a × (p − o)) per radian (n the unit
    normal from the big gear's nearest point p to the small gear's, a and o the big gear's axis
    and origin), so contact is expected d / rate further on. An estimate only (None when the pose
    already touches or the gap does not close): the contact is still proven by collisions."""
    pose = big_pose @ bp.rot_z4(turn)
    scene.set_pose(big_mesh, pose)
    near = scene.distance(big_mesh, small_mesh)
    gap = near.point_b - near.point_a
    d = float(np.linalg.norm(gap))
    if not d > 0.0:
        return None
    rate = float(np.dot(gap / d, np.cross(pose[:3, 2], near.point_a - pose[:3, 3])))
    if not rate * direction > 0.0:
        return None
    return turn + d / rate


def _bisect_mesh(scene: Scene, big_mesh: str, small_mesh: str, big_pose: np.ndarray, small_pose: np.ndarray,
                 exact_rad: float, direction: int, bound_rad: float, tol_rad: float,
                 hint: float | None = None, teeth: tuple[str, str] | None = None) -> dict:
    """Mesh contact turn of the big gear one way, bracketed around the exact one (contact proven
    from both sides), and whether the centred pose (turn 0) collides.

    The bracket is the bisection's, started at the exact contact (widened by the mesh-error bound
    if it does not hold), found in few collisions where the contact can be expected: at ``hint``
    (a congruent pair's measured contact) or else where one distance query puts it
    (:func:`_newton_turn`; between ``teeth``, the two teeth of the exact contact cut from the
    meshes, if given, else between the meshes); :func:`gearcheck.geometry.bisect.bisect_predicted` replays the
    halving, asks only the midpoints near the estimate, and proves the final bracket from both
    sides. If the estimate lies outside the first bracket, or the final bracket does not hold, the
    plain bisection runs (widening the bracket as needed)."""
    t0 = time.perf_counter()
    counted = CountedScene(scene)
    counted.set_pose(small_mesh, small_pose)

    def collides_at(turn: float) -> bool:
        counted.set_pose(big_mesh, big_pose @ bp.rot_z4(turn))
        return counted.collide(big_mesh, small_mesh)

    collides, asked = remembered(collides_at)  # every answer, shared by the tries below
    centred_collides = collides(0.0)
    inside = BRACKET_INSIDE_ARCMIN / bp.ARCMIN_PER_RAD
    outside = BRACKET_OUTSIDE_ARCMIN / bp.ARCMIN_PER_RAD
    levels = [(exact_rad - direction * (inside + w), exact_rad + direction * (outside + w))
              for w in (0.0, bound_rad, 3.0 * bound_rad)]
    bracket, widened, how = None, 0, "bisection"
    newton: list[float | None] = []  # the distance query's estimate, once asked

    def estimate_of(guess: float | None) -> float | None:
        if guess is not None:
            return guess
        if not newton:  # asked at the exact contact (chords are free there), else at the bracket's free end
            lo, hi = levels[0]
            asks = [(big_mesh, small_mesh, exact_rad), (big_mesh, small_mesh, lo)]
            if teeth is not None:  # the contact's two teeth first: half the cost of the meshes
                counted.set_pose(teeth[1], small_pose)
                asks.insert(0, (*teeth, exact_rad))
            for big, small, start in asks:
                estimate = _newton_turn(counted, big, small, big_pose, start, direction)
                if estimate is not None and (estimate - lo) * direction > 0.0 and (hi - estimate) * direction > 0.0:
                    break
            newton.append(estimate)
        return newton[0]

    guesses: list[tuple[float | None, float, str]] = [(hint, 0.0, "hint")] if hint is not None else []
    guesses += [(None, m * tol_rad, "distance") for m in NEWTON_MARGINS_TOL]
    for guess, margin, label in guesses:
        estimate = estimate_of(guess)
        if estimate is None:
            continue
        lo, hi = levels[0]
        if not ((estimate - lo) * direction > margin and (hi - estimate) * direction > margin):
            continue  # expected outside the first bracket: the plain path decides how far to widen
        found = bisect_predicted(collides, lo, hi, tol_rad, estimate, margin, asked=asked)
        if found is not None:
            bracket, how = found[0], label
            break
    if bracket is None:
        for widen, (lo, hi) in enumerate(levels):
            try:
                bracket = bisect_contact(collides, lo, hi, tol_rad)
                widened = widen
                break
            except ValueError:
                continue
    if bracket is None:
        raise RuntimeError(f"{big_mesh} vs {small_mesh}: no contact bracket within 3× the mesh-error bound of the "
                           f"exact contact ({bp.arcmin(exact_rad):.4f}′): mesh and exact model disagree")
    return {"free_rad": bracket.free, "touching_rad": bracket.touching, "centred_collides": centred_collides,
            "calls": counted.queries, "mesh_s": time.perf_counter() - t0, "widened": widened, "found_by": how}


def _mesh_names(meshes: list[tuple]) -> list[str]:
    """The mesh names a contact task uses (its pairs' big and small meshes)."""
    return [name for entry in meshes for name in entry[:2]]


def measure_contact(scene: Scene, exact_rad: float, direction: int, meshes: list[tuple], tol_rad: float,
                    contact_teeth: tuple[tuple[int, BevelGearSpec], tuple[int, BevelGearSpec]] | None = None
                    ) -> dict:
    """The mesh contact of each listed pair posed congruently to one exact contact (solved in the
    planning process, ``exact_rad``): (big_mesh, small_mesh, big_pose, small_pose, bound_rad) —
    the pair itself and its congruent twins (each twin expects the contact where the pair before
    it had it, and proves its own). ``contact_teeth``: the tooth (and gear design) of the exact
    contact on the first pair's big and small gear, for its distance estimate (:func:`cut_tooth`)."""
    teeth = None
    if contact_teeth is not None:
        cut = [cut_tooth(scene, name, k, spec) for name, (k, spec) in zip(meshes[0][:2], contact_teeth, strict=True)]
        teeth = (cut[0], cut[1]) if cut[0] is not None and cut[1] is not None else None
    scene.build(_mesh_names(meshes) + list(teeth or ()))  # BVHs first: not part of a measurement's time
    mesh = []
    hint = None
    for bm, sm, bpose, spose, bound in meshes:
        mesh.append(_bisect_mesh(scene, bm, sm, bpose, spose, exact_rad, direction, bound, tol_rad, hint,
                                 teeth if hint is None else None))
        hint = 0.5 * (mesh[-1]["free_rad"] + mesh[-1]["touching_rad"])
    return {"exact_rad": exact_rad, "mesh": mesh}


def exact_range_task(_scene: Scene, params, shim_mm: float, temperatures_C: list[float], angles_per_cycle: int
                     ) -> dict:
    """The exact model alone (no mesh) at some temperatures of the range: the plays over the cycle
    at its drive angles (the reduce step refines the leasts that can decide a range, over the whole
    range: :func:`.temperature.refined`) and where the least-play contacts lie (plain arrays), and
    the onset of binding wherever the least play crosses zero between two of them (solved here,
    beside the other tasks, rather than after them all; a crossing between two tasks' temperatures
    is solved in the reduce step)."""
    t0 = time.perf_counter()
    specs = gear_specs(params)
    plays = exact_plays_or_unsolved(params, shim_mm, temperatures_C, specs=specs, angles_per_cycle=angles_per_cycle)
    t1 = time.perf_counter()
    onsets = crossings(params, shim_mm, plays, specs=specs, angles_per_cycle=angles_per_cycle)
    return {"plays": plays, "onsets": onsets, "exact_s": t1 - t0, "onset_s": time.perf_counter() - t1}


# --------------------------------------------------------------------------------------------
# The plan

@dataclass(frozen=True)
class SweepSetup:
    """What the reduce step needs besides the task results (lives in the parent process)."""

    params: Any
    layout: Layout
    bodies: Mapping[str, Body]
    states: list[tuple[str, float]]  # (name, °C) of every state measured (at the template's shim)
    shim_states: list[list[int]]  # per shim: the indices of the states measured at it
    thermal_at: dict[tuple[float, str], dict[str, GearThermal]]  # (shim, state) → the gears' state
    shims: list[float]
    angles: np.ndarray
    period_rad: float
    owners: list[list[tuple]]  # per mesh task: the (shim index, state, angle index, big, small, direction) measured
    range_tasks: list[tuple[int, int]]  # per range task: (shim index, its task index)
    exact_solves: int
    exact_reused: int
    exact_s: float  # the planning process's exact solve (all contacts, one vectorised batch)
    bound_mm: float  # the largest pair bound
    bound_arcmin: float  # that bound as an angle on d1/2
    pruned_meshes: int
    pruned_triangles_mean: float
    whole: Scene  # the whole meshes for the worst-pose distances (:func:`whole_meshes`)
    started: float  # perf_counter when the plan was made (wall time of the sweep)


def _shims(layout: Layout, shims_mm) -> list[float]:
    if shims_mm is None:
        shims_mm = list(layout.study_shims_mm) + [0.0]
    # the template's shim exactly as given (its key in every table); others rounded to 1e-9 mm and
    # dropped where they repeat it (a study's shim need not be a round figure)
    out = [float(layout.template_shim_mm)]
    for s in sorted(round(float(x), 9) for x in shims_mm):
        if all(not math.isclose(s, o, abs_tol=1e-9) for o in out):
            out.append(s)
    return sorted(out)


def make_plan(params, assembly: Assembly, bodies: Mapping[str, Body],
              options: Mapping[str, Any] | None = None) -> SweepPlan:
    """Sweep each shim's states over one cycle of the output shafts' play; one mesh task per
    distinct exact contact (and direction), with the mesh bisections of every pair congruent to
    it; and the exact range tasks."""
    from gearcheck.mechanisms.differential.reduce import FAIL_STATES, reduce_sweep

    options = dict(options or {})
    unknown = sorted(set(options) - set(OPTIONS))
    if unknown:
        raise ValueError(f"differential sweep: unknown options {unknown}; known: {list(OPTIONS)}")
    angles_per_cycle = int(options.get("angles_per_cycle", ANGLES_PER_CYCLE))
    range_shims = options.get("range_shims", "all")
    if range_shims not in ("all", "template"):
        raise ValueError(f"differential sweep: range_shims must be 'all' or 'template', not {range_shims!r}")
    started = time.perf_counter()
    layout: Layout = assembly.layout
    specs, template_shim = layout.specs, layout.template_shim_mm
    bigs, smalls = layout.big_gears, layout.small_gears
    shims = _shims(layout, options.get("shims_mm"))
    states = meshed_states(params)
    names = [n for n, _ in states]
    every = [i for i, n in enumerate(names) if n in EVERY_SHIM_STATES]
    shim_states = [list(range(len(states))) if math.isclose(s, template_shim, abs_tol=1e-9) else every for s in shims]
    thermal_at = {(s, name): thermal_state(params, cold_C=temp, specs=specs, shim_mm=s)
                  for s, js in zip(shims, shim_states, strict=True) for name, temp in (states[j] for j in js)}
    built = {n: bodies[n].pose for n in bigs + smalls}
    period = play_period(built, bigs, smalls, specs.big, specs.small)
    angles = np.arange(angles_per_cycle) / angles_per_cycle * period
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    tol_rad = BISECTION_TOL_ARCMIN / bp.ARCMIN_PER_RAD

    scales = {name: thermal_at[(template_shim, name)] for name in names}  # the same for every shim
    bound_mm = {(b, s, name): bodies[b].error_bound_mm * th[b].scale + bodies[s].error_bound_mm * th[s].scale
                for name, th in scales.items() for b in bigs for s in smalls}
    bound_max_mm = max(bound_mm.values())

    meshes = pruned_meshes(bodies, layout, scales)
    pending, reused, exact, exact_s, solved = _exact_contacts(layout, built, shims, shim_states, names, angles,
                                                              thermal_at, bound_mm)
    tasks: list[tuple] = []
    owners: list[list[tuple]] = []
    weights: list[int] = []
    for n, (keys, pairs) in enumerate(pending):
        for d in DIRECTIONS:
            mesh_list = [(mesh_name(b, s, d, "big", variant), mesh_name(b, s, d, "small", ""), bpose, spose, bound)
                         for b, s, bpose, spose, bound, variant in pairs]
            c = exact[d][n]  # its teeth on the first pair (cut from the meshes by the worker)
            teeth = ((tooth_of(solved[n][0].turned(c.angle_rad).pose, c.point, specs.big), specs.big),
                     (tooth_of(solved[n][1].pose, c.point, specs.small), specs.small))
            tasks.append((measure_contact, (c.angle_rad, d, mesh_list, tol_rad, teeth)))
            owners.append([key + (d,) for key in keys])
            weights.append(len(pairs))
    range_tasks = _range_tasks(params, shims, template_shim, range_shims, angles_per_cycle, tasks, weights)
    setup = SweepSetup(
        params=params, layout=layout, bodies=bodies, states=states, shim_states=shim_states, thermal_at=thermal_at,
        shims=shims, angles=angles, period_rad=period, owners=owners, range_tasks=range_tasks,
        exact_solves=len(pending) * len(DIRECTIONS), exact_reused=reused, exact_s=exact_s, bound_mm=bound_max_mm,
        bound_arcmin=bound_max_mm / d1_half * bp.ARCMIN_PER_RAD, pruned_meshes=len(meshes),
        pruned_triangles_mean=float(np.mean([len(m.faces) for m in meshes])), started=started,
        whole=whole_meshes(bodies, layout, {n: th for n, th in scales.items() if n in FAIL_STATES}))
    return SweepPlan(meshes=meshes, tasks=tasks, reduce=functools.partial(reduce_sweep, setup),
                     weights=weights, unit="contact", order=run_order(tasks, range_tasks, weights),
                     first=setup.whole.build,
                     options={"angles_per_cycle": angles_per_cycle, "shims_mm": shims, "range_shims": range_shims})


def run_order(tasks: list[tuple], range_tasks: list[tuple[int, int]], weights: list[int]) -> list[int]:
    """The order to run the tasks in: mesh tasks grouped by the meshes they use (a process taking a
    run of them builds a few of the plan's BVHs, not all), in plan order within a group; the groups
    in two halves of about equal weight with the exact range tasks (no mesh) between them. The
    spawned workers take tasks from the front and the calling process from the back
    (:class:`gearcheck.executor.ProcessExecutor`), so on two processes each builds the BVHs of its
    own half only, and they meet in the range tasks, which take up the difference (the calling
    process first builds the whole meshes' BVHs for the worst poses)."""
    ranged = {task for _, task in range_tasks}

    def meshes_of(n: int) -> tuple[str, ...]:
        return tuple(sorted(_mesh_names(tasks[n][1][2])))

    groups: dict[tuple[str, ...], list[int]] = {}
    for n in range(len(tasks)):
        if n not in ranged:
            groups.setdefault(meshes_of(n), []).append(n)
    ordered = [groups[key] for key in sorted(groups)]
    sizes = np.cumsum([0] + [sum(weights[n] for n in group) for group in ordered])
    half = int(np.argmin(np.abs(sizes - sizes[-1] / 2.0)))
    front, back = ordered[:half], ordered[half:]
    return [n for group in front for n in group] + sorted(ranged) + [n for group in back for n in group]


def _exact_contacts(layout: Layout, built: Mapping[str, np.ndarray], shims: list[float], shim_states: list[list[int]],
                    names: list[str], angles: np.ndarray, thermal_at: Mapping, bound_mm: Mapping):
    """Every distinct exact contact of the sweep (pairs grouped by congruence at each pose), solved
    in one vectorised batch per direction. Returns per distinct pair its owners (shim index,
    state, angle index, big, small) and its mesh pairs (big, small, mesh poses, bound as an angle),
    how many pairs reuse a solve, the contacts per direction, the solve's time and the solved
    gears (big, small) per distinct pair."""
    specs, template_shim = layout.specs, layout.template_shim_mm
    bigs, smalls = layout.big_gears, layout.small_gears
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    solve: list[tuple[bp.PlacedGear, bp.PlacedGear]] = []
    pending: list[tuple[list[tuple], list[tuple]]] = []
    reused = 0
    for i, shim in enumerate(shims):
        for j in shim_states[i]:
            state = names[j]
            thermal = thermal_at[(shim, state)]
            for k, phi in enumerate(angles):
                poses = drive_poses(built, bigs, smalls, specs.big, specs.small, phi, shim - template_shim)
                placed = placed_gears(specs, poses, thermal)
                groups, twins = congruent_groups(placed, specs.big, specs.small, bigs, smalls)
                reused += twins
                for gb, gs, members in groups:
                    solve.append((placed[gb], placed[gs]))
                    pending.append(([(i, state, k, b, s) for b, s in members],
                                    [(b, s, *normalised_poses(thermal, b, s, poses[b], poses[s]),
                                      bound_mm[(b, s, state)] / d1_half, mesh_variant(thermal, b, s, state))
                                     for b, s in members]))
    t0 = time.perf_counter()
    exact = {d: bp.big_gear_contacts([p[0] for p in solve], [p[1] for p in solve], d) for d in DIRECTIONS}
    return pending, reused, exact, time.perf_counter() - t0, solve


def _range_tasks(params, shims: list[float], template_shim: float, range_shims: str, angles_per_cycle: int,
                 tasks: list[tuple], weights: list[int]) -> list[tuple[int, int]]:
    """Append the exact range tasks (the whole grid at each shim, or the template's, in chunks);
    returns (shim index, task index) of each."""
    grid = temperature_grid(params).tolist()
    out = []
    for i, shim in enumerate(shims):
        if range_shims == "template" and not math.isclose(shim, template_shim, abs_tol=1e-9):
            continue
        for c in range(0, len(grid), RANGE_CHUNK):
            chunk = grid[c:c + RANGE_CHUNK]
            out.append((i, len(tasks)))
            tasks.append((exact_range_task, (params, shim, chunk, angles_per_cycle)))
            weights.append(RANGE_WEIGHT_PER_TEMPERATURE * len(chunk))
    return out
