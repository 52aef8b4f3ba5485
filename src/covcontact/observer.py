"""The events of a run and what listens to them (docs/architecture.md).

A run emits, in this order: ``started`` (a fresh run, before its first step) or ``resumed`` (continued from a
checkpoint, after every part has restored itself); per stage ``stage_entered``; per step
``increment_started``, then ``increment_converged`` or ``increment_failed``; and at the end ``ended`` with
the run's status (``"completed"``, ``"failed"``, ``"interrupted"``, ``"stopped"``). Everything that records a
run (result files, summary.json, convergence.csv, checkpoints, progress lines, pictures) is an ``Observer``;
observers are called in the order they were registered, and the run knows none of their formats.

Whatever has history that a resumed run needs (an observer's records, Newton's predictor, the linear solver's
history, the contact couplings) takes part in checkpoints through ``checkpoint()`` -> (arrays, meta) and
``restore(arrays, meta)``: arrays are named with the part's own prefix, meta entries with keys of its own.
"""

from __future__ import annotations

from typing import Protocol


class Checkpointed(Protocol):
    """A part of a run with something to keep in a checkpoint."""

    def checkpoint(self) -> tuple[dict, dict]:
        """(named arrays, JSON-able meta data) of this part for a checkpoint."""
        ...

    def restore(self, arrays: dict, meta: dict) -> None:
        """Take this part's arrays and meta data from a checkpoint being resumed."""
        ...


class Observer:
    """Listens to a run's events; every hook does nothing unless overridden. ``run`` is the ``Run`` that
    emits (its problem, model, Newton solver, displacement ``u`` and committed ``state``)."""

    def started(self, run) -> None:
        """A fresh run, before its first step (``run.warnings``: the set-up's warnings)."""

    def resumed(self, run) -> None:
        """A run continued from a checkpoint (every part restored), before its next step."""

    def stage_entered(self, run, procedure, entering: bool) -> None:
        """The run starts or continues the stage of ``procedure``; ``entering``: the run just moved into it
        from the stage before (not a resume in the middle of it, not the first stage)."""

    def increment_started(self, run, step: int, lam: float) -> None:
        """Step ``step`` to load factor ``lam`` is about to be made."""

    def increment_converged(self, run, inc) -> None:
        """Step ``inc`` (a ``procedure.Increment``) converged; ``run.state`` is its committed state."""

    def increment_failed(self, run, inc) -> None:
        """Step ``inc`` failed even after its cutbacks; the run ends after this event."""

    def ended(self, run, status: str) -> None:
        """The run ended with ``status``; ``run.timing``: its time split."""

    def checkpoint(self) -> tuple[dict, dict]:
        return {}, {}

    def restore(self, arrays: dict, meta: dict) -> None:
        pass
