"""Touching or overlapping: a zero exact distance cannot tell them apart, so the exact B-rep
confirmation measures the overlap (the common volume, else a sampled penetration depth) and says
which it is. Before: at a differential shim of 0.034 mm the common volume was null, the distance
2e-15 mm, and the confirmation said only "agrees"."""

from __future__ import annotations

import cadquery as cq
import numpy as np
import pytest

from gearcheck.cad.confirm import CONTACT_MM, _common_volume, penetration_depth

pytestmark = pytest.mark.cad


def _boxes(gap_mm: float):
    a = cq.Workplane().box(10, 10, 10).val()  # x in [-5, 5]
    b = cq.Workplane().box(10, 10, 10).val().translate(cq.Vector(10 + gap_mm, 2.0, 1.0))  # x from 5 + gap
    return a.wrapped, b.wrapped


def test_face_to_face_boxes_touch_with_no_volume_and_no_depth():
    a, b = _boxes(0.0)
    assert _common_volume(a, b) == pytest.approx(0.0, abs=1e-9)
    assert penetration_depth(a, b, np.array([5.0, 2.0, 1.0])) <= CONTACT_MM


@pytest.mark.parametrize("depth", [0.002, 0.01])
def test_boxes_overlapping_by_microns_have_that_volume_and_depth(depth):
    a, b = _boxes(-depth)
    assert _common_volume(a, b) == pytest.approx(depth * 8 * 9, rel=1e-3)  # overlap 8 × 9 mm in y and z
    near = np.array([5.0 - depth / 2, 2.0, 1.0])
    assert penetration_depth(a, b, near) == pytest.approx(depth, rel=1e-6)
    assert penetration_depth(b, a, near) == pytest.approx(depth, rel=1e-6)
