"""Still pictures of a run's geometry (PNG), for print and the README: ``assembly.png`` (the whole
assembly as built) and ``worst_N.png`` (worst pose N, zoomed on the closest points, which are
marked), drawn offscreen with VTK (installed with CadQuery) from the same :class:`Scene` and
cameras (:mod:`gearcheck.report.camera`) as the report's 3D view.

VTK draws in a child process (``python -m gearcheck.report.pictures``, the scene as built and
then its worst poses pickled on its stdin, the pictures pickled on its stdout). A check starts it
with the run (:class:`Drawing`): it loads VTK while the CAD is built and draws the assembly while
the worst poses are confirmed, and the pictures are the same bytes as drawn at once. Offscreen
OpenGL goes through EGL (``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``, no X display), and on
a machine with no EGL, VTK falls back to OSMesa and, where that is missing too, crashes the
process (a segmentation fault, seen with VTK 9.6). In a child, such a crash becomes
:class:`PicturesUnavailable` with VTK's own last words, never a dead pipeline or a silent gap.

The pictures are deterministic: the same scene gives the same bytes (no time stamp in the PNG,
fixed size, fixed fonts).
"""

from __future__ import annotations

import functools
import math
import os
import pickle
import subprocess
import sys
from dataclasses import replace

import numpy as np

from gearcheck.report.camera import (
    DEFAULT_DIRECTION,
    azimuth_elevation,
    orbit_direction,
    pair,
    section,
    worst_direction,
    zoom_radius,
)
from gearcheck.report.child import ChildOwner
from gearcheck.scene import PoseView, Scene, distance_text

WIDTH, HEIGHT = 960, 720
FOV_DEG = 30.0  # vertical, as the 3D view
BACKGROUND = (0.957, 0.965, 0.976)
EDGE_RGB = (0.19, 0.20, 0.24)
RED, BLUE, ORANGE = (0.85, 0.1, 0.1), (0.1, 0.3, 0.9), (0.88, 0.54, 0.0)
SECTION_SHADE = 0.6  # a section's cut faces: the part's colour this much darker
FADED_OPACITY = 0.14
TIMEOUT_S = 300.0
# At most this many worst poses are drawn (the closest: a large assembly has one per pair, and
# each picture of a scene of many parts takes VTK about a second); the GLB and the 3D view keep all.
MAX_WORST_PICTURES = 12


class PicturesUnavailable(RuntimeError):
    """VTK could not draw offscreen here; ``reason`` says why (shown in the report instead)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def _messages(scene: Scene) -> list[bytes]:
    """What the picture process reads on its stdin: the scene as built (no worst poses: the
    assembly picture needs nothing else), then the worst poses."""
    return [pickle.dumps(replace(scene, worst=[])), pickle.dumps(list(scene.worst))]


def _environment() -> dict[str, str]:
    env = dict(os.environ)
    env.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    return env


def _received(returncode: int, stdout: bytes, stderr: bytes) -> dict[str, bytes]:
    """The pictures a finished picture process gave, or :class:`PicturesUnavailable` saying why not."""
    if returncode != 0:
        how = f"signal {-returncode}" if returncode < 0 else f"exit code {returncode}"
        raise PicturesUnavailable(f"VTK could not draw offscreen ({how}): {_last_words(stderr)}")
    try:
        out = pickle.loads(stdout)
    except (pickle.UnpicklingError, EOFError, ValueError) as exc:
        raise PicturesUnavailable(f"the picture process gave no pictures: {_last_words(stderr)}") from exc
    png = b"\x89PNG\r\n\x1a\n"
    if not isinstance(out, dict) or not all(isinstance(v, bytes) and v.startswith(png) for v in out.values()):
        raise PicturesUnavailable("the picture process gave something other than PNG pictures")
    return out


def pictures(scene: Scene, timeout_s: float = TIMEOUT_S) -> dict[str, bytes]:
    """``{"assembly.png": …, "worst_1.png": …, …}`` (PNG bytes) of the scene, drawn by VTK in a
    child process. Raises :class:`PicturesUnavailable` when it cannot draw."""
    try:
        done = subprocess.run([sys.executable, "-m", "gearcheck.report.pictures"], input=b"".join(_messages(scene)),
                              capture_output=True, env=_environment(), timeout=timeout_s, check=False)
    except subprocess.TimeoutExpired as exc:
        raise PicturesUnavailable(f"VTK did not finish the pictures in {timeout_s:.0f} s") from exc
    return _received(done.returncode, done.stdout, done.stderr)


class Drawing(ChildOwner):
    """The picture process of :func:`pictures`, started before its scene exists so that its
    start-up (Python, VTK) and the assembly picture overlap the run's other stages: started
    empty, given the scene as built (:meth:`assembly`: it draws the assembly picture at once),
    then the worst poses (:meth:`worst`), and :meth:`result` collects the same pictures, with
    the same errors, as :func:`pictures` of the whole scene. Use it in a ``with`` block: leaving
    it ends the process if its pictures were not collected."""

    def __init__(self, timeout_s: float = TIMEOUT_S):
        from gearcheck.report.child import ChildProcess

        self.timeout_s = timeout_s
        self._child = ChildProcess("gearcheck.report.pictures", _environment())
        self._sent = 0

    def assembly(self, scene: Scene) -> None:
        """Give the process the scene as built (its worst poses, if any, are not drawn yet)."""
        if self._sent != 0:
            raise RuntimeError("the scene was given already")
        self._child.send(_messages(scene)[0])
        self._sent = 1

    def worst(self, scene: Scene) -> None:
        """Give the process the worst poses of ``scene`` (the scene given to :meth:`assembly`,
        with its worst poses) and let it finish."""
        if self._sent != 1:
            raise RuntimeError("give the scene as built first")
        self._child.send(_messages(scene)[1])
        self._child.finish()
        self._sent = 2

    def result(self) -> dict[str, bytes]:
        """The pictures (waits for the process), or :class:`PicturesUnavailable`."""
        if self._sent != 2:
            raise RuntimeError("give the scene and its worst poses first")
        done = self._child.wait(self.timeout_s)
        if done is None:
            raise PicturesUnavailable(f"VTK did not finish the pictures in {self.timeout_s:.0f} s")
        return _received(*done)



render_pictures = pictures  # the name the pipeline calls it by


def _last_words(stderr: bytes, lines: int = 3) -> str:
    """The last few distinct warning/error lines of VTK's log (escape codes and stamps removed)."""
    text = stderr.decode("utf-8", "replace")
    plain = []
    for raw in text.splitlines():
        line = "".join(ch for ch in raw if ch.isprintable())
        line = line.replace("[0m", "").replace("[33m", "").replace("[31m", "").strip()
        if "|" in line:
            line = line.split("|", 1)[1].strip()
        if line and line not in plain:
            plain.append(line)
    return " / ".join(plain[-lines:]) or "no message"


# ------------------------------------------------------------------------------------------
# The child process: everything below runs with VTK imported.


def _polydata(vertices: np.ndarray, faces: np.ndarray):
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData

    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.ascontiguousarray(vertices, np.float64), deep=True))
    cells = vtkCellArray()
    f = np.asarray(faces, np.int64)
    offsets = np.arange(0, 3 * len(f) + 1, 3, dtype=np.int64)
    cells.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True), numpy_to_vtkIdTypeArray(f.reshape(-1), deep=True))
    poly = vtkPolyData()
    poly.SetPoints(points)
    poly.SetPolys(cells)
    return poly


def _mappers(vertices: np.ndarray, faces: np.ndarray) -> tuple:
    """(surface mapper with split normals, B-rep edge mapper) of one display mesh."""
    from vtkmodules.vtkFiltersCore import vtkFeatureEdges, vtkPolyDataNormals
    from vtkmodules.vtkRenderingCore import vtkPolyDataMapper

    normals = vtkPolyDataNormals()
    normals.SetInputData(_polydata(vertices, faces))
    normals.SetFeatureAngle(35.0)
    normals.SplittingOn()
    normals.ConsistencyOff()
    normals.AutoOrientNormalsOff()
    surface = vtkPolyDataMapper()
    surface.SetInputConnection(normals.GetOutputPort())
    # each B-rep face has its own vertices (cad.display), so a face's boundary is a boundary of
    # the mesh: these are the B-rep edges, as a CAD viewer draws them
    edges = vtkFeatureEdges()
    edges.SetInputData(_polydata(vertices, faces))
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOff()
    edges.ManifoldEdgesOff()
    edges.FeatureEdgesOff()
    edges.ColoringOff()
    lines = vtkPolyDataMapper()
    lines.SetInputConnection(edges.GetOutputPort())
    lines.ScalarVisibilityOff()
    return surface, lines


def _matrix(m: np.ndarray):
    from vtkmodules.vtkCommonMath import vtkMatrix4x4

    out = vtkMatrix4x4()
    for i in range(4):
        for j in range(4):
            out.SetElement(i, j, float(m[i, j]))
    return out


class _Stage:
    """One offscreen window with every part as an actor (meshes shared between copies)."""

    def __init__(self, scene: Scene):
        import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text)
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the OpenGL window factory)
        from vtkmodules.vtkRenderingCore import vtkActor, vtkLightKit, vtkPolyDataMapper, vtkRenderer, vtkRenderWindow

        self.scene = scene
        vtkPolyDataMapper.SetResolveCoincidentTopologyToPolygonOffset()
        self.window = vtkRenderWindow()
        self.window.SetOffScreenRendering(1)
        self.window.SetSize(WIDTH, HEIGHT)
        self.window.SetMultiSamples(0)
        self.renderer = vtkRenderer()
        self.renderer.SetBackground(*BACKGROUND)
        self.renderer.SetUseDepthPeeling(1)
        self.renderer.SetMaximumNumberOfPeels(8)
        self.renderer.SetOcclusionRatio(0.0)
        self.renderer.UseFXAAOn()
        vtkLightKit().AddLightsToRenderer(self.renderer)
        self.window.SetAlphaBitPlanes(1)
        self.window.AddRenderer(self.renderer)
        self.actors: dict[str, tuple] = {}
        mappers: dict[int, tuple] = {}
        self.mappers = mappers
        for p in scene.parts:
            key = id(p.vertices)
            if key not in mappers:
                mappers[key] = _mappers(p.vertices, p.faces)
            surface, lines = mappers[key]
            body, outline = vtkActor(), vtkActor()
            body.SetMapper(surface)
            outline.SetMapper(lines)
            prop = body.GetProperty()
            prop.SetColor(*p.color)
            prop.SetAmbient(0.25)
            prop.SetDiffuse(0.75)
            prop.SetSpecular(0.2)
            prop.SetSpecularPower(30)
            inside = prop.NewInstance()  # where a section cuts the part open
            inside.DeepCopy(prop)
            inside.SetAmbient(0.6)
            inside.SetDiffuse(0.3)
            body.SetBackfaceProperty(inside)
            outline.GetProperty().SetColor(*EDGE_RGB)
            outline.GetProperty().SetLineWidth(1.0)
            self.renderer.AddActor(body)
            self.renderer.AddActor(outline)
            self.actors[p.name] = (body, outline)
        self.extras: list = []

    def pose(self, view: PoseView | None, highlight: list[str] | None = None) -> None:
        for p in self.scene.parts:
            pose = p.pose if view is None else np.asarray(view.poses.get(p.name, p.pose), float)
            scale = 1.0 if view is None else float(view.scales.get(p.name, 1.0))
            m = np.asarray(pose, float).copy()
            m[:3, :3] *= scale
            body, outline = self.actors[p.name]
            faded = bool(highlight) and p.name not in (highlight or [])
            for actor in (body, outline):
                actor.SetUserMatrix(_matrix(m))
                actor.GetProperty().SetOpacity(FADED_OPACITY if faded else 1.0)
            colour = np.asarray(p.color, float)
            if highlight and p.name == highlight[0]:  # a hint of the marker's colour: which part is which
                colour = 0.82 * colour + 0.18 * np.asarray(RED)
            elif highlight and len(highlight) > 1 and p.name == highlight[1]:
                colour = 0.82 * colour + 0.18 * np.asarray(BLUE)
            body.GetProperty().SetColor(*(float(c) for c in colour))
            body.GetBackfaceProperty().SetColor(*(float(c) for c in SECTION_SHADE * colour))
            outline.SetVisibility(not faded)

    def cut(self, plane: tuple[np.ndarray, np.ndarray] | None) -> None:
        """Cut every part away on the camera's side of ``plane`` (point, normal toward the camera)."""
        from vtkmodules.vtkCommonDataModel import vtkPlane

        for surface, lines in self.mappers.values():
            for mapper in (surface, lines):
                mapper.RemoveAllClippingPlanes()
                if plane is not None:
                    clip = vtkPlane()
                    clip.SetOrigin(*plane[0])
                    clip.SetNormal(*(-plane[1]))  # the side the normal points to is kept
                    mapper.AddClippingPlane(clip)

    def clear(self) -> None:
        for actor in self.extras:
            self.renderer.RemoveViewProp(actor)
        self.extras = []

    def look(self, centre: np.ndarray, direction: np.ndarray, distance: float) -> None:
        camera = self.renderer.GetActiveCamera()
        camera.SetViewAngle(FOV_DEG)
        camera.SetFocalPoint(*centre)
        camera.SetPosition(*(centre + distance * direction))
        camera.SetViewUp(0.0, 0.0, 1.0)
        camera.OrthogonalizeViewUp()
        self.renderer.ResetCameraClippingRange()

    def fit(self, points: np.ndarray, direction: np.ndarray) -> None:
        """Look from ``direction`` with ``points`` filling the view, centred (as the 3D view)."""
        tan_v = math.tan(math.radians(FOV_DEG / 2))
        tan_h = tan_v * WIDTH / HEIGHT
        right = np.cross(direction, (0.0, 0.0, 1.0))
        if np.linalg.norm(right) < 1e-9:
            right = np.array([1.0, 0.0, 0.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, direction)
        q = points @ np.column_stack([right, up, direction])
        mid = 0.5 * (q.min(axis=0) + q.max(axis=0))
        centre = mid[0] * right + mid[1] * up + mid[2] * direction
        q = q - mid
        need = float(np.max(np.maximum(q[:, 2] + np.abs(q[:, 0]) / tan_h, q[:, 2] + np.abs(q[:, 1]) / tan_v)))
        self.look(centre, direction, 1.06 * need)

    def text(self, lines: list[str], corner: int = 2, size: int = 18) -> None:
        from vtkmodules.vtkRenderingCore import vtkTextActor

        actor = vtkTextActor()
        actor.SetInput("\n".join(lines))
        prop = actor.GetTextProperty()
        font = _font_file()
        if font:  # VTK's own Arial has no Greek (θ in the sweep's labels)
            from vtkmodules.vtkCommonCore import VTK_FONT_FILE

            prop.SetFontFamily(VTK_FONT_FILE)
            prop.SetFontFile(font)
        else:
            prop.SetFontFamilyToArial()
        prop.SetFontSize(size)
        prop.SetColor(0.11, 0.14, 0.19)
        prop.SetBackgroundColor(1.0, 1.0, 1.0)
        prop.SetBackgroundOpacity(0.85)
        prop.SetFrame(0)
        if corner == 2:  # top left
            prop.SetVerticalJustificationToTop()
            actor.SetPosition(12, HEIGHT - 12)
        else:  # bottom left
            actor.SetPosition(12, 12)
        self.renderer.AddViewProp(actor)
        self.extras.append(actor)

    def marks(self, a: np.ndarray, b: np.ndarray, radius: float) -> None:
        from vtkmodules.vtkFiltersSources import vtkLineSource, vtkSphereSource

        for point, colour, r in ((a, RED, radius), (b, BLUE, 0.6 * radius)):
            sphere = vtkSphereSource()
            sphere.SetCenter(*point)
            sphere.SetRadius(r)
            sphere.SetThetaResolution(24)
            sphere.SetPhiResolution(16)
            self._add(sphere, colour)
        line = vtkLineSource()
        line.SetPoint1(*a)
        line.SetPoint2(*b)
        actor = self._add(line, ORANGE)
        actor.GetProperty().SetLineWidth(3.0)

    def _add(self, source, colour):
        from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

        mapper = vtkPolyDataMapper()
        mapper.SetInputConnection(source.GetOutputPort())
        actor = vtkActor()
        actor.SetMapper(mapper)
        actor.GetProperty().SetColor(*colour)
        actor.GetProperty().SetAmbient(0.5)
        self.renderer.AddActor(actor)
        self.extras.append(actor)
        return actor

    def png(self) -> bytes:
        from vtkmodules.vtkIOImage import vtkPNGWriter
        from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

        self.window.Render()
        grab = vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.ShouldRerenderOff()
        grab.Update()
        writer = vtkPNGWriter()
        writer.SetInputConnection(grab.GetOutputPort())
        writer.SetCompressionLevel(6)
        writer.WriteToMemoryOn()
        writer.Write()
        return bytes(memoryview(writer.GetResult()))


@functools.lru_cache(maxsize=1)
def _font_file() -> str:
    """DejaVu Sans as shipped with matplotlib (a dependency): the same glyphs on every machine.
    Found in matplotlib's package folder without importing it (its import costs the picture
    process about 0.1 s for one path); looked up once per process, not for every picture's text."""
    import importlib.util

    try:
        spec = importlib.util.find_spec("matplotlib")
    except (ImportError, ValueError):
        return ""
    if spec is None or not spec.submodule_search_locations:
        return ""
    for folder in spec.submodule_search_locations:
        path = os.path.join(folder, "mpl-data", "fonts", "ttf", "DejaVuSans.ttf")
        if os.path.exists(path):
            return path
    return ""


def _fmt(x: float | None) -> str:
    return distance_text(x) or "n/a"


def render(scene: Scene) -> dict[str, bytes]:
    """The pictures (in this process: needs VTK and an offscreen OpenGL)."""
    drawer = _Drawer(scene)
    return {**drawer.assembly(), **drawer.worst(scene)}


class _Drawer:
    """The pictures in their order: the assembly first (it needs only the parts), then each
    worst pose, on one stage (:func:`render` draws both at once, the picture process as its
    messages come)."""

    def __init__(self, scene: Scene):
        self.stage = _Stage(scene)
        self.everything = np.concatenate(list(scene.world_vertices().values()))

    def assembly(self) -> dict[str, bytes]:
        stage, scene = self.stage, self.stage.scene
        stage.pose(None)
        stage.fit(self.everything, DEFAULT_DIRECTION)
        stage.text([f"{scene.name}: as built ({len(scene.parts)} parts)"])
        return {"assembly.png": stage.png()}

    def worst(self, scene: Scene) -> dict[str, bytes]:
        """The worst poses of ``scene`` (the stage's scene with its worst poses; the closest
        :data:`MAX_WORST_PICTURES` of them where there are more: :func:`drawn_worst`)."""
        stage, out = self.stage, {}
        drawn = set(drawn_worst(scene.worst))
        for i, view in enumerate(scene.worst, start=1):
            if i not in drawn:
                continue
            stage.clear()
            stage.cut(None)
            names = pair(view)
            stage.pose(view, names)
            lines = [f"worst pose {i}: {view.label}"]
            if view.point_a is not None and view.point_b is not None:
                a, b = np.asarray(view.point_a, float), np.asarray(view.point_b, float)
                radius = zoom_radius(scene, view)
                direction = orbit_direction(*azimuth_elevation(worst_direction(scene, view)))
                stage.look(0.5 * (a + b), direction, radius / math.sin(math.radians(FOV_DEG / 2)))
                stage.cut(section(scene, view))
                stage.marks(a, b, 0.02 * radius)
                lines.append(f"closest points {_fmt(view.distance_mm)} (red on {names[0]}, blue on {names[1]})"
                             if len(names) == 2 else f"closest points {_fmt(view.distance_mm)}")
            else:
                shown = scene.world_vertices(view)
                stage.fit(np.concatenate([shown[n] for n in names if n in shown] or [self.everything]),
                          DEFAULT_DIRECTION)
            if view.note:
                lines.append(view.note)
            stage.text([line for line in lines if line])
            out[f"worst_{i}.png"] = stage.png()
        return out


def drawn_worst(views: list[PoseView]) -> list[int]:
    """The worst poses that get a picture (their numbers, from 1, in order): every one, or, where
    there are more than :data:`MAX_WORST_PICTURES`, those with the least distance."""
    def distance(k: int) -> float:
        d = views[k].distance_mm
        return d if d is not None and math.isfinite(d) else math.inf

    order = sorted(range(len(views)), key=lambda k: (distance(k), k))
    return sorted(k + 1 for k in order[:MAX_WORST_PICTURES])


def _child() -> int:
    """The picture process: VTK loaded while it waits; the scene as built (the assembly is drawn
    as soon as it comes), then the worst poses, on stdin; the pictures pickled on stdout."""
    import vtkmodules.vtkFiltersCore  # noqa: F401  (loaded before the scene comes)
    import vtkmodules.vtkFiltersSources  # noqa: F401
    import vtkmodules.vtkIOImage  # noqa: F401
    import vtkmodules.vtkRenderingFreeType  # noqa: F401
    import vtkmodules.vtkRenderingOpenGL2  # noqa: F401

    _font_file()  # looked up (once, cached) while the scene is on its way
    # the pictures go to the real stdout; anything VTK prints there goes to stderr instead
    out = os.fdopen(os.dup(1), "wb")
    sys.stdout.flush()
    os.dup2(2, 1)
    stdin = sys.stdin.buffer
    built = pickle.load(stdin)
    drawer = _Drawer(built)
    drawn = drawer.assembly()
    drawn.update(drawer.worst(replace(built, worst=pickle.load(stdin))))
    out.write(pickle.dumps(drawn))
    out.close()
    return 0


if __name__ == "__main__":
    sys.exit(_child())
