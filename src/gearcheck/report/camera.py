"""Where the report's 3D view and its pictures look from (numpy only), so both frame a view alike.

The whole assembly is seen from :data:`DEFAULT_DIRECTION` (an isometric-like view from the
front right, above; +z up). A worst pose is a section: seen along the thinnest axis of the larger
of its two parts (a gear's or a sprocket's axis, the rack's width) with everything on the
camera's side of a plane through the closest points cut away, so the tooth profiles show edge on
with the gap between them, whatever wraps round the contact (a chain link's plates).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.scene import PoseView, Scene

# azimuth −1.0 rad about +z from +x, elevation 0.45 rad
DEFAULT_AZIMUTH, DEFAULT_ELEVATION = -1.0, 0.45
DEFAULT_DIRECTION = np.array([math.cos(DEFAULT_ELEVATION) * math.cos(DEFAULT_AZIMUTH),
                              math.cos(DEFAULT_ELEVATION) * math.sin(DEFAULT_AZIMUTH), math.sin(DEFAULT_ELEVATION)])
# a worst pose's view: this fraction of the smaller part's size about the closest points, and at
# least this many times the gap
ZOOM_FRACTION = 0.18
ZOOM_GAPS = 30.0


def _unit(v: np.ndarray) -> np.ndarray:
    n = float(np.linalg.norm(v))
    return v / n if n > 0 else v


def base(name: str) -> str:
    """A part's name from a feature's ("link_03.plate" → "link_03")."""
    return name.partition(".")[0]


def world(scene: Scene, view: PoseView | None, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(world vertices, faces) of one part at a view."""
    p = scene.part(name)
    pose = p.pose if view is None else np.asarray(view.poses.get(p.name, p.pose), float)
    scale = 1.0 if view is None else float(view.scales.get(p.name, 1.0))
    v = (scale * np.asarray(p.vertices, float)) @ pose[:3, :3].T + pose[:3, 3]
    return v, np.asarray(p.faces, np.int64)


def pair(view: PoseView) -> list[str]:
    return [base(n) for n in view.parts] if view.parts else []


def worst_direction(scene: Scene, view: PoseView) -> np.ndarray:
    """Unit vector from the closest points toward the camera for a worst pose: along the thinnest
    axis of the larger part (made square to the gap), from the side that leaves more of the two
    parts near the closest points behind the section plane (:func:`section`)."""
    names = [n for n in pair(view) if any(p.name == n for p in scene.parts)]
    if not names or view.point_a is None or view.point_b is None:
        return DEFAULT_DIRECTION.copy()
    meshes = [world(scene, view, n)[0] for n in names]
    sizes = [float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))) for v in meshes]
    big = meshes[int(np.argmax(sizes))]
    centred = big - big.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    axis = vectors[:, 0]  # the direction of least spread: the part's thinnest axis
    a, b = np.asarray(view.point_a, float), np.asarray(view.point_b, float)
    gap = b - a
    if np.linalg.norm(gap) > 1e-9:
        g = _unit(gap)
        # square to the gap; where the axis runs along the gap, look across it from the default side
        axis = DEFAULT_DIRECTION - (DEFAULT_DIRECTION @ g) * g if abs(float(axis @ g)) > 0.9 else axis - (axis @ g) * g
    axis = _unit(axis)
    middle = 0.5 * (a + b)
    radius = zoom_radius(scene, view)
    near = np.concatenate(meshes)
    near = near[np.linalg.norm(near - middle, axis=1) <= 1.5 * radius]
    scores = []
    for sign in (1.0, -1.0):
        d = sign * axis  # kept: clearly behind the plane (a face on the plane counts for neither side)
        kept = int(np.count_nonzero((near - middle) @ d < -KEPT_MARGIN * radius))
        scores.append((kept, float(d @ DEFAULT_DIRECTION), sign))
    kept_plus, kept_minus = scores[0][0], scores[1][0]
    if abs(kept_plus - kept_minus) <= 0.1 * max(kept_plus, kept_minus, 1):  # about even: the nicer side
        return axis if scores[0][1] >= scores[1][1] else -axis
    return max(scores)[2] * axis


# a vertex counts as kept by a section when it lies this fraction of the view's radius behind it
KEPT_MARGIN = 0.05
# the section plane lies this fraction of the view's radius behind the closest points (a cut
# exactly through a face the contact lies on would flicker between showing and hiding it)
SECTION_OFFSET = 0.004


def section(scene: Scene, view: PoseView) -> tuple[np.ndarray, np.ndarray] | None:
    """(point, unit normal toward the camera) of a worst pose's section plane: what lies on the
    camera's side of it is cut away, so the gap shows however the parts wrap round it. None
    without closest points."""
    if view.point_a is None or view.point_b is None:
        return None
    d = worst_direction(scene, view)
    middle = 0.5 * (np.asarray(view.point_a, float) + np.asarray(view.point_b, float))
    return middle - SECTION_OFFSET * zoom_radius(scene, view) * d, d


# the camera keeps +z up: a view straight along z is tilted to this elevation (rad)
MAX_ELEVATION = 1.55


def azimuth_elevation(direction: np.ndarray) -> tuple[float, float]:
    """(azimuth about +z from +x, elevation) of a unit direction toward the camera, as the
    viewer's orbit camera holds it; straight up or down keeps the default azimuth."""
    d = _unit(np.asarray(direction, float))
    elevation = math.asin(max(-1.0, min(1.0, float(d[2]))))
    elevation = max(-MAX_ELEVATION, min(MAX_ELEVATION, elevation))
    azimuth = math.atan2(float(d[1]), float(d[0])) if math.hypot(d[0], d[1]) > 1e-3 else DEFAULT_AZIMUTH
    return azimuth, elevation


def orbit_direction(azimuth: float, elevation: float) -> np.ndarray:
    return np.array([math.cos(elevation) * math.cos(azimuth), math.cos(elevation) * math.sin(azimuth),
                     math.sin(elevation)])


def zoom_radius(scene: Scene, view: PoseView) -> float:
    """Radius (mm) of the region about the closest points a worst pose's view shows."""
    names = [n for n in pair(view) if any(p.name == n for p in scene.parts)]
    sizes = []
    for n in names:
        v = np.asarray(scene.part(n).vertices, float)
        sizes.append(float(np.linalg.norm(v.max(axis=0) - v.min(axis=0))))
    gap = 0.0
    if view.point_a is not None and view.point_b is not None:
        gap = float(np.linalg.norm(np.asarray(view.point_b, float) - np.asarray(view.point_a, float)))
    size = min(sizes) if sizes else 1.0
    return max(ZOOM_FRACTION * size, ZOOM_GAPS * gap, 1e-3)
