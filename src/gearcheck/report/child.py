"""A helper process for a run's report: ``python -m MODULE`` started before its input exists, so
that its start-up (the interpreter, VTK or matplotlib) overlaps the run's other stages. Its input
goes to its stdin from a writer thread (a pipe never blocks the run), its output is read from its
stdout by a reader thread, its log kept in a temporary file (never a pipe that fills and stops
it). The process owns nothing of the run: whatever it gives is checked by its caller, and a
process that dies or hangs is reported, never waited for past its time.
"""

from __future__ import annotations

import contextlib
import os
import queue
import subprocess
import sys
import tempfile
import threading
from typing import TypeVar


class ChildProcess:
    """``python -m module`` with its stdin fed by :meth:`send` and :meth:`finish`, and its
    stdout, stderr and exit status given by :meth:`wait`. Use it in a ``with`` block (or call
    :meth:`close`): leaving ends the process if it is still running."""

    def __init__(self, module: str, env: dict[str, str] | None = None):
        self._stderr = tempfile.TemporaryFile()  # noqa: SIM115  (closed by close())
        try:
            self._proc = subprocess.Popen([sys.executable, "-m", module], stdin=subprocess.PIPE,
                                          stdout=subprocess.PIPE, stderr=self._stderr,
                                          env=env if env is not None else dict(os.environ))
        except BaseException:
            self._stderr.close()
            raise
        self._stdout = bytearray()
        self._queue: queue.Queue[bytes | None] = queue.Queue()
        self._writer = threading.Thread(target=self._write, daemon=True)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._writer.start()
        self._reader.start()

    @property
    def pid(self) -> int:
        return self._proc.pid

    def _write(self) -> None:
        stdin = self._proc.stdin
        assert stdin is not None
        try:
            while (data := self._queue.get()) is not None:
                stdin.write(data)
                stdin.flush()
        except OSError:  # the process died (a broken pipe): its exit status says why
            pass
        finally:
            with contextlib.suppress(OSError):
                stdin.close()

    def _read(self) -> None:
        assert self._proc.stdout is not None
        while chunk := self._proc.stdout.read(1 << 16):
            self._stdout += chunk

    def send(self, data: bytes) -> None:
        """Queue ``data`` for the process's stdin (written while this process goes on)."""
        self._queue.put(data)

    def finish(self) -> None:
        """No more input: the process's stdin is closed once everything sent is written."""
        self._queue.put(None)

    def wait(self, timeout_s: float) -> tuple[int, bytes, bytes] | None:
        """(exit status, stdout, stderr) once the process has ended; None if its output did not
        end within ``timeout_s`` (the process is then ended)."""
        self._reader.join(timeout_s)
        if self._reader.is_alive():
            self.close()
            return None
        returncode = self._proc.wait()
        self._stderr.seek(0)
        return returncode, bytes(self._stdout), self._stderr.read()

    def kill(self) -> None:
        if self._proc.poll() is None:
            self._proc.kill()

    def running(self) -> bool:
        return self._proc.poll() is None

    def close(self) -> None:
        """End the process (if still running) and release its pipes and threads."""
        self.kill()
        self._queue.put(None)
        self._proc.wait()
        self._writer.join()
        self._reader.join()
        if self._proc.stdout is not None:
            self._proc.stdout.close()
        self._stderr.close()

    def __enter__(self) -> ChildProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class ChildOwner:
    """A user of one :class:`ChildProcess` (``self._child``), usable in a ``with`` block: leaving
    it, or :meth:`close`, ends the process if still running and releases its pipes."""

    _child: ChildProcess

    def close(self) -> None:
        self._child.close()

    def __enter__(self: _Owner) -> _Owner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_Owner = TypeVar("_Owner", bound=ChildOwner)
