"""Mesh pruning for a pair of bodies in relative motion: keep the triangles of one body that come
within a margin of the other anywhere in the motion (numpy and scipy; no FCL, no CAD).

A sweep queries two bodies at poses where only a small part of each can be near the other (a
gear's teeth at the mesh, not the rest of the wheel); a BVH of that part alone is smaller and
every query through it cheaper. What is dropped cannot change a figure below the margin: a
dropped triangle is farther than the margin from the other body at every pose, so a distance at
most the margin is the whole meshes' distance, and a larger one is only known to exceed the margin.

How: the other body's surface is sampled (its vertices, and points spaced at most ``cell`` over
its larger triangles), reduced to the centres of the ``cell``-sized voxels it occupies, placed at
every relative pose in the first body's frame, and searched with a k-d tree for the centroid of
each triangle of the first body: a triangle is kept where its centroid lies within the margin plus
its own circumradius plus half a voxel diagonal of a placed sample. The caller adds to the margin
what moves between the poses (the largest displacement of a point between neighbouring poses, a
play searched beyond them). Where the poses are closer together than the margin needs, or the
placed samples would be many (fine surfaces, many poses), every s-th pose is placed and the
margin grows by s steps: the time and the memory stay bounded (:data:`MAX_PLACED`), only more
faces are kept.

Before any of that, many bodies: :func:`box_gaps` and :func:`segment_distances` bound each pair's
distance from below over the whole motion from each body's swept box (its box's corners at every
pose) and a capsule holding every place its motion takes it (a turn's cylinder, a slide's
stroke), so that pairs that can never come near are dropped without placing a single sample.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.sweep.bodies import MeshData

# near_faces places at most about this many samples (poses × voxels; 24 bytes each, and a k-d tree)
MAX_PLACED = 2_000_000
# ... and places every s-th pose where s steps between poses make at most 1/POSE_SHARE of the margin
POSE_SHARE = 8.0


def surface_samples(mesh: MeshData, spacing: float) -> np.ndarray:
    """Points on the mesh's surface no farther than about ``spacing`` from any surface point: its
    vertices, and a barycentric grid over every triangle larger than the spacing."""
    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    tri = v[f]  # (m, 3, 3)
    edges = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    out = [v]
    big = edges > spacing
    if big.any():
        for n in np.unique(np.ceil(edges[big] / spacing).astype(int)):
            pick = tri[big][np.ceil(edges[big] / spacing).astype(int) == n]
            i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
            keep = (i + j) <= n
            a, b = i[keep] / n, j[keep] / n
            w = np.stack([1.0 - a - b, a, b], axis=1)  # (k, 3) barycentric weights
            out.append(np.einsum("kc,mcd->mkd", w, pick).reshape(-1, 3))
    return np.concatenate(out)


def voxel_centres(points: np.ndarray, cell: float) -> np.ndarray:
    """The centres of the ``cell``-sized voxels the points occupy."""
    keys = np.unique(np.floor(points / cell).astype(np.int64), axis=0)
    return (keys + 0.5) * cell


def near_faces(mesh: MeshData, other: MeshData, relative: np.ndarray, margin: float,
               cell: float | None = None, step: float | None = None) -> np.ndarray:
    """The faces of ``mesh`` that come within ``margin`` of ``other`` at any of the relative poses
    ``relative`` ((P, 4, 4): ``other``'s frame → ``mesh``'s frame), as a boolean mask. The smaller
    side is placed: the other's samples in this mesh's frame at every pose (one k-d tree of them,
    queried by the face centroids), or, for a mesh of fewer faces than samples, the centroids in
    the other's frame (queried against one k-d tree of the samples): the same distances. Poses
    closer together than the margin needs are thinned to every s-th one, the margin grown by s
    steps (at most 1/:data:`POSE_SHARE` of it; more where :data:`MAX_PLACED` bounds the memory);
    ``step``: the largest step of ``other``'s box corners between the poses, if the caller has it."""
    from scipy.spatial import cKDTree

    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    if cell is None:
        extent = float(np.ptp(np.asarray(other.vertices, float), axis=0).max())
        cell = max(margin / 2.0, extent / 200.0, 1e-3)
    centres = voxel_centres(surface_samples(other, cell), cell)
    relative = np.asarray(relative, float).reshape(-1, 4, 4)
    faces_placed = len(f) < len(centres)
    stride = max(1, math.ceil(len(relative) * min(len(f), len(centres)) / MAX_PLACED))
    if len(relative) > 2:
        if step is None:
            ov = np.asarray(other.vertices, float)
            lo, hi = ov.min(axis=0), ov.max(axis=0)
            step = largest_step(np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])
                                          for z in (lo[2], hi[2])]), relative)
        if step > 0.0:  # poses closer than an eighth of the margin add nothing a grown margin misses
            stride = max(stride, int(margin / (POSE_SHARE * step)))
    if stride > 1:  # every stride-th pose (and the last): a pose between lies within stride steps of one
        margin += stride * (step or 0.0)
        relative = np.concatenate([relative[::stride], relative[-1:]])
    tri = v[f]
    centroid = tri.mean(axis=1)
    radius = np.linalg.norm(tri - centroid[:, None, :], axis=2).max(axis=1)
    reach = margin + radius + cell * math.sqrt(3.0) / 2.0
    if faces_placed:  # the centroids in the other's frame at every pose: inverse(relative) applied
        placed = (centroid[None, :, :] - relative[:, None, :3, 3]) @ relative[:, :3, :3]  # Rᵀ(c − t), as rows
        d, _ = cKDTree(centres).query(placed.reshape(-1, 3), k=1, distance_upper_bound=float(reach.max()))
        return np.asarray((d.reshape(len(relative), len(f)) <= reach[None, :]).any(axis=0))
    placed = (centres[None, :, :] @ np.swapaxes(relative[:, :3, :3], 1, 2) + relative[:, None, :3, 3]).reshape(-1, 3)
    d, _ = cKDTree(placed).query(centroid, k=1, distance_upper_bound=float(reach.max()))
    return np.asarray(d <= reach)


def largest_step(points: np.ndarray, relative: np.ndarray) -> float:
    """The largest displacement of any of ``points`` (a body's extreme points: its bounding-box
    corners serve for a rigid motion's bound) between neighbouring relative poses."""
    rel = np.asarray(relative, float)
    if len(rel) < 2:
        return 0.0
    placed = points[None, :, :] @ np.swapaxes(rel[:, :3, :3], 1, 2) + rel[:, None, :3, 3]
    return float(np.linalg.norm(np.diff(placed, axis=0), axis=2).max())


def relative_poses(mine: np.ndarray, other: np.ndarray) -> np.ndarray:
    """``inv(mine[k]) @ other[k]`` for rigid transforms ((P, 4, 4) each): ``other``'s frame →
    ``mine``'s frame at every pose."""
    r_t = np.swapaxes(mine[:, :3, :3], 1, 2)
    out = np.zeros_like(other)
    out[:, :3, :3] = r_t @ other[:, :3, :3]
    out[:, :3, 3] = np.einsum("pij,pj->pi", r_t, other[:, :3, 3] - mine[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


def swept_box(corners: np.ndarray, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """A body's box ``corners`` placed at every pose ((P, 4, 4)): the world box holding them all
    (lo, hi) and the largest displacement of a corner between neighbouring poses (every point of
    the body lies within it of the box at any pose between)."""
    placed = corners[None, :, :] @ np.swapaxes(poses[:, :3, :3], 1, 2) + poses[:, None, :3, 3]
    return placed.min(axis=(0, 1)), placed.max(axis=(0, 1)), largest_step(corners, poses)


def box_gaps(lo: np.ndarray, hi: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """The distance between boxes ``i`` and ``j`` (index arrays into ``lo``/``hi``, (n, 3) each)."""
    gap = np.maximum(0.0, np.maximum(lo[j] - hi[i], lo[i] - hi[j]))
    return np.linalg.norm(gap, axis=1)


def segment_distances(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """The least distance between the segments p1q1 and p2q2 ((n, 3) each; a segment may be a
    point): the closest points by clamping (Ericson, Real-Time Collision Detection, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e = np.einsum("ij,ij->i", d1, d1), np.einsum("ij,ij->i", d2, d2)
    b, c, f = np.einsum("ij,ij->i", d1, d2), np.einsum("ij,ij->i", d1, r), np.einsum("ij,ij->i", d2, r)
    tiny = 1e-18
    a_ok, e_ok = a > tiny, e > tiny
    safe_a, safe_e = np.where(a_ok, a, 1.0), np.where(e_ok, e, 1.0)
    denom = a * e - b * b
    # both proper segments: s on the infinite lines (0 where parallel), then t, each clamped in turn
    s = np.where(denom > tiny * np.maximum(a * e, tiny), (b * f - c * e) / np.where(denom > 0, denom, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    t = (b * s + f) / safe_e
    s = np.where(t < 0.0, np.clip(-c / safe_a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / safe_a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    # the first a point: t alone; the second a point: s alone; both points: 0, 0
    s = np.where(a_ok & ~e_ok, np.clip(-c / safe_a, 0.0, 1.0), np.where(a_ok, s, 0.0))
    t = np.where(~a_ok & e_ok, np.clip(f / safe_e, 0.0, 1.0), np.where(e_ok & a_ok, t, 0.0))
    return np.linalg.norm((p1 + d1 * s[:, None]) - (p2 + d2 * t[:, None]), axis=1)


def approaching_faces(mesh: MeshData, axis: np.ndarray, origin: np.ndarray | None, sign: float, moving: bool,
                      slack: float = 1e-9) -> np.ndarray:
    """The faces a motion can make first contact on (a boolean mask): the motion a rotation about
    ``axis`` through ``origin`` (a translation along ``axis`` where ``origin`` is None), ``sign`` its
    sense; ``axis`` and ``origin`` in the mesh's frame, each a single one or one per pose ((P, 3)).

    For the body that moves (``moving``): its faces whose outward normal has a positive component
    along their own velocity somewhere on them (a face that recedes into its body everywhere cannot
    meet another body first; the component is linear over a flat face, so its corners decide). For
    a body it moves towards: its faces whose outward normal has a negative component along the
    mover's velocity somewhere on them, at any pose. A face square to the motion (a tip land, a
    flat end) is met only through its edges, which the approaching faces beside it carry. Needs
    the outward winding the meshes are checked for."""
    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    tri = v[f]  # (m, 3, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    axes = np.atleast_2d(np.asarray(axis, float))
    origins = None if origin is None else np.atleast_2d(np.asarray(origin, float))
    keep = np.zeros(len(f), dtype=bool)
    for k in range(len(axes)):
        a = axes[k] / np.linalg.norm(axes[k])
        if origins is not None:
            vel = np.cross(a, tri - origins[min(k, len(origins) - 1)])  # (m, 3, 3): at each corner
        else:
            vel = np.broadcast_to(a, tri.shape)
        along = sign * np.einsum("mj,mcj->mc", normal, vel)  # (m, 3)
        scale = slack * np.linalg.norm(vel, axis=2).max(axis=1)
        keep |= (along.max(axis=1) > scale) if moving else (along.min(axis=1) < -scale)
    return keep
