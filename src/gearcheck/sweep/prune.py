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
play searched beyond them).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.sweep.bodies import MeshData


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
               cell: float | None = None) -> np.ndarray:
    """The faces of ``mesh`` that come within ``margin`` of ``other`` at any of the relative poses
    ``relative`` ((P, 4, 4): ``other``'s frame → ``mesh``'s frame), as a boolean mask."""
    from scipy.spatial import cKDTree

    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    if cell is None:
        extent = float(np.ptp(np.asarray(other.vertices, float), axis=0).max())
        cell = max(margin / 2.0, extent / 200.0, 1e-3)
    centres = voxel_centres(surface_samples(other, cell), cell)
    placed = np.concatenate([centres @ m[:3, :3].T + m[:3, 3] for m in np.asarray(relative, float)])
    tri = v[f]
    centroid = tri.mean(axis=1)
    radius = np.linalg.norm(tri - centroid[:, None, :], axis=2).max(axis=1)
    reach = margin + radius + cell * math.sqrt(3.0) / 2.0
    tree = cKDTree(placed)
    d, _ = tree.query(centroid, k=1, distance_upper_bound=float(reach.max()))
    return np.asarray(d <= reach)


def largest_step(points: np.ndarray, relative: np.ndarray) -> float:
    """The largest displacement of any of ``points`` (a body's extreme points: its bounding-box
    corners serve for a rigid motion's bound) between neighbouring relative poses."""
    rel = np.asarray(relative, float)
    if len(rel) < 2:
        return 0.0
    placed = np.einsum("pij,nj->pni", rel[:, :3, :3], points) + rel[:, None, :3, 3]
    return float(np.linalg.norm(np.diff(placed, axis=0), axis=2).max())


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
