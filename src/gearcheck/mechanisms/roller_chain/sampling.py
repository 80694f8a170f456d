"""Random roller-chain designs for `make fuzz` and the property tests: any chain of the ISO 606
table, 1–3 strands, any tooth count and form, the tip diameter across (and now and then past) the
range that leaves a tooth, the other knobs around their ISO 606 values."""

from __future__ import annotations

from gearcheck.geometry import iso606_chains
from gearcheck.mechanisms.roller_chain.params import MAX_TEETH, MIN_TEETH
from gearcheck.mechanisms.sampling import Draw, _int_knob, _knob


def sample_chain(data: dict, draw: Draw) -> None:
    names = iso606_chains.DESIGNATIONS
    size = iso606_chains.chain(names[draw.integer(0, len(names) - 1)])
    strands = _int_knob(draw, 1, 3, 1)
    z = _int_knob(draw, MIN_TEETH, MAX_TEETH, 2)
    form = _knob(draw, 0.0, 1.0, 3)
    data["chain"] = {"designation": size.designation, "strands": strands, "fixed_centres": draw.chance(0.3)}
    p, d1 = size.pitch_mm, size.roller_diameter_mm
    zz = min(max(z, MIN_TEETH), MAX_TEETH)
    ff = min(max(form, 0.0), 1.0)
    lo, hi = iso606_chains.tip_diameter_bounds(p, d1, zz, ff)
    bf = iso606_chains.tooth_width_max(size.inner_width_mm, p, max(1, min(strands, 3)))
    dg = iso606_chains.shroud_diameter_max(p, size.plate_depth_mm, zz)
    data["sprocket"] = {
        "teeth": z,
        "form": form,
        "tip_diameter_mm": _knob(draw, lo + 0.01 * (hi - lo), hi - 0.01 * (hi - lo), 3),
        "tooth_width_mm": _knob(draw, 0.8 * bf, 1.02 * bf, 3),
        "bore_diameter_mm": _knob(draw, 0.0, 0.9 * dg, 1),
    }
    data["drive"] = {"speed_rpm": _knob(draw, 10.0, 3000.0, 1), "power_kW": _knob(draw, 0.0, 50.0, 2),
                     "service_factor": _knob(draw, 1.0, 3.0, 2), "max_speed_ripple_pct": _knob(draw, 0.5, 5.0, 2)}
