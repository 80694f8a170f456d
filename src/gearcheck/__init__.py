"""gearcheck: parameter file → involute CAD (STEP/STL) → FCL interference sweep → report.

As a library::

    import gearcheck
    d = gearcheck.load("templates/zhurong_differential.toml", overrides={"shim.thickness_mm": 0.15})
    d.calc().to_dict()            # the analytical model (numpy only)
    r = d.check(out="out/x")      # CAD, meshes, sweep, report files; r.passed, r.verdicts, r.summary
    s = gearcheck.study("differential_tolerances.toml", samples=512, out="out/study")  # s.table, s.summary

``import gearcheck``, :func:`load` and ``calc`` import neither CadQuery nor FCL: everything
below is imported on first use.
"""

from __future__ import annotations

import importlib

# Not ``from typing import TYPE_CHECKING``: importing typing costs the command line ~20 ms before
# it can install its interrupt handlers (type checkers read this name the same way).
TYPE_CHECKING = False

__version__ = "0.1.0"

__all__ = [
    "CheckResult", "Comparison", "Design", "Mechanism", "ParamError", "Plot", "StudyResult", "Verdict", "WorstPose",
    "__version__", "load", "mechanism_names", "new", "study",
]

# name → (module, attribute); resolved lazily by __getattr__
_LAZY = {
    "load": ("gearcheck.design", "load"),
    "new": ("gearcheck.new_template", "new"),
    "study": ("gearcheck.studies.core", "study"),
    "StudyResult": ("gearcheck.studies.core", "StudyResult"),
    "Design": ("gearcheck.design", "Design"),
    "ParamError": ("gearcheck.params.common", "ParamError"),
    "Mechanism": ("gearcheck.mechanism", "Mechanism"),
    "CheckResult": ("gearcheck.results", "CheckResult"),
    "Comparison": ("gearcheck.results", "Comparison"),
    "Plot": ("gearcheck.results", "Plot"),
    "Verdict": ("gearcheck.results", "Verdict"),
    "WorstPose": ("gearcheck.results", "WorstPose"),
}

if TYPE_CHECKING:
    from typing import Any

    from gearcheck.design import Design, load
    from gearcheck.mechanism import Mechanism
    from gearcheck.new_template import new
    from gearcheck.params.common import ParamError
    from gearcheck.results import CheckResult, Comparison, Plot, Verdict, WorstPose
    from gearcheck.studies.core import StudyResult, study


def mechanism_names() -> list[str]:
    """Names of the registered mechanisms (entry-point group ``gearcheck.mechanisms``)."""
    from gearcheck.mechanism import names

    return names()


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        module, attr = _LAZY[name]
        value = getattr(importlib.import_module(module), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'gearcheck' has no attribute {name!r}")
