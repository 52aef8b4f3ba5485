"""Time of one Newton iteration split into phases, against the number of dofs.

Two problems: a block pressed onto a rigid plane (bulky, hex8) and a plate pressed by a rigid sphere
(shell-like, hex8 with one element through the thickness). Each size runs one load step; the per-phase
times (element assembly, contact, boundary conditions, factorisation, solve) are divided by the number of
iterations. Writes JSON.

    python benchmarks/newton_iteration.py --out newton.json            # sizes up to ~3e5 dofs
    python benchmarks/newton_iteration.py --quick                      # small sizes only
    python benchmarks/newton_iteration.py --blocks --plates 408 --iterations 2   # one 1e6-dof plate,
                                                                       # two Newton iterations timed
    python benchmarks/newton_iteration.py --blocks --plates 408 --reuse          # the whole step, reusing
                                                                       # factorisations (inexact Newton)
    python benchmarks/newton_iteration.py --blocks 16 --plates 80 --reuse auto --precision double  # against
                                                                       # --precision single: PARDISO in float32
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import time

import numba

from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import block, plate
from covcontact.problem import (Body, ContactPair, Dirichlet, OutputOptions, Problem, RigidBody, SolverOptions,
                                Steps)
from covcontact.solvers.model import Model
from covcontact.solvers.newton import Newton


def block_problem(n: int) -> Problem:
    mesh = block(1.0, 1.0, 1.0, n, n, n, cell="hex8")
    return Problem(
        name=f"block-{n}",
        bodies=[Body("b", mesh, SaintVenantKirchhoff(E=1000.0, nu=0.3))],
        rigid=[RigidBody("floor", shape="plane", params={"point": (0, 0, 0), "normal": (0, 0, 1)})],
        contacts=[ContactPair("c", ("b", "zmin"), ("floor", ""), penalty=1e7, weighting="area")],
        dirichlet=[Dirichlet("b", "zmax", (0, 1, 2), (0.0, 0.0, -0.01))],
        steps=Steps.equal(1), output=OutputOptions(vtu=False), solver=SolverOptions())


def plate_problem(n: int) -> Problem:
    mesh = plate(2.0, 2.0, 0.05, n, n, cell="hex8", origin=(-1.0, -1.0, 0.0))
    return Problem(
        name=f"plate-{n}",
        bodies=[Body("p", mesh, SaintVenantKirchhoff(E=1000.0, nu=0.3))],
        rigid=[RigidBody("ball", shape="sphere", params={"center": (0.013, 0.007, -0.5), "radius": 0.5,
                                                          "outside": True})],
        contacts=[ContactPair("c", ("p", "bottom"), ("ball", ""), penalty=1e6, weighting="area")],
        dirichlet=[Dirichlet("p", s, (0, 1, 2), (0.0, 0.0, -0.05)) for s in ("xmin", "xmax", "ymin", "ymax")],
        steps=Steps.equal(1), output=OutputOptions(vtu=False), solver=SolverOptions())


def two_blocks_problem(n: int) -> Problem:
    """A punch (n x n x n/2 hex8) pressed into a base (n x n x n/2, other grid): deformable-deformable
    contact on mesh facets, the set-up of examples/contact/two_blocks.toml refined."""
    base = block(2.0, 2.0, 0.5, n, n, max(n // 2, 1), cell="hex8", origin=(-1.0, -1.0, -0.5))
    punch = block(1.0, 1.0, 0.5, n + 1, n + 1, max(n // 2, 1), cell="hex8", origin=(-0.5, -0.5, 0.0))
    mat = SaintVenantKirchhoff(E=1000.0, nu=0.3)
    return Problem(
        name=f"two-blocks-{n}", bodies=[Body("base", base, mat), Body("punch", punch, mat)],
        contacts=[ContactPair("c", ("punch", "zmin"), ("base", "zmax"), penalty=1e6, weighting="area")],
        dirichlet=[Dirichlet("base", "zmin", (0, 1, 2), (0.0, 0.0, 0.0)),
                   Dirichlet("punch", "zmax", (0, 1, 2), (0.0, 0.0, -0.02))],
        steps=Steps.equal(1), output=OutputOptions(vtu=False), solver=SolverOptions())


def measure(prob: Problem, iterations: int | None = None, reuse: bool | str = False, solver: str = "auto",
            precision: str = "auto") -> dict:
    if iterations:  # time a fixed number of iterations of the first step (no cutback)
        prob.solver = SolverOptions(max_iterations=iterations, max_cutbacks=0)
    prob.solver.reuse_factorization = reuse
    prob.solver.linear = solver
    prob.solver.factorization_precision = precision
    t0 = time.perf_counter()
    model = Model(prob)
    newton = Newton(model, prob.solver)
    t_setup = time.perf_counter() - t0
    u = model.prescribed(0.0)
    t0 = time.perf_counter()
    ok, outcomes, cutbacks, why, _ = newton.advance(u, 0.0, 1.0, model.initial_state())
    wall = time.perf_counter() - t0
    its = max(sum(o.iterations for o in outcomes), 1)
    per_it = {k: v / its for k, v in newton.timing.items()}
    return {"problem": prob.name, "dofs": model.n_dofs, "converged": ok, "iterations": its,
            "cutbacks": cutbacks, "setup_s": t_setup, "wall_s": wall, "reuse_factorization": reuse,
            "factorizations": newton.stats["factorizations"], "krylov_iterations": newton.stats["krylov_iterations"],
            "residual_norms": [r for o in outcomes for r in o.residual_norms],
            "per_iteration_s": per_it, "iteration_total_s": wall / its,
            "solver": newton.linear.name, "factorization_precision": newton.linear.precision_report(),
            "flop_ratio": getattr(newton.linear, "flop_ratio", None),
            "peak_rss_gib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--blocks", type=int, nargs="*", help="block sizes n (n^3 hex8); none: skip the blocks")
    ap.add_argument("--plates", type=int, nargs="*", help="plate sizes n (n x n hex8, 6 (n + 1)^2 dofs)")
    ap.add_argument("--two-blocks", type=int, nargs="*", default=[],
                    help="two-block sizes n (mesh-facet contact between deformable bodies)")
    ap.add_argument("--iterations", type=int, default=None,
                    help="time only this many Newton iterations of the step (for the largest sizes)")
    ap.add_argument("--reuse", nargs="?", const="true", default="false", choices=("true", "false", "auto"),
                    help="[solver] reuse_factorization (--reuse alone: true): GMRES preconditioned by the last "
                         "factorisation (with an AMG solver: CG to Newton's forcing term on a kept hierarchy)")
    ap.add_argument("--precision", default="auto", choices=("auto", "double", "single"),
                    help="[solver] factorization_precision (PARDISO)")
    ap.add_argument("--solver", default="auto",
                    help="the linear solver (default auto: the direct one here, as the serial model is used)")
    args = ap.parse_args()
    blocks = [8, 12] if args.quick else [8, 16, 24, 32, 40]
    plates = [20, 40] if args.quick else [40, 80, 120, 160, 200]
    if args.blocks is not None:
        blocks = args.blocks
    if args.plates is not None:
        plates = args.plates
    reuse = {"true": True, "false": False}.get(args.reuse, args.reuse)
    measure(block_problem(4))  # compile
    rows = []
    for n in blocks:
        rows.append(measure(block_problem(n), args.iterations, reuse, args.solver, args.precision))
        print(json.dumps(rows[-1]))
    for n in plates:
        rows.append(measure(plate_problem(n), args.iterations, reuse, args.solver, args.precision))
        print(json.dumps(rows[-1]))
    for n in args.two_blocks:
        rows.append(measure(two_blocks_problem(n), args.iterations, reuse, args.solver, args.precision))
        print(json.dumps(rows[-1]))
    result = {"benchmark": "newton_iteration", "machine": platform.machine(), "threads": numba.get_num_threads(),
              "date": time.strftime("%Y-%m-%d"), "rows": rows}
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(result, fh, indent=2)


if __name__ == "__main__":
    main()
