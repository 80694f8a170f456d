"""Atomic output: write to a temporary file in the target folder, then rename."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from gearcheck.params import ParamError


def ensure_out_dir(folder: Path) -> Path:
    """Create ``folder`` (and parents); a bad target is a ParamError naming ``--out``."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ParamError("--out", str(folder), "exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ParamError("--out", str(folder), f"cannot create folder: {exc.strerror}") from None
    if not os.access(folder, os.W_OK):
        raise ParamError("--out", str(folder), "folder is not writable")
    # os.access says yes to root even where no file can be made (/proc, /sys, read-only mounts):
    # try the real thing, the way every output file is written (a temporary file beside it).
    try:
        fd, probe = tempfile.mkstemp(prefix=".gearcheck-write-test.", suffix=".part", dir=folder)
    except OSError as exc:
        raise ParamError("--out", str(folder),
                         f"folder is not writable (cannot create a file there: {exc.strerror})") from None
    os.close(fd)
    os.unlink(probe)
    return folder


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def temp_path_beside(path: Path) -> Path:
    """A fresh hidden temporary file next to ``path`` (same file system, so rename is atomic),
    with ordinary file permissions (mkstemp's are owner-only)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())
    return Path(tmp)


def atomic_write_bytes(path: Path, data: bytes) -> None:
    path = Path(path)
    tmp = temp_path_beside(path)
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))
