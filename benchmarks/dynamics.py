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
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _report import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from hertz_setup import hertz_mesh, hertz_problem, impact_problem, impact_reference

V = 3e-4
DEPTH = impact_reference(V)[2]  # Hertz's largest indentation


def impact(n: int, reuse: bool):
    prob = impact_problem(hertz_mesh(n=n, nr=n // 2), V)
    prob.solver = dataclasses.replace(prob.solver, reuse_factorization=reuse)
    return prob


def static(n: int):
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
