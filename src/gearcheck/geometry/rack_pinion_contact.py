"""Exact conjugate contact intervals of every tooth pair of the trimmed rack and pinion, and the
continuous drive they give through every hand-over (towing and power mode), numpy only.

A pair's contact runs along its line of action between the first and the last point at which
both flanks exist: the rack flank between its root line and its (trimmed) top corner, the
pinion involute between its form circle and its (topped) tip circle. Each end is converted to
the pinion angle of conjugate mesh (φ = L/r). The drive is continuous from angle 0 as long as
the next pair starts before every earlier one has ended; the first gap, or the end of the last
pair, is the limit, named by the event that decides it.

Frame, angle 0 and tooth numbering: :mod:`gearcheck.geometry.rack_pinion` (φ > 0: the first rack
tooth comes under the pinion; the other direction is the mirror image).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gearcheck.geometry.rack_pinion import RackPinionGeometry

MODES = ("towing", "power")


@dataclass(frozen=True)
class PairContact:
    """Conjugate contact of one tooth pair: pinion tooth j against rack tooth k, from φ start to
    φ end (rad), with what starts and ends it. Empty when start ≥ end."""

    mode: str
    j: int
    k: int
    start_rad: float
    end_rad: float
    start_by: str
    end_by: str

    @property
    def empty(self) -> bool:
        return not self.end_rad > self.start_rad


@dataclass(frozen=True)
class ContinuousDrive:
    """Where unbroken conjugate drive from angle 0 ends in one mode, and why."""

    mode: str
    angle_rad: float
    event: str  # e.g. "towing: G1's conjugate contact ends (at S1, its tip corner)"
    gap_rad: tuple[float, float] | None  # (last contact ends, next begins) when a hand-over gap decides it
    pairs: tuple[PairContact, ...]
    # every hand-over on the way, (the earlier pair's contact ends, the next one's begins), the gap last
    handovers: tuple[tuple[float, float], ...] = ()

    @property
    def angle_deg(self) -> float:
        return math.degrees(self.angle_rad)


def pinion_name(g: RackPinionGeometry, j: int) -> str:
    """G1, G2, … from the topped end tooth (j = sector first) inwards; the mirror side: j = …"""
    n = j - g.sector_first_tooth + 1
    return f"G{n}" if n <= (g.sector_last_tooth - g.sector_first_tooth) // 2 + 1 else f"pinion tooth j = {j}"


def rack_corner_name(g: RackPinionGeometry, k: int, side: int) -> str:
    """S2/S4 (left, side −1) and S6/S8 (right, side +1) on the two end teeth, else a plain name."""
    first = g.rack_first_tooth
    names = {(first, -1): "S2", (first + 1, -1): "S4", (first, +1): "S6", (first + 1, +1): "S8"}
    return names.get((k, side), f"the {'left' if side < 0 else 'right'} top corner of rack tooth k = {k}")


def pinion_corner_name(g: RackPinionGeometry, j: int) -> str:
    names = {g.sector_first_tooth: "S1", g.sector_first_tooth + 1: "S3"}
    tip = f"{pinion_name(g, j)}'s tip corner"
    return f"{names[j]}, {tip}" if j in names else tip


def pair_contact(g: RackPinionGeometry, mode: str, j: int, k: int) -> PairContact:
    """Exact conjugate contact interval of pinion tooth j and rack tooth k. Towing (k = j + 1):
    the pinion's right flank pushes the rack's left flank, line of action through P = (0, h) along
    (cos α, −sin α); power (k = j): the rack's right flank pushes the pinion's left flank, along
    (cos α, sin α). A point at t on it lies at radius √(rb² + (r sin α ± t)²) from the centre.
    h = H + Δa − r: the line of action is fixed to the pinion, so φ(t) is the pinion's alone and
    a centre-distance error moves only where the rack's root and top corners meet it."""
    a = g.pressure_angle_rad
    sa, ca = math.sin(a), math.cos(a)
    h, rb, r = g.rolling_line_height, g.base_radius, g.pitch_radius
    w0 = g.rack_half_thickness_at_rolling_line
    r_tip, r_form = g.pinion_tip_radius(j), max(g.form_radius, rb)
    root_t = (h - g.rack_root_height) / sa
    tip_t = math.sqrt(max(r_tip ** 2 - rb ** 2, 0.0)) - r * sa
    form_t = math.sqrt(max(r_form ** 2 - rb ** 2, 0.0)) - r * sa
    left, right = g.rack_corner_heights(k)
    if mode == "towing":
        starts = [(-(left - h) / sa, "rack_top"), (form_t, "pinion_form")]
        ends = [(tip_t, "pinion_tip"), (root_t, "rack_root")]
        sign = +1.0
    elif mode == "power":
        starts = [(-tip_t, "pinion_tip"), (-root_t, "rack_root")]
        ends = [((right - h) / sa, "rack_top"), (-form_t, "pinion_form")]
        sign = -1.0
    else:
        raise ValueError(f"mode {mode!r} is not one of {MODES}")
    t0, by0 = max(starts)
    t1, by1 = min(ends)

    def phi(t: float) -> float:
        return (t / ca - k * g.pitch + sign * w0) / r

    return PairContact(mode, j, k, phi(t0), phi(t1), end_name(g, mode, j, k, by0), end_name(g, mode, j, k, by1))


def end_name(g: RackPinionGeometry, mode: str, j: int, k: int, which: str) -> str:
    """How a pair's conjugate contact starts or ends, by the flank end that decides it (``which``:
    "rack_top", "rack_root", "pinion_tip" or "pinion_form"), e.g. "at S2", "at S1, G1's tip corner"."""
    gname = pinion_name(g, j)
    names = {
        "rack_top": f"at {rack_corner_name(g, k, -1 if mode == 'towing' else +1)}",
        "rack_root": "at the rack root",
        "pinion_tip": f"at {pinion_corner_name(g, j)}" if mode == "towing" else f"at {gname}'s tip corner",
        "pinion_form": f"on {gname}'s form circle",
    }
    return names[which]


def pair_contacts(g: RackPinionGeometry, mode: str) -> list[PairContact]:
    """Every pair that can mesh in the φ > 0 direction, in the order they engage (decreasing j)."""
    offset = 1 if mode == "towing" else 0
    out = []
    for j in range(g.sector_last_tooth, g.sector_first_tooth - 1, -1):
        k = j + offset
        if g.rack_first_tooth <= k <= g.rack_last_tooth:
            out.append(pair_contact(g, mode, j, k))
    return out


def continuous_drive(g: RackPinionGeometry, mode: str, pairs: tuple[PairContact, ...] | None = None
                     ) -> ContinuousDrive:
    """Unbroken conjugate drive from angle 0 in ``mode``: the first hand-over gap, or the end of
    the last pair's contact. ``pairs``: the contact intervals (default: the exact ones of
    :func:`pair_contacts`; a mesh sweep passes the ones it measured)."""
    pairs = tuple(p for p in (pair_contacts(g, mode) if pairs is None else pairs) if not p.empty)
    live = [p for p in pairs if p.start_rad <= 0.0 <= p.end_rad]
    if not live:
        return ContinuousDrive(mode, 0.0, f"{mode}: no tooth pair in contact at angle 0", None, pairs)
    cur = max(live, key=lambda p: p.end_rad)
    handovers: list[tuple[float, float]] = []
    for p in sorted(pairs, key=lambda p: (p.start_rad, -p.j)):
        if p.end_rad <= cur.end_rad:
            continue
        handovers.append((cur.end_rad, p.start_rad))
        if p.start_rad > cur.end_rad:
            a, b = math.degrees(cur.end_rad), math.degrees(p.start_rad)
            event = (f"{mode}: hand-over gap {pinion_name(g, cur.j)}→{pinion_name(g, p.j)} "
                     f"{a:.3f}°–{b:.3f}° ({pinion_name(g, cur.j)}'s contact ends {cur.end_by}, "
                     f"{pinion_name(g, p.j)}'s begins {p.start_by})")
            return ContinuousDrive(mode, cur.end_rad, event, (cur.end_rad, p.start_rad), pairs, tuple(handovers))
        cur = p
    event = (f"{mode}: {pinion_name(g, cur.j)}'s conjugate contact ends at {math.degrees(cur.end_rad):.3f}° "
             f"({cur.end_by})")
    return ContinuousDrive(mode, cur.end_rad, event, None, pairs, tuple(handovers))


def whole_drive(g: RackPinionGeometry) -> tuple[ContinuousDrive, ContinuousDrive]:
    """(towing, power) continuous drive."""
    return continuous_drive(g, "towing"), continuous_drive(g, "power")


def stop_phrase(g: RackPinionGeometry, pusher: tuple[int, int] | None) -> str:
    """What happens past the towing stop, named by the pair that pushed last: "G1's tip land
    grazes S2" for the paper's design, "G2's tip land grazes S4" where G2's corner S3 decides the
    stop; without a stop, that the rack is still moving."""
    if pusher is None:
        return "the rack is still moving at the end of the swing"
    j, k = pusher
    return f"{pinion_name(g, j)}'s tip land grazes {rack_corner_name(g, k, -1)}"
