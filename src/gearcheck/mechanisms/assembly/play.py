"""The play part's move to contact, one way, at one pose: the bracket the plain bisection of
[0, limit] on FCL collide ends with, found with few queries around an estimate and proven from
both sides (:func:`gearcheck.geometry.bisect.bisect_predicted`).

The estimates, in order: Newton steps on the gap between small cuts of the meshes around the last
contact (:mod:`~gearcheck.mechanisms.assembly.local`), started from the last poses' moves
extrapolated; the same with the cuts seated again by one whole-mesh distance query; the
extrapolation alone, then with a wider margin; Newton steps on the whole directed meshes (two,
then between cuts; then all of them). A wrong estimate costs queries, never the figure: the
bracket is the plain bisection's, bit for bit.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from gearcheck.geometry.bisect import bisect, bisect_predicted, remembered
from gearcheck.mechanisms.assembly.local import Cut, Cuts, to_local
from gearcheck.sweep.motion import Rotation
from gearcheck.sweep.tools import CountedScene

if TYPE_CHECKING:
    from gearcheck.mechanisms.assembly.sweep import Spec

NEWTON_STEPS = 4  # distance queries at most per contact estimate
CUT_MARGIN_TOL = 0.5  # the least margin of an estimate from the cuts, in bisection tolerances (their error: < 0.6)
COLD_STEPS = 2  # with no earlier pose: this many on the whole meshes, the rest between cuts around the contact
EXTRAPOLATION_MEMORY = 4  # the last poses a line is fitted to, for the next pose's estimate
EXTRAPOLATION_MARGIN_TOL = 1.5  # the least margin, in bisection tolerances
FIRST_MARGIN_TOL = 8.0  # the margin around the last pose's move alone, in bisection tolerances
WIDER = 8.0  # a second try around the same extrapolation: its margin this many times wider
NEWTON_DAMPING = (0.6, 0.9, 0.95)  # each step goes this share of the predicted way (a first one runs long)
NEAR_DAMPING = (0.95,)  # the same from a start a few tolerances short of the contact


def _gap_rate(scene: CountedScene, spec: Spec, part: str, sign: float, ahead: list[str],
              facing: list[str], seen: Callable[[int, Any], None] | None = None) -> tuple[float, float] | None:
    """(gap, closing rate per unit move) to the nearest neighbour at the current pose: the distance
    between the nearest points and n·v (n the unit normal from the mover's nearest point to the
    neighbour's, v the mover's velocity there per unit move of its joint). None where touching or
    the gap does not close. ``seen``: told each neighbour's distance (its index, the result)."""
    line = spec.kin.lines[part]
    best = None
    for k, (m, o) in enumerate(zip(ahead, facing, strict=True)):
        d = scene.distance(m, o)
        if not d.distance > 0.0:
            return (0.0, 1.0)  # touching
        if seen is not None:
            seen(k, d)
        n = (d.point_b - d.point_a) / d.distance
        if line.unit == "deg":
            motion = line.motion
            assert isinstance(motion, Rotation)
            a, origin = np.asarray(motion.axis, float), np.asarray(motion.origin, float)
            rate = sign * float(n @ np.cross(a, d.point_a - origin)) * math.pi / 180.0
        else:
            rate = sign * float(n @ np.asarray(line.motion.axis, float))
        if rate > 1e-12 and (best is None or d.distance / rate < best[0] / best[1]):
            best = (d.distance, rate)
    return best


def _told(seen: Callable[[int, Any, float], None], at: float, j: int, d: Any) -> None:
    seen(j, d, at)


def _newton(scene: CountedScene, spec: Spec, part: str, x: float, sign: float, ahead: list[str],
            facing: list[str], tol: float, limit: float, start: float = 0.0,
            seen: Callable[[int, Any, float], None] | None = None, steps: int = 0,
            least: float = 1.0, damping: tuple[float, ...] = NEWTON_DAMPING) -> tuple[float, float] | None:
    """(estimate, margin) of the move that brings the play part into contact, from damped Newton
    steps on the gap between nearest points (:func:`_gap_rate`, one distance query each; every
    step stays free, a positive distance says so), from the move ``start`` (free): an estimate
    only, the contact is still proven by collisions. None where it cannot say. ``seen``: told each
    distance query (the neighbour's index, the result, the move); ``steps``: at most this many
    (default :data:`NEWTON_STEPS`)."""
    free, at, step = start, start, math.inf
    for k in range(steps or NEWTON_STEPS):
        pose = spec.kin.pose(part, x, sign * at)
        for name in ahead:
            scene.set_pose(name, pose)
        told = None if seen is None else functools.partial(_told, seen, at)
        gr = _gap_rate(scene, spec, part, sign, ahead, facing, told)
        if gr is None or (k == 0 and gr[0] == 0.0 and start > 0.0):
            return None  # no closing gap, or the start already touches
        if gr[0] == 0.0:  # the step ran into contact: it lies between the last free move and this one
            return 0.5 * (free + at), 0.5 * (at - free) + tol
        free, step = at, gr[0] / gr[1]
        if step <= tol or at + step >= limit:
            break
        at += damping[min(k, len(damping) - 1)] * step
    return free + step, max(least * tol, step)


def _extrapolated(history: list[float], tol: float, widen: float = 1.0) -> tuple[float, float] | None:
    """(estimate, margin) of the next pose's move from the last poses' (the motion's poses are
    close: the contact moves little from one to the next), or None without one. With
    :data:`EXTRAPOLATION_MEMORY` of them, a straight line fitted to them (the moves are bisection
    brackets, each rounded by up to one tolerance: the fit averages that out), its margin from how
    far the fitted points lie off the line; with fewer, the line through the last two, its margin
    their difference; with one, that move, its margin :data:`FIRST_MARGIN_TOL` tolerances. Each
    margin times ``widen`` (a second try after the first estimate failed to prove its bracket)."""
    recent = history[-EXTRAPOLATION_MEMORY:]
    if not history or not (math.isfinite(history[-1]) and history[-1] > 0.0):
        return None
    if len(history) < 2 or not (math.isfinite(history[-2]) and history[-2] > 0.0):
        return history[-1], widen * FIRST_MARGIN_TOL * tol
    if len(recent) < EXTRAPOLATION_MEMORY or not all(math.isfinite(h) and h > 0.0 for h in recent):
        last, before = history[-1], history[-2]
        return last + (last - before), widen * max(2.0 * tol, abs(last - before))
    k = np.arange(len(recent), dtype=float)
    slope, offset = np.polyfit(k, np.asarray(recent, float), 1)
    off = float(np.abs(offset + slope * k - np.asarray(recent, float)).max())
    return float(offset + slope * len(recent)), widen * max(EXTRAPOLATION_MARGIN_TOL * tol, 2.0 * off + tol)


def _to_contact(hits_at: Callable[[float], bool], tol: float, limit: float,
                estimates: tuple[Callable[[], tuple[float, float] | None], ...],
                known: dict[float, bool] | None = None) -> float:
    """The touching end of the bracket the plain bisection of [0, limit] ends with (``limit`` where
    nothing touches within it), found around the first estimate that proves its bracket (each an
    (estimate, margin) or None, tried in order, answers shared), else by that bisection. ``known``:
    answers already had (the pose itself, say: free)."""
    ask, asked = remembered(hits_at)
    asked.update(known or {})
    for make in estimates:
        estimate = make()
        if estimate is None or not 0.0 < estimate[0] < limit:
            continue
        found = bisect_predicted(ask, 0.0, limit, tol, estimate[0], estimate[1], asked=asked)
        if found is not None:
            return found[0].touching
    return bisect(ask, 0.0, limit, tol, check_ends=False).touching if ask(limit) else limit


def contact_move(scene: CountedScene, spec: Spec, cuts: Cuts, x: float, sign: float, keys: list[tuple],
                 ahead: list[str], facing: list[str], whole: tuple[list[str], list[str]], past: list[float],
                 free: bool, tol: float) -> float:
    """The play part's move one way (``sign``) from its coupled position at ``x`` to contact with any of
    its neighbours (``ahead``/``facing``: its directed meshes and theirs, posed at ``x``; ``whole``:
    the whole pruned meshes, for the pose itself; ``keys``: the cut key per neighbour): the bracket
    the plain bisection of [0, limit] ends with, found around the first estimate that proves it —
    Newton steps on the gap between the cuts around the last contact (from the last poses' moves
    extrapolated, :func:`_extrapolated`); the same with every cut seated again by one whole
    distance query; the extrapolation alone, then with a wider margin; :data:`COLD_STEPS` Newton
    steps on the whole directed meshes continued between cuts seated where they end; all
    :data:`NEWTON_STEPS` on the whole meshes — else by the plain bisection, to ``tol``. A collision
    between cuts answers "touching" (the cuts are subsets); "free" is asked of the whole meshes."""
    part = spec.play
    assert part is not None
    kin, limit = spec.kin, spec.play_limit
    others = [kin.pose(name.partition("~")[0], x) for name in facing]

    def live() -> list[Cut]:
        return [c for c in (cuts.get(k) for k in keys) if c is not None]

    def seat(j: int, d: Any, at: float, grow: bool = False) -> Cut:
        mover = kin.pose(part, x, sign * at)
        cut = cuts.seat(keys[j], ahead[j], facing[j], to_local(mover, d.point_a), to_local(others[j], d.point_b),
                        grow)
        scene.set_pose(cut.other, others[j])
        return cut

    for cut, other in zip([cuts.get(k) for k in keys], others, strict=True):
        if cut is not None:
            scene.set_pose(cut.other, other)

    def hits_at(d: float) -> bool:
        if d == 0.0:  # at the pose itself: the whole pruned meshes (an overlap may be on any face)
            return any(scene.collide(m, o) for m, o in zip(*whole, strict=True))
        pose = kin.pose(part, x, sign * d)
        for cut in live():  # touching between the cuts: touching (they are subsets)
            scene.set_pose(cut.mover, pose)
            if scene.collide(cut.mover, cut.other):
                return True
        for name in ahead:
            scene.set_pose(name, pose)
        return any(scene.collide(m, o) for m, o in zip(ahead, facing, strict=True))

    def on_cuts(start: float) -> tuple[float, float] | None:
        """Newton steps between the cuts from ``start`` (free); a cut the contact strays from is seated
        again where it went, and the steps run once more."""
        found = None
        for _ in range(2):
            stray: dict[int, tuple[Any, float]] = {}

            def check(j: int, d: Any, at: float, stray: dict[int, tuple[Any, float]] = stray) -> None:
                cut = cuts.get(keys[j])
                mover = kin.pose(part, x, sign * at)
                if cut is not None and cut.strays(to_local(mover, d.point_a), to_local(others[j], d.point_b)):
                    stray[j] = (d, at)
            cut_list = [c for c in (cuts.get(k) for k in keys) if c is not None]
            found = _newton(scene, spec, part, x, sign, [c.mover for c in cut_list], [c.other for c in cut_list],
                            tol, limit, start, check, least=CUT_MARGIN_TOL, damping=NEAR_DAMPING)
            if not stray:
                break
            for j, (d, at) in stray.items():
                seat(j, d, at, grow=True)
        return found

    def near_cuts(again: bool = False) -> tuple[float, float] | None:
        """From the last poses' moves extrapolated: Newton steps between the cuts (a neighbour
        without one, or every one ``again``, seated by one whole distance query at the start)."""
        guess = _extrapolated(past, tol)
        if guess is None:
            return None
        start = max(0.0, guess[0] - 2.0 * guess[1])
        pose = kin.pose(part, x, sign * start)
        for j, key in enumerate(keys):
            if again or cuts.get(key) is None:
                scene.set_pose(ahead[j], pose)
                d = scene.distance(ahead[j], facing[j])
                if not d.distance > 0.0:
                    return None
                seat(j, d, start)
        return on_cuts(start)

    def on_whole(steps: int = NEWTON_STEPS) -> tuple[float, float] | None:
        """Newton steps on the whole directed meshes from the pose, the cuts seated where they end;
        after ``steps`` short of :data:`NEWTON_STEPS`, continued between the cuts."""
        last: dict[int, tuple[Any, float]] = {}
        found = _newton(scene, spec, part, x, sign, ahead, facing, tol, limit,
                        seen=lambda j, d, at: last.__setitem__(j, (d, at)), steps=steps)
        for j, (d, at) in last.items():
            seat(j, d, at)
        if found is None or steps >= NEWTON_STEPS or len(last) < len(keys):
            return found
        return on_cuts(max(at for _, at in last.values()))

    return _to_contact(hits_at, tol, limit, (
        near_cuts, functools.partial(near_cuts, True), functools.partial(_extrapolated, past, tol),
        functools.partial(_extrapolated, past, tol, WIDER), functools.partial(on_whole, COLD_STEPS), on_whole),
        known={0.0: False} if free else None)
