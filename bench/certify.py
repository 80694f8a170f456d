"""What certifying the sweeps over the continuous motion costs (`make bench`, section "certify").

The three templates' sweeps and the roller chain's (the whole mechanism check on the meshes: plan, workers, reduce with
its certificates) on one worker, in a fresh process each, at the commit before the certified
sweeps (:data:`PRE_CERTIFY_COMMIT`, checked out into a temporary worktree as bench/run.py does for
its baseline) and on the current code, alternating; each figure is the median CPU seconds (the
process and its workers) of ``repeat`` runs. The target: the current code within
:data:`RATIO_TARGET` of the commit before, per template.

Run alone: ``python bench/certify.py`` (prints its JSON).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

BENCH = Path(__file__).resolve().parent
PRE_CERTIFY_COMMIT = "667762d"  # the last commit before clearances were certified over the continuous motion
RATIO_TARGET = 1.3


def _cpu(runs: list[dict]) -> list[float | None]:
    return [r.get("runs", {}).get("jobs_1", {}).get("cpu_s") for r in runs if r.get("ok", True)]


# Beside the three papers' templates: the roller chain's (certified too; the same template at both commits).
MORE_TEMPLATES = {"roller_chain": "roller_chain_12B_z21"}


def _probe(run_probe: Callable[[Any, list[str]], dict], mech: str) -> Callable[[Any], dict]:
    """The sweep probe of one template's mechanism on one worker, on a side."""
    def measure(side: Any) -> dict:
        template = (side.root / "templates" / f"{MORE_TEMPLATES[mech]}.toml" if mech in MORE_TEMPLATES
                    else side.template(mech))
        return run_probe(side, ["sweep", str(template), "--jobs", "1"])

    return measure


def bench_certify(repeat: int = 3) -> dict[str, Any]:
    sys.path[:0] = [str(BENCH)]
    from run import TEMPLATES, Step, alternate, baseline_worktree, current_side, median, ratio, run_probe, \
        verify_and_warm

    current = current_side()
    raw: dict[str, dict[str, list]] = {"baseline": {}, "current": {}}
    with baseline_worktree(PRE_CERTIFY_COMMIT) as before:
        for side in (before, current):
            verify_and_warm(side)
        mechs = [*TEMPLATES, *MORE_TEMPLATES]
        steps = [Step(f"sweep_{m}", f"sweep {m} (1 worker)", _probe(run_probe, m)) for m in mechs]
        alternate([before, current], steps, repeat, raw)
        before_sha = before.commit
    out: dict[str, Any] = {"pre_certify_commit": PRE_CERTIFY_COMMIT, "pre_certify_sha": before_sha,
                           "current_commit": current.commit, "repeat": repeat}
    for mech in mechs:
        pre, cur = median(_cpu(raw["baseline"][f"sweep_{mech}"])), median(_cpu(raw["current"][f"sweep_{mech}"]))
        r = ratio(cur, pre)
        out[mech] = {"pre_certify_cpu_s": pre, "current_cpu_s": cur, "ratio": r, "target": f"≤ {RATIO_TARGET}×",
                     "met": r is not None and r <= RATIO_TARGET,
                     "runs": {"pre_certify": _cpu(raw["baseline"][f"sweep_{mech}"]),
                              "current": _cpu(raw["current"][f"sweep_{mech}"])}}
    return out


if __name__ == "__main__":
    print(json.dumps(bench_certify(), indent=1))
