"""Several broken rules named at once: :class:`ParamErrors` (one line each) and :class:`Problems`,
the collector a template's validators add each broken rule to."""

from __future__ import annotations

from typing import Any

from gearcheck.params.common import ParamError


class ParamErrors(ParamError):
    """Several rules a template breaks, named at once: ``str()`` is one line each (field, value,
    the value that satisfies it where there is one). ``field``, ``value`` and ``allowed`` are the
    first one's, so code reading one error still reads the first."""

    def __init__(self, errors: list[ParamError], source: str = ""):
        self.errors = [e.with_source(source) for e in errors] if source else list(errors)
        first = self.errors[0]
        super().__init__(first.field, first.value, first.allowed, first.source)
        self.args = ("\n".join(str(e) for e in self.errors),)

    def __str__(self) -> str:
        return self.args[0]

    def with_source(self, source: str) -> ParamErrors:
        return ParamErrors(self.errors, source)


class Problems:
    """The rules a validator finds broken, raised together: ``add`` each, then ``check()`` (or leave
    a ``with Problems() as p:`` block) raises one :class:`ParamError`, or :class:`ParamErrors` for
    several. Rules that need earlier ones to hold go after a ``check()``."""

    def __init__(self) -> None:
        self.errors: list[ParamError] = []

    def add(self, field: str, value: Any, allowed: str) -> None:
        self.errors.append(ParamError(field, value, allowed))

    def extend(self, error: ParamError) -> None:
        self.errors.extend(error.errors if isinstance(error, ParamErrors) else [error])

    def __bool__(self) -> bool:
        return bool(self.errors)

    def check(self) -> None:
        if len(self.errors) == 1:
            raise self.errors[0]
        if self.errors:
            raise ParamErrors(self.errors)

    def __enter__(self) -> Problems:
        return self

    def __exit__(self, kind: object, *_: object) -> None:
        if kind is None:
            self.check()
