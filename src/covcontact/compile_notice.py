"""Tell the user when a run compiles numba kernels (the first run of an installation, or after a numba
upgrade): one line on stderr at the first compilation, so that a slow first run is not a mystery."""

from __future__ import annotations

import sys

_installed = False

MESSAGE = ("covcontact: compiling the numerical kernels for this installation (once: later runs load them "
           "from numba's cache, see NUMBA_CACHE_DIR); this first run takes minutes longer")


def install(stream=None) -> None:
    """Print MESSAGE on ``stream`` (default stderr) when numba compiles anything for the first time; under
    mpiexec only rank 0 says it."""
    global _installed
    if _installed:
        return
    _installed = True
    from .parallel.launcher import rank_from_env

    if rank_from_env() != 0:
        return
    from numba.core import event

    class _Notice(event.Listener):
        said = False

        def on_start(self, e) -> None:
            if not self.said:
                self.said = True
                print(MESSAGE, file=stream or sys.stderr, flush=True)

        def on_end(self, e) -> None:
            pass

    event.register("numba:compile", _Notice())
