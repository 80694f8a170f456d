"""The differential's tooth contact analysis in the report: the transmission error of each flank
over two mesh cycles (as designed and at each thermal state) and the contact pattern mapped on the
big gear's developed flank, warm and cold."""

from __future__ import annotations

import math

import numpy as np

from gearcheck.geometry import bevel_tca as bt
from gearcheck.mechanisms.differential.tca import PairTca
from gearcheck.mechanisms.differential.temperature import STATE_TEXT
from gearcheck.mechanisms.differential.thermal import BIG_GEARS
from gearcheck.results import FieldMap, Plot, Series
from gearcheck.scene import Overlay

# The states whose patterns are mapped: the two the paper's question is about.
MAPPED = ("warm", "cold")


def pair_text(pair: PairTca) -> str:
    """"as designed" or "warm 25 °C"."""
    if pair.name == "aligned":
        return "as designed"
    return f"{STATE_TEXT.get(pair.name, pair.name)} {pair.temperature_C:g} °C"


def te_plots(pairs: list[PairTca]) -> list[Plot]:
    """TE − its mean of the drive and the coast flank (µrad of the big gear), each pair a line."""
    out = []
    for flank in ("drive", "coast"):
        series = []
        for pair in pairs:
            te = pair.te.drive_rad if flank == "drive" else pair.te.coast_rad
            micro = 1e6 * te
            series.append(Series(f"{pair_text(pair)}: p-p {np.ptp(micro):.3g} µrad, mean {np.mean(micro):.4g} µrad",
                                 np.degrees(pair.te.drive_angles_rad).tolist(), (micro - micro.mean()).tolist()))
        out.append(Plot(f"Transmission error of the {flank} flank over two mesh cycles", "small-gear drive angle (deg)",
                        "TE less its mean (µrad of the big gear)", series,
                        caption=(f"The big gear's turn at first contact on the {flank} flank less the conjugate turn "
                                 "(negative: it lags), on the exact spherical-involute flanks, with the pair as "
                                 "designed and as each thermal state mounts it (the shim and the expansions as "
                                 "E/P/G/Σ and scales). The means differ by the play each state leaves; the curves "
                                 "show how smoothly the pair runs. As designed the flanks are conjugate: flat. One "
                                 "big gear with one small gear: an output shaft meets two small gears half a pitch "
                                 "apart, and its TE is the earlier of the two contacts (summary.json tca.states).")))
    return out


def pattern_plot(pair: PairTca, flank: str = "drive") -> Plot:
    """The contact pattern of one flank on the developed flank, with the flank's outline, the
    form line and the contact path."""
    p = pair.patterns[flank]
    x, y = p.developed()
    outline = p.developed([0.0, 1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0, 0.0])
    along = pair.te.drive_along if flank == "drive" else pair.te.coast_along
    height = pair.te.drive_height if flank == "drive" else pair.te.coast_height
    path = p.developed(along, height)
    e = p.extent()
    ends = [w for w in ("toe", "heel") if e[w]]
    series = [Series("first contact at each drive angle (the contact path)", path[0].tolist(), path[1].tolist(),
                     "points"),
              Series("flank outline (toe left, heel right, root cone below, tip cone above)", outline[0].tolist(),
                     outline[1].tolist())]
    if p.form > 0.0:
        form = p.developed([0.0, 1.0], [p.form, p.form])
        series.append(Series("form line (the involute starts)", form[0].tolist(), form[1].tolist()))
    compound = p.compound_mm * 1e3
    length = p.length
    return Plot(f"Contact pattern, big gear {flank} flank, {pair_text(pair)} ({compound:g} µm compound)",
                "along the face from the toe (mm)", "up the flank from the root cone (mm)", series,
                caption=(f"The flank developed flat. Coloured where the gap to the mating flank comes under "
                         f"{compound:g} µm during a whole pass of the tooth through the mesh (darkest: touching): "
                         f"the mark marking compound leaves. The pattern covers {length:.0%} of the face, centre "
                         f"{e['centre_along']:.2f} (toe 0 … heel 1)"
                         + (f", and reaches the {' and '.join(ends)}" if ends else ", clear of toe and heel") + "."),
                field=FieldMap(x.tolist(), y.tolist(), np.where(np.isfinite(p.gap_mm), p.gap_mm * 1e3,
                                                               math.nan).tolist(), "gap (µm)", compound))


def tca_plots(pairs: list[PairTca]) -> list[Plot]:
    """The TE plots, then the drive flank's pattern warm and cold (as designed where no state is)."""
    mapped = [p for p in pairs if p.name in MAPPED] or pairs[:1]
    return [*te_plots(pairs), *(pattern_plot(p) for p in mapped)]


# Paint: the warm pattern on the first output shaft's gear, the cold one on the second's.
PAINT = {"warm": (0, (0.86, 0.12, 0.10)), "cold": (1, (0.12, 0.38, 0.92))}


def tca_overlays(pairs: list[PairTca], specs) -> list[Overlay]:
    """The warm and the cold pattern painted on both flanks of every tooth of one big gear each
    (the pattern is a whole pass of a tooth through the mesh: every tooth bears it)."""
    out = []
    for pair in pairs:
        if pair.name not in PAINT:
            continue
        gear, rgb = PAINT[pair.name]
        patches = [bt.pattern_patch(specs.big, p) for p in pair.patterns.values()]
        vertices = np.concatenate([v for v, _ in patches])
        offsets = np.cumsum([0] + [len(v) for v, _ in patches[:-1]])
        faces = np.concatenate([f + o for (_, f), o in zip(patches, offsets, strict=True)]).astype(np.uint32)
        if len(faces):
            compound = pair.patterns["drive"].compound_mm * 1e3
            out.append(Overlay(f"pattern_{pair.name}", BIG_GEARS[gear], rgb, vertices, faces,
                               f"contact pattern {pair_text(pair)} ({compound:g} µm compound, both flanks)"))
    return out
