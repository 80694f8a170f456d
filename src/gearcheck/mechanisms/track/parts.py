"""The track drive's CAD hook: solids for the assembly's part specs (the only module of the
mechanism that touches :mod:`gearcheck.cad`). The sprocket and the link solid are each built
once; every link part shares the link solid and its plate and sleeve features."""

from __future__ import annotations

from typing import TYPE_CHECKING

from gearcheck.mechanisms.track.assembly import LINK, SPROCKET

if TYPE_CHECKING:
    from gearcheck.cad.placement import Part
    from gearcheck.mechanism import Assembly


def build_parts(assembly: Assembly) -> list[Part]:
    """One :class:`~gearcheck.cad.placement.Part` per spec, in the assembly's order."""
    from gearcheck.cad.placement import Part
    from gearcheck.cad.sprocket import build_link, build_sprocket

    sprocket = build_sprocket(assembly.solids[SPROCKET])
    link = build_link(assembly.solids[LINK])
    solids = {SPROCKET: sprocket, LINK: link.link}
    features = {"plate": link.plate, "sleeve": link.sleeve}
    return [Part(spec.name, spec.material, solids[spec.solid], spec.pose, spec.color, spec.motion,
                 {name: features[name] for name in spec.features})
            for spec in assembly.parts]
