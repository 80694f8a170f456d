"""Short stretches of work that an interrupt must not cut in two (a folder swap, starting worker
processes): SIGINT and SIGTERM arriving meanwhile are recorded, and raised again once the
stretch is over, where the handlers in force then deal with them.

Only the main thread of the main process may change signal handlers; elsewhere (a worker, a
thread) :class:`DeferredSignals` does nothing, and the stretch runs as it is.
"""

from __future__ import annotations

import multiprocessing as mp
import signal
import threading
from typing import Any

DEFERRED = (signal.SIGINT, signal.SIGTERM)


def may_handle_signals() -> bool:
    """True in the main thread of the main process (where Python lets signal handlers change)."""
    return mp.parent_process() is None and threading.current_thread() is threading.main_thread()


class DeferredSignals:
    """``with DeferredSignals(): ...``: SIGINT and SIGTERM only recorded inside the block, then
    raised again on leaving it, once each, in the order they came."""

    def __init__(self) -> None:
        self.active = may_handle_signals()
        self.pending: list[int] = []
        self._handlers: dict[int, Any] = {}

    def _record(self, signum: int, _frame: object) -> None:
        self.pending.append(signum)

    def __enter__(self) -> DeferredSignals:
        if self.active:
            self._handlers = {s: signal.signal(s, self._record) for s in DEFERRED}
        return self

    def __exit__(self, *exc: object) -> None:
        self.restore()
        self.deliver()

    def restore(self) -> None:
        """The handlers from before the block back in force (once)."""
        handlers, self._handlers = self._handlers, {}
        for s, handler in handlers.items():
            signal.signal(s, handler if handler is not None else signal.SIG_DFL)

    def deliver(self) -> None:
        """Raise the signals recorded meanwhile (handled by the restored handlers)."""
        pending, self.pending = list(dict.fromkeys(self.pending)), []
        for s in pending:
            signal.raise_signal(s)
