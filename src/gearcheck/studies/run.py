"""Evaluating a study's variants, level by level, on any executor.

Each variant is a pure function of its parameters: the template's data with the sampled fields
set, validated like any template (a rejected variant is counted with its one-line reason, never
dropped), then evaluated

1. ``analytical``: the mechanism's analytical model (``Mechanism.study_row(params,
   "analytical")``; vectorised over every variant when the mechanism offers
   ``study_batch``);
2. ``exact``: its exact model (numpy only, no mesh) on every variant or the declared prefix;
3. ``check``: the full pipeline (CAD, meshes, sweep, exact B-rep) on the K worst variants.

Levels 1 and 2 run as chunks of variants through an :class:`gearcheck.executor.Executor` — local
processes, this process, or a Dask cluster — and come back in variant order, so the table is the
same row for row whatever runs it.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

log = logging.getLogger("gearcheck")

# Variants per task: large enough to amortise a task's overhead, small enough to balance.
CHUNK = {"analytical": 64, "exact": 4, "contact": 4}


@dataclass(frozen=True)
class Base:
    """What every worker needs: the mechanism, the template's data and the fields sampled as
    whole numbers (small, picklable)."""

    mechanism: str
    data: dict
    integers: frozenset[str] = frozenset()


def variant_data(base: Base, values: dict[str, float]) -> dict:
    """The template's data with a variant's values set (a whole-number field as an int)."""
    from gearcheck.params.common import apply_values

    return apply_values(base.data, {f: int(v) if f in base.integers and math.isfinite(v) else v
                                    for f, v in values.items()})


def _numbers(row: dict) -> dict[str, float]:
    return {k: float(v) for k, v in row.items() if isinstance(v, (int, float))}  # bools count as 1/0


def evaluate_chunk(base: Base, level: str, variants: Sequence[dict[str, float]]) -> list[dict | str]:
    """Validate and evaluate variants at one level: a row of figures each, or the rejection's
    one-line reason (a str). Runs in workers: imports neither CadQuery nor FCL."""
    from gearcheck import mechanism as registry
    from gearcheck.design import from_data
    from gearcheck.params import ParamError

    impl = registry.get(base.mechanism)
    out: list[dict | str] = []
    for values in variants:
        try:
            design = from_data(variant_data(base, values))
        except ParamError as exc:
            out.append(str(exc.with_source("")))  # the field, its value, the allowed range
            continue
        out.append(_numbers(impl.study_row(design.params, level)))
    return out


def _run_chunk(_state: Any, base: Base, level: str, variants: list[dict[str, float]]) -> list[dict | str]:
    return evaluate_chunk(base, level, variants)


@dataclass
class LevelResult:
    """One level over the variants it evaluated (indices into the table)."""

    level: str
    indices: np.ndarray
    rows: list[dict | str]
    columns: dict[str, np.ndarray] = field(default_factory=dict)


def run_level(base: Base, level: str, inputs: dict[str, np.ndarray], indices: np.ndarray, executor,
              progress: Callable[[int], None] | None = None) -> LevelResult:
    """Evaluate ``indices`` of the input table at ``level`` on ``executor`` (rows in order)."""
    fields = list(inputs)
    variants = [{f: float(inputs[f][i]) for f in fields} for i in indices]
    size = CHUNK[level]
    chunks = [variants[k:k + size] for k in range(0, len(variants), size)]
    tasks = [(base, level, c) for c in chunks]
    results = executor.map(_run_chunk, tasks, progress=progress, weights=[len(c) for c in chunks])
    rows = [r for chunk in results for r in chunk]
    return LevelResult(level, np.asarray(indices), rows, columns(rows, len(indices)))


def columns(rows: list[dict | str], n: int) -> dict[str, np.ndarray]:
    """Rows → float columns (NaN where a row lacks a figure or was rejected), keys sorted."""
    keys = sorted({k for r in rows if isinstance(r, dict) for k in r})
    out = {k: np.full(n, math.nan) for k in keys}
    for i, r in enumerate(rows):
        if isinstance(r, dict):
            for k, v in r.items():
                out[k][i] = v
    return out


def batch_analytical(base: Base, inputs: dict[str, np.ndarray], valid: np.ndarray) -> dict[str, np.ndarray] | None:
    """The vectorised analytical level over every valid variant, if the mechanism offers it."""
    from gearcheck import mechanism as registry
    from gearcheck.design import from_data

    impl = registry.get(base.mechanism)
    params = from_data(base.data).params
    cols = {k: np.asarray(v, float)[valid] for k, v in inputs.items()}
    got = impl.study_batch(params, cols)
    if got is None:
        return None
    n = len(valid)
    out = {}
    for k, v in got.items():
        full = np.full(n, math.nan)
        full[valid] = np.asarray(v, float)
        out[k] = full
    return out
