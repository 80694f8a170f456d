"""gearcheck.geometry.spur, the public building blocks of a plugin's gear: the outline's vertices
lie on the involute, tip and root circles, its tooth thickness on the pitch circle is the standard
one less the thinning, and the transforms are rigid."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearcheck.geometry.spur import flank_sag_mm, rot_z, spur_outline, translation


def test_outline_vertices_lie_on_the_involute_and_the_circles():
    z, m, alpha, t = 18, 2.0, math.radians(20.0), 0.05
    pts = spur_outline(z, m, alpha, t)
    r, rb = m * z / 2, m * z / 2 * math.cos(alpha)
    rho = np.hypot(pts[:, 0], pts[:, 1])
    assert rho.max() == pytest.approx(r + m, abs=1e-12) and rho.min() == pytest.approx(r - 1.25 * m, abs=1e-12)
    # tooth 0 (centred on +x): on its flanks, the polar angle is ±(ψ + inv α − inv α_ρ)
    psi = math.pi / (2 * z) - t / (2 * r)
    gamma = np.arctan2(pts[:, 1], pts[:, 0])
    flank = (rho > rb + 1e-9) & (rho < r + m - 1e-9) & (np.abs(gamma) < math.pi / z)
    a_rho = np.arccos(rb / rho[flank])
    expected = psi + (math.tan(alpha) - alpha) - (np.tan(a_rho) - a_rho)
    assert flank.sum() >= 40 and np.allclose(np.abs(gamma[flank]), expected, atol=1e-12)
    # the tooth's chordal arc on the pitch circle: πm/2 − t
    half = psi + 0.0  # at ρ = r the involute term is inv α − inv α = 0
    assert 2 * half * r == pytest.approx(math.pi * m / 2 - t, abs=1e-12)
    assert 0 < flank_sag_mm(z, m, alpha) < 1e-3
    with pytest.raises(ValueError, match="pointed teeth"):
        spur_outline(6, 2.0, alpha, 2.0)


def test_transforms_are_rigid_and_compose():
    a = rot_z(0.3) @ translation((1.0, 2.0, 3.0))
    assert np.allclose(a[:3, :3].T @ a[:3, :3], np.eye(3)) and np.linalg.det(a[:3, :3]) == pytest.approx(1.0)
    assert np.allclose(rot_z(0.3) @ rot_z(-0.3), np.eye(4))
    assert np.allclose(a @ [0, 0, 0, 1], [math.cos(0.3) - 2 * math.sin(0.3), math.sin(0.3) + 2 * math.cos(0.3), 3, 1])
