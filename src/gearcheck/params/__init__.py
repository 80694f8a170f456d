"""Parameters: TOML templates, ``--set`` overrides, validation with one-line errors."""

from gearcheck.params.common import ParamError, Section, apply_overrides, read_toml, validate

__all__ = ["ParamError", "Section", "apply_overrides", "read_toml", "validate"]
