"""The assembly's play search: the cuts around the contact change its cost, never its figures.

Each move to contact is the bracket the plain bisection of [0, limit] ends with: found around
estimates (Newton steps between small cuts of the meshes around the last contact, the last poses'
moves extrapolated, Newton steps on the whole meshes), the bracket proven from both sides. Here
every pose's moves are checked against the plain bisection on the whole directed meshes, bit for
bit, and the cost the cuts save is counted: whole-mesh distance queries only where a task starts
(or a cut is lost), one whole-mesh collision per move where the estimate holds.
"""

from __future__ import annotations

import numpy as np
import pytest

from gearcheck import pipeline
from gearcheck.design import load
from gearcheck.geometry.bisect import bisect
from gearcheck.mechanisms.assembly.local import CUT_FACES, Cuts, to_local
from gearcheck.mechanisms.assembly.sweep import BISECT_DEG, plan_sweep, sweep_poses
from gearcheck.sweep.engine import Scene
from step_pairs import template, train_template, write_pair, write_train

pytestmark = pytest.mark.cad

M, Z1, Z2, ALPHA, DA = 2.0, 18, 24, 20.0, 0.1


class Counting(Scene):
    """A scene that counts the play search's queries (on the directed meshes, whole or cut)."""

    def __init__(self, meshes):
        super().__init__(meshes)
        self.counts = {"whole collide": 0, "cut collide": 0, "whole distance": 0, "cut distance": 0}

    def _count(self, name: str, query: str) -> None:
        if "|cut" in name:
            self.counts[f"cut {query}"] += 1
        elif name.endswith(("+", "-")):
            self.counts[f"whole {query}"] += 1

    def collide(self, a, b):
        self._count(a, "collide")
        return super().collide(a, b)

    def distance(self, a, b):
        self._count(a, "distance")
        return super().distance(a, b)


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    folder = tmp_path_factory.mktemp("play")
    design = load(template(write_pair(folder / "open.step", M, Z1, Z2, ALPHA, DA), M, Z1, Z2, DA))
    built = pipeline.build(design, folder / "run")
    return plan_sweep(built.assembly, built.bodies, None)


def _plain_moves(planned, spec, indices: list[int]) -> np.ndarray:
    """Each pose's moves both ways by the plain bisection on the whole directed meshes (any neighbour)."""
    kin, part = spec.kin, spec.play
    plain = Scene(planned.meshes)
    out = np.full((len(indices), 2), np.nan)
    for row, i in enumerate(indices):
        x = float(kin.coordinates[i])
        for column, sign in ((0, 1.0), (1, -1.0)):
            pairs = [spec.play_meshes[(other, sign)] for other in spec.play_neighbours]
            for other, (_, theirs) in zip(spec.play_neighbours, pairs, strict=True):
                plain.set_pose(theirs, kin.pose(other, x))

            def hits(d: float, x: float = x, sign: float = sign, pairs: list = pairs) -> bool:
                for mine, _ in pairs:
                    plain.set_pose(mine, kin.pose(part, x, sign * d))
                return any(plain.collide(mine, theirs) for mine, theirs in pairs)
            out[row, column] = bisect(hits, 0.0, spec.play_limit, BISECT_DEG, check_ends=False).touching
    return out


def test_every_move_is_the_plain_bisections_bracket(planned):
    spec = planned.tasks[0][1][0]
    indices = planned.tasks[0][1][2]
    scene = Counting(planned.meshes)
    out = sweep_poses(scene, spec, "as_built", indices, True)
    assert np.array_equal(out["play"][:, :2], _plain_moves(planned, spec, indices))
    moves = 2 * len(indices)
    c = scene.counts
    # a cold start per sense (two whole queries, then the cuts); the rest between cuts
    assert c["whole distance"] <= 2 * 2 + 0.1 * moves, c
    assert c["cut distance"] >= moves and c["cut collide"] >= moves, c
    assert c["whole collide"] <= 1.5 * moves, c  # the free end's proof (about 5 a move before the cuts)


def test_a_cut_holds_the_faces_nearest_the_contact(planned):
    mesh = next(m for m in planned.meshes if m.name.endswith("+"))
    scene = Scene(planned.meshes)
    cuts = Cuts(scene)
    centroids = mesh.vertices[mesh.faces].mean(axis=1)
    centre = centroids[len(centroids) // 2]
    cut = cuts.seat(("key",), mesh.name, mesh.name, centre, centre)
    part = scene.mesh(cut.mover)
    assert len(part.faces) == CUT_FACES
    # its faces are the mesh's nearest to the centre (by centroid), none farther than its radius
    mine = part.vertices[part.faces].mean(axis=1)
    d = np.sort(np.linalg.norm(centroids - centre, axis=1))
    assert np.linalg.norm(mine - centre, axis=1).max() == pytest.approx(d[CUT_FACES - 1])
    assert cut.radii[0] == pytest.approx(d[CUT_FACES - 1])
    assert not cut.strays(centre, centre) and cut.strays(centre + [cut.radii[0], 0, 0], centre)
    # seated again: the earlier cut leaves the scene
    again = cuts.seat(("key",), mesh.name, mesh.name, centroids[0], centroids[0])
    assert cut.mover not in scene.names and again.mover in scene.names
    cuts.clear()
    assert again.mover not in scene.names


def test_to_local_inverts_a_pose():
    angle = 0.3
    pose = np.eye(4)
    pose[:3, :3] = [[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]]
    pose[:3, 3] = [1.0, 2.0, 3.0]
    p = np.array([0.5, -0.2, 0.7])
    assert to_local(pose, pose[:3, :3] @ p + pose[:3, 3]) == pytest.approx(p)


def test_a_part_between_two_neighbours_is_bracketed_the_same(tmp_path):
    """The middle gear of three, its play measured against both neighbours (a cut per neighbour and
    sense): the moves are the plain bisection's, and each names the neighbour touched."""
    step = write_train(tmp_path / "train.step", gears=3)
    data = train_template(step, gears=3, tol_mm=0.005)
    data["play"]["part"] = "gear_2"
    built = pipeline.build(load(data), tmp_path / "run")
    plan = plan_sweep(built.assembly, built.bodies, None)
    spec, indices = plan.tasks[0][1][0], plan.tasks[0][1][2]
    assert len(spec.play_neighbours) == 2
    scene = Counting(plan.meshes)
    out = sweep_poses(scene, spec, "as_built", indices, True)
    assert np.array_equal(out["play"][:, :2], _plain_moves(plan, spec, indices))
    assert np.all(np.isfinite(out["play"][:, 2:]))  # a neighbour touched each way
    assert scene.counts["cut distance"] > 0
