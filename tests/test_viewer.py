"""The report's 3D view as HTML (gearcheck.report.viewer), its vendored three.js, the pictures
(gearcheck.report.pictures) and the mechanisms' motion frames (…/display.py), without a browser
(tests/test_browser.py opens the view in Chromium).

The scene here is a template's parts as built (no meshing, no sweep) with one made-up worst pose:
its first two parts where they stand, measured on the exact B-rep (tests/viewer_page.py).
"""

from __future__ import annotations

import base64
import hashlib
import io
import json
import math
import re
from importlib import import_module, resources
from pathlib import Path

import numpy as np
import pytest

TEMPLATES = ["eod_track_drive", "zhurong_differential", "nose_wheel_steering"]
VENDOR = Path(__file__).resolve().parents[1] / "src" / "gearcheck" / "report" / "vendor" / "three"
# The view's HTML for a template (three.js is about 690 kB of it).
HTML_BUDGET_BYTES = 1_600_000


@pytest.fixture(scope="module")
def scenes():
    from viewer_page import made_up_scene

    cache = {}

    def get(name: str):
        if name not in cache:
            cache[name] = made_up_scene(name)
        return cache[name]

    return get


# --- vendored three.js -----------------------------------------------------------------------


def test_vendored_three_matches_its_readme():
    readme = (VENDOR / "README.md").read_text(encoding="utf-8")
    for name in ("three.module.min.js", "LICENSE"):
        digest = hashlib.sha256((VENDOR / name).read_bytes()).hexdigest()
        assert re.search(rf"`{re.escape(name)}`.*`{digest}`", readme), f"{name}: sha256 {digest} not in README.md"
    assert "0.170.0" in readme and 'const t="170"' in (VENDOR / "three.module.min.js").read_text(encoding="utf-8")[:400]
    assert "MIT" in (VENDOR / "LICENSE").read_text(encoding="utf-8")


def test_vendored_files_ship_with_the_package():
    files = resources.files("gearcheck.report")
    assert files.joinpath("vendor/three/three.module.min.js").is_file()
    assert files.joinpath("viewer.js").is_file()


def test_three_export_clause_becomes_a_namespace():
    from gearcheck.report.viewer import three_source

    src = three_source()
    assert "export{" not in src.replace(" ", "") and "export {" not in src
    assert re.search(r"\bimport\s*[({\"'*]|\bimport\s+\w", src) is None, "three.js must not import anything"
    names = dict(e.split(":") for e in src[src.rindex("const THREE={") + 13:src.rindex("};")].split(","))
    for needed in ("WebGLRenderer", "Scene", "PerspectiveCamera", "Mesh", "BufferGeometry", "EdgesGeometry",
                   "MeshStandardMaterial", "Plane", "Points", "SRGBColorSpace", "Matrix4", "BackSide"):
        assert needed in names, needed


# --- the HTML block --------------------------------------------------------------------------


def payload(block: str) -> dict:
    match = re.search(r'<script type="application/json" class="gc3d-data">(.*?)</script>', block, re.S)
    assert match, "no scene data in the view"
    return json.loads(match.group(1))


@pytest.mark.parametrize("name", TEMPLATES)
def test_view_carries_the_scene_and_loads_nothing(scenes, name):
    from gearcheck.report.viewer import viewer_html

    scene = scenes(name)
    block = viewer_html(scene)
    assert block == viewer_html(scene), "the view must be deterministic"
    assert len(block.encode()) <= HTML_BUDGET_BYTES, len(block.encode())
    assert block.startswith('<figure class="gc3d"') and 'data-rendered="0"' in block
    assert block.count("<script") == 2 and block.count("</script>") == 2  # the data and one inline module
    assert re.search(r"<(script|link|img|iframe)[^>]*\s(src|href)=", block) is None, "nothing may load from elsewhere"
    viewer_js = resources.files("gearcheck.report").joinpath("viewer.js").read_text(encoding="utf-8")
    assert re.search(r"\bfetch\s*\(|XMLHttpRequest|\bimport\s*\(|^\s*import\s", viewer_js, re.M) is None
    assert viewer_js in block
    for text in ("drag to turn", "Reset view", "3D view unavailable", "preserveDrawingBuffer: true"):
        assert text.lower() in block.lower(), text

    data = payload(block)
    assert len(data["meshes"]) == len({id(p.vertices) for p in scene.parts})
    for part, entry in zip(scene.parts, data["parts"], strict=True):
        mesh = data["meshes"][entry["m"]]
        vertices = np.frombuffer(base64.b64decode(mesh["v"]), "<f4").reshape(-1, 3)
        faces = np.frombuffer(base64.b64decode(mesh["i"]), "<u2" if mesh["u16"] else "<u4").reshape(-1, 3)
        assert np.array_equal(vertices, np.asarray(part.vertices, np.float32))
        assert np.array_equal(faces, np.asarray(part.faces))
        assert entry["n"] == part.name
        assert np.allclose(np.array(entry["p"]).reshape(4, 4), part.pose, atol=1e-7)
        assert np.allclose(entry["c"], part.color, atol=1e-4)
    (worst,) = data["worst"]
    view = scene.worst[0]
    assert np.allclose(worst["a"], view.point_a, atol=1e-7) and np.allclose(worst["b"], view.point_b, atol=1e-7)
    assert worst["d"] == pytest.approx(view.distance_mm, abs=1e-12)
    assert len(data["frames"]) == len(scene.frames) > 0


def test_section_plane_passes_by_the_closest_points(scenes):
    from gearcheck.report.camera import section, zoom_radius

    for name in TEMPLATES:
        scene = scenes(name)
        view = scene.worst[0]
        point, normal = section(scene, view)
        assert abs(float(np.linalg.norm(normal)) - 1.0) < 1e-12
        middle = 0.5 * (np.asarray(view.point_a) + np.asarray(view.point_b))
        # just behind the closest points, seen from the camera; square to the gap where there is one
        depth = float((middle - point) @ normal)
        assert 0.0 < depth <= 0.01 * zoom_radius(scene, view)
        gap = np.asarray(view.point_b) - np.asarray(view.point_a)
        if np.linalg.norm(gap) > 1e-6:
            assert abs(float(gap @ normal)) <= 1e-9 * max(1.0, float(np.linalg.norm(gap)))


# --- pictures --------------------------------------------------------------------------------


def png_pixels(data: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def test_pictures_are_deterministic_and_show_something(scenes):
    from gearcheck.report.pictures import HEIGHT, WIDTH, pictures

    scene = scenes("nose_wheel_steering")
    first = pictures(scene)
    assert first == pictures(scene), "two renders of one scene must give the same bytes"
    assert sorted(first) == ["assembly.png", "worst_1.png"]
    for name, data in first.items():
        assert len(data) < 400_000, (name, len(data))
        px = png_pixels(data)
        assert px.shape == (HEIGHT, WIDTH, 3)
        colours = len(np.unique(px.reshape(-1, 3), axis=0))
        assert colours > 200 and px.std() > 10.0, (name, colours, px.std())
        background = np.all(px == px[-1, -1], axis=2).mean()
        assert 0.05 < background < 0.95, (name, background)
    # the worst pose is centred on its closest points: the red marker is at the middle
    px = png_pixels(first["worst_1.png"]).astype(int)
    middle = px[HEIGHT // 2 - 25:HEIGHT // 2 + 25, WIDTH // 2 - 25:WIDTH // 2 + 25]
    red = (middle[..., 0] > 150) & (middle[..., 1] < 90) & (middle[..., 2] < 90)
    assert red.sum() >= 20, "no closest-point marker at the middle of the worst pose's picture"


def test_pictures_unavailable_carries_the_reason(monkeypatch, scenes):
    """A render process that dies (as VTK's does on a machine without EGL or OSMesa) is a
    PicturesUnavailable naming the signal and VTK's last words, not a crash."""
    import subprocess

    from gearcheck.report import pictures as pics

    def dead(*args, **kwargs):
        return subprocess.CompletedProcess(args, -11, b"", b"\x1b[33mWARN| libOSMesa not found. It appears that\n")

    monkeypatch.setattr(pics.subprocess, "run", dead)
    with pytest.raises(pics.PicturesUnavailable) as caught:
        pics.pictures(scenes("nose_wheel_steering"))
    assert "signal 11" in caught.value.reason and "libOSMesa not found" in caught.value.reason


def test_pictures_without_egl_fail_with_a_reason(monkeypatch, scenes):
    """Really without EGL (no vendor library for libglvnd) and without OSMesa, VTK cannot draw."""
    import glob

    from gearcheck.report.pictures import PicturesUnavailable, pictures

    if glob.glob("/usr/lib/*/libOSMesa.so*") or glob.glob("/usr/lib/libOSMesa.so*"):
        pytest.skip("OSMesa is installed here: VTK would draw without EGL")
    monkeypatch.setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/egl_vendor.json")
    monkeypatch.setenv("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    with pytest.raises(PicturesUnavailable) as caught:
        pictures(scenes("nose_wheel_steering"))
    assert caught.value.reason


# --- motion frames ---------------------------------------------------------------------------


def frames_of(name: str):
    from gearcheck.design import load_template

    design = load_template(Path(__file__).resolve().parents[1] / "templates" / f"{name}.toml", [])
    assembly = design.impl.assembly(design.params)
    module = import_module(f"gearcheck.mechanisms.{design.mechanism}.display")
    frames, label = module.display_frames(design.params, assembly)
    return design, assembly, frames, label


@pytest.mark.parametrize("name", TEMPLATES)
def test_frames_start_as_built_and_stay_rigid(name):
    _, assembly, frames, label = frames_of(name)
    assert 12 <= len(frames) <= 60 and label
    moving = {p.name for p in assembly.parts if p.motion is not None}
    assert set(frames[0].poses) == moving, "every moving part, and only those, is posed in each frame"
    for f in frames:
        assert set(f.poses) == moving and f.label
        for pose in f.poses.values():
            r = pose[:3, :3]
            assert np.allclose(r @ r.T, np.eye(3), atol=1e-12) and np.linalg.det(r) == pytest.approx(1.0)
            assert np.array_equal(pose[3], [0.0, 0.0, 0.0, 1.0])
    for part, pose in frames[0].poses.items():
        assert np.allclose(pose, assembly.part(part).pose, atol=1e-9), part


def test_steering_frames_let_the_rack_go_and_pick_it_up():
    from gearcheck.mechanisms.steering import analysis as an

    design, assembly, frames, _ = frames_of("nose_wheel_steering")
    tow = an.analyse_towing(assembly.layout.geometry, design.params.towing.max_angle_deg)
    angle = [math.atan2(f.poses["pinion"][1, 0], f.poses["pinion"][0, 0]) for f in frames]
    travel = np.array([f.poses["rack"][0, 3] for f in frames])
    turn = int(np.argmax(angle))
    assert math.degrees(angle[turn]) == pytest.approx(design.params.towing.max_angle_deg)
    assert angle[0] == angle[-1] == 0.0 and travel[0] == 0.0 and abs(travel[-1]) < 1e-3  # the return: to a µm
    assert np.all(np.diff(travel[:turn + 1]) >= 0) and np.all(np.diff(travel[turn:]) <= 0)
    let_go = next(f for f in frames if "let go" in f.label)
    assert let_go.poses["rack"][0, 3] == pytest.approx(tow.travel_at_disengage_mm, abs=1e-6)
    assert math.atan2(let_go.poses["pinion"][1, 0], let_go.poses["pinion"][0, 0]) == pytest.approx(tow.disengage_rad)
    # standing from the disengage to the swing's end and back to the re-engage
    standing = [t for f, t in zip(frames, travel, strict=True)
                if math.atan2(f.poses["pinion"][1, 0], f.poses["pinion"][0, 0]) >= tow.disengage_rad]
    assert np.ptp(standing) < 1e-3
    assert any("picked up" in f.label for f in frames[turn:])


def test_track_frames_advance_the_chain_one_link_per_cycle():
    _, assembly, frames, _ = frames_of("eod_track_drive")
    wrap = assembly.layout.wrap
    per_cycle = (len(frames) - 1) // 2
    links = [p.name for p in assembly.parts if p.name.startswith("link_")]
    angle = math.atan2(frames[-1].poses["sprocket"][1, 0], frames[-1].poses["sprocket"][0, 0])
    assert angle == pytest.approx(2 * wrap.cycle_rad)
    start, after = frames[0].poses, frames[per_cycle].poses
    shifts = [s for s in (1, -1) if all(np.allclose(after[links[j]][:3, 3], start[links[j + s]][:3, 3], atol=1e-6)
                                        for j in range(len(links)) if 0 <= j + s < len(links))]
    assert len(shifts) == 1, "after one cycle each link stands where its neighbour stood"


def test_differential_frames_roll_the_pitch_cones():
    from gearcheck.geometry.bevel_mesh import drive_poses, play_period
    from gearcheck.mechanisms.differential.thermal import BIG_GEARS, SMALL_GEARS

    _, assembly, frames, _ = frames_of("zhurong_differential")
    specs = assembly.layout.specs
    built = {p.name: p.pose for p in assembly.parts}
    period = play_period(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small)
    for k, f in enumerate(frames):
        phi = period * k / (len(frames) - 1)
        expected = drive_poses(built, BIG_GEARS, SMALL_GEARS, specs.big, specs.small, phi)
        for gear, pose in expected.items():
            assert np.allclose(f.poses[gear], pose, atol=1e-9), (k, gear)
        for side in ("right", "left"):  # a shaft turns with its big gear
            rel = np.linalg.inv(f.poses[f"big_gear_{side}"]) @ f.poses[f"shaft_{side}"]
            assert np.allclose(rel, np.linalg.inv(built[f"big_gear_{side}"]) @ built[f"shaft_{side}"], atol=1e-9)
