"""Export a mechanism's parts: STEP assembly (mm, one named product per part instance, coloured
and tagged by material; :mod:`gearcheck.cad.step`), one STL per part, manifest.json.

Every file is written to a temporary name in the target folder and renamed into place (the STEP
only after it has been read back and checked), and the manifest is written last, so an
interrupted or failed build never leaves a half-written file or a manifest describing files that
are not there. The manifest's B-rep volumes are the adaptive integration of
:func:`gearcheck.cad.bevel.volume_mm3` (CadQuery's fixed-order ``Volume()`` was 1.1 mm³ off on
the z13 bevel gear).
"""

from __future__ import annotations

import hashlib
import json
import pickle
from dataclasses import dataclass, replace
from pathlib import Path

import cadquery as cq
import numpy as np

from gearcheck import __version__
from gearcheck.cad.bevel import volume_mm3
from gearcheck.cad.mesh import CHORDAL_TOL_MM, TooManyTriangles, TriMesh, mesh_shape
from gearcheck.cad.placement import Part, location
from gearcheck.cad.step import StepWriteError, appearance, write_step
from gearcheck.names import file_in
from gearcheck.output import atomic_write_bytes, atomic_write_text, ensure_out_dir
from gearcheck.params.common import to_toml

__all__ = ["ExportedPart", "StepWriteError", "cad_assembly", "cad_bytes", "cad_from_bytes", "export_parts",
           "mesh_parts", "posed", "sha256", "stl_bytes", "write_step"]


@dataclass(frozen=True)
class ExportedPart:
    part: Part
    mesh: TriMesh  # in the part's own frame; the STL holds it moved by the part's pose
    stl: Path
    brep_volume_mm3: float


def posed(mesh: TriMesh, pose: np.ndarray) -> TriMesh:
    """The mesh moved by a rigid 4×4 pose (volume, error and winding unchanged)."""
    vertices = mesh.vertices @ pose[:3, :3].T + pose[:3, 3]
    return replace(mesh, vertices=vertices)


def stl_bytes(mesh: TriMesh, name: str) -> bytes:
    """Binary STL of an indexed mesh (deterministic: no timestamp in the header)."""
    tri = mesh.vertices[mesh.faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    normals = np.divide(normals, lengths[:, None], out=np.zeros_like(normals), where=lengths[:, None] > 0)
    record = np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    data = np.zeros(len(tri), dtype=record)
    data["n"] = normals
    data["v"] = tri
    header = f"gearcheck {__version__} {name} mm".encode("ascii", "replace")[:80].ljust(80, b" ")
    return header + np.uint32(len(tri)).tobytes() + data.tobytes()


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def cad_assembly(parts: list[Part], assembly_name: str) -> cq.Assembly:
    """A named CadQuery assembly for viewers (ocp_vscode): one component per part at its pose
    (mm), coloured by material as in the STEP. The STEP file itself is written by
    :func:`gearcheck.cad.step.write_step`, not from this."""
    assy = cq.Assembly(name=assembly_name)
    for part in parts:
        assy.add(part.solid, name=part.name, loc=location(part.pose), color=cq.Color(*appearance(part).rgb))
    return assy


def mesh_parts(parts: list[Part], tol_mm: float = CHORDAL_TOL_MM, progress=None,
               max_triangles: int | None = None) -> list[tuple[TriMesh, float]]:
    """(mesh in the part's own frame, B-rep volume in mm³) of every part, in order; copies share
    a solid, and are meshed once (they share the mesh). ``progress`` (optional) is called with
    each part name as it is meshed. Meshing leaves each solid carrying its triangulation.
    ``max_triangles``: once the distinct meshes hold more, :class:`TooManyTriangles` is raised
    (the parts after it are not meshed)."""
    meshed: dict[int, tuple[TriMesh, float]] = {}
    out = []
    total = 0
    for part in parts:
        if progress:
            progress(part.name)
        if id(part.solid) not in meshed:
            mesh = mesh_shape(part.solid, tol_mm)
            total += len(mesh.faces)
            if max_triangles is not None and total > max_triangles:
                raise TooManyTriangles(total, max_triangles)
            meshed[id(part.solid)] = (mesh, float(volume_mm3(part.solid)))
        out.append(meshed[id(part.solid)])
    return out


def cad_bytes(parts: list[Part], meshed: list[tuple[TriMesh, float]]) -> bytes:
    """The parts (solids with their triangulations: OCCT's binary B-rep) and their meshes as one
    pickle, shared solids and meshes shared once, for :mod:`gearcheck.cache`."""
    return pickle.dumps((parts, meshed), protocol=5)


def cad_from_bytes(data: bytes) -> tuple[list[Part], list[tuple[TriMesh, float]]]:
    """What :func:`cad_bytes` wrote: the same solids (bit for bit, triangulations included, so
    what is measured on them later sees the same B-rep) and meshes."""
    parts, meshed = pickle.loads(data)
    return parts, meshed


def export_parts(
    parts: list[Part],
    folder: Path,
    *,
    name: str,
    mechanism: str,
    params_data: dict,
    tol_mm: float = CHORDAL_TOL_MM,
    extra: dict | None = None,
    progress=None,
    params_comment: str = "",
    meshed: list[tuple[TriMesh, float]] | None = None,
    step_data: bytes | None = None,
    max_triangles: int | None = None,
) -> tuple[dict, list[ExportedPart], bytes]:
    """Mesh and write every part, the STEP assembly, params.toml and manifest.json; returns the
    manifest, the exported parts (meshes in their own frames) and the STEP file's bytes.
    ``progress`` (optional) is called with each part name as it is meshed. ``meshed`` (one
    :func:`mesh_parts` entry per part) and ``step_data`` (a STEP file of these parts, its header
    stamped again now) are used instead of meshing and writing the STEP anew: a design's CAD
    from the cache. ``max_triangles``: as for :func:`mesh_parts`."""
    folder = ensure_out_dir(folder)
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        raise ValueError(f"part names must be unique: {names}")
    if meshed is None:
        meshed = mesh_parts(parts, tol_mm, progress, max_triangles)
    exported: list[ExportedPart] = []
    for part, (mesh, volume) in zip(parts, meshed, strict=True):
        stl = file_in(folder, f"{part.name}.stl")  # a name resolving outside the folder: refused
        atomic_write_bytes(stl, stl_bytes(posed(mesh, part.pose), part.name))
        exported.append(ExportedPart(part, mesh, stl, volume))
    step = file_in(folder, f"{name}.step")
    step_data = write_step(parts, step, name, step_data)
    params_file = folder / "params.toml"
    atomic_write_text(params_file, to_toml(params_data, comment=params_comment))

    checked: dict[int, tuple[float, bool, bool]] = {}  # copies share a mesh: measure it once
    for e in exported:
        if id(e.mesh) not in checked:
            checked[id(e.mesh)] = (e.mesh.volume(), e.mesh.is_watertight(), e.mesh.is_winding_consistent())

    manifest = {
        "gearcheck_version": __version__,
        "mechanism": mechanism,
        "name": name,
        "units": "mm",
        "chordal_tolerance_mm": tol_mm,
        "step": {"file": step.name, "sha256": sha256(step)},
        "params_file": {"file": params_file.name, "sha256": sha256(params_file)},
        "parts": [
            {
                "name": e.part.name,
                "material": e.part.material,
                "brep_volume_mm3": e.brep_volume_mm3,
                "mesh_volume_mm3": checked[id(e.mesh)][0],
                "triangles": int(len(e.mesh.faces)),
                "vertices": int(len(e.mesh.vertices)),
                "tolerance_mm": e.mesh.tolerance_mm,
                "measured_mesh_error_mm": e.mesh.sampled_error_mm,
                "mesh_error_bound_mm": e.mesh.error_bound_mm,
                "watertight": checked[id(e.mesh)][1],
                "winding_consistent": checked[id(e.mesh)][2],
                "pose": np.asarray(e.part.pose).tolist(),
                "motion": e.part.motion.to_dict() if e.part.motion is not None else {},
                "stl": {"file": e.stl.name, "sha256": sha256(e.stl)},
            }
            for e in exported
        ],
        "params": params_data,
    }
    if extra:
        manifest.update(extra)
    atomic_write_text(folder / "manifest.json", json.dumps(manifest, indent=2, allow_nan=False) + "\n")
    return manifest, exported, step_data
