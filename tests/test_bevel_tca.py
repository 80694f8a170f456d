"""Tooth contact analysis of the differential's bevel pair: the aligned pair's TE is flat, the TE of
a misaligned pair agrees with an independent brute force (flank point clouds, nearest approach by
Newton steps on the other flank, the big gear's turn to first contact by bisection), the play is
TE_coast − TE_drive, and E/P/G/Σ read back from their displacements."""

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from gearcheck.design import load_template
from gearcheck.geometry import bevel_contact as bc
from gearcheck.geometry import bevel_play as bp
from gearcheck.geometry import bevel_tca as bt
from gearcheck.mechanisms.differential.poses import gear_specs


@pytest.fixture(scope="module")
def specs(templates_dir):
    return gear_specs(load_template(templates_dir / "zhurong_differential.toml").params)


def test_the_aligned_pair_runs_without_transmission_error(specs):
    """Conjugate spherical involutes on their design mounting: TE peak to peak ≤ 1e-7 rad on both
    flanks over two mesh cycles, the play the same at every drive angle."""
    te = bt.transmission_error(specs.big, specs.small)
    assert te.drive_angles_rad[-1] == pytest.approx(2 * specs.small.angular_pitch_rad)
    assert te.peak_to_peak("drive") <= 1e-7 and te.peak_to_peak("coast") <= 1e-7
    assert np.ptp(te.play_rad) <= 2e-7 and te.mean("coast") > 0 > te.mean("drive")


def test_the_play_is_coast_less_drive_the_play_solve(specs):
    """One model: TE_coast − TE_drive at each drive angle is the play the play solve gives there."""
    m = bt.Misalignment(big_axial_mm=0.02, offset_mm=0.01)
    te = bt.transmission_error(specs.big, specs.small, m, cycles=1, per_cycle=6)
    db, ds = m.displacements()
    cycle = bp.pair_play_over_cycle(specs.big, specs.small, te.drive_angles_rad, db, ds)
    np.testing.assert_allclose(te.play_rad, cycle.plus_rad - cycle.minus_rad, atol=1e-12)


@pytest.mark.parametrize("m", [bt.Misalignment(offset_mm=0.02, small_axial_mm=-0.01, big_axial_mm=0.03,
                                               shaft_angle_rad=math.radians(0.02))])
def test_e_p_g_sigma_read_back(m):
    got = bt.equivalent_misalignment(*m.displacements())
    assert got["offset_mm"] == pytest.approx(m.offset_mm, abs=1e-12)
    assert got["small_axial_mm"] == pytest.approx(m.small_axial_mm, abs=1e-12)
    assert got["big_axial_mm"] == pytest.approx(m.big_axial_mm, abs=1e-12)
    assert got["shaft_angle_rad"] == pytest.approx(m.shaft_angle_rad, abs=1e-12)
    assert got["tilt_rad"] == pytest.approx(0.0, abs=1e-12)


# ------------------------------------------------------------------------- the brute force

# A grid over each flank, and its four edges far denser: misaligned, the first contact is an edge of
# one gear against the other's face, between two edge samples (the gap along an edge is quadratic
# about it).
PROFILE, RULING, EDGE, TEETH = 24, 16, 240, range(-2, 3)


class _Flanks:
    """Side +1 flanks of a gear's teeth near the mesh as a point cloud (gear frame) with a KD-tree,
    and nearest approach to the surface by Newton steps on its two parameters."""

    def __init__(self, spec, scale=1.0):
        self.spec, self.scale = spec, scale
        u, v = np.meshgrid(np.linspace(0, 1, PROFILE), np.linspace(0, 1, RULING), indexing="ij")
        edge = np.linspace(0, 1, EDGE)
        u = np.concatenate([u.ravel(), edge, edge, np.zeros(EDGE), np.ones(EDGE)])
        v = np.concatenate([v.ravel(), np.zeros(EDGE), np.ones(EDGE), edge, edge])
        self.u = np.concatenate([u] * len(TEETH))
        self.v = np.concatenate([v] * len(TEETH))
        self.tooth = np.repeat(list(TEETH), u.size).astype(float)
        self.points = self.at(self.u, self.v, self.tooth)
        self.tree = cKDTree(self.points)

    def at(self, u, v, tooth):
        return np.stack(bc.flank_xyz(self.spec, self.scale, tooth, 1, u, v), axis=-1)

    def bounded(self, q):
        """Distance of points q (gear frame) to the flank bounded by its edges (the foot clamped to
        the flank's parameters), and whether the foot lies inside them."""
        u, v, t, inside = self._foot(q)
        return np.linalg.norm(q - self.at(u, v, t), axis=-1), inside

    def _foot(self, q):
        _, i = self.tree.query(q)
        u, v, t = self.u[i].copy(), self.v[i].copy(), self.tooth[i]
        h = 1e-6
        for _ in range(4):  # Newton on the foot of the perpendicular (clamped to the flank)
            s = self.at(u, v, t)
            su = (self.at(u + h, v, t) - self.at(u - h, v, t)) / (2 * h)
            sv = (self.at(u, v + h, t) - self.at(u, v - h, t)) / (2 * h)
            r = q - s
            a11, a12, a22 = (su * su).sum(-1), (su * sv).sum(-1), (sv * sv).sum(-1)
            b1, b2 = (r * su).sum(-1), (r * sv).sum(-1)
            det = a11 * a22 - a12 * a12
            u = u + (a22 * b1 - a12 * b2) / det
            v = v + (a11 * b2 - a12 * b1) / det
        inside = (u >= 0) & (u <= 1) & (v >= 0) & (v <= 1)
        return np.clip(u, 0, 1), np.clip(v, 0, 1), t, inside

    def signed(self, q):
        """Signed distance (+ outside the tooth, i.e. towards +azimuth of a side +1 flank) of points q
        (gear frame) to the flank surface, and whether the foot lies inside the flank's parameters."""
        u, v, t, inside = self._foot(q)
        h = 1e-6
        s = self.at(u, v, t)
        su = self.at(u + h, v, t) - self.at(u - h, v, t)
        sv = self.at(u, v + h, t) - self.at(u, v - h, t)
        n = np.cross(su, sv)
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        azimuthal = np.stack([-s[:, 1], s[:, 0], np.zeros(len(s))], axis=-1)
        n *= np.sign((n * azimuthal).sum(-1))[:, None]
        return ((q - s) * n).sum(-1), inside


def _world(pose, pts):
    return pts @ pose[:3, :3].T + pose[:3, 3]


def _local(pose, pts):
    return (pts - pose[:3, 3]) @ pose[:3, :3]


def _brute_plus(big_flanks, small_flanks, big, small, db, ds, phi):
    """The big gear's turn (from its conjugate pose) at first contact turning +: the least turn at
    which a flank point of either gear reaches the other's flank, by bisection."""
    small_pose = ds @ bp.nominal_small_pose(big, small) @ bp.rot_z4(phi)
    small_world = _world(small_pose, small_flanks.points)

    def gap(turn):
        big_pose = db @ bp.rot_z4(bp.conjugate_big_turn(big, small, phi) + turn)
        d1, in1 = big_flanks.signed(_local(big_pose, small_world))
        d2, in2 = small_flanks.signed(_local(small_pose, _world(big_pose, big_flanks.points)))
        return min(d1[in1].min(initial=np.inf), d2[in2].min(initial=np.inf))

    lo, hi = 0.0, 0.004
    assert gap(lo) > 0 > gap(hi)  # free at the conjugate turn (the backlash), overlapping at 0.004 rad
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("m", [bt.Misalignment(big_axial_mm=0.05), bt.Misalignment(offset_mm=0.05)],
                         ids=["G 50 µm", "E 50 µm"])
def test_the_te_of_a_misaligned_pair_agrees_with_brute_force(specs, m):
    big, small = specs.big, specs.small
    te = bt.transmission_error(big, small, m, cycles=1, per_cycle=3)
    db, ds = m.displacements()
    flanks = _Flanks(big), _Flanks(small)
    brute = np.array([-_brute_plus(*flanks, big, small, db, ds, phi) for phi in te.drive_angles_rad[:-1]])
    # the clouds lie on the same closed-form flanks, the solves share nothing. The brute force's points
    # are flank points, so its turn to contact is never short of the true one: the exact solve's TE is
    # at or above it, by no more than the clouds' spacing leaves (0.3 µrad: 0.5 % of G's TE p-p)
    lag = te.drive_rad[:-1] - brute
    assert np.all(lag >= -1e-10) and np.all(lag <= 3e-7), lag
    assert np.ptp(te.drive_rad) > 1e-5  # the misalignment shows in the TE


def test_the_check_reports_the_te_as_designed_and_per_mounting_error(specs):
    """summary.json ``tca``: flat as designed; each mounting error alone, at the size its figure is
    quoted per, moves the mean and (but for Σ, which keeps the spherical involutes conjugate about
    their common apex) the peak to peak; misaligned, the contact runs to an edge of the face."""
    from gearcheck.mechanisms.differential.tca import STEPS, tca_summary

    tca = tca_summary(specs)
    assert set(tca) == {"aligned", *STEPS}
    assert tca["aligned"]["drive_te_pp_urad"] <= 0.1 and tca["aligned"]["coast_te_pp_urad"] <= 0.1
    for name in ("E_10um", "P_10um", "G_10um"):
        assert tca[name]["drive_te_pp_urad"] > 1.0, name
        assert min(tca[name]["drive_contact_along_min"], 1 - tca[name]["drive_contact_along_max"]) < 0.01, name
    assert tca["sigma_0p01deg"]["drive_te_pp_urad"] <= 0.1
    assert tca["sigma_0p01deg"]["least_play_arcmin"] > tca["aligned"]["least_play_arcmin"]
    # the play is the gap between the flanks' TE means when the TE is flat
    a = tca["aligned"]
    assert a["least_play_arcmin"] == pytest.approx((a["coast_te_mean_urad"] - a["drive_te_mean_urad"]) * 1e-6
                                                   * 10800 / math.pi, abs=1e-4)


@pytest.mark.cad
def test_the_play_identity_holds_at_every_state_the_check_meshes(template_check):
    """summary.json ``tca.states``: each thermal state's mounting as E/P/G/Σ and its TE from the check's
    own exact solve, whose least TE_coast − TE_drive is the check's least play there (one model, to
    1e-4′); warm, the mounting is the shim alone (G)."""
    s = template_check("zhurong_differential").summary["differential"]
    states = s["tca"]["states"]
    assert {"warm", "cold"} <= set(states) <= set(s["states"])
    for name, st in states.items():
        assert st["least_play_arcmin"] == pytest.approx(s["states"][name]["exact_play_sampled_min_arcmin"],
                                                        abs=1e-4), name
    warm = states["warm"]
    assert warm["big_axial_mm"] == pytest.approx(s["template_shim_mm"], abs=1e-9)
    assert all(abs(warm[k]) < 1e-9 for k in ("offset_mm", "small_axial_mm", "shaft_angle_rad", "tilt_rad"))
    cold = states["cold"]
    assert cold["big_scale"] < 1.0 and cold["small_axial_mm"] < 0.0  # the cold gears shrink towards the apex


# ------------------------------------------------------------------------- the contact pattern

def test_the_pattern_gap_agrees_with_brute_force(specs):
    """The pattern's gap at one drive angle (the big gear turned to its first contact there) agrees
    with the brute force's nearest approach to the small gear's flank bounded by its edges (a point
    cloud, then Newton steps on its parameters, the foot clamped to the flank) over the whole band
    under 20 µm: to 1e-6 mm where the foot lies on the flank, to 2 % beyond its edges (there the
    pattern takes the distance to the edge to first order)."""
    big, small = specs.big, specs.small
    m = bt.Misalignment(big_axial_mm=0.05)
    mounting = bt.Mounting.of(m)
    te = bt.mounted_transmission_error(big, small, mounting, cycles=1, per_cycle=4)
    p = bt.contact_pattern(big, small, mounting, te, "drive", steps=1)  # at the first drive angle only
    b, s = mounting.placed(big, small, te.drive_angles_rad[0], -te.drive_rad[0])
    small_flanks = _Flanks(small)
    brute = np.full(p.gap_mm.shape, np.inf)
    t, u = np.meshgrid(p.height, p.along, indexing="ij")
    for tooth in range(-2, 3):
        pts = np.stack(bc.flank_xyz(big, 1.0, tooth, 1, t.ravel(), u.ravel()), axis=-1)
        d, inside = small_flanks.bounded(_local(s.pose, _world(b.pose, pts)))
        better = d.reshape(t.shape) < brute
        brute = np.where(better, d.reshape(t.shape), brute)
        on_flank = np.where(better, inside.reshape(t.shape), on_flank) if tooth > -2 else inside.reshape(t.shape)
    near = p.gap_mm < 0.02
    assert (near & on_flank).sum() > 50 and (near & ~on_flank).sum() > 10  # a band on the flank and beyond
    np.testing.assert_allclose(p.gap_mm[near & on_flank], brute[near & on_flank], atol=1e-6)
    np.testing.assert_allclose(p.gap_mm[near & ~on_flank], brute[near & ~on_flank], rtol=0.02, atol=1e-6)
    assert p.gap_mm.min() < 1e-4  # touching at the contact


def test_the_contact_path_lies_in_the_pattern(specs):
    """Every first contact of the TE solve that the big gear's flank makes with its face or its
    edges lies in the marked pattern (the nearest grid point's gap under the compound), on each
    flank, aligned and misaligned. (Where an edge of the small gear bears on the big gear's face,
    the mark is a stripe a few µm wide along that edge, narrower than the grid: the map's rings
    show those contacts.) Misaligned by G the pattern leaves the toe and moves toward the heel;
    aligned it bears from toe to heel."""
    big, small = specs.big, specs.small
    checked = 0
    for m in (bt.Misalignment(), bt.Misalignment(big_axial_mm=0.05), bt.Misalignment(offset_mm=0.03)):
        mounting = bt.Mounting.of(m)
        te = bt.mounted_transmission_error(big, small, mounting, cycles=1, per_cycle=8)
        bigs, smalls = zip(*(mounting.placed(big, small, phi) for phi in te.drive_angles_rad), strict=True)
        both = bp.big_gear_contacts_both(bigs, smalls)
        for flank, along, height, way in (("drive", te.drive_along, te.drive_height, both[0]),
                                          ("coast", te.coast_along, te.coast_height, both[1])):
            p = bt.contact_pattern(big, small, mounting, te, flank)
            on_big = np.array([c.on == "big" for c in way])
            i = np.abs(p.height[:, None] - height[None, :]).argmin(axis=0)
            j = np.abs(p.along[:, None] - along[None, :]).argmin(axis=0)
            assert np.all(p.gap_mm[i, j][on_big] <= p.compound_mm), (m, flank, p.gap_mm[i, j])
            checked += int(on_big.sum())
    assert checked >= 20  # of the 54 contacts
    aligned = bt.Mounting.of()
    e = bt.contact_pattern(big, small, aligned, bt.mounted_transmission_error(big, small, aligned, 1, 8)).extent()
    assert e["toe"] and e["heel"] and e["along_max"] - e["along_min"] == 1.0
    shifted = bt.Mounting.of(bt.Misalignment(big_axial_mm=0.1))
    g = bt.contact_pattern(big, small, shifted, bt.mounted_transmission_error(big, small, shifted, 1, 8)).extent()
    assert g["heel"] and not g["toe"] and g["centre_along"] > e["centre_along"] + 0.1


def test_the_pattern_patch_lies_on_the_marked_flank(specs):
    """The painted patch: every vertex stands just outside a big gear's drive flank (lifted across
    the tooth by at most its lift, at least half of it), inside the tooth zone, on the teeth asked
    for, and only where the pattern is marked."""
    big, small = specs.big, specs.small
    mounting = bt.Mounting.of(bt.Misalignment(big_axial_mm=0.1))
    p = bt.contact_pattern(big, small, mounting, bt.mounted_transmission_error(big, small, mounting, 1, 8))
    lift = 0.004
    v, f = bt.pattern_patch(big, p, teeth=[0, 5], lift_mm=lift)
    assert len(f) and f.max() < len(v)
    x, y, z = (v[:, k].astype(float) for k in range(3))
    tooth = np.round(np.arctan2(y, x) / big.angular_pitch_rad - 0.25)
    assert set(tooth.tolist()) == {0.0, 5.0}
    d = bc.signed_to_flank(big, x, y, z, tooth, 1.0)
    assert np.all((d > 0.5 * lift) & (d <= lift + 1e-6)), (d.min(), d.max())
    assert np.all(bc.in_tooth_zone(big, 1.0, x, y, z, tol=1e-4, along_tol=1e-3))
    # only marked cells: the patch stays toward the heel, as the pattern does (toe clear under G)
    along = (np.sqrt(x * x + y * y) * math.sin(big.pitch_angle_rad) + z * math.cos(big.pitch_angle_rad)
             - big.inner_cone_distance_mm) / (big.outer_cone_distance_mm - big.inner_cone_distance_mm)
    assert along.min() >= p.extent()["along_min"] - 1e-3


@pytest.mark.cad
def test_the_check_maps_the_pattern_warm_and_cold(template_check):
    """summary.json ``tca.patterns``: warm (the shim's G alone) the pattern bears toward the heel
    with the toe clear; cold it moves toward the toe and reaches it; on the involute throughout.
    The template's requirement is a verdict, and the report maps the patterns and paints them."""
    run = template_check("zhurong_differential")
    s = run.summary["differential"]
    patterns = s["tca"]["patterns"]
    assert {"aligned", "warm", "cold"} <= set(patterns) and patterns["compound_um"] == 6.0
    warm, cold = patterns["warm"]["drive"], patterns["cold"]["drive"]
    assert warm["reaches_toe"] == 0.0 and warm["reaches_heel"] == 1.0
    assert cold["reaches_toe"] == 1.0 and cold["centre_along"] < warm["centre_along"] - 0.1
    assert all(p[f]["below_form"] == 0.0 for name, p in patterns.items() if name != "compound_um"
               for f in ("drive", "coast"))
    verdict = next(v for v in run.result.verdicts if v.name == "contact_pattern")
    least = min(patterns[n][f]["length"] for n in ("warm", "cold", "operating_min", "operating_max")
                for f in ("drive", "coast"))
    assert verdict.figures["least_length"] == pytest.approx(least, abs=1e-12)
    assert (verdict.level == "pass") == (least >= 0.5) and s["verdicts"]["contact_pattern"] == 1
    page = (run.folder / "report.html").read_text(encoding="utf-8")
    assert "Contact pattern, big gear drive flank, warm 25 °C" in page and "Transmission error of the coast" in page
    assert 'class="gc3d-paint"' in page and '"overlays":[{' in page


def test_the_mounting_study_samples_e_p_g_sigma_into_the_contact_analysis():
    """The shipped study of the pairs' mounting errors: each variant's exact figures are the tooth
    contact analysis of its own sampled E/P/G/Σ (the same function, run again on that variant),
    the errors move them, and the zero-error design reproduces the check's pattern figures to the
    study's coarser grid (1/28 of the face)."""
    import gearcheck
    from gearcheck.mechanisms.differential.poses import gear_specs
    from gearcheck.mechanisms.differential.tca import STUDY_KEYS, study_figures

    res = gearcheck.study("src/gearcheck/templates/studies/differential_mounting.toml", samples=6, exact=6, jobs=1,
                          check_worst=0)
    t = res.table.to_pydict()
    fields = ("tca.offset_mm", "tca.small_axial_mm", "tca.big_axial_mm", "tca.shaft_angle_deg")
    i = 2
    one = gearcheck.load("templates/zhurong_differential.toml", {f: float(t[f"field.{f}"][i]) for f in fields})
    again = study_figures(one.params, gear_specs(one.params))
    assert {k: t[f"contact.{k}"][i] for k in STUDY_KEYS} == pytest.approx(again, abs=1e-9)
    assert np.ptp(t["contact.te_pp_urad"]) > 1.0 and np.ptp(t["contact.pattern_length"]) > 0.02
    design = gearcheck.load("templates/zhurong_differential.toml")
    own = study_figures(design.params, gear_specs(design.params))
    assert own["pattern_length"] == pytest.approx(0.554, abs=1 / 28)  # the check's least length (full grid)
    assert set(res.summary["failures"]) == {"pattern_short", "pattern_at_tip", "pattern_on_one_end",
                                            "te_over_300_urad"}


def test_the_api_returns_the_curves_as_arrays():
    """``Design.tca()``: the pair as designed and at each meshed state, as arrays — the same TE and
    patterns the check reports (its figures come from this function)."""
    import gearcheck
    from gearcheck.mechanisms.differential.tca import pattern_summary

    design = gearcheck.load("templates/zhurong_differential.toml")
    got = design.tca()
    assert list(got)[:3] == ["aligned", "warm", "cold"]
    warm = got["warm"]
    assert isinstance(warm.te.drive_rad, np.ndarray) and warm.te.drive_rad.shape == warm.te.drive_angles_rad.shape
    assert warm.patterns["drive"].gap_mm.shape == (bt.PATTERN_PROFILE, bt.PATTERN_RULING)
    assert np.ptp(got["aligned"].te.drive_rad) <= 1e-7 < np.ptp(warm.te.drive_rad)
    e = pattern_summary(warm.patterns["drive"])
    assert e["reaches_heel"] == 1.0 and e["reaches_toe"] == 0.0
    with pytest.raises(ValueError, match="no tooth contact analysis"):
        gearcheck.load("templates/assembly_spur_pair.toml").tca()
