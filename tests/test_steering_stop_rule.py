"""How high the trimmed corners S6 and S8 may stand is a design result, decided where the rack really
stands while the pinion's tip lands pass over the trimmed tops (src/gearcheck/mechanisms/steering/
ends.py, docs/steering.md "Trimmed tops past the stop"): a verdict of the check (exit 1), never a
rejection of the input (exit 2).

The reference here is a brute-force push written from scratch (no gearcheck geometry): the rack and
pinion drawn from the template's inputs, the pinion turned in small steps, the rack moved only by
what its flanks meet (a trimmed top never pushes the rack: docs/steering.md, "push model"), and every
pinion tooth near the trimmed end checked for overlap with the rack teeth at every step. Over a grid
of RS1 and hS6 the check's verdict on the trimmed ends must agree with it at every point, and so
must the stop (travel, angle, the corner pair that decides it) and the pick-up on the return swing.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from gearcheck.cli import main
from gearcheck.design import load_template
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import ends
from gearcheck.params import ParamError

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "nose_wheel_steering.toml"

# The grid: RS1 from below the equal-travel radius (84.207: S3 reaching S4 stops the rack, S1
# passing S2 leaves it standing until S3 picks it up) to above it (S1 at S2 stops it), and hS6
# from the machined 25.51 to the rack top. Every point lies at least 0.04 mm of hS6 from its limit.
RS1_GRID = (83.0, 83.3, 83.7, 84.294, 84.5)
HS6_GRID = (25.5, 25.75, 26.0, 26.25, 26.6, 27.0)
HS8_GRID = (26.5, 26.7, 26.85)  # at the template's RS1 (G1 stops the rack: S4 stands outside Ra)

# Brute force: pinion angle steps, points per flank and tip land, and its verdict thresholds
# (Euclidean depth of one part inside the other): clear below CLEAR_MM, caught above CAUGHT_MM, and
# no grid point may fall in between.
START_DEG = 59.0  # G1 and G2 both in conjugate drive (towing contact ratio 1.2 here)
END_DEG = 90.0  # the end teeth are clear of the tip lands by 83°
# Steps: STEP_DEG over FINE (S1 passes S2 from 71.3° on this grid, the stop and the usual pick-up
# lie between 73.8° and 76.7°), COARSE_DEG elsewhere.
STEP_DEG, COARSE_DEG, FINE = 0.025, 0.1, (70.5, 77.0)
POINTS = 60
CLEAR_MM, CAUGHT_MM = 1e-5, 1e-3
MOVED_MM = 1e-4  # the rack moved in a step (the tip land's chords make it creep by ≤ 0.07 µm)


# ----------------------------------------------------------------------------- the reference

@dataclass
class Drawing:
    """The template's rack and pinion from its inputs alone (profile shift 0)."""

    m: float
    z: int
    alpha: float
    ha: float
    H: float
    rack_ha: float
    rack_hf: float
    j1: int  # G1
    k1: int  # first rack tooth
    rs1: float
    hs2: float
    hs4: float
    hs6: float
    hs8: float
    _polar: dict = field(default_factory=dict, repr=False)

    @property
    def r(self) -> float:
        return self.m * self.z / 2.0

    @property
    def pitch(self) -> float:
        return math.pi * self.m

    def tip(self, j: int) -> float:
        return self.rs1 if j == self.j1 else self.r + self.ha * self.m

    def heights(self, k: int) -> tuple[float, float]:
        top = self.H - self.r + self.rack_ha * self.m
        return {self.k1: (self.hs2, self.hs6), self.k1 + 1: (self.hs4, self.hs8)}.get(k, (top, top))

    def half_width(self, y):
        return math.pi * self.m / 4.0 - (np.asarray(y) - (self.H - self.r)) * math.tan(self.alpha)

    def rack_tooth(self, k: int, travel: float) -> np.ndarray:
        """Counter-clockwise: bottom left, bottom right, top right, top left."""
        c = k * self.pitch + travel
        y0 = self.H - self.r - self.rack_hf * self.m
        hl, hr = self.heights(k)
        return np.array([[c - self.half_width(y0), y0], [c + self.half_width(y0), y0],
                         [c + self.half_width(hr), hr], [c - self.half_width(hl), hl]])

    def tooth_polar(self, j: int) -> tuple[np.ndarray, np.ndarray]:
        """Pinion tooth j above radius 79.9 (no rack point comes nearer the centre than H − top = 80),
        as (radius, polar angle from the tooth's centre line): its right flank out to the tip, the tip
        land, its left flank back in (clockwise seen with y up). Involute half angle
        β(ρ) = π/(2z) + inv α − inv α_ρ."""
        if j in self._polar:
            return self._polar[j]
        rb = self.r * math.cos(self.alpha)

        def inv(a):
            return np.tan(a) - a

        radii = np.linspace(79.9, self.tip(j), POINTS)
        beta = math.pi / (2 * self.z) + inv(self.alpha) - inv(np.arccos(rb / radii))
        land = np.linspace(beta[-1], -beta[-1], POINTS)[1:-1]
        rho = np.concatenate([radii, np.full(land.size, self.tip(j)), radii[::-1]])
        gam = np.concatenate([beta, land, -beta[::-1]])
        self._polar[j] = (rho, gam)
        return rho, gam

    def tooth(self, j: int, phi: float) -> np.ndarray:
        rho, gam = self.tooth_polar(j)
        a = gam + (j + 0.5) * 2 * math.pi / self.z + phi
        return np.stack([rho * np.sin(a), self.H - rho * np.cos(a)], axis=1)


def _drawing(overrides) -> Drawing:
    p = load_template(TEMPLATE, list(overrides)).params
    assert p.pinion.profile_shift == 0.0
    return Drawing(p.pinion.module_mm, p.pinion.teeth, math.radians(p.pinion.pressure_angle_deg),
                   p.pinion.addendum_coefficient, p.layout.centre_to_datum_mm, p.rack.addendum_coefficient,
                   p.rack.dedendum_coefficient, p.pinion.sector_first_tooth, p.rack.first_tooth,
                   p.pinion.topped_radius_mm, p.trim.hS2_mm, p.trim.hS4_mm, p.trim.hS6_mm, p.trim.hS8_mm)


def _flank_cut(poly: tuple[np.ndarray, ...], a: np.ndarray, b: np.ndarray, side: int) -> float:
    """How far the polygon (x, y of its points and of the next ones round it) reaches across the
    straight flank a→b (a below b) into the tooth, along x, where it cuts the flank: side +1 for a
    left flank (the tooth lies right of it), −1 for a right one. Its points between the flank's
    heights and its edges crossing the flank's top height; a polygon lying wholly on one side does
    not cut it (inside the tooth it overlaps it)."""
    x, y, nx, ny = poly
    band = (y >= a[1]) & (y <= b[1])
    t = (b[1] - y) / np.where(ny == y, np.inf, ny - y)
    cross = (t >= 0.0) & (t <= 1.0)
    if not (band.any() or cross.any()):
        return 0.0
    xs = np.concatenate([x[band], (x + t * (nx - x))[cross]])
    ys = np.concatenate([y[band], np.full(int(cross.sum()), b[1])])
    reach = side * (xs - (a[0] + (ys - a[1]) * (b[0] - a[0]) / (b[1] - a[1])))
    return float(reach.max()) if reach.min() < 0.0 < reach.max() else 0.0


def _depth_in(poly: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Per angle: the deepest of the points inside the convex counter-clockwise polygon (distance to
    its boundary), 0 when none is. ``poly`` (n, v, 2), ``points`` (n, p, 2)."""
    a, b = poly, np.roll(poly, -1, axis=1)
    edge = b - a
    normal = np.stack([-edge[..., 1], edge[..., 0]], axis=-1) / np.hypot(edge[..., 0], edge[..., 1])[..., None]
    inside = np.einsum("nej,npj->npe", normal, points) - np.einsum("nej,nej->ne", normal, a)[:, None, :]
    return np.maximum(inside.min(axis=2).max(axis=1), 0.0)


def _overlaps(d: Drawing, phis: np.ndarray, travel: np.ndarray) -> tuple[float, float, tuple[int, int] | None]:
    """Deepest overlap, over the angles, of a pinion tooth with a trimmed rack end tooth:
    pinion points inside the rack tooth, or rack corners inside the pinion tooth (a closed convex
    polygon too). Returns (depth, angle, pair)."""
    worst = (0.0, math.nan, None)
    for j in (d.j1, d.j1 + 1, d.j1 + 2):
        pts = np.stack([d.tooth(j, phi) for phi in phis])
        for k in (j, j + 1):
            if not d.k1 <= k <= d.k1 + 1:  # the trimmed end teeth
                continue
            rack = np.stack([d.rack_tooth(k, t) for t in travel])
            near = np.flatnonzero((pts[..., 0].max(axis=1) >= rack[..., 0].min(axis=1))
                                  & (pts[..., 0].min(axis=1) <= rack[..., 0].max(axis=1))
                                  & (pts[..., 1].min(axis=1) <= rack[..., 1].max(axis=1)))  # boxes meet
            if not near.size:
                continue
            depth = np.maximum(_depth_in(rack[near], pts[near]), _depth_in(pts[near, ::-1], rack[near]))
            i = int(np.argmax(depth))
            if depth[i] > worst[0]:
                worst = (float(depth[i]), math.degrees(phis[near[i]]), (j, k))
    return worst


@dataclass
class Swing:
    stop_deg: float
    stop_mm: float
    last_pusher: tuple[int, int]
    pickup_deg: float
    overlap_mm: float
    overlap_deg: float
    overlap_pair: tuple[int, int] | None


def _push(d: Drawing, phis: np.ndarray, travel: float, direction: int) -> tuple[np.ndarray, list]:
    """The rack at each angle, moved only as far as the flanks the pinion teeth cut push it: left
    flanks going out (+x: of rack tooth j + 1, whose space tooth j is in, or of the next one once it
    has passed over it), right flanks coming back (−x: of rack tooth j, or j + 1 once passed over)."""
    pairs = [(j, k) for j in (d.j1, d.j1 + 1, d.j1 + 2)
             for k in ((j + 1, j + 2) if direction > 0 else (j, j + 1)) if k >= d.k1]
    flank = {}  # at travel 0: (lower end, upper end)
    for _, k in pairs:
        bl, br, tr, tl = d.rack_tooth(k, 0.0)
        flank[k] = (bl, tl) if direction > 0 else (br, tr)
    out, pushed = [], []
    for phi in phis:
        teeth = {}
        for j in (d.j1, d.j1 + 1, d.j1 + 2):
            p = d.tooth(j, phi)
            x, y = p[:, 0], p[:, 1]
            teeth[j] = (x, y, np.append(x[1:], x[0]), np.append(y[1:], y[0]))
        for _ in range(4):
            shift = np.array([travel, 0.0])
            cut, pair = max((_flank_cut(teeth[j], flank[k][0] + shift, flank[k][1] + shift, direction), (j, k))
                            for j, k in pairs)
            if cut <= 1e-9:
                break
            travel += direction * cut
            pushed.append((float(phi), pair))
        out.append(travel)
    return np.array(out), pushed


def brute_force(overrides) -> Swing:
    """The towing swing out to END_DEG and back."""
    d = _drawing(overrides)
    phis = np.radians(np.unique(np.round(np.concatenate([
        np.arange(START_DEG, FINE[0], COARSE_DEG), np.arange(*FINE, STEP_DEG),
        np.arange(FINE[1], END_DEG + COARSE_DEG / 2, COARSE_DEG)]), 9)))
    out, pushed = _push(d, phis, d.r * phis[0] - 0.05, +1)  # the teeth bring it into the conjugate position
    assert abs(out[0] - d.r * phis[0]) < 1e-3  # conjugate drive at the start: L = r·φ
    moving = np.flatnonzero(np.diff(out) > MOVED_MM)
    stop = phis[moving[-1] + 1]
    last = max((p for p in pushed if p[0] <= stop + 1e-12), key=lambda p: p[0])[1]
    back, _ = _push(d, phis[::-1], float(out[-1]), -1)
    moved = np.flatnonzero(back < out[-1] - MOVED_MM)
    pickup = math.degrees(phis[::-1][moved[0]]) if moved.size else math.nan
    worst = max(_overlaps(d, phis, out), _overlaps(d, phis[::-1], back), key=lambda w: w[0])
    return Swing(math.degrees(stop), float(out[-1]), last, pickup, *worst)


# ----------------------------------------------------------------------------- gearcheck's side

def _gearcheck(overrides):
    g = an.geometry_from_params(load_template(TEMPLATE, list(overrides)).params)
    tow = an.analyse_towing(g, END_DEG)
    return g, tow, ends.end_tops(g, tow)


def _agree(overrides) -> tuple[bool, tuple[ends.EndTop, ...]]:
    g, tow, tops = _gearcheck(overrides)
    ref = brute_force(overrides)
    assert not CLEAR_MM < ref.overlap_mm < CAUGHT_MM, (overrides, ref.overlap_mm)  # no point on the fence
    passed = all(e.clears for e in tops)
    assert passed == (ref.overlap_mm <= CLEAR_MM), (overrides, ref, tops)
    # the stop, its corner pair and the pick-up, within the reference's step
    assert tow.travel_at_disengage_mm == pytest.approx(ref.stop_mm, abs=2e-3), overrides
    assert math.degrees(tow.disengage_rad) == pytest.approx(ref.stop_deg, abs=2 * STEP_DEG), overrides
    assert tow.last_pusher == ref.last_pusher, overrides
    step = STEP_DEG if FINE[0] <= ref.pickup_deg <= FINE[1] else COARSE_DEG
    assert math.degrees(tow.reengage_rad) == pytest.approx(ref.pickup_deg, abs=step + 1e-6), overrides
    if not passed:  # the brute force finds the same tooth caught
        caught = {(g.sector_first_tooth, g.rack_first_tooth) if e.tooth == "G1"
                  else (g.sector_first_tooth + 1, g.rack_first_tooth + 1) for e in tops if not e.clears}
        assert ref.overlap_pair in caught, (overrides, ref.overlap_pair, caught)
    return passed, tops


@pytest.mark.parametrize("rs1", RS1_GRID)
def test_trimmed_top_verdict_agrees_with_a_brute_force_push(rs1):
    """For each RS1, every hS6 of the grid: accepted as input, and the check's exact verdict on the
    trimmed ends is the brute force's; the verdicts flip once, at the limit the rule gives."""
    verdicts = []
    for hs6 in HS6_GRID:
        overrides = [f"pinion.topped_radius_mm={rs1}", f"trim.hS6_mm={hs6}"]
        passed, (s6, _) = _agree(overrides)
        assert passed == (hs6 <= s6.limit_mm)
        verdicts.append(passed)
    assert verdicts == sorted(verdicts, reverse=True) and verdicts[0] and not verdicts[-1]


@pytest.mark.parametrize("hs8", HS8_GRID)
def test_s8_verdict_agrees_with_a_brute_force_push(hs8):
    """The S4–S8 top at the template's RS1: G1 stops the rack with S4 0.135 mm outside G2's tip circle,
    so hS8 may rise to 26.775, above the 26.561 of the tangent at S4 on it."""
    passed, _ = _agree([f"trim.hS8_mm={hs8}"])
    assert passed == (hs8 <= 26.775)


def test_corners_above_the_rack_tooth_top_stay_bad_input():
    """No design has a trimmed corner above the tooth it is cut from: that stays exit 2."""
    for name in ("hS6", "hS8"):
        with pytest.raises(ParamError) as info:
            load_template(TEMPLATE, [f"trim.{name}_mm=27.2"])
        assert info.value.field == f"trim.{name}_mm" and "at most the rack tooth top" in str(info.value)


# ----------------------------------------------------------------------------- the rule itself

def test_template_limits_are_the_tangents_at_the_stop():
    """The paper's design: S1 stops the rack at S2 (110.182 mm), S2 on the RS1 circle, so the hS6 limit
    is the paper's tangent construction (calc's hS6_max, 26.075); S4 stands outside the tip circle there
    and hS8 may rise to 26.775."""
    g, tow, (s6, s8) = _gearcheck([])
    assert s6.clears and s8.clears
    assert s6.stand.why == "S1 passes S2" and s6.stand.final and s6.on_circle
    assert s6.limit_mm == pytest.approx(26.0752, abs=1e-4)
    assert s8.corner_gap_mm == pytest.approx(0.135, abs=1e-3) and s8.limit_mm == pytest.approx(26.775, abs=1e-3)
    calc = {f.key: f.value for f in load_template(TEMPLATE).calc().figures}
    assert s6.limit_mm == pytest.approx(calc["hS6_max_mm"], abs=1e-9)


def test_below_equal_travel_the_rack_stands_where_S1_passes_S2():
    """RS1 83.3: S1 passes S2 at 72.556° and the rack stands at 105.482 mm (S2 on the RS1 circle) until
    S3 picks it up at 72.881°; it stops for good at 109.816 mm when S3 reaches S4. The tip land sweeps
    over the S2–S6 top while the rack stands, so the tangent at S2 there (25.872) is the limit, not the
    top against the circle at the final stop (26.98, S2 0.907 mm outside it)."""
    g, tow, (s6, _) = _gearcheck(["pinion.topped_radius_mm=83.3", "trim.hS6_mm=26.2"])
    first, final = ends.stands(g, tow)
    assert first.why == "S1 passes S2" and not first.final
    assert (first.start_deg, first.end_deg, first.travel_mm) == pytest.approx((72.556, 72.881, 105.4815), abs=1e-3)
    assert final.why == "S3 passes S4" and final.final and final.travel_mm == pytest.approx(109.8158, abs=1e-4)
    assert ends._corner_gap(g, g.sector_first_tooth, g.rack_first_tooth, final.travel_mm) == pytest.approx(
        0.907, abs=1e-3)
    assert ends._stand_limit(g, g.sector_first_tooth, g.rack_first_tooth, final) == pytest.approx(26.98, abs=0.01)
    assert s6.stand == first and s6.limit_mm == pytest.approx(25.8717, abs=1e-4) and not s6.clears
    assert s6.overlap_mm == pytest.approx(0.136, abs=1e-3) and s6.overlap_swing == "forward"


def test_the_stand_at_RS1_83_3_by_hand():
    """The stand that decides RS1 83.3 / hS6 26.2, from the template's inputs with a pocket calculator's
    formulas: a pinion tip corner at radius R and polar angle γ = (j + ½)τ + φ + β(R) (β the involute
    half angle) pushing a straight rack flank puts the rack at L = x − k·p + w(y), w(y) = p/4 − (y − h)·tan α
    the half width at height y (h the rolling line). When G1's corner S1 (R = RS1) reaches S2's height
    the rack is at 105.482 mm and G2's corner S3 (R = Ra) would hold it only at 105.07: 0.40 mm short, so
    nothing carries the rack while G1's tip land passes over the S2–S6 top, and the top must clear the
    RS1 circle there. That circle's tangent at S2 rises 0.187 mm per mm; the top to hS6 = 26.2 rises
    0.28 mm per mm, so S1 meets it at once."""
    m, z, alpha, H, rs1, ra, hs2, hs6 = 4.0, 42, math.radians(25.0), 107.0, 83.3, 88.0, 25.13, 26.2
    r, p, tau = m * z / 2.0, math.pi * m, 2.0 * math.pi / z
    h = H - r
    rb = r * math.cos(alpha)

    def inv(a: float) -> float:
        return math.tan(a) - a

    def corner(j: int, radius: float, phi: float) -> tuple[float, float]:
        beta = math.pi / (2 * z) + inv(alpha) - inv(math.acos(rb / radius))
        gamma = (j + 0.5) * tau + phi + beta
        return radius * math.sin(gamma), H - radius * math.cos(gamma)

    def travel(k: int, x: float, y: float) -> float:
        return x - k * p + p / 4.0 - (y - h) * math.tan(alpha)

    from scipy.optimize import brentq

    phi = brentq(lambda a: corner(-8, rs1, a)[1] - hs2, math.radians(70.0), math.radians(75.0))
    at_s2 = travel(-7, *corner(-8, rs1, phi))
    by_s3 = travel(-6, *corner(-7, ra, phi))
    assert math.degrees(phi) == pytest.approx(72.556, abs=1e-3) and at_s2 == pytest.approx(105.482, abs=1e-3)
    assert at_s2 - by_s3 == pytest.approx(0.404, abs=2e-3)
    x_s2 = corner(-8, rs1, phi)[0]
    tangent_slope = x_s2 / (H - hs2)  # the RS1 circle's slope at S2 (its radius there is perpendicular)
    half = (p / 4.0 - (hs2 - h) * math.tan(alpha), p / 4.0 - (hs6 - h) * math.tan(alpha))
    top_slope = (hs6 - hs2) / (half[0] + half[1])
    assert tangent_slope == pytest.approx(0.187, abs=1e-3) and top_slope == pytest.approx(0.282, abs=1e-3)
    g, tow, (s6, _) = _gearcheck(["pinion.topped_radius_mm=83.3", "trim.hS6_mm=26.2"])
    assert ends.stands(g, tow)[0].travel_mm == pytest.approx(at_s2, abs=1e-4)


# ----------------------------------------------------------------------------- the check

@pytest.mark.cad
@pytest.mark.parametrize("overrides, words, also", [
    (["pinion.topped_radius_mm=83.3", "trim.hS6_mm=26.2"],
     ["up to hS6 = 25.872 mm: S1 passes S2 at 72.556° and the rack stands at 105.482 mm until it is picked up "
      "again at 72.881°, with S2 on G1's RS1 circle", "G1 cuts 0.1360 mm into the first rack tooth at +72.850°"], set()),
    # the rack stops for good: G1's tip land sweeps the top again on the way back (the mesh's overlap there,
    # 0.019 mm, lies within its contact tolerance; the exact model certifies 0.0176 mm)
    (["trim.hS6_mm=26.15"],
     ["up to hS6 = 26.075 mm: S1 passes S2 at 76.011° and the rack stops there for good at 110.182 mm",
      "G1 cuts 0.0684 mm into the first rack tooth at +77.550°"], {"no_interference_reengage"}),
])
def test_a_top_the_tip_land_catches_fails_the_check_not_the_input(tmp_path, capsys, overrides, words, also):
    """Both designs were refused as bad input (exit 2) before; they are designs that fail (exit 1):
    the interference verdicts fail, decided by the exact model, with the limit, where the rack stands
    and the overlap; every other design verdict passes."""
    args = ["check", str(TEMPLATE), "--out", str(tmp_path / "run"), "--jobs", "2"]
    for o in overrides:
        args += ["--set", o]
    assert main(args) == 1
    s = json.loads((tmp_path / "run" / "summary.json").read_text())["steering"]
    failed = {name for name, ok in s["verdicts"].items() if not ok}
    assert failed == {"no_interference_past_disengage", "no_interference_anywhere"} | also
    assert all(s["verdict_evidence"][name].startswith("exact model") for name in failed)
    assert s["certified"]["anywhere"]["certified_min_mm"] < -0.01  # the exact model over the continuous motion
    # where the mesh sweep found the pinion in the rack deeper than the contact tolerance, that pose is
    # confirmed on the exact solids: they overlap there, by a volume (RS1 83.3: the rack stands at
    # 105.482 mm while G1's tip land comes over the top; hS6 26.15: the meshed top drags the rack on)
    if s["min_signed_clearance_mm"] < -s["contact_tolerance_mm"]:
        deepest = s["exact_confirmation"]["deepest_overlap_of_the_sweep"]
        assert deepest["contact"] == "overlapping" and deepest["overlap_mm3"] > 1e-3 and deepest["agrees"] == 1.0
    else:
        assert "deepest_overlap_of_the_sweep" not in s["exact_confirmation"]
    assert (s["min_signed_clearance_mm"] < -s["contact_tolerance_mm"]) == ("83.3" in " ".join(overrides))
    out = " ".join(" ".join(s["verdict_measured"][name] for name in failed).split())  # the whole sentences
    for w in words:
        assert w in out, w
    shown = capsys.readouterr().out  # the terminal: one line each, the shortfall
    assert "FAIL  towing: no interference past the disengage" in shown and "hS6 = 26." in shown
