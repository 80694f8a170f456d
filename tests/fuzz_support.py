"""Shared by the property and CAD fuzz tests: hypothesis as a sampling.Draw, the shipped
templates' data, and the checks on a rejection."""

from __future__ import annotations

import math
from pathlib import Path

from hypothesis import strategies as st

from gearcheck.design import Design, load_template
from gearcheck.mechanism import get as mechanism
from gearcheck.mechanisms.sampling import sample
from gearcheck.params import ParamError, validate

TEMPLATE_DIR = Path(__file__).resolve().parents[1] / "templates"
TEMPLATES = {
    "differential": "zhurong_differential.toml",
    "track": "eod_track_drive.toml",
    "steering": "nose_wheel_steering.toml",
}
BASE = {mech: load_template(TEMPLATE_DIR / name).data for mech, name in TEMPLATES.items()}

NAN_ALLOWED = {mech: mechanism(mech).nan_figures for mech in TEMPLATES}


def design_of(mech: str, params) -> Design:
    """A design from validated parameters (no template file), named "fuzz"."""
    return Design(None, mech, params, {"mechanism": mech, "name": "fuzz"})


class HypothesisDraw:
    """:class:`gearcheck.mechanisms.sampling.Draw` on a hypothesis ``data`` object. ``chance``
    shrinks towards False (the common, in-band branch)."""

    def __init__(self, data):
        self.data = data

    def real(self, lo: float, hi: float) -> float:
        lo, hi = min(lo, hi), max(lo, hi)
        return self.data.draw(st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False))

    def integer(self, lo: int, hi: int) -> int:
        return self.data.draw(st.integers(min(lo, hi), max(lo, hi)))

    def chance(self, p: float) -> bool:
        return self.data.draw(st.integers(0, 999)) >= round(1000 * (1.0 - p))


def draw_set(mech: str, data) -> dict:
    """A template body (TOML data without ``mechanism``) drawn around the shipped template."""
    body = sample(BASE[mech], HypothesisDraw(data))
    del body["mechanism"]
    return body


def validate_set(mech: str, body: dict):
    """The validated Params, or the ParamError (after checking its one-line form)."""
    try:
        return validate(mechanism(mech).Params, body, "fuzz.toml")
    except ParamError as exc:
        check_rejection(mech, body, exc)
        return exc


def _lookup(body: dict, path: list[str]):
    node = body
    for name in path:
        if isinstance(node, dict) and name in node:
            node = node[name]
        elif isinstance(node, list) and name.isdigit() and int(name) < len(node):
            node = node[int(name)]
        else:
            raise KeyError(name)
    return node


def check_rejection(mech: str, body: dict, exc: ParamError) -> None:
    """One line per broken rule (independent rules are named together: ``exc.errors``), each
    'fuzz.toml: FIELD = VALUE: ... allowed ...', FIELD a path of the template whose input value is
    VALUE; ``exc`` itself carries the first one's."""
    errors = getattr(exc, "errors", None)
    if errors is not None:
        assert str(exc).splitlines() == [str(e) for e in errors], str(exc)
        assert (exc.field, exc.value) == (errors[0].field, errors[0].value), str(exc)
        for e in errors:
            check_rejection(mech, body, e)
        return
    text = str(exc)
    assert "\n" not in text, text
    assert exc.field, text
    assert text.startswith(f"fuzz.toml: {exc.field} = "), text
    assert "allowed" in exc.allowed, text
    value = _lookup(body, exc.field.split("."))  # the field is in the set (KeyError otherwise)
    if not isinstance(value, dict):
        assert value == exc.value or (isinstance(value, float) and math.isnan(value)), (text, value)
