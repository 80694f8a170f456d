"""STEP assembly reader on OCP's XCAF (a user's own STEP file, from any CAD system).

:func:`read_step` reads a file with ``STEPCAFControl_Reader`` into an XCAF document (names on;
colours, layers, materials, GD&T and metadata off) and returns a :class:`StepFile`: one
:class:`StepProduct` per *leaf product instance* that holds at least one solid, reached from the
file's free shapes through every level of (nested) sub-assemblies, each with its shape already
placed in the file's global frame.

Units
-----
STEP coordinates are in the file's own length unit (each representation context declares one:
``SI_UNIT(.MILLI.,.METRE.)``, ``CONVERSION_BASED_UNIT('INCH', …)``…) and OCCT scales them into a
*target* unit while transferring. In OCCT 7.9 ``STEPCAFControl_Reader::Transfer`` takes that
target from the XCAF document's length unit when the document has one; when it has none, it uses
the process-wide ``xstep.cascade.unit`` setting and stamps that on the document. That setting is
global state any exporter may change and leave changed (CadQuery's ``exportAssembly`` sets it to
its ``unit`` argument), so, tried with OCP 7.9.3: an inch file read into a document without a
unit after ``xstep.cascade.unit`` was set to ``INCH`` came back in inches, and a millimetre file
after ``M`` came back in metres. Here the document's length unit is set to millimetres
(``XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)``, in metres) before the transfer, which
gives millimetres for every file unit whatever ``xstep.cascade.unit`` holds, and no process-wide
setting is touched. :attr:`StepFile.unit` is the unit the file declares (``STEPControl_Reader::
FileUnits``), normalised to ``MM``, ``CM``, ``M``, ``UM``, ``INCH``, ``FT``… (several contexts
with different units: the distinct units comma-joined in file order, e.g. ``"MM,INCH"``).

Names
-----
A level of the tree (a leaf or a sub-assembly) is named by its *instance* name (the
``NEXT_ASSEMBLY_USAGE_OCCURRENCE``'s description or name, as OCCT reads it) when the file gives
one, else by its *product* name. Two kinds of name are treated as no name:

* the occurrence's *id*, which OCCT puts on an instance whose name and description are both
  empty (CadQuery writes its sub-assembly instances so: ``NEXT_ASSEMBLY_USAGE_OCCURRENCE('4',
  '','',…)`` would name the instance ``4``);
* the placeholder product name OCCT's writer gives a shape without one (``Open CASCADE STEP
  translator 7.9 2``, as ``cadquery.exporters.export`` writes it).

An occurrence named beyond ASCII (``齿轮``, encoded ``\\X2\\9F7F8F6E\\X0\\`` in the file) keeps its
name: OCCT's reader would put the occurrence's id in its place, and the id is read back as the
name the file gives.

A leaf without a name is ``solid_1``, ``solid_2``… in file order. Leaf names are made unique in
file order: a name that occurs again gets ``#2``, ``#3``… (skipping any name the file itself
uses, so no name the file gives is ever changed). :attr:`StepProduct.path` names every level
from the root down (``""`` for a sub-assembly level without a name) and ends with the product's
unique name.

Shapes are shared, not copied: a product's shape is the transferred shape moved by the composed
location of its levels (``TopoDS_Shape.Moved``: same geometry and topology, new placement), so N
instances of one part hold one copy of its B-rep; the STEP entity model and the XCAF document are
released when :func:`read_step` returns.

Every failure is a :class:`StepImportError` (a ``ValueError``) with a one-line message naming the
file; OCCT's own console messages are silenced while the file is read.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from OCP.Bnd import Bnd_Box
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepGProp import BRepGProp
from OCP.GProp import GProp_GProps
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Message import Message
from OCP.STEPCAFControl import STEPCAFControl_Reader
from OCP.StepRepr import StepRepr_NextAssemblyUsageOccurrence
from OCP.TCollection import TCollection_AsciiString, TCollection_ExtendedString
from OCP.TColStd import TColStd_SequenceOfAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDF import TDF_Label, TDF_LabelSequence, TDF_Tool
from OCP.TDocStd import TDocStd_Document
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS_Shape
from OCP.XCAFApp import XCAFApp_Application
from OCP.XCAFDoc import XCAFDoc_DocumentTool
from OCP.XCAFDoc import XCAFDoc_ShapeTool as ShapeTool

from gearcheck.cad.step import solid_count

log = logging.getLogger("gearcheck")

Point = tuple[float, float, float]
BBox = tuple[Point, Point]

# the product name OCCT's STEP writer gives a shape that has none ("… translator 7.9 2", "… 7.9 1.1")
_OCCT_PLACEHOLDER = re.compile(r"Open CASCADE STEP translator \d+(\.\d+)* \d+(\.\d+)*")
# the unit names STEPControl_Reader.FileUnits gives (SI: prefix + "metre"; else the file's own name)
_UNITS = {
    "millimetre": "MM", "millimeter": "MM", "mm": "MM",
    "centimetre": "CM", "centimeter": "CM", "cm": "CM",
    "decimetre": "DM", "decimeter": "DM",
    "metre": "M", "meter": "M", "m": "M",
    "kilometre": "KM", "kilometer": "KM", "km": "KM",
    "micrometre": "UM", "micrometer": "UM", "micron": "UM",
    "nanometre": "NM", "nanometer": "NM",
    "inch": "INCH", "in": "INCH",
    "foot": "FT", "feet": "FT", "ft": "FT",
    "mile": "MI", "mi": "MI",
    "yard": "YD", "yd": "YD",
    "mil": "MIL", "thou": "MIL",
}
DOCUMENT_UNIT_M = 0.001  # the XCAF document's length unit, in metres: shapes come out in mm
_NAMES_SHOWN = 40  # at most this many names listed in an error message


class StepImportError(ValueError):
    """A STEP file that cannot be used: missing, unreadable, not STEP, without solids, or a
    product name it does not have. The message is one line and names the file."""


@dataclass
class StepProduct:
    """One leaf product instance of a STEP file: a shape with at least one solid, placed in the
    file's global frame, in millimetres.

    ``name`` is unique in the file (see the module docstring for the naming rule); ``path``
    names the levels from the root down and ends with ``name``; ``shape`` is an OCP
    ``TopoDS_Shape`` sharing its B-rep with every other instance of the same product;
    ``bbox`` is ``((xmin, ymin, zmin), (xmax, ymax, zmax))`` of the placed shape (exact, not
    enlarged by tolerances)."""

    name: str
    path: tuple[str, ...]
    shape: TopoDS_Shape
    solids: int
    volume_mm3: float
    bbox: BBox


@dataclass
class StepFile:
    """A STEP file as read by :func:`read_step`: its path, the length unit it declares
    (``MM``, ``INCH``… whatever it is, the products are in millimetres) and its leaf products
    in file order."""

    path: Path
    unit: str
    products: list[StepProduct] = field(default_factory=list)

    def names(self) -> list[str]:
        """The products' unique names, in file order."""
        return [p.name for p in self.products]

    def product(self, name: str) -> StepProduct:
        """The product named ``name``; StepImportError listing the file's names if there is none."""
        for p in self.products:
            if p.name == name:
                return p
        raise StepImportError(f"{self.path}: no product named {name!r}; the file has {_listing(self.names())}")


@dataclass(frozen=True)
class _Leaf:
    """A leaf instance found in the document, before names are made unique."""

    names: tuple[str | None, ...]  # each level's name from the root down, None where it has none
    product: TDF_Label  # the product's own label (its shape in its own frame)
    location: TopLoc_Location  # composed placement of every level above it


def _listing(names: list[str]) -> str:
    """``'a', 'b', …`` on one line (names repr-quoted, so no line break gets through), at most
    :data:`_NAMES_SHOWN` of them."""
    shown = ", ".join(repr(n) for n in names[:_NAMES_SHOWN])
    more = len(names) - _NAMES_SHOWN
    return f"{len(names)} products: {shown}" + (f", … and {more} more" if more > 0 else "")


def _one_line(text: str) -> str:
    """``text`` with every run of white space (line breaks included) made one space."""
    return " ".join(str(text).split())


# ------------------------------------------------------------------------------------------
# Reading the file into an XCAF document


@contextlib.contextmanager
def _occt_quiet() -> Iterator[None]:
    """Detach the printers of OCCT's default messenger (parse errors, transfer warnings go to
    the console otherwise) for the read, and put them back after it."""
    messenger = Message.DefaultMessenger_s()
    printers = messenger.Printers()
    saved = [printers.Value(i) for i in range(1, printers.Size() + 1)]
    for printer in saved:
        messenger.RemovePrinter(printer)
    try:
        yield
    finally:
        for printer in saved:
            messenger.AddPrinter(printer)


def _reader() -> STEPCAFControl_Reader:
    """An XCAF reader that transfers shapes and names only."""
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    reader.SetColorMode(False)
    reader.SetLayerMode(False)
    reader.SetPropsMode(False)
    reader.SetMatMode(False)
    reader.SetGDTMode(False)
    reader.SetSHUOMode(False)
    reader.SetViewMode(False)
    reader.SetMetaMode(False)
    reader.SetProductMetaMode(False)
    return reader


def _document() -> TDocStd_Document:
    """An empty XCAF document whose length unit is the millimetre: the reader scales the
    file's coordinates to it (see the module docstring)."""
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, DOCUMENT_UNIT_M)
    return doc


def _check_openable(path: Path) -> None:
    """StepImportError unless ``path`` is a file this process can open."""
    if not path.exists():
        raise StepImportError(f"{path}: no such STEP file")
    if not path.is_file():
        raise StepImportError(f"{path}: not a file")
    try:
        with open(path, "rb"):
            pass
    except OSError as exc:
        raise StepImportError(f"{path}: cannot open the STEP file: {_one_line(exc.strerror or str(exc))}") from None


def _file_unit(reader: STEPCAFControl_Reader) -> str:
    """The length unit(s) the file declares, normalised (``MM``, ``INCH``…), ``UNKNOWN`` if none."""
    lengths, angles, solid_angles = (TColStd_SequenceOfAsciiString() for _ in range(3))
    reader.ChangeReader().FileUnits(lengths, angles, solid_angles)
    units: list[str] = []
    for i in range(1, lengths.Length() + 1):
        raw = lengths.Value(i).ToCString().strip()
        unit = _UNITS.get(raw.lower(), raw.upper())
        if unit and unit not in units:
            units.append(unit)
    return ",".join(units) or "UNKNOWN"


def _id_only_instances(reader: STEPCAFControl_Reader) -> dict[str, str | None]:
    """The ids OCCT may have put in place of an assembly occurrence's name, each with the name
    it stands for: ``None`` for an occurrence with neither name nor description (OCCT names such
    an instance by its id), the decoded name for one whose name holds characters beyond ASCII
    (``\\X2\\...\\X0\\`` in the file: OCCT's reader drops such a name for the id). An id that
    another occurrence uses as its own name is left out: it is a real name there."""
    model = reader.ChangeReader().StepModel()
    ids: dict[str, str | None] = {}
    names: set[str] = set()
    for i in range(1, model.NbEntities() + 1):
        entity = model.Value(i)
        if not isinstance(entity, StepRepr_NextAssemblyUsageOccurrence):
            continue
        description = entity.Description().ToCString() if entity.HasDescription() else ""
        name = entity.Name().ToCString() if entity.Name() is not None else ""
        own = (description or name).strip()
        if own:
            names.add(own)
        if entity.Id() is None:
            continue
        if not own:
            ids[entity.Id().ToCString()] = None
        elif not own.isascii():
            ids[entity.Id().ToCString()] = own
    return {k: v for k, v in ids.items() if k not in names or v is not None}


def _transfer(path: Path) -> tuple[TDocStd_Document, str, dict[str, str | None]]:
    """Parse and transfer the file: the XCAF document (mm), the file's unit and the ids OCCT
    used as instance names. The reader (and its STEP entity model) is released on return."""
    reader = _reader()
    try:
        with _occt_quiet():
            status = reader.ReadFile(str(path))
            if status != IFSelect_ReturnStatus.IFSelect_RetDone:
                raise StepImportError(f"{path}: not a readable STEP file (the OCCT STEP parser returned {status.name})")
            if reader.NbRootsForTransfer() == 0:
                raise StepImportError(f"{path}: not a STEP file with shapes (no product or shape representation "
                                      "to transfer)")
            unit = _file_unit(reader)
            id_only = _id_only_instances(reader)
            doc = _document()
            if not reader.Transfer(doc):
                raise StepImportError(f"{path}: OCCT could not transfer the STEP file's shapes")
    except StepImportError:
        raise
    except Exception as exc:  # an OCCT exception (Standard_Failure) surfacing through the bindings
        raise StepImportError(f"{path}: OCCT failed reading the STEP file: "
                              f"{_one_line(f'{type(exc).__name__}: {exc}')}") from None
    return doc, unit, id_only


# ------------------------------------------------------------------------------------------
# Walking the document


_NO_IDS: Mapping[str, str | None] = {}


def _label_name(label: TDF_Label) -> str:
    """The label's TDataStd_Name, "" if it has none."""
    attr = TDataStd_Name()
    return attr.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), attr) else ""


def _real(name: str, id_only: Mapping[str, str | None] = _NO_IDS) -> str | None:
    """``name`` unless it is empty or OCCT's placeholder; an id OCCT put in place of a name is
    the name it stands for (``None`` for an occurrence without one)."""
    name = name.strip()
    if name in id_only:
        return id_only[name]
    if not name or _OCCT_PLACEHOLDER.fullmatch(name):
        return None
    return name


def _level_name(instance: TDF_Label | None, product: TDF_Label, id_only: Mapping[str, str | None]) -> str | None:
    """A level's name: the instance's own name when it has one, else the product's."""
    own = _real(_label_name(instance), id_only) if instance is not None else None
    return own or _real(_label_name(product))


def _leaves(doc: TDocStd_Document, id_only: Mapping[str, str | None]) -> list[_Leaf]:
    """Every leaf (non-assembly) product instance reachable from the free shapes, depth first in
    file order, with its composed placement."""
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    free = TDF_LabelSequence()
    tool.GetFreeShapes(free)
    out: list[_Leaf] = []
    for i in range(1, free.Length() + 1):
        root = free.Value(i)
        _walk(root, None, TopLoc_Location(), (), id_only, out)
    return out


def _walk(product: TDF_Label, instance: TDF_Label | None, location: TopLoc_Location,
          names: tuple[str | None, ...], id_only: Mapping[str, str | None], out: list[_Leaf]) -> None:
    """Append the leaves under ``product`` (reached through ``instance``, None for a free
    shape) to ``out``: a component's placement is composed after its parent's (``location``)."""
    names = (*names, _level_name(instance, product, id_only))
    if not ShapeTool.IsAssembly_s(product):
        out.append(_Leaf(names, product, location))
        return
    components = TDF_LabelSequence()
    ShapeTool.GetComponents_s(product, components, False)
    for i in range(1, components.Length() + 1):
        component = components.Value(i)
        referred = TDF_Label()
        if not ShapeTool.GetReferredShape_s(component, referred):
            continue
        placed = location.Multiplied(ShapeTool.GetLocation_s(component))
        _walk(referred, component, placed, names, id_only, out)


# ------------------------------------------------------------------------------------------
# Products


def volume_mm3(shape: TopoDS_Shape) -> float:
    """Volume of ``shape`` (its solids) in the shape's unit cubed."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, False, False, False)
    return float(props.Mass())


def centroid(shape: TopoDS_Shape) -> tuple[float, float, float]:
    """Centre of volume of ``shape`` (its solids), in the shape's frame and unit: on a gear's
    axis whatever its tooth count (a bounding box's centre is not, for an odd count)."""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props, False, False, False)
    c = props.CentreOfMass()
    return float(c.X()), float(c.Y()), float(c.Z())


def bounding_box(shape: TopoDS_Shape) -> BBox:
    """Exact axis-aligned bounds of ``shape`` (from its geometry, not enlarged by tolerances)."""
    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    xmin, ymin, zmin, xmax, ymax, zmax = box.Get()
    return (xmin, ymin, zmin), (xmax, ymax, zmax)


def unique_names(raw: list[str | None]) -> list[str]:
    """Unique names in order: an unnamed entry is ``solid_<k>``; a repeated name gets ``#2``,
    ``#3``…; a generated name never takes a name given in ``raw``."""
    given = {n for n in raw if n is not None}
    used: set[str] = set()
    out: list[str] = []
    unnamed = 0
    for name in raw:
        if name is None:
            unnamed += 1
            candidate, base, k = f"solid_{unnamed}", None, 1
        else:
            candidate, base, k = name, name, 1
        while candidate in used or (candidate != name and candidate in given):
            if base is None:
                unnamed += 1
                candidate = f"solid_{unnamed}"
            else:
                k += 1
                candidate = f"{base}#{k}"
        used.add(candidate)
        out.append(candidate)
    return out


def _entry(label: TDF_Label) -> str:
    """The label's entry (``0:1:1:3``): one key per product of the document."""
    entry = TCollection_AsciiString()
    TDF_Tool.Entry_s(label, entry)
    return str(entry.ToCString())


def _products(leaves: list[_Leaf]) -> list[StepProduct]:
    """The products of the leaves that hold solids: placed shapes, sizes and unique names."""
    solid: list[tuple[_Leaf, TopoDS_Shape, int]] = []
    for leaf in leaves:
        shape = ShapeTool.GetShape_s(leaf.product)
        n = solid_count(shape)
        if n:
            solid.append((leaf, shape, n))
        else:
            log.debug("STEP: %s holds no solid; left out", "/".join(x or "?" for x in leaf.names))
    names = unique_names([leaf.names[-1] for leaf, _, _ in solid])
    volumes: dict[str, float] = {}  # per product label: one volume for all its instances
    products = []
    for (leaf, shape, n), name in zip(solid, names, strict=True):
        placed = shape.Moved(leaf.location)
        scale = leaf.location.Transformation().ScaleFactor()
        if abs(abs(scale) - 1.0) > 1e-12:
            volume = volume_mm3(placed)
        else:
            key = _entry(leaf.product)
            if key not in volumes:
                volumes[key] = volume_mm3(shape)
            volume = volumes[key]
        path = (*(x or "" for x in leaf.names[:-1]), name)
        products.append(StepProduct(name, path, placed, n, volume, bounding_box(placed)))
    return products


def read_step(path: str | os.PathLike[str]) -> StepFile:
    """Read a STEP file: its leaf products (each instance with at least one solid), placed in
    the file's global frame, in millimetres whatever the file's unit. StepImportError (one line,
    naming the file) if the file is missing, not STEP, unreadable, or holds no solid."""
    file = Path(path)
    _check_openable(file)
    doc, unit, id_only = _transfer(file)
    try:
        leaves = _leaves(doc, id_only)
        products = _products(leaves)
    except Exception as exc:  # an OCCT exception while exploring the transferred shapes
        raise StepImportError(f"{file}: OCCT failed exploring the STEP file's shapes: "
                              f"{_one_line(f'{type(exc).__name__}: {exc}')}") from None
    if not products:
        found = f"{len(leaves)} shape{'' if len(leaves) == 1 else 's'}, none with a solid"
        raise StepImportError(f"{file}: the STEP file holds no solids ({found}: wires, surfaces or points only)")
    return StepFile(file, unit, products)


def baked(shape: TopoDS_Shape) -> TopoDS_Shape:
    """The shape with its placement applied to its geometry and no location left: what a solid of
    a part is, whose own frame is the file's frame (a copy of the B-rep where the shape was placed;
    the shape itself where it was not)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform

    loc = shape.Location()
    if loc.IsIdentity():
        return shape
    return BRepBuilderAPI_Transform(shape.Located(TopLoc_Location()), loc.Transformation(), True).Shape()


def part_solid(product: StepProduct):
    """A product as the solid of a part (a CadQuery shape, its placement baked in: the part's own
    frame is the file's frame)."""
    import cadquery as cq

    return cq.Shape.cast(baked(product.shape))
