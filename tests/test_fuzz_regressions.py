"""Sets `make fuzz` found failing, kept as regression tests. Each set is written out
whole, so a change of the sampler cannot lose it.

* Differential, fuzz seed 100 (z 60/40, α 15.74°): the path of contact reaches 1.35 pitches from
  the pitch point, so the exact-flank play model's fixed window of ±2 teeth ended on the tooth
  in contact and raised. The window now follows the path of contact (teeth_window).
* Steering, fuzz seeds 2000084 and 2000091: steeply slanted trimmed tops. The push model let a
  slanted top drive the rack (the mesh sweep did not: its pusher faces were |n_x| > 0.5, its
  reach 1.5·r_tip per radian), so the towing curves parted by up to 78 mm. Both now apply one
  rule: only flanks push, at most r_tip / PUSH_NORMAL_MIN per radian; anything else jams.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest

from gearcheck.geometry import bevel_contact as bc
from gearcheck.geometry import bevel_play as bp
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.differential.poses import gear_specs
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.params import validate

DIFFERENTIAL_SEED_100 = {
    "gears": {"module_mm": 4.9685, "big_teeth": 60, "small_teeth": 40, "face_width_mm": 31.494,
              "pressure_angle_deg": 15.74, "shaft_angle_deg": 90.0, "small_profile_shift": 0.411},
    "backlash": {"mesh_thinning_min_mm": 0.0226, "mesh_thinning_max_mm": 0.0708},
    "materials": {"housing": "7A09 aluminium alloy", "housing_cte_per_K": 1.6662e-05,
                  "shaft": "TC4 titanium alloy (Ti-6Al-4V)", "shaft_cte_per_K": 4.813e-06,
                  "gear": "CF170 stainless steel (17-4PH class)", "gear_cte_per_K": 1.69e-07},
    "dimensions": {"a_mm": 313.78, "b_mm": 260.382, "l11_mm": 16.985, "l12_mm": 13.836, "l2_mm": 7.835},
    "operating": {"warm_C": 57.5, "cold_C": -61.3, "operating_min_C": -60.2, "operating_max_C": 16.1,
                  "storage_min_C": -11.7, "storage_max_C": 29.1},
    "shim": {"thickness_mm": 0.357, "study_mm": [0.13, 0.16, 0.35, 0.44]},
}

STEERING_SEED_2000091 = {  # S6 3 mm below S2: the first tooth's top slopes 36° (|n_x| 0.59)
    "pinion": {"module_mm": 3.713, "teeth": 26, "profile_shift": -0.353, "pressure_angle_deg": 22.41,
               "addendum_coefficient": 1.06, "dedendum_coefficient": 1.1, "sector_first_tooth": -6,
               "sector_last_tooth": 5, "topped_radius_mm": 47.1162},
    "rack": {"first_tooth": -5, "last_tooth": 5, "addendum_coefficient": 0.989, "dedendum_coefficient": 1.384},
    "layout": {"centre_to_datum_mm": 54.473},
    "trim": {"min_contact_ratio": 1.252, "hS2_mm": 11.0792, "hS4_mm": 11.1141, "hS6_mm": 8.0621, "hS8_mm": 9.7966},
    "targets": {"continuous_drive_deg": 16.52},
    "towing": {"max_angle_deg": 110.2},
}

STEERING_SEED_2000084 = {  # S2 2.8 mm above S4/S6: corner pushes faster than 1.5·r_tip per radian
    "pinion": {"module_mm": 8.868, "teeth": 25, "profile_shift": 0.183, "pressure_angle_deg": 18.92,
               "addendum_coefficient": 1.023, "dedendum_coefficient": 1.343, "sector_first_tooth": -5,
               "sector_last_tooth": 4, "topped_radius_mm": 114.039},
    "rack": {"first_tooth": -4, "last_tooth": 4, "addendum_coefficient": 1.051, "dedendum_coefficient": 1.21},
    "layout": {"centre_to_datum_mm": 160.631},
    "trim": {"min_contact_ratio": 1.091, "hS2_mm": 55.2, "hS4_mm": 52.3712, "hS6_mm": 51.7331, "hS8_mm": 53.3557},
    "targets": {"continuous_drive_deg": 14.97},
    "towing": {"max_angle_deg": 115.23},
}


def params_of(mech: str, body: dict):
    return validate(mechanism(mech).Params, body, f"{mech}-regression.toml")


# --- math layer (fast) -----------------------------------------------------------------------

def test_long_contact_path_widens_the_exact_play_window(monkeypatch):
    specs = gear_specs(params_of("differential", DIFFERENTIAL_SEED_100))
    assert bp.teeth_window(specs.big, specs.small) == 3  # path reaches 1.35 pitches → 2 + 1
    angles = np.linspace(0.0, specs.small.angular_pitch_rad, 4, endpoint=False)
    cycle = bp.pair_play_over_cycle(specs.big, specs.small, angles)
    # the same play with far more teeth sampled: the window misses no tooth that touches first
    monkeypatch.setattr(bc, "MIN_TEETH_WINDOW", 6)
    wide = bp.pair_play_over_cycle(specs.big, specs.small, angles)
    assert np.allclose(cycle.plus_rad, wide.plus_rad, atol=1e-12)
    assert np.allclose(cycle.minus_rad, wide.minus_rad, atol=1e-12)
    assert np.all(cycle.total_arcmin > 0.0)


def test_template_keeps_the_two_tooth_window(templates_dir):
    from gearcheck.design import load_template

    specs = gear_specs(load_template(templates_dir / "zhurong_differential.toml").params)
    assert bp.teeth_window(specs.big, specs.small) == 2  # path reaches 0.95 pitches


def test_a_slanted_top_never_pushes_the_rack():
    g = an.geometry_from_params(params_of("steering", STEERING_SEED_2000091))
    s2, s6 = g.trim_corners(0.0)["S2"], g.trim_corners(0.0)["S6"]
    slope = math.degrees(math.atan2(s2[1] - s6[1], s6[0] - s2[0]))
    assert slope > 30.0  # steeper than the push rule's 60° from the travel: would push if it could
    t = an.analyse_towing(g, 110.2)
    # the return swing meets the first tooth's top and jams: interference, never a push through it
    assert t.back.max_overlap_mm > 1.0
    jam = np.flatnonzero(t.back.jammed)[0]
    assert t.back.travel_mm[jam] == pytest.approx(t.forward.travel_mm[-1], abs=1e-9)
    # every push is bounded by the flank rule's rate
    assert t.forward.max_rate <= an.PUSH_RATE_PER_TIP_RADIUS * g.tip_radius * (1 + 1e-9)
    assert t.back.max_rate <= an.PUSH_RATE_PER_TIP_RADIUS * g.tip_radius * (1 + 1e-9)


def test_paper_figures_only_for_the_papers_design(templates_dir):
    from gearcheck.design import load_template
    from gearcheck.mechanisms.steering.report import paper_figures

    template = load_template(templates_dir / "nose_wheel_steering.toml").params
    other = params_of("steering", STEERING_SEED_2000084)
    assert paper_figures(template)["disengage_deg"] == an.PAPER["disengage_deg"]
    assert set(paper_figures(other).values()) == {None}
    # the calc table likewise: printed values beside the paper's design only
    calc = mechanism("steering").analyse
    assert sum(f.paper is not None for f in calc(template)) >= 10
    assert all(f.paper is None for f in calc(other))


# --- mesh sweep against the model (CAD) ------------------------------------------------------

def _swept(mech: str, body: dict, **kwargs):
    from gearcheck import pipeline
    from gearcheck.design import Design

    design = Design(None, mech, params_of(mech, body), {"mechanism": mech, "name": "regression", **body})
    with tempfile.TemporaryDirectory() as tmp:
        run = pipeline.build(design, Path(tmp), tol_mm=0.01)
    return pipeline.sweep(design, run.assembly, run.bodies, jobs=1, options=kwargs)


@pytest.mark.cad
def test_long_contact_path_mesh_play_agrees():
    result = _swept("differential", DIFFERENTIAL_SEED_100, angles_per_cycle=4, shims_mm=[0.357])
    verdicts = {v.name: v for v in result.verdicts}
    assert verdicts["mesh_agrees_with_exact"].passed, verdicts["mesh_agrees_with_exact"].measured


@pytest.mark.cad
@pytest.mark.parametrize("body, jams", [(STEERING_SEED_2000091, True), (STEERING_SEED_2000084, False)],
                         ids=["seed-2000091-steep-top-jams", "seed-2000084-fast-corner-push"])
def test_slanted_tops_mesh_towing_curve_agrees(body, jams):
    result = _swept("steering", body)
    verdicts = {v.name: v for v in result.verdicts}
    assert verdicts["mesh_agrees_with_exact"].passed, verdicts["mesh_agrees_with_exact"].measured
    # the jam is a design failure both ways agree on, shown as interference on the return swing
    assert verdicts["no_interference_reengage"].passed is (not jams), verdicts["no_interference_reengage"].measured
    # another design than the paper's: no printed figure is shown beside it as if it were a target
    assert all(c.paper is None for c in result.comparisons)
    assert not any("paper" in label for plot in result.plots for label, x in plot.markers if x is not None)


@pytest.mark.parametrize("tol", [10**400, -(10**400), 10**30])
def test_a_whole_number_too_large_for_a_float_is_one_line(tol):
    """Fuzz (the loader's hypothesis run): mesh_tol_mm = a 400-digit integer raised OverflowError
    from math.isfinite; it is out of range, one line naming the field."""
    from gearcheck.design import from_data
    from gearcheck.params import ParamError

    with pytest.raises(ParamError, match=r"mesh_tol_mm = .*out of range: allowed"):
        from_data({"mechanism": "assembly", "name": "x", "mesh_tol_mm": tol})
