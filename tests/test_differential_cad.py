"""The differential assembly, measured on the placed solids: cone apexes, shim displacement."""

import numpy as np
import pytest

pytestmark = pytest.mark.cad


def _cone_faces_apexes(shape, semi_angle_rad):
    """Apexes of the conical faces of ``shape`` with the given semi-angle (the tip-cone lands)."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Cone

    apexes = []
    for face in shape.Faces():
        surface = BRepAdaptor_Surface(face.wrapped)
        if surface.GetType() != GeomAbs_Cone:
            continue
        cone = surface.Cone()
        if abs(abs(cone.SemiAngle()) - semi_angle_rad) < 1e-7:
            apexes.append(np.array(cone.Apex().Coord()))
    return apexes


@pytest.fixture(scope="module", params=[0.0, 0.1])
def assembly(request, templates_dir):
    from gearcheck.design import load_template
    from gearcheck.pipeline import build_parts

    shim = request.param
    design = load_template(templates_dir / "zhurong_differential.toml", [f"shim.thickness_mm={shim}"])
    assembly, parts = build_parts(design)
    return shim, {p.name: p for p in parts}, assembly.layout.specs


def test_every_solid_valid(assembly):
    _, parts, _ = assembly
    for name, part in parts.items():
        assert part.placed().isValid(), name


def test_cone_apexes_on_common_apex_or_shimmed_out(assembly):
    """Tip-cone lands of each gear, measured on its placed solid: at shim 0 all four apexes
    coincide at the origin within 0.01 mm; with shim x each big gear's apex lies x ± 0.01 mm
    out along its own axis (±Y) and the small gears stay on the common apex."""
    shim, parts, specs = assembly
    expected = {
        "big_gear_right": np.array([0.0, shim, 0.0]),
        "big_gear_left": np.array([0.0, -shim, 0.0]),
        "small_gear_front": np.zeros(3),
        "small_gear_back": np.zeros(3),
    }
    for name, where in expected.items():
        spec = specs.big if name.startswith("big") else specs.small
        apexes = _cone_faces_apexes(parts[name].placed(), spec.face_angle_rad)
        assert len(apexes) == spec.teeth, name  # one tip land per tooth
        for apex in apexes:
            assert np.linalg.norm(apex - where) <= 0.01, (name, apex)


def test_gears_do_not_intersect_and_mesh_closely(assembly):
    """Meshing gears at the built pose, on 0.002 mm meshes with FCL (a whole-gear B-rep distance
    costs ~15 s): the clearance minus the measured mesh-error bound is positive (no
    interference) and below 0.2 mm (they are in mesh, not pulled apart)."""
    from gearcheck.cad.mesh import mesh_shape
    from gearcheck.sweep.engine import MeshData, Scene

    _, parts, _ = assembly
    names = ["big_gear_right", "big_gear_left", "small_gear_front", "small_gear_back"]
    # 0.002 mm: the centred shim-0 mesh leaves ~0.01 mm per flank, finer than a 0.01 mm mesh proves
    meshes = {n: mesh_shape(parts[n].placed(), 0.002) for n in names}
    scene = Scene([MeshData(n, m.vertices, m.faces) for n, m in meshes.items()])
    for big in names[:2]:
        for small in names[2:]:
            bound = meshes[big].error_bound_mm + meshes[small].error_bound_mm
            clearance = scene.distance(big, small).distance
            assert not scene.collide(big, small)
            assert bound < clearance < 0.2, (big, small, clearance, bound)
