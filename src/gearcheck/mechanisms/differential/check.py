"""Differential sweep (seed 000, issue 10): angular play of the output shafts, warm and cold, for
each study shim — measured with FCL on the built meshes and checked against the exact-flank model.

Poses are data. At drive angle φ each small gear turns φ about its own axis and each big gear
−φ·z_small/z_big about its own (the pitch cones roll; carrier held), from the poses the build
placed them at (:mod:`.poses`). Other shims than the built one translate the big gears along their
own axes by the shim difference; nothing else about the geometry changes. The cold state moves and
shrinks every gear by its own materials about its own datum (:mod:`.thermal`), never a uniform
scale of the assembly.

Play of one output shaft: hold the small gears, turn the big gear about its own axis until a
flank touches, both ways (bisection on ``collide``, :func:`gearcheck.sweep.engine.bisect_contact`,
contact proven from both sides). The big gear meshes with *both* small gears, so each way it stops
at the tighter of its two meshes: plus = min over the small gears, minus = max; play = plus −
minus, in arcmin on the big gear's axis. That is the paper's "per side" backlash (one big/small
mesh side of the shaft-to-shaft total, which is twice it).

Cycle. Identical teeth: one small-gear tooth pitch of drive repeats every pose. With z_big odd
(33) each big gear meets its two small gears half a tooth apart, so its play repeats every half
pitch (:func:`play_period` checks this on the poses); :data:`ANGLES_PER_CYCLE` drive angles over
that period cover the whole cycle, and each big gear's two meshes together pass twice as many
phases of one full mesh cycle. The cold drop is the cycle minimum warm minus the cycle minimum
cold, for geometry, the exact model and the paper's model alike.

One exact solve per distinct mesh: at a given pose the other output shaft's meshes are congruent
to this one's (the assembly's symmetry, checked on the poses by :func:`_congruent`), so they reuse
its exact contact and get only their own mesh bisection.

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
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry.bevel import BevelGearSpec
from gearcheck.mechanisms.differential import PAPER, PAPER_SHIM_MM, PAPER_TEMPERATURE_DROP_K, analyse_params, analysis
from gearcheck.mechanisms.differential.poses import assembly_poses, gear_specs
from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS, GearThermal, thermal_state
from gearcheck.sweep.engine import Body, MeshData, Scene, bisect_contact
from gearcheck.sweep.pool import default_workers, map_scene
from gearcheck.sweep.result import CheckResult, Clearance, Comparison, Plot, Series, Verdict, WorstPose

SECTION = "differential"

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
# Mesh vs exact: within the mesh-error bound (as an angle on d1/2) plus this fraction.
AGREEMENT_RELATIVE = 0.02
# Pruning: extra teeth kept beyond the exact model's window and the cycle's turn; a triangle
# counts as root land (dropped) when no vertex rises this far above the root cone.
PRUNE_EXTRA_TEETH = 1
ROOT_LAND_MARGIN_RAD = 1e-5
STATES = ("warm", "cold")
DIRECTIONS = (1, -1)


# --------------------------------------------------------------------------------------------
# Poses and meshes

def check_bodies(bodies: dict[str, Body], specs, template_shim_mm: float) -> None:
    """The bodies must be this template's gears, placed as the build placed them."""
    expected = assembly_poses(specs, template_shim_mm).as_dict()
    for name, pose in expected.items():
        if name not in bodies:
            raise ValueError(f"missing body {name!r}: expected the differential's four gears")
        if not np.allclose(bodies[name].pose, pose, atol=1e-9):
            raise ValueError(f"{name}: pose differs from the template's assembly (built with other parameters?)")


def warm_poses(bodies: dict[str, Body], specs, shim_mm: float, template_shim_mm: float,
               drive_angle: float) -> dict[str, np.ndarray]:
    """Gear frame → world at a drive angle, warm, for a shim (big gears shifted along their axes
    by the difference to the built shim)."""
    out = {}
    big_turn = bp.conjugate_big_turn(specs.big, specs.small, drive_angle)
    for name in BIG_GEARS:
        pose = bodies[name].pose
        out[name] = bp.translation4((shim_mm - template_shim_mm) * pose[:3, 2]) @ pose @ bp.rot_z4(big_turn)
    for name in SMALL_GEARS:
        out[name] = bodies[name].pose @ bp.rot_z4(drive_angle)
    return out


def _zone_azimuth(this_pose: np.ndarray, other_pose: np.ndarray) -> float:
    axis = this_pose[:3, :3].T @ other_pose[:3, 2]
    return math.atan2(axis[1], axis[0])


def tooth_half_mask(vertices: np.ndarray, faces: np.ndarray, spec: BevelGearSpec, side: int,
                    teeth: np.ndarray) -> np.ndarray:
    """Faces (own frame) on the ``side`` half of the given teeth, above the root land: the side
    of a triangle is the sign of its centroid's azimuth from the nearest tooth centre."""
    pitch = spec.angular_pitch_rad
    centroid = vertices[faces].mean(axis=1)
    azimuth = np.arctan2(centroid[:, 1], centroid[:, 0])
    tooth = np.round(azimuth / pitch)
    offset = azimuth - tooth * pitch
    polar = np.arctan2(np.hypot(vertices[:, 0], vertices[:, 1]), vertices[:, 2])
    above_root = (polar[faces] > spec.root_angle_rad + ROOT_LAND_MARGIN_RAD).any(axis=1)
    in_window = np.isin(np.mod(tooth, spec.teeth), np.mod(teeth, spec.teeth))
    return above_root & in_window & (np.sign(offset) == side)


def submesh(name: str, vertices: np.ndarray, faces: np.ndarray, mask: np.ndarray) -> MeshData:
    kept = faces[mask]
    used = np.unique(kept)
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return MeshData(name, np.ascontiguousarray(vertices[used]), remap[kept])


def mesh_name(big: str, small: str, direction: int, part: str, state: str) -> str:
    return f"{big}|{small}|{'+' if direction > 0 else '-'}|{part}|{state}"


def pruned_meshes(bodies: dict[str, Body], specs, thermal: dict[str, GearThermal]) -> list[MeshData]:
    """Per big/small pair, direction and state: the two gears' tooth halves that can touch."""
    big_spec, small_spec = specs.big, specs.small
    out = []
    cold = {n: bodies[n].scaled(thermal[n].scale, thermal[n].datum_local).mesh.vertices
            for n in BIG_GEARS + SMALL_GEARS}
    for big in BIG_GEARS:
        for small in SMALL_GEARS:
            b, s = bodies[big], bodies[small]
            # teeth near the mesh zone over the cycle: the big gear turns −1 pitch (its zone moves
            # +1 pitch in its own frame), the small gear +1 pitch (its zone moves −1 pitch)
            cb = round(_zone_azimuth(b.pose, s.pose) / big_spec.angular_pitch_rad)
            cs = round(_zone_azimuth(s.pose, b.pose) / small_spec.angular_pitch_rad)
            wb = ws = bp.teeth_window(big_spec, small_spec) + PRUNE_EXTRA_TEETH
            big_teeth = np.arange(cb - wb, cb + wb + 2)
            small_teeth = np.arange(cs - ws - 1, cs + ws + 1)
            for d in DIRECTIONS:
                mb = tooth_half_mask(b.mesh.vertices, b.mesh.faces, big_spec, d, big_teeth)
                ms = tooth_half_mask(s.mesh.vertices, s.mesh.faces, small_spec, d, small_teeth)
                for state in STATES:
                    vb = b.mesh.vertices if state == "warm" else cold[big]
                    vs = s.mesh.vertices if state == "warm" else cold[small]
                    out.append(submesh(mesh_name(big, small, d, "big", state), vb, b.mesh.faces, mb))
                    out.append(submesh(mesh_name(big, small, d, "small", state), vs, s.mesh.faces, ms))
    return out


# --------------------------------------------------------------------------------------------
# One measurement (runs in a worker: numpy + fcl only)

def _bisect_mesh(scene: Scene, big_mesh: str, small_mesh: str, big_pose: np.ndarray, small_pose: np.ndarray,
                 exact_rad: float, direction: int, bound_rad: float, tol_rad: float) -> dict:
    """Mesh contact turn of the big gear one way, bracketed around the exact one (contact proven
    from both sides), and whether the centred pose (turn 0) collides."""
    t0 = time.perf_counter()
    calls = 0
    scene.set_pose(small_mesh, small_pose)

    def collides(turn: float) -> bool:
        nonlocal calls
        calls += 1
        scene.set_pose(big_mesh, big_pose @ bp.rot_z4(turn))
        return scene.collide(big_mesh, small_mesh)

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
            "calls": calls, "mesh_s": time.perf_counter() - t0, "widened": widened}


def measure_contact(scene: Scene, big_exact: bp.PlacedGear, small_exact: bp.PlacedGear, direction: int,
                    meshes: list[tuple], tol_rad: float) -> dict:
    """Exact contact turn of the big gear one way (analytic flanks), then the mesh contact of
    each listed pair posed congruently to it: (big_mesh, small_mesh, big_pose, small_pose,
    bound_rad) — the pair itself and its congruent twins (see :func:`congruent_pairs`)."""
    t0 = time.perf_counter()
    exact = bp.big_gear_contact(big_exact, small_exact, direction)
    exact_s = time.perf_counter() - t0
    mesh = [_bisect_mesh(scene, bm, sm, bpose, spose, exact.angle_rad, direction, bound, tol_rad)
            for bm, sm, bpose, spose, bound in meshes]
    return {"exact_rad": exact.angle_rad, "exact_on": exact.on, "exact_s": exact_s, "mesh": mesh}


def _congruent(q1: np.ndarray, q2: np.ndarray, big: BevelGearSpec, small: BevelGearSpec, tol: float = 1e-9) -> bool:
    """Two big/small pairs, given as small-frame → big-frame transforms, are the same mesh when
    q2 = Rz(k·pitch_big)·q1·Rz(j·pitch_small) for whole k, j (identical teeth relabelled)."""
    a1 = math.atan2(q1[1, 2], q1[0, 2])
    a2 = math.atan2(q2[1, 2], q2[0, 2])
    k = (a2 - a1) / big.angular_pitch_rad
    if abs(k - round(k)) > tol:
        return False
    m = np.linalg.inv(bp.rot_z4(round(k) * big.angular_pitch_rad) @ q1) @ q2
    if not (np.allclose(m[:3, 2], [0.0, 0.0, 1.0], atol=tol) and np.allclose(m[:3, 3], 0.0, atol=tol)):
        return False
    j = math.atan2(m[1, 0], m[0, 0]) / small.angular_pitch_rad
    return abs(j - round(j)) <= tol


def play_period(bodies: dict[str, Body], specs) -> float:
    """Drive period of every output shaft's play: half a small-gear pitch when each big gear's two
    meshes run half a tooth apart (z_big odd: the mesh with one small gear at φ + p/2 is congruent
    to the mesh with the other at φ), else a whole pitch."""
    pitch = specs.small.angular_pitch_rad
    for big in BIG_GEARS:
        a = warm_poses(bodies, specs, 0.0, 0.0, 0.0)
        h = warm_poses(bodies, specs, 0.0, 0.0, pitch / 2.0)
        for s1, s2 in ((SMALL_GEARS[0], SMALL_GEARS[1]), (SMALL_GEARS[1], SMALL_GEARS[0])):
            q1 = np.linalg.inv(a[big]) @ a[s1]
            q2 = np.linalg.inv(h[big]) @ h[s2]
            if not _congruent(q2, q1, specs.big, specs.small):
                return pitch
    return pitch / 2.0


# --------------------------------------------------------------------------------------------
# The check

def _model_per_side(params, shim_mm: float) -> dict:
    """Paper's model (eqs 1–11) per side, at the built thinning (the template's least)."""
    r = analyse_params(params)
    geom = r.geometry
    alpha = math.radians(params.gears.pressure_angle_deg)
    gain = analysis.shim_gain(geom, alpha, shim_mm)
    thinning = analysis.big_gear_arcmin(params.backlash.mesh_thinning_min_mm, geom)
    warm = thinning + gain.per_side_arcmin
    clean_warm = thinning + gain.clean_per_side_arcmin
    return {"warm": warm, "cold": warm - r.cold.per_side_arcmin,
            "clean_warm": clean_warm, "clean_cold": clean_warm - r.cold.clean_per_side_arcmin,
            "drop": r.cold.per_side_arcmin, "clean_drop": r.cold.clean_per_side_arcmin}


def run_check(params, bodies: dict[str, Body], progress: Callable[[int], None] | None = None, *,
              angles_per_cycle: int = ANGLES_PER_CYCLE, shims_mm: list[float] | None = None,
              workers: int | None = None, timings: dict | None = None) -> CheckResult:
    """Sweep warm and cold over one cycle of the output shafts' play for each shim (the template's
    study, its own shim and 0 unless ``shims_mm`` is given); ``progress(n)`` advances by n
    collide calls (counted per measurement as its bracket needs). Speed figures vary from run to
    run, so they stay out of the (deterministic) summary: pass a dict as ``timings`` to get them
    (``make bench``)."""
    specs = gear_specs(params)
    template_shim = params.shim.thickness_mm
    check_bodies(bodies, specs, template_shim)
    if shims_mm is None:
        shims_mm = list(params.shim.study_mm) + [0.0]
    shims = sorted({round(float(s), 9) for s in list(shims_mm) + [template_shim]})
    thermal = thermal_state(params, specs=specs)  # scales and datums: the same for every shim
    thermal_at = {s: thermal_state(params, specs=specs, shim_mm=s) for s in shims}  # datum shifts
    period = play_period(bodies, specs)
    angles = np.arange(angles_per_cycle) / angles_per_cycle * period
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    tol_rad = BISECTION_TOL_ARCMIN / bp.ARCMIN_PER_RAD

    bound_mm = {}
    for big in BIG_GEARS:
        for small in SMALL_GEARS:
            bound_mm[(big, small, "warm")] = bodies[big].error_bound_mm + bodies[small].error_bound_mm
            bound_mm[(big, small, "cold")] = (bodies[big].error_bound_mm * thermal[big].scale
                                              + bodies[small].error_bound_mm * thermal[small].scale)
    bound_max_mm = max(bound_mm.values())
    bound_arcmin = bound_max_mm / d1_half * bp.ARCMIN_PER_RAD

    meshes = pruned_meshes(bodies, specs, thermal)
    # One exact solve per distinct mesh: a pair congruent to one already listed at the same shim,
    # state and drive angle (the other output shaft, by the assembly's symmetry) only gets its
    # own mesh bisection, bracketed by that exact contact.
    jobs, owners = [], []  # owners[j]: the (shim, state, k, big, small) measured in job j's mesh list
    reused = 0
    for i, shim in enumerate(shims):
        for state in STATES:
            for k, phi in enumerate(angles):
                poses = warm_poses(bodies, specs, shim, template_shim, phi)
                placed, mesh_pose = {}, {}
                for name in BIG_GEARS + SMALL_GEARS:
                    spec = specs.big if name in BIG_GEARS else specs.small
                    if state == "warm":
                        placed[name] = bp.PlacedGear(spec, poses[name])
                        mesh_pose[name] = poses[name]
                    else:
                        th = thermal_at[shim][name]
                        placed[name] = bp.PlacedGear(spec, th.cold_pose_about_origin(poses[name]), th.scale)
                        mesh_pose[name] = th.cold_pose(poses[name])
                groups: list[tuple[str, str, list]] = []  # (big, small, members)
                for big in BIG_GEARS:
                    for small in SMALL_GEARS:
                        q = np.linalg.inv(placed[big].pose) @ placed[small].pose
                        for g in groups:
                            gq = np.linalg.inv(placed[g[0]].pose) @ placed[g[1]].pose
                            same_scales = (placed[g[0]].scale == placed[big].scale
                                           and placed[g[1]].scale == placed[small].scale)
                            if same_scales and _congruent(gq, q, specs.big, specs.small, tol=1e-7):
                                g[2].append((big, small))
                                reused += 1
                                break
                        else:
                            groups.append((big, small, [(big, small)]))
                for gb, gs, members in groups:
                    for d in DIRECTIONS:
                        mesh_list = [(mesh_name(b, s, d, "big", state), mesh_name(b, s, d, "small", state),
                                      mesh_pose[b], mesh_pose[s], bound_mm[(b, s, state)] / d1_half)
                                     for b, s in members]
                        jobs.append((placed[gb], placed[gs], d, mesh_list, tol_rad))
                        owners.append([(i, state, k, b, s, d) for b, s in members])
    per_pair = 3 + math.ceil(math.log2((BRACKET_INSIDE_ARCMIN + BRACKET_OUTSIDE_ARCMIN) / BISECTION_TOL_ARCMIN))
    per_job = per_pair * sum(len(o) for o in owners) / len(jobs)  # collide calls per job, for progress
    t0 = time.perf_counter()
    results = map_scene(measure_contact, meshes, jobs, workers=workers,
                        progress=(lambda n: progress(round(n * per_job))) if progress else None)
    wall_s = time.perf_counter() - t0
    by_key = {}
    for result, keys in zip(results, owners):
        for key, mesh in zip(keys, result["mesh"]):
            by_key[key] = {**mesh, "exact_rad": result["exact_rad"], "exact_s": result["exact_s"] / len(keys)}
    n_workers = workers if workers is not None else default_workers()
    speed = {"wall_s": wall_s, "workers": n_workers, "exact_solves": len(jobs), "exact_reused": reused,
             "exact_s": sum(r["exact_s"] for r in results), "period_rad": period}
    result = _assemble(params, specs, bodies, thermal_at, shims, template_shim, angles, by_key, bound_arcmin,
                       bound_max_mm, speed, meshes)
    result.timings.update(_timings(by_key, results, speed))
    if timings is not None:
        timings.update(result.timings)
    return result


def _timings(by_key: dict, results: list, speed: dict) -> dict:
    """Speed of the sweep: collide calls per second (over the time spent bisecting, times the
    workers), one play measurement (one big gear against one small gear, both ways, on the
    meshes), one exact contact solve, wall time of the whole pool."""
    calls = sum(r["calls"] for r in by_key.values())
    mesh_s = sum(r["mesh_s"] for r in by_key.values())
    pair_play_s = [by_key[key]["mesh_s"] + by_key[key[:5] + (-1,)]["mesh_s"] for key in by_key if key[5] == 1]
    return {
        "collide_calls": int(calls),
        "collide_calls_per_s_per_worker": calls / mesh_s,
        "poses_per_s": calls / mesh_s * speed["workers"],
        "workers": speed["workers"],
        "ms_per_play_measurement": 1e3 * float(np.mean(pair_play_s)),
        "ms_per_play_measurement_max": 1e3 * float(np.max(pair_play_s)),
        "ms_per_exact_contact": 1e3 * speed["exact_s"] / len(results),
        "sweep_wall_s": speed["wall_s"],
    }


def _assemble(params, specs, bodies, thermal, shims, template_shim, angles, by_key, bound_arcmin, bound_mm,
              speed, meshes) -> CheckResult:
    arcmin = bp.ARCMIN_PER_RAD
    n_s, n_a = len(shims), len(angles)
    shape = (n_s, len(STATES), n_a, len(BIG_GEARS))
    geom_plus, geom_minus = np.empty(shape), np.empty(shape)
    exact_plus, exact_minus = np.empty(shape), np.empty(shape)
    centred_free = np.ones(shape, dtype=bool)
    deviation = []  # per contact: (|geom − exact|, allowed)
    for (i, state, k, big, small, d), r in by_key.items():
        j, b = STATES.index(state), BIG_GEARS.index(big)
        geom = 0.5 * (r["free_rad"] + r["touching_rad"]) * arcmin
        exact = r["exact_rad"] * arcmin
        deviation.append((abs(geom - exact), bound_arcmin + AGREEMENT_RELATIVE * abs(exact)))
        centred_free[i, j, k, b] &= not r["centred_collides"]
    for i in range(n_s):
        for j, state in enumerate(STATES):
            for k in range(n_a):
                for b, big in enumerate(BIG_GEARS):
                    rs = [(by_key[(i, state, k, big, s, 1)], by_key[(i, state, k, big, s, -1)]) for s in SMALL_GEARS]
                    geom_plus[i, j, k, b] = min(0.5 * (p["free_rad"] + p["touching_rad"]) for p, _ in rs) * arcmin
                    geom_minus[i, j, k, b] = max(0.5 * (m["free_rad"] + m["touching_rad"]) for _, m in rs) * arcmin
                    exact_plus[i, j, k, b] = min(p["exact_rad"] for p, _ in rs) * arcmin
                    exact_minus[i, j, k, b] = max(m["exact_rad"] for _, m in rs) * arcmin
    geom_play = geom_plus - geom_minus
    exact_play = exact_plus - exact_minus
    geom_min = geom_play.min(axis=(2, 3))  # (shim, state)
    exact_min = exact_play.min(axis=(2, 3))
    total_dev = np.abs(geom_play - exact_play)
    total_ok = bool(np.all(total_dev <= 2.0 * bound_arcmin + AGREEMENT_RELATIVE * np.abs(exact_play)))
    contact_dev = np.array([dv for dv, _ in deviation])
    contact_ok = all(dv <= allowed for dv, allowed in deviation)
    t = shims.index(round(template_shim, 9))
    W, C = STATES.index("warm"), STATES.index("cold")
    models = [_model_per_side(params, s) for s in shims]
    model = models[t]
    z = shims.index(0.0) if 0.0 in shims else None

    calls = sum(r["calls"] for r in by_key.values())
    widened = sum(r["widened"] > 0 for r in by_key.values())

    # worst pose: cold, template shim, least geometric play; the side with the smaller margin
    kk, bb = np.unravel_index(np.argmin(geom_play[t, C]), geom_play[t, C].shape)
    big = BIG_GEARS[bb]
    plus_margin, minus_margin = geom_plus[t, C, kk, bb], -geom_minus[t, C, kk, bb]
    d = 1 if plus_margin <= minus_margin else -1
    cands = [(s, by_key[(t, "cold", kk, big, s, d)]) for s in SMALL_GEARS]
    small, rec = (min if d == 1 else max)(cands, key=lambda c: c[1]["free_rad"])
    worst = _worst_poses(bodies, specs, thermal[shims[t]], shims[t], template_shim, angles[kk], big, small, d, rec)

    summary = {
        "template_shim_mm": template_shim,
        "geom_cold_drop_per_side_arcmin": float(geom_min[t, W] - geom_min[t, C]),
        "exact_cold_drop_per_side_arcmin": float(exact_min[t, W] - exact_min[t, C]),
        "model_cold_drop_per_side_arcmin": model["drop"],
        "clean_model_cold_drop_per_side_arcmin": model["clean_drop"],
        "geom_warm_play_min_arcmin": float(geom_min[t, W]),
        "geom_cold_play_min_arcmin": float(geom_min[t, C]),
        "exact_warm_play_min_arcmin": float(exact_min[t, W]),
        "exact_cold_play_min_arcmin": float(exact_min[t, C]),
        "model_warm_play_min_arcmin": model["warm"],
        "model_cold_play_min_arcmin": model["cold"],
        "geom_cold_backlash_total_min_arcmin": float(2.0 * geom_min[t, C]),
        "exact_cold_backlash_total_min_arcmin": float(2.0 * exact_min[t, C]),
        "geom_warm_backlash_total_min_arcmin": float(2.0 * geom_min[t, W]),
        "exact_warm_backlash_total_min_arcmin": float(2.0 * exact_min[t, W]),
        "mesh_error_bound_mm": bound_mm,
        "mesh_error_bound_arcmin": bound_arcmin,
        "max_mesh_exact_contact_deviation_arcmin": float(contact_dev.max()),
        "max_mesh_exact_play_deviation_arcmin": float(total_dev.max()),
        "mesh_agrees_with_exact": int(contact_ok and total_ok),
        "angles_per_cycle": len(angles),
        "poses": int(calls),
        "exact_solves": speed["exact_solves"],
        "exact_solves_reused_by_congruence": speed["exact_reused"] * len(DIRECTIONS),
        "cycle_deg": math.degrees(speed["period_rad"]),
        "brackets_widened": int(widened),
        "pruned_meshes": len(meshes),
        "pruned_triangles_mean": float(np.mean([len(m.faces) for m in meshes])),
    }
    if z is not None:
        summary["geom_shim_gain_per_side_arcmin"] = float(geom_min[t, W] - geom_min[z, W])
        summary["exact_shim_gain_per_side_arcmin"] = float(exact_min[t, W] - exact_min[z, W])
        summary["model_shim_gain_per_side_arcmin"] = model["warm"] - models[z]["warm"]
    summary["shim_study"] = {
        "shims_mm": list(shims),
        "geom_warm_play_min_arcmin": geom_min[:, W].tolist(),
        "geom_cold_play_min_arcmin": geom_min[:, C].tolist(),
        "exact_warm_play_min_arcmin": exact_min[:, W].tolist(),
        "exact_cold_play_min_arcmin": exact_min[:, C].tolist(),
        "model_warm_play_min_arcmin": [m["warm"] for m in models],
        "model_cold_play_min_arcmin": [m["cold"] for m in models],
        "clean_model_warm_play_min_arcmin": [m["clean_warm"] for m in models],
        "clean_model_cold_play_min_arcmin": [m["clean_cold"] for m in models],
        "geom_cold_drop_per_side_arcmin": (geom_min[:, W] - geom_min[:, C]).tolist(),
        "exact_cold_drop_per_side_arcmin": (exact_min[:, W] - exact_min[:, C]).tolist(),
        "model_cold_drop_per_side_arcmin": [m["drop"] for m in models],
    }

    # verdicts at the template's shim
    warm_free = bool(centred_free[t, W].all())
    least_warm = np.unravel_index(np.argmin(geom_play[t, W]), geom_play[t, W].shape)
    n_poses = n_a * len(BIG_GEARS) * len(SMALL_GEARS)
    cold_centred_free = bool(centred_free[t, C].all())
    cold_ok = bool(geom_min[t, C] > 0.0 and exact_min[t, C] > 0.0 and cold_centred_free)
    verdicts = [
        Verdict("no_interference_warm", f"no interference warm at shim {shims[t]:.2f} mm",
                warm_free and bool(geom_min[t, W] > 0.0),
                f"{n_poses} centred poses (4 meshes × {n_a} drive angles) free"
                f"{'' if warm_free else ' — NOT all'}; contact reached both ways at every pose; least warm play "
                f"{geom_min[t, W]:.3f}′ per side ({BIG_GEARS[least_warm[1]]}, "
                f"drive {math.degrees(angles[least_warm[0]]):.2f}°), "
                f"exact {exact_min[t, W]:.3f}′, mesh bound ±{2 * bound_arcmin:.2f}′ on a play"),
        Verdict("cold_play_positive", f"cold play > 0 over the whole cycle at shim {shims[t]:.2f} mm", cold_ok,
                f"least cold play {geom_min[t, C]:.3f}′ per side (geometry), exact {exact_min[t, C]:.3f}′; "
                f"centred cold poses {'all free' if cold_centred_free else 'COLLIDE'}; worst-case mesh bound "
                f"±{2 * bound_arcmin:.2f}′ on a play (the mesh matches the exact flanks to "
                f"{total_dev[t, C].max():.3f}′ here)"),
        Verdict("mesh_agrees_with_exact", "mesh sweep agrees with the exact-flank model",
                contact_ok and total_ok,
                f"largest difference {contact_dev.max():.3f}′ per contact and {total_dev.max():.3f}′ per play over "
                f"{len(by_key)} contacts; allowed {bound_arcmin:.2f}′ (bound {bound_mm * 1e3:.1f} µm on d1/2) + "
                f"{AGREEMENT_RELATIVE:.0%} per contact, twice the bound per play"),
    ]
    passed = all(v.passed for v in verdicts)
    summary["verdict_pass"] = int(passed)

    rows = []
    for i, shim in enumerate(shims):
        for j, state in enumerate(STATES):
            m = models[i]["warm" if state == "warm" else "cold"]
            for k, phi in enumerate(angles):
                row = {"shim_mm": shim, "state": state, "drive_angle_deg": math.degrees(phi)}
                for b, big in enumerate(BIG_GEARS):
                    side = big.removeprefix("big_gear_")
                    row.update({
                        f"{side}_geom_plus_arcmin": geom_plus[i, j, k, b],
                        f"{side}_geom_minus_arcmin": geom_minus[i, j, k, b],
                        f"{side}_geom_play_arcmin": geom_play[i, j, k, b],
                        f"{side}_exact_plus_arcmin": exact_plus[i, j, k, b],
                        f"{side}_exact_minus_arcmin": exact_minus[i, j, k, b],
                        f"{side}_exact_play_arcmin": exact_play[i, j, k, b],
                        f"{side}_centred_free": int(centred_free[i, j, k, b]),
                    })
                row["model_play_arcmin"] = m
                rows.append({key: (float(v) if isinstance(v, (np.floating, float)) else v) for key, v in row.items()})

    deg = np.degrees(angles).tolist()
    # the two output shafts: one series each where they differ, one for both where they do not
    same = float(np.abs(geom_play[..., 0] - geom_play[..., 1]).max())
    shafts = ([(0, "both shafts")] if same < 1e-6
              else [(b, big.removeprefix("big_gear_")) for b, big in enumerate(BIG_GEARS)])
    period_text = f"{math.degrees(speed['period_rad']):.2f}° of drive"
    plots = [
        Plot(f"Play of the output shafts over one cycle ({period_text}), shim {shims[t]:.2f} mm",
             "small-gear drive angle (deg)", "play per side (arcmin)",
             [Series(f"geometry {state}, {label}", deg, geom_play[t, STATES.index(state), :, b].tolist(), "points")
              for state in STATES for b, label in shafts]
             + [Series(f"exact flanks {state}", deg, exact_play[t, STATES.index(state), :, 0].tolist())
                for state in STATES],
             hlines=[("paper model warm", model["warm"]), ("paper model cold", model["cold"])]),
        Plot("Least play over the cycle against shim", "shim under each big gear (mm)", "least play per side (arcmin)",
             [Series("geometry warm", list(shims), geom_min[:, W].tolist(), "points"),
              Series("geometry cold", list(shims), geom_min[:, C].tolist(), "points"),
              Series("exact flanks warm", list(shims), exact_min[:, W].tolist()),
              Series("exact flanks cold", list(shims), exact_min[:, C].tolist()),
              Series("paper model warm (eqs 1–11)", list(shims), [m["warm"] for m in models]),
              Series("paper model cold (eqs 1–11)", list(shims), [m["cold"] for m in models])],
             markers=[("template shim", template_shim)], hlines=[("binding", 0.0)]),
        Plot("Cold drop against shim", "shim under each big gear (mm)",
             "cycle min warm − cycle min cold, per side (arcmin)",
             [Series("geometry", list(shims), (geom_min[:, W] - geom_min[:, C]).tolist(), "points"),
              Series("exact flanks", list(shims), (exact_min[:, W] - exact_min[:, C]).tolist()),
              Series("paper model (printed eq 9)", list(shims), [m["drop"] for m in models]),
              Series("paper model (clean eq 9)", list(shims), [m["clean_drop"] for m in models])],
             markers=[("template shim", template_shim)]),
    ]

    r = analyse_params(params)
    at_paper_dT = math.isclose(r.approach.temperature_drop_K, PAPER_TEMPERATURE_DROP_K, abs_tol=1e-9)
    at_paper_shim = math.isclose(template_shim, PAPER_SHIM_MM, abs_tol=1e-9)
    why = ("displaced apexes make the mesh non-conjugate (reference §1); a net approach is decided at the toe, "
           "an opening at the heel: reported, not tuned")
    comparisons = [
        Comparison(f"cold backlash drop per side, shim {shims[t]:.2f} mm", "arcmin",
                   PAPER["cold_drop_per_side_arcmin"] if at_paper_dT else None, model["drop"],
                   summary["geom_cold_drop_per_side_arcmin"], why, summary["exact_cold_drop_per_side_arcmin"]),
        Comparison("cold backlash drop, both sides", "arcmin",
                   PAPER["cold_drop_total_arcmin"] if at_paper_dT else None, 2 * model["drop"],
                   2 * summary["geom_cold_drop_per_side_arcmin"], "twice the per-side drop",
                   2 * summary["exact_cold_drop_per_side_arcmin"]),
        Comparison("cold drop per side, clean eq (9)", "arcmin", None, model["clean_drop"],
                   summary["geom_cold_drop_per_side_arcmin"], "dimensionally clean eq (9) (docs/differential.md)",
                   summary["exact_cold_drop_per_side_arcmin"]),
        Comparison(f"warm backlash total, least, shim {shims[t]:.2f} mm", "arcmin",
                   PAPER["warm_backlash_total_min_arcmin"] if at_paper_shim else None, 2 * model["warm"],
                   float(2 * geom_min[t, W]), "built with the least thinning; the shim gains less on exact flanks",
                   float(2 * exact_min[t, W])),
        Comparison(f"cold backlash total, least, shim {shims[t]:.2f} mm", "arcmin",
                   PAPER["cold_backlash_total_min_arcmin"] if (at_paper_shim and at_paper_dT) else None,
                   2 * model["cold"], float(2 * geom_min[t, C]), "paper: a bound (≥ 10′)", float(2 * exact_min[t, C])),
    ]
    if z is not None:
        comparisons.insert(3, Comparison(
            f"shim gain per side, {shims[t]:.2f} mm", "arcmin", None, summary["model_shim_gain_per_side_arcmin"],
            summary["geom_shim_gain_per_side_arcmin"],
            "eq (11); the shim slides the big gear's apex off the common apex too",
            summary["exact_shim_gain_per_side_arcmin"]))
        comparisons.append(Comparison(
            "cold play per side, no shim", "arcmin", None, models[z]["cold"], float(geom_min[z, C]),
            "binds cold (negative: overlap as an angle)" if geom_min[z, C] <= 0 else "", float(exact_min[z, C])))

    notes = _notes(shims, t, geom_min, summary, specs, angles, bound_arcmin, speed)
    return CheckResult(SECTION, summary, verdicts, rows, comparisons, plots, notes, worst,
                       smallest_clearance=smallest_clearance(specs, shims[t], exact_min[t, W], exact_min[t, C]))


def smallest_clearance(specs, shim_mm: float, warm_arcmin: float, cold_arcmin: float) -> Clearance | None:
    """The least positive play per side at the template's shim (exact flanks, warm or cold) as the
    arc it spans on the big gear's outer pitch circle: the radius the check converts its mesh
    bound with, so the rule reads bound ≤ play/10 in the verdicts' own terms."""
    plays = [(v, state) for v, state in ((cold_arcmin, "cold"), (warm_arcmin, "warm")) if v > 0.0]
    if not plays:
        return None
    play, state = min(plays)
    d1_half = specs.big.outer_pitch_diameter_mm / 2.0
    return Clearance(float(play) / bp.ARCMIN_PER_RAD * d1_half,
                     f"least {state} play per side at shim {shim_mm:.2f} mm (exact flanks, {play:.3f}′ on d1/2)")


def _worst_poses(bodies, specs, thermal, shim, template_shim, phi, big, small, direction, rec) -> list[WorstPose]:
    """The cold pose with the least play: the big gear at the free side of its contact bracket,
    and at the centred pose; mesh distances on the whole (unpruned) cold meshes."""
    poses = warm_poses(bodies, specs, shim, template_shim, phi)
    tb, ts = thermal[big], thermal[small]
    scene = Scene([bodies[big].scaled(tb.scale, tb.datum_local).mesh,
                   bodies[small].scaled(ts.scale, ts.datum_local).mesh])
    scene.set_pose(small, ts.cold_pose(poses[small]))
    out = []
    way = "+" if direction > 0 else "−"
    for label, turn in ((f"cold least play, contact {way} (free side), {math.degrees(phi):.2f}°", rec["free_rad"]),
                        (f"cold least play, centred, {math.degrees(phi):.2f}°", 0.0)):
        big_pose = poses[big] @ bp.rot_z4(turn)
        scene.set_pose(big, tb.cold_pose(big_pose))
        distance = scene.distance(big, small).distance
        out.append(WorstPose(label, big, small, tb.cold_pose_about_origin(big_pose).tolist(),
                             ts.cold_pose_about_origin(poses[small]).tolist(), float(distance), tb.scale, ts.scale))
    return out


def _cycle_note(specs, angles, speed) -> str:
    pitch_deg = math.degrees(specs.small.angular_pitch_rad)
    period_deg = math.degrees(speed["period_rad"])
    text = (f"Cycle: identical teeth, so one small-gear pitch ({pitch_deg:.2f}°) of drive repeats every pose. "
            f"{len(angles)} drive angles over {period_deg:.2f}°")
    if period_deg < pitch_deg - 1e-9:
        text += (" (half a pitch: z_big is odd, so each big gear meets its two small gears half a tooth apart and "
                 "its play repeats every half pitch, checked on the poses; its two meshes together pass "
                 f"{2 * len(angles)} phases of one full mesh cycle)")
    text += (f". Exact solves: {speed['exact_solves']}; {speed['exact_reused'] * len(DIRECTIONS)} more contacts are on "
             "pairs congruent to a solved one at the same pose (the other output shaft), checked on the poses, "
             "and get only their own mesh bisection.")
    return text


def _notes(shims, t, geom_min, summary, specs, angles, bound_arcmin, speed) -> list[str]:
    C = STATES.index("cold")
    toe = specs.big.outer_cone_distance_mm / specs.big.inner_cone_distance_mm
    sm = summary
    notes = [
        f"Cold drop per side at shim {shims[t]:.2f} mm: geometry {sm['geom_cold_drop_per_side_arcmin']:.2f}′, exact "
        f"flanks {sm['exact_cold_drop_per_side_arcmin']:.2f}′, paper's model {sm['model_cold_drop_per_side_arcmin']:.2f}′ "
        f"(clean eq 9: {sm['clean_model_cold_drop_per_side_arcmin']:.2f}′). Eqs (1)–(11) look at one tooth pair at the "
        "outer pitch point; the cold state slides each gear's apex off the common apex, so the mesh is no longer "
        "conjugate and neighbouring tooth pairs close up (reference §1). Reported, not tuned.",
        "Where the play is decided: a translation changes the flank gap by the same amount in mm along the whole "
        "face, while the designed backlash tapers with the cone distance. A net opening (the shim) is therefore "
        "limited at the heel, as eq (10) assumes; a net approach (cold, little or no shim) at the toe, where the same "
        f"loss is Re/Ri = {toe:.2f} times the eq (10) angle. Hence the larger drop at small shims.",
        "Output-shaft play: each big gear meshes with both small gears; each way it stops at the tighter mesh "
        "(plus = min, minus = max over the two small gears). Per side = one big gear's play, as in the paper.",
        _cycle_note(specs, angles, speed),
        f"Meshes pruned to the tooth halves that can touch ({sm['pruned_meshes']} pruned meshes, "
        f"{sm['pruned_triangles_mean']:.0f} triangles each on average); each direction measured on its own flank "
        "halves, so a side that binds gives a negative play instead of a failed bisection.",
        f"Mesh-error bound {sm['mesh_error_bound_mm'] * 1e3:.1f} µm per pair, {bound_arcmin:.2f}′ per contact on "
        f"d1/2; the mesh plays exceed the exact ones by at most {sm['max_mesh_exact_play_deviation_arcmin']:.3f}′ "
        "(chords inside convex flanks: meshes overstate clearance).",
    ]
    binding = [i for i in range(len(shims)) if geom_min[i, C] <= 0.0]
    if binding:
        notes.append(f"Binds cold (geometry) at shim {', '.join(f'{shims[i]:.2f} mm' for i in binding)}: least cold "
                     f"play {', '.join(f'{geom_min[i, C]:.2f}′' for i in binding)} per side; the paper shims for this "
                     "reason.")
    return notes
