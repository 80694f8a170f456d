"""Straight bevel gears with spherical-involute flanks (numpy only).

Frame of one gear: the apex (the common apex of the pair) is the origin, the gear axis is +z and
the teeth lie at z > 0 (cone distance r = |p|, polar angle θ = angle from +z, azimuth a). Tooth 0
is centred on azimuth 0 (the +x half-plane). Every surface of a tooth — both flanks, the tip land
(face cone) and the root (root cone) — is a cone through the apex: a point of a flank is r·u with
u a unit vector on the spherical profile. Hence the section of the teeth by any plane z = h is the
central projection h·u/u_z of the spherical profile, and two such sections differ only by the
homothety about the apex (docs/bevel.md).

Spherical involute (docs/bevel.md §1). A great circle rolls without slip on the base circle
(polar angle δb) of the unit sphere; a point of it traces the involute. With roll angle φ (the
azimuth of the tangency point T) the rolled arc is s = φ·sin δb and

    u(φ) = cos s · T(φ) − sin s · t(φ),   T = (sin δb cos φ, sin δb sin φ, cos δb),
                                           t = (−sin φ, cos φ, 0)

so cos θ = cos δb · cos s and the azimuth is η(φ) = φ − atan(tan s / sin δb) (the spherical
"inv"). The generating great circle is the flank normal; it is tangent to the base circle, and the
spherical sine rule at the pitch point gives sin δb = sin δ · cos α.

Sides: ``side = -1`` is the flank on the −azimuth side of tooth 0 (the basic involute above,
rotated), ``side = +1`` its mirror image in the xz-plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np

# Outline segment kinds of a planar section (see SectionProfile).
SegmentKind = Literal["flank", "radial", "tip", "root", "side"]

# A blank face must not coincide with a tooth surface (booleans on coincident faces are slow and
# fragile): the blank's outer cone clears the tip cone by this angle.
BLANK_TIP_MARGIN_RAD = math.radians(1.0)
# Default depth of the blank under the roots at the back and front ends, in modules.
BLANK_RIM_MODULES = 1.0


def gleason_profile_shift(pinion_teeth: int, gear_teeth: int) -> float:
    """Long/short addendum rule for 90° straight bevels: pinion addendum = (1 + x)·m with
    x = 0.46·(1 − (z1/z2)²), the gear gets −x (Gleason's 0.54 + 0.46/u² gear addendum).
    For 13/33 it gives 0.389."""
    ratio = pinion_teeth / gear_teeth
    return 0.46 * (1.0 - ratio * ratio)


@dataclass(frozen=True)
class BevelGearSpec:
    """One straight bevel gear of a pair with a common apex. Lengths in mm at the outer end.

    profile_shift: x in modules (long/short addendum: + on the pinion, − on the gear); it moves
    addendum and dedendum by x·m and thickens the outer pitch tooth by 2·x·m·tan α (the pair has
    zero backlash for x_gear = −x_pinion and no thinning).
    thinning_mm: circumferential tooth thinning at the outer pitch circle (backlash allowance);
    the thinning tapers to the apex with the tooth.
    mounting_distance_mm / front_face_distance_mm: apex to the back (mounting) face and to the
    front (toe) face, along the axis; None puts each BLANK_RIM_MODULES modules under the root
    (the front face at most halfway from the inner root corner to the back face).
    """

    teeth: int
    mate_teeth: int
    module_mm: float
    face_width_mm: float
    pressure_angle_deg: float = 20.0
    shaft_angle_deg: float = 90.0
    profile_shift: float = 0.0
    thinning_mm: float = 0.0
    addendum_coef: float = 1.0
    clearance_coef: float = 0.25
    bore_mm: float = 0.0
    mounting_distance_mm: float | None = None
    front_face_distance_mm: float | None = None

    def __post_init__(self):
        if self.teeth < 5 or self.mate_teeth < 5:
            raise ValueError("teeth and mate_teeth must be >= 5")
        if not (self.module_mm > 0 and self.face_width_mm > 0):
            raise ValueError("module_mm and face_width_mm must be > 0")
        if not (10.0 <= self.pressure_angle_deg <= 30.0):
            raise ValueError("pressure_angle_deg must be in [10, 30]")
        if not (20.0 <= self.shaft_angle_deg <= 160.0):
            raise ValueError("shaft_angle_deg must be in [20, 160]")
        if not (self.face_width_mm < 0.5 * self.outer_cone_distance_mm):
            raise ValueError("face_width_mm must be < half the outer cone distance")
        if self.face_angle_rad >= math.radians(85.0):
            raise ValueError("face cone too flat for planar sections (face angle >= 85°)")
        if self.tip_land_angle_rad <= 0.0:
            raise ValueError("pointed tooth: reduce profile_shift or addendum_coef")
        if self.root_space_angle_rad <= 0.0:
            raise ValueError("no tooth space at the root: profile_shift too large")
        if self.bore_mm < 0:
            raise ValueError("bore_mm must be >= 0")
        self.blank_profile()  # raises if the blank faces do not fit under the roots

    # -- cones -----------------------------------------------------------------------------
    @property
    def pressure_angle_rad(self) -> float:
        return math.radians(self.pressure_angle_deg)

    @property
    def pitch_angle_rad(self) -> float:
        """δ: tan δ = sin Σ / (z_mate/z + cos Σ) (90°: δ = atan(z/z_mate))."""
        sigma = math.radians(self.shaft_angle_deg)
        return math.atan2(math.sin(sigma), self.mate_teeth / self.teeth + math.cos(sigma))

    @property
    def base_angle_rad(self) -> float:
        """δb: sin δb = sin δ · cos α (spherical sine rule at the pitch point)."""
        return math.asin(math.sin(self.pitch_angle_rad) * math.cos(self.pressure_angle_rad))

    @property
    def outer_pitch_diameter_mm(self) -> float:
        return self.teeth * self.module_mm

    @property
    def outer_cone_distance_mm(self) -> float:
        """Re = d / (2 sin δ); the same for both gears of the pair."""
        return self.outer_pitch_diameter_mm / (2.0 * math.sin(self.pitch_angle_rad))

    @property
    def inner_cone_distance_mm(self) -> float:
        return self.outer_cone_distance_mm - self.face_width_mm

    @property
    def virtual_teeth(self) -> float:
        """Tredgold's back-cone equivalent spur tooth count z / cos δ."""
        return self.teeth / math.cos(self.pitch_angle_rad)

    @property
    def addendum_mm(self) -> float:
        """Outer addendum (ha* + x)·m."""
        return (self.addendum_coef + self.profile_shift) * self.module_mm

    @property
    def dedendum_mm(self) -> float:
        """Outer dedendum (ha* + c* − x)·m."""
        return (self.addendum_coef + self.clearance_coef - self.profile_shift) * self.module_mm

    @property
    def face_angle_rad(self) -> float:
        """Tip (face) cone θa = δ + atan(ha / Re): through the apex (tapered depth, §2 docs)."""
        return self.pitch_angle_rad + math.atan(self.addendum_mm / self.outer_cone_distance_mm)

    @property
    def root_angle_rad(self) -> float:
        """Root cone θf = δ − atan(hf / Re), through the apex."""
        return self.pitch_angle_rad - math.atan(self.dedendum_mm / self.outer_cone_distance_mm)

    # -- tooth thickness (azimuth angles on the sphere) ------------------------------------
    @property
    def outer_pitch_thickness_mm(self) -> float:
        """Circular thickness on the outer pitch circle: m(π/2 + 2x tan α) − thinning."""
        m = self.module_mm
        return (m * (math.pi / 2 + 2 * self.profile_shift * math.tan(self.pressure_angle_rad))
                - self.thinning_mm)

    @property
    def pitch_thickness_angle_rad(self) -> float:
        """ψ: azimuth subtended by the tooth on the pitch cone (the same at every cone distance)."""
        return self.outer_pitch_thickness_mm / (self.outer_pitch_diameter_mm / 2)

    @property
    def angular_pitch_rad(self) -> float:
        return 2 * math.pi / self.teeth

    @property
    def tip_land_angle_rad(self) -> float:
        """Azimuth width of the tip land (on the face cone)."""
        return 2 * float(flank_azimuth(self, self.face_angle_rad, +1))

    @property
    def form_angle_rad(self) -> float:
        """Polar angle where the involute starts: the base cone, or the root cone if higher."""
        return max(self.base_angle_rad, self.root_angle_rad)

    @property
    def root_space_angle_rad(self) -> float:
        """Azimuth width of the tooth space on the root cone."""
        return self.angular_pitch_rad - 2 * float(flank_azimuth(self, self.root_angle_rad, +1))

    # -- blank -----------------------------------------------------------------------------
    def _root_corner(self, cone_distance: float) -> tuple[float, float]:
        """(ρ, z) where the root cone meets the back cone (Re) or front cone (Ri)."""
        d, f = self.pitch_angle_rad, self.root_angle_rad
        r = cone_distance / math.cos(d - f)  # root element meets the back/front cone
        return r * math.sin(f), r * math.cos(f)

    @property
    def mounting_distance(self) -> float:
        """Apex → back face along the axis (mm); default BLANK_RIM_MODULES·m under the outer
        root along the back cone."""
        if self.mounting_distance_mm is not None:
            return self.mounting_distance_mm
        d = self.pitch_angle_rad
        rho, z = self._root_corner(self.outer_cone_distance_mm)
        # step down the back cone (direction (−cos δ, +sin δ) in (ρ, z)) by one rim depth
        return z + BLANK_RIM_MODULES * self.module_mm * math.sin(d)

    @property
    def front_face_distance(self) -> float:
        """Apex → front (toe) face along the axis (mm); default BLANK_RIM_MODULES·m under the
        inner root along the front cone, but never past halfway from the inner root corner to
        the back face: a back face close behind the roots (a flat gear mounted near its heel,
        e.g. a ring gear) keeps a web between the two faces instead of a front face behind the
        back face (a blank turned inside out)."""
        if self.front_face_distance_mm is not None:
            return self.front_face_distance_mm
        d = self.pitch_angle_rad
        rho, z = self._root_corner(self.inner_cone_distance_mm)
        rim = z + BLANK_RIM_MODULES * self.module_mm * math.sin(d)
        return min(rim, 0.5 * (z + self.mounting_distance))

    def blank_profile(self) -> np.ndarray:
        """Closed meridian polygon (ρ, z), counter-clockwise, of the blank to revolve about z.

        Bounded by the bore, the front face, the front cone (ρ sin δ + z cos δ = Ri), an outer
        cone BLANK_TIP_MARGIN_RAD beyond the tips, the back cone (ρ sin δ + z cos δ = Re) and the
        back (mounting) face. The teeth come from the tooth loft, not from this polygon.
        """
        d = self.pitch_angle_rad
        sd, cd = math.sin(d), math.cos(d)
        re, ri = self.outer_cone_distance_mm, self.inner_cone_distance_mm
        r_bore = self.bore_mm / 2
        z_back, z_front = self.mounting_distance, self.front_face_distance
        to = math.tan(self.face_angle_rad + BLANK_TIP_MARGIN_RAD)

        def on_cone_at_z(distance, z):  # ρ on the back/front cone at height z
            return (distance - z * cd) / sd

        def on_cone_and_outer(distance):  # back/front cone ∩ outer cone ρ = z·to
            z = distance / (to * sd + cd)
            return z * to, z

        pts = []
        rho_f = on_cone_at_z(ri, z_front)
        rho_b = on_cone_at_z(re, z_back)
        root_in = self._root_corner(ri)[0]
        root_out = self._root_corner(re)[0]
        # the back face first: the default front face is placed from it
        if not rho_b < root_out:
            raise ValueError("mounting_distance_mm must put the back face under the outer root")
        if not (r_bore < rho_f < root_in):
            raise ValueError("front_face_distance_mm must put the front face under the inner root")
        if not z_front < z_back:
            raise ValueError("front_face_distance_mm must put the front face in front of the back face")
        pts.append((r_bore, z_front))
        pts.append((rho_f, z_front))
        pts.append(on_cone_and_outer(ri))
        pts.append(on_cone_and_outer(re))
        if rho_b > r_bore:
            pts.append((rho_b, z_back))
            pts.append((r_bore, z_back))
        else:  # the back cone reaches the bore before the back face
            pts.append((r_bore, (re - r_bore * sd) / cd))
        return np.array(pts, dtype=float)


def mating_spec(spec: BevelGearSpec, **changes) -> BevelGearSpec:
    """The other gear of the pair: teeth swapped, profile shift negated, default blank."""
    base: dict[str, Any] = dict(teeth=spec.mate_teeth, mate_teeth=spec.teeth, profile_shift=-spec.profile_shift,
                                mounting_distance_mm=None, front_face_distance_mm=None, bore_mm=0.0)
    base.update(changes)
    return replace(spec, **base)


# -- spherical involute -------------------------------------------------------------------
def spherical_involute(base_angle: float, roll) -> np.ndarray:
    """Unit vectors u(φ) (…, 3) of the basic spherical involute (starts at azimuth 0)."""
    phi = np.asarray(roll, dtype=float)
    sb, cb = math.sin(base_angle), math.cos(base_angle)
    s = phi * sb
    cs, ss = np.cos(s), np.sin(s)
    cp, sp = np.cos(phi), np.sin(phi)
    return np.stack([cs * sb * cp + ss * sp, cs * sb * sp - ss * cp, cs * cb * np.ones_like(cp)],
                    axis=-1)


def roll_angle_at_polar(base_angle: float, polar) -> np.ndarray:
    """φ with polar angle θ(φ) = polar (θ ≥ δb): cos θ = cos δb · cos(φ sin δb)."""
    return _rolled_arc(base_angle, np.asarray(polar, dtype=float)) / math.sin(base_angle)


def _rolled_arc(base_angle: float, polar: np.ndarray | np.floating) -> np.ndarray:
    """s with cos s = cos θ / cos δb, in the form tan s = √(sin(θ−δb)·sin(θ+δb)) / cos θ, which
    keeps full precision at the base cone (arccos of a ratio near 1 loses half the digits)."""
    prod = np.sin(polar - base_angle) * np.sin(polar + base_angle)
    return np.arctan2(np.sqrt(np.maximum(prod, 0.0)), np.cos(polar))


def involute_azimuth(base_angle: float, polar) -> np.ndarray:
    """η(θ): azimuth of the basic spherical involute at polar angle θ ≥ δb (spherical 'inv')."""
    sb = math.sin(base_angle)
    phi = roll_angle_at_polar(base_angle, polar)
    return phi - np.arctan(np.tan(phi * sb) / sb)


def flank_azimuth(spec: BevelGearSpec, polar, side: int) -> np.ndarray:
    """Azimuth of tooth 0's flank (side ±1) at polar angle θ; radial (constant) below δb."""
    db = spec.base_angle_rad
    theta = np.maximum(np.asarray(polar, dtype=float), db)
    half = spec.pitch_thickness_angle_rad / 2 + involute_azimuth(db, spec.pitch_angle_rad)
    return side * (half - involute_azimuth(db, theta))


def _unit(polar, azimuth) -> np.ndarray:
    polar, azimuth = np.broadcast_arrays(np.asarray(polar, float), np.asarray(azimuth, float))
    st = np.sin(polar)
    return np.stack([st * np.cos(azimuth), st * np.sin(azimuth), np.cos(polar)], axis=-1)


def _involute_rolls(spec: BevelGearSpec, n: int) -> np.ndarray:
    """n roll angles, uniform, from the form cone to the tip cone (dense near the base cusp)."""
    db = spec.base_angle_rad
    return np.linspace(roll_angle_at_polar(db, spec.form_angle_rad),
                       roll_angle_at_polar(db, spec.face_angle_rad), n)


def _flank_polar_samples(spec: BevelGearSpec, n: int) -> np.ndarray:
    """Polar angles of n points root → tip: uniform roll angle on the involute part, and the
    root point in front when the root cone is below the base cone (radial part, a great arc)."""
    db = spec.base_angle_rad
    radial = spec.root_angle_rad < db
    rolls = _involute_rolls(spec, n - 1 if radial else n)
    polar = np.arccos(np.cos(db) * np.cos(rolls * math.sin(db)))
    if radial:
        polar = np.concatenate([[spec.root_angle_rad], polar])
    return polar


def flank_directions(spec: BevelGearSpec, side: int, n: int = 50) -> np.ndarray:
    """(n, 3) unit vectors along tooth 0's flank (side ±1), root cone → tip cone.

    The flank surface is {r·u : Ri ≤ r ≤ Re} for these u (a cone through the apex).
    """
    if side not in (-1, 1):
        raise ValueError("side must be -1 or +1")
    polar = _flank_polar_samples(spec, n)
    return _unit(polar, flank_azimuth(spec, polar, side))


def pitch_cone_tooth_thickness(spec: BevelGearSpec, cone_distance) -> np.ndarray:
    """Circular tooth thickness (mm) on the pitch circle at a cone distance: the arc
    R·sin δ·ψ, proportional to R (the tooth tapers to the apex)."""
    return np.asarray(cone_distance, dtype=float) * math.sin(spec.pitch_angle_rad) * \
        spec.pitch_thickness_angle_rad


# -- planar sections ----------------------------------------------------------------------
@dataclass(frozen=True)
class ProfileSegment:
    """One piece of a section outline: ``flank`` points to interpolate (root → tip or tip →
    root, following the outline), ``radial``/``side`` a straight 2-point line, ``tip``/``root``
    a circular arc given by (start, middle, end) exactly on the circle of radius z·tan θ."""

    kind: SegmentKind
    points: np.ndarray  # (k, 2)


@dataclass(frozen=True)
class SectionProfile:
    """Closed outline in the plane z = z_plane, counter-clockwise about +z: the whole gear, or
    one tooth's sector (two ``side`` lines from the axis point (0, 0) to the root circle at
    azimuth ∓π/z)."""

    z_plane: float
    segments: tuple[ProfileSegment, ...]
    teeth: int = field(default=0)

    def polyline(self, arc_points: int = 9) -> np.ndarray:
        """Dense closed polyline (N, 2) (arcs sampled; last point not repeated)."""
        out = []
        for seg in self.segments:
            if seg.kind in ("tip", "root"):
                a0 = math.atan2(seg.points[0, 1], seg.points[0, 0])
                a1 = math.atan2(seg.points[2, 1], seg.points[2, 0])
                a1 = a0 + (a1 - a0) % (2 * math.pi)
                rad = float(np.hypot(*seg.points[0]))
                a = np.linspace(a0, a1, arc_points)
                out.append(np.stack([rad * np.cos(a), rad * np.sin(a)], -1)[:-1])
            else:
                out.append(seg.points[:-1])
        return np.concatenate(out)


def section_profile(spec: BevelGearSpec, z_plane: float, flank_points: int = 24,
                    sector: bool = False) -> SectionProfile:
    """The whole-gear outline in the plane z = z_plane: central projection h·u/u_z of the
    spherical tooth profile (so ρ = z·tan θ at azimuth a).

    Per tooth k (centre 2πk/z), counter-clockwise: [radial −] flank − (root → tip), tip arc,
    flank + (tip → root), [radial +], root arc to tooth k+1. Flanks carry ``flank_points``
    points uniform in roll angle; consecutive segments share their end points exactly.
    ``sector``: only tooth 0, from the axis point along azimuth −π/z to the root circle, half a
    root arc, the tooth, half a root arc to azimuth +π/z and back to the axis point.
    """
    if z_plane <= 0:
        raise ValueError("z_plane must be > 0 (in front of the apex)")
    db = spec.base_angle_rad
    radial = spec.root_angle_rad < db
    polar = np.arccos(np.cos(db) * np.cos(_involute_rolls(spec, flank_points) * math.sin(db)))
    az_minus = flank_azimuth(spec, polar, -1)
    rho = z_plane * np.tan(polar)
    rho_root = z_plane * math.tan(spec.root_angle_rad)
    rho_tip = rho[-1]
    az_root_minus = float(flank_azimuth(spec, spec.root_angle_rad, -1))
    az_tip = float(flank_azimuth(spec, spec.face_angle_rad, +1))

    def pol(r, a):
        a = np.asarray(a, float)
        return np.stack([r * np.cos(a), r * np.sin(a)], -1)

    def arc(r, a0, a1):
        return pol(r, np.array([a0, 0.5 * (a0 + a1), a1]))

    segs: list[ProfileSegment] = []
    pitch = spec.angular_pitch_rad
    if sector:
        half = pitch / 2
        segs.append(ProfileSegment("side", np.array([[0.0, 0.0], pol(rho_root, -half)])))
        segs.append(ProfileSegment("root", arc(rho_root, -half, az_root_minus)))
    for k in range(1 if sector else spec.teeth):
        g = k * pitch
        if radial:
            segs.append(ProfileSegment("radial",
                                       pol(np.array([rho_root, rho[0]]), g + az_minus[0])))
        segs.append(ProfileSegment("flank", pol(rho, g + az_minus)))
        segs.append(ProfileSegment("tip", arc(rho_tip, g - az_tip, g + az_tip)))
        segs.append(ProfileSegment("flank", pol(rho[::-1], g - az_minus[::-1])))
        if radial:
            segs.append(ProfileSegment("radial",
                                       pol(np.array([rho[0], rho_root]), g - az_minus[0])))
        if sector:
            segs.append(ProfileSegment("root", arc(rho_root, -az_root_minus, pitch / 2)))
            segs.append(ProfileSegment("side", np.array([pol(rho_root, pitch / 2), [0.0, 0.0]])))
        else:
            segs.append(ProfileSegment("root", arc(rho_root, g - az_root_minus,
                                                   g + pitch + az_root_minus)))
    # make shared end points bit-identical (the arcs were evaluated separately)
    fixed = []
    for i, seg in enumerate(segs):
        pts = seg.points.copy()
        prev = segs[i - 1].points
        pts[0] = prev[-1]
        fixed.append(ProfileSegment(seg.kind, pts))
    return SectionProfile(z_plane=z_plane, segments=tuple(fixed), teeth=spec.teeth)


# -- exact distance from the flank surface ----------------------------------------------
def minus_flank_signed(spec: BevelGearSpec, p: np.ndarray) -> np.ndarray:
    """Signed distance (mm, + outside the tooth) of points p (N, 3) from tooth 0's −flank,
    extended: the cone over the whole involute for θ ≥ δb, the meridian half-plane below.

    Exact: the normals of a spherical involute are the great circles tangent to the base
    circle, so the foot point's roll angle is φ = a' + acos(tan δb / tan θp) (a' the point's
    azimuth from the involute start) and the point lies on that great circle at arc σ from T,
    cos σ = cos θp / cos δb; the distance to the ruling is |p|·sin(σ − φ sin δb).
    """
    db = spec.base_angle_rad
    sb = math.sin(db)
    r = np.linalg.norm(p, axis=1)
    rho = np.hypot(p[:, 0], p[:, 1])
    theta = np.arctan2(rho, p[:, 2])
    start = float(flank_azimuth(spec, db, -1))  # azimuth of the involute's start (its base point)
    a = np.angle(np.exp(1j * (np.arctan2(p[:, 1], p[:, 0]) - start)))
    out = rho * np.sin(-a)  # below the base cone: distance to the meridian half-plane
    above = theta >= db
    th = theta[above]
    # β: angle at the pole between the point and T; cos β = tan δb / tan θ, written via
    # sin β = √(sin(θ−δb) sin(θ+δb)) / (sin θ cos δb) for precision near the base cone.
    root = np.sqrt(np.maximum(np.sin(th - db) * np.sin(th + db), 0.0))
    beta = np.arctan2(root / (np.sin(th) * math.cos(db)), math.tan(db) / np.tan(th))
    sigma = _rolled_arc(db, th)
    s = (a[above] + beta) * sb
    out[above] = r[above] * np.sin(sigma - s)
    return out


def flank_distance(spec: BevelGearSpec, points, side: int | None = None,
                   signed: bool = False) -> np.ndarray:
    """Exact distance (mm) of 3D points (N, 3), gear frame, from the nearest analytic flank.

    Candidates are the flanks (of ``side``, or both) of the nearest tooth and its two
    neighbours; the smallest |distance| wins. ``signed``: + outside the tooth material.
    """
    p = np.atleast_2d(np.asarray(points, dtype=float))
    pitch = spec.angular_pitch_rad
    k0 = np.round(np.arctan2(p[:, 1], p[:, 0]) / pitch)
    sides = (-1, 1) if side is None else (side,)
    best = np.full(len(p), np.inf)
    for dk in (-1, 0, 1):
        ang = -(k0 + dk) * pitch
        c, s = np.cos(ang), np.sin(ang)
        q = np.stack([c * p[:, 0] - s * p[:, 1], s * p[:, 0] + c * p[:, 1], p[:, 2]], -1)
        for sd in sides:
            qq = q if sd == -1 else q * np.array([1.0, -1.0, 1.0])
            d = minus_flank_signed(spec, qq)
            best = np.where(np.abs(d) < np.abs(best), d, best)
    return best if signed else np.abs(best)


# -- line of action, undercut, contact ratio --------------------------------------------
@dataclass(frozen=True)
class LineOfAction:
    """Contact along the great circle of action (plane of action through the apex), as arcs
    (rad, unit sphere) measured from this gear's base tangency point T.

    start/end: where this gear's flank enters/leaves contact (mate tip / own tip).
    start < 0 means the mate's tip reaches past T: involute interference (undercut).
    """

    start_arc: float
    pitch_arc: float
    end_arc: float
    base_pitch_arc: float
    form_arc: float

    @property
    def contact_ratio(self) -> float:
        return (self.end_arc - self.start_arc) / self.base_pitch_arc

    @property
    def interference_free(self) -> bool:
        """The mate's tip first touches this flank on its involute, above the form cone."""
        return self.start_arc >= self.form_arc

    def start_polar_rad(self, spec: BevelGearSpec) -> float:
        return math.acos(math.cos(spec.base_angle_rad) * math.cos(max(self.start_arc, 0.0)))


def line_of_action(spec: BevelGearSpec, mate: BevelGearSpec | None = None) -> LineOfAction:
    """Exact spherical path of contact: a point at arc s from T has cos θ = cos δb·cos s."""
    mate = mating_spec(spec) if mate is None else mate

    def arc(g: BevelGearSpec, polar: float) -> float:
        return float(_rolled_arc(g.base_angle_rad, np.float64(max(polar, g.base_angle_rad))))

    p1, p2 = arc(spec, spec.pitch_angle_rad), arc(mate, mate.pitch_angle_rad)
    return LineOfAction(
        start_arc=p1 + p2 - arc(mate, mate.face_angle_rad),
        pitch_arc=p1,
        end_arc=arc(spec, spec.face_angle_rad),
        base_pitch_arc=spec.angular_pitch_rad * math.sin(spec.base_angle_rad),
        form_arc=arc(spec, spec.form_angle_rad),
    )


# -- pair kinematics (theoretical mounting: common apex) --------------------------------
def mate_rotation(spec: BevelGearSpec, angle_rad: float, mate: BevelGearSpec | None = None
                  ) -> np.ndarray:
    """3×3 rotation R with p_this = R @ p_mate (both in their own body frames) for the pair
    mounted on a common apex, this gear turned by ``angle_rad`` about its axis and the mate by
    −angle·z/z_mate about its own.

    Mounting (fixed frame = this gear's frame at angle 0): the mate's axis is (sin Σ, 0, cos Σ);
    the pitch element (sin δ, 0, cos δ) lies at this gear's azimuth 0 (tooth 0's centre) and,
    at angle 0, at the mate's azimuth −π/z_mate (a tooth-space centre), so tooth 0 sits in a
    mate tooth space. The angular velocities differ by a vector along the pitch element (the
    pitch cones roll): ω_mate / ω = −sin δ / sin δ_mate = −z / z_mate.
    """
    mate = mating_spec(spec) if mate is None else mate
    sigma = math.radians(spec.shaft_angle_deg)
    d = spec.pitch_angle_rad
    axis = np.array([math.sin(sigma), 0.0, math.cos(sigma)])
    pitch = np.array([math.sin(d), 0.0, math.cos(d)])
    x_m = pitch - (pitch @ axis) * axis
    x_m /= np.linalg.norm(x_m)
    y_m = np.cross(axis, x_m)
    mount = np.stack([x_m, y_m, axis], axis=1)  # mate frame → this frame, mate at angle 0

    def rot_z(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])

    mate_angle = math.pi / mate.teeth - angle_rad * spec.teeth / mate.teeth
    return rot_z(-angle_rad) @ mount @ rot_z(mate_angle)
