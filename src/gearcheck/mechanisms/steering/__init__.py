"""Nose-wheel steering: a trimmed rack and a topped pinion sector (continuous power drive,
towing disengage and re-engage).

The mechanism (:class:`.mechanism.Steering`) wires its hooks to the modules here: :mod:`.calc`
(figures), :mod:`.analysis` and :mod:`.push` (the analytical model), :mod:`.assembly` (parts as
data), :mod:`.parts` (the CAD hook), :mod:`.sweep` and :mod:`.tasks` (the mesh sweep),
:mod:`.verdicts` and :mod:`.report`. Reconstruction and every paper slip: docs/steering.md.
"""
