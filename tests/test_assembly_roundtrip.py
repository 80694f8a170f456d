"""Round trips: a built-in mechanism's own STEP (its check's run folder) declared as an ``assembly``
gives the figures of its native check. The native runs are the session's shared template checks.

- The differential: one big gear and one small gear, their axes from the run's manifest, the
  ratio z_small / z_big, the big gear's play measured: the warm least play per side of the native
  check, within the pair's mesh bound.
- The steering: pinion and rack in power mode (rack travel = pitch radius × pinion angle) swept
  to the continuous-drive limit both ways: no interference, and contact within the steering's
  contact tolerance at every pose.
"""

from __future__ import annotations

import json
import math

import pytest

import gearcheck

pytestmark = pytest.mark.cad


def _manifest(run) -> dict:
    return json.loads((run.folder / "manifest.json").read_text())


def _joint(part: dict, kind: str) -> dict:
    motion = part["motion"]
    joint = {"part": part["name"], "kind": kind, "axis": motion["axis"]}
    if kind == "revolute":
        joint["point"] = motion["origin"]
    return joint


def test_the_differential_as_an_assembly_gives_its_warm_play(template_check, tmp_path):
    native = template_check("zhurong_differential")
    man = _manifest(native)
    parts = {p["name"]: p for p in man["parts"]}
    g = man["params"]["gears"]
    pitch = 360.0 / g["small_teeth"]
    data = {
        "mechanism": "assembly", "name": "differential_pair", "mesh_tol_mm": 0.005,  # coarser than the native's
        "assembly": {"step": str(native.folder / man["step"]["file"])},
        "part": [{"name": "big_gear_right", "material": "17-4PH"}, {"name": "small_gear_front", "material": "17-4PH"}],
        "joint": [_joint(parts["big_gear_right"], "revolute"), _joint(parts["small_gear_front"], "revolute")],
        # the side gear follows the planet gear (opposite sense about these axes)
        "couple": [{"driver": "small_gear_front", "driven": "big_gear_right", "ratio": -g["small_teeth"] / g["big_teeth"]}],
        "motion": {"part": "small_gear_front", "start_deg": 0.0, "end_deg": pitch, "step_deg": pitch / 12},
        "play": {"part": "big_gear_right", "limit_deg": 1.0},
        "require": [{"parts": ["big_gear_right", "small_gear_front"], "min_clearance_mm": 0.0}],
    }
    run = gearcheck.load(data).check(out=tmp_path / "run", jobs=2)
    s = run.summary["assembly"]
    mine = s["play_min_deg"] * 60.0
    theirs = native.summary["differential"]["geom_play_min_arcmin_at_warm"]
    # both within their meshes' bounds of the true play: the native's bound (as an angle) and this
    # pair's, as an angle on the same radius (the native's bound in mm over its arcmin)
    native_bound = native.summary["differential"]["mesh_error_bound_arcmin"]
    mm_per_arcmin = native.summary["differential"]["mesh_error_bound_mm"] / native_bound
    bound = native_bound + s["pairs"]["big_gear_right__small_gear_front"]["mesh_error_bound_mm"] / mm_per_arcmin
    assert abs(mine - theirs) <= bound, (mine, theirs, bound)
    assert run.passed
    # the play is the same both ways: the coupling has the gears' own sense and ratio
    state = s["play"]["as_built"]
    assert state["play_plus_min_deg"] == pytest.approx(state["play_minus_min_deg"], abs=0.1 * state["play_min_deg"])


def test_the_steering_as_an_assembly_drives_in_contact_to_the_continuous_limit(template_check, tmp_path):
    native = template_check("nose_wheel_steering")
    man = _manifest(native)
    parts = {p["name"]: p for p in man["parts"]}
    pinion = man["params"]["pinion"]
    radius = pinion["module_mm"] * pinion["teeth"] / 2.0
    limit = native.summary["steering"]["continuous_drive_deg"]
    tol = native.summary["steering"]["contact_tolerance_mm"]
    data = {
        "mechanism": "assembly", "name": "steering_power",
        "assembly": {"step": str(native.folder / man["step"]["file"]), "contact_tolerance_mm": tol},
        "part": [{"name": "pinion"}, {"name": "rack"}],
        "joint": [_joint(parts["pinion"], "revolute"), _joint(parts["rack"], "prismatic")],
        "couple": [{"driver": "pinion", "driven": "rack", "mm_per_rad": radius}],
        "motion": {"part": "pinion", "start_deg": -math.floor(limit), "end_deg": math.floor(limit), "step_deg": 1.0},
        "require": [{"parts": ["pinion", "rack"], "contact": True}],
    }
    run = gearcheck.load(data).check(out=tmp_path / "run", jobs=2)
    s = run.summary["assembly"]
    pair = s["pairs"]["pinion__rack"]
    assert run.passed, [v.line() for v in run.verdicts]
    assert pair["touching_poses"] == s["poses"]  # in contact (≤ tolerance) at every pose
    assert pair.get("max_overlap_mm", 0.0) <= tol  # and never deeper
    assert pair["min_clearance_mm"] <= tol
