"""The STEP assembly as written by ``gearcheck.cad.step``, read back with OCP's XCAF reader.

Each template is built once per module through the pipeline (SOURCE_DATE_EPOCH set), its STEP
read back independently of the writer: one product per part instance named by its role, the
run-named root, colours and material names (and densities) by material, solid volumes equal to
the manifest's B-rep volumes, placements equal to the manifest's poses. A second build gives a
byte-identical file. A writer that fails (a refused serialisation, a file-size limit) raises and
leaves no STEP behind.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from gearcheck import __version__

pytestmark = pytest.mark.cad

TEMPLATES = ["zhurong_differential", "eod_track_drive", "nose_wheel_steering"]
EPOCH = "1700000000"  # 2023-11-14T22:13:20 UTC
ROOT = Path(__file__).resolve().parents[1]


def _build(name: str, folder: Path):
    from gearcheck import pipeline
    from gearcheck.design import load_template

    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("SOURCE_DATE_EPOCH", EPOCH)
        return pipeline.build(load_template(ROOT / "templates" / f"{name}.toml"), folder)


@dataclass
class Instance:
    name: str  # the assembly occurrence (component label)
    product: str  # the product it instantiates (referred shape label)
    label_entry: str
    shape: object  # TopoDS_Shape in the product's own frame
    pose: np.ndarray  # the occurrence's placement, 4×4
    rgb: tuple[float, float, float] | None
    material: str | None
    density: float | None


@dataclass
class StepRead:
    root: str
    instances: list[Instance]


def _label_name(label) -> str | None:
    from OCP.TDataStd import TDataStd_Name

    attr = TDataStd_Name()
    return attr.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), attr) else None


def _matrix(loc) -> np.ndarray:
    trsf = loc.Transformation()
    m = np.eye(4)
    for i in range(3):
        for j in range(4):
            m[i, j] = trsf.Value(i + 1, j + 1)
    return m


def read_step(path: Path) -> StepRead:
    """The file through STEPCAFControl_Reader (names, colours, materials) into an XCAF document."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_TreeNode
    from OCP.TDF import TDF_Label, TDF_LabelSequence, TDF_Tool
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFApp import XCAFApp_Application
    from OCP.XCAFDoc import XCAFDoc, XCAFDoc_ColorTool, XCAFDoc_ColorType, XCAFDoc_DocumentTool, XCAFDoc_Material
    from OCP.XCAFDoc import XCAFDoc_ShapeTool as Tool
    from OCP.TCollection import TCollection_AsciiString

    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    reader.SetColorMode(True)
    reader.SetMatMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_ReturnStatus.IFSelect_RetDone
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    assert reader.Transfer(doc)
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    free = TDF_LabelSequence()
    shapes.GetFreeShapes(free)
    assert free.Length() == 1, "one root assembly"
    root = free.Value(1)
    assert Tool.IsAssembly_s(root)
    components = TDF_LabelSequence()
    Tool.GetComponents_s(root, components, False)
    instances = []
    for i in range(1, components.Length() + 1):
        component = components.Value(i)
        product = TDF_Label()
        assert Tool.GetReferredShape_s(component, product)
        color = Quantity_Color()
        has_color = XCAFDoc_ColorTool.GetColor_s(product, XCAFDoc_ColorType.XCAFDoc_ColorSurf, color)
        material = density = None
        node = TDataStd_TreeNode()
        if product.FindAttribute(XCAFDoc.MaterialRefGUID_s(), node) and node.HasFather():
            attr = XCAFDoc_Material()
            if node.Father().Label().FindAttribute(XCAFDoc_Material.GetID_s(), attr):
                material, density = attr.GetName().ToCString(), attr.GetDensity()
        entry = TCollection_AsciiString()
        TDF_Tool.Entry_s(product, entry)
        instances.append(Instance(
            _label_name(component), _label_name(product), entry.ToCString(), Tool.GetShape_s(product),
            _matrix(Tool.GetLocation_s(component)),
            color.Values(Quantity_TypeOfColor.Quantity_TOC_sRGB) if has_color else None, material, density))
    return StepRead(_label_name(root), instances)


def _solids(shape) -> int:
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    explorer, n = TopExp_Explorer(shape, TopAbs_SOLID), 0
    while explorer.More():
        n, _ = n + 1, explorer.Next()
    return n


def _volume(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, 1e-6, False)
    return props.Mass()


@pytest.fixture(scope="module", params=TEMPLATES)
def built(request, tmp_path_factory):
    name = request.param
    run = _build(name, tmp_path_factory.mktemp(name) / "out")
    manifest = json.loads((run.folder / "manifest.json").read_text())
    step = run.folder / manifest["step"]["file"]
    return name, run, manifest, step, read_step(step)


def test_one_product_per_part_instance_named_by_role(built):
    name, run, manifest, _, read = built
    names = [p["name"] for p in manifest["parts"]]
    assert read.root == name == manifest["name"]
    assert [i.name for i in read.instances] == names
    assert [i.product for i in read.instances] == names  # each instance its own product, by its role
    assert len({i.label_entry for i in read.instances}) == len(names)
    assert all(_solids(i.shape) == 1 for i in read.instances)
    assert [p.name for p in run.parts] == names


def test_copies_are_separate_products(built):
    """Parts sharing one solid in memory (big gears, small gears, links) are still one product
    each in the file (no "big_gear_right ×2" in a bill of materials)."""
    _, run, _, _, read = built
    shared = {}
    for part in run.parts:
        shared.setdefault(id(part.solid), []).append(part.name)
    copies = [names for names in shared.values() if len(names) > 1]
    if run.design.mechanism != "steering":
        assert copies, "the differential and the track have copies"
    products = {i.name: i.product for i in read.instances}
    for names in copies:
        assert [products[n] for n in names] == names


def test_colours_by_material(built):
    from gearcheck.cad.step import appearance

    _, run, _, _, read = built
    by_material: dict[str, set] = {}
    for part, inst in zip(run.parts, read.instances, strict=True):
        assert inst.rgb is not None, inst.name
        assert inst.rgb == pytest.approx(appearance(part).rgb, abs=1e-6), inst.name
        by_material.setdefault(part.material, set()).add(tuple(round(c, 6) for c in inst.rgb))
    assert all(len(colours) == 1 for colours in by_material.values())


def test_material_names_and_densities(built):
    from gearcheck.cad.step import appearance

    _, run, manifest, step, read = built
    for entry, inst, part in zip(manifest["parts"], read.instances, run.parts, strict=True):
        assert inst.material == entry["material"], inst.name
        density = appearance(part).density_g_cm3
        assert inst.density == pytest.approx(density or 0.0), inst.name
    if any(appearance(p).density_g_cm3 for p in run.parts):
        text = step.read_bytes()
        assert b"SI_UNIT($,.GRAM.)" in text and b"DERIVED_UNIT_ELEMENT" in text
        # g·cm⁻³ (OCCT writes g³·cm²; the writer puts the exponents right)
        assert b",3.);" not in text and b",-3.);" in text


def test_solid_volumes_equal_manifest_brep_volumes(built):
    _, _, manifest, _, read = built
    for entry, inst in zip(manifest["parts"], read.instances, strict=True):
        assert _volume(inst.shape) == pytest.approx(entry["brep_volume_mm3"], rel=1e-7), inst.name


def test_placements_equal_manifest_poses(built):
    _, _, manifest, _, read = built
    for entry, inst in zip(manifest["parts"], read.instances, strict=True):
        np.testing.assert_allclose(inst.pose, np.asarray(entry["pose"]), atol=1e-9, err_msg=inst.name)


def test_units_and_header(built):
    from OCP.STEPControl import STEPControl_Reader

    name, _, _, step, _ = built
    text = step.read_bytes()
    assert text.rstrip().endswith(b"END-ISO-10303-21;")
    header = text[:text.index(b"ENDSEC;")].decode()
    flat = "".join(line.strip() for line in header.splitlines())
    assert f"FILE_NAME('{name}.step','2023-11-14T22:13:20+00:00',('gearcheck'),('gearcheck')," in flat
    assert f"'gearcheck {__version__}'" in flat
    reader = STEPControl_Reader()
    reader.ReadFile(str(step))
    from OCP.TColStd import TColStd_SequenceOfAsciiString

    lengths, angles, solid_angles = (TColStd_SequenceOfAsciiString() for _ in range(3))
    reader.FileUnits(lengths, angles, solid_angles)
    assert {lengths.Value(i).ToCString() for i in range(1, lengths.Length() + 1)} == {"millimetre"}


def test_two_builds_give_byte_identical_step(built, tmp_path):
    """OCCT orders the colour entities by memory addresses and numbers assembly occurrences
    with a process-wide counter; the writer fixes both, so a rebuild is byte-identical."""
    name, _, _, step, _ = built
    again = _build(name, tmp_path / "again")
    assert (again.folder / step.name).read_bytes() == step.read_bytes()


def test_accurate_volume_on_the_z13_bevel_gear(built):
    """The manifest's volume is the adaptive integration: on the z13 gear it agrees with the
    CAD-free analytic volume to < 0.01 mm³, where CadQuery's Volume() was 1.1 mm³ off; and with
    the mesh volume within area × error bound."""
    from gearcheck.geometry.bevel_volume import analytic_volume_mm3

    name, run, manifest, _, _ = built
    if name != "zhurong_differential":
        pytest.skip("the bevel gears are the differential's")
    spec = run.assembly.solids["small_gear"]
    assert spec.teeth == 13
    part = next(p for p in run.parts if p.name == "small_gear_front")
    entry = next(p for p in manifest["parts"] if p["name"] == "small_gear_front")
    analytic = analytic_volume_mm3(spec)
    accurate = entry["brep_volume_mm3"]
    fixed_order = part.solid.Volume()
    assert abs(accurate - analytic) < 0.01
    assert abs(fixed_order - analytic) > 0.5  # why the manifest no longer uses it
    exported = next(e for e in run.exported if e.part.name == "small_gear_front")
    assert abs(entry["mesh_volume_mm3"] - accurate) <= exported.mesh.area() * entry["mesh_error_bound_mm"]


# ------------------------------------------------------------------------------------------
# Failures: nothing truncated left behind


@pytest.fixture(scope="module")
def steering_parts():
    from gearcheck import pipeline
    from gearcheck.design import load_template

    return pipeline.build_parts(load_template(ROOT / "templates" / "nose_wheel_steering.toml"))[1]


class _FailingWriter:
    """STEPCAFControl_Writer whose serialisation writes half a file and reports failure."""

    def __init__(self, *args):
        from OCP.STEPCAFControl import STEPCAFControl_Writer

        self._writer = STEPCAFControl_Writer(*args)

    def __getattr__(self, name):
        return getattr(self._writer, name)

    def WriteStream(self, stream):  # noqa: N802 (OCP's name)
        from OCP.IFSelect import IFSelect_ReturnStatus

        stream.write(b"ISO-10303-21;\nHEADER;\n")
        return IFSelect_ReturnStatus.IFSelect_RetFail


def test_failed_serialisation_raises_and_leaves_nothing(steering_parts, tmp_path, monkeypatch):
    from gearcheck.cad import step

    monkeypatch.setattr(step, "STEPCAFControl_Writer", _FailingWriter)
    target = tmp_path / "nose_wheel_steering.step"
    with pytest.raises(OSError, match="RetFail") as info:
        step.write_step(steering_parts, target, "nose_wheel_steering")
    assert info.value.filename == str(target)
    assert list(tmp_path.iterdir()) == []


def test_failed_transfer_raises(steering_parts, tmp_path, monkeypatch):
    from gearcheck.cad import step

    class NoTransfer(_FailingWriter):
        def Transfer(self, *args):  # noqa: N802 (OCP's name)
            return False

    monkeypatch.setattr(step, "STEPCAFControl_Writer", NoTransfer)
    with pytest.raises(step.StepWriteError, match="transfer"):
        step.write_step(steering_parts, tmp_path / "x.step", "x")
    assert list(tmp_path.iterdir()) == []


def test_file_that_does_not_read_back_is_not_kept(steering_parts, tmp_path, monkeypatch):
    """The check after writing: a file whose products are not the parts is refused."""
    from gearcheck.cad import step

    monkeypatch.setattr(step, "step_products", lambda path, shown=None: ({"x": 0}, []))
    with pytest.raises(step.StepWriteError, match="read back"):
        step.write_step(steering_parts, tmp_path / "x.step", "x")
    assert list(tmp_path.iterdir()) == []


def test_file_size_limit_raises_instead_of_keeping_a_truncated_step(tmp_path):
    """Under ``ulimit -f`` (RLIMIT_FSIZE; Python ignores SIGXFSZ, so the write gets EFBIG) the
    write fails loudly and neither the STEP nor a temporary file is left (CadQuery's exporter
    ignored the writer's status and kept a cut-short file)."""
    script = textwrap.dedent(f"""
        import errno, resource, sys
        from pathlib import Path
        from gearcheck import pipeline
        from gearcheck.design import load_template
        from gearcheck.cad.step import StepWriteError, write_step
        parts = pipeline.build_parts(load_template(Path({str(ROOT / "templates" / "nose_wheel_steering.toml")!r})))[1]
        resource.setrlimit(resource.RLIMIT_FSIZE, (200_000, resource.RLIM_INFINITY))
        try:
            write_step(parts, Path({str(tmp_path / "limited.step")!r}), "nose_wheel_steering")
        except StepWriteError as exc:
            print("raised", exc.errno == errno.EFBIG, exc.filename)
            sys.exit(0)
        sys.exit("no error")
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["raised", "True", str(tmp_path / "limited.step")]
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------------
# Palette and header pieces


def _part(material: str, color=(0.1, 0.2, 0.3)):
    from gearcheck.cad.placement import Part

    return Part("p", material, None, color=color)  # type: ignore[arg-type]


@pytest.mark.parametrize(("material", "label", "density"), [
    ("CF170 stainless steel (17-4PH class)", "stainless steel 17-4PH", 7.78),
    ("TC4 titanium alloy (Ti-6Al-4V)", "titanium alloy Ti-6Al-4V (TC4)", 4.43),
    ("7A09 aluminium alloy", "aluminium alloy 7A09", 2.81),
    ("7075-T651 aluminium alloy", "aluminium alloy 7075", 2.81),
    ("steel shim", "steel", 7.85),
    ("steel", "steel", 7.85),
    ("cast aluminium track link with steel sleeve", "cast aluminium", None),  # two metals: no density
    ("Aluminum", "aluminium", None),
])
def test_palette(material, label, density):
    from gearcheck.cad.step import appearance, material_style

    style = material_style(material)
    assert style is not None and style.label == label
    look = appearance(_part(material))
    assert look.material == material and look.rgb == style.rgb and look.density_g_cm3 == density


def test_unknown_material_keeps_the_part_colour():
    from gearcheck.cad.step import appearance

    look = appearance(_part("unobtainium", (0.1, 0.2, 0.3)))
    assert (look.rgb, look.density_g_cm3, look.description) == ((0.1, 0.2, 0.3), None, "")


def test_header_timestamp():
    from gearcheck.cad.step import header_timestamp
    from gearcheck.params import ParamError

    assert header_timestamp({"SOURCE_DATE_EPOCH": "0"}) == "1970-01-01T00:00:00+00:00"
    assert header_timestamp({"SOURCE_DATE_EPOCH": EPOCH}) == "2023-11-14T22:13:20+00:00"
    assert header_timestamp({}).endswith("+00:00")
    with pytest.raises(ParamError, match="SOURCE_DATE_EPOCH"):
        header_timestamp({"SOURCE_DATE_EPOCH": "yesterday"})


def test_restamped_file_is_the_file_written_at_that_time(steering_parts, tmp_path, monkeypatch):
    """A STEP file from the CAD cache gets the time stamp of now: restamping the bytes made at one
    time gives the bytes made at another, and the file written from them is checked for its size
    and trailer (not parsed again)."""
    from gearcheck.cad import step

    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1000000000")
    early = step.step_bytes(steering_parts, "nose_wheel_steering", tmp_path / "n.step")
    monkeypatch.setenv("SOURCE_DATE_EPOCH", EPOCH)
    late = step.step_bytes(steering_parts, "nose_wheel_steering", tmp_path / "n.step")
    assert early != late
    assert step.restamped(early, step.header_timestamp()) == late
    assert step.restamped(b"ISO-10303-21;\nHEADER;\nENDSEC;\n", step.header_timestamp()) is None

    def parse(*_args, **_kw):
        raise AssertionError("a file from the cache is not parsed again")

    monkeypatch.setattr(step, "step_products", parse)
    assert step.write_step(steering_parts, tmp_path / "n.step", "nose_wheel_steering", early) == late
    assert (tmp_path / "n.step").read_bytes() == late
