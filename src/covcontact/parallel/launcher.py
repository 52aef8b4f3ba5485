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


def cores_here() -> int:
    """The cores this process may run on: its affinity mask where the system has one, at most the CPU quota of
    its control group (a container limited to 2 CPUs on a 64-core host sees 64 cores in its mask)."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    quota = cgroup_cpus()
    return max(1, min(cores, quota)) if quota is not None else cores


def cgroup_cpus(root: str = "/sys/fs/cgroup") -> int | None:
    """The CPU quota of this process's control group rounded up to whole CPUs (cgroup v2 ``cpu.max``, v1
    ``cpu.cfs_quota_us`` / ``cpu.cfs_period_us``); None where there is none or it cannot be read."""
    import math

    def read(name: str) -> str:
        try:
            with open(os.path.join(root, name)) as fh:
                return fh.read().strip()
        except OSError:
            return ""

    v2 = read("cpu.max").split()
    if len(v2) == 2 and v2[0] != "max":
        quota, period = v2
    else:
        quota, period = read("cpu/cpu.cfs_quota_us"), read("cpu/cpu.cfs_period_us")
    try:
        q, p = int(quota), int(period)
    except ValueError:
        return None
    return max(1, math.ceil(q / p)) if q > 0 and p > 0 else None


#: the variables by which a process started in an MPI job (an MPI singleton too, as a Python that loaded PETSc)
#: finds its launcher
_LAUNCHER_VARS = ("PMIX_", "PMI_", "ORTE_", "HYDRA_", "OMPI_MCA_orte_", "OMPI_MCA_ess", "OMPI_MCA_pmix", "OMPI_APP_CTX",
                  "OMPI_COMM_WORLD", "OMPI_UNIVERSE", "OMPI_FILE_LOCATION", "OMPI_NUM_APP_CTX", "OMPI_FIRST_RANKS")


def environment_for_mpiexec() -> dict[str, str]:
    """This process's environment for an ``mpiexec`` it starts: without the launcher variables of a job it may
    itself belong to (mpiexec would join that job instead of starting its own), and as root with Open MPI's
    permission to run as root."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(_LAUNCHER_VARS)}
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    return env


#: the thread counts a run started with ``--ranks auto`` divides among its ranks
THREAD_VARS = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def threads_per_rank(env: dict[str, str], ranks: int) -> dict[str, str]:
    """The thread-count variables of ``env`` that are set, each divided among ``ranks`` ranks (at least 1 each),
    so that ranks started on the cores of one run do not each take the whole run's threads."""
    return {k: str(max(1, int(env[k]) // ranks)) for k in THREAD_VARS if env.get(k, "").strip().isdigit()}


def is_open_mpi(mpiexec: str) -> bool:
    """Whether ``mpiexec`` is Open MPI's (it asks for --oversubscribe to run more ranks than cores, and kills its
    ranks right after passing SIGTERM or SIGINT on, but passes SIGUSR1 and SIGUSR2 on alone)."""
    import subprocess

    version = subprocess.run([mpiexec, "--version"], capture_output=True, text=True, check=False).stdout
    return "Open MPI" in version or "OpenRTE" in version
