"""Clearance certified over the continuous motion (gearcheck.sweep.certify): a lower bound between
samples from the ends' clearances and the largest displacement, refined where it does not decide.
The case of a minimum between two samples: sampled, the requirement passes; certified, the true
figure is found and it fails."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.sweep.certify import arc_displacement, certify, interval_bound

RADIUS = 5.0  # a fixed disc at the origin; a point moves along the line y = H past it
H = 5.2


def clearance(x: float) -> float:
    return math.hypot(x, H) - RADIUS


def test_the_interval_bound_is_a_lower_bound():
    rng = np.random.default_rng(3)
    for _ in range(2000):
        x0, x1 = sorted(rng.uniform(-20, 20, 2))
        inside = np.linspace(x0, x1, 101)
        true = min(clearance(float(x)) for x in inside)
        bound = interval_bound(clearance(x0), clearance(x1), abs(x1 - x0))  # a translation: δ = |Δx|
        assert bound <= true + 1e-12


def test_a_minimum_between_two_samples_is_caught():
    xs = [-3.0, 3.0]  # the closest approach (x = 0: 0.2 mm) lies between the two samples
    cs = [clearance(x) for x in xs]
    requirement = 0.5
    assert min(cs) > requirement  # sampled: a pass
    calls = []

    def measure(x: float) -> float:
        calls.append(x)
        return clearance(x)

    cert = certify(xs, cs, measure, lambda a, b: abs(b - a), requirement, resolution=1e-4)
    assert not cert.passed and cert.sampled_min == pytest.approx(0.2, abs=1e-9)  # the true figure, a fail
    assert cert.certified_min <= 0.2 and cert.refined == len(calls) > 0
    assert cert.at[0] <= 0.0 <= cert.at[1] or min(abs(cert.at[0]), abs(cert.at[1])) < 1e-6


def test_a_clear_motion_is_certified_with_few_measurements():
    xs = list(np.linspace(-20, 20, 41))
    cs = [clearance(x) for x in xs]
    cert = certify(xs, cs, clearance, lambda a, b: abs(b - a), 0.1, resolution=1e-4)
    assert cert.passed and cert.decides
    assert 0.1 <= cert.certified_min <= 0.2 and cert.refined < 40


def test_a_requirement_met_only_within_the_resolution_is_left_undecided():
    xs = [-1.0, 1.0]
    cs = [clearance(x) for x in xs]
    cert = certify(xs, cs, clearance, lambda a, b: abs(b - a), 0.2, resolution=1e-3)
    assert cert.undecided and all(x1 - x0 <= 1e-3 for x0, x1, _ in cert.undecided)
    assert cert.certified_min == pytest.approx(0.2, abs=1e-3)


def test_a_turn_moves_a_point_by_its_arc():
    assert arc_displacement(10.0, 180.0) == pytest.approx(10 * math.pi)


def test_sharpening_brings_the_figure_to_the_true_least_clearance():
    xs = list(np.linspace(-20, 20, 9))  # 5 mm apart: the bound alone is far below the true 0.2 mm
    cs = [clearance(x) for x in xs]
    loose = certify(xs, cs, clearance, lambda a, b: abs(b - a), 0.0, resolution=1e-6)
    sharp = certify(xs, cs, clearance, lambda a, b: abs(b - a), 0.0, resolution=1e-6, precision=1e-4, sharpen=400)
    assert loose.passed and loose.certified_min < 0.1  # decided, but far below the true 0.2 mm
    assert sharp.certified_min <= 0.2 + 1e-12  # still a lower bound of the true least clearance ...
    assert sharp.certified_min == pytest.approx(0.2, abs=2e-3)  # ... and close to it
    assert loose.refined < sharp.refined <= loose.refined + 400


def _dip(x):
    x = np.asarray(x, float)
    return 1.0 - 0.3 * np.maximum(0.0, 1.0 - np.abs(np.mod(x, 1.0) - 0.37) / 0.2) + 0.05 * np.sin(2 * np.pi * x)


def test_the_least_of_a_cycle_is_refined_to_its_precision():
    from gearcheck.sweep.certify import refine_least

    xs = [0.0, 1 / 3, 2 / 3]  # three samples per cycle: the dip at 0.37 lies between two of them
    fine = np.linspace(0.0, 1.0, 300, endpoint=False)  # 100× finer
    calls = []

    def evaluate(points):
        calls.append(len(points))
        return _dip(points)

    r = refine_least(xs, _dip(xs), evaluate, 1.0, precision=1e-4)
    true = float(_dip(np.linspace(0.0, 1.0, 200001)).min())
    assert min(_dip(xs)) - true > 0.05  # the samples alone miss it by far
    assert r.least == pytest.approx(true, abs=1e-4)
    assert r.lower <= true <= r.least and r.lower <= float(_dip(fine).min()) and r.bracket <= 1e-4
    assert r.refined == sum(calls) < 400 and abs(r.at - 0.37) < 0.01
