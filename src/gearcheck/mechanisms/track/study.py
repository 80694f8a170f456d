"""The track drive's figures for a study (numpy only, no mesh): the exact 2-D model of the new
chain and of the chain at the variant's wear.

A link "jumps" when, at the chain's elongation, it fails to seat in its groove (the sleeve rides
up the driving flank to the tip or past it) or the worn chain's sweep meets the sprocket; the tip
touches the plate when the least exact tip-to-plate distance reaches 0."""

from __future__ import annotations

from gearcheck.geometry.track_section import ExactSection
from gearcheck.mechanisms.track import wear as track_wear
from gearcheck.mechanisms.track.assembly import TrackModel


def exact_row(model: TrackModel) -> dict[str, float]:
    """Exact figures of one variant: new chain and worn chain (at ``model.wear_elongation``)."""
    section = ExactSection(model.gap, model.link)
    new = track_wear.sweep_check(model.gap, model.link, model.wrap, 0.0, exact=section)
    worn = track_wear.sweep_check(model.gap, model.link, model.wrap, model.wear_elongation, exact=section)
    seat = track_wear.seat_check(model.gap, model.link.sleeve_radius_mm, model.wear_elongation)
    tip_limit = track_wear.tip_limit_closed_form(model.gap, model.link.sleeve_radius_mm)
    jumps = not (seat.ok and worn.ok)
    return {
        "min_tip_plate_mm": min(new.min_plate_mm, worn.min_plate_mm),
        "min_tooth_sleeve_mm": new.min_sleeve_mm,
        "worn_min_tip_plate_mm": worn.min_plate_mm,
        "worn_min_tooth_sleeve_mm": worn.min_sleeve_mm,
        "wear_pct": 100.0 * model.wear_elongation,
        "wear_limit_tip_pct": 100.0 * tip_limit,
        "wear_margin_pct": 100.0 * (tip_limit - model.wear_elongation),
        "link_seats": float(seat.ok),
        "link_jumps": float(jumps),
    }
