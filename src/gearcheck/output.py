"""Output folders as transactions: a run's files are written into a staging folder beside the
target, verified, and swapped in by renames, so ``out/NAME`` holds the previous complete run or
the new complete run, never a mix, whatever fails or whoever interrupts.

- :class:`RunFolder` locks the target (a second run into the same folder is refused), removes
  what a killed run left (staging folders, half-swapped old runs), stages, and on
  :meth:`RunFolder.commit` swaps the staging folder in (an atomic exchange where the kernel has
  one, else two renames that the next run completes) and deletes the old run last.
- Every write failure (no space, file too large, no permission, name too long) becomes one
  :class:`OutputError` line naming the path and the cause; the staging folder is removed and
  the target left as it was.
- :func:`atomic_write_bytes` / :func:`atomic_write_text`: one file, temp file then rename (used
  inside the staging folder, and for single files such as bench/fuzz reports).
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import logging
import os
import shutil
import tempfile
from pathlib import Path
from collections.abc import Callable
from types import TracebackType

from gearcheck.params import ParamError

log = logging.getLogger("gearcheck")

# Marks a folder as a gearcheck run (a target holding anything else is never replaced).
RUN_MARKER = ".gearcheck-run"
_STAGING = ".staging-"
_OLD = ".old-"
_LOCK = ".lock"


class OutputError(ParamError):
    """A file or folder could not be written: one line naming the path and the cause (exit 2)."""

    def __init__(self, path: str | os.PathLike, cause: str):
        super().__init__("", None, cause, str(path))


def output_error(exc: OSError, path: str | os.PathLike | None = None, verb: str = "write") -> OutputError:
    """The one line for an OSError raised while writing (or ``verb``-ing) ``path``."""
    where = exc.filename if exc.filename else path
    code = errno.errorcode.get(exc.errno or 0, "")
    cause = f"cannot {verb}: {exc.strerror or exc}" + (f" ({code})" if code else "")
    return OutputError(where if where is not None else "output", cause)


def check_out_target(folder: Path) -> None:
    """Before any work: ``--out`` names a folder that a run can be swapped into — an existing
    writable folder, or a new one under a parent that can be created and written. Nothing is
    created but missing parents."""
    folder = Path(folder)
    check_folder_name(folder)
    try:
        if folder.exists():
            ensure_out_dir(folder)  # a folder: writable? (probes with a temporary file, leaves nothing)
        else:
            ensure_out_dir(folder.absolute().parent)
    except ParamError as exc:
        raise ParamError("--out", str(folder), exc.allowed) from None


def check_folder_name(folder: Path) -> None:
    """``--out`` names a folder: not empty, not a root, '.' or '..'."""
    text = str(folder)
    if text in ("", "."):
        raise ParamError("--out", text, "allowed a folder path (an empty path would write into the working folder)")
    if folder.name in ("", ".", ".."):
        raise ParamError("--out", text, "allowed a path that names a folder (not a root, '.' or '..')")


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


def replace_atomically(path: Path, data: bytes, check: Callable[[Path], None] | None = None) -> None:
    """Write ``data`` to a temporary file beside ``path``, fsync it, let ``check`` read it (it
    raises to refuse it), then rename it over ``path``. Errors propagate as raised; no temporary
    file is left whatever fails. The one atomic write: :func:`atomic_write_bytes` and the STEP
    writer turn its errors into their own one-line errors."""
    path = Path(path)
    tmp: Path | None = None
    try:
        tmp = temp_path_beside(path)
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        if check is not None:
            check(tmp)
        os.replace(tmp, path)
        tmp = None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                tmp.unlink()


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename; an OSError becomes one
    :class:`OutputError` line, and no temporary file is left."""
    try:
        replace_atomically(path, data)
    except OSError as exc:
        raise output_error(exc, path) from None


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


# ------------------------------------------------------------------------------------------
# The run folder


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux renameat2 RENAME_EXCHANGE); False where unsupported."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), str(b))


def is_run_folder(folder: Path) -> bool:
    """A folder gearcheck may replace: empty, or a run it wrote (marker, or an older version's
    manifest.json)."""
    if not any(folder.iterdir()):
        return True
    if (folder / RUN_MARKER).is_file():
        return True
    manifest = folder / "manifest.json"
    try:
        return manifest.is_file() and '"gearcheck_version"' in manifest.read_text(encoding="utf-8")[:4096]
    except (OSError, UnicodeDecodeError):
        return False


class RunFolder:
    """One run's output folder as a transaction (see the module docstring).

    ``with RunFolder(target) as run: ...write into run.staging...; run.commit()``. Leaving the
    block without commit (an exception, an interrupt) removes the staging folder and leaves the
    target as it was. The current run is recorded in :data:`active` so that an interrupt
    message can name it."""

    active: RunFolder | None = None  # the run being written now
    abandoned: str | None = None  # the last target a run left unchanged (failed or interrupted)

    def __init__(self, target: Path):
        target = Path(target)
        check_folder_name(target)
        self.target = target.absolute()
        self.shown = str(target)
        self.parent = self.target.parent
        self.name = self.target.name
        self._staging: Path | None = None
        self.committed = False
        self._lock_fd: int | None = None

    def _hidden(self, kind: str) -> str:
        return f".{self.name}{kind}"

    # -- lifecycle -----------------------------------------------------------------------------
    def __enter__(self) -> RunFolder:
        check_out_target(Path(self.shown))
        self._lock()
        try:
            self._recover()
            if self.target.is_dir() and not is_run_folder(self.target):
                raise ParamError("--out", self.shown, "holds files that are not a gearcheck run: allowed a new, "
                                 "empty or earlier gearcheck output folder (nothing there is replaced)")
            try:
                self._staging = Path(tempfile.mkdtemp(prefix=self._hidden(_STAGING), dir=self.parent))
                os.chmod(self._staging, 0o777 & ~_umask())
            except OSError as exc:
                raise output_error(exc, self.parent) from None
            RunFolder.active = self
        except BaseException:
            self._unlock()
            raise
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        staging = self._staging
        if not self.committed and exc is not None:
            RunFolder.abandoned = self.shown
        try:
            if staging is not None and staging.exists():
                shutil.rmtree(staging, ignore_errors=True)
        finally:
            self._staging = None
            RunFolder.active = None
            self._unlock()
        if isinstance(exc, OSError):
            exc = output_error(exc, staging)
        if isinstance(exc, OutputError) and staging is not None and str(staging) in exc.source:
            # name the file as the user knows it: inside the target, not the staging folder
            raise OutputError(exc.source.replace(str(staging), self.shown), exc.allowed) from None
        if isinstance(exc, OutputError):
            raise exc from None

    @property
    def staging(self) -> Path:
        """Where this run's files are written until :meth:`commit`."""
        if self._staging is None:
            raise RuntimeError("the run folder is not open (use it in a with block, before commit)")
        return self._staging

    def commit(self) -> Path:
        """Swap the staging folder in; the old run (if any) is deleted after the swap."""
        log.info("stage commit: %s", self.shown)
        try:
            (self.staging / RUN_MARKER).write_text(f"gearcheck run folder {self.name}\n", encoding="utf-8")
            if not self.target.exists():
                os.rename(self.staging, self.target)
                old = None
            elif _exchange(self.staging, self.target):
                old = self.staging  # now holds the previous run
            else:
                old = self.parent / f"{self._hidden(_OLD)}{os.getpid()}"
                os.rename(self.target, old)  # a crash here is completed by the next run (_recover)
                os.rename(self.staging, self.target)
        except OSError as exc:
            raise output_error(exc, self.target) from None
        self._staging = None
        self.committed = True
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
        return self.target

    # -- lock and leftovers --------------------------------------------------------------------
    def _lock(self) -> None:
        path = self.parent / self._hidden(_LOCK)
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666 & ~_umask())
        except OSError as exc:
            raise output_error(exc, path) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise ParamError("--out", self.shown, "another gearcheck run is writing this folder now "
                             "(wait for it to finish, or choose another --out)") from None
        self._lock_fd = fd

    def _unlock(self) -> None:
        if self._lock_fd is not None:
            with contextlib.suppress(OSError):
                fcntl.flock(self._lock_fd, fcntl.LOCK_UN)
                os.close(self._lock_fd)
            self._lock_fd = None

    def _recover(self) -> None:
        """Under the lock: finish what a killed run left. A previous run moved aside but never
        replaced is put back; staging folders and swapped-out old runs are deleted."""
        olds = sorted(self.parent.glob(self._hidden(_OLD) + "*"), key=lambda p: p.stat().st_mtime)
        if not self.target.exists() and olds:
            log.info("restoring %s from an interrupted swap", self.target)
            os.rename(olds.pop(), self.target)
        for left in [*olds, *self.parent.glob(self._hidden(_STAGING) + "*")]:
            log.info("removing %s left by an interrupted run", left)
            shutil.rmtree(left, ignore_errors=True)
