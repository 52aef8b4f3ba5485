"""Which linear solver and how many MPI ranks a run gets (``linear = "auto"``, ``--ranks auto``).

Decided before a run starts, from the problem and the machine: the launcher (``covcontact run``) and
``solve_problem`` ask here; the run itself only receives the answer.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.validate import InputError

#: ``linear = "auto"`` hands a frictionless problem of solid (hex/tet) bodies of compressible materials with at
#: least this many dofs to ``petsc-gamg`` where it is installed (docs/performance.md: 2.5x faster than PARDISO
#: on the Hertz ball at 199,053 dofs, 3.5x on two deformable blocks at 192,480); else to the direct default
AUTO_AMG_DOFS = 100_000
#: the largest Poisson's ratio of such a problem: nearly incompressible bodies slow AMG down
AUTO_AMG_NU = 0.45
#: the largest share of nodes on the bodies' boundaries: a bulky mesh (0.11-0.19 for the raced 2e5-dof meshes)
#: factorises slowly, a plate-like one (1.0 with one element through the thickness) quickly and is hard for AMG
AUTO_AMG_BOUNDARY = 0.3


def auto_amg(problem) -> bool:
    """Whether ``linear = "auto"`` picks the AMG-preconditioned CG of ``petsc-gamg`` for ``problem``: at least
    ``AUTO_AMG_DOFS`` dofs of deformable bodies, all of them ``solid`` (not solid-shell or F-bar) with a
    material of Poisson's ratio at most ``AUTO_AMG_NU``, bulky meshes (at most ``AUTO_AMG_BOUNDARY`` of their
    nodes on a boundary face), no friction (CG needs a symmetric tangent), no rigid body with free components
    (the distributed model has none yet)."""
    from ..mesh.faces import FACES, boundary_faces

    n_nodes = sum(b.mesh.points.shape[0] for b in problem.bodies)
    if 3 * n_nodes < AUTO_AMG_DOFS:
        return False
    if any(b.formulation != "solid" or not 0.0 <= float(getattr(b.material, "nu", 1.0)) <= AUTO_AMG_NU
           or b.mesh.cell_type not in FACES for b in problem.bodies):
        return False
    if any(c.friction for c in problem.contacts) or any(rb.free or rb.attach for rb in problem.rigid) or _dynamic(problem) \
            or getattr(problem, "gravity", None) is not None or getattr(problem, "equations", None) \
            or getattr(problem, "mpcs", None) \
            or getattr(problem, "springs", None) or getattr(problem, "dashpots", None):
        return False
    on_boundary = sum(np.unique(boundary_faces(b.mesh)[0]).size for b in problem.bodies)
    return on_boundary <= AUTO_AMG_BOUNDARY * n_nodes


def requested_linear(problem, linear: str | None) -> str:
    """The linear solver asked for: ``linear`` (the command line's), else the problem's, else ``"auto"``."""
    return (linear or problem.solver.linear or "auto").lower().strip()


def resolve_linear(problem, linear: str | None, ranks: int | None = None) -> str:
    """The linear solver of a run: :func:`requested_linear`, whose ``"auto"`` becomes ``petsc-gamg`` where
    :func:`auto_amg` says so and it is installed, else stays ``"auto"`` (the first direct backend available).
    Run as several MPI ranks (``ranks``, by default what the launcher's environment says), ``"auto"`` becomes
    ``petsc-gamg`` where :func:`auto_amg` says so, else ``petsc`` (MUMPS): the distributed solvers."""
    from ..parallel.launcher import ranks_from_env
    from .linear import _probe

    name = requested_linear(problem, linear)
    if name != "auto":
        return name
    if auto_amg(problem) and _probe("petsc-gamg")[0]:
        return "petsc-gamg"
    return "petsc" if (ranks or ranks_from_env()) > 1 else name


#: a run that ``auto`` hands to petsc-gamg on several cores is started as one MPI rank per core, with at least this
#: many dofs per rank (GAMG's coarse levels and the ranks' shared interfaces cost more than they save below it)
AUTO_DOFS_PER_RANK = 50_000


def thread_budget() -> int:
    """The cores a run may use: those this process may run on, at most ``NUMBA_NUM_THREADS`` where it is set."""
    import os

    from ..parallel.launcher import cores_here

    budget = cores_here()
    value = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    return max(1, min(budget, int(value))) if value.isdigit() else budget


def checkpoint_ranks(out: Path) -> int | None:
    """The number of ranks that wrote the checkpoint in ``out`` (None where there is none)."""
    if (out / "checkpoint.npz").is_file():
        return 1
    for path in sorted(out.glob("checkpoint.rank0-of-*.npz")):
        n = path.name[len("checkpoint.rank0-of-"):-len(".npz")]
        if n.isdigit():
            return int(n)
    return None


def auto_ranks(problem, linear: str | None, out: str | Path | None, resume: bool) -> int:
    """How many MPI ranks ``covcontact run`` starts without ``--ranks``: one (this process) unless ``auto`` hands
    the problem to ``petsc-gamg`` (:func:`auto_amg`), whose Krylov solves and GAMG run one thread per rank, and the
    run may use several cores (:func:`thread_budget`) and ``mpiexec`` is on the PATH: then one rank per core, at
    most one per ``AUTO_DOFS_PER_RANK`` dofs. ``--resume`` takes the number of ranks of the checkpoint it resumes.
    A process that an MPI launcher started is a rank itself: one."""
    import shutil

    from ..parallel.launcher import under_launcher

    if under_launcher() or requested_linear(problem, linear) != "auto":
        return 1
    folder = Path(out) if out is not None else Path("results") / problem.name
    if resume and (n := checkpoint_ranks(folder)) is not None:
        return n
    if resolve_linear(problem, linear, ranks=1) != "petsc-gamg" or shutil.which("mpiexec") is None:
        return 1
    dofs = 3 * sum(b.mesh.points.shape[0] for b in problem.bodies)
    return max(1, min(thread_budget(), dofs // AUTO_DOFS_PER_RANK))


def distributes(linear: str) -> bool:
    """Whether the linear solver ``linear`` runs the distributed model (``petsc*``)."""
    from .linear import REGISTRY, backend_class

    return linear in REGISTRY and getattr(backend_class(linear), "distributed", False)


def auto_line(linear: str, ranks: int, one_core_hint: bool = False, started: bool = False) -> str:
    """The line a run prints when ``auto`` picked ``linear`` (``petsc-gamg``, or ``petsc`` on several ranks);
    ``started``: the ranks were started by :func:`auto_ranks`, not asked for."""
    if linear != "petsc-gamg":
        return f"linear solver: {linear} (auto, {ranks} MPI ranks: MUMPS, distributed)"
    why = "a large frictionless problem of bulky solid bodies"
    if ranks > 1:
        how = "; one per core, `--ranks 1` keeps one process" if started else ""
        return f"linear solver: {linear} (auto, {ranks} MPI ranks: {why}{how})"
    hint = "; its solves run on one core, `--ranks 2` runs two MPI ranks" if one_core_hint else ""
    return (f"linear solver: {linear} (auto: {why}; --solver with a direct one, `covcontact info` lists them, to "
            f"factorise instead{hint})")


def _dynamic(problem) -> bool:
    """Whether ``problem`` has a dynamic stage."""
    return any(problem.stage_dynamics(k) is not None for k in range(len(problem.stages) + 1))


def check_distributable(problem, linear: str, ranks: int) -> None:
    """Raise InputError where ``ranks`` MPI ranks cannot run ``problem`` with the solver ``linear``."""
    where = problem.source or problem.name
    if ranks > 1 and not distributes(linear):
        raise InputError(f"{where}: {ranks} MPI ranks, but the linear solver {linear!r} runs in one process; "
                         f"use --solver petsc or petsc-gamg (or leave the solver to auto)")
    if distributes(linear) and any(rb.free or rb.attach for rb in problem.rigid):
        raise InputError(f"{where}: rigid bodies with free components or attached nodes (reference nodes) are not available with "
                         f"the distributed solver {linear!r} yet; use a serial solver")
    if distributes(linear) and (getattr(problem, "equations", None) or getattr(problem, "mpcs", None)):
        raise InputError(f"{where}: multi-point constraints ([[equation]], [[mpc]]) are not available with the distributed "
                         f"solver {linear!r} yet; use a serial solver (--solver pardiso or superlu)")
    nodal = [c.name for c in problem.contacts if getattr(c, "gap", "points") == "nodal"]
    if ranks > 1 and nodal:
        raise InputError(f"{where}: contact {nodal[0]!r}: gap = \"nodal\" runs in one process (a node's weighted gap "
                         f"takes the points of all its facets); leave out --ranks or use --ranks 1")
    if distributes(linear) and (getattr(problem, "springs", None) or getattr(problem, "dashpots", None)):
        raise InputError(f"{where}: springs and dashpots ([[spring]], [[dashpot]]) are not available with the "
                         f"distributed solver {linear!r} yet; use a serial solver (--solver pardiso or superlu)")



def run_solver(problem, linear: str | None) -> tuple[str, str]:
    """(the solver asked for, the solver the run gets) for a run of ``problem`` in this process; InputError
    where the MPI ranks this process belongs to cannot run the problem with it."""
    from ..parallel.launcher import ranks_from_env

    name = resolve_linear(problem, linear)
    check_distributable(problem, name, ranks_from_env())
    return requested_linear(problem, linear), name
