"""The meshes the steering sweep uses, cut from the built parts (numpy only).

Both parts are straight extrusions over the same z range, so their solids overlap exactly when
their side walls cross (a profile wholly inside the other cannot happen with small steps): the
end faces are left out, and so are the pinion's walls that can never reach the rack (radius
below H − rack top: bore, roots) and the rack's walls below the pinion's tip circle. The rack's
left and right flanks are kept apart as well: only flanks push the rack (the push model's rule,
:data:`gearcheck.mechanisms.steering.push.PUSH_NORMAL_MIN`), a trimmed top never does.
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry.rack_pinion import RackPinionGeometry
from gearcheck.sweep.bodies import Body, MeshData, submesh

PINION, RACK = "pinion", "rack"
RACK_FACING_MINUS_X = "rack_left_flanks"  # facing −x: pushed by the pinion towards +x
RACK_FACING_PLUS_X = "rack_right_flanks"  # facing +x: pushed towards −x, drive in power mode

# A rack triangle is a flank (the only faces that push the rack) when its centroid lies within
# this of a flank segment of the drawing, in the section plane.
FLANK_MATCH_MM = 1e-6
# Walls kept: the pinion's reaching within this of the rack's top (radius ≥ H − top − margin),
# the rack's reaching within this of the pinion's tip circle.
WALL_REACH_MARGIN_MM = 1.0


def pusher(sense: int) -> str:
    """Rack faces a tooth pushes when it drives the rack towards ``sense`` (±x)."""
    return RACK_FACING_MINUS_X if sense > 0 else RACK_FACING_PLUS_X


def normals(mesh: MeshData) -> np.ndarray:
    """Unit normals of the mesh's triangles."""
    t = mesh.vertices[mesh.faces]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    return n / np.linalg.norm(n, axis=1)[:, None]


def rack_flank_faces(g: RackPinionGeometry, rack: MeshData) -> tuple[np.ndarray, np.ndarray]:
    """Masks of the rack triangles on the left flanks (facing −x) and on the right flanks
    (facing +x) of the drawing's teeth: matched by position, so that a trimmed top, however
    slanted, never counts as a flank (the push model's rule)."""
    centroid = rack.vertices[rack.faces].mean(axis=1)[:, :2]
    left = np.zeros(len(rack.faces), bool)
    right = np.zeros(len(rack.faces), bool)
    for k in range(g.rack_first_tooth, g.rack_last_tooth + 1):
        bl, br, tr, tl = g.rack_tooth_polygon(k, 0.0)
        for a, b, side in ((bl, tl, left), (br, tr, right)):
            d = b - a
            t = (centroid - a) @ d / float(d @ d)
            rel = centroid - a
            off = np.abs(d[0] * rel[:, 1] - d[1] * rel[:, 0]) / float(np.linalg.norm(d))
            np.logical_or(side, (t >= 0.0) & (t <= 1.0) & (off <= FLANK_MATCH_MM), out=side)  # left or right, in place
    return left, right


def sweep_meshes(pinion: Body, rack: Body, centre_height_mm: float, flanks: tuple[np.ndarray, np.ndarray]
                 ) -> tuple[list[MeshData], dict]:
    """The meshes the sweep uses (own frames): pinion and rack side walls that can meet, and the
    rack's left and right flanks apart (``flanks``: :func:`rack_flank_faces`, the faces that push).
    Also returns counts for the report."""
    zp, zr = pinion.mesh.vertices[:, 2], rack.mesh.vertices[:, 2]
    same_z = abs(zp.min() - zr.min()) < 1e-6 and abs(zp.max() - zr.max()) < 1e-6
    np_, nr = normals(pinion.mesh), normals(rack.mesh)
    walls_p = np.abs(np_[:, 2]) < 0.5 if same_z else np.ones(len(np_), bool)
    walls_r = np.abs(nr[:, 2]) < 0.5 if same_z else np.ones(len(nr), bool)
    rack_top = float(rack.mesh.vertices[:, 1].max())
    radius = np.hypot(pinion.mesh.vertices[:, 0], pinion.mesh.vertices[:, 1])[pinion.mesh.faces].max(axis=1)
    reach = centre_height_mm - rack_top - WALL_REACH_MARGIN_MM
    keep_p = walls_p & (radius >= reach)
    tip = float(radius.max())
    rack_height = rack.mesh.vertices[:, 1][rack.mesh.faces].max(axis=1)
    keep_r = walls_r & (rack_height >= centre_height_mm - tip - WALL_REACH_MARGIN_MM)
    left, right = flanks
    meshes = [
        submesh(pinion.mesh, PINION, keep_p),
        submesh(rack.mesh, RACK, keep_r),
        submesh(rack.mesh, RACK_FACING_MINUS_X, keep_r & left),
        submesh(rack.mesh, RACK_FACING_PLUS_X, keep_r & right),
    ]
    info = {"pinion_triangles_total": len(pinion.mesh.faces), "pinion_triangles_swept": int(keep_p.sum()),
            "rack_triangles_total": len(rack.mesh.faces), "rack_triangles_swept": int(keep_r.sum()),
            "end_faces_dropped": int(same_z)}
    return meshes, info


def pinion_profile(pinion: MeshData, root_radius_mm: float, bore_radius_mm: float) -> np.ndarray:
    """The pinion's outline as the mesh has it (own frame, (n, 2), ordered by polar angle): the
    vertices on one end face. Every wall triangle spans the face width, so these are all the
    profile's vertices (exact points of the B-rep outline). The outer outline (teeth, root arcs)
    is kept and the bore left out: the outline lies on or outside the root circle, the bore
    strictly inside it, and the cut is made half way between the two (a share of the tip radius
    would cut a topped end tooth's corner off a small, coarse pinion)."""
    v = pinion.vertices
    ring = v[np.abs(v[:, 2] - v[:, 2].max()) < 1e-6]
    rho = np.hypot(ring[:, 0], ring[:, 1])
    ring = ring[rho > 0.5 * (root_radius_mm + bore_radius_mm)]
    gamma = np.arctan2(ring[:, 0], -ring[:, 1])
    return ring[np.argsort(gamma), :2]


def driving_flank(g: RackPinionGeometry, rack: MeshData, right: np.ndarray, corner: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The outward normal of the first rack tooth's driving (right) flank at its top corner S6
    (``corner``, as drawn: it must be a vertex of the rack mesh), from the mesh's flank triangles
    at that vertex (``right``: :func:`rack_flank_faces`), and the direction along that flank
    towards S6."""
    rv, rf = rack.vertices, rack.faces
    if float(np.min(np.hypot(rv[:, 0] - corner[0], rv[:, 1] - corner[1]))) > 1e-6:
        raise ValueError("the rack mesh has no vertex at the S6 corner of the drawing")
    nr = normals(rack)
    touches = np.any(np.hypot(rv[rf][..., 0] - corner[0], rv[rf][..., 1] - corner[1]) < 1e-6, axis=1)
    facing = np.flatnonzero(touches & right)
    a = g.pressure_angle_rad
    if facing.size:
        normal = nr[facing[0], :2] / np.linalg.norm(nr[facing[0], :2])
    else:
        normal = np.array([math.cos(a), math.sin(a)])
    up = np.array([-normal[1], normal[0]])
    up = up if up[1] > 0 else -up
    return normal, up


def rack_profile(rack: MeshData) -> np.ndarray:
    """The rack's outline vertices as the mesh has them (own frame, xy): those on one end face,
    exact points of the B-rep outline (every wall triangle spans the face width)."""
    v = rack.vertices
    return v[np.abs(v[:, 2] - v[:, 2].max()) < 1e-6][:, :2]
