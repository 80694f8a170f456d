"""The sweep budget: a sweep that would take the machine for hours (or fill its memory) is never
started. A mechanism whose cost grows with what the user declares (the ``assembly``: parts ×
poses) says before its sweep what it will cost (:class:`SweepCost`, in its
:class:`~gearcheck.mechanism.SweepPlan`): the pairs it queries at every pose *after pruning*
(pairs whose parts never come near over the motion are never queried), the poses and states,
and the cost of one pair at one pose *measured* on a sample of its own pairs and poses (the same
code the tasks run: queries, overlaps, the clearance certified between the poses).

The pipeline states that figure before the sweep starts (the progress display, the log), and
compares it with the budget (:data:`SWEEP_BUDGET_CPU_S` CPU seconds, ``--budget``; memory:
:data:`SWEEP_MEMORY_GB`). Over it, the run is refused in one line naming the setting that sets
the poses and the value that would fit (:meth:`SweepCost.refusal`), nothing written; the poses
are the user's own choice, so they are never coarsened behind the user's back. After the sweep
the measured CPU seconds stand beside the prediction (manifest.json ``sweep_cost``, the report).
Pure: no numpy, CadQuery or FCL.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from gearcheck.params import ParamError

# The most CPU seconds a sweep may be predicted to take (every worker's together; --budget).
SWEEP_BUDGET_CPU_S = 3600.0
# The most memory a sweep's results may be predicted to hold (GB; the meshes have their own
# budget, gearcheck.resolution.TRIANGLE_BUDGET).
SWEEP_MEMORY_GB = 4.0
# A sweep predicted to take at least this many CPU seconds is announced (a line before it starts,
# progress lines where stderr is not a terminal).
ANNOUNCE_CPU_S = 10.0
# A step named as fitting the budget is one whose prediction holds at most this share of it.
FIT_SHARE = 0.9


@dataclass(frozen=True)
class SweepCost:
    """What a sweep will cost, predicted before it starts. Per state, every queried pair at every
    pose (``pair_pose_s`` each), the play measurement at every pose (``play_pose_s``), the pairs
    the motion does not move at the first pose only; once per worker and state, the BVHs
    (``setup_s``). ``setting`` is the template field that sets the poses (with its ``value``,
    ``unit`` and the motion's ``extent``; ``extent`` 0: a list of stops, counted)."""

    poses: int
    states: int
    pairs: int  # queried at every pose (the motion moves them relative to each other), after pruning
    static_pairs: int  # queried at the first pose only
    pruned_pairs: int  # never within the pruning margin: never queried
    pair_pose_s: float  # one pair at one pose, measured (queries, overlap, the certificate's share)
    play_pose_s: float  # one play measurement (both ways) at one pose, measured (0: no play part)
    setup_s: float  # the BVHs of one state's meshes, once per worker (estimated from the sample's)
    calibration_s: float  # what the measurement itself took (before the sweep, in this process)
    setting: str
    value: float
    unit: str
    extent: float
    bytes_per_pair_pose: float = 400.0  # results held and written: arrays, sweep.csv's cells

    @property
    def pose_s(self) -> float:
        """CPU seconds of one pose in every state."""
        return self.states * (self.pairs * self.pair_pose_s + self.play_pose_s)

    def fixed_s(self, workers: int = 1) -> float:
        """CPU seconds that do not grow with the poses."""
        return self.states * (self.static_pairs * self.pair_pose_s + max(1, workers) * self.setup_s)

    def cpu_s(self, workers: int = 1) -> float:
        """The predicted CPU seconds of the whole sweep (every worker's together)."""
        return self.fixed_s(workers) + self.poses * self.pose_s

    @property
    def memory_gb(self) -> float:
        """The predicted memory of the results (every pair at every pose and state)."""
        return self.poses * self.states * (self.pairs + self.static_pairs) * self.bytes_per_pair_pose / 1e9

    def describe(self, workers: int = 1, budget_s: float | None = None) -> str:
        """One line: the prediction and what it is made of."""
        play = f" + play {1e3 * self.play_pose_s:.3g} ms a pose" if self.play_pose_s else ""
        states = f" × {self.states} states" if self.states > 1 else ""
        static = f", {self.static_pairs} more at the first pose" if self.static_pairs else ""
        head = (f"about {self.cpu_s(workers):.0f} CPU s: {self.poses} poses{states} × {self.pairs} pairs × "
                f"{1e3 * self.pair_pose_s:.3g} ms{play}{static} ({self.pruned_pairs} pairs never near: not queried)")
        if budget_s is not None:
            head += f"; budget {budget_s:g} CPU s"
        return head

    def fitting_poses(self, budget_s: float, memory_gb: float, workers: int = 1) -> int:
        """The most poses that fit both budgets (with :data:`FIT_SHARE` to spare)."""
        by_time = (FIT_SHARE * budget_s - self.fixed_s(workers)) / self.pose_s if self.pose_s > 0 else math.inf
        per_pose_gb = self.memory_gb / self.poses if self.poses else 0.0
        by_memory = FIT_SHARE * memory_gb / per_pose_gb if per_pose_gb > 0 else math.inf
        return int(max(0.0, min(by_time, by_memory, 1e12)))

    def fitting_value(self, poses: int) -> float | None:
        """The setting's value that gives at most ``poses`` poses (None: fewer than two)."""
        if poses < 2:
            return None
        if self.extent <= 0.0:  # a list of stops: their count
            return float(poses)
        step = self.extent / (poses - 1)
        rounded = float(f"{step:.2g}")
        return rounded if rounded >= step else float(f"{step * 1.05:.2g}")

    def refusal(self, budget_s: float, memory_gb: float, workers: int = 1) -> ParamError | None:
        """The one line that refuses a sweep over either budget (None: within both)."""
        over_time = self.cpu_s(workers) > budget_s
        over_memory = self.memory_gb > memory_gb
        if not (over_time or over_memory):
            return None
        within = (f"the budget of {budget_s:g} CPU s" if over_time and not over_memory else
                  f"the memory budget of {memory_gb:g} GB" if not over_time else
                  f"the budgets of {budget_s:g} CPU s and {memory_gb:g} GB")
        predicted = (f"predicted {self.cpu_s(workers):.0f} CPU s, {self.memory_gb:.2g} GB at {self.poses} poses: "
                     f"{self.pairs} pairs × {1e3 * self.pair_pose_s:.3g} ms a pose")
        raise_it = "raise --budget" if over_time and not over_memory else "check fewer pairs (ignore = true)"
        fit = self.fitting_value(self.fitting_poses(budget_s, memory_gb, workers))
        pairs = f"this assembly's {self.pairs} pairs"
        if fit is None:
            fixed = self.fixed_s(workers)
            return ParamError(self.setting, self.value,
                              f"no motion fits {within} with {pairs} ({predicted}; the pairs and BVHs alone take "
                              f"{fixed:.0f} CPU s: {raise_it})")
        allowed = (f"allowed ≥ {fit:g} {self.unit}" if self.extent > 0.0 else f"allowed at most {fit:g} stops")
        return ParamError(self.setting, self.value if self.extent > 0.0 else f"{self.poses} stops",
                          f"{allowed} for {pairs} within {within} ({predicted}; or {raise_it})")

    def record(self, workers: int, budget_s: float, actual_cpu_s: float | None, wall_s: float | None) -> dict:
        """The prediction beside what the sweep took (manifest.json ``sweep_cost``; timings, so
        not in summary.json, which a re-run reproduces byte for byte)."""
        out: dict = {"predicted_cpu_s": round(self.cpu_s(workers), 3), "budget_cpu_s": budget_s,
                     "predicted_memory_gb": round(self.memory_gb, 4), "memory_budget_gb": SWEEP_MEMORY_GB,
                     "workers": workers, "poses": self.poses, "states": self.states, "pairs_every_pose": self.pairs,
                     "pairs_first_pose": self.static_pairs, "pairs_never_near": self.pruned_pairs,
                     "ms_per_pair_pose": round(1e3 * self.pair_pose_s, 5),
                     "ms_per_play_pose": round(1e3 * self.play_pose_s, 4), "setup_s": round(self.setup_s, 4),
                     "calibration_s": round(self.calibration_s, 4)}
        if actual_cpu_s is not None:
            out["actual_cpu_s"] = round(actual_cpu_s, 3)
            out["actual_over_predicted"] = round(actual_cpu_s / max(self.cpu_s(workers), 1e-9), 3)
        if wall_s is not None:
            out["wall_s"] = round(wall_s, 3)
        return out

    def note(self, workers: int, budget_s: float, actual_cpu_s: float | None) -> str:
        """The report's sentence: predicted before, measured after."""
        actual = f"; it took {actual_cpu_s:.1f} CPU s" if actual_cpu_s is not None else ""
        return (f"Sweep cost: predicted before the sweep {self.describe(workers, budget_s)}, the cost of a pair "
                f"at a pose measured on a sample of them{actual}.")
