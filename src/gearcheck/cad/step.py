"""STEP assembly writer on OCP's XCAF (the one place a STEP file is made).

The file (AP214, mm) holds one assembly product named after the run and, under it, one product
per part *instance* named by the part's role (``big_gear_left``, ``link_07``): copies that share
one solid in memory get a topological copy each (geometry shared, so no extra kernel work), so a
bill of materials lists every instance by its own name instead of "big_gear_right ×2". Each
instance is placed by its pose, coloured by its material (:data:`PALETTE`) and carries its
material name, and its density where the palette knows it (g/cm³, the OCCT convention).

Written so a file on disk is either complete and checked or not there:

* every status is checked: transfer to a STEP model and the serialisation must succeed, else
  :class:`StepWriteError` (an ``OSError``) naming the path;
* the bytes go to a temporary file beside the target (an ``OSError`` such as EFBIG under
  ``ulimit -f`` surfaces as :class:`StepWriteError`), are fsynced, and are verified before the
  rename: size, the ``END-ISO-10303-21;`` trailer, and a parse of the file read back with
  ``STEPControl_Reader`` giving the root product and one product per part by name, each with
  its number of solids;
* the output is deterministic: OCCT numbers assembly occurrences with a process-wide counter
  (renumbered in the model) and registers the colour presentations in a hash-map order that
  depends on memory addresses (renumbered in the serialised text: entity lookups by handle do
  not work through the Python bindings). The header's time stamp is
  ``SOURCE_DATE_EPOCH`` when set (reproducible builds), else the current time; author,
  organisation and originating system are fixed (``gearcheck`` and its version). The
  translator settings that shape the file are set for the write and restored after it.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import re
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import OCP
from OCP.APIHeaderSection import APIHeaderSection_MakeHeader
from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy
from OCP.IFSelect import IFSelect_ReturnStatus
from OCP.Interface import Interface_Static
from OCP.Quantity import Quantity_Color, Quantity_TypeOfColor
from OCP.STEPCAFControl import STEPCAFControl_Controller, STEPCAFControl_Writer
from OCP.STEPControl import STEPControl_Reader, STEPControl_StepModelType
from OCP.StepBasic import (
    StepBasic_DerivedUnit,
    StepBasic_Product,
    StepBasic_SiUnitAndLengthUnit,
    StepBasic_SiUnitAndMassUnit,
)
from OCP.StepRepr import StepRepr_MeasureRepresentationItem, StepRepr_NextAssemblyUsageOccurrence
from OCP.StepShape import StepShape_ShapeDefinitionRepresentation, StepShape_SolidModel
from OCP.TCollection import TCollection_ExtendedString, TCollection_HAsciiString
from OCP.TDataStd import TDataStd_Name
from OCP.TDocStd import TDocStd_Document
from OCP.TopAbs import TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.XCAFApp import XCAFApp_Application
from OCP.XCAFDoc import XCAFDoc_ColorType, XCAFDoc_DocumentTool
from OCP.XSControl import XSControl_WorkSession

from gearcheck import __version__
from gearcheck.cad.placement import Part, location
from gearcheck.output import replace_atomically
from gearcheck.params import ParamError

log = logging.getLogger("gearcheck")

STEP_TRAILER = b"END-ISO-10303-21;"
TIMESTAMP_FORMAT = "%Y-%m-%dT%H:%M:%S+00:00"
# FILE_NAME('name', 'time stamp', ...: the stamp as TIMESTAMP_FORMAT writes it
_STAMP = re.compile(rb"FILE_NAME\('(?:[^']|'')*',\s*'(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00)'")
AUTHOR = "gearcheck"
ORGANISATION = "gearcheck"
ORIGINATING_SYSTEM = f"gearcheck {__version__}"
PREPROCESSOR = f"Open CASCADE STEP processor {OCP.__version__}"  # the OCP build that wrote it

# Translator settings (process-wide Interface_Static values) that decide what the file looks like:
# set for each write, whatever another exporter in this process left there, and restored after.
WRITER_SETTINGS = {
    "write.step.schema": "AP214IS",
    "write.step.unit": "MM",
    "xstep.cascade.unit": "MM",
    "write.step.assembly": "Auto",
    "write.precision.mode": "Average",
    "write.surfacecurve.mode": "On",
    "write.step.vertex.mode": "Compound",
    "write.step.nonmanifold": "Off",
    "write.stepcaf.subshapes.name": "Off",
    "write.step.tessellated": "Off",
    "write.step.product.name": "gearcheck part",
    "write.step.sequence": "ToSTEP",
}


class StepWriteError(OSError):
    """The STEP could not be written completely (transfer, serialisation, disk, or the check of
    the file read back); no file is left at the target path. An OSError with ``filename`` the
    STEP path, ``strerror`` the cause and ``errno`` that of the failed system call (else None)."""

    def __init__(self, path: str | os.PathLike, cause: str, code: int | None = None):
        super().__init__(code, cause, str(path))

    def __str__(self) -> str:
        return f"{self.filename}: cannot write the STEP file: {self.strerror}"


# ------------------------------------------------------------------------------------------
# Material palette


@dataclass(frozen=True)
class MaterialStyle:
    """How a material shows in the STEP: a colour (sRGB, 0–1) and, where the name identifies
    the alloy, its density (g/cm³, room temperature, handbook value)."""

    label: str
    family: str  # base metal: a name naming two families is a composite (no density)
    keywords: tuple[str, ...]  # lower-case substrings of the material name
    rgb: tuple[float, float, float]
    density_g_cm3: float | None = None


STAINLESS = (0.72, 0.72, 0.78)
STEEL = (0.62, 0.63, 0.67)
TITANIUM = (0.55, 0.55, 0.60)
ALUMINIUM = (0.85, 0.85, 0.90)
CAST_ALUMINIUM = (0.30, 0.30, 0.35)

# First match wins (so a specific alloy comes before its family). Densities: ASM handbook
# values; 7A09 (GB/T 3190) has the composition limits of 7075, so it takes 7075's 2.81 g/cm³.
PALETTE: tuple[MaterialStyle, ...] = (
    MaterialStyle("titanium alloy Ti-6Al-4V (TC4)", "titanium", ("ti-6al-4v", "tc4"), TITANIUM, 4.43),
    MaterialStyle("titanium", "titanium", ("titanium",), TITANIUM),
    MaterialStyle("stainless steel 17-4PH", "steel", ("17-4ph", "cf170"), STAINLESS, 7.78),
    MaterialStyle("stainless steel", "steel", ("stainless",), STAINLESS),
    MaterialStyle("cast aluminium", "aluminium", ("cast aluminium", "cast aluminum"), CAST_ALUMINIUM),
    MaterialStyle("aluminium alloy 7075", "aluminium", ("7075",), ALUMINIUM, 2.81),
    MaterialStyle("aluminium alloy 7A09", "aluminium", ("7a09",), ALUMINIUM, 2.81),
    MaterialStyle("aluminium", "aluminium", ("aluminium", "aluminum"), ALUMINIUM),
    MaterialStyle("steel", "steel", ("steel",), STEEL, 7.85),
)


@dataclass(frozen=True)
class Appearance:
    """What the STEP records for one part's material."""

    material: str
    description: str  # the palette entry ("" when the name matched none)
    rgb: tuple[float, float, float]
    density_g_cm3: float | None


def material_style(material: str) -> MaterialStyle | None:
    """The first palette entry whose keyword occurs in ``material`` (case-insensitive)."""
    low = material.lower()
    return next((s for s in PALETTE if any(k in low for k in s.keywords)), None)


def appearance(part: Part) -> Appearance:
    """Colour and density of a part by its material name; a name the palette does not know
    keeps the part's own colour and gets no density, and so does the density of a name that
    names two metal families ("cast aluminium link with steel sleeve")."""
    style = material_style(part.material)
    if style is None:
        return Appearance(part.material, "", tuple(part.color), None)  # type: ignore[arg-type]
    low = part.material.lower()
    families = {s.family for s in PALETTE if any(k in low for k in s.keywords)}
    density = style.density_g_cm3 if len(families) == 1 else None
    return Appearance(part.material, style.label, style.rgb, density)


# ------------------------------------------------------------------------------------------
# Header


def header_timestamp(environ: Mapping[str, str] | None = None) -> str:
    """ISO 8601 UTC time stamp for the header: ``SOURCE_DATE_EPOCH`` (whole seconds since
    1970, the reproducible-builds convention) when set, else now. A malformed value is a
    ParamError (the build stops rather than stamping a wrong time)."""
    env = os.environ if environ is None else environ
    raw = env.get("SOURCE_DATE_EPOCH", "")
    if raw == "":
        return datetime.fromtimestamp(int(time.time()), UTC).strftime(TIMESTAMP_FORMAT)
    try:
        return datetime.fromtimestamp(int(raw), UTC).strftime(TIMESTAMP_FORMAT)
    except (ValueError, OverflowError, OSError):
        raise ParamError("SOURCE_DATE_EPOCH", raw, "allowed a whole number of seconds since 1970-01-01 UTC "
                         "(environment variable)") from None


def _hstr(text: str) -> TCollection_HAsciiString:
    return TCollection_HAsciiString(text)


def _set_header(model, file_name: str, assembly_name: str, timestamp: str) -> None:
    header = APIHeaderSection_MakeHeader(model)
    header.SetName(_hstr(file_name))
    header.SetTimeStamp(_hstr(timestamp))
    header.SetAuthorValue(1, _hstr(AUTHOR))
    header.SetOrganizationValue(1, _hstr(ORGANISATION))
    header.SetOriginatingSystem(_hstr(ORIGINATING_SYSTEM))
    header.SetPreprocessorVersion(_hstr(PREPROCESSOR))
    header.SetAuthorisation(_hstr(""))
    header.SetDescriptionValue(1, _hstr(f"gearcheck assembly {assembly_name}"))


@contextlib.contextmanager
def writer_settings() -> Iterator[None]:
    """Set :data:`WRITER_SETTINGS` for one write and put the previous values back. The STEP
    controller is initialised first: before it, the settings do not exist yet (a process whose
    first STEP work is this write would skip them all, and name its products OCCT's way)."""
    STEPCAFControl_Controller.Init_s()
    previous = {k: Interface_Static.CVal_s(k) for k in WRITER_SETTINGS if Interface_Static.IsPresent_s(k)}
    try:
        for key in previous:
            if not Interface_Static.SetCVal_s(key, WRITER_SETTINGS[key]):
                raise RuntimeError(f"STEP writer setting {key}={WRITER_SETTINGS[key]!r} was refused")
        yield
    finally:
        for key, value in previous.items():
            Interface_Static.SetCVal_s(key, value)


# ------------------------------------------------------------------------------------------
# Document → STEP model → bytes


def solid_count(shape) -> int:
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    n = 0
    while explorer.More():
        n += 1
        explorer.Next()
    return n


def _name(label, text: str) -> None:
    TDataStd_Name.Set_s(label, TCollection_ExtendedString(text))


def xcaf_document(parts: Sequence[Part], assembly_name: str) -> TDocStd_Document:
    """An XCAF document: root assembly ``assembly_name`` with one named, coloured, material-
    tagged product per part (each its own copy of the shape), placed by the part's pose."""
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFApp_Application.GetApplication_s().InitDocument(doc)
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)  # model values are mm
    shapes = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    shapes.SetAutoNaming_s(False)
    colors = XCAFDoc_DocumentTool.ColorTool_s(doc.Main())
    materials = XCAFDoc_DocumentTool.MaterialTool_s(doc.Main())
    root = shapes.NewShape()
    _name(root, assembly_name)
    for part in parts:
        # a copy per instance (topology only, geometry shared): one TShape → one product
        shape = BRepBuilderAPI_Copy(part.solid.wrapped, False, False).Shape()
        label = shapes.AddShape(shape, False, False)
        _name(label, part.name)
        look = appearance(part)
        color = Quantity_Color(*look.rgb, Quantity_TypeOfColor.Quantity_TOC_sRGB)
        colors.SetColor(label, color, XCAFDoc_ColorType.XCAFDoc_ColorSurf)
        materials.SetMaterial(label, _hstr(look.material), _hstr(look.description), look.density_g_cm3 or 0.0,
                              _hstr("density"), _hstr("POSITIVE_RATIO_MEASURE"))
        component = shapes.AddComponent(root, label, location(part.pose).wrapped)
        _name(component, part.name)
    shapes.UpdateAssemblies()
    return doc


def part21_string(text: str) -> str:
    """``text`` as an ISO 10303-21 string's contents: ASCII as it is, every run of other
    characters as ``\\X2\\`` + four hex digits a character + ``\\X0\\`` (``\\X4\\``, eight
    digits, beyond the basic plane)."""
    out: list[str] = []
    for run in re.findall(r"[\x00-\x7f]+|[^\x00-\x7f\U00010000-\U0010ffff]+|[\U00010000-\U0010ffff]+", text):
        if run.isascii():
            out.append(run)
        elif ord(run[0]) <= 0xFFFF:
            out.append("\\X2\\" + "".join(f"{ord(c):04X}" for c in run) + "\\X0\\")
        else:
            out.append("\\X4\\" + "".join(f"{ord(c):08X}" for c in run) + "\\X0\\")
    return "".join(out)


def _written_as(text: str) -> str | None:
    """The name OCCT's model holds as ``text`` (UTF-8 bytes as Latin-1 characters), decoded; None
    for an ASCII text or one that is not such bytes."""
    if text.isascii():
        return None
    try:
        return text.encode("latin-1").decode("utf-8")
    except UnicodeError:
        return None


def _encode_names(entity) -> None:
    """The entity's id, name and description in ISO 10303-21's encoding (see :func:`_fix_model`)."""
    for field in ("Id", "Name", "Description"):
        value = getattr(entity, field)() if hasattr(entity, field) else None
        if value is None:
            continue
        original = _written_as(value.ToCString())
        if original is not None:
            getattr(entity, "Set" + field)(_hstr(part21_string(original)))


def _entities(model) -> list:
    return [model.Value(i) for i in range(1, model.NbEntities() + 1)]


def _fix_model(model) -> None:
    """Entity fields OCCT fills in a way that depends on the process, or wrongly.

    * NEXT_ASSEMBLY_USAGE_OCCURRENCE ids come from a process-wide counter: renumber 1, 2, ….
    * The density unit is written as g³·cm² (exponents swapped in OCCT's writer): make it g·cm⁻³
      (OCCT's reader takes the value as g/cm³ either way).
    * A name beyond ASCII (``齿轮``) reaches the model as its UTF-8 bytes taken one by one as
      Latin-1 characters, which the file would show as ``é½¿è½®``: write it in ISO 10303-21's
      own encoding, ``\\X2\\9F7F8F6E\\X0\\``, which every reader (OCCT's too) decodes.
    """
    k = 0
    for e in _entities(model):
        if isinstance(e, (StepBasic_Product, StepRepr_NextAssemblyUsageOccurrence)):
            _encode_names(e)
        if isinstance(e, StepRepr_NextAssemblyUsageOccurrence):
            k += 1
            e.SetId(_hstr(str(k)))
        elif isinstance(e, StepRepr_MeasureRepresentationItem) and e.Name().ToCString() == "density":
            unit = e.Measure().UnitComponent().DerivedUnit()
            if isinstance(unit, StepBasic_DerivedUnit):
                for j in range(1, unit.NbElements() + 1):
                    element = unit.ElementsValue(j)
                    if isinstance(element.Unit(), StepBasic_SiUnitAndMassUnit):
                        element.SetExponent(1.0)
                    elif isinstance(element.Unit(), StepBasic_SiUnitAndLengthUnit):
                        element.SetExponent(-3.0)


# a quoted string (kept as is), a line break with its indentation (dropped), an entity reference
_FIELD = re.compile(rb"'(?:[^']|'')*'|\r?\n[ \t]*|#(\d+)")
_RECORD_END = re.compile(rb"'(?:[^']|'')*'|;")
_REF = re.compile(rb"'(?:[^']|'')*'|#(\d+)")
_MDGPR = re.compile(rb"\n#(\d+) = MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION\(")


def _refs(body: bytes) -> list[int]:
    return [int(m.group(1)) for m in _REF.finditer(body) if m.group(1) is not None]


def canonical_colour_order(text: bytes) -> bytes:
    """Renumber the colour presentations OCCT appends last in hash-map order (one
    MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION per product, each followed by the
    styles and colours it brings first): presentations in the order of the entities they style,
    each followed depth-first by what it references, one record a line. The entity numbers
    before the first presentation, and so every shape, product and placement, are unchanged."""
    found = _MDGPR.search(text)
    if found is None:
        return text
    tail_at = found.start() + 1
    first = int(found.group(1))
    data_end = text.rindex(b"\nENDSEC;", tail_at) + 1
    records: dict[int, bytes] = {}
    at = tail_at
    for m in _RECORD_END.finditer(text, tail_at, data_end):
        if m.group(0) == b";":
            head, _, body = text[at:m.start()].strip().partition(b"=")
            records[int(head.strip()[1:])] = body.strip()
            at = m.end()
    if text[at:data_end].strip() or sorted(records) != list(range(first, first + len(records))):
        log.warning("STEP: unexpected layout of the writer's colour records; entity order left as written")
        return text
    inside = {n: [r for r in _refs(body) if r in records] for n, body in records.items()}

    def closure(n: int, seen: set[int], out: list[int]) -> None:
        if n in seen:
            return
        seen.add(n)
        out.append(n)
        for r in inside[n]:
            closure(r, seen, out)

    def key(n: int) -> list[int]:  # what a presentation styles: entities before the tail
        members: list[int] = []
        closure(n, set(), members)
        return sorted(r for m in members for r in _refs(records[m]) if r < first)

    presentations = [n for n, body in records.items()
                     if body.startswith(b"MECHANICAL_DESIGN_GEOMETRIC_PRESENTATION_REPRESENTATION(")]
    order: list[int] = []
    seen: set[int] = set()
    for n in sorted(presentations, key=lambda n: (key(n), n)):
        closure(n, seen, order)
    order += [n for n in records if n not in seen]
    renumber = {old: first + i for i, old in enumerate(order)}

    def field(m: re.Match) -> bytes:
        if m.group(1) is not None:
            return b"#%d" % renumber.get(int(m.group(1)), int(m.group(1)))
        return b"" if m.group(0)[:1] in b"\r\n" else m.group(0)

    head_text = text[:tail_at]
    if any(int(r) >= first for r in re.findall(rb"#(\d+)", head_text[head_text.index(b"\nDATA;"):])):
        log.warning("STEP: an entity before the colour records refers to one of them; entity order left as written")
        return text
    tail = b"".join(b"#%d = %s;\n" % (first + i, _FIELD.sub(field, records[old])) for i, old in enumerate(order))
    return head_text + tail + text[data_end:]


def step_bytes(parts: Sequence[Part], assembly_name: str, path: Path) -> bytes:
    """The bytes of the STEP file ``path`` will hold (nothing touches the disk; the header
    names ``path.name``). StepWriteError if OCCT reports a failed transfer or serialisation."""
    doc = xcaf_document(parts, assembly_name)
    with writer_settings():
        session = XSControl_WorkSession()
        writer = STEPCAFControl_Writer(session, False)
        writer.SetColorMode(True)
        writer.SetNameMode(True)
        writer.SetMaterialMode(True)
        writer.SetLayerMode(False)
        writer.SetPropsMode(False)
        writer.SetSHUOMode(False)
        writer.SetDimTolMode(False)
        if not writer.Transfer(doc, STEPControl_StepModelType.STEPControl_AsIs):
            raise StepWriteError(path, "OCCT could not transfer the assembly to a STEP model")
        model = writer.ChangeWriter().Model()
        _fix_model(model)
        _set_header(model, Path(path).name, assembly_name, header_timestamp())
        stream = io.BytesIO()
        status = writer.WriteStream(stream)
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise StepWriteError(path, f"the OCCT STEP writer returned {status.name}")
    data = stream.getvalue()
    if not data.rstrip().endswith(STEP_TRAILER):
        raise StepWriteError(path, f"the OCCT STEP writer's output has no {STEP_TRAILER.decode()} trailer")
    return canonical_colour_order(data)


# ------------------------------------------------------------------------------------------
# Checking a written file


def step_products(path: Path, shown: Path | None = None) -> tuple[dict[str, int], list[str]]:
    """Parse a STEP file (entities only, no geometry transfer): ``{product name: solids in its
    shape representation}`` and the assembly occurrence names in file order. StepWriteError
    (naming ``shown``, default ``path``) if the file does not parse."""
    reader = STEPControl_Reader()
    status = reader.ReadFile(str(path))
    if status != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise StepWriteError(shown or path, f"the file read back does not parse ({status.name})")
    products: dict[str, int] = {}
    occurrences: list[str] = []
    for e in _entities(reader.StepModel()):
        if isinstance(e, StepShape_ShapeDefinitionRepresentation):
            pds = e.Definition().PropertyDefinition()
            product = pds.Definition().ProductDefinition().Formation().OfProduct()
            rep = e.UsedRepresentation()
            solids = sum(isinstance(rep.ItemsValue(k), StepShape_SolidModel) for k in range(1, rep.NbItems() + 1))
            name = product.Name().ToCString()
            products[name] = products.get(name, 0) + solids
        elif isinstance(e, StepRepr_NextAssemblyUsageOccurrence):
            occurrences.append(e.Name().ToCString())
    return products, occurrences


def verify_step_file(path: Path, parts: Sequence[Part], assembly_name: str, size: int,
                     shown: Path | None = None, products: bool = True) -> None:
    """The file as written: ``size`` bytes, the ISO 10303-21 trailer, and (with ``products``)
    read back, the root product plus one product per part by name, each with the part's solids,
    and one assembly occurrence per part in order. StepWriteError naming ``shown`` (default
    ``path``)."""
    path = Path(path)
    shown = shown or path
    actual = path.stat().st_size
    if actual != size:
        raise StepWriteError(shown, f"{actual} bytes on disk, {size} written")
    with open(path, "rb") as fh:
        fh.seek(max(0, size - 64))
        if not fh.read().rstrip().endswith(STEP_TRAILER):
            raise StepWriteError(shown, f"no {STEP_TRAILER.decode()} trailer on disk")
    if not products:
        return
    found, occurrences = step_products(path, shown)
    expected = {assembly_name: 0} | {p.name: solid_count(p.solid.wrapped) for p in parts}
    if found != expected:
        raise StepWriteError(shown, f"read back, products and solids {found} instead of {expected}")
    if occurrences != [p.name for p in parts]:
        raise StepWriteError(shown, f"read back, instances {occurrences} instead of {[p.name for p in parts]}")


def restamped(data: bytes, timestamp: str) -> bytes | None:
    """A STEP file's bytes with its header's time stamp replaced by ``timestamp`` (of
    :data:`TIMESTAMP_FORMAT`, so the header keeps its length and line breaks), or None where the
    header holds no such stamp."""
    stamp = timestamp.encode("ascii")
    end = data.find(b"ENDSEC;")
    head = data[:end]
    found = list(_STAMP.finditer(head)) if end > 0 else []
    if len(found) != 1 or len(found[0].group(1)) != len(stamp):
        return None
    m = found[0]
    return head[:m.start(1)] + stamp + head[m.end(1):] + data[end:]


def write_step(parts: Sequence[Part], path: Path, assembly_name: str, data: bytes | None = None) -> bytes:
    """Write the STEP assembly to ``path`` atomically and check it; returns the bytes written.
    ``data``: a STEP file these parts made before (from the cache), stamped now and checked for
    its size and trailer as written (its products were read back when it was made); else the
    file is made now and read back. StepWriteError (an OSError whose ``filename`` is ``path``)
    on any failure, leaving neither the file nor a temporary file behind."""
    path = Path(path)
    names = [p.name for p in parts]
    if assembly_name in names or len(set(names)) != len(names):
        raise ValueError(f"STEP product names must be unique: {assembly_name!r} and {names}")
    stamped = restamped(data, header_timestamp()) if data is not None else None
    if stamped is None:
        stamped = step_bytes(parts, assembly_name, path)
        products = True
    else:
        products = False

    def check(tmp: Path) -> None:
        verify_step_file(tmp, parts, assembly_name, len(stamped), shown=path, products=products)

    try:
        replace_atomically(path, stamped, check=check)
    except StepWriteError:
        raise
    except OSError as exc:  # EFBIG under ulimit -f, ENOSPC, EACCES…
        raise StepWriteError(path, exc.strerror or str(exc), exc.errno) from exc
    return stamped
