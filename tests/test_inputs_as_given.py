"""The report's inputs table shows what the user did, and only that.

Before: an assembly run without any --set listed "with overrides: assembly.step =
"/abs/path/rp.step"" (the path the run resolved, which also leaked the user's folders into a
report meant for customers); a coefficient the run took from a material's name was not told
apart from one the user gave.
"""

from __future__ import annotations

import gearcheck
from conftest import TEMPLATES
from gearcheck.report.inputs import input_rows


def test_an_assembly_without_overrides_shows_none():
    design = gearcheck.load(TEMPLATES / "assembly_spur_pair.toml")
    rows = input_rows(design, [])
    assert not [r.key for r in rows if r.overridden]
    assert not any(str(TEMPLATES) in r.value or str(TEMPLATES.resolve()) in r.value for r in rows)
    step = next(r for r in rows if r.key == "assembly.step")
    assert step.value == '"assembly_spur_pair.step"'


def test_a_coefficient_from_a_new_name_is_shown_as_derived():
    setting = 'materials.housing="grey cast iron"'
    design = gearcheck.load(TEMPLATES / "zhurong_differential.toml", overrides=[setting])
    rows = {r.key: r for r in input_rows(design, [setting])}
    cte = rows["materials.housing_cte_per_K"]
    assert cte.overridden and cte.value == "1.05e-05" and cte.template_value == "2.36e-05"
    assert "material's name" in cte.note
    assert not rows["materials.shaft_cte_per_K"].overridden


def test_no_field_description_quotes_the_paper():
    """Before: "Module m (paper: 4; see docs/steering.md for why not 5)" and "the paper's test: 0,
    0.05, 0.10, 0.15" stood in the inputs table beside a user's own design. Paper values belong
    beside the paper's own design only (its comparison rows), never in what a field is."""
    from gearcheck import mechanism as registry
    from gearcheck.schema import _models

    for name in registry.names():
        for model in _models(registry.get(name).Params, {}).values():
            for key, info in model.model_fields.items():
                assert "paper" not in (info.description or "").lower(), (name, key, info.description)
