"""`gearcheck build` outputs, read back from disk: STL meshes, STEP assembly, manifest.

Each template is built once per session (module fixture) into a temporary folder.
"""

import hashlib
import json

import pytest
import trimesh

from gearcheck.cli import main

pytestmark = pytest.mark.cad

TEMPLATES = ["zhurong_differential", "eod_track_drive", "nose_wheel_steering"]


@pytest.fixture(scope="module", params=TEMPLATES)
def built(request, tmp_path_factory, templates_dir):
    name = request.param
    out = tmp_path_factory.mktemp(name)
    assert main(["build", str(templates_dir / f"{name}.toml"), "--out", str(out)]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    return name, out, manifest


def test_no_temporary_files_left(built):
    from gearcheck.output import RUN_MARKER  # the run folder's own marker, not a leftover

    _, out, _ = built
    leftovers = [p.name for p in out.iterdir()
                 if p.name != RUN_MARKER and (p.name.startswith(".") or p.suffix == ".part")]
    assert leftovers == []


def test_manifest_hashes_match_files(built):
    _, out, manifest = built
    files = [manifest["step"], manifest["params_file"]] + [p["stl"] for p in manifest["parts"]]
    for entry in files:
        assert hashlib.sha256((out / entry["file"]).read_bytes()).hexdigest() == entry["sha256"]
    assert manifest["gearcheck_version"]
    assert manifest["params"]["mechanism"] == manifest["mechanism"]


def test_stl_watertight_and_volume_within_tessellation_bound(built):
    """Each STL read back: watertight, consistent winding, outward normals, and
    |V_mesh − V_brep| ≤ area × (measured mesh-error bound) — chords deviate from the surface by
    at most the bound, so the enclosed volume can differ by at most area·bound."""
    _, out, manifest = built
    for part in manifest["parts"]:
        mesh = trimesh.load_mesh(out / part["stl"]["file"], process=True)
        assert mesh.is_watertight, part["name"]
        assert mesh.is_winding_consistent, part["name"]
        assert mesh.volume > 0, part["name"]  # outward normals
        assert len(mesh.faces) == part["triangles"]
        bound = mesh.area * part["mesh_error_bound_mm"]
        # STL stores float32 (~1e-5 mm at 100 mm), negligible beside the bound
        assert abs(mesh.volume - part["brep_volume_mm3"]) <= bound, part["name"]
        assert part["mesh_error_bound_mm"] <= part["tolerance_mm"] + 1e-12


def test_step_reimports_in_cadquery_with_same_parts_and_volumes(built):
    """CadQuery's own STEP importer reads the file (interoperability): one child per part, named
    by its role, with the manifest's volume (both by the adaptive integration; the full read-back
    checks are in test_step_export.py)."""
    import cadquery as cq

    from gearcheck.cad.bevel import volume_mm3

    name, out, manifest = built
    assy = cq.Assembly.importStep(str(out / manifest["step"]["file"]))
    assert assy.name == name
    volumes = {}
    for child_name, sub in assy.traverse():
        if sub.obj is not None:
            shape = sub.obj if isinstance(sub.obj, cq.Shape) else sub.obj.val()
            volumes[child_name] = volume_mm3(shape)
    expected = {p["name"]: p["brep_volume_mm3"] for p in manifest["parts"]}
    assert set(volumes) == set(expected)
    for part, volume in expected.items():
        assert volumes[part] == pytest.approx(volume, rel=1e-7), part
