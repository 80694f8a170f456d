"""B-rep → watertight triangle mesh with an ABSOLUTE chordal tolerance (numpy out).

CadQuery's exporters treat the tolerance as relative or default to 0.1 mm — the size of the
backlash we measure. Here: BRepTools.Clean, then
BRepMesh_IncrementalMesh(shape, tol_mm, relative=False, angular, parallel), read every face's
triangulation (its location applied, winding flipped on reversed faces) and merge the
per-face copies of shared edge nodes into one vertex each.

The error is measured, not assumed: triangle centroids and edge midpoints projected onto their
face's surface. (Poly_Triangulation::Deflection is not that distance: it read 0.040 mm on lofted
flanks whose measured deviation is 0.0078 mm at tol 0.01 mm, so it is not used.) Chords
lie inside convex surfaces, so a mesh of convex flanks overstates clearances by up to the error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepMesh import BRepMesh_IncrementalMesh
from OCP.BRepTools import BRepTools
from OCP.IMeshTools import IMeshTools_Parameters
from OCP.gp import gp_Pnt, gp_Pnt2d
from OCP.ShapeAnalysis import ShapeAnalysis_Surface
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from gearcheck.verify import occurs_twice

# Default absolute chordal deflection (mm): 1/10 of the smallest backlash we resolve.
CHORDAL_TOL_MM = 0.01
# Angular deflection (rad): loose, so the absolute chordal tolerance governs on the gears.
ANGULAR_TOL_RAD = 0.5
# Per-face copies of one edge node agree to rounding (and at most the sewing tolerance).
MERGE_TOL_MM = 1e-5
# Triangles sampled for the measured mesh error.
ERROR_SAMPLES = 3000
# The triangle-count estimate of a fine mesh: a probe mesh this many times coarser (about 1/8
# of the fine mesh's work), its count scaled by probe / tol. Chordal meshing of doubly curved
# faces makes about 1/tol triangles, of singly curved and flat faces fewer; measured on the three
# templates' solids the estimate lies within a factor of 0.8 to 3.4 of the count it predicts, so
# the meshing itself also counts (:class:`TooManyTriangles`).
PROBE_FACTOR = 8.0


@dataclass(frozen=True)
class TriMesh:
    """Indexed triangle mesh (mm), outward counter-clockwise winding."""

    vertices: np.ndarray  # (n, 3) float64
    faces: np.ndarray  # (m, 3) int64
    face_ids: np.ndarray  # (m,) index of the B-rep face (TopExp_Explorer order) per triangle
    tolerance_mm: float  # requested absolute chordal deflection
    sampled_error_mm: float  # max measured distance of sampled mesh points from the B-rep

    @property
    def error_bound_mm(self) -> float:
        """What to claim: the larger of the requested and the measured deviation."""
        return max(self.tolerance_mm, self.sampled_error_mm)

    def volume(self) -> float:
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)

    def area(self) -> float:
        a, b, c = (self.vertices[self.faces[:, i]] for i in range(3))
        return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2.0)

    def _directed_edges(self) -> tuple[np.ndarray, np.ndarray, np.int64]:
        """(tails, heads, n) of every triangle's three directed edges, n the number of vertices:
        the edge (i, j) is the one integer i·n + j, so counting edges sorts plain integers."""
        f = self.faces.astype(np.int64)
        n = np.int64(max(len(self.vertices), int(f.max(initial=-1)) + 1))
        return np.concatenate([f[:, 0], f[:, 1], f[:, 2]]), np.concatenate([f[:, 1], f[:, 2], f[:, 0]]), n

    def is_watertight(self) -> bool:
        """Every undirected edge is used by exactly two triangles."""
        tails, heads, n = self._directed_edges()
        return occurs_twice(np.minimum(tails, heads) * n + np.maximum(tails, heads))

    def is_winding_consistent(self) -> bool:
        """Every directed edge occurs once (its neighbour runs it the other way)."""
        tails, heads, n = self._directed_edges()
        keys = np.sort(tails * n + heads)
        return bool(np.all(keys[1:] != keys[:-1]))


def _faces_of(shape):
    explorer = TopExp_Explorer(shape, TopAbs_FACE)
    while explorer.More():
        yield TopoDS.Face_s(explorer.Current())
        explorer.Next()


def node_coordinates(tri, loc) -> np.ndarray:
    """(n, 3) nodes of a face's triangulation with the face's location applied. An identity
    location is skipped: OCCT's gp_Pnt::Transform leaves a point untouched under an identity
    transformation, so the coordinates are the same bits either way."""
    nodes = range(1, tri.NbNodes() + 1)
    if loc.IsIdentity():
        return np.array([tri.Node(i).Coord() for i in nodes])
    trsf = loc.Transformation()
    return np.array([tri.Node(i).Transformed(trsf).Coord() for i in nodes])


def triangulate(topo, tol_mm: float, angular_rad: float) -> None:
    """Triangulate an OCC shape in place at an absolute chordal tolerance (mm) and an angular one
    (rad). Analytic surfaces (the big back/front cones with a toothed boundary) are otherwise
    split by a fixed range rule and measured up to 2.3 × tol_mm off: they are checked against the
    deflection like B-splines."""
    params = IMeshTools_Parameters()
    params.Deflection = tol_mm
    params.Angle = angular_rad
    params.Relative = False
    params.InParallel = True
    params.ControlSurfaceDeflection = True
    params.EnableControlSurfaceDeflectionAllSurfaces = True
    BRepMesh_IncrementalMesh(topo, params)


def triangle_count(shape, tol_mm: float, angular_rad: float = ANGULAR_TOL_RAD) -> int:
    """Triangles of ``shape`` meshed at ``tol_mm``, counted on a copy (the shape keeps whatever
    triangulation it has: what is meshed from it later is unchanged)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy

    topo = BRepBuilderAPI_Copy(getattr(shape, "wrapped", shape), True, False).Shape()
    triangulate(topo, tol_mm, angular_rad)
    count = 0
    for face in _faces_of(topo):
        tri = BRep_Tool.Triangulation_s(face, TopLoc_Location())
        count += tri.NbTriangles() if tri is not None else 0
    return count


def estimate_triangles(shapes: list, tol_mm: float, factor: float = PROBE_FACTOR) -> int:
    """About how many triangles ``shapes`` make at ``tol_mm``, from a probe mesh ``factor``
    times coarser (about 1/factor of the fine mesh's work), before that mesh is made."""
    probe = min(tol_mm * factor, 0.5)
    return int(math.ceil(sum(triangle_count(s, probe) for s in shapes) * probe / tol_mm))


class TooManyTriangles(Exception):
    """Meshing stopped: the meshes made so far hold more triangles than the budget allowed."""

    def __init__(self, triangles: int, budget: int):
        super().__init__(f"{triangles} triangles, over the budget of {budget}")
        self.triangles, self.budget = triangles, budget


def mesh_shape(shape, tol_mm: float = CHORDAL_TOL_MM, angular_rad: float = ANGULAR_TOL_RAD,
               error_samples: int = ERROR_SAMPLES, seed: int = 0) -> TriMesh:
    """Tessellate a cadquery Shape (or TopoDS_Shape) and return a merged, watertight mesh."""
    topo = getattr(shape, "wrapped", shape)
    BRepTools.Clean_s(topo)
    triangulate(topo, tol_mm, angular_rad)

    verts: list[np.ndarray] = []
    uvs: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    owner: list[np.ndarray] = []
    faces: list = []
    offset = 0
    for face in _faces_of(topo):
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        if tri is None:
            raise RuntimeError("a face has no triangulation")
        if tri.NbTriangles() == 0:  # degenerate face: nothing to draw
            continue
        nodes = node_coordinates(tri, loc)
        uv = np.array([tri.UVNode(i).Coord() for i in range(1, tri.NbNodes() + 1)])
        idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
        if face.Orientation() == TopAbs_REVERSED:
            idx = idx[:, ::-1]
        verts.append(nodes)
        uvs.append(uv)
        tris.append(idx + offset)
        owner.append(np.full(len(idx), len(faces)))
        faces.append(face)
        offset += len(nodes)
    vertices = np.concatenate(verts)
    triangles = np.concatenate(tris)
    face_of_triangle = np.concatenate(owner)

    # merge coincident nodes (connected components of the "closer than MERGE_TOL" graph)
    pairs = cKDTree(vertices).query_pairs(MERGE_TOL_MM, output_type="ndarray")
    n = len(vertices)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, -1)
    first[label[::-1]] = np.arange(n)[::-1]  # lowest original index of each component
    merged_vertices = vertices[first]
    merged = label[triangles]
    keep = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & \
        (merged[:, 2] != merged[:, 0])
    merged, face_of_triangle = merged[keep], face_of_triangle[keep]

    sampled = _sampled_error(vertices, np.concatenate(uvs), triangles[keep], face_of_triangle,
                             faces, error_samples, seed)
    return TriMesh(merged_vertices, merged.astype(np.int64), face_of_triangle, tol_mm, sampled)


def _sampled_error(vertices, uv, triangles, face_of_triangle, faces, samples, seed) -> float:
    """Max distance from its B-rep face's surface of the centroid and edge midpoints of
    ``samples`` random triangles (all if fewer): each point is projected by a local Newton
    search started at the mean of the triangle's (u, v) nodes."""
    rng = np.random.default_rng(seed)
    pick = np.arange(len(triangles))
    if len(pick) > samples:
        pick = rng.choice(pick, samples, replace=False)
    weights = np.array([[1 / 3, 1 / 3, 1 / 3], [0.5, 0.5, 0], [0, 0.5, 0.5], [0.5, 0, 0.5]])
    worst = 0.0
    analysers = {}
    for t in pick:
        fi = int(face_of_triangle[t])
        if fi not in analysers:  # surface with the face's location applied, as the nodes
            analysers[fi] = ShapeAnalysis_Surface(BRep_Tool.Surface_s(faces[fi]))
        sas = analysers[fi]
        corners, corner_uv = vertices[triangles[t]], uv[triangles[t]]
        for w in weights:
            q, guess = w @ corners, w @ corner_uv
            sas.NextValueOfUV(gp_Pnt2d(*guess), gp_Pnt(*q), 1e-9)
            worst = max(worst, sas.Gap())
    return worst
