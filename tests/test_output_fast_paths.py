"""The faster ways the build, the confirmation, the pictures and the seal do their work give what
the plain ways give, bit for bit: edge counting on integer keys instead of rows of floats, one
FCL scene per pair of parts at the worst poses, the picture process started before its scene.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gearcheck.verify import stl_is_watertight, vertex_index

ROOT = Path(__file__).resolve().parents[1]


def reference_stl_watertight(triangles: np.ndarray) -> bool:
    """Every undirected edge shared by exactly two triangles, vertices matched by np.unique on
    rows of floats (the plain way)."""
    if len(triangles) == 0:
        return False
    _, index = np.unique(triangles.reshape(-1, 3), axis=0, return_inverse=True)
    faces = index.reshape(-1, 3)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def reference_mesh_checks(faces: np.ndarray) -> tuple[bool, bool]:
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, undirected = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    _, once = np.unique(directed, axis=0, return_counts=True)
    return bool(np.all(undirected == 2)), bool(np.all(once == 1))


TETRA_POINTS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float32)
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])


def test_vertex_index_matches_equal_coordinates_only():
    points = np.array([[0.0, 1, 2], [-0.0, 1, 2], [0, 1, 2.0000002], [np.nan, 0, 0], [np.nan, 0, 0], [0, 1, 2]],
                      np.float32)
    index = vertex_index(points)
    assert index[0] == index[1] == index[5], "-0.0 is 0.0"
    assert len({index[0], index[2], index[3], index[4]}) == 4, "NaN equals nothing, nearby floats are other points"


def test_stl_watertight_as_the_row_sort_on_random_soups():
    rng = np.random.default_rng(7)
    for k in range(4000):
        points = rng.integers(-2, 3, (6, 3)).astype(np.float32)
        points[points == 0] *= rng.choice([1.0, -1.0], size=int((points == 0).sum()))  # -0.0 and 0.0
        if k % 7 == 0:
            points[rng.integers(6), rng.integers(3)] = np.nan
        triangles = points[rng.integers(0, 6, (rng.integers(1, 9), 3))]
        assert stl_is_watertight(triangles) == reference_stl_watertight(triangles), triangles
    closed = TETRA_POINTS[TETRA_FACES].copy()
    closed[0, 0, 0] = -0.0
    assert stl_is_watertight(closed) and reference_stl_watertight(closed)
    assert not stl_is_watertight(closed[:3]) and not stl_is_watertight(closed[:0])


def test_mesh_edge_checks_as_the_row_sort():
    from gearcheck.cad.mesh import TriMesh

    rng = np.random.default_rng(3)
    for _ in range(4000):
        n = int(rng.integers(1, 7))
        faces = rng.integers(0, n, (int(rng.integers(0, 9)), 3)).astype(np.int64)
        mesh = TriMesh(np.zeros((n, 3)), faces, np.zeros(len(faces), int), 0.01, 0.0)
        assert (mesh.is_watertight(), mesh.is_winding_consistent()) == reference_mesh_checks(faces), faces
    flipped = TETRA_FACES.copy()
    flipped[0] = flipped[0][::-1]
    mesh = TriMesh(TETRA_POINTS.astype(float), flipped, np.zeros(4, int), 0.01, 0.0)
    assert mesh.is_watertight() and not mesh.is_winding_consistent()


def test_stls_of_a_build_watertight_as_the_row_sort(build_bodies):
    from gearcheck.verify import read_stl

    run = build_bodies("nose_wheel_steering")
    stls = sorted(Path(run.folder).glob("*.stl"))
    assert stls
    for path in stls:
        triangles = read_stl(path)
        assert stl_is_watertight(triangles) == reference_stl_watertight(triangles) is True, path.name
        assert not stl_is_watertight(triangles[1:]) and not reference_stl_watertight(triangles[1:]), path.name


def test_mesh_pairs_answer_as_the_sweep_tools(template_check):
    """One scene per pair at the worst poses: the same overlap and nearest points as building
    the scene for each question."""
    from gearcheck.confirmation import _MeshPairs
    from gearcheck.sweep.tools import mesh_nearest_midpoint, meshes_overlap

    run = template_check("eod_track_drive")
    bodies, worst = run.build.bodies, run.result.worst_poses
    assert worst
    pairs = _MeshPairs(bodies)
    for w in [*worst, *worst]:  # asked twice: a scene posed again answers the same
        assert pairs.overlap(w) == meshes_overlap(bodies, w)
        mine, theirs = pairs.nearest_midpoint(w), mesh_nearest_midpoint(bodies, w)
        assert (mine is None) == (theirs is None)
        if mine is not None:
            assert np.array_equal(mine, theirs)


@pytest.fixture(scope="module")
def scene():
    from viewer_page import made_up_scene

    return made_up_scene("nose_wheel_steering", frames=False)


def test_picture_process_started_early_draws_the_same_pictures(scene):
    from gearcheck.report.pictures import Drawing, PicturesUnavailable, pictures

    try:
        at_once = pictures(scene)
    except PicturesUnavailable as exc:
        pytest.skip(f"no offscreen drawing here: {exc}")
    with Drawing() as drawing:
        drawing.assembly(scene)
        drawing.worst(scene)
        early = drawing.result()
    assert list(early) == list(at_once) == ["assembly.png", "worst_1.png"]
    assert early == at_once


def test_picture_process_ended_when_its_pictures_are_not_collected(scene):
    from gearcheck.report.pictures import Drawing

    with Drawing() as drawing:
        drawing.assembly(scene)
        proc = drawing._child._proc
    assert proc.poll() is not None, "leaving the block ends the process"
    with Drawing() as drawing:  # never given a scene (a run that failed before its geometry)
        proc = drawing._child._proc
    assert proc.poll() is not None
    with pytest.raises(RuntimeError), Drawing() as drawing:
        drawing.worst(scene)  # the scene as built comes first


def test_picture_process_death_is_pictures_unavailable(scene, monkeypatch):
    """A picture process that dies (no EGL, no OSMesa) gives the reason, not a hang."""
    from gearcheck.report import pictures as pics

    monkeypatch.setattr(pics.sys, "executable", str(ROOT / "tests" / "no-such-python"))
    with pytest.raises(OSError):
        pics.Drawing()
    monkeypatch.undo()
    with pics.Drawing() as drawing:
        drawing._child.kill()
        drawing.assembly(scene)
        drawing.worst(scene)
        with pytest.raises(pics.PicturesUnavailable) as caught:
            drawing.result()
    assert "signal 9" in caught.value.reason


def some_plots():
    from gearcheck.results import Plot, Series

    xs = [float(x) for x in np.linspace(0.0, 30.0, 61)]
    wave = [float(np.sin(np.radians(12.0 * x))) for x in xs]
    return [Plot("play over the pinion angle", "pinion angle (deg)", "play (arcmin)",
                 [Series("left", xs, wave), Series("right", xs, [0.5 * w + 1 for w in wave], "points")],
                 markers=[("contact", 12.5)], hlines=[("limit", 1.2)], caption="a made-up plot"),
            Plot("distance", "angle (deg)", "distance (mm)", [Series("d", xs, [0.01 * x for x in xs])])]


def test_plot_process_draws_the_same_html():
    from gearcheck.report.plots import Plotting, plot_html

    plots = some_plots()
    with Plotting() as plotting:
        plotting.draw(plots)
        there = plotting.result()
    assert there == [plot_html(p) for p in plots]
    with Plotting() as plotting:
        plotting.draw([])
        assert plotting.result() == []


def test_plot_process_death_is_plots_unavailable():
    from gearcheck.report.plots import Plotting, PlotsUnavailable

    with Plotting() as plotting:
        plotting._child.kill()
        plotting.draw(some_plots())
        with pytest.raises(PlotsUnavailable):
            plotting.result()
    with pytest.raises(RuntimeError), Plotting() as plotting:
        plotting.result()  # the plots come first


def test_report_plots_drawn_here_when_the_plot_process_fails(template_check):
    """The pipeline falls back to drawing the plots itself: the same HTML."""
    from gearcheck.pipeline import _plots
    from gearcheck.report.html import plots_html
    from gearcheck.report.plots import Plotting

    result = template_check("nose_wheel_steering").result
    assert result.plots
    with Plotting() as plotting:
        plotting._child.kill()
        plotting.draw(result.plots)
        assert _plots(result, plotting) == plots_html(result)
    assert _plots(result, None) == plots_html(result)
