"""A cache of built CAD: a design's solids, their meshes and its STEP file, kept by what they are
built from, so that a re-check changing only sweep, report or study settings skips the CAD
kernel (solids, meshing, the STEP write and its read-back).

Where: the folder ``$GEARCHECK_CACHE`` (``off`` turns the cache off), else
``$XDG_CACHE_HOME/gearcheck``, else ``~/.cache/gearcheck``.

The folder is gearcheck's alone. gearcheck marks it with a ``CACHEDIR.TAG`` (the Cache Directory
Tagging signature, which also tells backup tools to skip it, and a line naming gearcheck) when it
creates the folder or finds it empty. A folder that exists, holds anything and has no such tag
is not used for the run (one warning names it and why) and nothing in it is read, written or
removed: the cache never deletes files in a folder it did not make (a project or home folder
given by mistake).

An entry is a folder named by its key (64 hex digits) holding a mark file (:data:`MARK`), the
entry's files and ``index.json`` (the cache's format, the entry's key, when it was made, and
each file's size and SHA-256). It is written into a staging folder (``.gearcheck-staging-`` and
the key's first 16 digits, the mark written first) and published by one rename, so a reader sees
a whole entry or none, and two runs building the same design at once both succeed (the first
rename wins).

Every read checks the entry: it is a real folder (not a link) with the mark, every file is a
regular file (a link, a pipe or a device is not read: it could lead outside the cache or block
the run), the index has its exact shape and names this folder's key, and each file matches its
size and SHA-256. An entry that does not read back (cut short, edited, malformed, or copied from
another key, whose files were made from other inputs) is removed with a warning and the CAD
built again: it is gearcheck's own (the mark), its name says it is this key's entry while its
content is not, and leaving it would keep this key from ever being written. A folder without the
mark is not gearcheck's and is left as it is (the run builds the CAD and does not cache it).

Reading an entry marks it used; beyond :data:`MAX_BYTES` the entries used longest ago are
removed, and so are staging folders left over an hour ago by a killed run. Eviction removes only
what gearcheck made (a folder with the mark and gearcheck's naming: an entry with a well-formed
index of its own key, or a staging folder); anything else in the folder is never removed.

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
import re
import shutil
import stat
import sys
import tempfile
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

log = logging.getLogger("gearcheck")

FORMAT = 2  # bump when what an entry holds changes
ENV = "GEARCHECK_CACHE"
OFF = frozenset({"off", "0", "no", "false", "none"})
MAX_BYTES = 4 << 30  # entries beyond this (least recently used first) are removed
INDEX = "index.json"
MAX_INDEX_BYTES = 1 << 20
STALE_S = 3600.0  # a staging folder this old was left by a killed run
# The cache folder's mark (https://bford.info/cachedir/): the standard signature, then gearcheck's line.
TAG = "CACHEDIR.TAG"
TAG_SIGNATURE = "Signature: 8a477f597d28d172789f06886806bc55"
TAG_OWNER = "# gearcheck CAD cache"
TAG_TEXT = (f"{TAG_SIGNATURE}\n{TAG_OWNER}: made by gearcheck, which may remove what it wrote here.\n"
            "# For information about cache directory tags, see https://bford.info/cachedir/\n")
TAG_STAGING = ".gearcheck-tag-"  # the tag is written under this prefix and renamed into place
# The mark of a folder gearcheck made: the first file written into every staging folder.
MARK = ".gearcheck-entry"
MARK_TEXT = b"gearcheck CAD cache entry\n"
STAGING = ".gearcheck-staging-"
KEY = re.compile(r"[0-9a-f]{64}")
STAGING_NAME = re.compile(re.escape(STAGING) + r"[0-9a-f]{16}-[A-Za-z0-9_]+")
FILE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,63}")  # an entry's files: plain names, none hidden
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


def _check_key(key: str) -> None:
    if not KEY.fullmatch(key):
        raise ValueError(f"not a CAD cache key (64 hex digits): {key!r}")


def _read_regular(path: Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, not through a link, at most ``limit`` of them. A
    link, a pipe, a device or a larger file is a ValueError: nothing is read that could lead
    outside the cache, block the run or fill its memory."""
    if not stat.S_ISREG(os.lstat(path).st_mode):
        raise ValueError(f"{path.name} is not a regular file")
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0)
    fd = os.open(path, flags)  # non-blocking: a pipe put there since the check does not wait for a writer
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(f.fileno())
        if not stat.S_ISREG(info.st_mode):
            raise ValueError(f"{path.name} is not a regular file")
        if info.st_size > limit:
            raise ValueError(f"{path.name} is {info.st_size} bytes, more than {limit}")
        data = f.read(limit + 1)
    if len(data) > limit:
        raise ValueError(f"{path.name} is more than {limit} bytes")
    return data


def _tagged(folder: Path) -> bool:
    """Whether ``folder`` holds gearcheck's CACHEDIR.TAG (a regular file: the signature, then
    gearcheck's line)."""
    try:
        lines = _read_regular(folder / TAG, 4096).decode("utf-8").splitlines()
    except (OSError, ValueError):
        return False
    return len(lines) >= 2 and lines[0] == TAG_SIGNATURE and lines[1].startswith(TAG_OWNER)


_refused: set[str] = set()  # cache folders refused in this process (warned about once)


def _usable(folder: Path, create: bool) -> bool:
    """Whether ``folder`` is gearcheck's cache folder: tagged, or (with ``create``) made now or
    found empty, and then tagged. A folder holding anything else is refused with one warning
    (per process) and left as it is. OSError when ``create`` and the folder cannot be made or
    tagged."""
    if _tagged(folder):
        return True
    try:
        if create:
            folder.mkdir(parents=True, exist_ok=True)
        names = [n for n in os.listdir(folder) if not n.startswith(TAG_STAGING)]  # another run's tag in writing
    except OSError:
        if create:
            raise
        return False  # no such folder yet: nothing to read
    if names and create and _earlier_cache(folder, names):
        log.warning("CAD cache %s: entries of an earlier gearcheck (format 1, never read again) removed", folder)
        for name in names:
            shutil.rmtree(folder / name, ignore_errors=True)
        names = [n for n in os.listdir(folder) if not n.startswith(TAG_STAGING)]
    if names:
        if _tagged(folder):  # tagged by another run since the first look
            return True
        if str(folder) not in _refused:
            _refused.add(str(folder))
            log.warning("CAD cache %s holds files gearcheck did not write (no gearcheck %s): cache not used "
                        "(point %s at an empty or new folder)", folder.absolute(), TAG, ENV)
        return False
    if not create:
        return False  # empty: nothing to read
    fd, tmp = tempfile.mkstemp(prefix=TAG_STAGING, dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(TAG_TEXT)
        os.replace(tmp, folder / TAG)  # whole or absent to a reader; a tag another run wrote is the same
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
    return _tagged(folder)


# What an earlier gearcheck (cache format 1, before the tag and the marks) left: entries named by
# their key, and staging folders named by mkdtemp after the key's first 16 digits.
_EARLIER_ENTRY = re.compile(r"[0-9a-f]{64}")
_EARLIER_STAGING = re.compile(r"\.[0-9a-f]{16}-[a-z0-9_]{8}")
_EARLIER_FILES = frozenset({INDEX, "cad.pickle", "model.step"})


def _earlier_cache(folder: Path, names: list[str]) -> bool:
    """Whether everything in ``folder`` is what an earlier gearcheck's cache held (so the folder is
    gearcheck's, made before it was tagged): format-1 entries whose index lists exactly their
    files, and staging folders of those files only; all real folders, no links."""
    for name in names:
        path = folder / name
        try:
            if not stat.S_ISDIR(os.lstat(path).st_mode):
                return False
            files = set(os.listdir(path))
            if not files <= _EARLIER_FILES or any(not stat.S_ISREG(os.lstat(path / f).st_mode) for f in files):
                return False
            if _EARLIER_STAGING.fullmatch(name):
                continue
            if not _EARLIER_ENTRY.fullmatch(name):
                return False
            index = json.loads(_read_regular(path / INDEX, 1 << 20))
            if not (isinstance(index, dict) and index.get("format") == 1 and isinstance(index.get("files"), dict)
                    and set(index["files"]) | {INDEX} == files):
                return False
        except (OSError, ValueError):
            return False
    return True


def _ours(path: Path) -> bool:
    """Whether ``path`` is a folder gearcheck made (an entry or a staging folder): a real folder,
    not a link, holding gearcheck's mark."""
    try:
        if not stat.S_ISDIR(os.lstat(path).st_mode):
            return False
        return _read_regular(path / MARK, len(MARK_TEXT)) == MARK_TEXT
    except (OSError, ValueError):
        return False


def _remove(path: Path) -> None:
    """Remove ``path`` (a plain name in the cache folder) if it is a folder gearcheck made; the
    removal does not follow links (a link inside is removed, not what it points to)."""
    if _ours(path):
        shutil.rmtree(path, ignore_errors=True)


def _index(raw: bytes, key: str) -> tuple[str, dict[str, tuple[int, str]]]:
    """An entry's index read: (when made, {file name: (size, SHA-256)}); ValueError unless it
    has its exact shape, this cache's format and the key ``key``."""
    index: Any = json.loads(raw.decode("utf-8"))
    if not isinstance(index, dict) or set(index) != {"format", "key", "created", "files"}:
        raise ValueError("index is not an object of format, key, created and files")
    if type(index["format"]) is not int or index["format"] != FORMAT:
        raise ValueError(f"index format {index['format']!r}, not {FORMAT}")
    if index["key"] != key:
        raise ValueError(f"index of another key ({str(index['key'])[:80]!r}): an entry copied or moved "
                         "under this key")
    created = index["created"]
    if not isinstance(created, str) or len(created) > 64:
        raise ValueError("index's created is not a time")
    files = index["files"]
    if not isinstance(files, dict) or not files:
        raise ValueError("index's files is not an object of file names")
    listed = {}
    for name, spec in files.items():
        if not FILE_NAME.fullmatch(name) or name == INDEX:
            raise ValueError(f"index names a file {name[:80]!r}, not a plain file name")
        if not (isinstance(spec, list) and len(spec) == 2 and type(spec[0]) is int and spec[0] >= 0
                and isinstance(spec[1], str) and KEY.fullmatch(spec[1])):
            raise ValueError(f"index's entry for {name} is not [size, SHA-256]")
        listed[name] = (spec[0], spec[1])
    return created, listed


def _read_index(where: Path, key: str) -> tuple[str, dict[str, tuple[int, str]], int]:
    raw = _read_regular(where / INDEX, MAX_INDEX_BYTES)
    try:
        created, listed = _index(raw, key)
    except RecursionError:  # JSON nested deeper than the parser goes
        raise ValueError("index nested too deeply") from None
    return created, listed, len(raw)


def load(folder: Path | None, key: str) -> Entry | None:
    """The entry ``key`` with every file checked against its index, or None (no cache, a cache
    folder that is not gearcheck's, no such entry, or one that does not read back: then it is
    removed, with a warning, if gearcheck made it)."""
    if folder is None:
        return None
    _check_key(key)
    if not _usable(folder, create=False):
        return None
    where = folder / key
    if not os.path.lexists(where):
        return None
    if not _ours(where):
        log.warning("CAD cache %s was not written by gearcheck: left as it is, building the CAD", where)
        return None
    try:
        created, listed, _ = _read_index(where, key)
        files = {}
        for name, (size, digest) in listed.items():
            data = _read_regular(where / name, size)
            if len(data) != size or _digest(data) != digest:
                raise ValueError(f"{name} does not match its index")
            files[name] = data
    except (OSError, ValueError) as exc:  # a file missing, cut short, edited or not a file; a bad index
        log.warning("CAD cache entry %s unreadable (%s): removed, building the CAD", where, exc)
        _remove(where)
        return None
    with contextlib.suppress(OSError):
        os.utime(where / INDEX)  # used now: the last to be evicted
    return Entry(key, files, created)


def discard(folder: Path | None, key: str) -> None:
    """Remove an entry (one whose files read back but whose content could not be used), if
    gearcheck made it."""
    if folder is not None:
        _check_key(key)
        if _tagged(folder):
            _remove(folder / key)


def store(folder: Path | None, key: str, files: Mapping[str, bytes], max_bytes: int = MAX_BYTES) -> bool:
    """Publish an entry (True if this call published it). Never fails the run: a cache that
    cannot be written (read-only, full disk) is a warning and the run goes on without it, and
    a folder that is not gearcheck's cache is left as it is (:func:`_usable`)."""
    if folder is None:
        return False
    _check_key(key)
    for name in files:
        if not FILE_NAME.fullmatch(name) or name == INDEX:
            raise ValueError(f"not a plain file name for a CAD cache entry: {name!r}")
    try:
        if not _usable(folder, create=True):
            return False
        if os.path.lexists(folder / key):
            return False
        staging = Path(tempfile.mkdtemp(prefix=f"{STAGING}{key[:16]}-", dir=folder))
        try:
            (staging / MARK).write_bytes(MARK_TEXT)  # first: what tells eviction it is gearcheck's
            for name, data in files.items():
                (staging / name).write_bytes(data)
            index = {"format": FORMAT, "key": key, "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                     "files": {name: [len(data), _digest(data)] for name, data in files.items()}}
            (staging / INDEX).write_text(json.dumps(index, indent=1) + "\n")
            os.rename(staging, folder / key)  # atomic; fails if another run published it first
        except OSError:
            shutil.rmtree(staging, ignore_errors=True)
            if os.path.lexists(folder / key):
                return False
            raise
    except OSError as exc:
        log.warning("CAD cache %s not written (%s): the run goes on without it", folder, exc)
        return False
    evict(folder, max_bytes)
    return True


def evict(folder: Path, max_bytes: int = MAX_BYTES) -> list[str]:
    """Remove the entries used longest ago until the rest fit in ``max_bytes`` (and the staging
    folders killed runs left over an hour ago); the removed entries' keys. Only what gearcheck
    made is counted or removed (:func:`_ours`, and an entry's own index): nothing else in the
    folder is touched, and a folder that is not gearcheck's cache is not looked into."""
    if not _tagged(folder):
        return []
    entries = []
    now = time.time()
    with os.scandir(folder) as found:
        names = [item.name for item in found]
    for name in names:
        path = folder / name
        try:
            if STAGING_NAME.fullmatch(name):
                if now - os.lstat(path).st_mtime > STALE_S:
                    _remove(path)
            elif KEY.fullmatch(name) and _ours(path):
                _, listed, index_bytes = _read_index(path, name)
                size = index_bytes + len(MARK_TEXT) + sum(size for size, _ in listed.values())
                entries.append((os.lstat(path / INDEX).st_mtime, size, name))
        except (OSError, ValueError):
            continue  # being removed, or not an entry
    entries.sort(key=lambda e: e[0], reverse=True)  # most recently used first
    kept, removed = 0, []
    for _, size, name in entries:
        kept += size
        if kept > max_bytes:
            _remove(folder / name)
            removed.append(name)
    return removed
