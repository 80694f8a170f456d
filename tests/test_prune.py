"""Mesh pruning for a pair in relative motion (gearcheck.sweep.prune), against brute force: no face
that comes within the margin of the other body at any pose is dropped, faces far away are, and the
faces a motion can first meet are the ones facing it."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.sweep.bodies import MeshData
from gearcheck.sweep.prune import approaching_faces, largest_step, near_faces, surface_samples


def _box(lo, hi, n: int = 6, name: str = "box") -> MeshData:
    """A box's surface, each face an n × n grid of squares split in two triangles, wound outward."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    verts, faces = [], []
    for axis in range(3):
        for side in (0, 1):
            u, w = [a for a in range(3) if a != axis]
            base = len(verts)
            for i in range(n + 1):
                for j in range(n + 1):
                    p = np.empty(3)
                    p[axis] = hi[axis] if side else lo[axis]
                    p[u] = lo[u] + (hi[u] - lo[u]) * i / n
                    p[w] = lo[w] + (hi[w] - lo[w]) * j / n
                    verts.append(p)
            for i in range(n):
                for j in range(n):
                    a, b, c, d = (base + i * (n + 1) + j, base + (i + 1) * (n + 1) + j,
                                  base + (i + 1) * (n + 1) + j + 1, base + i * (n + 1) + j + 1)
                    tri = [(a, b, c), (a, c, d)]
                    # outward: the normal of (b − a) × (c − a) along +axis on the high side
                    flip = (side == 1) != ((u, w) in ((1, 2), (2, 0), (0, 1)))
                    faces += [t[::-1] if flip else t for t in tri]
    return MeshData(name, np.array(verts), np.array(faces))


def _turn(deg: float) -> np.ndarray:
    a = math.radians(deg)
    m = np.eye(4)
    m[:2, :2] = [[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]
    return m


def _face_distance(mesh: MeshData, other_points: np.ndarray) -> np.ndarray:
    """Brute force: each face's least distance (dense samples of the face) to a cloud."""
    tri = mesh.vertices[mesh.faces]
    w = np.array([(a, b, 1 - a - b) for a in np.linspace(0, 1, 9) for b in np.linspace(0, 1, 9) if a + b <= 1])
    pts = np.einsum("kc,mcd->mkd", w, tri)
    from scipy.spatial import cKDTree

    d, _ = cKDTree(other_points).query(pts.reshape(-1, 3))
    return d.reshape(len(tri), -1).min(axis=1)


def test_no_face_within_the_margin_is_dropped_and_far_ones_are():
    fixed = _box((-5, -5, -2), (5, 5, 2), name="fixed")
    arm = _box((6, -1, -1), (16, 1, 1), name="arm")  # turns about z past the fixed box
    rel = np.array([np.linalg.inv(_turn(0.0)) @ _turn(a) for a in np.linspace(0.0, 40.0, 9)])
    margin = 1.5 + largest_step(arm.vertices, rel)
    keep = near_faces(fixed, arm, rel, margin)
    cloud = np.concatenate([surface_samples(arm, 0.05) @ m[:3, :3].T + m[:3, 3] for m in rel])
    true = _face_distance(fixed, cloud)
    assert keep[true <= margin].all()  # nothing within the margin is lost
    assert not keep[true > margin + 4.0].any()  # what is well beyond it goes
    assert 0 < keep.sum() < len(keep)


def test_the_faces_a_turn_meets_first_are_the_ones_facing_it():
    box = _box((2, -1, -1), (4, 1, 1), name="b")
    plus = approaching_faces(box, np.array([0.0, 0.0, 1.0]), np.zeros(3), +1.0, moving=True)
    normal = np.cross(*(box.vertices[box.faces][:, k] - box.vertices[box.faces][:, 0] for k in (1, 2)))
    # turning + about z at x ≈ 3 moves the box along +y: its +y face leads, its −y face trails
    assert plus[normal[:, 1] > 0].all() and not plus[normal[:, 1] < 0].any()
    minus = approaching_faces(box, np.array([0.0, 0.0, 1.0]), np.zeros(3), -1.0, moving=True)
    assert minus[normal[:, 1] < 0].all() and not minus[normal[:, 1] > 0].any()
    # a body the turn moves towards: its faces looking against the motion
    wall = approaching_faces(box, np.array([0.0, 0.0, 1.0]), np.zeros(3), +1.0, moving=False)
    assert wall[normal[:, 1] < 0].all() and not wall[normal[:, 1] > 0].any()
