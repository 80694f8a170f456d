"""The CAD hook: the differential's solids from its part specs (bevel gears from their
:class:`~gearcheck.geometry.bevel.BevelGearSpec`, shafts, shims and housing walls from their
ring specs), one solid per distinct spec, placed as :mod:`.assembly` says."""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearcheck.geometry.bevel import BevelGearSpec
from gearcheck.geometry.solids import Ring, RingStack

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.mechanism import Assembly


def _solid(spec):
    from gearcheck.cad.bevel import build_bevel_gear
    from gearcheck.cad.primitives import build_ring, build_ring_stack

    if isinstance(spec, BevelGearSpec):
        return build_bevel_gear(spec).solid
    if isinstance(spec, RingStack):
        return build_ring_stack(spec)
    if isinstance(spec, Ring):
        return build_ring(spec)
    raise TypeError(f"no CAD builder for {type(spec).__name__}")


def build_parts(assembly: Assembly) -> list[Part]:
    from gearcheck.cad.placement import Part

    solids = {key: _solid(spec) for key, spec in assembly.solids.items()}
    return [Part(p.name, p.material, solids[p.solid], p.pose, p.color, p.motion) for p in assembly.parts]
