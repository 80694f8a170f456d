"""Exact 2-D section model of the track drive (numpy only, no mesh, no FCL): the distances a
mesh sweep of sprocket and links must agree with.

The sprocket is an extrusion of the ISO 606 outline and the link an extrusion of a circle (sleeve)
and a rectangle (plate) across both tooth rows, so the 3-D distances between them are 2-D
distances between the outline and the link section. The outline is sampled at
``OUTLINE_STEP_MM`` with every arc end exact (chord sagitta ≤ step²/(8·ri), about 1e-5 mm).
Frames as in :mod:`gearcheck.geometry.track_chain` (sprocket frame, link frame).
"""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc

# Outline sampling step, and how far from a link its distances are resolved (mm).
OUTLINE_STEP_MM = 0.02
REACH_MM = 4.0


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
    for a, b in zip(c, c[1:] + c[:1], strict=True):
        out += _clip_outside_circle(a, b, link.sleeve_radius_mm)
    return out


class ExactSection:
    """Distances between the sprocket outline (one tooth row's section, a polyline through exact arc
    points) and a link's section: the sleeve circle and the plate's exposed boundary."""

    def __init__(self, gap: iso606.ToothGap, link: tc.LinkGeometry, step_mm: float = OUTLINE_STEP_MM,
                 reach_mm: float = REACH_MM):
        self.gap = gap
        self.link = link
        self.reach_mm = reach_mm
        self.step_mm = step_mm
        self.points = iso606.sprocket_outline(gap, step_mm)
        n = len(self.points)
        self.next = np.roll(np.arange(n), -1)
        self.prev = np.roll(np.arange(n), 1)
        self.max_edge = float(np.hypot(*(self.points[self.next] - self.points).T).max())
        self.outer_radius_mm = float(np.hypot(self.points[:, 0], self.points[:, 1]).max())
        # points sorted by polar angle: a disc around a point away from the axis lies inside an
        # angular window, i.e. a slice of this order
        polar = np.arctan2(self.points[:, 1], self.points[:, 0])
        self.order = np.argsort(polar)
        self.sorted_polar = polar[self.order]
        self.rect = link.plate_rect()
        self.plate_segments = plate_boundary(link)
        self.plate_starts = np.array([a for a, _ in self.plate_segments])
        self.plate_ends = np.array([b for _, b in self.plate_segments])
        self.plate_corners = np.unique(np.vstack([self.plate_starts, self.plate_ends]), axis=0)
        x0, x1, y0, y1 = self.rect
        self.plate_centre = np.array([(x0 + x1) / 2.0, (y0 + y1) / 2.0])
        self.plate_radius = math.hypot(x1 - x0, y1 - y0) / 2.0
        # the polyline's chords lie at most step²/(8ρ) from the arcs, ρ ≥ ri (flanks, tip: larger)
        self.sagitta_mm = step_mm**2 / (8.0 * gap.seating_radius_mm)

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

    def _sleeve(self, origin: np.ndarray) -> float:
        r = self.link.sleeve_radius_mm
        idx = self._near(origin, r + self.reach_mm)
        if not idx.size:
            return math.inf
        return self._polyline_distance(origin, idx, self.points[idx], lambda i: self.points[i]) - r

    def sleeve_clearance(self, sprocket_pose: np.ndarray, link_pose: np.ndarray) -> float:
        """The first of :meth:`link_distances` alone (the same figure)."""
        return self._sleeve(np.linalg.solve(sprocket_pose, link_pose)[:2, 3])

    def clear_of_outline(self, sprocket_pose: np.ndarray, link_pose: np.ndarray,
                         margin_mm: float = 0.0) -> tuple[bool, bool]:
        """Whether the sleeve, and the plate, certainly lie clear of the outline (distance > 0, and
        > ``margin_mm`` when that is positive) without measuring: wholly outside the circle through
        the outline's farthest vertex (its chords, and the exact arcs, lie inside it) by that much."""
        rel = np.linalg.solve(sprocket_pose, link_pose)
        rot, origin = rel[:2, :2], rel[:2, 3]
        beyond = self.outer_radius_mm + max(margin_mm, 0.0) + 1e-9
        sleeve = float(np.hypot(*origin)) - self.link.sleeve_radius_mm > beyond
        axis = -(origin @ rot)  # the sprocket axis in the link frame
        x0, x1, y0, y1 = self.rect
        plate = math.hypot(max(x0 - axis[0], 0.0, axis[0] - x1), max(y0 - axis[1], 0.0, axis[1] - y1)) > beyond
        return sleeve, plate

    def link_distances(self, sprocket_pose: np.ndarray, link_pose: np.ndarray) -> tuple[float, float]:
        """(sleeve clearance, plate distance) in mm, negative by the depth when the outline enters
        the sleeve or the plate; inf when no outline lies within the reach."""
        rel = np.linalg.solve(sprocket_pose, link_pose)  # link frame → sprocket frame
        rot, origin = rel[:2, :2], rel[:2, 3]
        sleeve = self._sleeve(origin)

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
