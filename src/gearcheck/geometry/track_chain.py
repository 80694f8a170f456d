"""Track chain wrapped on the every-other-tooth sprocket: link poses as data, numpy only.

Frames (millimetres, radians):

- **Sprocket frame**: axis +z at the origin, mid-plane z = 0 (between the two tooth rows), groove
  k centred on polar angle k·2π/z (as in :mod:`gearcheck.geometry.iso606`). In the world the
  sprocket is turned by the drive angle θ about +z (counter-clockwise positive).
- **Link frame**: origin on the link's own pin axis (its sleeve's axis), +x towards the link's
  other pin (pin distance p), +y the outward normal of the pin line (away from the sprocket, the
  side the track plate lies on), +z = sprocket axis, z = 0 the track mid-plane.

Wrap (a documented choice, :class:`ChainWrap`): a segment of ``links`` links, pins numbered 0 …
links from the downstream end. Link j joins pins j and j + 1 and carries the sleeve on pin j.
The chain runs counter-clockwise with the sprocket: it arrives along the *entry run* (a straight
line with the fixed direction of the tangent at polar angle ψ_in), follows the sprocket over the
wrap angle, and leaves along the *exit run* (fixed direction of the tangent at ψ_out = ψ_in +
wrap). The idlers are taken as infinitely far, so each run keeps its direction and passes through
the outermost seated pin on its side (the chordal rise of a roller-chain drive).

Pin j belongs to groove k_j = k_0 − 2j (pins sit in grooves two apart; d = p / sin(360°/z), so
the link chord between them is exactly p). With the groove's polar angle φ_j = θ + 2π·k_j/z, the
pin is **seated** (its axis on the pin circle, at the groove's seating centre) while

    ψ_in − β/2 ≤ φ_j ≤ ψ_out + β/2,          β = 2·(2π/z), the angle a link subtends.

At ψ_in − β/2 a pin arriving on the entry run meets the pin circle exactly at its groove (the
link ahead of it is then a chord parallel to the run), and at ψ_out + β/2 the last seated pin
leaves it the same way, so the poses are continuous in θ. Between seatings the link behind the
first seated pin stays parallel to the entry run while the sprocket turns under it: relative to
the sprocket it swings into mesh (by β per cycle), its free pin approaching its groove from
outside the pin circle; at the exit it swings out the same way. A link is seated when both its
pins are. One engagement cycle is β of sprocket rotation: after it every pose repeats with the
pin numbers shifted by one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gearcheck.geometry import iso606

# Tolerance (rad) on the seating bounds, so a pin exactly at a bound counts as seated; the poses
# are continuous there, so either side gives the same positions.
SEATING_ANGLE_TOL_RAD = 1e-12

# Link shape choices (not in the paper; see docs/sprocket_cad.md).
PLATE_THICKNESS_MM = 5.0
# Gap between the plate's end and the next link's sleeve (the plate ends short of the next pin).
SLEEVE_PLATE_CLEARANCE_MM = 0.5
# Gap between the ends of adjacent plates on a straight run (it opens wider on the wrap).
PLATE_END_GAP_MM = 2.0


def pin_circle_radius(pitch_mm: float, teeth: int) -> float:
    """Radius of the circle the seated pin axes lie on: d/2, d = p / sin(360°/z) (paper eq. 6)."""
    return iso606.every_other_tooth_pitch_diameter(pitch_mm, teeth) / 2.0


def link_angle_rad(teeth: int) -> float:
    """β = 2·(2π/z): the angle a seated link subtends at the sprocket axis (two groove steps).
    Also the sprocket rotation of one engagement cycle."""
    return 4.0 * math.pi / teeth


def tangent_direction(polar_angle_rad: float) -> np.ndarray:
    """Unit direction of counter-clockwise motion on a circle at the given polar angle."""
    return np.array([-math.sin(polar_angle_rad), math.cos(polar_angle_rad)])


@dataclass(frozen=True)
class ChainWrap:
    """A chain segment wrapped counter-clockwise on the sprocket (see the module docstring).

    ``entry_angle_deg`` (ψ_in) is the polar angle where the entry run is tangent to the pin circle
    (90°: the upper run, horizontal, arriving from +x); ``wrap_angle_deg`` the angle between the
    entry and exit tangents; ``first_pin_groove`` the groove k_0 of pin 0 at θ = 0.
    """

    teeth: int
    pitch_mm: float
    links: int
    first_pin_groove: int
    entry_angle_deg: float = 90.0
    wrap_angle_deg: float = 120.0

    def __post_init__(self) -> None:
        beta = link_angle_rad(self.teeth)
        if self.links < 1:
            raise ValueError("a chain segment needs at least one link")
        if not 0.0 < math.radians(self.wrap_angle_deg) < 2.0 * math.pi - 2.0 * beta:
            raise ValueError("wrap angle must be positive and leave room for the runs")
        if (self.links + 1) * beta >= 2.0 * math.pi:
            raise ValueError("the segment would wrap all the way round the sprocket")

    @classmethod
    def centred(cls, teeth: int, pitch_mm: float, links: int | None = None, entry_angle_deg: float = 90.0,
                wrap_angle_deg: float = 120.0, run_links: int = 2) -> ChainWrap:
        """The segment whose middle pin sits, at θ = 0, in the groove nearest the middle of the wrap
        (so both runs carry about the same number of links). Without ``links``: as many links as
        the wrap seats (wrap/β, rounded) plus ``run_links`` on each run."""
        step = 2.0 * math.pi / teeth
        if links is None:
            links = round(math.radians(wrap_angle_deg) / link_angle_rad(teeth)) + 2 * run_links
        middle = math.radians(entry_angle_deg + wrap_angle_deg / 2.0)
        k_mid = round(middle / step)
        return cls(teeth, pitch_mm, links, k_mid + 2 * (links // 2), entry_angle_deg, wrap_angle_deg)

    @property
    def pin_radius_mm(self) -> float:
        return pin_circle_radius(self.pitch_mm, self.teeth)

    @property
    def cycle_rad(self) -> float:
        """Sprocket rotation of one engagement cycle, β."""
        return link_angle_rad(self.teeth)

    @property
    def entry_angle_rad(self) -> float:
        return math.radians(self.entry_angle_deg)

    @property
    def exit_angle_rad(self) -> float:
        return math.radians(self.entry_angle_deg + self.wrap_angle_deg)

    def pin_grooves(self) -> np.ndarray:
        """Groove k_j of each pin j (0 … links), pins two grooves apart."""
        return self.first_pin_groove - 2 * np.arange(self.links + 1)

    def groove_angles(self, sprocket_angle_rad: float) -> np.ndarray:
        """Polar angle φ_j of each pin's groove at drive angle θ (not reduced modulo 2π)."""
        return sprocket_angle_rad + 2.0 * math.pi * self.pin_grooves() / self.teeth

    def seated_pins(self, sprocket_angle_rad: float) -> np.ndarray:
        """Boolean per pin: axis on the pin circle, in its groove (ψ_in − β/2 ≤ φ_j ≤ ψ_out + β/2)."""
        beta = self.cycle_rad
        lo = self.entry_angle_rad - beta / 2.0
        span = self.exit_angle_rad + beta / 2.0 - lo
        rel = np.mod(self.groove_angles(sprocket_angle_rad) - lo + SEATING_ANGLE_TOL_RAD, 2.0 * math.pi)
        return rel <= span + 2.0 * SEATING_ANGLE_TOL_RAD

    def seated_links(self, sprocket_angle_rad: float) -> np.ndarray:
        """Boolean per link: both its pins seated."""
        s = self.seated_pins(sprocket_angle_rad)
        return s[:-1] & s[1:]

    def pin_positions(self, sprocket_angle_rad: float) -> np.ndarray:
        """(links + 1, 2) pin-axis positions in the world plane at drive angle θ."""
        seated = self.seated_pins(sprocket_angle_rad)
        idx = np.flatnonzero(seated)
        if idx.size == 0:
            raise ValueError("no pin of the segment is on the sprocket at this angle")
        first, last = int(idx[0]), int(idx[-1])  # exit-side (downstream) and entry-side seated pins
        if idx.size != last - first + 1:
            raise ValueError("seated pins are not contiguous: the segment is too long for the wrap")
        phi = self.groove_angles(sprocket_angle_rad)
        r = self.pin_radius_mm
        pins = np.column_stack([r * np.cos(phi), r * np.sin(phi)])
        d_in = tangent_direction(self.entry_angle_rad)
        d_out = tangent_direction(self.exit_angle_rad)
        j = np.arange(self.links + 1)
        up = j > last  # entry run: upstream of the first seated pin, against the motion
        pins[up] = pins[last] - np.outer(j[up] - last, d_in) * self.pitch_mm
        down = j < first  # exit run: downstream of the last seated pin, with the motion
        pins[down] = pins[first] + np.outer(first - j[down], d_out) * self.pitch_mm
        return pins

    def link_poses(self, sprocket_angle_rad: float) -> np.ndarray:
        """(links, 3) planar pose of each link frame: x, y of its own pin (pin j) and the angle of
        its +x axis (towards pin j + 1)."""
        pins = self.pin_positions(sprocket_angle_rad)
        step = pins[1:] - pins[:-1]
        return np.column_stack([pins[:-1], np.arctan2(step[:, 1], step[:, 0])])

    def link_matrices(self, sprocket_angle_rad: float) -> np.ndarray:
        """(links, 4, 4) homogeneous transforms link frame → world."""
        return np.stack([planar_matrix(x, y, a) for x, y, a in self.link_poses(sprocket_angle_rad)])


def planar_matrix(x_mm: float, y_mm: float, angle_rad: float) -> np.ndarray:
    """4×4 transform: rotation by ``angle_rad`` about +z, then translation (x, y, 0)."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[:2, 3] = (x_mm, y_mm)
    return m


def sprocket_matrix(sprocket_angle_rad: float) -> np.ndarray:
    """4×4 transform sprocket frame → world at drive angle θ."""
    return planar_matrix(0.0, 0.0, sprocket_angle_rad)


@dataclass(frozen=True)
class LinkGeometry:
    """One track link in its own frame (see the module docstring): a sleeve of radius
    ``sleeve_radius_mm`` on the pin axis (the z axis), ``sleeve_length_mm`` long, centred on z = 0,
    and a plate (box) x ∈ [plate_start_x, plate_end_x], y ∈ [e, e + thickness], |z| ≤ width/2.

    The plate's inner face lies ``plate_offset_mm`` (e) outside the pin line; the sleeve crosses
    it, which joins sleeve and plate. The plate stops short of the next pin (x = p) so that the next
    link's sleeve, which turns about that pin, never meets it, whatever the joint angle.
    """

    pitch_mm: float
    sleeve_radius_mm: float
    sleeve_length_mm: float
    plate_offset_mm: float
    plate_thickness_mm: float
    plate_width_mm: float
    plate_start_x_mm: float
    plate_end_x_mm: float

    @property
    def plate_face_y_mm(self) -> float:
        return self.plate_offset_mm

    @property
    def plate_length_mm(self) -> float:
        return self.plate_end_x_mm - self.plate_start_x_mm

    def sleeve_plate_clearance_mm(self) -> float:
        """Distance from the next link's sleeve (axis at x = p, y = 0) to this plate's end."""
        return _point_box_distance_2d(np.array([self.pitch_mm, 0.0]), self.plate_rect()) - self.sleeve_radius_mm

    def plate_rect(self) -> tuple[float, float, float, float]:
        """(x0, x1, y0, y1) of the plate's section in the link frame."""
        e = self.plate_offset_mm
        return self.plate_start_x_mm, self.plate_end_x_mm, e, e + self.plate_thickness_mm


def _point_box_distance_2d(point: np.ndarray, rect: tuple[float, float, float, float]) -> float:
    x0, x1, y0, y1 = rect
    dx = max(x0 - point[0], 0.0, point[0] - x1)
    dy = max(y0 - point[1], 0.0, point[1] - y1)
    return math.hypot(dx, dy)


def link_geometry(
    pitch_mm: float,
    sleeve_diameter_mm: float,
    plate_offset_mm: float,
    track_width_mm: float,
    plate_thickness_mm: float = PLATE_THICKNESS_MM,
    sleeve_plate_clearance_mm: float = SLEEVE_PLATE_CLEARANCE_MM,
    plate_end_gap_mm: float = PLATE_END_GAP_MM,
) -> LinkGeometry:
    """The link used here: sleeve and plate across the full track width; the plate's end is
    ``sleeve_plate_clearance_mm`` clear of the next sleeve where that sleeve crosses the face
    plane (x = p − √(R² − e²) − clearance), and the plate starts ``plate_end_gap_mm`` after the
    previous plate's end on a straight run (so it overhangs its own pin by a little).

    Requires e < R (the sleeve must cross the plate face to join the plate) and a plate start
    before the sleeve leaves the face plane.
    """
    r = sleeve_diameter_mm / 2.0
    e = plate_offset_mm
    if not 0.0 < e < r:
        raise ValueError(f"plate offset e = {e:g} mm must lie inside the sleeve radius {r:g} mm "
                         "so that the sleeve joins the plate")
    half_cut = math.sqrt(r * r - e * e)  # half-width of the sleeve's trace on the face plane
    end_x = pitch_mm - half_cut - sleeve_plate_clearance_mm
    start_x = end_x - pitch_mm + plate_end_gap_mm
    if not -half_cut < start_x < half_cut:
        raise ValueError("plate start must lie over its own sleeve (choose a smaller end gap/clearance)")
    return LinkGeometry(
        pitch_mm=pitch_mm,
        sleeve_radius_mm=r,
        sleeve_length_mm=track_width_mm,
        plate_offset_mm=e,
        plate_thickness_mm=plate_thickness_mm,
        plate_width_mm=track_width_mm,
        plate_start_x_mm=start_x,
        plate_end_x_mm=end_x,
    )


# --------------------------------------------------------------------------------------------
# The polygon effect: the entry run's speed and height over an engagement cycle

@dataclass(frozen=True)
class PolygonEffect:
    """The entry run over one engagement cycle, from the wrap's poses: drive angles (rad), the run's
    distance from the sprocket axis (mm) and its speed along itself over ω·R (R the pin circle's
    radius); the speed ripple 1 − v_min/v_max and the chordal rise (the distance's range)."""

    angles: np.ndarray
    height_mm: np.ndarray
    speed: np.ndarray

    @property
    def ripple(self) -> float:
        return float(1.0 - self.speed.min() / self.speed.max())

    @property
    def rise_mm(self) -> float:
        return float(self.height_mm.max() - self.height_mm.min())


# Half the step of the central differences of the run's position (rad of drive angle): the error is
# ~R·ε²/6 relative to R, far below 1e-9.
SPEED_STEP_RAD = 1e-6


def polygon_effect(wrap: ChainWrap, samples: int = 64) -> PolygonEffect:
    """Measure the polygon effect on the wrap's own poses over one cycle, from one seating of an
    entry pin to the next: the run through the entry-side seated pin (the line of the entry
    direction), its distance from the axis, and the speed of the point one pitch up the run (its
    position along the run, differentiated: central differences, one-sided at the two seatings,
    where the run's speed has a kink)."""
    beta = wrap.cycle_rad
    lo = wrap.entry_angle_rad - beta / 2.0  # a pin seats on the entry side where its groove reaches this
    start = float(np.min(np.mod(lo - wrap.groove_angles(0.0), beta)))
    angles = start + beta * np.linspace(0.0, 1.0, samples + 1)
    d_in = tangent_direction(wrap.entry_angle_rad)
    normal = np.array([math.cos(wrap.entry_angle_rad), math.sin(wrap.entry_angle_rad)])
    eps = SPEED_STEP_RAD
    height, speed = np.empty(angles.size), np.empty(angles.size)
    for n, theta in enumerate(angles):
        last = int(np.flatnonzero(wrap.seated_pins(theta))[-1])  # the entry-side seated pin
        height[n] = float(normal @ wrap.pin_positions(theta)[last])
        # offsets on one side of a seating (the first and the last angle are seatings)
        steps = (0.0, eps, 2 * eps) if n == 0 else (-2 * eps, -eps, 0.0) if n == samples else (-eps, 0.0, eps)
        a, b, c = (float(d_in @ _run_point(wrap, theta + s, last)) for s in steps)
        slope = (-3 * a + 4 * b - c) if n == 0 else (a - 4 * b + 3 * c) if n == samples else (c - a)
        speed[n] = slope / (2 * eps) / wrap.pin_radius_mm
    return PolygonEffect(angles, height, speed)


def _run_point(wrap: ChainWrap, theta: float, pin: int) -> np.ndarray:
    """The point one pitch up the entry run from the seated ``pin`` at drive angle θ (that pin on
    the pin circle at its groove, as :meth:`ChainWrap.pin_positions` places it)."""
    phi = float(wrap.groove_angles(theta)[pin])
    r = wrap.pin_radius_mm
    return np.array([r * math.cos(phi), r * math.sin(phi)]) - tangent_direction(wrap.entry_angle_rad) * wrap.pitch_mm


def speed_ripple(teeth: int) -> float:
    """Closed form of the run's speed ripple on every other tooth: 1 − cos(360°/z) (a link subtends
    two tooth steps, so the chain is a polygon of z/2 sides)."""
    return 1.0 - math.cos(2.0 * math.pi / teeth)


def chordal_rise(pitch_mm: float, teeth: int) -> float:
    """Closed form of the chordal rise on every other tooth: R·(1 − cos(360°/z)), R = d/2."""
    return pin_circle_radius(pitch_mm, teeth) * speed_ripple(teeth)
