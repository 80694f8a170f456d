"""Tooth contact analysis benchmarks (`make bench`, section "tca"), CPU seconds on one core, the
median of a few runs: one bevel pair at one thermal state (TE over two mesh cycles and both
flanks' contact patterns) against its 2 s budget, everything the differential's check adds to
summary.json ``tca``, one variant of a study's "contact" level, and the steering's TE (its curves
and its figures under the mounting errors)."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
TEMPLATES = ROOT / "src" / "gearcheck" / "templates"
REPEAT = 5
PAIR_BUDGET_CPU_S = 2.0


def _cpu(call, repeat: int = REPEAT) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        call()
        times.append(time.process_time() - t0)
    return statistics.median(times)


def bench_tca() -> dict[str, Any]:
    from gearcheck.design import load_template
    from gearcheck.mechanisms.differential import tca as dt
    from gearcheck.mechanisms.differential.poses import gear_specs
    from gearcheck.mechanisms.steering import analysis as an
    from gearcheck.mechanisms.steering.tca import steering_tca

    diff = load_template(TEMPLATES / "zhurong_differential.toml")
    params: Any = diff.params
    specs = gear_specs(params)
    warm = params.operating.warm_C
    pair = _cpu(lambda: dt.state_tca(params, specs, params.shim.thickness_mm, "warm", warm))

    def whole_check() -> None:
        pairs = list(dt.design_tca(params).values())
        for p in pairs:
            if p.name in ("warm", "cold"):
                dt.sensitivity(specs, p)

    check = _cpu(whole_check, 2)
    contact = _cpu(lambda: dt.study_figures(params, specs))
    steer = load_template(TEMPLATES / "nose_wheel_steering.toml")
    steer_params: Any = steer.params
    g = an.geometry_from_params(steer_params)
    tow = an.analyse_towing(g, steer_params.towing.max_angle_deg)
    steering = _cpu(lambda: steering_tca(g, tow), 2)
    return {"pair_state_cpu_s": pair, "pair_state_budget_cpu_s": PAIR_BUDGET_CPU_S,
            "pair_state_meets_budget": pair <= PAIR_BUDGET_CPU_S,
            "differential_check_tca_cpu_s": check, "contact_level_variant_cpu_s": contact,
            "steering_tca_cpu_s": steering}


if __name__ == "__main__":
    import json

    print(json.dumps(bench_tca(), indent=1))
