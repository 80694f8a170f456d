"""``gearcheck.new`` and ``gearcheck new``: a design from the numbers that define it
(:func:`gearcheck.drafting.new`), its template written with the JSON schema its ``#:schema`` line
points at beside it. Apart from :mod:`gearcheck.drafting` so that the template model
(drafting, mechanism, design) never imports the schema, which is made from it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearcheck import drafting

if TYPE_CHECKING:
    from gearcheck.design import Design


def new(mechanism: str, *, out: str | Path | None = None, overrides: Mapping[str, Any] | Sequence[str] | None = None,
        force: bool = False, **inputs: Any) -> Design | None:
    """A complete, validated design from the numbers that define it, e.g.
    ``new("differential", module=3, teeth="14/30")``, ``new("roller_chain", chain="12B", teeth=21)``.

    Every dependent value is derived (see each mechanism's docs); ``overrides`` (``{"section.key":
    value}`` or ``--set`` strings) change any other. With ``out`` the template is written there
    (an existing file only with ``force``), the schema it points at beside it
    (``schema/MECHANISM.json``), and the Design reads from it. Raises :class:`ParamError` (exit 2
    on the command line) when the numbers admit no design. A template to fill in (an
    ``assembly``'s: how its parts move is the user's to say) is written unvalidated, and gives None."""
    from gearcheck.schema import write_beside

    design = drafting.new(mechanism, out=out, overrides=overrides, force=force, **inputs)
    if out is not None:
        write_beside(Path(out).parent, mechanism)
    return design
