"""The FCL layer alone, on meshes whose answers are known exactly (boxes: flat faces, no chord error)."""

import numpy as np
import pytest

from gearcheck.sweep.engine import MeshData, Scene, bisect_contact


def box(name, size):
    sx, sy, sz = (s / 2 for s in size)
    v = np.array([[x, y, z] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)], float)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return MeshData(name, v, f)


def translation(x, y=0.0, z=0.0):
    t = np.eye(4)
    t[:3, 3] = (x, y, z)
    return t


def test_distance_and_nearest_points():
    scene = Scene([box("a", (2, 2, 2)), box("b", (2, 2, 2))])
    scene.set_pose("b", translation(2.5))
    d = scene.distance("a", "b")
    assert d.distance == pytest.approx(0.5, abs=1e-9)
    assert d.point_a[0] == pytest.approx(1.0, abs=1e-9)
    assert d.point_b[0] == pytest.approx(1.5, abs=1e-9)
    assert not scene.collide("a", "b")
    scene.set_pose("b", translation(1.9))
    assert scene.collide("a", "b")


def test_a_body_is_built_when_first_used():
    scene = Scene([box("a", (2, 2, 2)), box("b", (2, 2, 2)), box("c", (1, 1, 1))])
    assert scene.names == ["a", "b", "c"] and scene.built == []
    scene.set_pose("b", translation(2.5))
    assert scene.built == ["b"]
    assert scene.distance("a", "b").distance == pytest.approx(0.5, abs=1e-9)
    assert sorted(scene.built) == ["a", "b"]  # "c" never used: no BVH
    scene.build()
    assert sorted(scene.built) == ["a", "b", "c"]
    assert not scene.collide("a", "c")  # c lies wholly inside a: surfaces, no intersection


def test_bisection_finds_contact_from_both_sides():
    scene = Scene([box("a", (2, 2, 2)), box("b", (1, 1, 1))])

    def collides(x):
        scene.set_pose("b", translation(x))
        return scene.collide("a", "b")

    # touching=1.2 overlaps partly: FCL mesh–mesh tests surface triangles, so a body wholly
    # inside another is not a collision (sweep steps must stay small against tooth size).
    bracket = bisect_contact(collides, free=3.0, touching=1.2, tol=1e-7)
    assert bracket.value == pytest.approx(1.5, abs=1e-6)
    assert not collides(bracket.free) and collides(bracket.touching)


def test_bisection_refuses_a_pair_that_never_touches():
    scene = Scene([box("a", (2, 2, 2)), box("b", (1, 1, 1))])

    def collides(x):
        scene.set_pose("b", translation(x))
        return scene.collide("a", "b")

    with pytest.raises(ValueError, match="does not reach contact"):
        bisect_contact(collides, free=5.0, touching=4.0)


def test_contact_proven_from_both_sides_on_a_known_gap():
    from gearcheck.sweep.tools import prove_contact

    scene = Scene([box("a", (2, 2, 2)), box("b", (1, 1, 1))])
    pose = translation(2.0)  # b's near face at x = 1.5: gap 0.5 to a's face at x = 1
    proof = prove_contact(scene, "a", "b", pose, np.array([-1.0, 0, 0]), 0.5, 0.02, "box", 1e-8)
    assert proof.free_at_minus and proof.touching_at_plus and proof.holds(1e-6)
    assert proof.contact_mm == pytest.approx(0.5, abs=1e-7)
    wrong = prove_contact(scene, "a", "b", pose, np.array([-1.0, 0, 0]), 0.3, 0.02, "box", 1e-8)
    assert not wrong.touching_at_plus and not wrong.holds(0.01)  # a clearance claimed too small is caught


def test_clearing_and_contact_distances_and_events():
    from gearcheck.sweep.tools import clearing_distance, contact_distance, extrapolated_event, smallest_clearing_move

    scene = Scene([box("a", (2, 2, 2)), box("b", (1, 1, 1))])

    def hits_from(x0):
        def hits(d):
            scene.set_pose("b", translation(x0 + d))
            return scene.collide("a", "b")
        return hits

    assert clearing_distance(hits_from(1.4), 0.01, 5.0, 1e-8) == pytest.approx(0.1, abs=1e-7)
    assert contact_distance(lambda d: hits_from(2.0)(-d), 0.01, 5.0, 1e-8) == pytest.approx(0.5, abs=1e-7)
    assert smallest_clearing_move(hits_from(1.4), 1.0, 0.0, 1e-8) == pytest.approx(0.1, abs=1e-7)
    assert smallest_clearing_move(lambda d: True, 1.0, 0.0, 1e-8) is None  # jammed: no jump past
    # an event decided at an offset δ, linear in δ, extrapolated to δ = 0
    grid = np.linspace(0.0, 1.0, 11)
    x, bracket = extrapolated_event(grid, lambda d: grid >= 0.42 + 0.3 * d, lambda d, x: x >= 0.42 + 0.3 * d,
                                    0.01, 1e-10, first=True)
    assert x == pytest.approx(0.42, abs=1e-9) and bracket.free < 0.423 <= bracket.touching
