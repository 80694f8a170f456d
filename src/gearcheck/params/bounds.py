"""The allowed ranges an error line names: a rule's boundary found by bisection, and bounds and
ranges printed to the digits that keep them inside their rule."""

from __future__ import annotations

import math
from collections.abc import Callable
from decimal import ROUND_HALF_EVEN, Decimal, localcontext

from gearcheck.geometry.bisect import bisect


def bisect_boundary(ok, good: float, bad: float, steps: int) -> float | None:
    """Where ``ok`` changes between ``good`` (ok) and ``bad`` (not ok), by ``steps`` bisections,
    on the ok side; None if ``ok(good)`` fails (no boundary in the bracket). The models use it to
    say how far a rejected value may go."""
    if not ok(good):
        return None
    return bisect(lambda x: not ok(x), good, bad, tol=None, max_iter=steps, check_ends=False).free


# A bound that fails its rule's own test after rounding steps inward by one unit of its last
# digit at most this many times (the rule and the bound's computation differ by float rounding
# or a root finder's tolerance, far below one printed unit).
MAX_BOUND_STEPS = 3
# A range narrower than a unit of the requested digits gets up to this many more digits.
MAX_EXTRA_DIGITS = 6


def fmt_bound(value: float, side: str, digits: int | None = 3,
              ok: Callable[[float], bool] | None = None, strict: bool = False) -> str:
    """A computed bound as a rejection prints it, rounded INWARD at ``digits`` decimals: a
    ``"lower"`` bound up, an ``"upper"`` bound down, so that the number read back from the text
    lies inside the allowed range (a closed bound printed is itself accepted; an open one, '>x'
    or '<x', prints a range inside the true one). The comparison is on the float the text reads
    back as, so a bound already on the grid (0.505·8 = 4.04) prints as it is.

    digits None: the shortest text that reads back as exactly ``value`` (a bound that is another
    input, e.g. 'allowed < sleeve diameter 8.5 mm'). ``ok``: the rule's own test of a value, for
    a bound computed apart from the rule (by a root finder, or in other arithmetic); the printed
    bound steps inward until ``ok`` accepts it (at most MAX_BOUND_STEPS units) or, ``strict``
    (an open bound, not itself allowed), accepts the float just inside it.
    """
    if side not in ("lower", "upper"):
        raise ValueError(f"side must be 'lower' or 'upper', not {side!r}")
    if digits is None:
        short = f"{value:g}"
        return short if float(short) == value else repr(value)
    lower = side == "lower"
    unit = Decimal(1).scaleb(-digits)
    with localcontext() as ctx:
        ctx.prec = 60
        d = Decimal(value).quantize(unit, rounding=ROUND_HALF_EVEN)
        if (float(d) < value) if lower else (float(d) > value):
            d += unit if lower else -unit
        for _ in range(MAX_BOUND_STEPS):
            if ok is None:
                break
            probe = float(d)
            if strict:
                probe = math.nextafter(probe, math.inf if lower else -math.inf)
            if ok(probe):
                break
            d += unit if lower else -unit
        if d == 0:
            d = abs(d)  # no '-0.000'
        return f"{d:f}"


def fmt_range(lo: float, hi: float, digits: int | None = 3, *, lo_open: bool = False, hi_open: bool = False,
              lo_ok: Callable[[float], bool] | None = None, hi_ok: Callable[[float], bool] | None = None) -> str:
    """'lo to hi' ('>lo', '<hi' for open ends), each end rounded inward (:func:`fmt_bound`); a
    range narrower than one unit at ``digits`` gets more digits, so its printed ends stay ordered."""
    extra = 0
    while True:
        n = None if digits is None else digits + extra
        a = fmt_bound(lo, "lower", n, lo_ok, strict=lo_open)
        b = fmt_bound(hi, "upper", n, hi_ok, strict=hi_open)
        if n is None or lo > hi or float(a) <= float(b) or extra >= MAX_EXTRA_DIGITS:
            break  # (an empty range, lo > hi, is the caller's to word)
        extra += 1
    return f"{'>' if lo_open else ''}{a} to {'<' if hi_open else ''}{b}"
