"""The STEP reader (``gearcheck.cad.step_import``) on files CadQuery and OCP write in tmp_path.

A nested CadQuery assembly (a plate, a rotated shaft, a sub-assembly placed and rotated holding a
pin) reads back as its three leaf products by name, each with its analytic volume and the bounds
of its placement composed through every level; the same assembly written in inches (and in
metres) reads back in millimetres whatever the process-wide ``xstep.cascade.unit`` holds, with
the file's unit recorded. Flat files (one or several free solids, a compound), instance versus
product names, repeated names, shared geometry, and every error case (unknown product name,
missing path, not STEP, no roots, no solids) as one-line StepImportErrors naming the file.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from pathlib import Path

import cadquery as cq  # noqa: TID251 - the tests build their STEP inputs with CadQuery
import pytest
from cadquery.occ_impl.exporters.assembly import exportAssembly  # noqa: TID251
from OCP.Interface import Interface_Static  # noqa: TID251
from OCP.STEPCAFControl import STEPCAFControl_Writer  # noqa: TID251
from OCP.STEPControl import STEPControl_Controller, STEPControl_StepModelType, STEPControl_Writer  # noqa: TID251
from OCP.TCollection import TCollection_ExtendedString  # noqa: TID251
from OCP.TDataStd import TDataStd_Name  # noqa: TID251
from OCP.TDocStd import TDocStd_Document  # noqa: TID251
from OCP.XCAFApp import XCAFApp_Application  # noqa: TID251
from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ShapeTool  # noqa: TID251
from OCP.XSControl import XSControl_WorkSession  # noqa: TID251

from gearcheck.cad.step_import import StepFile, StepImportError, read_step, unique_names

pytestmark = pytest.mark.cad

TOL_MM = 1e-6
REL = 1e-6

# the analytic parts: box 40×20×5, cylinder r 4 h 30, box 2×3×4 (all centred on their origin)
VOLUMES = {"plate": 40 * 20 * 5, "shaft": math.pi * 4**2 * 30, "pin": 2 * 3 * 4}
# placed: plate at (10, 0, 0); shaft turned 90° about x (its axis along y) at (0, 50, 0); the pin
# at (1, 2, 3) in a sub-assembly turned 90° about z at (100, 0, 0): x → -y, y → x
BBOXES = {
    "plate": ((-10.0, -10.0, -2.5), (30.0, 10.0, 2.5)),
    "shaft": ((-4.0, 35.0, -4.0), (4.0, 65.0, 4.0)),
    "pin": ((100 - 3.5, 0.0, 1.0), (100 - 0.5, 2.0, 5.0)),
}
PATHS = {"plate": ("top", "plate"), "shaft": ("top", "shaft"), "pin": ("top", "sub", "pin")}
UNIT_SETTINGS = ("xstep.cascade.unit", "write.step.unit")


@contextlib.contextmanager
def statics(**values: str) -> Iterator[None]:
    """Process-wide translator settings (keys with ``_`` for ``.``) for a block, restored after;
    CadQuery's exporter changes ``xstep.cascade.unit`` and ``write.step.unit`` and leaves them."""
    STEPControl_Controller.Init_s()  # the STEP settings exist once the controller is set up
    keys: dict[str, str | None] = {k: None for k in UNIT_SETTINGS} | {k.replace("_", "."): v for k, v in values.items()}
    previous = {k: Interface_Static.CVal_s(k) for k in keys}
    try:
        for key, value in keys.items():
            if value is not None:
                assert Interface_Static.SetCVal_s(key, value), key
        yield
    finally:
        for key, value in previous.items():
            assert Interface_Static.SetCVal_s(key, value), key


def _assembly() -> cq.Assembly:
    sub = cq.Assembly(name="sub")
    sub.add(cq.Workplane().box(2, 3, 4), name="pin", loc=cq.Location((1, 2, 3)))
    top = cq.Assembly(name="top")
    top.add(cq.Workplane().box(40, 20, 5), name="plate", loc=cq.Location((10, 0, 0)))
    top.add(cq.Workplane().cylinder(30, 4), name="shaft", loc=cq.Location((0, 50, 0), (1, 0, 0), 90))
    top.add(sub, name="sub", loc=cq.Location((100, 0, 0), (0, 0, 1), 90))
    return top


def _export(assy: cq.Assembly, path: Path, unit: str = "MM") -> Path:
    with statics():
        assert exportAssembly(assy, str(path), unit="MM", outputUnit=unit)  # type: ignore[arg-type]
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """The assembly written in mm, inches and metres."""
    folder = tmp_path_factory.mktemp("step_import")
    assy = _assembly()
    return {unit: _export(assy, folder / f"assy_{unit}.step", unit) for unit in ("MM", "INCH", "M")}


def _one_line_naming(exc: pytest.ExceptionInfo, path: Path | str) -> str:
    message = str(exc.value)
    assert "\n" not in message
    assert str(path) in message
    assert isinstance(exc.value, ValueError)
    return message


def _assert_box(actual, expected) -> None:
    for got, want in zip(actual, expected, strict=True):
        assert got == pytest.approx(want, abs=TOL_MM)


def _assert_assembly(read: StepFile) -> None:
    assert read.names() == ["plate", "shaft", "pin"]
    for name in read.names():
        product = read.product(name)
        assert product.path == PATHS[name]
        assert product.solids == 1
        assert product.volume_mm3 == pytest.approx(VOLUMES[name], rel=REL), name
        _assert_box(product.bbox, BBOXES[name])


# ------------------------------------------------------------------------------------------
# Assemblies and units


def test_nested_assembly_leaves_by_name_placed_through_every_level(files):
    read = read_step(files["MM"])
    assert read.unit == "MM"
    assert read.path == files["MM"]
    _assert_assembly(read)


def test_inch_file_reads_in_millimetres(files):
    text = files["INCH"].read_text()
    assert "CONVERSION_BASED_UNIT('INCH'" in text
    assert "0.393700787402" in text  # the plate's 10 mm offset, written in inches
    read = read_step(files["INCH"])
    assert read.unit == "INCH"
    _assert_assembly(read)


def test_metre_file_reads_in_millimetres(files):
    assert "SI_UNIT($,.METRE.)" in files["M"].read_text()
    read = read_step(files["M"])
    assert read.unit == "M"
    _assert_assembly(read)


@pytest.mark.parametrize("cascade", ["INCH", "M", "MM"])
@pytest.mark.parametrize("unit", ["MM", "INCH"])
def test_millimetres_whatever_the_process_cascade_unit(files, unit, cascade):
    """Another exporter in the process may leave ``xstep.cascade.unit`` at inches or metres (an
    XCAF document without a unit of its own would follow it): the reader gives mm all the same."""
    with statics(xstep_cascade_unit=cascade):
        read = read_step(files[unit])
        assert Interface_Static.CVal_s("xstep.cascade.unit") == cascade  # not changed by the read
    _assert_assembly(read)


def test_repeated_instances_get_unique_names_and_share_geometry(tmp_path):
    """One sub-assembly placed twice: its pin appears twice (``pin``, ``pin#2``), each placed,
    both on the one B-rep (no copy per instance)."""
    sub = cq.Assembly(name="sub")
    sub.add(cq.Workplane().box(2, 3, 4), name="pin", loc=cq.Location((1, 2, 3)))
    top = cq.Assembly(name="top")
    top.add(sub, name="left", loc=cq.Location((100, 0, 0)))
    top.add(sub, name="right", loc=cq.Location((-100, 0, 0)))
    read = read_step(_export(top, tmp_path / "twice.step"))
    assert read.names() == ["pin", "pin#2"]
    assert [p.path for p in read.products] == [("top", "left", "pin"), ("top", "right", "pin#2")]
    left, right = read.products
    _assert_box(left.bbox, ((100.0, 0.5, 1.0), (102.0, 3.5, 5.0)))
    _assert_box(right.bbox, ((-100.0, 0.5, 1.0), (-98.0, 3.5, 5.0)))
    assert left.volume_mm3 == right.volume_mm3 == pytest.approx(24.0, rel=REL)
    assert left.shape.IsPartner(right.shape)  # same TShape, different locations
    assert not left.shape.IsSame(right.shape)


def test_same_leaf_name_in_two_sub_assemblies(tmp_path):
    top = cq.Assembly(name="top")
    for side, x in (("left", -50), ("right", 50)):
        sub = cq.Assembly(name=side)
        sub.add(cq.Workplane().box(1, 1, 1), name="bolt")
        sub.add(cq.Workplane().box(2, 2, 2), name="nut", loc=cq.Location((0, 0, 5)))
        top.add(sub, name=side, loc=cq.Location((x, 0, 0)))
    read = read_step(_export(top, tmp_path / "bolts.step"))
    assert read.names() == ["bolt", "nut", "bolt#2", "nut#2"]
    assert read.product("bolt#2").path == ("top", "right", "bolt#2")
    assert read.product("bolt#2").bbox[0][0] == pytest.approx(49.5, abs=TOL_MM)


# ------------------------------------------------------------------------------------------
# Names given by XCAF documents written directly


def _doc() -> tuple[TDocStd_Document, XCAFDoc_ShapeTool]:
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    tool.SetAutoNaming_s(False)
    return doc, tool


def _name(label, text: str) -> None:
    TDataStd_Name.Set_s(label, TCollection_ExtendedString(text))


def _write_doc(doc: TDocStd_Document, path: Path) -> Path:
    with statics(xstep_cascade_unit="MM", write_step_unit="MM"):
        writer = STEPCAFControl_Writer(XSControl_WorkSession(), False)
        writer.SetNameMode(True)
        assert writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs)
        writer.Write(str(path))
    return path


def test_instance_names_preferred_to_the_product_name(tmp_path):
    """A product ``bolt`` placed twice as ``bolt-1`` and ``bolt-2`` (as SolidWorks names
    instances): the leaves take the instance names, the path the root's product name."""
    doc, tool = _doc()
    root = tool.NewShape()
    _name(root, "frame")
    bolt = tool.AddShape(cq.Solid.makeBox(1, 2, 3).wrapped, False, False)
    _name(bolt, "bolt")
    for k, x in ((1, 0.0), (2, 10.0)):
        component = tool.AddComponent(root, bolt, cq.Location((x, 0, 0)).wrapped)
        _name(component, f"bolt-{k}")
    tool.UpdateAssemblies()
    read = read_step(_write_doc(doc, tmp_path / "bolts.step"))
    assert read.names() == ["bolt-1", "bolt-2"]
    assert read.product("bolt-2").path == ("frame", "bolt-2")
    _assert_box(read.product("bolt-2").bbox, ((10.0, 0.0, 0.0), (11.0, 2.0, 3.0)))


def test_flat_file_named_by_its_product(tmp_path):
    doc, tool = _doc()
    label = tool.AddShape(cq.Solid.makeCylinder(5, 10).wrapped, False, False)
    _name(label, "bracket")
    read = read_step(_write_doc(doc, tmp_path / "bracket.step"))
    assert read.names() == ["bracket"]
    (product,) = read.products
    assert product.path == ("bracket",)
    assert product.volume_mm3 == pytest.approx(math.pi * 25 * 10, rel=REL)
    _assert_box(product.bbox, ((-5.0, -5.0, 0.0), (5.0, 5.0, 10.0)))


# ------------------------------------------------------------------------------------------
# Flat files


def test_flat_single_solid_from_cadquery_export(tmp_path):
    """``cq.exporters.export`` gives the product OCCT's placeholder name: the solid is ``solid_1``."""
    path = tmp_path / "box.step"
    with statics():
        cq.exporters.export(cq.Workplane().box(40, 20, 5).translate((1, 2, 3)), str(path))
    assert "Open CASCADE STEP translator" in path.read_text()
    read = read_step(path)
    assert read.unit == "MM"
    assert read.names() == ["solid_1"]
    (product,) = read.products
    assert product.path == ("solid_1",)
    assert product.solids == 1
    assert product.volume_mm3 == pytest.approx(4000.0, rel=REL)
    _assert_box(product.bbox, ((-19.0, -8.0, 0.5), (21.0, 12.0, 5.5)))


def test_flat_several_free_solids(tmp_path):
    path = tmp_path / "roots.step"
    with statics(xstep_cascade_unit="MM", write_step_unit="MM"):
        writer = STEPControl_Writer()
        for solid in (cq.Solid.makeBox(1, 1, 1), cq.Solid.makeBox(2, 2, 2, pnt=cq.Vector(10, 0, 0))):
            writer.Transfer(solid.wrapped, STEPControl_StepModelType.STEPControl_AsIs)
        writer.Write(str(path))
    read = read_step(path)
    assert read.names() == ["solid_1", "solid_2"]
    assert [p.volume_mm3 for p in read.products] == pytest.approx([1.0, 8.0], rel=REL)
    _assert_box(read.product("solid_2").bbox, ((10.0, 0.0, 0.0), (12.0, 2.0, 2.0)))


def test_flat_compound_of_solids(tmp_path):
    path = tmp_path / "two.step"
    two = cq.Workplane().box(1, 1, 1).union(cq.Workplane().box(1, 1, 1).translate((5, 0, 0)))
    with statics():
        cq.exporters.export(two, str(path))
    read = read_step(path)
    assert read.names() == ["solid_1", "solid_2"]
    assert all(p.solids == 1 and p.volume_mm3 == pytest.approx(1.0, rel=REL) for p in read.products)
    _assert_box(read.product("solid_2").bbox, ((4.5, -0.5, -0.5), (5.5, 0.5, 0.5)))


# ------------------------------------------------------------------------------------------
# Errors


def test_unknown_product_name_lists_the_names(files):
    read = read_step(files["MM"])
    with pytest.raises(StepImportError) as exc:
        read.product("gear")
    message = _one_line_naming(exc, files["MM"])
    assert "'gear'" in message
    assert all(repr(n) in message for n in ("plate", "shaft", "pin"))


def test_missing_file(tmp_path):
    path = tmp_path / "absent.step"
    with pytest.raises(StepImportError) as exc:
        read_step(path)
    assert "no such STEP file" in _one_line_naming(exc, path)


def test_directory(tmp_path):
    with pytest.raises(StepImportError) as exc:
        read_step(tmp_path)
    assert "not a file" in _one_line_naming(exc, tmp_path)


@pytest.mark.parametrize("text", ["hello world\nthis is not a STEP file\n", ""])
def test_not_step(tmp_path, capfd, text):
    path = tmp_path / "garbage.step"
    path.write_text(text)
    with pytest.raises(StepImportError) as exc:
        read_step(path)
    assert "not a readable STEP file" in _one_line_naming(exc, path)
    out, err = capfd.readouterr()
    assert "StepFile" not in out + err  # OCCT's parser message is not printed


def test_no_roots(tmp_path):
    path = tmp_path / "point.step"
    path.write_text("ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\n"
                    "FILE_NAME('point.step','2026-01-01T00:00:00',('a'),('b'),'c','d','e');\n"
                    "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\n"
                    "DATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n")
    with pytest.raises(StepImportError) as exc:
        read_step(path)
    assert "no product or shape" in _one_line_naming(exc, path)


@pytest.mark.parametrize("kind", ["wire", "edge", "face"])
def test_no_solids(tmp_path, kind):
    shape: cq.Shape = {
        "wire": cq.Wire.makePolygon([cq.Vector(0, 0, 0), cq.Vector(1, 0, 0), cq.Vector(1, 1, 0)], close=True),
        "edge": cq.Edge.makeLine(cq.Vector(0, 0, 0), cq.Vector(1, 2, 3)),
        "face": cq.Face.makePlane(3, 3),
    }[kind]
    path = tmp_path / f"{kind}.step"
    with statics():
        cq.exporters.export(shape, str(path))
    with pytest.raises(StepImportError) as exc:
        read_step(path)
    assert "holds no solids" in _one_line_naming(exc, path)


# ------------------------------------------------------------------------------------------
# Naming rule


def test_unique_names():
    assert unique_names(["a", None, "a", "b", "a", None]) == ["a", "solid_1", "a#2", "b", "a#3", "solid_2"]
    # a name the file gives is never taken by a generated one
    assert unique_names(["a", "a", "a#2", None, "solid_1"]) == ["a", "a#3", "a#2", "solid_2", "solid_1"]
