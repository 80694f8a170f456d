"""Mean linear expansion coefficients of common gear and mechanism materials (1/K, about 20–100 °C,
typical handbook values: an engineer with a data sheet gives ``cte_per_K`` instead).

A material is found by name, case-insensitive, by the first entry whose keywords occur in it
("steel 42CrMo4" → steel; "Ti-6Al-4V" → titanium alloy). Cold states far below −50 °C shrink less
than these room-temperature means say; for a cryogenic check give the mean over the range.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Material:
    name: str
    cte_per_K: float
    keywords: tuple[str, ...]


TABLE: tuple[Material, ...] = (
    Material("precipitation-hardening stainless 17-4PH", 10.8e-6, ("17-4ph", "17-4")),
    Material("stainless steel", 16.0e-6, ("stainless", "304", "316")),
    Material("titanium alloy Ti-6Al-4V", 8.6e-6, ("ti-6al-4v", "tc4", "titanium")),
    Material("aluminium alloy", 23.0e-6, ("aluminium", "aluminum", "alu", "7075", "6061", "2024")),
    Material("cast iron", 10.5e-6, ("cast iron", "ductile iron")),
    Material("bronze", 18.0e-6, ("bronze",)),
    Material("brass", 19.0e-6, ("brass",)),
    Material("acetal (POM)", 110e-6, ("pom", "acetal", "delrin")),
    Material("polyamide (PA66)", 80e-6, ("pa66", "pa6", "polyamide", "nylon")),
    Material("steel", 11.5e-6, ("steel", "42crmo4", "20mncr5", "18crnimo", "c45")),
)

NAMES: tuple[str, ...] = tuple(m.keywords[0] for m in TABLE)


def find(name: str) -> Material | None:
    """The table's entry for a material name, or None."""
    low = name.lower()
    return next((m for m in TABLE if any(k in low for k in m.keywords)), None)


def cte_per_K(name: str) -> float | None:
    """The mean linear expansion coefficient of a material by name (1/K), or None."""
    m = find(name)
    return None if m is None else m.cte_per_K
