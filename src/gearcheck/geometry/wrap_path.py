"""How far a part of a chain wrapped on a sprocket moves relative to the sprocket (numpy only).

In the sprocket's frame a seated pin (or roller) stands in its groove; the runs beyond the first
and the last seated pin are straight lines with a fixed direction in the world, so each run turns
rigidly about its seated end pin by the sprocket's turn, the other way. Between two seating
events, then, a part of the chain stands still (seated) or turns about one pivot; its path over
an interval is the sum over the pieces of the turn times its farthest point's distance from the
pivot. Used by the track's and the roller chain's certified clearances
(:mod:`gearcheck.sweep.certify`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np


def wrap_path_mm(seated_at: Callable[[float], np.ndarray], cuts: Sequence[float], index: int, pitch_mm: float,
                 reach_mm: float, round_mm: float | None = None, link: bool = True,
                 partner: int | None = None) -> float:
    """The longest path (mm) a point of a chain part takes relative to the sprocket over the drive
    angles ``cuts[0]`` … ``cuts[-1]`` (rad), cut at every seating event between them (so that on
    each piece the seated pins do not change): ``seated_at(angle)`` the seated flags of the pins;
    the part is link ``index`` (pins ``index`` and ``index + 1``; ``link``) or pin ``index`` alone,
    carried by a link with pin ``partner`` (a roller on its inner link: while it is seated and its
    partner is not, it turns about its own axis); ``reach_mm`` its farthest point from pin
    ``index``'s axis, in the plane.

    On a piece a seated part stands still; else it turns with its run about the run's seated end
    pin, and its points lie within (pitches to the pivot) · pitch + reach of it. ``round_mm``: the
    part is round about its own pin axis to within this (0: exactly); where it turns about that
    very axis it stays within ``round_mm`` of itself, counted as a path of 2·round_mm."""
    path, turns_round = 0.0, False
    for b0, b1 in zip(cuts[:-1], cuts[1:], strict=True):
        if not b1 > b0:
            continue
        seated = seated_at(0.5 * (b0 + b1))
        other = index + 1 if link else partner
        if seated[index] and (other is None or seated[other]):
            continue
        idx = np.flatnonzero(seated)
        first, last = int(idx[0]), int(idx[-1])
        rho = (index - last) * pitch_mm if index >= last else (first - index) * pitch_mm  # to the run's pivot
        if rho == 0.0 and round_mm is not None:
            turns_round = True
        else:
            path += (b1 - b0) * (rho + reach_mm)
    return path + (2.0 * round_mm if turns_round and round_mm is not None else 0.0)
