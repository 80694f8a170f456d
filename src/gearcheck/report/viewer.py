"""The report's 3D view: an HTML block with everything inlined — three.js (vendored, see
``vendor/three/README.md``), the viewer code (``viewer.js``) and the scene's display meshes — so
report.html turns the assembly in 3D from disk with the network off.

What it shows (a selector): the assembly as built; each worst pose of the sweep (its two parts
highlighted, the others faded, the closest points as a red and a blue dot joined by a line, the
distance beside it); the motion frames with a slider, when the scene has them. Drag turns,
shift-drag or right-drag pans, the wheel (or a pinch) zooms, Reset goes back to the view's
starting camera; arrow keys, +/− and R do the same on the focused canvas. Without WebGL 2 (or
JavaScript) a text fallback lists the parts and the worst poses.

three.js is inlined as a module; its closing ``export {…}`` clause becomes ``const THREE = {…}``
so the viewer code that follows in the same module reaches it by name without any import. Once
the first frame is drawn the container gets ``data-rendered="1"`` (``"fallback"`` when the text
fallback shows), which the browser test waits for.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import math
import re
from functools import lru_cache
from importlib import resources

import numpy as np

from gearcheck.report.camera import azimuth_elevation, section, worst_direction, zoom_radius
from gearcheck.scene import PoseView, Scene, distance_text

VENDOR = "vendor/three/three.module.min.js"
_EXPORT = re.compile(r"export\s*\{([^{}]*)\}\s*;?\s*$")

CSS = """
.gc3d { margin: 1em 0; max-width: 100%; min-width: 0; }
.gc3d [hidden] { display: none !important; }
.gc3d-bar { display: flex; flex-wrap: wrap; gap: 0.4em 0.8em; align-items: center; margin-bottom: 0.4em; }
.gc3d-bar label { min-width: 0; max-width: 100%; }
.gc3d-bar select { max-width: 100%; min-width: 0; font: inherit; }
.gc3d button { font: inherit; padding: 0.15em 0.7em; }
.gc3d-stage { position: relative; width: 100%; aspect-ratio: 4 / 3; max-height: 72vh; overflow: hidden;
              border: 1px solid #d6d9e0; border-radius: 4px; background: #f4f6f9; }
.gc3d-stage canvas { position: absolute; inset: 0; width: 100%; height: 100%; display: block;
                     touch-action: none; cursor: grab; }
.gc3d-stage canvas:focus-visible { outline: 2px solid #2b6cb0; outline-offset: -2px; }
.gc3d-tag { position: absolute; transform: translate(10px, -130%); pointer-events: none; white-space: nowrap;
            background: rgba(255, 255, 255, 0.9); border: 1px solid #e08a00; border-radius: 3px;
            padding: 0 0.35em; font-size: 0.85em; font-variant-numeric: tabular-nums; }
.gc3d-frames { display: flex; flex-wrap: wrap; gap: 0.3em 0.8em; align-items: center; margin-top: 0.4em; }
.gc3d-frames label { display: flex; gap: 0.5em; align-items: center; flex: 1 1 12em; min-width: 0; }
.gc3d-frames input { flex: 1 1 auto; min-width: 0; }
.gc3d-paint { font-size: 0.9em; margin: 0.4em 0 0; }
.gc3d-sw { display: inline-block; width: 0.9em; height: 0.9em; vertical-align: -0.1em; border-radius: 2px; }
.gc3d-status { font-size: 0.9em; margin: 0.4em 0 0; min-height: 1.4em; overflow-wrap: anywhere; }
.gc3d figcaption { font-size: 0.85em; color: #5a6275; margin-top: 0.3em; }
.gc3d-fallback { border: 1px dashed #b0b6c3; padding: 0.5em 0.8em; overflow-wrap: anywhere; }
"""

CAPTION = ("3D view (display meshes, coarser than the checked ones). Drag to turn; shift-drag or right-drag to "
           "pan; wheel or pinch to zoom; Reset restores the view. On the focused view: arrow keys turn, "
           "shift+arrows pan, + and − zoom, R resets. Lengths in mm.")


@lru_cache(maxsize=1)
def three_source() -> str:
    """three.js's module build with its export clause turned into ``const THREE = {…};``."""
    text = resources.files("gearcheck.report").joinpath(VENDOR).read_text(encoding="utf-8")
    match = _EXPORT.search(text)
    if match is None:
        raise RuntimeError(f"{VENDOR}: no closing export clause (not a three.js module build?)")
    entries = []
    for item in match.group(1).split(","):
        local, _, exported = item.strip().partition(" as ")
        entries.append(f"{(exported or local).strip()}:{local.strip()}")
    return text[:match.start()] + "const THREE={" + ",".join(entries) + "};\n"


@lru_cache(maxsize=1)
def viewer_source() -> str:
    return resources.files("gearcheck.report").joinpath("viewer.js").read_text(encoding="utf-8")


def _b64(array: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(array).tobytes()).decode("ascii")


def _pose(m) -> list[float]:
    """A 4×4 as 16 numbers, row-major (three.js Matrix4.set order), rounded to a nanometre."""
    return [round(float(x), 7) + 0.0 for x in np.asarray(m, float).reshape(-1)]


def _point(p) -> list[float] | None:
    return None if p is None else [round(float(x), 7) + 0.0 for x in np.asarray(p, float)]


def _view(view: PoseView) -> dict:
    distance = view.distance_mm
    return {
        "label": view.label,
        "poses": {name: _pose(m) for name, m in sorted(view.poses.items())},
        "scales": {name: float(s) for name, s in sorted(view.scales.items())},
        "parts": [p.partition(".")[0] for p in view.parts] if view.parts else None,
        "a": _point(view.point_a),
        "b": _point(view.point_b),
        "d": float(distance) if distance is not None and math.isfinite(distance) else None,
        "note": view.note,
    }


def scene_data(scene: Scene) -> dict:
    """The scene as the viewer's JSON: meshes once (base64 little-endian float32 vertices,
    uint16/uint32 indices), parts referring to them, worst poses and frames."""
    meshes: list[dict] = []
    index: dict[tuple[int, int], int] = {}
    parts = []
    for p in scene.parts:
        key = (id(p.vertices), id(p.faces))
        if key not in index:
            small = len(p.vertices) < 65536
            meshes.append({"v": _b64(np.asarray(p.vertices, "<f4")),
                           "i": _b64(np.asarray(p.faces, "<u2" if small else "<u4")), "u16": small})
            index[key] = len(meshes) - 1
        parts.append({"n": p.name, "m": index[key], "c": [round(float(c), 4) for c in p.color], "p": _pose(p.pose),
                      "mat": p.material})
    worst = []
    for w in scene.worst:
        entry = _view(w)
        if w.point_a is not None and w.point_b is not None:
            entry["dir"] = [round(x, 6) + 0.0 for x in azimuth_elevation(worst_direction(scene, w))]
            entry["r"] = round(zoom_radius(scene, w), 6)
            cut = section(scene, w)
            if cut is not None:
                entry["cut"] = [round(float(x), 7) + 0.0 for x in np.concatenate(cut)]
        worst.append(entry)
    overlays = [{"n": o.name, "h": o.host, "c": [round(float(c), 4) for c in o.color],
                 "v": _b64(np.asarray(o.vertices, "<f4")),
                 "i": _b64(np.asarray(o.faces, "<u2" if len(o.vertices) < 65536 else "<u4")),
                 "u16": len(o.vertices) < 65536} for o in scene.overlays]
    return {"name": scene.name, "meshes": meshes, "parts": parts, "worst": worst,
            "frames": [_view(f) for f in scene.frames], "frames_label": scene.frames_label, "overlays": overlays}


def _fallback(scene: Scene) -> str:
    """The text shown where WebGL (or JavaScript) is not available."""
    items = []
    for w in scene.worst:
        where = ""
        if w.point_a is not None and w.point_b is not None:
            a, b = (", ".join(f"{x:.3f}" for x in np.asarray(p, float)) for p in (w.point_a, w.point_b))
            where = f" at ({a}) and ({b}) mm"
        dist = f": {distance_text(w.distance_mm)}" if distance_text(w.distance_mm) else ""
        pair = " / ".join(w.parts) if w.parts else ""
        items.append(f"<li>{html.escape(w.label)} — {html.escape(pair)}{dist}{html.escape(where)}</li>")
    worst = f"<p>Worst poses (closest points, world frame):</p><ul>{''.join(items)}</ul>" if items else ""
    names = ", ".join(html.escape(p.name) for p in scene.parts)
    return (f"<p><strong>3D view unavailable</strong>: <span class='gc3d-why'>it needs JavaScript and "
            f"WebGL 2.</span> The assembly has {len(scene.parts)} parts: {names}.</p>{worst}")


def _options(scene: Scene) -> str:
    opts = ['<option value="built">Assembly as built</option>']
    for i, w in enumerate(scene.worst):
        dist = f" ({distance_text(w.distance_mm)})" if distance_text(w.distance_mm) else ""
        opts.append(f'<option value="worst:{i}">Worst pose {i + 1}: {html.escape(w.label + dist)}</option>')
    if scene.frames:
        label = scene.frames_label or "key frames"
        opts.append(f'<option value="frames">Motion: {html.escape(label)}</option>')
    return "".join(opts)


def _frames(scene: Scene) -> str:
    if not scene.frames:
        return ""
    n = len(scene.frames)
    first = html.escape(scene.frames[0].label)
    return (f'<div class="gc3d-frames" hidden><button type="button" class="gc3d-play">Play</button>'
            f'<label>Frame <input type="range" min="0" max="{n - 1}" step="1" value="0" '
            f'aria-label="motion frame"></label><output aria-live="polite">{first}</output></div>')


def _painted(scene: Scene) -> str:
    """What is painted on the parts, each with its colour (under the view)."""
    if not scene.overlays:
        return ""
    items = []
    for o in scene.overlays:
        rgb = "#" + "".join(f"{round(255 * c):02x}" for c in o.color)
        items.append(f"<span><span class='gc3d-sw' style='background:{rgb}'></span> {html.escape(o.label)} on "
                     f"{html.escape(o.host)}</span>")
    return f'<p class="gc3d-paint">Painted: {"; ".join(items)}</p>'


def viewer_html(scene: Scene) -> str:
    """The 3D view as one HTML block (a ``<figure class="gc3d">``) to inline in report.html."""
    payload = json.dumps(scene_data(scene), separators=(",", ":"), allow_nan=False)
    payload = payload.replace("</", "<\\/")  # never closes the script element early
    uid = "gc3d-" + hashlib.sha256(payload.encode()).hexdigest()[:10]
    title = html.escape(scene.name)
    module = f"const ROOT_ID={json.dumps(uid)};\n{three_source()}\n{viewer_source()}"
    if "</script" in module.lower():
        raise RuntimeError("the viewer's script would close its element early")
    frames_bar = _frames(scene) or '<div class="gc3d-frames" hidden></div>'
    return (
        f'<figure class="gc3d" id="{uid}" data-rendered="0" aria-label="3D view of {title}">'
        f"<style>{CSS}</style>"
        f'<div class="gc3d-bar"><label>View <select aria-label="what the 3D view shows">{_options(scene)}'
        f'</select></label><button type="button" class="gc3d-reset">Reset view</button>'
        f'<label class="gc3d-cut" hidden><input type="checkbox" checked> section through the closest points'
        f"</label></div>"
        f'<div class="gc3d-stage"><canvas tabindex="0" role="img" aria-label="3D view of {title}: drag to turn">'
        f'</canvas><div class="gc3d-tag" hidden></div></div>'
        f"{frames_bar}{_painted(scene)}"
        f'<p class="gc3d-status" aria-live="polite"></p>'
        f'<div class="gc3d-fallback" hidden>{_fallback(scene)}</div>'
        f'<noscript><div class="gc3d-fallback">{_fallback(scene)}</div></noscript>'
        f"<figcaption>{html.escape(CAPTION)}</figcaption>"
        f'<script type="application/json" class="gc3d-data">{payload}</script>'
        f'<script type="module">{module}</script>'
        f"</figure>"
    )
