"""The push model's overlap intervals, computed the fast way (edge crossings shared by height,
vertex blocks pruned by bounds, one pair or one side alone), are bit for bit those of the direct
evaluation of every vertex and every edge of the pinion polygon at every angle (kept here as the
reference), on the template and on perturbed designs; and the towing analysis built on them is
unchanged to the last bit.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from gearcheck.design import load_template
from gearcheck.mechanisms.steering import analysis as an
from gearcheck.mechanisms.steering import push

TEMPLATE = Path(__file__).resolve().parents[1] / "templates" / "nose_wheel_steering.toml"
DESIGNS = {
    "template": [],
    "higher RS1": ["pinion.topped_radius_mm=84.5"],
    "lower hS2, hS6": ["trim.hS2_mm=25.0", "trim.hS6_mm=25.3"],
    "shifted, higher hS8": ["pinion.profile_shift=0.1", "trim.hS8_mm=25.8"],
}


def _reference_offsets(px, py, chain, want_lo=True, want_hi=True):
    """min and max over the chain's heights of [pinion boundary x(y) − chain x(y)] per row: every
    vertex within the heights, every non-horizontal edge crossing each chain vertex height."""
    ys, xs = chain
    bx, by = np.roll(px, -1, axis=1), np.roll(py, -1, axis=1)
    dy = by - py
    flat = dy == 0.0
    inv_dy = 1.0 / np.where(flat, 1.0, dy)
    slope_x = (bx - px) * inv_dy
    inside = (py >= ys[0]) & (py <= ys[-1])
    d = px - np.interp(py, ys, xs)
    hi = np.where(inside, d, -np.inf).max(axis=1) if want_hi else None
    lo = np.where(inside, d, np.inf).min(axis=1) if want_lo else None
    for uy, ux in zip(ys, xs, strict=True):
        t = (uy - py) * inv_dy
        crossing = ~flat & (t >= 0.0) & (t <= 1.0)
        x = px + (uy - py) * slope_x
        if want_hi:
            hi = np.maximum(hi, np.where(crossing, x, -np.inf).max(axis=1) - ux)
        if want_lo:
            lo = np.minimum(lo, np.where(crossing, x, np.inf).min(axis=1) - ux)
    return lo, hi


def _reference_intervals(g, phis):
    """:func:`push.all_intervals` by direct evaluation, pair by pair."""
    phis = np.atleast_1d(np.asarray(phis, dtype=float))
    pairs, rows = [], []
    for j, ks in push._tooth_pairs_by_pinion(g).items():
        chains = [push._rack_chains(g, k) for k in ks]
        idx = np.flatnonzero(push._active(g, j, max(c[5] for c in chains), phis))
        rho, gam = g.pinion_contact_polygon_polar(j)
        ang = gam[None, :] + g.pinion_tooth_angle(j, phis[idx])[:, None]
        px, py = rho * np.sin(ang), g.centre_to_datum_mm - rho * np.cos(ang)
        for k, (left, right, left_flank, right_flank, y0, top) in zip(ks, chains, strict=True):
            pairs.append((j, k))
            out = [np.full(phis.shape, np.nan) for _ in range(6)]
            rows.append(out)
            overlap = (py.min(axis=1) <= top) & (py.max(axis=1) >= y0) if idx.size else np.zeros(0, bool)
            if not overlap.any():
                continue
            sub = px[overlap], py[overlap]
            whole = (_reference_offsets(*sub, right, want_hi=False)[0],
                     _reference_offsets(*sub, left, want_lo=False)[1])
            found = [whole, _reference_offsets(*sub, left_flank), _reference_offsets(*sub, right_flank)]
            for n, (lo, hi) in enumerate(found):
                ok = np.isfinite(hi) & np.isfinite(lo)
                out[2 * n][idx[overlap][ok]] = lo[ok]
                out[2 * n + 1][idx[overlap][ok]] = hi[ok]
    arrays = [np.array([r[n] for r in rows]) for n in range(6)]
    return pairs, arrays


def _bitwise(a, b) -> bool:
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def _geometry(overrides):
    return an.geometry_from_params(load_template(TEMPLATE, overrides).params)


@pytest.mark.parametrize("name", list(DESIGNS))
def test_intervals_are_bit_identical_to_evaluating_every_vertex(name):
    g = _geometry(DESIGNS[name])
    phis = push.towing_grid(100.0)
    pairs, whole, left, right = push.all_intervals(g, phis)
    ref_pairs, ref = _reference_intervals(g, phis)
    assert pairs == ref_pairs
    fast = [*whole, *left, *right]
    for n in range(6):
        assert _bitwise(fast[n], ref[n]), n
    assert np.isfinite(ref[0]).sum() > 1000  # the comparison covers real overlaps


def test_one_pair_or_one_side_alone_as_when_computing_all():
    g = _geometry([])
    phis = np.radians([0.0, 30.0, 62.5, 76.0, 76.01, 80.0])
    pairs, *everything = push.all_intervals(g, phis)
    for parts, n_part in ((("left",), 1), (("right",), 2), (("whole",), 0)):
        _, *alone = push.all_intervals(g, phis, parts=parts)
        for m in range(3):
            for side in (0, 1):
                expected = everything[m][side] if m == n_part else np.full_like(everything[m][side], np.nan)
                assert _bitwise(alone[m][side], expected)
    for pair in [(g.sector_first_tooth, g.rack_first_tooth), (0, 0), (0, 1)]:
        n = pairs.index(pair)
        _, *single = push.all_intervals(g, phis, only=pair)
        for m in range(3):
            for side in (0, 1):
                assert _bitwise(single[m][side][n], everything[m][side][n])
                assert np.isnan(np.delete(single[m][side], n, axis=0)).all()


def test_pruned_blocks_match_every_vertex_at_few_and_many_angles():
    """The direct path (few angles) and the pruned one (many) give the same bits at the same angle."""
    g = _geometry([])
    phis = push.towing_grid(100.0)
    _, *many = push.all_intervals(g, phis)
    for i in np.linspace(0, phis.size - 1, 25).astype(int):
        _, *one = push.all_intervals(g, phis[i:i + 1])
        for m in range(3):
            for side in (0, 1):
                assert _bitwise(one[m][side][:, 0], many[m][side][:, i])


def _same(a, b) -> bool:
    if dataclasses.is_dataclass(a):
        return all(_same(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a))
    if isinstance(a, np.ndarray):
        return _bitwise(np.asarray(a, float), np.asarray(b, float))
    if isinstance(a, float):
        return np.float64(a).view(np.int64) == np.float64(b).view(np.int64) or (math.isnan(a) and math.isnan(b))
    return a == b


@pytest.mark.parametrize("name", ["template", "lower hS2, hS6"])
def test_towing_analysis_unchanged_by_the_fast_intervals(name, monkeypatch):
    """analyse_towing on the fast intervals equals analyse_towing on the reference ones, bit for bit
    (every array and event angle)."""
    g = _geometry(DESIGNS[name])
    fast = push.analyse_towing(g, 100.0, step_deg=0.1)

    def reference_all(g_, phis, only=None, parts=push.PARTS):
        pairs, arrays = _reference_intervals(g_, phis)
        for m, part in enumerate(push.PARTS):
            keep = part in parts
            for side in (0, 1):
                a = arrays[2 * m + side]
                if not keep:
                    a[:] = np.nan
                elif only is not None:
                    a[[n for n, p in enumerate(pairs) if p != only]] = np.nan
        return pairs, (arrays[0], arrays[1]), (arrays[2], arrays[3]), (arrays[4], arrays[5])

    monkeypatch.setattr(push, "all_intervals", reference_all)
    slow = push.analyse_towing(_geometry(DESIGNS[name]), 100.0, step_deg=0.1)
    assert _same(fast, slow)
