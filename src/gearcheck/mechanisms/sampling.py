"""Random parameter sets around the shipped templates (stdlib only), for property tests and
`make fuzz`: the shared draws; each mechanism's sampler lives in its own package and is reached
through its ``Mechanism.sample`` hook.

A sample starts from a real template's data and redraws every documented knob of its mechanism
(module, tooth counts, face width, pressure angle, profile shift, pitch, sleeve diameter,
temperatures, shim, trim heights, ...). Most values are drawn inside the band where a design can
work, so that a good share of the sets is accepted; a small fraction lands outside the fields'
documented ranges or breaks a cross-field rule, so that every rejection path runs too. Inputs the
models tie to others (the common-apex lengths a, b; the trims between the rolling line and the
rack top) are drawn relative to what they depend on, with an occasional miss.

The draws go through a :class:`Draw`, so the same definition serves hypothesis (tests: shrinking,
a seeded database-free run) and :class:`random.Random` (``bench/fuzz.py``).
"""

from __future__ import annotations

import copy
import random
from typing import Protocol


# Share of knobs drawn outside their working band, and exactly at one of its ends (each knob
# decides alone).
OUT_OF_BAND = 0.04
EDGE = 0.03

class Draw(Protocol):
    def real(self, lo: float, hi: float) -> float: ...

    def integer(self, lo: int, hi: int) -> int: ...

    def chance(self, p: float) -> bool: ...


class RandomDraw:
    """:class:`Draw` from a seeded :class:`random.Random`."""

    def __init__(self, seed: int):
        self.rng = random.Random(seed)

    def real(self, lo: float, hi: float) -> float:
        return self.rng.uniform(lo, hi)

    def integer(self, lo: int, hi: int) -> int:
        return self.rng.randint(lo, hi)

    def chance(self, p: float) -> bool:
        return self.rng.random() < p


def _knob(draw: Draw, lo: float, hi: float, digits: int = 4) -> float:
    """Inside [lo, hi] mostly; exactly an end EDGE of the time (bounds are where rules break);
    else up to 30 % of the span beyond one end."""
    if draw.chance(EDGE):
        return round(lo if draw.chance(0.5) else hi, digits)
    if draw.chance(OUT_OF_BAND):
        span = 0.3 * (hi - lo) if hi > lo else 1.0
        value = draw.real(hi, hi + span) if draw.chance(0.5) else draw.real(lo - span, lo)
    else:
        value = draw.real(lo, hi)
    return round(value, digits)


def _int_knob(draw: Draw, lo: int, hi: int, out: int = 3) -> int:
    if draw.chance(OUT_OF_BAND):
        return draw.integer(hi + 1, hi + out) if draw.chance(0.5) else draw.integer(lo - out, lo - 1)
    return draw.integer(lo, hi)


def _near(draw: Draw, value: float, miss: float, digits: int = 4) -> float:
    """``value`` up to rounding (and, OUT_OF_BAND of the time, off by up to ±``miss``)."""
    if draw.chance(OUT_OF_BAND):
        value += draw.real(-miss, miss)
    return round(value, digits)


def sample(base: dict, draw: Draw) -> dict:
    """A new template body (TOML data, ``mechanism`` key kept) redrawn from ``base`` by its
    mechanism's sampler (:meth:`gearcheck.mechanism.Mechanism.sample`). Figures a model documents
    as possibly NaN are its ``nan_figures``; every other figure of an accepted set must be
    finite, and none infinite: what the property tests and `make fuzz` check."""
    from gearcheck.mechanism import get

    data = copy.deepcopy(base)
    get(data["mechanism"]).sample(data, draw)
    return data
