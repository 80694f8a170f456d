"""Small cuts of the play part's meshes around its last contact: cheap distance queries for the
contact estimate, and cheap "touching" answers.

A play measurement asks FCL many times near one contact. A distance query between the whole
directed meshes of a gear pair costs about 8 ms there; between a few hundred faces of each around
the contact, 0.05–0.5 ms. A cut holds a subset of each mesh's faces, so a collision between the
cuts is a collision between the meshes (a "touching" answer proven at a cut's price); a free
answer, and so every bracket's free end, is still asked of the whole meshes. The distance between
the cuts is never less than between the meshes: it only guides the estimate, which the
collisions then prove or reject.

A cut follows the contact: it is centred on the nearest points of the last distance query, in
each part's own frame, and cut again when a nearest point strays past half its radius — twice as
large, up to a limit (poses far apart move the contact far along a flank).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gearcheck.sweep.bodies import submesh
from gearcheck.sweep.engine import Scene

CUT_FACES = 400  # faces kept per mesh at first: the nearest to the contact, by face centroid
MOST_CUT_FACES = 3200  # a cut the contact strays from is cut again twice as large, up to this


@dataclass(frozen=True)
class Cut:
    """A pair of cuts (the mover's and its neighbour's), each with its centre and radius (own frame)."""

    mover: str
    other: str
    centres: tuple[np.ndarray, np.ndarray]
    radii: tuple[float, float]

    def strays(self, local_a: np.ndarray, local_b: np.ndarray) -> bool:
        """True where a nearest point (own frames) lies past half a cut's radius from its centre: the
        contact may have left the cut."""
        return any(float(np.linalg.norm(p - c)) > 0.5 * r
                   for p, c, r in zip((local_a, local_b), self.centres, self.radii, strict=True))


class Cuts:
    """The current cut per key (a turning sense and a neighbour), for one task's scene."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.current: dict[tuple, Cut] = {}
        self.faces: dict[tuple, int] = {}  # per key: the faces a cut keeps
        self._centroids: dict[str, np.ndarray] = {}
        self._made = 0

    def _cut(self, name: str, centre: np.ndarray, faces: int) -> tuple[str, float]:
        centroids = self._centroids.get(name)
        mesh = self.scene.mesh(name)
        if centroids is None:
            centroids = self._centroids[name] = mesh.vertices[mesh.faces].mean(axis=1)
        d = np.linalg.norm(centroids - centre, axis=1)
        keep = np.argpartition(d, faces)[:faces] if len(d) > faces else np.arange(len(d))
        self._made += 1
        cut = submesh(mesh, f"{name}|cut {self._made}", keep)
        self.scene.add(cut)
        return cut.name, float(d[keep].max())

    def seat(self, key: tuple, mover: str, other: str, local_a: np.ndarray, local_b: np.ndarray,
             grow: bool = False) -> Cut:
        """Cut ``mover`` and ``other`` (scene meshes) around the points ``local_a``, ``local_b`` (their
        own frames), replacing the key's earlier cut; ``grow``: twice as many faces as the key's
        cuts had (the contact strayed)."""
        self._drop(key)
        faces = self.faces.get(key, CUT_FACES)
        if grow:
            faces = self.faces[key] = min(MOST_CUT_FACES, 2 * faces)
        (ma, ra) = self._cut(mover, np.asarray(local_a, float), faces)
        (mb, rb) = self._cut(other, np.asarray(local_b, float), faces)
        cut = self.current[key] = Cut(ma, mb, (np.asarray(local_a, float), np.asarray(local_b, float)), (ra, rb))
        return cut

    def get(self, key: tuple) -> Cut | None:
        return self.current.get(key)

    def clear(self) -> None:
        for key in list(self.current):
            self._drop(key)

    def _drop(self, key: tuple) -> None:
        """The key's cut pair, if any, out of the scene."""
        old = self.current.pop(key, None)
        if old is not None:
            self.scene.discard(old.mover)
            self.scene.discard(old.other)


def to_local(pose: np.ndarray, point: np.ndarray) -> np.ndarray:
    """A world point in the frame of a body posed at ``pose`` (4×4, rigid)."""
    return pose[:3, :3].T @ (np.asarray(point, float) - pose[:3, 3])
