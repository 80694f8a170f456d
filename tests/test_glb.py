"""The display meshes (gearcheck.cad.display), the closest points of the exact confirmation
(gearcheck.cad.confirm) and the GLB file (gearcheck.report.glb), measured on each template's
check run:

* display meshes against the STL files the run wrote: every display vertex lies within the STL's
  mesh-error bound of the STL's surface (both meshes' vertices lie on the B-rep), every sampled
  display triangle's centroid within the display tolerance plus that bound, and the bounding
  boxes agree within the same; copies share one pair of arrays; triangle budget per template;
* closest points: the exact distance is the distance between the two points returned, each
  point lies on its own solid, and exact_distance is unchanged;
* the GLB re-read by trimesh: one node per part named after it at its pose, the right triangle
  count and material colour on each, copies sharing one mesh; the worst poses as further scenes
  with their closest points; the file is deterministic and glTF-valid in its framing;
* glTF's units and axes: the scene trimesh reads is in metres with Y up, its bounds the assembly's
  millimetre Z-up bounds scaled by 0.001 and turned (x, y, z) → (x, z, −y).
"""

from __future__ import annotations

import io
import json
import struct

import numpy as np
import pytest
from scipy.spatial import cKDTree

TEMPLATES = ["eod_track_drive", "zhurong_differential", "nose_wheel_steering"]
# A browser must draw the whole assembly: triangles drawn (copies counted) per template.
TRIANGLE_BUDGET = 60_000
SAMPLES = 600


@pytest.fixture(scope="module")
def runs(template_check):
    """name → (CheckRun, Scene with the check's worst poses and the mechanism's frames)."""
    from viewer_page import scene_of

    cache = {}

    def get(name: str):
        if name not in cache:
            run = template_check(name)
            cache[name] = (run, scene_of(run.build, run.result))
        return cache[name]

    return get


# --- distance from points to a triangle mesh (exact, no rtree) ----------------------------------


def closest_on_triangles(p, a, b, c):
    """Closest points of triangles (a, b, c) to points p, row by row (Ericson's regions)."""
    ab, ac = b - a, c - a
    d1, d2 = np.einsum("ij,ij->i", ab, p - a), np.einsum("ij,ij->i", ac, p - a)
    d3, d4 = np.einsum("ij,ij->i", ab, p - b), np.einsum("ij,ij->i", ac, p - b)
    d5, d6 = np.einsum("ij,ij->i", ab, p - c), np.einsum("ij,ij->i", ac, p - c)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    out = np.empty_like(p)
    done = np.zeros(len(p), bool)

    def put(mask, value):
        m = mask & ~done
        out[m] = value[m]
        done[m] = True

    with np.errstate(divide="ignore", invalid="ignore"):
        put((d1 <= 0) & (d2 <= 0), a)
        put((d3 >= 0) & (d4 <= d3), b)
        put((d6 >= 0) & (d5 <= d6), c)
        put((vc <= 0) & (d1 >= 0) & (d3 <= 0), a + (d1 / (d1 - d3))[:, None] * ab)
        put((vb <= 0) & (d2 >= 0) & (d6 <= 0), a + (d2 / (d2 - d6))[:, None] * ac)
        put((va <= 0) & (d4 >= d3) & (d5 >= d6), b + ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None] * (c - b))
        s = 1.0 / (va + vb + vc)
        put(np.ones(len(p), bool), a + (vb * s)[:, None] * ab + (vc * s)[:, None] * ac)
    return out


def distance_to_mesh(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Exact distance from each point to the mesh's surface: a first guess from the nearest
    centroids and the largest triangles, then every triangle whose centroid could still be
    closer (its centroid within the guess plus its own reach)."""
    tri = vertices[faces]
    centroid = tri.mean(axis=1)
    reach = np.linalg.norm(tri - centroid[:, None], axis=2).max(axis=1)
    large = np.flatnonzero(reach > np.quantile(reach, 0.98))
    small_reach = float(np.delete(reach, large).max()) if len(large) < len(reach) else 0.0
    tree = cKDTree(centroid)
    _, nearest = tree.query(points, k=min(8, len(centroid)))
    out = np.empty(len(points))

    def dist(p, idx):
        idx = np.asarray(idx)
        q = closest_on_triangles(np.repeat(p[None], len(idx), 0), tri[idx, 0], tri[idx, 1], tri[idx, 2])
        return float(np.linalg.norm(q - p, axis=1).min())

    for i, p in enumerate(points):
        d = dist(p, np.unique(np.concatenate([np.atleast_1d(nearest[i]), large])))
        ball = tree.query_ball_point(p, d + small_reach)
        out[i] = min(d, dist(p, ball)) if ball else d
    return out


def test_distance_to_mesh_is_exact():
    """The helper against brute force on a coarse sphere and points around it."""
    from gearcheck.report.glb import icosphere

    v, f = icosphere(10.0, 2)
    v, f = v.astype(float), f.astype(np.int64)
    pts = np.random.default_rng(1).normal(size=(50, 3)) * 8.0
    brute = [float(np.linalg.norm(closest_on_triangles(np.repeat(p[None], len(f), 0), *v[f].transpose(1, 0, 2)) - p,
                                  axis=1).min()) for p in pts]
    assert np.allclose(distance_to_mesh(pts, v, f), brute, atol=1e-12)


# --- display meshes --------------------------------------------------------------------------


@pytest.mark.parametrize("name", TEMPLATES)
def test_display_meshes_follow_the_stl(runs, name):
    import trimesh

    from gearcheck.cad.display import display_tolerance

    run, scene = runs(name)
    tol = display_tolerance(run.build.parts)
    manifest = {p["name"]: p for p in run.build.manifest["parts"]}
    drawn = sum(p.triangles for p in scene.parts)
    assert drawn <= TRIANGLE_BUDGET, f"{drawn} triangles to draw"
    rng = np.random.default_rng(0)
    seen: set[int] = set()
    for part in scene.parts:
        stl = trimesh.load(run.folder / manifest[part.name]["stl"]["file"], file_type="stl", process=False)
        bound = manifest[part.name]["mesh_error_bound_mm"]
        world = scene.world_vertices()[part.name]
        lo, hi = np.asarray(stl.vertices).min(axis=0), np.asarray(stl.vertices).max(axis=0)
        assert np.allclose(world.min(axis=0), lo, atol=tol + bound), part.name
        assert np.allclose(world.max(axis=0), hi, atol=tol + bound), part.name
        if id(part.vertices) in seen:  # a copy: the same arrays, measured once
            continue
        seen.add(id(part.vertices))
        sv, sf = np.asarray(stl.vertices, float), np.asarray(stl.faces, np.int64)
        pick_v = rng.choice(len(world), min(SAMPLES, len(world)), replace=False)
        pick_f = rng.choice(part.triangles, min(SAMPLES, part.triangles), replace=False)
        on_surface = distance_to_mesh(world[pick_v], sv, sf)
        centroids = distance_to_mesh(world[np.asarray(part.faces)[pick_f]].mean(axis=1), sv, sf)
        # STL vertices are stored as float32: a few 1e-5 mm of rounding
        assert on_surface.max() <= bound + 1e-4, (part.name, on_surface.max(), bound)
        assert centroids.max() <= tol + bound + 1e-4, (part.name, centroids.max(), tol)


@pytest.mark.parametrize("name", TEMPLATES)
def test_copies_share_one_display_mesh(runs, name):
    run, scene = runs(name)
    solids = {id(p.solid) for p in run.build.parts}
    meshes = {id(p.vertices) for p in scene.parts}
    assert len(meshes) == len(solids)
    for part, dp in zip(run.build.parts, scene.parts, strict=True):
        assert dp.name == part.name and dp.material == part.material
        assert np.array_equal(dp.pose, part.pose)
        assert np.asarray(dp.faces).max() < len(dp.vertices)


# --- closest points --------------------------------------------------------------------------


@pytest.mark.parametrize("name", TEMPLATES)
def test_closest_points_lie_on_the_solids(runs, name):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.gp import gp_Pnt

    from gearcheck.cad.confirm import _posed, exact_closest, exact_distance

    run, scene = runs(name)
    by_name = {p.name: p for p in run.build.parts}
    assert scene.worst and len(scene.worst) == len(run.result.worst_poses)
    for worst, view, confirmed in zip(run.result.worst_poses, scene.worst, run.result.confirmations, strict=True):
        a, b = np.asarray(view.point_a), np.asarray(view.point_b)
        assert abs(float(np.linalg.norm(b - a)) - view.distance_mm) < 1e-6, worst.label
        assert abs(view.distance_mm - confirmed.brep_mm) < 1e-6, worst.label  # what the check confirmed
        for point, part, pose, scale in ((a, worst.part_a, worst.pose_a, worst.scale_a),
                                         (b, worst.part_b, worst.pose_b, worst.scale_b)):
            solid = _posed(by_name, part, pose, scale)
            probe = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*point)).Vertex(), solid.wrapped)
            assert probe.Value() < 1e-6, (worst.label, part, probe.Value(), point)
    worst = run.result.worst_poses[-1]
    d, _, _ = exact_closest(by_name, worst)
    assert d == pytest.approx(exact_distance(by_name, worst), abs=1e-9)


# --- GLB -------------------------------------------------------------------------------------


def glb_json(data: bytes) -> dict:
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert (magic, version, length) == (0x46546C67, 2, len(data))
    chunk_len, chunk_type = struct.unpack_from("<II", data, 12)
    assert chunk_type == 0x4E4F534A and chunk_len % 4 == 0
    bin_len, bin_type = struct.unpack_from("<II", data, 20 + chunk_len)
    assert bin_type == 0x004E4942 and 28 + chunk_len + bin_len == len(data)
    return json.loads(data[20:20 + chunk_len])


@pytest.mark.parametrize("name", TEMPLATES)
def test_glb_reads_back_with_named_coloured_nodes(runs, name):
    import trimesh

    from gearcheck.report.glb import glb_bytes, srgb_to_linear

    _, scene = runs(name)
    data = glb_bytes(scene)
    assert data == glb_bytes(scene), "GLB bytes differ between two writes"
    loaded = trimesh.load(io.BytesIO(data), file_type="glb")
    names = {p.name for p in scene.parts}
    assert names <= set(loaded.graph.nodes_geometry)
    geometry_of = {}
    to_gltf = np.array([[1e-3, 0, 0, 0], [0, 0, 1e-3, 0], [0, -1e-3, 0, 0], [0, 0, 0, 1]], float)
    for part in scene.parts:
        transform, key = loaded.graph[part.name]
        assert np.allclose(transform, to_gltf @ part.pose, atol=1e-9), part.name
        mesh = loaded.geometry[key]
        assert len(mesh.faces) == part.triangles, part.name
        assert np.allclose(np.asarray(mesh.vertices), np.asarray(part.vertices), atol=1e-5)
        colour = np.asarray(mesh.visual.material.baseColorFactor[:3], float)
        if colour.max() > 1.0:  # trimesh hands back 8-bit channels
            colour = colour / 255.0
        assert np.allclose(colour, [srgb_to_linear(c) for c in part.color], atol=1.0 / 255 + 1e-9), part.name
        geometry_of[part.name] = key
    assert len(set(geometry_of.values())) == len({id(p.vertices) for p in scene.parts}), "copies must share a mesh"

    # metres, Y up: the bounds trimesh reads are the assembly's (mm, Z up) scaled and turned
    world = np.concatenate(list(scene.world_vertices().values()))
    lo, hi = world.min(axis=0), world.max(axis=0)
    expected = np.array([[lo[0], lo[2], -hi[1]], [hi[0], hi[2], -lo[1]]]) * 1e-3
    assert np.allclose(loaded.bounds, expected, atol=1e-7), (loaded.bounds, expected)
    tree = glb_json(data)
    assert tree["asset"]["extras"]["units"].startswith("m, Y up")
    assert tree["scenes"][0]["nodes"] == [tree["nodes"].index(next(n for n in tree["nodes"]
                                                                    if n["name"] == f"{scene.name}_m_yup"))]
    assert [s["name"] for s in tree["scenes"]] == [scene.name] + [f"worst_{i + 1}" for i in range(len(scene.worst))]
    for view, entry in zip(scene.worst, tree["scenes"][1:], strict=True):
        assert entry["extras"]["distance_mm"] == pytest.approx(view.distance_mm, abs=1e-12)
        assert np.allclose(entry["extras"]["point_a"], view.point_a)
        assert np.allclose(entry["extras"]["point_b"], view.point_b)
        (root,) = entry["nodes"]
        assert tree["nodes"][root]["name"] == entry["name"] + "_m_yup"
        nodes = {tree["nodes"][i]["name"]: tree["nodes"][i] for i in tree["nodes"][root]["children"]}
        prefix = entry["name"] + "/"
        assert {prefix + n for n in names} <= set(nodes)
        for part, pose in view.poses.items():
            m = np.array(nodes[prefix + part]["matrix"]).reshape(4, 4).T
            scale = view.scales.get(part, 1.0)
            assert np.allclose(m[:3, :3], scale * np.asarray(pose)[:3, :3], atol=1e-8)
            assert np.allclose(m[:3, 3], np.asarray(pose)[:3, 3], atol=1e-6)
        marker = np.array(nodes[prefix + "closest_a"]["matrix"]).reshape(4, 4).T
        assert np.allclose(marker[:3, 3], view.point_a)
    if scene.frames:
        (animation,) = tree["animations"]
        assert len(animation["extras"]["frames"]) == len(scene.frames)
        times = tree["accessors"][animation["samplers"][0]["input"]]
        assert times["count"] == len(scene.frames)
