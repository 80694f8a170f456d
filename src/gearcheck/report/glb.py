"""The run's geometry as one binary glTF file (GLB) beside the STEP: for viewers, Blender, a web
page — the display meshes of :mod:`gearcheck.scene`, not the checked ones (those are the STL).

Layout of the file (glTF 2.0, written here with numpy and json: deterministic bytes):

* scene 0 (the default), named after the run: one node per part, named after the part, at its
  pose as built; copies (the chain links, the two big gears) share one mesh;
* one more scene per worst pose of the sweep (``worst_1``, ``worst_2``, …): every part at that
  pose (node ``worst_1/<part>``), the two measured parts' closest points as small spheres and the
  line between them (``worst_1/closest_a``, ``…/closest_b``, ``…/gap``); the scene's extras hold
  the label, the pair, the points and the distance;
* with motion frames, an animation ``motion`` stepping the moving parts of scene 0 through the
  frames (one key frame per second, linear).

Units and axes as glTF specifies: metres, Y up. Each scene holds one root node (``<scene>_m_yup``)
whose matrix scales gearcheck's millimetres to metres and turns its Z-up frame to Y up (x, y, z) →
(x, z, −y); below it every node keeps the part's pose in millimetres, so the animation and the
extras' figures (``distance_mm``, ``point_a`` …, in the Z-up millimetre frame of the STEP and the
STL) read as everywhere else in gearcheck. Blender, three.js and other viewers then show a 240 mm
sprocket as 0.24 m, standing the right way up. Colours are each part's material colour (sRGB) as PBR base
colour (linear, as glTF requires). Normals are per vertex within each B-rep face (the display
mesh keeps each face's own vertices), so faces shade smoothly and their edges stay sharp.
"""

from __future__ import annotations

import json
import math
import struct

import numpy as np

from gearcheck import __version__
from gearcheck.scene import PoseView, Scene

GLB_MAGIC = 0x46546C67  # "glTF"
CHUNK_JSON = 0x4E4F534A
CHUNK_BIN = 0x004E4942
FLOAT, UINT32 = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963
MODE_LINES, MODE_TRIANGLES = 1, 4
# scene root: millimetres → metres, Z up → Y up ((x, y, z) → (x, z, −y)), as glTF specifies
TO_GLTF = np.array([[1e-3, 0.0, 0.0, 0.0], [0.0, 0.0, 1e-3, 0.0], [0.0, -1e-3, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
# closest-point markers: radius as a fraction of the assembly's bounding-box diagonal
MARKER_FRACTION = 0.006
MARKER_RGB = {"closest_a": (0.85, 0.1, 0.1), "closest_b": (0.1, 0.3, 0.9), "gap": (0.95, 0.65, 0.0)}


def srgb_to_linear(c: float) -> float:
    """One sRGB channel (0…1) as linear light (glTF's baseColorFactor)."""
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit area-weighted vertex normals (float32; +z where a vertex has no area)."""
    v = np.asarray(vertices, float)
    f = np.asarray(faces, np.int64)
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for k in range(3):
        np.add.at(n, f[:, k], cross)
    length = np.linalg.norm(n, axis=1)
    n[length == 0] = (0.0, 0.0, 1.0)
    length[length == 0] = 1.0
    return (n / length[:, None]).astype(np.float32)


def icosphere(radius: float, subdivisions: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A small sphere (vertices, faces) about the origin."""
    t = (1.0 + 5 ** 0.5) / 2.0
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
         (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    faces = list(f)
    for _ in range(subdivisions):
        mid: dict[tuple[int, int], int] = {}
        new = []
        for tri in faces:
            ends = []
            for i, j in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
                key = (min(i, j), max(i, j))
                if key not in mid:
                    p = verts[i] + verts[j]
                    verts.append(p / np.linalg.norm(p))
                    mid[key] = len(verts) - 1
                ends.append(mid[key])
            ab, bc, ca = ends
            new += [(tri[0], ab, ca), (tri[1], bc, ab), (tri[2], ca, bc), (ab, bc, ca)]
        faces = new
    return (radius * np.array(verts)).astype(np.float32), np.array(faces, np.uint32)


def _matrix(m: np.ndarray) -> list[float]:
    """A 4×4 as glTF's column-major list (rounded to keep the JSON short and stable)."""
    return [round(float(x), 9) + 0.0 for x in np.asarray(m, float).T.reshape(-1)]


def _scaled(pose: np.ndarray, scale: float) -> np.ndarray:
    out = np.asarray(pose, float).copy()
    if scale != 1.0:
        out[:3, :3] *= scale
    return out


def _quaternion(r: np.ndarray) -> list[float]:
    """Unit quaternion (x, y, z, w) of a rotation matrix."""
    m = np.asarray(r, float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    arr = np.array(q)
    return list(arr / np.linalg.norm(arr))


class _Writer:
    """Accumulates the binary buffer and the glTF JSON lists."""

    def __init__(self) -> None:
        self.bin = bytearray()
        self.tree: dict = {"bufferViews": [], "accessors": [], "meshes": [], "materials": [], "nodes": []}
        self._materials: dict[tuple, int] = {}

    def view(self, data: bytes, target: int | None = None) -> int:
        while len(self.bin) % 4:
            self.bin.append(0)
        entry = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target is not None:
            entry["target"] = target
        self.bin.extend(data)
        self.tree["bufferViews"].append(entry)
        return len(self.tree["bufferViews"]) - 1

    def accessor(self, array: np.ndarray, kind: str, target: int | None, bounds: bool = False) -> int:
        comp = FLOAT if array.dtype == np.float32 else UINT32
        entry = {"bufferView": self.view(array.tobytes(), target), "componentType": comp,
                 "count": int(array.shape[0]) if kind != "SCALAR" else int(array.size), "type": kind}
        if bounds:
            entry["min"] = [float(x) for x in array.min(axis=0)]
            entry["max"] = [float(x) for x in array.max(axis=0)]
        self.tree["accessors"].append(entry)
        return len(self.tree["accessors"]) - 1

    def material(self, name: str, rgb: tuple[float, float, float], metallic: float = 0.6) -> int:
        key = (name, tuple(round(c, 6) for c in rgb), metallic)
        if key not in self._materials:
            self.tree["materials"].append({
                "name": name,
                "pbrMetallicRoughness": {"baseColorFactor": [round(srgb_to_linear(c), 6) for c in rgb] + [1.0],
                                         "metallicFactor": metallic, "roughnessFactor": 0.5},
                "extras": {"srgb": [float(c) for c in rgb]},
            })
            self._materials[key] = len(self.tree["materials"]) - 1
        return self._materials[key]

    def mesh(self, name: str, vertices: np.ndarray, faces: np.ndarray, material: int, normals: bool = True) -> int:
        v = np.ascontiguousarray(vertices, np.float32)
        attributes = {"POSITION": self.accessor(v, "VEC3", ARRAY_BUFFER, bounds=True)}
        if normals:
            attributes["NORMAL"] = self.accessor(vertex_normals(v, faces), "VEC3", ARRAY_BUFFER)
        indices = self.accessor(np.ascontiguousarray(faces, np.uint32).reshape(-1), "SCALAR",
                                ELEMENT_ARRAY_BUFFER)
        mode = MODE_TRIANGLES if np.asarray(faces).ndim == 2 and np.asarray(faces).shape[1] == 3 else MODE_LINES
        self.tree["meshes"].append({"name": name, "primitives": [
            {"attributes": attributes, "indices": indices, "material": material, "mode": mode}]})
        return len(self.tree["meshes"]) - 1

    def node(self, name: str, mesh: int | None = None, matrix: np.ndarray | None = None,
             extras: dict | None = None, children: list[int] | None = None) -> int:
        entry: dict = {"name": name}
        if mesh is not None:
            entry["mesh"] = mesh
        if matrix is not None and not np.allclose(matrix, np.eye(4), atol=0.0):
            entry["matrix"] = _matrix(matrix)
        if children:
            entry["children"] = children
        if extras:
            entry["extras"] = extras
        self.tree["nodes"].append(entry)
        return len(self.tree["nodes"]) - 1

    def glb(self) -> bytes:
        while len(self.bin) % 4:
            self.bin.append(0)
        self.tree["buffers"] = [{"byteLength": len(self.bin)}]
        text = json.dumps(self.tree, separators=(",", ":"), sort_keys=False, allow_nan=False).encode()
        text += b" " * (-len(text) % 4)
        total = 12 + 8 + len(text) + 8 + len(self.bin)
        return (struct.pack("<III", GLB_MAGIC, 2, total) + struct.pack("<II", len(text), CHUNK_JSON) + text
                + struct.pack("<II", len(self.bin), CHUNK_BIN) + bytes(self.bin))


def _extent(scene: Scene) -> float:
    world = scene.world_vertices()
    if not world:
        return 1.0
    allv = np.concatenate(list(world.values()))
    return float(np.linalg.norm(allv.max(axis=0) - allv.min(axis=0))) or 1.0


def _worst_extras(view: PoseView) -> dict:
    extras: dict = {"label": view.label, "note": view.note}
    if view.parts is not None:
        extras["parts"] = list(view.parts)
    if view.distance_mm is not None and math.isfinite(view.distance_mm):
        extras["distance_mm"] = float(view.distance_mm)
    for key, point in (("point_a", view.point_a), ("point_b", view.point_b)):
        if point is not None:
            extras[key] = [float(x) for x in np.asarray(point, float)]
    return extras


def glb_bytes(scene: Scene) -> bytes:
    """The scene as a GLB file (bytes): see the module docstring for its layout."""
    w = _Writer()
    w.tree["asset"] = {"version": "2.0", "generator": f"gearcheck {__version__}",
                       "extras": {"units": "m, Y up (each scene's root node scales gearcheck's Z-up millimetres)",
                                  "figures": "extras' *_mm and points: millimetres in the Z-up frame of the STEP"}}
    meshes: dict[tuple[int, int, tuple], int] = {}
    part_mesh: dict[str, int] = {}
    for p in scene.parts:
        key = (id(p.vertices), id(p.faces), p.color)
        if key not in meshes:
            material = w.material(p.material, p.color)
            meshes[key] = w.mesh(p.name, p.vertices, p.faces, material)
        part_mesh[p.name] = meshes[key]

    painted: dict[str, list[int]] = {}  # the overlays' nodes by host (children of its as-built node)
    for o in scene.overlays:
        mesh = w.mesh(o.name, np.asarray(o.vertices, np.float32), np.asarray(o.faces, np.uint32),
                      w.material(o.name, o.color, 0.0))
        painted.setdefault(o.host, []).append(w.node(o.name, mesh, None, {"label": o.label} if o.label else None))

    def part_nodes(prefix: str, view: PoseView | None) -> list[int]:
        out = []
        for p in scene.parts:
            pose = p.pose if view is None else np.asarray(view.poses.get(p.name, p.pose), float)
            scale = 1.0 if view is None else float(view.scales.get(p.name, 1.0))
            extras = {"material": p.material} if view is None else None
            children = painted.get(p.name) if view is None else None
            out.append(w.node(prefix + p.name, part_mesh[p.name], _scaled(pose, scale), extras, children))
        return out

    def rooted(name: str, children: list[int]) -> list[int]:
        return [w.node(f"{name}_m_yup", None, TO_GLTF, children=children)]

    roots = part_nodes("", None)
    scenes = [{"name": scene.name, "nodes": rooted(scene.name, roots), "extras": {"units": "m"}}]

    radius = MARKER_FRACTION * _extent(scene)
    sphere = icosphere(radius)
    marker_mesh: dict[str, int] = {}
    for i, view in enumerate(scene.worst, start=1):
        prefix = f"worst_{i}/"
        nodes = part_nodes(prefix, view)
        if view.point_a is not None and view.point_b is not None:
            a, b = np.asarray(view.point_a, float), np.asarray(view.point_b, float)
            for marker, point in (("closest_a", a), ("closest_b", b)):
                if marker not in marker_mesh:
                    marker_mesh[marker] = w.mesh(marker, *sphere, w.material(marker, MARKER_RGB[marker], 0.0))
                m = np.eye(4)
                m[:3, 3] = point
                nodes.append(w.node(prefix + marker, marker_mesh[marker], m))
            line = w.mesh(prefix + "gap", np.array([a, b], np.float32), np.array([[0, 1]], np.uint32),
                          w.material("gap", MARKER_RGB["gap"], 0.0), normals=False)
            nodes.append(w.node(prefix + "gap", line))
        scenes.append({"name": f"worst_{i}", "nodes": rooted(f"worst_{i}", nodes), "extras": _worst_extras(view)})
    w.tree["scenes"] = scenes
    w.tree["scene"] = 0
    if scene.frames:
        _animation(w, scene, roots)
    return w.glb()


def _animation(w: _Writer, scene: Scene, roots: list[int]) -> None:
    """The motion frames as one animation of scene 0's nodes (1 s per frame, linear)."""
    times = np.arange(len(scene.frames), dtype=np.float32)
    time_acc = w.accessor(times, "SCALAR", None)
    w.tree["accessors"][time_acc]["min"] = [float(times[0])]
    w.tree["accessors"][time_acc]["max"] = [float(times[-1])]
    channels: list[dict] = []
    samplers: list[dict] = []
    for node, p in zip(roots, scene.parts, strict=True):
        poses = [np.asarray(f.poses.get(p.name, p.pose), float) for f in scene.frames]
        if all(np.allclose(q, p.pose) for q in poses):
            continue
        t = np.array([q[:3, 3] for q in poses], np.float32)
        r = np.array([_quaternion(q[:3, :3]) for q in poses], float)
        for k in range(1, len(r)):  # the shorter way round between key frames
            if float(np.dot(r[k], r[k - 1])) < 0.0:
                r[k] = -r[k]
        for path, values, kind in (("translation", t, "VEC3"), ("rotation", r.astype(np.float32), "VEC4")):
            samplers.append({"input": time_acc, "output": w.accessor(values, kind, None), "interpolation": "LINEAR"})
            channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})
    if channels:
        # an animated node must carry TRS, not a matrix: give the moving nodes their built pose as TRS
        for ch in channels:
            entry = w.tree["nodes"][ch["target"]["node"]]
            if "matrix" in entry:
                m = np.array(entry.pop("matrix")).reshape(4, 4).T
                entry["translation"] = [float(x) for x in m[:3, 3]]
                entry["rotation"] = [float(x) for x in _quaternion(m[:3, :3])]
        animation: dict = {"name": "motion", "channels": channels, "samplers": samplers,
                            "extras": {"label": scene.frames_label, "frames": [f.label for f in scene.frames]}}
        w.tree["animations"] = [animation]
