"""SIGTERM and SIGINT during a run: stop at once, keep every file on disk valid.

Inside :meth:`StopSignals.critical` (writing the result files and the checkpoint of a converged step) a
signal is held back until the block ends, so the files of one step are written together or not at all;
anywhere else the handler raises :class:`Interrupted` at once, which drops the step in flight.
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager


class Interrupted(BaseException):
    """The run was stopped by a signal; ``exit_code`` is 128 + the signal number (130, 143)."""

    def __init__(self, signum: int):
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.signum = signum
        self.exit_code = 128 + signum


class StopSignals:
    """Context manager installing the handlers (main thread of a serial run only; else a no-op)."""

    SIGNALS = (signal.SIGTERM, signal.SIGINT)

    def __init__(self, enabled: bool = True):
        self.enabled = enabled and threading.current_thread() is threading.main_thread()
        self._old: dict = {}
        self._depth = 0
        self._pending: int | None = None

    def _handler(self, signum, frame) -> None:
        if self._depth > 0:
            self._pending = signum
            return
        raise Interrupted(signum)

    def __enter__(self) -> StopSignals:
        if self.enabled:
            for s in self.SIGNALS:
                self._old[s] = signal.signal(s, self._handler)
        return self

    def __exit__(self, *exc) -> None:
        for s, h in self._old.items():
            signal.signal(s, h)
        self._old.clear()

    @contextmanager
    def critical(self):
        """A block that a signal does not cut; a signal that came meanwhile stops the run after it."""
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
        if self._depth == 0 and self._pending is not None:
            signum, self._pending = self._pending, None
            raise Interrupted(signum)
