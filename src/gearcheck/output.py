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
- A commit — a run folder's swap, or the rename of a file that is one of the command's declared
  outputs (:data:`gearcheck.interrupts.outputs`, e.g. ``gearcheck new``'s template) — runs with
  SIGINT / SIGTERM deferred, and records itself there before they are delivered: an interrupt
  comes before the commit (nothing of it written) or after it (the output complete and known
  to be), never in between.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import fcntl
import logging
import os
import re
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from types import TracebackType

from gearcheck.interrupts import DeferredSignals, outputs
from gearcheck.params import ParamError

log = logging.getLogger("gearcheck")

# Marks a folder as a gearcheck run (a target holding anything else is never replaced).
RUN_MARKER = ".gearcheck-run"
_STAGING = ".staging-"
_OLD = ".old-"
_LOCK = ".lock"
# the longest hidden name a run makes beside the target: "." NAME ".staging-" and mkdtemp's 8
# characters; a file name holds at most 255 bytes
_HIDDEN_EXTRA = 1 + len(_STAGING) + 8
NAME_MAX = 255


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
    created but missing parents. A symbolic link is followed: the run replaces the folder it
    points to, and the link stays."""
    folder = Path(folder)
    check_folder_name(folder)
    real = resolved_target(folder)
    try:
        if real.exists():
            ensure_out_dir(real)  # a folder: writable? (probes with a temporary file, leaves nothing)
        else:
            ensure_out_dir(real.parent)
    except ParamError as exc:
        raise ParamError("--out", str(folder), exc.allowed) from None


def resolved_target(folder: Path) -> Path:
    """The absolute folder a run into ``folder`` replaces: a symbolic link's target (followed
    through every link, as the kernel does), else ``folder`` itself."""
    folder = Path(folder).absolute()
    return Path(os.path.realpath(folder)) if folder.is_symlink() else folder


def check_folder_name(folder: Path, flag: str = "--out") -> None:
    """``--out`` names a folder: not empty, not a root, '.' or '..', and short enough that the
    hidden staging folder beside it has a legal name."""
    text = str(folder)
    if text in ("", "."):
        raise ParamError(flag, text, "allowed a folder path (an empty path would write into the working folder)")
    if folder.name in ("", ".", ".."):
        raise ParamError(flag, text, "allowed a path that names a folder (not a root, '.' or '..')")
    size = len(os.fsencode(folder.name))
    if size > NAME_MAX - _HIDDEN_EXTRA:
        raise ParamError(flag, _shortened(text), f"allowed a folder name of at most {NAME_MAX - _HIDDEN_EXTRA} "
                         f"bytes (this one has {size}; the run is staged beside it under a longer name)")


def _shortened(text: str, keep: int = 60) -> str:
    return text if len(text) <= 2 * keep else f"{text[:keep]}…{text[-keep:]}"


def ensure_out_dir(folder: Path, flag: str = "--out") -> Path:
    """Create ``folder`` (and parents); a bad target is a ParamError naming ``flag``."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ParamError(flag, str(folder), "exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ParamError(flag, str(folder), f"cannot create folder: {exc.strerror}") from None
    if not os.access(folder, os.W_OK):
        raise ParamError(flag, str(folder), "folder is not writable")
    # os.access says yes to root even where no file can be made (/proc, /sys, read-only mounts):
    # try the real thing, the way every output file is written (a temporary file beside it).
    try:
        fd, probe = tempfile.mkstemp(prefix=".gearcheck-write-test.", suffix=".part", dir=folder)
    except OSError as exc:
        raise ParamError(flag, str(folder),
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
        if outputs.declares(path):  # the command's output: its commit
            with DeferredSignals():
                os.replace(tmp, path)
                tmp = None
                outputs.committed(path)
        else:
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
    message can name it. A target that is a symbolic link is followed: the folder it points to
    is replaced, the link stays.

    Beside the target, a run makes only hidden names of its own: ``.NAME.lock``,
    ``.NAME.staging-XXXXXXXX`` (mkdtemp's eight characters) and ``.NAME.old-PID``. What a killed
    run left is recognised by exactly these shapes (NAME taken literally, never as a pattern), so
    no other run's or user's file is ever removed."""

    active: RunFolder | None = None  # the run being written now
    # what the last run did, for an interrupt's message (one of the two is set)
    abandoned: str | None = None  # the target it left unchanged (failed or interrupted)
    written: str | None = None  # the target it replaced (its old run possibly still being removed)

    def __init__(self, target: Path):
        target = Path(target)
        check_folder_name(target)
        self.target = resolved_target(target)
        self.shown = str(target)
        self.parent = self.target.parent
        self.name = self.target.name
        self._staging: Path | None = None
        self._old: Path | None = None
        self.committed = False
        self._lock_fd: int | None = None
        check_folder_name(self.target)  # a link's target names a folder too

    def _hidden(self, kind: str) -> str:
        return f".{self.name}{kind}"

    def _leftovers(self, kind: str, tail: str) -> list[Path]:
        """Hidden folders beside the target of this run's own ``kind`` (staging or old), matched
        exactly: ``.NAME`` + kind + ``tail`` (a regular expression for the random part)."""
        shape = re.compile(re.escape(self._hidden(kind)) + tail)
        try:
            names = os.listdir(self.parent)
        except OSError:
            return []
        return [self.parent / n for n in names if shape.fullmatch(n) and (self.parent / n).is_dir()
                and not (self.parent / n).is_symlink()]

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
            RunFolder.abandoned, RunFolder.written = self.shown, None
        try:
            for left in (staging, self._old):  # an interrupt while the old run was being removed
                if left is not None and left.exists():
                    shutil.rmtree(left, ignore_errors=True)
        finally:
            self._staging = self._old = None
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
        """Swap the staging folder in; the old run (if any) is deleted after the swap. An
        interrupt during the swap takes effect once it is done and recorded (the target holds
        the new run, :data:`gearcheck.interrupts.outputs` knows it); one while the old run is
        being deleted leaves the new run, and the old one is deleted on the way out."""
        log.info("stage commit: %s", self.shown)
        try:
            (self.staging / RUN_MARKER).write_text(f"gearcheck run folder {self.name}\n", encoding="utf-8")
            with DeferredSignals():
                self._swap()
                self.committed = True
                RunFolder.written, RunFolder.abandoned = self.shown, None
                outputs.committed(self.shown)
        except OSError as exc:
            raise output_error(exc, self.target) from None
        old = self._old
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
            self._old = None
        return self.target

    def _swap(self) -> None:
        """The staging folder in place of the target; the previous run (if any) left in
        ``self._old``. Raises OSError with the target as it was."""
        staging = self.staging
        old = self.parent / f"{self._hidden(_OLD)}{os.getpid()}"
        if not self.target.exists():
            os.rename(staging, self.target)
            self._staging = None
        elif _exchange(staging, self.target):
            self._staging, self._old = None, staging  # the new run is in: the staging name holds the old
            with contextlib.suppress(OSError):
                os.rename(staging, old)  # named as what it is (a kill while it is removed: _recover)
                self._old = old
        else:
            os.rename(self.target, old)  # a crash here is completed by the next run (_recover)
            try:
                os.rename(staging, self.target)
            except OSError:
                with contextlib.suppress(OSError):
                    os.rename(old, self.target)  # the previous run back
                raise
            self._staging, self._old = None, old

    # -- lock and leftovers --------------------------------------------------------------------
    def _lock(self) -> None:
        path = self.parent / self._hidden(_LOCK)
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o666 & ~_umask())
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
        olds = sorted(self._leftovers(_OLD, r"[0-9]+"), key=lambda p: p.stat().st_mtime)
        if not self.target.exists() and not self.target.is_symlink() and olds:
            log.info("restoring %s from an interrupted swap", self.target)
            os.rename(olds.pop(), self.target)
        for left in [*olds, *self._leftovers(_STAGING, r"[a-z0-9_]{8}")]:
            log.info("removing %s left by an interrupted run", left)
            shutil.rmtree(left, ignore_errors=True)


def remove_leftovers(folder: Path) -> None:
    """What a run into ``folder`` that was stopped without a chance to clean up (a worker
    process killed by its parent) left beside it: removed, under the folder's lock. Nothing is
    done while another run holds the lock, nor where the folder's name is not one a run uses."""
    try:
        run = RunFolder(folder)
        run._lock()
    except (ParamError, OSError):
        return
    try:
        run._recover()
    except OSError as exc:
        log.info("leftovers of %s not removed: %s", folder, exc)
    finally:
        run._unlock()
