"""Interrupts and a command's outputs.

- :class:`DeferredSignals`: short stretches of work that an interrupt must not cut in two (a
  folder swap, starting worker processes): SIGINT and SIGTERM arriving meanwhile are recorded,
  and raised again once the stretch is over, where the handlers in force then deal with them.
  Only the main thread of the main process may change signal handlers; elsewhere (a worker, a
  thread) it does nothing, and the stretch runs as it is.
- :data:`outputs` (an :class:`Outputs`): the files and folders the running command writes, each
  committed by one rename (a run folder's swap, a template file's replace). The command line
  declares them before any work; the rename that commits one records it, inside a
  :class:`DeferredSignals` stretch, so the record and the file system never disagree for the
  interrupt handler. The rule it serves: once every output is committed the command's result
  stands (an interrupt only adds a line saying so); before, an interrupt leaves whatever is not
  committed as it was.

Standard library only: the command line's interrupt handler reads this module (if loaded) at
any moment, start-up included.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import threading
from collections.abc import Iterable
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
        """The handlers from before the block back in force (once), every one of them even if a
        signal arriving meanwhile raises in the first one restored."""
        handlers, self._handlers = self._handlers, {}
        _put_back(list(handlers.items()))

    def deliver(self) -> None:
        """Raise the signals recorded meanwhile (handled by the restored handlers)."""
        pending, self.pending = list(dict.fromkeys(self.pending)), []
        for s in pending:
            signal.raise_signal(s)


def _put_back(handlers: list[tuple[int, Any]]) -> None:
    if not handlers:
        return
    (s, handler), rest = handlers[0], handlers[1:]
    try:
        signal.signal(s, handler if handler is not None else signal.SIG_DFL)
    finally:
        _put_back(rest)


# ------------------------------------------------------------------------------------------
# The running command's outputs


class _Output:
    """One declared output: its path as shown, whether something was there before, its identity
    then (to see a commit made by another process), whether it is committed."""

    def __init__(self, shown: str, noun: str, marker: str | None):
        self.shown, self.noun, self.marker = shown, noun, marker
        self.before = _identity(shown)
        self.previous = self.before is not None and not (os.path.isdir(shown) and not _any_entry(shown))
        self.written = False

    def replaced(self) -> bool:
        """Committed by another process (a worker of ``--all --jobs N``): the path is another
        file or folder than before, and a complete one (its run marker in it)."""
        now = _identity(self.shown)
        if now is None or now == self.before:
            return False
        return self.marker is None or os.path.isfile(os.path.join(self.shown, self.marker))


def _identity(path: str) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def _any_entry(folder: str) -> bool:
    try:
        with os.scandir(folder) as it:
            return next(it, None) is not None
    except OSError:
        return True


def _key(path: str | os.PathLike) -> str:
    return os.path.abspath(os.fspath(path))


def _listed(names: list[str]) -> str:
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


class Outputs:
    """The outputs of the command running now, in the order it writes them (see the module
    docstring). ``noun`` says what an output held before, for the interrupt's line ("run":
    "out/x keeps its previous run"; "version" for a file);
    ``marker``: the file a complete output folder holds, by which a commit made in another
    process is recognised (:attr:`elsewhere`)."""

    def __init__(self) -> None:
        self._declared: dict[str, _Output] = {}
        #: outputs may be committed by other processes too (``--all --jobs N``): those not
        #: recorded here are looked for on the file system
        self.elsewhere = False

    def clear(self) -> None:
        """No command running: nothing declared."""
        self._declared, self.elsewhere = {}, False

    def expect(self, paths: Iterable[str | os.PathLike], noun: str = "run", marker: str | None = None) -> None:
        """The running command writes ``paths`` (any earlier command's are forgotten)."""
        declared = {_key(p): _Output(str(p), noun, marker) for p in paths}
        self._declared, self.elsewhere = declared, False

    def declares(self, path: str | os.PathLike) -> bool:
        return _key(path) in self._declared

    def committed(self, path: str | os.PathLike) -> None:
        """``path`` was just committed (its rename done): call inside the stretch that defers
        signals across that rename. A path not declared (a run inside another's staging folder,
        a library call) is no output of the command, and ignored."""
        out = self._declared.get(_key(path))
        if out is not None:
            out.written = True

    def _states(self) -> list[tuple[_Output, bool]]:
        return [(o, o.written or (self.elsewhere and o.replaced())) for o in self._declared.values()]

    def complete(self) -> bool:
        """Every declared output is committed: the command's result stands, whatever interrupts
        it now. False while nothing is declared."""
        states = self._states()
        return bool(states) and all(done for _, done in states)

    def written(self) -> list[str]:
        """The declared outputs committed so far, as shown."""
        return [o.shown for o, done in self._states() if done]

    def after(self) -> str:
        """What the line of an interrupt that came once every output was committed says after
        "interrupted (SIG…)": "after out/x was written: it is complete"."""
        names = self.written()
        if len(names) == 1:
            return f"after {names[0]} was written: it is complete"
        return f"after {_listed(names) if names else 'its outputs'} were written: they are complete"

    def unwound(self) -> str:
        """What the line of an interrupt that unwound the command says: what was written, and
        that the rest keeps what it held ("nothing written, out/x keeps its previous run")."""
        states = self._states()
        done = [o.shown for o, d in states if d]
        kept = [o for o, d in states if not d and o.previous]
        parts = []
        if done:
            parts.append(f"{_listed(done)} {'was' if len(done) == 1 else 'were'} written: "
                         f"{'it is' if len(done) == 1 else 'they are'} complete")
        text = "nothing else written" if done else "nothing written"
        if kept:
            nouns = {o.noun for o in kept}
            noun = nouns.pop() if len(nouns) == 1 else "output"
            text += (f", {kept[0].shown} keeps its previous {noun}" if len(kept) == 1 else
                     f", {_listed([o.shown for o in kept])} keep their previous {noun}s")
        parts.append(text)
        return "; ".join(parts)


#: The outputs of the command running in this process (declared by the command line).
outputs = Outputs()
