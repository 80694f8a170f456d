"""The mechanism contract (gearcheck.testing.MechanismContract), for every registered mechanism:
the shipped ones from the entry-point group, and the spur pair defined in tests/spur_pair.py. A new
mechanism is tested by registering it (its template shipped), or by subclassing the contract as a
plugin does (tests/test_testing_plugin.py runs one from outside this repository).

- ``analyse`` gives finite figures (NaN only where the mechanism documents it) without CadQuery
  or FCL;
- the assembly's poses are rigid transforms, its motions typed, its solids specified;
- the plan's tasks pickle and run in a fresh process that never imports CadQuery, with the same
  result as in this process;
- the check's verdict names are unique, levels valid, and the report files render.
"""

from __future__ import annotations

from pathlib import Path

from gearcheck import mechanism as registry
from gearcheck.testing import MechanismContract
from spur_pair import TEMPLATE as SPUR_TEMPLATE
from spur_pair import SpurPair

ROOT = Path(__file__).resolve().parents[1]


def test_every_shipped_mechanism_is_registered():
    assert {"differential", "track", "steering"} <= set(registry.names())


class TestSpurPair(MechanismContract):
    mechanism = SpurPair
    template = SPUR_TEMPLATE


# one contract class per installed mechanism, on its shipped template (meshed at 0.01 mm)
for _name in registry.names():
    _impl = registry.get(_name)
    assert _impl.template, f"{_name}: a shipped mechanism ships a template"
    globals()[f"Test_{_name}"] = type(f"Test_{_name}", (MechanismContract,), {
        "mechanism": _name, "template": ROOT / "templates" / _impl.template, "tol_mm": 0.01})
