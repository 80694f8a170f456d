"""The CAD hook: the steering part specs as solids (:mod:`gearcheck.cad.rack_pinion`), each
built once, posed, coloured and moved as the assembly says."""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearcheck.mechanism import Assembly

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part


def parts(assembly: Assembly) -> list[Part]:
    """Pinion and rack solids for the specs of ``assembly``, in its part order."""
    from gearcheck.cad.placement import Part
    from gearcheck.cad.rack_pinion import build_pinion, build_rack
    from gearcheck.geometry.rack_pinion import PinionSpec, RackSpec

    def build(spec):
        if isinstance(spec, PinionSpec):
            return build_pinion(spec.geometry, spec.face_width_mm, spec.bore_diameter_mm)
        if isinstance(spec, RackSpec):
            return build_rack(spec.geometry, spec.face_width_mm)
        raise TypeError(f"no steering solid for {type(spec).__name__}")

    solids = {key: build(spec) for key, spec in assembly.solids.items()}
    return [Part(p.name, p.material, solids[p.solid], p.pose, p.color, p.motion) for p in assembly.parts]
