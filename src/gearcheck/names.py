"""The one rule for every name that becomes a file or folder name: a template's result name, a
part's name (its STL, its mesh in the 3-D view) and whatever a user's STEP file calls a product.

A name is 1 to :data:`MAX_CHARS` characters (at most :data:`MAX_BYTES` bytes in UTF-8, so a file
name made of it and a suffix fits every file system) of letters and digits of any script
(``齿轮``, ``Zahnrad_2``), ``_``, ``-`` and, where the name allows it, ``.``; it starts with a
letter, a digit or ``_``. So it holds no path separator (``/``, ``\\``), no space or control
character, no ``..`` and no leading dot or dash: ``folder / name`` is always a file in ``folder``.
A part's name takes no dot (its files are ``NAME.stl``; ``~`` and ``@`` name its pieces inside
gearcheck, so they are not allowed either).

:func:`file_in` is the check at the write: the path of a name in a folder, refused (an internal
error, never a user's input) when it would resolve anywhere else.

Nothing here imports the rest of gearcheck.
"""

from __future__ import annotations

import re
import unicodedata
from pathlib import Path

MAX_CHARS = 64
MAX_BYTES = 200

# \w is Unicode here: letters and digits of any script and _ (no space, punctuation or control)
_NAME = re.compile(r"\w[\w.-]*")
_PART = re.compile(r"\w[\w-]*")

NAME_RULE = (f"allowed 1 to {MAX_CHARS} letters (any script), digits, _ . - starting with a letter, digit or _ "
             "(a file name: no spaces, no / or \\)")
PART_RULE = (f"allowed 1 to {MAX_CHARS} letters (any script), digits, _ - starting with a letter, digit or _ "
             "(a file name: no dots, no spaces, no / or \\)")

# The same rules as a JSON schema's pattern, in the regular expressions every editor and
# validator reads (no \p{L}): ASCII as the rule says, any character beyond ASCII taken as a letter
_BEYOND = r"[^\x00-\x7f]"
NAME_SCHEMA_PATTERN = rf"^(?:[A-Za-z0-9_]|{_BEYOND})(?:[A-Za-z0-9_.-]|{_BEYOND}){{0,{MAX_CHARS - 1}}}$"
PART_SCHEMA_PATTERN = rf"^(?:[A-Za-z0-9_]|{_BEYOND})(?:[A-Za-z0-9_-]|{_BEYOND}){{0,{MAX_CHARS - 1}}}$"


def name_problem(name: object, *, dots: bool = True) -> str | None:
    """Why ``name`` cannot name a file (the rule it breaks, in the words of :data:`NAME_RULE`), or
    None when it can. ``dots=False``: a part's name (:data:`PART_RULE`)."""
    rule = NAME_RULE if dots else PART_RULE
    if not isinstance(name, str):
        return f"wrong type: a text; {rule}"
    if not name:
        return f"empty; {rule}"
    if len(name) > MAX_CHARS or len(name.encode("utf-8", "surrogatepass")) > MAX_BYTES:
        return f"too long ({len(name)} characters); {rule}"
    if not (_NAME if dots else _PART).fullmatch(name):
        return rule
    return None


def is_name(name: object, *, dots: bool = True) -> bool:
    """True when ``name`` can name a file (:func:`name_problem` has nothing to say)."""
    return name_problem(name, dots=dots) is None


def as_name(text: str, taken: set[str] | frozenset[str] = frozenset(), *, dots: bool = False) -> str:
    """A name that follows the rule made from any ``text`` (a product's name in a STEP file):
    every run of characters the rule does not allow becomes one ``_``, leading ``.``/``-`` go,
    the length is cut to the limits; ``part`` for a text with nothing left. Made unique against
    ``taken`` with ``_2``, ``_3``…"""
    text = unicodedata.normalize("NFC", text)
    allowed = r"[^\w.-]+" if dots else r"[^\w-]+"
    base = re.sub(allowed, "_", text).strip("_")
    base = re.sub(r"^[.-]+", "", base)
    base = _cut(base) or "part"
    if not re.match(r"\w", base):
        base = _cut("_" + base)
    name, k = base, 1
    while name in taken:
        k += 1
        tail = f"_{k}"
        name = _cut(base, len(tail)) + tail
    return name


def _cut(text: str, room: int = 0) -> str:
    """``text`` cut to the limits, less ``room`` characters (and bytes)."""
    text = text[: MAX_CHARS - room]
    while len(text.encode("utf-8", "surrogatepass")) > MAX_BYTES - room:
        text = text[:-1]
    return text


class OutsideFolderError(RuntimeError):
    """A file about to be written outside its run's folder: an internal error (exit 3)."""


def file_in(folder: Path, name: str) -> Path:
    """``folder / name``, checked at the write: ``name`` must be one plain file name (no
    separator, not ``.`` or ``..``) and the path must resolve inside ``folder``. Anything else
    raises :class:`OutsideFolderError` before a byte is written."""
    folder = Path(folder)
    if (not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name
            or Path(name).is_absolute()):
        raise OutsideFolderError(f"refused to write {name!r}: not a plain file name inside {folder}")
    path = folder / name
    home = folder.resolve()
    if path.resolve().parent != home:
        raise OutsideFolderError(f"refused to write {name!r}: it resolves outside {home}")
    return path
