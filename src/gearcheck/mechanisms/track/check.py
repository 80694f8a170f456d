"""Track drive sweep (seed 002, issue 10): the sprocket turns, the chain advances, links swing into
and out of mesh; FCL on the generated meshes measures tooth–sleeve clearance and tip-to-plate
distance at every pose, and an exact 2-D model checks every figure.

Poses are data (:class:`gearcheck.geometry.track_chain.ChainWrap`): at drive angle θ the sprocket
is ``sprocket_matrix(θ)`` and link j is ``wrap.link_matrices(θ)[j]``; every link body shares one
mesh in the link frame. One engagement cycle is β = 2·360°/z of sprocket rotation; after it every
pose repeats with the pin numbers shifted by one and the sprocket turned by two grooves, which is
one of its symmetries. So sweeping θ over one cycle moves every link of the segment through its
own stretch of the path, and together they cover the whole path (entry run, swinging in, seated,
swinging out, exit run). The sweep runs from −margin to β + margin so both ends of the cycle are
inside it.

The link solid is the sleeve fused with the plate, but the two clearances belong to different
features: the sleeve sits in its seat (ri − R, 0.1 mm) and the plate face over the tooth tip
(the tip gap, 0.75 mm). The link mesh is therefore split by position in the link frame
(:func:`split_link_mesh`): triangles whose vertices all lie within R of the pin axis are the
sleeve, the rest the plate.

Exact 2-D model (:class:`ExactSection`): the sprocket is an extrusion of the ISO 606 outline and
the link an extrusion of a circle (sleeve) and a rectangle (plate) across both tooth rows, so the
3-D distances are 2-D distances between the outline and the link section. The outline is sampled
at ``EXACT_OUTLINE_STEP_MM`` with every arc end exact (chord sagitta ≤ step²/(8·ri), about 1e-5 mm),
with no mesh and no FCL: the mesh sweep must agree with it within the mesh-error bound at every
pose and link.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Callable

import numpy as np

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.mechanisms.track import GAP_CHECK_STEP_MM, analysis, layout
from gearcheck.sweep.engine import Body, MeshData, Scene, bisect_contact
from gearcheck.sweep.pool import map_scene
from gearcheck.sweep.result import CheckResult, Clearance, Comparison, Plot, Series, Verdict, WorstPose

SECTION = "track"

# Sprocket angles per engagement cycle β (step β/60 = 0.245°: a seated pin moves 0.50 mm per step,
# far less than the 8 mm sleeve, so no body can pass through another between poses).
STEPS_PER_CYCLE = 60
# The sweep runs this fraction of a cycle before θ = 0 and after θ = β.
CYCLE_MARGIN_FRACTION = 0.125
# Contact is judged with this tolerance, or the mesh-error bound if that is larger: pushed by the
# measured gap − tolerance the pair must be free, by gap + tolerance it must collide.
CONTACT_TOLERANCE_MM = 0.02
# Bisection on the push distance stops at this bracket width.
BISECTION_TOL_MM = 1e-5
# A link-mesh triangle belongs to the sleeve when all its vertices lie within R + this of the pin
# axis (mesh vertices lie on the B-rep surfaces; plate triangles reach out to the plate's far edges).
SLEEVE_SELECT_MARGIN_MM = 1e-4
# Exact model: outline sampling step, and how far from a link its distances are resolved.
EXACT_OUTLINE_STEP_MM = 0.02
EXACT_REACH_MM = 4.0
# Rounding of measured values against the paper's window (report precision, 1 µm).
WINDOW_ROUNDING_MM = 1e-6

SLEEVE, PLATE, LINK, SPROCKET = "sleeve", "plate", "link", "sprocket"


# --------------------------------------------------------------------------------------------
# Geometry the check needs (numpy only: the layout the CAD stage built from)


@dataclass(frozen=True)
class TrackModel:
    """The template's sprocket groove, wrap and link section, rebuilt from the parameters."""

    gap: iso606.ToothGap
    wrap: tc.ChainWrap
    link: tc.LinkGeometry
    tip_gap_mm: float  # template input: the gap the plate offset was solved for
    required_gap_min_mm: float
    required_gap_max_mm: float

    @property
    def sleeve_radius_mm(self) -> float:
        return self.link.sleeve_radius_mm

    def key(self) -> tuple:
        g, w = self.gap, self.wrap
        return (g.teeth, g.pitch_radius_mm, g.seating_radius_mm, g.flank_radius_mm, g.seating_angle_rad,
                g.tip_radius_mm, self.link, w)

    @property
    def seating_clearance_mm(self) -> float:
        """ri − R: a sleeve centred on its seating centre, concentric with the seating arc."""
        return self.gap.seating_radius_mm - self.link.sleeve_radius_mm


def track_model(params) -> TrackModel:
    """The layout `gearcheck build` builds from (:func:`.layout.track_layout`, same functions)."""
    lay = layout.track_layout(params)
    tp = params.track_plate
    return TrackModel(lay.sprocket.gap, lay.wrap, lay.link, tp.tip_gap_mm, tp.required_gap_min_mm,
                      tp.required_gap_max_mm)


def link_names(bodies: dict[str, Body]) -> list[str]:
    return sorted(n for n in bodies if n.startswith("link_"))


def check_bodies(model: TrackModel, bodies: dict[str, Body]) -> None:
    """The bodies must be the parts of this wrap: one link body per link, posed at θ = 0."""
    names = link_names(bodies)
    if SPROCKET not in bodies or len(names) != model.wrap.links:
        raise ValueError(f"expected a sprocket and {model.wrap.links} links, got {sorted(bodies)}")
    built = np.stack([bodies[n].pose for n in names])
    if not np.allclose(built, model.wrap.link_matrices(0.0), atol=1e-9):
        raise ValueError("link poses do not match the default wrap at θ = 0 (bodies built with another wrap?)")
    if not np.allclose(bodies[SPROCKET].pose, tc.sprocket_matrix(0.0), atol=1e-12):
        raise ValueError("sprocket pose is not the θ = 0 pose")
    first = bodies[names[0]].mesh
    for n in names[1:]:
        m = bodies[n].mesh
        if m.vertices.shape != first.vertices.shape or not np.array_equal(m.faces, first.faces):
            raise ValueError("link bodies do not share one mesh")


def split_link_mesh(mesh: MeshData, sleeve_radius_mm: float,
                    margin_mm: float = SLEEVE_SELECT_MARGIN_MM) -> tuple[MeshData, MeshData]:
    """(sleeve, plate) sub-meshes of the fused link mesh (link frame: pin axis = z axis).

    Sleeve: triangles with every vertex within R + margin of the pin axis (its cylinder and the
    discs of its end faces); plate: the rest. The pieces are open surfaces, which is all FCL's
    mesh distance and collision need.
    """
    v, f = mesh.vertices, mesh.faces
    radius = np.hypot(v[:, 0], v[:, 1])
    on_sleeve = np.all(radius[f] <= sleeve_radius_mm + margin_mm, axis=1)
    if on_sleeve.all() or not on_sleeve.any():
        raise ValueError("link mesh does not split into sleeve and plate")
    return MeshData(SLEEVE, v, f[on_sleeve]), MeshData(PLATE, v, f[~on_sleeve])


# --------------------------------------------------------------------------------------------
# Mesh sweep (FCL); the pose function runs in worker processes


def evaluate_pose(scene: Scene, model: "TrackModel", angle_rad: float) -> np.ndarray:
    """(links, 5) per link at drive angle θ: mesh sprocket–sleeve distance, mesh sprocket–plate
    distance (mm), whether the sprocket and the whole link mesh intersect (1/0), and the exact
    2-D sleeve clearance and plate distance at the same pose."""
    exact = _exact_section(model)
    sprocket = tc.sprocket_matrix(angle_rad)
    scene.set_pose(SPROCKET, sprocket)
    poses = model.wrap.link_matrices(angle_rad)
    out = np.empty((len(poses), 5))
    for j, pose in enumerate(poses):
        scene.set_poses({SLEEVE: pose, PLATE: pose, LINK: pose})
        out[j, 0] = scene.distance(SPROCKET, SLEEVE).distance
        out[j, 1] = scene.distance(SPROCKET, PLATE).distance
        out[j, 2] = scene.collide(SPROCKET, LINK)
        out[j, 3:] = exact.link_distances(sprocket, pose)
    return out


_EXACT_CACHE: dict = {}


def _exact_section(model: "TrackModel") -> "ExactSection":
    """One exact model per process and template (workers receive the model with every pose)."""
    key = model.key()
    if key not in _EXACT_CACHE:
        _EXACT_CACHE.clear()
        _EXACT_CACHE[key] = ExactSection(model)
    return _EXACT_CACHE[key]


def sweep_angles(wrap: tc.ChainWrap, steps_per_cycle: int = STEPS_PER_CYCLE,
                 margin_fraction: float = CYCLE_MARGIN_FRACTION) -> np.ndarray:
    """θ from −margin to β + margin in steps of β/steps_per_cycle; 0 and β are samples."""
    before = int(math.ceil(margin_fraction * steps_per_cycle))
    k = np.arange(-before, steps_per_cycle + before + 1)
    return k * wrap.cycle_rad / steps_per_cycle


# --------------------------------------------------------------------------------------------
# Exact 2-D model (no mesh, no FCL)


def _segment_distances(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances from one point to each segment a[i]–b[i]."""
    return _pairwise_distances(np.asarray(point, float)[None, :], a, b)[0]


def _pairwise_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(points, segments) distances from each point to each segment a[k]–b[k]."""
    ex, ey = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
    px = points[:, 0, None] - a[None, :, 0]
    py = points[:, 1, None] - a[None, :, 1]
    t = np.clip((px * ex + py * ey) / np.maximum(ex * ex + ey * ey, 1e-300), 0.0, 1.0)
    return np.hypot(px - t * ex, py - t * ey)


def _clip_outside_circle(a: np.ndarray, b: np.ndarray, radius: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The parts of segment a–b outside the circle |p| < radius (0, 1 or 2 segments)."""
    d = b - a
    qa, qb, qc = float(d @ d), 2.0 * float(a @ d), float(a @ a) - radius * radius
    disc = qb * qb - 4.0 * qa * qc
    if disc <= 0.0:
        return [(a, b)]
    t0, t1 = sorted(((-qb - math.sqrt(disc)) / (2 * qa), (-qb + math.sqrt(disc)) / (2 * qa)))
    parts = []
    if t0 > 0.0:
        parts.append((a, a + min(t0, 1.0) * d))
    if t1 < 1.0:
        parts.append((a + max(t1, 0.0) * d, b))
    return parts


def plate_boundary(link: tc.LinkGeometry) -> list[tuple[np.ndarray, np.ndarray]]:
    """The plate's exposed section boundary in the link frame: the rectangle's edges less what
    lies inside the sleeve (the fused link has no plate surface there)."""
    x0, x1, y0, y1 = link.plate_rect()
    c = [np.array(p, float) for p in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
    out = []
    for a, b in zip(c, c[1:] + c[:1]):
        out += _clip_outside_circle(a, b, link.sleeve_radius_mm)
    return out


class ExactSection:
    """Distances between the sprocket outline (one tooth row's section, a polyline through exact arc
    points) and a link's section: the sleeve circle and the plate's exposed boundary."""

    def __init__(self, model: TrackModel, step_mm: float = EXACT_OUTLINE_STEP_MM, reach_mm: float = EXACT_REACH_MM):
        self.model = model
        self.reach_mm = reach_mm
        self.step_mm = step_mm
        self.points = iso606.sprocket_outline(model.gap, step_mm)
        n = len(self.points)
        self.next = np.roll(np.arange(n), -1)
        self.prev = np.roll(np.arange(n), 1)
        self.max_edge = float(np.hypot(*(self.points[self.next] - self.points).T).max())
        # points sorted by polar angle: a disc around a point away from the axis lies inside an
        # angular window, i.e. a slice of this order
        polar = np.arctan2(self.points[:, 1], self.points[:, 0])
        self.order = np.argsort(polar)
        self.sorted_polar = polar[self.order]
        self.rect = model.link.plate_rect()
        self.plate_segments = plate_boundary(model.link)
        self.plate_starts = np.array([a for a, _ in self.plate_segments])
        self.plate_ends = np.array([b for _, b in self.plate_segments])
        self.plate_corners = np.unique(np.vstack([self.plate_starts, self.plate_ends]), axis=0)
        x0, x1, y0, y1 = self.rect
        self.plate_centre = np.array([(x0 + x1) / 2.0, (y0 + y1) / 2.0])
        self.plate_radius = math.hypot(x1 - x0, y1 - y0) / 2.0
        # the polyline's chords lie at most step²/(8ρ) from the arcs, ρ ≥ ri (flanks, tip: larger)
        self.sagitta_mm = step_mm**2 / (8.0 * model.gap.seating_radius_mm)

    def _near(self, centre: np.ndarray, radius: float) -> np.ndarray:
        """Indices of outline points that may lie within ``radius`` of ``centre``."""
        rc = float(np.hypot(*centre))
        half = math.asin(min(1.0, radius / rc)) if rc > radius else math.pi
        c = math.atan2(centre[1], centre[0])
        lo, hi = c - half, c + half
        ranges = [(lo, hi)]
        if lo < -math.pi:
            ranges = [(lo + 2 * math.pi, math.pi), (-math.pi, hi)]
        elif hi > math.pi:
            ranges = [(lo, math.pi), (-math.pi, hi - 2 * math.pi)]
        parts = [self.order[np.searchsorted(self.sorted_polar, a): np.searchsorted(self.sorted_polar, b, "right")]
                 for a, b in ranges]
        return np.concatenate(parts)

    def _polyline_distance(self, point: np.ndarray, idx: np.ndarray, local: np.ndarray, to_frame) -> float:
        """Distance from ``point`` to the outline polyline, given outline vertices ``idx`` (with
        coordinates ``local`` in the point's frame) that include every vertex near it: the nearest
        polyline point lies on a segment with an end within (nearest vertex + longest edge)."""
        d = np.hypot(local[:, 0] - point[0], local[:, 1] - point[1])
        cand = idx[d <= d.min() + self.max_edge]
        starts = np.concatenate([self.prev[cand], cand])
        ends = np.concatenate([cand, self.next[cand]])
        return float(_segment_distances(point, to_frame(starts), to_frame(ends)).min())

    def link_distances(self, sprocket_pose: np.ndarray, link_pose: np.ndarray) -> tuple[float, float]:
        """(sleeve clearance, plate distance) in mm, negative by the depth when the outline enters
        the sleeve or the plate; inf when no outline lies within the reach."""
        rel = np.linalg.solve(sprocket_pose, link_pose)  # link frame → sprocket frame
        rot, origin = rel[:2, :2], rel[:2, 3]
        r = self.model.sleeve_radius_mm
        sleeve = math.inf
        idx = self._near(origin, r + self.reach_mm)
        if idx.size:
            sleeve = self._polyline_distance(origin, idx, self.points[idx], lambda i: self.points[i]) - r

        def to_link(i: np.ndarray) -> np.ndarray:
            return (self.points[i] - origin) @ rot

        idx = self._near(rot @ self.plate_centre + origin, self.plate_radius + self.reach_mm)
        if not idx.size:
            return sleeve, math.inf
        a = to_link(idx)
        x0, x1, y0, y1 = self.rect
        zero = np.zeros(len(a))
        dx = np.maximum.reduce([x0 - a[:, 0], zero, a[:, 0] - x1])
        dy = np.maximum.reduce([y0 - a[:, 1], zero, a[:, 1] - y1])
        to_rect = np.hypot(dx, dy)  # ≤ the distance to the plate's exposed boundary
        inside = to_rect == 0.0
        if inside.any():
            q = a[inside]
            depth = np.minimum.reduce([q[:, 0] - x0, x1 - q[:, 0], q[:, 1] - y0, y1 - q[:, 1]])
            return sleeve, -float(depth.max())
        if to_rect.min() >= self.reach_mm:
            return sleeve, math.inf
        # polyline vs the plate's boundary segments (disjoint): the nearest pair has a vertex of
        # one of them on it. Outline vertices: the distance to the rectangle is a lower bound, so
        # only vertices whose bound is below the nearest-to-rectangle vertex's true distance count.
        s0, s1 = self.plate_starts, self.plate_ends
        first = int(np.argmin(to_rect))
        best = float(_pairwise_distances(a[first:first + 1], s0, s1).min())
        cand = to_rect <= best
        vertex_side = float(_pairwise_distances(a[cand], s0, s1).min()) if cand.any() else best
        # plate segment ends: the nearest outline segment has an end within (nearest vertex + edge)
        corners = self.plate_corners
        d = np.hypot(a[None, :, 0] - corners[:, 0, None], a[None, :, 1] - corners[:, 1, None])
        near = idx[(d <= d.min(axis=1, keepdims=True) + self.max_edge).any(axis=0)]
        starts = to_link(np.concatenate([self.prev[near], near]))
        ends = to_link(np.concatenate([near, self.next[near]]))
        plate = min(best, vertex_side, float(_pairwise_distances(corners, starts, ends).min()))
        return sleeve, (plate if plate < self.reach_mm else math.inf)


# --------------------------------------------------------------------------------------------
# Contact from both sides


@dataclass(frozen=True)
class ContactProof:
    """A feature pushed along ``direction`` (world) from its measured pose: free at
    distance − tolerance, colliding at distance + tolerance, contact bracketed by bisection."""

    label: str
    measured_mm: float
    tolerance_mm: float
    free_at_minus: bool
    touching_at_plus: bool
    free_mm: float
    touching_mm: float
    direction: np.ndarray

    @property
    def contact_mm(self) -> float:
        return 0.5 * (self.free_mm + self.touching_mm)

    def holds(self, bound_mm: float) -> bool:
        return (self.free_at_minus and self.touching_at_plus
                and abs(self.contact_mm - self.measured_mm) <= bound_mm)


def prove_contact(scene: Scene, moving: str, pose: np.ndarray, direction: np.ndarray, measured_mm: float,
                  tolerance_mm: float, label: str) -> ContactProof:
    direction = np.asarray(direction, float) / np.linalg.norm(direction)

    def collides(push_mm: float) -> bool:
        moved = pose.copy()
        moved[:3, 3] += push_mm * direction
        scene.set_pose(moving, moved)
        return scene.collide(SPROCKET, moving)

    lo, hi = measured_mm - tolerance_mm, measured_mm + tolerance_mm
    free_lo, touch_hi = not collides(lo), collides(hi)
    free, touching = math.nan, math.nan
    if free_lo and touch_hi:
        bracket = bisect_contact(collides, lo, hi, BISECTION_TOL_MM)
        free, touching = bracket.free, bracket.touching
    scene.set_pose(moving, pose)
    return ContactProof(label, measured_mm, tolerance_mm, free_lo, touch_hi, free, touching, direction)


# --------------------------------------------------------------------------------------------
# The check


@dataclass(frozen=True)
class _Extreme:
    value: float
    pose_index: int
    link: int


def _argmin(values: np.ndarray, mask: np.ndarray) -> _Extreme:
    masked = np.where(mask, values, np.inf)
    i, j = np.unravel_index(int(np.argmin(masked)), masked.shape)
    return _Extreme(float(masked[i, j]), int(i), int(j))


def _rowmin(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    return np.where(mask, values, np.inf).min(axis=1)


def _finite(x: float, fallback: float = -1.0) -> float:
    """Summary leaves must be plain finite numbers."""
    return float(x) if math.isfinite(x) else fallback


def run_check(params, bodies: dict[str, Body], progress: Callable[[int], None] | None = None, *,
              steps_per_cycle: int = STEPS_PER_CYCLE, margin_fraction: float = CYCLE_MARGIN_FRACTION,
              workers: int | None = None) -> CheckResult:
    model = track_model(params)
    check_bodies(model, bodies)
    wrap = model.wrap
    names = link_names(bodies)
    link_body, sprocket_body = bodies[names[0]], bodies[SPROCKET]
    sleeve_mesh, plate_mesh = split_link_mesh(link_body.mesh, model.sleeve_radius_mm)
    whole_link = MeshData(LINK, link_body.mesh.vertices, link_body.mesh.faces)
    meshes = [sprocket_body.mesh, sleeve_mesh, plate_mesh, whole_link]
    bound = sprocket_body.error_bound_mm + link_body.error_bound_mm
    contact_tol = max(CONTACT_TOLERANCE_MM, bound)

    # --- the sweep: mesh (FCL) and exact 2-D distances at every pose
    angles = sweep_angles(wrap, steps_per_cycle, margin_fraction)
    t0 = time.perf_counter()
    out = np.array(map_scene(evaluate_pose, meshes, [(model, float(a)) for a in angles], workers=workers,
                             progress=progress))  # (poses, links, 5)
    sweep_s = time.perf_counter() - t0
    sleeve_d, plate_d, hits = out[..., 0], out[..., 1], out[..., 2] > 0.5
    ex_sleeve, ex_plate = out[..., 3], out[..., 4]
    exact = _exact_section(model)
    pins_seated = np.array([wrap.seated_pins(a) for a in angles])
    links_seated = pins_seated[:, :-1] & pins_seated[:, 1:]
    sleeve_seated = pins_seated[:, :-1]  # link j carries the sleeve on pin j
    everything = np.ones_like(links_seated)

    # compared where the mesh sees the link within half the exact model's reach (farther links
    # do not matter for any minimum; an exact inf there is a disagreement)
    dev_sleeve = np.abs(np.where(sleeve_d < exact.reach_mm / 2, sleeve_d - ex_sleeve, 0.0))
    dev_plate = np.abs(np.where(plate_d < exact.reach_mm / 2, plate_d - ex_plate, 0.0))
    max_dev = float(max(dev_sleeve.max(), dev_plate.max()))

    # --- extremes
    min_sleeve = _argmin(sleeve_d, everything)
    min_plate = _argmin(plate_d, everything)
    seated_gap = _argmin(plate_d, links_seated)
    seated_gap_max = float(np.where(links_seated, plate_d, -np.inf).max())
    seated_sleeve = _argmin(sleeve_d, sleeve_seated)
    off_sleeve = _argmin(sleeve_d, ~sleeve_seated)
    off_plate = _argmin(plate_d, ~links_seated)
    ex_min_sleeve = _argmin(ex_sleeve, everything)
    ex_min_plate = _argmin(ex_plate, everything)
    ex_seated_gap = _argmin(ex_plate, links_seated)
    ex_seated_sleeve = _argmin(ex_sleeve, sleeve_seated)
    ex_off_sleeve = _argmin(ex_sleeve, ~sleeve_seated)
    ex_off_plate = _argmin(ex_plate, ~links_seated)
    collisions = int(hits.sum())
    colliding_poses = np.flatnonzero(hits.any(axis=1))

    # --- contact from both sides, at the worst poses (in this process)
    t2 = time.perf_counter()
    scene = Scene(meshes)

    def place(index: int) -> tuple[np.ndarray, np.ndarray]:
        a = float(angles[index])
        s = tc.sprocket_matrix(a)
        scene.set_pose(SPROCKET, s)
        return s, wrap.link_matrices(a)

    s_gap, links_gap = place(seated_gap.pose_index)
    pose_gap = links_gap[seated_gap.link]
    inward = -pose_gap[:3, 1]  # the link's −y: from the plate face towards the sprocket axis
    gap_proof = prove_contact(scene, PLATE, pose_gap, inward, seated_gap.value, contact_tol,
                              "plate pushed towards the axis (plate alone: the sleeve would seat first)")
    scene.set_pose(PLATE, pose_gap)
    near_gap = scene.distance(SPROCKET, PLATE)
    gap_point_link = np.linalg.solve(pose_gap, np.append(near_gap.point_b, 1.0))[:2]

    s_sl, links_sl = place(min_sleeve.pose_index)
    pose_sl = links_sl[min_sleeve.link]
    if sleeve_seated[min_sleeve.pose_index, min_sleeve.link]:
        direction = -pose_sl[:3, 3] * np.array([1.0, 1.0, 0.0])  # radially in, into the seat
        how = "sleeve pushed radially into its seat"
    else:
        scene.set_pose(SLEEVE, pose_sl)
        near = scene.distance(SPROCKET, SLEEVE)
        direction = near.point_a - near.point_b  # from the sleeve's nearest point to the tooth's
        how = "sleeve pushed towards the nearest tooth point"
    sleeve_proof = prove_contact(scene, SLEEVE, pose_sl, direction, min_sleeve.value, contact_tol, how)
    proof_s = time.perf_counter() - t2

    # whole-link distance at the sleeve's worst pose (what an exact B-rep distance of the whole
    # link will measure), and nearest points for the notes
    scene.set_pose(LINK, pose_sl)
    whole_link_at_sleeve = scene.distance(SPROCKET, LINK).distance
    s_pl, links_pl = place(min_plate.pose_index)
    pose_pl = links_pl[min_plate.link]

    deg = np.degrees
    cycle_deg = float(deg(wrap.cycle_rad))
    seated_counts = links_seated.sum(axis=1)
    # the analytical model's tip gap, as `gearcheck calc` measures it on the 2-D outline
    model_gap = analysis.measured_tip_gap(iso606.sprocket_outline(model.gap, GAP_CHECK_STEP_MM), model.gap,
                                          wrap.pitch_mm, model.link.plate_offset_mm)

    def where(x: _Extreme, seated: np.ndarray = links_seated, what: str = "link") -> str:
        state = "seated" if seated[x.pose_index, x.link] else "off its seat"
        return f"{names[x.link]} ({what} {state}) at θ = {deg(angles[x.pose_index]):.3f}°"

    def where_sleeve(x: _Extreme) -> str:
        return where(x, sleeve_seated, "sleeve")

    # --- verdicts
    def rounded(x: float) -> float:
        return round(x / WINDOW_ROUNDING_MM) * WINDOW_ROUNDING_MM

    exact_penetration = min(ex_min_sleeve.value, ex_min_plate.value) < 0.0
    no_interference = collisions == 0 and not exact_penetration
    gap_in_window = (rounded(seated_gap.value) >= model.required_gap_min_mm
                     and rounded(seated_gap_max) <= model.required_gap_max_mm)
    min_plate_ok = rounded(min_plate.value) >= model.required_gap_min_mm
    proofs_hold = gap_proof.holds(bound) and sleeve_proof.holds(bound)
    agrees = max_dev <= bound
    clash = (f"{collisions} colliding link poses, first at θ = {deg(angles[colliding_poses[0]]):.3f}°; "
             if collisions else f"FCL collide false at all {len(angles)}×{wrap.links} link poses; ")
    resolved = ("a positive clearance beyond the bound" if min_sleeve.value > bound
                else "within the bound: a contact, not a resolved clearance")
    verdicts = [
        Verdict("no_interference", "no interference between sprocket and links over the sweep", no_interference,
                clash + f"min tooth–sleeve {min_sleeve.value:.4f} mm ({resolved}; exact "
                f"{ex_min_sleeve.value:.4f}), min tip–plate {min_plate.value:.4f} mm; bound {bound:.3f} mm"),
        Verdict("seated_tip_gap_in_window", "seated-link tip gap inside the paper's window", gap_in_window,
                f"{seated_gap.value:.4f}–{seated_gap_max:.4f} mm over {int(links_seated.sum())} seated link poses "
                f"(template {model.tip_gap_mm:g}), window {model.required_gap_min_mm:g}–"
                f"{model.required_gap_max_mm:g} mm; bound {bound:.3f} mm"),
        Verdict("min_tip_plate_distance", "tip-to-plate distance over the sweep ≥ the paper's minimum", min_plate_ok,
                f"min {min_plate.value:.4f} mm at {where(min_plate)}, limit ≥ {model.required_gap_min_mm:g} mm; "
                f"bound {bound:.3f} mm"),
        Verdict("contact_proven", "clearances proven from both sides (free at −tol, contact at +tol)", proofs_hold,
                f"tip gap: contact at {gap_proof.contact_mm:.5f} mm vs measured {gap_proof.measured_mm:.5f}; "
                f"seat: contact at {sleeve_proof.contact_mm:.5f} mm vs measured {sleeve_proof.measured_mm:.5f}; "
                f"tol ±{contact_tol:.3f} mm"),
        Verdict("mesh_matches_exact", "mesh sweep agrees with the exact 2-D model at every pose and link", agrees,
                f"max |mesh − exact| = {max_dev:.4f} mm, bound {bound:.3f} mm"),
    ]
    passed = all(v.passed for v in verdicts)

    # --- summary
    n_poses = len(angles)
    summary = {
        "min_tip_plate_distance_mm": min_plate.value,
        "min_tip_plate_angle_deg": float(deg(angles[min_plate.pose_index])),
        "min_tip_plate_link": min_plate.link,
        "min_tip_plate_link_seated": int(links_seated[min_plate.pose_index, min_plate.link]),
        "min_tip_plate_unseated_mm": _finite(off_plate.value),
        "min_tip_plate_unseated_angle_deg": float(deg(angles[off_plate.pose_index])),
        "seated_tip_gap_mm": seated_gap.value,
        "seated_tip_gap_max_mm": seated_gap_max,
        "seated_tip_gap_angle_deg": float(deg(angles[seated_gap.pose_index])),
        "seated_tip_gap_link": seated_gap.link,
        "template_tip_gap_mm": model.tip_gap_mm,
        "model_tip_gap_mm": model_gap,
        "min_tooth_sleeve_clearance_mm": min_sleeve.value,
        "min_tooth_sleeve_angle_deg": float(deg(angles[min_sleeve.pose_index])),
        "min_tooth_sleeve_link": min_sleeve.link,
        "min_tooth_sleeve_seated": int(sleeve_seated[min_sleeve.pose_index, min_sleeve.link]),
        "seated_sleeve_clearance_mm": seated_sleeve.value,
        "min_tooth_sleeve_unseated_mm": _finite(off_sleeve.value),
        "min_tooth_sleeve_unseated_angle_deg": float(deg(angles[off_sleeve.pose_index])),
        "model_seating_clearance_mm": model.seating_clearance_mm,
        "exact": {
            "min_tip_plate_distance_mm": ex_min_plate.value,
            "seated_tip_gap_mm": ex_seated_gap.value,
            "min_tip_plate_unseated_mm": _finite(ex_off_plate.value),
            "min_tooth_sleeve_clearance_mm": ex_min_sleeve.value,
            "seated_sleeve_clearance_mm": ex_seated_sleeve.value,
            "min_tooth_sleeve_unseated_mm": _finite(ex_off_sleeve.value),
            "max_mesh_deviation_mm": max_dev,
            "outline_step_mm": EXACT_OUTLINE_STEP_MM,
            "sagitta_bound_mm": exact.sagitta_mm,
        },
        "contact": {
            "tip_gap_free_mm": _finite(gap_proof.free_mm),
            "tip_gap_touching_mm": _finite(gap_proof.touching_mm),
            "tip_gap_free_at_minus_tol": int(gap_proof.free_at_minus),
            "tip_gap_touching_at_plus_tol": int(gap_proof.touching_at_plus),
            "seat_free_mm": _finite(sleeve_proof.free_mm),
            "seat_touching_mm": _finite(sleeve_proof.touching_mm),
            "seat_free_at_minus_tol": int(sleeve_proof.free_at_minus),
            "seat_touching_at_plus_tol": int(sleeve_proof.touching_at_plus),
            "tolerance_mm": contact_tol,
        },
        "mesh_error_bound_mm": bound,
        "contact_tolerance_mm": contact_tol,
        "collisions": collisions,
        "poses": n_poses,
        "links": wrap.links,
        "link_poses": n_poses * wrap.links,
        "cycle_deg": cycle_deg,
        "cycles_covered": float((angles[-1] - angles[0]) / wrap.cycle_rad),
        "sweep_start_deg": float(deg(angles[0])),
        "sweep_end_deg": float(deg(angles[-1])),
        "step_deg": float(deg(angles[1] - angles[0])),
        "seated_links_min": int(seated_counts.min()),
        "seated_links_max": int(seated_counts.max()),
        "min_at_seated_links": int(ex_off_plate.value >= ex_seated_gap.value - WINDOW_ROUNDING_MM
                                   and ex_off_sleeve.value >= ex_seated_sleeve.value - WINDOW_ROUNDING_MM),
        "verdict_pass": int(passed),
    }

    # --- rows (sweep.csv): one per sprocket angle
    row_sleeve, row_plate = sleeve_d.min(axis=1), plate_d.min(axis=1)
    off_s, off_p = _rowmin(sleeve_d, ~sleeve_seated), _rowmin(plate_d, ~links_seated)
    ex_row_s, ex_row_p = ex_sleeve.min(axis=1), ex_plate.min(axis=1)
    rows = [
        {
            "angle_deg": float(deg(a)),
            "min_tooth_sleeve_clearance_mm": float(row_sleeve[i]),
            "min_tip_plate_distance_mm": float(row_plate[i]),
            "seated_links": int(seated_counts[i]),
            "collide": int(hits[i].any()),
            "unseated_min_tooth_sleeve_mm": _finite(off_s[i]),
            "unseated_min_tip_plate_mm": _finite(off_p[i]),
            "exact_min_tooth_sleeve_mm": float(ex_row_s[i]),
            "exact_min_tip_plate_mm": float(ex_row_p[i]),
        }
        for i, a in enumerate(angles)
    ]

    # --- comparisons, plots, notes, worst poses
    x = [float(deg(a)) for a in angles]
    cycle_marks = [("cycle start θ = 0", 0.0), (f"one cycle β = {cycle_deg:.3f}°", cycle_deg)]
    comparisons = [
        Comparison("seated tip gap (tip to plate face)", "mm", None, model_gap, seated_gap.value,
                   f"template gap {model.tip_gap_mm:g} mm; model: 2-D outline at the plate offset e; "
                   f"paper window {model.required_gap_min_mm:g}–{model.required_gap_max_mm:g} mm",
                   exact=ex_seated_gap.value),
        Comparison("seating clearance ri − R (seated sleeve)", "mm", None, model.seating_clearance_mm,
                   seated_sleeve.value, "sleeve concentric with its seating arc; mesh within the bound",
                   exact=ex_seated_sleeve.value),
        Comparison("paper's window, lower limit vs min tip-to-plate over the sweep", "mm",
                   model.required_gap_min_mm, None, min_plate.value,
                   "links swinging in/out lift away: the minimum is at seated links", exact=ex_min_plate.value),
        Comparison("paper's window, upper limit vs largest seated tip gap", "mm", model.required_gap_max_mm,
                   None, seated_gap_max, "", exact=float(np.where(links_seated, ex_plate, -np.inf).max())),
        Comparison("closest sampled tip-to-plate distance of links off their seats", "mm", None, None,
                   _finite(off_plate.value), "swinging in/out: falls steadily to the seated gap as the pin "
                   "seats, never below it",
                   exact=_finite(ex_off_plate.value)),
        Comparison("closest sampled tooth–sleeve clearance of sleeves off their seats", "mm", None, None,
                   _finite(off_sleeve.value), "approaching / leaving: falls steadily to ri − R as the pin seats",
                   exact=_finite(ex_off_sleeve.value)),
    ]
    plots = [
        Plot("Track: tip-to-plate distance against sprocket angle", "sprocket angle θ (°)", "distance (mm)",
             [Series("min over all links (mesh)", x, [float(v) for v in row_plate]),
              Series("min over links off their seats (mesh)", x, [_finite(v) for v in off_p]),
              Series("min over all links (exact 2-D)", x, [float(v) for v in ex_row_p], "points")],
             markers=cycle_marks,
             hlines=[(f"paper minimum {model.required_gap_min_mm:g} mm", model.required_gap_min_mm),
                     (f"template gap {model.tip_gap_mm:g} mm", model.tip_gap_mm)]),
        Plot("Track: tooth–sleeve clearance against sprocket angle", "sprocket angle θ (°)", "clearance (mm)",
             [Series("min over all sleeves (mesh)", x, [float(v) for v in row_sleeve]),
              Series("min over sleeves off their seats (mesh)", x, [_finite(v) for v in off_s]),
              Series("min over all sleeves (exact 2-D)", x, [float(v) for v in ex_row_s], "points")],
             markers=cycle_marks,
             hlines=[(f"ri − R = {model.seating_clearance_mm:.3f} mm", model.seating_clearance_mm)]),
    ]
    notes = [
        f"Sweep: θ from {deg(angles[0]):.3f}° to {deg(angles[-1]):.3f}° in {n_poses} poses "
        f"({(angles[-1] - angles[0]) / wrap.cycle_rad:.2f} engagement cycles of β = {cycle_deg:.3f}°), "
        f"{wrap.links} links each ({seated_counts.min()}–{seated_counts.max()} seated). After one cycle every "
        "pose repeats shifted by one pin and two grooves (a symmetry of the sprocket), so the links "
        "together pass every point of the path: entry run, swinging in, seated, swinging out, exit run.",
        f"The fused link mesh is split by position in the link frame: {len(sleeve_mesh.faces)} sleeve triangles "
        f"(within R of the pin axis) and {len(plate_mesh.faces)} plate triangles.",
        f"Minimum tip-to-plate distance {min_plate.value:.4f} mm at {where(min_plate)}; links off their "
        f"seats stay ≥ {_finite(off_plate.value):.4f} mm at the sampled poses (closest at θ = "
        f"{deg(angles[off_plate.pose_index]):.3f}°, just before a pin seats: a swinging link's distance falls "
        "steadily to the seated gap at the seating instant, so the off-seat minimum is the sample nearest "
        "that instant and the overall minimum is at seated links). "
        f"Seated gap nearest point on the plate at x = {gap_point_link[0]:.3f}, y = {gap_point_link[1]:.4f} mm in the "
        "link frame: the plate face above the tip corner.",
        f"Minimum tooth–sleeve clearance {min_sleeve.value:.4f} mm at {where_sleeve(min_sleeve)} (whole link: "
        f"{whole_link_at_sleeve:.4f} mm); sleeves off their seats stay ≥ {_finite(off_sleeve.value):.4f} mm.",
        f"Contact from both sides: {gap_proof.label}: free at {gap_proof.measured_mm - contact_tol:.4f} mm, "
        f"collides at {gap_proof.measured_mm + contact_tol:.4f} mm, contact bracket "
        f"[{gap_proof.free_mm:.6f}, {gap_proof.touching_mm:.6f}] mm. {sleeve_proof.label}: contact bracket "
        f"[{sleeve_proof.free_mm:.6f}, {sleeve_proof.touching_mm:.6f}] mm (ri − R = {model.seating_clearance_mm:.4f}).",
        f"Exact 2-D model (ISO 606 outline at {EXACT_OUTLINE_STEP_MM} mm, no mesh): largest |mesh − exact| "
        f"over all {n_poses * wrap.links} link poses {max_dev:.4f} mm (bound {bound:.3f} mm).",
        f"Speed: {n_poses} poses ({n_poses * wrap.links} link poses, each 2 FCL distances, 1 FCL collision and "
        f"the exact 2-D distances) in {sweep_s:.2f} s = {n_poses / sweep_s:.0f} poses/s; contact proofs "
        f"{proof_s:.2f} s.",
    ]
    worst = [
        WorstPose(f"track: min tooth–sleeve clearance, {where_sleeve(min_sleeve)}", SPROCKET,
                  names[min_sleeve.link], s_sl.tolist(), pose_sl.tolist(), float(whole_link_at_sleeve)),
        WorstPose(f"track: min tip-to-plate distance, {where(min_plate)} (plate alone)", SPROCKET,
                  f"{names[min_plate.link]}.plate", s_pl.tolist(), pose_pl.tolist(), min_plate.value),
    ]
    timings = {"sweep_s": sweep_s, "poses_per_s": n_poses / sweep_s,
               "link_poses_per_s": n_poses * wrap.links / sweep_s, "contact_proof_s": proof_s}
    clearances = [(v, what) for v, what in ((ex_min_sleeve.value, "least tooth–sleeve clearance"),
                                            (ex_min_plate.value, "least tip-to-plate distance")) if v > 0.0]
    least = min(clearances) if clearances else None
    clearance = Clearance(float(least[0]), f"{least[1]} (exact 2-D)") if least else None
    return CheckResult(SECTION, summary, verdicts, rows, comparisons, plots, notes, worst, timings, clearance)
