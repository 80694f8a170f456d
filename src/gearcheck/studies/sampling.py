"""Variants of a template: a seeded low-discrepancy sequence (scipy.stats.qmc) in the unit
cube, mapped through each input's inverse distribution function.

Reproducible: the same seed, sampler and sample count give the same table, value for value, on
any machine, executor and worker count (the table is drawn once, in the calling process; workers
only evaluate rows). Sobol sequences are scrambled (Owen) with the seed and drawn in a power-of-2
block, so any prefix of the table is itself a balanced design (the exact level evaluates a
prefix).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gearcheck.studies.spec import Input, StudySpec


def unit_cube(n: int, d: int, sampler: str, seed: int) -> np.ndarray:
    """(n, d) points in [0, 1)^d."""
    from scipy.stats import qmc

    if sampler == "random":
        return np.random.default_rng(seed).random((n, d))
    if sampler == "lhs":
        return qmc.LatinHypercube(d=d, seed=np.random.default_rng(seed)).random(n)
    engine = qmc.Sobol(d=d, scramble=True, seed=np.random.default_rng(seed))
    m = max(1, math.ceil(math.log2(n)))
    return engine.random_base2(m)[:n]


def _ppf(inp: Input, centre: float, u: np.ndarray) -> np.ndarray:
    """The input's draws from uniform ``u``; ``centre``: the template's value (0 for an offset)."""
    from scipy import stats

    # keep u inside (0, 1): a Sobol point may be exactly 0
    u = np.clip(u, 1e-12, 1 - 1e-12)
    if inp.distribution == "uniform":
        return float(inp.low) + u * (float(inp.high) - float(inp.low))  # type: ignore[arg-type]
    mean = centre if inp.mean is None else inp.mean
    sd = float(inp.sd or 0.0)
    if sd == 0.0:
        return np.full_like(u, mean)
    if inp.distribution == "normal":
        return stats.norm.ppf(u, loc=mean, scale=sd)
    a = -np.inf if inp.low is None else (inp.low - mean) / sd
    b = np.inf if inp.high is None else (inp.high - mean) / sd
    return stats.truncnorm.ppf(u, a, b, loc=mean, scale=sd)


def draw(spec: StudySpec, nominal: dict[str, float], samples: int | None = None,
         seed: int | None = None) -> dict[str, np.ndarray]:
    """The input columns, keyed by input (its name, else its field), for ``samples`` variants
    (default: the study's). ``nominal``: each field's template value (a value input's centre
    unless a mean is given; offsets are centred on 0)."""
    n = spec.samples if samples is None else samples
    s = spec.seed if seed is None else seed
    u = unit_cube(n, len(spec.inputs), spec.sampler, s)
    out = {}
    for j, inp in enumerate(spec.inputs):
        centre = 0.0 if inp.mode == "offset" else float(nominal[inp.field])
        col = np.asarray(_ppf(inp, centre, u[:, j]), float)
        out[inp.key] = np.rint(col) if inp.integer else col
    return out


def field_values(spec: StudySpec, nominal: dict[str, float], inputs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The template fields each variant sets: a value input's draw, else the template's value,
    plus every offset on that field."""
    n = len(next(iter(inputs.values())))
    out: dict[str, np.ndarray] = {}
    for inp in spec.inputs:
        if inp.mode == "value":
            out[inp.field] = np.array(inputs[inp.key], float)
    for inp in spec.inputs:
        if inp.mode == "offset":
            base = out.get(inp.field, np.full(n, nominal[inp.field]))
            out[inp.field] = base + inputs[inp.key]
    for inp in spec.inputs:
        for other in inp.also:
            out[other] = out[inp.field]
    return out


def integer_fields(spec: StudySpec, nominal: dict[str, float]) -> frozenset[str]:
    """The template fields every variant sets to whole numbers (a tooth count): those every
    input acting on is ``integer`` (a field only offset: from a whole template value), and the
    fields that take their values (``also``). The template gets them as ints, as its own file
    has them."""
    acting: dict[str, list[Input]] = {}
    for inp in spec.inputs:
        acting.setdefault(inp.field, []).append(inp)
    whole = {f for f, inps in acting.items() if all(i.integer for i in inps)
             and (any(i.mode == "value" for i in inps) or float(nominal[f]).is_integer())}
    return frozenset(whole | {other for inp in spec.inputs if inp.field in whole for other in inp.also})


def nominal_values(data: dict, fields: list[str]) -> dict[str, float]:
    """The template's value of each field (a field the template leaves to its default must be
    given a mean or bounds in the study)."""
    from gearcheck.params import ParamError

    out: dict[str, float] = {}
    for f in fields:
        node: Any = data
        for part in f.split("."):
            if not isinstance(node, dict) or part not in node:
                node = None
                break
            node = node[part]
        if node is None:
            out[f] = math.nan
        elif isinstance(node, bool) or not isinstance(node, (int, float)):
            raise ParamError(f"inputs[{f}]", node, "the template field must be a number to be sampled")
        else:
            out[f] = float(node)
    return out
