"""Display meshes: each part tessellated coarsely enough for a browser to draw the whole assembly,
for the report's 3D view, its pictures and the GLB file (:mod:`gearcheck.scene`).

Not the sweep's meshes (:mod:`gearcheck.cad.mesh`): the chordal tolerance follows the size of the
assembly (:data:`DISPLAY_FRACTION` of its bounding-box diagonal) instead of the clearances, and
each B-rep face keeps its own vertices (no merge across faces), so a viewer that averages normals
at shared vertices shades curved faces smoothly and keeps the edges between faces sharp.

Each distinct solid is tessellated once (copies share one ``solid`` object: the chain links, the
two big gears) and its copies share the arrays. The tessellation is made on a copy of the
solid's topology (the geometry is shared), so the triangulation the sweep's meshes left on the
solid is not replaced by a coarse one.
"""

from __future__ import annotations

import numpy as np
from OCP.Bnd import Bnd_Box
from OCP.BRep import BRep_Tool
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS

from gearcheck.cad.mesh import node_coordinates, triangulate
from gearcheck.cad.placement import Part
from gearcheck.cad.step import appearance
from gearcheck.scene import DisplayPart

# Chordal tolerance when none is given: this fraction of the assembly's bounding-box diagonal
# (the track drive: 0.09 mm), kept within the clamp below.
DISPLAY_FRACTION = 2.5e-4
DISPLAY_TOL_MIN_MM = 0.02
DISPLAY_TOL_MAX_MM = 1.0
# Angular deflection (rad): 0.35 rad draws a bore or a shaft with 18 segments.
DISPLAY_ANGULAR_RAD = 0.35


def _bounding_diagonal(parts: list[Part]) -> float:
    """Diagonal (mm) of the world bounding box of all the parts as built."""
    box = Bnd_Box()
    for part in parts:  # from the geometry alone: the same before and after any meshing
        BRepBndLib.AddOptimal_s(part.placed().wrapped, box, False, False)
    if box.IsVoid():
        return 0.0
    x0, y0, z0, x1, y1, z1 = box.Get()
    return float(np.linalg.norm([x1 - x0, y1 - y0, z1 - z0]))


def display_tolerance(parts: list[Part]) -> float:
    """The default display chordal tolerance (mm) for an assembly."""
    tol = DISPLAY_FRACTION * _bounding_diagonal(parts)
    return float(min(max(tol, DISPLAY_TOL_MIN_MM), DISPLAY_TOL_MAX_MM))


def tessellate(shape, tol_mm: float, angular_rad: float = DISPLAY_ANGULAR_RAD) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) float32 mm, faces (m, 3) uint32) of a cadquery Shape (or TopoDS_Shape) in
    its own frame, outward counter-clockwise; each B-rep face keeps its own vertices."""
    topo = getattr(shape, "wrapped", shape)
    copy = BRepBuilderAPI_Copy(topo, False, False).Shape()  # new topology, shared geometry
    triangulate(copy, tol_mm, angular_rad)
    verts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    offset = 0
    explorer = TopExp_Explorer(copy, TopAbs_FACE)
    while explorer.More():
        face = TopoDS.Face_s(explorer.Current())
        explorer.Next()
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        if tri is None or tri.NbTriangles() == 0:  # a degenerate face: nothing to draw
            continue
        nodes = node_coordinates(tri, loc)
        idx = np.array([tri.Triangle(i).Get() for i in range(1, tri.NbTriangles() + 1)]) - 1
        if face.Orientation() == TopAbs_REVERSED:
            idx = idx[:, ::-1]
        # drop triangles with a repeated node (zero area at a pole or a seam)
        idx = idx[(idx[:, 0] != idx[:, 1]) & (idx[:, 1] != idx[:, 2]) & (idx[:, 2] != idx[:, 0])]
        verts.append(nodes)
        tris.append(idx + offset)
        offset += len(nodes)
    if not tris:
        raise RuntimeError("the solid has no faces to draw")
    return np.concatenate(verts).astype(np.float32), np.concatenate(tris).astype(np.uint32)


def display_parts(parts: list[Part], tol_mm: float | None = None) -> list[DisplayPart]:
    """Every part as a display mesh in its own frame (copies share one pair of arrays), coloured
    by its material as in the STEP file (:func:`gearcheck.cad.step.appearance`: the part's own
    colour where the material is not in the palette), with its pose as built."""
    tol = display_tolerance(parts) if tol_mm is None else float(tol_mm)
    if not tol > 0.0:
        raise ValueError(f"display tolerance must be positive, got {tol_mm}")
    meshed: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    out = []
    for part in parts:
        if id(part.solid) not in meshed:
            vertices, faces = tessellate(part.solid, tol)
            vertices.flags.writeable = False  # shared by the copies
            faces.flags.writeable = False
            meshed[id(part.solid)] = (vertices, faces)
        vertices, faces = meshed[id(part.solid)]
        rgb = tuple(float(c) for c in appearance(part).rgb)
        out.append(DisplayPart(part.name, part.material, (rgb[0], rgb[1], rgb[2]), vertices, faces,
                               np.asarray(part.pose, float).copy()))
    return out
