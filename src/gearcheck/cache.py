"""A cache of built CAD: a design's solids, their meshes and its STEP file, kept by what they are
built from, so that a re-check changing only sweep, report or study settings skips the CAD
kernel (solids, meshing, the STEP write and its read-back).

Where: the folder ``$GEARCHECK_CACHE`` (``off`` turns the cache off), else
``$XDG_CACHE_HOME/gearcheck``, else ``~/.cache/gearcheck``. One entry per key, a folder named by
the key holding the entry's files and ``index.json`` (each file's size and SHA-256). An entry is
written into a temporary folder and published by one rename, so a reader sees a whole entry or
none, and two runs building the same design at once both succeed (the first rename wins). Every
read checks each file against the index: an entry that does not read back (cut short, edited)
is removed and the CAD built again. Reading an entry marks it used; beyond :data:`MAX_BYTES` the
entries used longest ago are removed.

The key (:func:`key_of`) is the SHA-256 of what the files are made from: this cache's format,
gearcheck's version and a digest of its own source files (any code change is a new key), the
CAD kernel's versions, and the caller's inputs (the design's name, the mesh tolerance, the
assembly's part and solid specs, and the source of the mechanism's own package when it is not
gearcheck's: :func:`code_digest`). The files are pickles, which run code when read: the cache
folder must be writable only by its user (as the default in the home folder is).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import logging
import os
import pickle
import shutil
import sys
import tempfile
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

log = logging.getLogger("gearcheck")

FORMAT = 1  # bump when what an entry holds changes
ENV = "GEARCHECK_CACHE"
OFF = frozenset({"off", "0", "no", "false", "none"})
MAX_BYTES = 4 << 30  # entries beyond this (least recently used first) are removed
INDEX = "index.json"
STALE_S = 3600.0  # a staging folder this old was left by a killed run
# distributions whose versions change what the CAD kernel makes of the same specs
KERNEL = ("cadquery", "cadquery-ocp")


def root(environ: Mapping[str, str] | None = None) -> Path | None:
    """The cache folder, or None when ``$GEARCHECK_CACHE`` turns the cache off."""
    env = os.environ if environ is None else environ
    given = env.get(ENV, "").strip()
    if given.lower() in OFF:
        return None
    if given:
        return Path(given).expanduser()
    base = env.get("XDG_CACHE_HOME", "").strip()
    return (Path(base) if base else Path.home() / ".cache") / "gearcheck"


@functools.lru_cache(maxsize=8)
def _tree_digest(root: Path) -> str:
    """SHA-256 of every ``.py`` file under ``root`` (a package folder) or of ``root`` itself (a
    single module), by relative path and content."""
    h = hashlib.sha256()
    files = sorted(root.rglob("*.py")) if root.is_dir() else [root]
    for path in files:
        h.update(str(path.relative_to(root) if root.is_dir() else path.name).encode() + b"\0")
        h.update(path.read_bytes() + b"\0")
    return h.hexdigest()


def source_digest() -> str:
    """SHA-256 of gearcheck's own Python source (every ``.py`` under the package, by relative
    path): a key ingredient, so an edited checkout never reads an entry made by other code."""
    return _tree_digest(Path(__file__).resolve().parent)


def code_digest(cls: type) -> str:
    """SHA-256 of the source of the package ``cls`` comes from (its top-level package's ``.py``
    files, or its module's file): a mechanism registered from outside gearcheck (a plugin) keys
    its CAD by its own code too. "unknown" where the source cannot be found (then only the
    rest of the key tells entries apart)."""
    top = sys.modules.get(cls.__module__.split(".")[0])
    file = getattr(top, "__file__", None)
    if not file:
        return "unknown"
    path = Path(file).resolve()
    return _tree_digest(path.parent if path.name == "__init__.py" else path)


@functools.lru_cache(maxsize=1)
def kernel_versions() -> tuple[tuple[str, str], ...]:
    from importlib import metadata

    found = []
    for name in KERNEL:
        try:
            found.append((name, metadata.version(name)))
        except metadata.PackageNotFoundError:
            found.append((name, "absent"))
    return tuple(found)


def key_of(*inputs: object) -> str:
    """The key of an entry made from ``inputs`` (picklable, pickled deterministically: plain
    data, dataclasses, numpy arrays; no sets) by this code on this CAD kernel."""
    from gearcheck import __version__

    data = pickle.dumps((FORMAT, __version__, source_digest(), kernel_versions(), inputs), protocol=5)
    return hashlib.sha256(data).hexdigest()


@dataclass(frozen=True)
class Entry:
    """An entry as read: its files' bytes by name, and when it was made (UTC, ISO 8601)."""

    key: str
    files: dict[str, bytes]
    created: str


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def load(folder: Path | None, key: str) -> Entry | None:
    """The entry ``key`` with every file checked against its index, or None (no cache, no such
    entry, or one that does not read back: then it is removed, with a warning)."""
    if folder is None:
        return None
    where = folder / key
    if not where.is_dir():
        return None
    try:
        index = json.loads((where / INDEX).read_text())
        files = {}
        for name, (size, digest) in index["files"].items():
            data = (where / name).read_bytes()
            if len(data) != size or _digest(data) != digest:
                raise ValueError(f"{name} does not match its index")
            files[name] = data
        created = str(index["created"])
    except (OSError, ValueError, KeyError, TypeError) as exc:  # a file missing, cut short or edited
        log.warning("CAD cache entry %s unreadable (%s): removed, building the CAD", where, exc)
        shutil.rmtree(where, ignore_errors=True)
        return None
    with contextlib.suppress(OSError):
        os.utime(where / INDEX)  # used now: the last to be evicted
    return Entry(key, files, created)


def discard(folder: Path | None, key: str) -> None:
    """Remove an entry (one whose files read back but whose content could not be used)."""
    if folder is not None:
        shutil.rmtree(folder / key, ignore_errors=True)


def store(folder: Path | None, key: str, files: Mapping[str, bytes], max_bytes: int = MAX_BYTES) -> bool:
    """Publish an entry (True if this call published it). Never fails the run: a cache that
    cannot be written (read-only, full disk) is a warning and the run goes on without it."""
    if folder is None:
        return False
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if (folder / key).exists():
            return False
        staging = Path(tempfile.mkdtemp(prefix=f".{key[:16]}-", dir=folder))
        try:
            for name, data in files.items():
                (staging / name).write_bytes(data)
            index = {"format": FORMAT, "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                     "files": {name: [len(data), _digest(data)] for name, data in files.items()}}
            (staging / INDEX).write_text(json.dumps(index, indent=1) + "\n")
            os.rename(staging, folder / key)  # atomic; fails if another run published it first
        except OSError:
            shutil.rmtree(staging, ignore_errors=True)
            if (folder / key).exists():
                return False
            raise
    except OSError as exc:
        log.warning("CAD cache %s not written (%s): the run goes on without it", folder, exc)
        return False
    evict(folder, max_bytes)
    return True


def _size(entry: Path) -> int:
    return sum(f.stat().st_size for f in entry.iterdir() if f.is_file())


def evict(folder: Path, max_bytes: int = MAX_BYTES) -> list[str]:
    """Remove the entries used longest ago until the rest fit in ``max_bytes`` (and what killed
    runs left half-written over an hour ago); the removed entries' keys."""
    entries = []
    for entry in folder.iterdir():
        try:
            if entry.name.startswith("."):
                if entry.is_dir() and time.time() - entry.stat().st_mtime > STALE_S:
                    shutil.rmtree(entry, ignore_errors=True)
            elif entry.is_dir():
                entries.append(((entry / INDEX).stat().st_mtime, _size(entry), entry))
        except OSError:
            continue  # being removed, or not an entry
    entries.sort(key=lambda e: e[0], reverse=True)  # most recently used first
    kept, removed = 0, []
    for _, size, entry in entries:
        kept += size
        if kept > max_bytes:
            shutil.rmtree(entry, ignore_errors=True)
            removed.append(entry.name)
    return removed
