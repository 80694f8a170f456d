"""A material's name carries its physics: one materials table for every mechanism, a name sets
its expansion coefficient, a coefficient given beside it wins and is said to be given, an
unknown name without one is refused in one line.

Before: in the differential the name and the coefficient were separate keys, so
``--set 'materials.housing="grey cast iron"'`` kept aluminium's 23.6e-6/K and a "42CrMo4 steel"
shaft kept titanium's, silently.
"""

from __future__ import annotations

import pytest

import gearcheck
from conftest import TEMPLATES
from gearcheck.cli import main
from gearcheck.geometry import materials

DIFF = TEMPLATES / "zhurong_differential.toml"


def _materials(*overrides: str):
    return gearcheck.load(DIFF, overrides=list(overrides))


def test_the_template_keeps_its_given_coefficients():
    d = _materials()
    m = d.params.materials
    assert (m.housing_cte_per_K, m.shaft_cte_per_K, m.gear_cte_per_K) == (23.6e-6, 8.8e-6, 10.8e-6)
    assert set(m.cte_sources.values()) == {"given"}


@pytest.mark.parametrize("member, name, table", [
    ("housing", "grey cast iron", "cast iron"),
    ("shaft", "42CrMo4 steel", "steel"),
    ("gear", "PA66 moulded", "polyamide (PA66)"),
])
def test_a_new_name_brings_its_own_coefficient(member, name, table):
    d = _materials(f'materials.{member}="{name}"')
    m = d.params.materials
    assert getattr(m, f"{member}_cte_per_K") == materials.find(name).cte_per_K
    assert m.cte_sources[member] == table
    # the run records the coefficient it used (params.toml)
    assert d.resolved_data["materials"][f"{member}_cte_per_K"] == materials.find(name).cte_per_K
    # the others keep the template's
    others = [k for k in ("housing", "shaft", "gear") if k != member]
    assert all(m.cte_sources[k] == "given" for k in others)


def test_the_new_name_changes_the_physics():
    """The cold backlash follows the housing's expansion: a cast-iron housing shrinks less
    than aluminium, so it loses less play on cooling than the aluminium one."""
    alu = _materials().calc()
    iron = _materials('materials.housing="grey cast iron"').calc()
    assert iron["cold_drop_per_side_arcmin"] < 0.8 * alu["cold_drop_per_side_arcmin"]


def test_a_given_coefficient_wins():
    m = _materials('materials.housing="grey cast iron"', "materials.housing_cte_per_K=11e-6").params.materials
    assert m.housing_cte_per_K == 11e-6 and m.cte_sources["housing"] == "given"


def test_an_unknown_name_without_a_coefficient_is_one_line(capsys):
    assert main(["calc", str(DIFF), "--set", 'materials.housing="unobtainium"']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "materials.housing" in err[0] and "unobtainium" in err[0]
    assert "cast iron" in err[0] and "housing_cte_per_K" in err[0]


def test_an_unknown_name_with_a_coefficient_is_fine():
    m = _materials('materials.housing="unobtainium"', "materials.housing_cte_per_K=5e-6").params.materials
    assert m.housing_cte_per_K == 5e-6


def test_one_table_for_every_mechanism():
    """The assembly finds a material by the same keywords (one table, gearcheck.geometry.materials)."""
    from gearcheck.mechanisms.assembly import params as assembly_params

    assert assembly_params.materials is materials
