"""Sizes and materials of the steering parts that the paper does not give, and the one build
condition they add: used by the assembly (the part specs the CAD builds from) and by the template
model, which rejects a set the CAD could not build before any CAD work.
"""

from __future__ import annotations

from gearcheck.geometry import rack_pinion as rp

# Face width of pinion and rack (not in the paper): b = 7.5·m, a usual 6–10·m for a through-
# hardened steel rack drive; it changes no kinematic figure. A template input if strength is ever
# checked.
FACE_WIDTH_MM = 30.0
# Pinion bore (not in the paper; the pinion sits on the steering collar). It must stay inside
# the root circle (79 mm), where nothing meets the rack.
PINION_BORE_DIAMETER_MM = 60.0
# Rack body under its teeth, in modules: the rack's root line lies this far above its datum
# (mounting face). The paper's rack, root 18 mm above the datum at m = 4, scaled with the module;
# `gearcheck new` sets the centre height H from it (H = r + x·m + (rack dedendum + this)·m).
RACK_ROOT_MODULES = 4.5
# Materials (not in the paper; aircraft steering gears are through-hardened alloy steel).
PINION_MATERIAL = "steel"
RACK_MATERIAL = "steel"


def bore_fits(root_radius_mm: float, bore_diameter_mm: float = PINION_BORE_DIAMETER_MM) -> bool:
    """The pinion bore lies strictly inside the root circle (a ring of material is left)."""
    return rp.bore_fits(root_radius_mm, bore_diameter_mm)
