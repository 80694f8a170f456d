"""The roller-chain drive's parts as data (numpy only): the sprocket and the chain segment
wrapped on it at θ = 0 (:class:`gearcheck.geometry.roller_chain.RollerWrap`), inner and outer
links alternating; every inner link shares one solid, every outer link another."""

from __future__ import annotations

import math

from gearcheck.mechanism import Assembly, PartSpec
from gearcheck.mechanisms.roller_chain.model import RollerChainModel, build_model
from gearcheck.scene import PoseView
from gearcheck.sweep.motion import ChainLink, Rotation

SPROCKET, INNER, OUTER = "sprocket", "inner", "outer"
SPROCKET_MATERIAL = "steel C45, teeth hardened"
LINK_MATERIAL = "case-hardened steel chain"
COLORS = {SPROCKET: (0.75, 0.75, 0.8), INNER: (0.35, 0.35, 0.4), OUTER: (0.55, 0.55, 0.6)}
FEATURES = {INNER: ("rollers", "plates"), OUTER: ("pins", "plates")}


def link_name(j: int) -> str:
    return f"link_{j:02d}"


def link_kind(j: int) -> str:
    return INNER if j % 2 == 0 else OUTER


def chain_assembly(params) -> Assembly:
    model = build_model(params)
    wrap = model.wrap
    parts = [PartSpec(SPROCKET, SPROCKET, SPROCKET_MATERIAL, wrap.sprocket_matrix(0.0), COLORS[SPROCKET],
                      Rotation.about((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)))]
    for j, pose in enumerate(wrap.link_matrices(0.0)):
        kind = link_kind(j)
        parts.append(PartSpec(link_name(j), kind, LINK_MATERIAL, pose, COLORS[kind], ChainLink(j), FEATURES[kind]))
    return Assembly("roller_chain", tuple(parts), {SPROCKET: model.sprocket, INNER: model.inner, OUTER: model.outer},
                    model)


def build_parts(assembly: Assembly) -> list:
    """The CAD hook: the sprocket and the two link solids, built once each."""
    from gearcheck.cad.placement import Part
    from gearcheck.cad.roller_chain import build_link
    from gearcheck.cad.sprocket import build_sprocket

    sprocket = build_sprocket(assembly.solids[SPROCKET])
    links = {kind: build_link(assembly.solids[kind]) for kind in (INNER, OUTER)}
    solids = {SPROCKET: sprocket, INNER: links[INNER].link, OUTER: links[OUTER].link}
    out = []
    for spec in assembly.parts:
        feats = {} if spec.solid == SPROCKET else {n: links[spec.solid].features[n] for n in spec.features}
        out.append(Part(spec.name, spec.material, solids[spec.solid], spec.pose, spec.color, spec.motion, feats))
    return out


FRAMES_PER_CYCLE = 8
CYCLES = 2


def display_frames(model: RollerChainModel) -> tuple[list[PoseView], str]:
    """The sprocket turning through two tooth pitches, every link posed by the wrap."""
    wrap = model.wrap
    frames = []
    for k in range(CYCLES * FRAMES_PER_CYCLE + 1):
        theta = k * wrap.cycle_rad / FRAMES_PER_CYCLE
        poses = {SPROCKET: wrap.sprocket_matrix(theta)}
        poses.update({link_name(j): m for j, m in enumerate(wrap.link_matrices(theta))})
        frames.append(PoseView(f"θ = {math.degrees(theta):.2f}°", poses))
    return frames, f"sprocket drive angle θ over two tooth pitches (0 → {math.degrees(CYCLES * wrap.cycle_rad):.2f}°)"
