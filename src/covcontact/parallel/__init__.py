"""Distributed runs over MPI: ``mpiexec -n N covcontact run PROBLEM.toml --solver petsc``.

Replicated state, distributed work: every rank holds the whole problem and displacement vector, assembles
its own elements and contact slaves, and hands its share of the tangent to one distributed PETSc matrix
(:mod:`covcontact.solvers.petsc_backend`). Nothing here is imported by a serial run.
"""

from __future__ import annotations

__all__ = ["DistMatrix", "DistributedModel", "DofLayout", "rcb"]


def __getattr__(name: str):
    if name in ("DistributedModel", "DistMatrix"):
        from . import model

        return getattr(model, name)
    if name in ("DofLayout", "rcb"):
        from . import partition

        return getattr(partition, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
