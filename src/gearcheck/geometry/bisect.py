"""One bisection for every "where does it change" search (numpy-free): contact along a motion
coordinate in the sweeps, an event angle, the edge of a parameter's allowed range.

``flag(x)`` is False at ``free`` and True at ``touching``; the bracket is halved until it is no
wider than ``tol`` (or for ``max_iter`` halvings), keeping one end on each side.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

# Bisection stops when the bracket is this narrow (mm or rad, by caller), unless told otherwise.
DEFAULT_TOL = 1e-6
DEFAULT_MAX_ITER = 200


@dataclass(frozen=True)
class Bracket:
    """Where ``flag`` changes: False at ``free``, True at ``touching``."""

    free: float
    touching: float

    @property
    def value(self) -> float:
        return 0.5 * (self.free + self.touching)

    @property
    def width(self) -> float:
        return abs(self.touching - self.free)


def bisect(flag: Callable[[float], bool], free: float, touching: float, tol: float | None = DEFAULT_TOL,
           max_iter: int = DEFAULT_MAX_ITER, check_ends: bool = True) -> Bracket:
    """Halve [free, touching] (either order) keeping ``flag`` False at one end and True at the other.

    With ``check_ends`` the ends are tested first and a bracket that does not hold raises
    ValueError (a motion that never reaches contact proves nothing about clearance). ``tol``
    None: exactly ``max_iter`` halvings."""
    if check_ends:
        if flag(free):
            raise ValueError(f"start {free!r} already has the flag (no bracket)")
        if not flag(touching):
            raise ValueError(f"end {touching!r} does not reach the flag (no bracket)")
    for _ in range(max_iter):
        if tol is not None and abs(touching - free) <= tol:
            break
        mid = 0.5 * (free + touching)
        if flag(mid):
            touching = mid
        else:
            free = mid
    return Bracket(free, touching)


def remembered(flag: Callable[[float], bool]) -> tuple[Callable[[float], bool], dict[float, bool]]:
    """``flag`` asked once per argument, and its answers (argument → flag): pass both to several
    tries on one bracket (:func:`bisect_predicted` with ``asked``, then :func:`bisect`) so that
    none asks again what an earlier one was told."""
    asked: dict[float, bool] = {}

    def ask(x: float) -> bool:
        if x not in asked:
            asked[x] = flag(x)
        return asked[x]

    return ask, asked


def bisect_predicted(flag: Callable[[float], bool], free: float, touching: float, tol: float, estimate: float,
                     margin: float, max_iter: int = DEFAULT_MAX_ITER,
                     asked: dict[float, bool] | None = None) -> tuple[Bracket, int] | None:
    """The bracket :func:`bisect` (``check_ends=False``) would end with, found with few calls of
    ``flag`` when the change is expected at ``estimate`` (within ``margin``).

    The halving is replayed: a midpoint farther than ``margin`` from the estimate is given the side
    the estimate puts it on, a nearer one is asked of ``flag``. The final bracket is then proven:
    ``flag`` False at its free end and True at its touching end, both asked. Where ``flag`` changes
    once over the bracket (a monotone contact), a proven final bracket means every midpoint that
    was not asked lies on the side the estimate gave it, so the result is the plain bisection's,
    bit for bit. Returns the bracket and the number of calls, or None when the final bracket does
    not hold (the estimate was wrong): the caller then tries a wider margin or bisects as usual.

    ``asked`` (turn → flag) carries the answers of earlier tries on the same bracket: none is asked
    twice, and a midpoint not beyond the farthest free answer (or not short of the nearest
    touching one) takes that side, as one change over the bracket implies, wherever the estimate
    puts it. Answers that contradict one change decide nothing."""
    sign = 1.0 if touching > free else -1.0
    calls = 0
    asked = {} if asked is None else asked
    lo, hi = sorted((free, touching))
    inside = [(sign * x, hit) for x, hit in asked.items() if lo <= x <= hi]
    last_free = max((s for s, hit in inside if not hit), default=-math.inf)
    first_touching = min((s for s, hit in inside if hit), default=math.inf)

    def ask(x: float) -> bool:
        nonlocal calls, last_free, first_touching
        if x not in asked:
            calls += 1
            asked[x] = flag(x)
            if asked[x]:
                first_touching = min(first_touching, sign * x)
            else:
                last_free = max(last_free, sign * x)
        return asked[x]

    for _ in range(max_iter):
        if abs(touching - free) <= tol:
            break
        mid = 0.5 * (free + touching)
        s = sign * mid
        if last_free < first_touching and (s <= last_free or s >= first_touching):
            hit = s >= first_touching  # an answer beyond it decides, given one change
        elif abs(mid - estimate) <= margin:
            hit = ask(mid)
        else:
            hit = sign * (mid - estimate) > 0.0
        if hit:
            touching = mid
        else:
            free = mid
    if ask(free) or not ask(touching):
        return None
    return Bracket(free, touching), calls
