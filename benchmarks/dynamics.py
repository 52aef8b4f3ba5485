"""What a dynamic step costs: the Hertzian impact of tests/verification/test_hertz_impact.py (the quarter half-ball,
redistributed mass, trapezoidal rule, 100 steps) on a mesh of ``--n`` elements per quarter circle, run with
factorisation reuse off and on (``[solver] reuse_factorization``: the later Newton corrections of a step by GMRES
preconditioned with the step's first factorisation), and the same ball's quasi-static indentation to the same
depth (10 steps) for the cost of a static iteration. Per variant: whole-run wall time (median of ``--repeats``,
alternating), Newton iterations and factorisations per step, and the seconds per step and per factorisation.

    python benchmarks/dynamics.py --out dynamics.json [--n 16] [--repeats 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _report import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from hertz_setup import E, NU, R, hertz_mesh, hertz_problem  # noqa: E402

from covcontact.materials import SaintVenantKirchhoff  # noqa: E402
from covcontact.problem import (  # noqa: E402
    Body,
    ContactPair,
    Dirichlet,
    Dynamics,
    InitialVelocity,
    OutputOptions,
    Problem,
    RigidBody,
)

V, RHO = 3e-4, 1.0
E_STAR = E / (1.0 - NU ** 2)
M_HALF = RHO * 2.0 / 3.0 * math.pi * R ** 3
T_C = 2.868 * (M_HALF ** 2 / (R * E_STAR ** 2 * V)) ** 0.2
DEPTH = (15.0 * M_HALF * V * V / (16.0 * E_STAR * math.sqrt(R))) ** 0.4  # Hertz's largest indentation


def impact(n: int, reuse: bool) -> Problem:
    mesh = hertz_mesh(n=n, nr=n // 2)
    dyn = Dynamics(dt=1.2 * T_C / 100, t_end=1.2 * T_C, method="newmark", mass="redistributed")
    prob = Problem(
        name="hertz-impact",
        bodies=[Body("ball", mesh, SaintVenantKirchhoff(E=E, nu=NU, density=RHO))],
        dirichlet=[Dirichlet("ball", "symx", (0,), (0.0,)), Dirichlet("ball", "symy", (1,), (0.0,))],
        rigid=[RigidBody("floor", shape="plane", params={"point": (0.0, 0.0, 0.0), "normal": (0.0, 0.0, 1.0)})],
        contacts=[ContactPair("floor", ("ball", "curved"), ("floor", ""), penalty=1e4, weighting="area")],
        steps=dyn.steps(), output=OutputOptions(vtu=False), dynamics=dyn,
        initial_velocity=[InitialVelocity("ball", "", (0.0, 0.0, -V))],
    )
    prob.solver = dataclasses.replace(prob.solver, reuse_factorization=reuse)
    return prob


def static(n: int) -> Problem:
    prob = hertz_problem(hertz_mesh(n=n, nr=n // 2), "svk", steps=10, d_max=DEPTH, vtu=False)
    prob.solver = dataclasses.replace(prob.solver, reuse_factorization=False)
    return prob


def measure(make, folder: Path) -> dict:
    t0 = time.perf_counter()
    res = make().run(out=folder)
    wall = time.perf_counter() - t0
    steps = res.summary["steps"]
    fact = sum(s["factorizations"] for s in steps)
    return {"wall_s": wall, "steps": len(steps), "iterations": res.summary["total_iterations"],
            "factorizations": fact, "factor_s": res.summary["timing"]["factor"], "exit_code": res.exit_code}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--n", type=int, default=16)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    variants = {"dynamic": lambda: impact(args.n, False), "dynamic-reuse": lambda: impact(args.n, True),
                "static": lambda: static(args.n)}
    runs: dict[str, list[dict]] = {k: [] for k in variants}
    with tempfile.TemporaryDirectory() as tmp:
        measure(variants["dynamic"], Path(tmp) / "warm")  # compiled kernels
        for r in range(args.repeats):
            for name, make in variants.items():
                runs[name].append(measure(make, Path(tmp) / f"{name}{r}"))
    out = {"n": args.n, "dofs": 3 * hertz_mesh(n=args.n, nr=args.n // 2).n_nodes, "variants": {}}
    rows = ["| variant | steps | Newton iterations per step | factorisations per step | median wall s | s per step |",
            "|---|---|---|---|---|---|"]
    for name, rs in runs.items():
        wall = statistics.median(x["wall_s"] for x in rs)
        first = rs[0]
        rec = {"median_wall_s": round(wall, 3), "steps": first["steps"],
               "iterations_per_step": round(first["iterations"] / first["steps"], 3),
               "factorizations_per_step": round(first["factorizations"] / first["steps"], 3),
               "s_per_step": round(wall / first["steps"], 4), "exit_codes": [x["exit_code"] for x in rs]}
        out["variants"][name] = rec
        rows.append(f"| {name} | {rec['steps']} | {rec['iterations_per_step']} | {rec['factorizations_per_step']} | "
                    f"{rec['median_wall_s']} | {rec['s_per_step']} |")
    emit(out, args.out, "\n".join(rows))


if __name__ == "__main__":
    main()
