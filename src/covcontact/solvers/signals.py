"""SIGTERM and SIGINT during a run: stop at once, keep every file on disk valid.

Inside :meth:`StopSignals.critical` (writing the result files and the checkpoint of a converged step) a
signal is held back until the block ends, so the files of one step are written together or not at all;
anywhere else the handler raises :class:`Interrupted` at once, which drops the step in flight.

A distributed run (several MPI ranks) cannot stop one rank at once: the others would wait for it in their
next collective operation. There the handler only records the signal, and :meth:`StopSignals.poll`, called
by every rank at the same points of the computation (each Newton iteration, each step's end), agrees on it
with one allgather and raises :class:`Interrupted` on every rank together. Open MPI's mpiexec kills its ranks
moments after passing SIGTERM or SIGINT on, but passes SIGUSR1 and SIGUSR2 on and lets them run: a distributed
run takes SIGUSR1 as SIGTERM and SIGUSR2 as SIGINT (``covcontact run --ranks`` sends those to mpiexec).
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import ClassVar


class Interrupted(BaseException):
    """The run was stopped by a signal; ``exit_code`` is 128 + the signal number (130, 143)."""

    def __init__(self, signum: int):
        super().__init__(f"stopped by {signal.Signals(signum).name}")
        self.signum = signum
        self.exit_code = 128 + signum


class StopSignals:
    """Context manager installing the handlers (main thread only; else a no-op).

    ``comm``: the MPI communicator of a distributed run with more than one rank: signals are then recorded
    and acted on at :meth:`poll` (collective)."""

    SIGNALS = (signal.SIGTERM, signal.SIGINT)
    #: a distributed run's stop requests passed on by mpiexec, and the signal each stands for
    RELAYED: ClassVar[dict] = {signal.SIGUSR1: signal.SIGTERM, signal.SIGUSR2: signal.SIGINT}

    def __init__(self, enabled: bool = True, comm=None):
        self.enabled = enabled and threading.current_thread() is threading.main_thread()
        self.comm = comm if comm is not None and comm.Get_size() > 1 else None
        self._old: dict = {}
        self._depth = 0
        self._pending: int | None = None

    def _handler(self, signum, frame) -> None:
        signum = int(self.RELAYED.get(signum, signum))
        if self._depth > 0 or self.comm is not None:
            self._pending = self._pending or signum
            return
        raise Interrupted(signum)

    def poll(self) -> None:
        """Distributed: raise Interrupted on every rank if any rank has been signalled (the lowest signal
        number among them: SIGINT before SIGTERM). Every rank must call it at the same point. Serial: nothing
        (the handler has already raised)."""
        if self.comm is None:
            return
        signals = [s for s in self.comm.allgather(self._pending) if s]
        if signals:
            self._pending = None
            raise Interrupted(min(signals))

    def __enter__(self) -> StopSignals:
        if self.enabled:
            for s in self.SIGNALS + (tuple(self.RELAYED) if self.comm is not None else ()):
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
        if self._depth == 0 and self._pending is not None and self.comm is None:
            signum, self._pending = self._pending, None
            raise Interrupted(signum)
