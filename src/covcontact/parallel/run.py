"""The distributed run's strategy (``covcontact.solvers.run``): every MPI rank builds the distributed model
(its share of the elements), only the first writes files and prints, and an exception on one rank aborts
them all (the others would wait forever in the next collective call)."""

from __future__ import annotations

import sys
import traceback
from pathlib import Path


class DistributedRun:
    """What a run on the distributed solvers (``petsc``, ``petsc-gamg``) does differently."""

    def make_model(self, problem, tangent: str | None):
        from ..allocator import keep_freed_memory
        from .model import DistributedModel

        keep_freed_memory()  # PETSc's matrices and hierarchies of each iteration reuse memory (allocator.py)
        return DistributedModel(problem, tangent=tangent)

    def execute(self, model, run):
        if model.size == 1:
            return run()
        from ..io.validate import InputError

        try:
            return run()
        except InputError:  # a refused checkpoint: raised on every rank alike (exit 2)
            raise
        except Exception:  # noqa: BLE001  (maybe on one rank only: the others would wait forever)
            traceback.print_exc()
            sys.stderr.flush()
            model.comm.Abort(3)

    def check_resumed(self, model, state, out: Path) -> None:
        """The ranks' checkpoints must end at the same step (a rank may have stopped while writing)."""
        if model.size == 1:
            return
        from ..io.checkpoint import CheckpointError
        from .comm import gather_all

        steps = gather_all(model.comm, state.step)
        if len(set(steps)) > 1:
            raise CheckpointError(f"{out}: the ranks' checkpoints end at different steps {sorted(set(steps))} (a "
                                  f"rank stopped while writing); start again without --resume")

    def signal_comm(self, model):
        """The communicator over which a stop signal is agreed (None on one rank)."""
        return model.comm if model.size > 1 else None
