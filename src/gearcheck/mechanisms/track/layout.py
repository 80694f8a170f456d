"""The numbers the track drive's CAD is built from (numpy only): the sprocket spec (ISO 606
groove, rows, hub, bore), the link section and the chain segment wrapped at θ = 0.

One source of truth for two users: the mechanism's assembly (:mod:`.assembly`) poses these
specs, which :mod:`gearcheck.cad.sprocket` turns into solids, and the template model
(:mod:`gearcheck.mechanisms.track.params`) builds the same layout in its validator, so a
parameter set the CAD could not build is rejected first, with a one-line error. Each function
raises ``ValueError`` (:class:`~gearcheck.geometry.iso606.ToothFormError` for the groove) when
the numbers leave no valid part.
"""

from __future__ import annotations

from dataclasses import dataclass

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.geometry.sprocket import SprocketSpec
from gearcheck.mechanisms.track import analysis

# Depth of the middle (guide-lug) groove's floor below the root circle r = d/2 − ri. The paper's
# Fig. 8 is lost; 6 mm leaves the track's guide lugs room to hang 6 mm below the seating bottom.
MIDDLE_GROOVE_DEPTH_MM = 6.0
# Shaft bore (not given by the paper; ~27 N·m per sprocket needs far less than 25 mm of steel).
BORE_DIAMETER_MM = 25.0
# The default segment and its wrap (see track_chain.ChainWrap): upper run horizontal, arriving
# from +x at the top, 120° of wrap, lower run leaving 30° below horizontal towards +x (a raised
# drive sprocket); the links the wrap seats plus 2 on each run (z = 49: 12 links, 8 seated at θ = 0).
DEFAULT_RUN_LINKS = 2
DEFAULT_ENTRY_ANGLE_DEG = 90.0
DEFAULT_WRAP_ANGLE_DEG = 120.0


class BoreTooLarge(ValueError):
    """The shaft bore does not fit under the middle groove's floor."""


class RowsWithoutGroove(ValueError):
    """Two or more tooth rows with no middle groove between them (a zero-length hub)."""


def hub_radius_mm(pitch_diameter_mm: float, seating_radius_mm: float,
                  middle_groove_depth_mm: float = MIDDLE_GROOVE_DEPTH_MM) -> float:
    """Radius of the middle groove's floor: the root circle d/2 − ri less the groove depth."""
    return pitch_diameter_mm / 2.0 - seating_radius_mm - middle_groove_depth_mm


def sprocket_spec(params, middle_groove_depth_mm: float = MIDDLE_GROOVE_DEPTH_MM,
                  bore_diameter_mm: float = BORE_DIAMETER_MM) -> SprocketSpec:
    """The template's sprocket: eq. 6–8 diameters and the chosen ISO 606 form."""
    sp, ch = params.sprocket, params.chain
    d = iso606.every_other_tooth_pitch_diameter(ch.pitch_mm, sp.teeth)
    gap = iso606.tooth_gap(d, sp.teeth, sp.seating_radius_mm, sp.flank_radius_mm, sp.seating_angle_deg,
                           d + sp.tip_over_pitch_mm)
    if sp.tooth_rows > 1 and not sp.middle_groove_width_mm > 0.0:
        raise RowsWithoutGroove("tooth rows need a middle groove between them")
    hub = hub_radius_mm(d, gap.seating_radius_mm, middle_groove_depth_mm)
    if not bore_diameter_mm / 2.0 < hub:
        raise BoreTooLarge("bore larger than the middle groove's floor")
    return SprocketSpec(gap, sp.tooth_width_mm, sp.tooth_rows, sp.middle_groove_width_mm, hub,
                        bore_diameter_mm / 2.0)


def link_geometry(params, gap: iso606.ToothGap) -> tc.LinkGeometry:
    """The link section: plate offset e solved from the template's tip gap (the analysis owns
    e = gap + tip − pin line), sleeve and plate across the track width."""
    ch = params.chain
    e = analysis.plate_offset_for_tip_gap(gap, params.track_plate.tip_gap_mm)
    return tc.link_geometry(ch.pitch_mm, ch.sleeve_diameter_mm, e, ch.track_width_mm)


def default_wrap(teeth: int, pitch_mm: float, links: int | None = None,
                 entry_angle_deg: float = DEFAULT_ENTRY_ANGLE_DEG,
                 wrap_angle_deg: float = DEFAULT_WRAP_ANGLE_DEG,
                 run_links: int = DEFAULT_RUN_LINKS) -> tc.ChainWrap:
    """The chain segment `gearcheck build` wraps on the sprocket (the wrap's links plus
    ``run_links`` on each run, unless ``links`` is given)."""
    return tc.ChainWrap.centred(teeth, pitch_mm, links, entry_angle_deg, wrap_angle_deg, run_links)


@dataclass(frozen=True)
class TrackLayout:
    sprocket: SprocketSpec
    link: tc.LinkGeometry
    wrap: tc.ChainWrap


def track_layout(params) -> TrackLayout:
    """Everything the default build needs, checked: raises ValueError where no part is left."""
    spec = sprocket_spec(params)
    return TrackLayout(spec, link_geometry(params, spec.gap),
                       default_wrap(params.sprocket.teeth, params.chain.pitch_mm))
