"""The mechanisms shipped with gearcheck, one package each (differential, track, steering).

Each package implements :class:`gearcheck.mechanism.Mechanism` once, in its ``mechanism``
module, and is registered by an entry point in the ``gearcheck.mechanisms`` group
(pyproject.toml); nothing else lists them. Shared by all: :mod:`.sampling` (random draws for the
fuzz and property tests).
"""
