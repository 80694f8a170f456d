"""The track drive's parts as data (numpy only): the sprocket and a chain segment wrapped on it at
drive angle θ = 0, their specs, poses and motions, and the layout the sweep works from.

Poses (:mod:`gearcheck.geometry.track_chain`): at drive angle θ the sprocket is
``sprocket_matrix(θ)`` (a rotation about +z through the origin) and link j is
``wrap.link_matrices(θ)[j]`` (a :class:`~gearcheck.sweep.motion.ChainLink`: posed by the wrap,
not by a rigid motion of its own). Every link is a copy of one link solid.
"""

from __future__ import annotations

from dataclasses import dataclass

from gearcheck.geometry import iso606
from gearcheck.geometry import track_chain as tc
from gearcheck.mechanism import Assembly, PartSpec
from gearcheck.mechanisms.track import layout
from gearcheck.sweep.motion import ChainLink, Rotation

SPROCKET, LINK = "sprocket", "link"
SPROCKET_MATERIAL = "7075-T651 aluminium alloy"
LINK_MATERIAL = "cast aluminium track link with steel sleeve"
SPROCKET_COLOR = (0.75, 0.75, 0.8)
LINK_COLOR = (0.3, 0.3, 0.35)
# Sub-solids of a link the CAD hook builds with it, for exact confirmations ("link_03.plate").
LINK_FEATURES = ("plate", "sleeve")


@dataclass(frozen=True)
class TrackModel:
    """The template's sprocket groove, wrap and link section, derived from the parameters once."""

    gap: iso606.ToothGap
    wrap: tc.ChainWrap
    link: tc.LinkGeometry
    tip_gap_mm: float  # template input: the gap the plate offset was solved for
    required_gap_min_mm: float
    required_gap_max_mm: float
    wear_elongation: float = 0.0  # declared pitch growth by wear (fraction), chain.wear_elongation_pct / 100

    @property
    def sleeve_radius_mm(self) -> float:
        return self.link.sleeve_radius_mm

    def key(self) -> tuple:
        g, w = self.gap, self.wrap
        return (g.teeth, g.pitch_radius_mm, g.seating_radius_mm, g.flank_radius_mm, g.seating_angle_rad,
                g.tip_radius_mm, self.link, w)

    def section_key(self) -> tuple:
        """What the exact 2-D section depends on (not the wrap): the groove and the link."""
        return self.key()[:-1]

    @property
    def seating_clearance_mm(self) -> float:
        """ri − R: a sleeve centred on its seating centre, concentric with the seating arc."""
        return self.gap.seating_radius_mm - self.link.sleeve_radius_mm


def link_name(index: int) -> str:
    return f"link_{index:02d}"


def track_assembly(params) -> Assembly:
    """Sprocket + the default chain segment (:func:`.layout.track_layout`) at θ = 0."""
    lay = layout.track_layout(params)
    tp = params.track_plate
    model = TrackModel(lay.sprocket.gap, lay.wrap, lay.link, tp.tip_gap_mm, tp.required_gap_min_mm,
                       tp.required_gap_max_mm, params.chain.wear_elongation_pct / 100.0)
    poses = lay.wrap.link_matrices(0.0)
    parts = [PartSpec(SPROCKET, SPROCKET, SPROCKET_MATERIAL, tc.sprocket_matrix(0.0), SPROCKET_COLOR,
                      Rotation.about((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)))]
    parts += [PartSpec(link_name(j), LINK, LINK_MATERIAL, poses[j], LINK_COLOR, ChainLink(j), LINK_FEATURES)
              for j in range(lay.wrap.links)]
    return Assembly("track", tuple(parts), {SPROCKET: lay.sprocket, LINK: lay.link}, model)
