"""Parameters: TOML templates, ``--set`` overrides, validation with one-line errors."""

from gearcheck.params.common import ParamError, Section, apply_overrides, read_toml, validate
from gearcheck.params.problems import ParamErrors, Problems

__all__ = ["ParamError", "ParamErrors", "Problems", "Section", "apply_overrides", "read_toml", "validate"]
