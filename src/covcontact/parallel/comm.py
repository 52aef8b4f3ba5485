"""MPI helpers of the distributed run: the world communicator, sums every rank agrees on bit for bit.

mpi4py is imported only here and only when a distributed run starts, so the serial path never loads MPI.
Sums are reduced on rank 0 and broadcast (not ``Allreduce``): every rank then holds bitwise identical
vectors, so the Newton decisions taken from them (norms, convergence, cutbacks) agree on every rank.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np


def world() -> Any:
    """mpi4py's COMM_WORLD (initialises MPI; a plain ``python`` run is one rank). InputError where the launcher
    started several processes but MPI sees one rank in each: an ``mpiexec`` of another MPI than the one mpi4py
    was built on, whose processes would each run the whole problem into the same output folder."""
    from mpi4py import MPI

    from ..io.validate import InputError
    from .launcher import ranks_from_env

    comm = MPI.COMM_WORLD
    started = ranks_from_env()
    if started > 1 and comm.size == 1:
        raise InputError(f"mpiexec started {started} processes, but MPI sees one rank in each: that "
                         f"mpiexec belongs to another MPI than mpi4py's (mpi4py.get_config() names it); put that "
                         f"MPI's mpiexec first on the PATH, or run one process (--ranks 1)")
    return comm


def sum_all(comm, a: np.ndarray) -> np.ndarray:
    """Elementwise sum of ``a`` over the ranks, identical on every rank (a new array)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    if comm.size == 1:
        return a.copy()
    from mpi4py import MPI

    out = np.empty_like(a)
    comm.Reduce(a, out, op=MPI.SUM, root=0)
    comm.Bcast(out, root=0)
    return out


def max_all(comm, value: float) -> float:
    """Largest value over the ranks."""
    return value if comm.size == 1 else comm.allreduce(value, op=_op("MAX"))


def min_all(comm, value: float) -> float:
    """Smallest value over the ranks."""
    return value if comm.size == 1 else comm.allreduce(value, op=_op("MIN"))


def count_all(comm, value: int) -> int:
    """Integer sum over the ranks."""
    return int(value) if comm.size == 1 else int(comm.allreduce(int(value), op=_op("SUM")))


def gather_all(comm, obj) -> list:
    """[obj of rank 0, obj of rank 1, ...] on every rank."""
    return [obj] if comm.size == 1 else comm.allgather(obj)


def _op(name: str):
    from mpi4py import MPI

    return getattr(MPI, name)


def share_cores(comm) -> int:
    """Give each rank its share of the cores for the numba element loops; returns the thread count.

    Left alone when ``NUMBA_NUM_THREADS`` is set. A rank bound to some cores (Open MPI binds to one core
    per rank by default) uses those; an unbound rank shares the node's cores with the ranks on its node; the
    ranks of a node share its control group's CPU quota where it has one.
    """
    import numba

    if comm.size == 1 or "NUMBA_NUM_THREADS" in os.environ:
        return numba.get_num_threads()
    from mpi4py import MPI

    from .launcher import cgroup_cpus

    local = comm.Split_type(MPI.COMM_TYPE_SHARED)
    n_local = local.size
    local.Free()
    mine = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    total = os.cpu_count() or mine
    threads = mine if mine < total else max(1, total // n_local)
    quota = cgroup_cpus()  # a container's CPUs, shared by the ranks on its node
    if quota is not None:
        threads = min(threads, max(1, quota // n_local))
    threads = max(1, min(threads, numba.config.NUMBA_NUM_THREADS))
    numba.set_num_threads(threads)
    return threads
