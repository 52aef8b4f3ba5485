"""What the MPI launcher (mpiexec of Open MPI, MPICH or a PMIx launcher) tells a process through its
environment: read without starting MPI, so that a serial run never loads it."""

from __future__ import annotations

import os

_SIZE = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS")
_RANK = ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK", "MPI_LOCALRANKID")


def _first_int(keys: tuple[str, ...], default: int) -> int:
    for key in keys:
        value = os.environ.get(key, "")
        if value.isdigit():
            return int(value)
    return default


def under_launcher() -> bool:
    """Whether this process was started by an MPI launcher (even as its only rank)."""
    return any(key in os.environ for key in _SIZE)


def ranks_from_env() -> int:
    """The number of ranks of the MPI job this process was started in, 1 outside one."""
    return _first_int(_SIZE, 1)


def rank_from_env() -> int:
    """This process's rank in the MPI job it was started in, 0 outside one."""
    return _first_int(_RANK, 0) if ranks_from_env() > 1 else 0
