"""Distributed runs on PETSc: one rank against several, per Newton iteration, split into phases.

The problem is ``two_blocks`` scaled up: a hex8 punch pressed into a larger hex8 base block through a
deformable node-to-surface contact pair (108,900 dofs with the default size), one load step. Every
configuration runs ``covcontact run`` in a subprocess (under ``mpiexec -n N`` for N > 1) and reads the
phase times of rank 0 from summary.json, divided by the number of Newton iterations:

- assembly: element loop (numba); contact: search, projection and contact assembly; comm: the sum of the
  residual over the ranks; factor: PETSc matrix values + factorisation (MUMPS) or GAMG set-up; solve:
  triangular solves or Krylov iterations and the gather of the solution.

    python benchmarks/mpi_scaling.py --out mpi_scaling.json                  # ~1e5 dofs
    python benchmarks/mpi_scaling.py --n 12 --solvers petsc --ranks 1,2      # quick
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PROBLEM = """[problem]
name = "two-blocks-{n}"

[[bodies]]
name = "base"
element = "hex8"
material = {{ model = "svk", E = 1000.0, nu = 0.3 }}
mesh = {{ generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = {nb}, ny = {nb}, nz = {nz}, origin = [-1.0, -1.0, -0.5] }}

[[bodies]]
name = "punch"
element = "hex8"
material = {{ model = "svk", E = 1000.0, nu = 0.3 }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = {n}, ny = {n}, nz = {nz}, origin = [-0.5, -0.5, 0.0] }}

[[contact]]
slave = "punch.zmin"
master = "base.zmax"
penalty = 1.0e6
weighting = "area"

[[dirichlet]]
set = "base.zmin"
components = "xyz"

[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.0, 0.0, -0.02]

[steps]
count = 1

[output]
vtu = false
"""


def write_problem(folder: Path, n: int) -> tuple[Path, int]:
    """The problem file (punch n x n x n/3 elements, base 4n/3 x 4n/3) and its number of dofs."""
    nb, nz = max(2, round(4 * n / 3)), max(2, round(n / 3))
    path = folder / f"two_blocks_{n}.toml"
    path.write_text(PROBLEM.format(n=n, nb=nb, nz=nz))
    dofs = 3 * ((nb + 1) ** 2 * (nz + 1) + (n + 1) ** 2 * (nz + 1))
    return path, dofs


def run(problem: Path, solver: str, ranks: int, threads: int | None, out: Path) -> dict:
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(problem), "--solver", solver, "--out", str(out),
           "--quiet"]
    if ranks > 1:
        cmd = ["mpiexec", "-n", str(ranks), "--oversubscribe", *cmd]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, check=False, env=env, capture_output=True, text=True, timeout=3600)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    s = json.loads((out / "summary.json").read_text())
    its = max(int(s["total_iterations"]), 1)
    t = s["timing"]
    per = {k: round(t.get(k, 0.0) / its, 4) for k in ("assembly", "contact", "comm", "factor", "solve")}
    per["total"] = round(sum(per.values()), 4)
    return {"solver": solver, "ranks": ranks, "numba_threads": s.get("parallel", {}).get("numba_threads"),
            "iterations": its, "per_iteration_s": per, "run_total_s": round(t["total"], 2),
            "process_wall_s": round(wall, 2), "partition": s.get("parallel")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=32, help="punch elements per side (32: 108,900 dofs)")
    ap.add_argument("--solvers", default="petsc,petsc-gamg")
    ap.add_argument("--ranks", default="1,2")
    ap.add_argument("--single-thread", action="store_true", help="also 1 rank with 1 numba thread")
    ap.add_argument("--out", default="mpi_scaling.json")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        problem, dofs = write_problem(folder, args.n)
        for solver in args.solvers.split(","):
            configs = [(int(r), None) for r in args.ranks.split(",")]
            if args.single_thread:
                configs.insert(1, (1, 1))
            for ranks, threads in configs:
                row = run(problem, solver, ranks, threads, folder / f"{solver}-{ranks}-{threads}")
                rows.append(row)
                print(json.dumps({k: row[k] for k in ("solver", "ranks", "numba_threads", "iterations",
                                                      "per_iteration_s")}), flush=True)
    result = {"problem": f"two-blocks-{args.n}", "dofs": dofs, "machine": platform.platform(),
              "cpus": os.cpu_count(), "runs": rows}
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
