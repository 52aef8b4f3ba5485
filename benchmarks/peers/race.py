"""Race covcontact against Kratos Multiphysics (and CalculiX where installed) on two comparable contact problems.

Problems (St. Venant-Kirchhoff on every side, hex8 with 2x2x2 Gauss points, frictionless penalty contact, 10
equal load steps, the same mesh written for every code):

- ``two_blocks``: benchmarks/problems/two_blocks_5k.toml scaled: the base block (2 x 2 x 0.5, E = 1000,
  nu = 0.3) clamped at its bottom, the punch (1 x 1 x 0.5) pressed 0.05 down by its top, sizes "5k" (base
  10 x 10 x 5, punch 11 x 11 x 5: 4,770 dofs), "35k" (21 x 21 x 10, 23 x 23 x 10: 34,980), "200k"
  (37 x 37 x 19, 41 x 41 x 19: 192,480). Kratos and, when ``ccx`` is on the PATH, CalculiX
  (ccx_deck.bodies_deck).
- ``hertz``: the quarter ball of tests/verification/test_hertz.py (``hertz_mesh(n, n/2)``, R = 1, E = 1,
  nu = 0.3, flat face moved down to d = 0.01 R onto the plane z = 0), sizes n = 14 (5,085 dofs), 28
  (36,627), 50 (199,053). Kratos and, when ``ccx`` is on the PATH, CalculiX (ccx_deck.hertz_deck).

Kratos solves its linear systems with AMGCL (``--kratos-solver amgcl``, the default; ``sparse_lu`` for Eigen's
SparseLU): of the solvers its wheels carry, the fastest on both problems.

covcontact's area-weighted penalty k (pressure = k x penetration) is given to Kratos as a per-node eps of its
mortar penalty condition (kratos_deck.nodal_penalties) and to CalculiX as the slope of its linear
pressure-overclosure law. Default k: 2.5e5 for two_blocks (Kratos's active set does not settle with the problem
file's 1e6; see peers/README.md), 1e4 for hertz.

Each run is a whole process, start to exit (covcontact: ``python -m covcontact run FILE``; for hertz the file reads
the graded ball from an Abaqus mesh file the race writes, as no TOML generator grades it; Kratos:
kratos_run.py under Kratos's Python; CalculiX: ``ccx -i job``). The codes alternate, ``--repeats`` runs each,
the median wall time is kept and the ratio peer / covcontact is formed from the medians of the same race. Every
code gets ``--threads`` threads (OMP, MKL, NUMBA, OpenBLAS and CalculiX's variables, and Kratos's
``ParallelUtilities.SetNumThreads``). One untimed covcontact run first fills numba's on-disk cache, and
covcontact's modules are compiled to bytecode first, as an installed package has them (an editable installation
run with PYTHONDONTWRITEBYTECODE would compile them again in every timed run, about 0.1 s).
covcontact decides itself how to use them (``--ranks auto``: one MPI rank per thread where its solver ``auto``
picks ``petsc-gamg``, the 2e5 sizes, else one process of ``--threads`` threads); ``--ours-ranks 1`` keeps it
to one process, ``--ours-ranks N`` runs N ranks with ``petsc-gamg`` (docs/performance.md, "Distributed runs").

Accuracy: the total force per step of every code (covcontact: its contact force; Kratos and CalculiX: the
reaction of the loaded face), each peer's relative difference to covcontact, and for hertz F / F_Hertz per step.

    python benchmarks/peers/race.py --kratos-python KRATOS_PY --problems two_blocks,hertz --sizes 5k,35k \\
        --repeats 3 --threads 1 --out race.json

``--kratos-python`` (or the environment variable KRATOS_PYTHON) is the Python interpreter of an environment with
the Kratos wheels (see peers/README.md, "Kratos").
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from _report import emit
from calculix_hertz import _ccx_version, _covcontact_state, timed
from ccx_deck import bodies_deck, hertz_deck
from ccx_results import parse_dat, parse_sta, parse_stdout
from hertz_setup import C_HERTZ, D_MAX, NU, E, hertz_mesh
from kratos_deck import hertz_case, two_blocks_case, write_case
from kratos_results import read_results

from covcontact.problem import SolverOptions
from covcontact.warmup import byte_compile

THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS",
               "CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_STIFFNESS", "CCX_NPROC_RESULTS", "NUMBER_OF_CPUS")
#: two_blocks sizes: (base nx = ny, base nz, punch nx = ny, punch nz); no punch node lies on a base facet edge
TWO_BLOCKS = {"5k": (10, 5, 11, 5), "35k": (21, 10, 23, 10), "200k": (37, 19, 41, 19)}
#: hertz sizes: n of hertz_mesh(n, n/2)
HERTZ = {"5k": 14, "35k": 28, "200k": 50}
STEPS = 10
CCX_STRESS_SCALE = 1e5  # see peers/README.md, CalculiX: "Stress unit of the deck"
#: Kratos's linear solvers offered to the race (its wheels have no PARDISO); AMGCL is its fastest here
KRATOS_SOLVERS = {"amgcl": "amgcl (AMG-preconditioned Krylov, Kratos's defaults)",
                  "sparse_lu": "sparse_lu (Eigen SparseLU)"}


def thread_env(threads: int) -> dict:
    env = dict(os.environ)
    env.update({k: str(threads) for k in THREAD_VARS})
    return env


def hertz_toml(mesh, mesh_file: Path, size: str, penalty: float, rtol: float | None = None) -> str:
    """The problem file of one hertz size, equal to tests/verification/hertz_setup.hertz_problem (SVK, 10 steps,
    the flat face moved down by D_MAX, sliding, symmetry planes, no VTU); writes the graded quarter ball to
    ``mesh_file`` (Abaqus, its node sets flat, curved, symx and symy), which the problem file reads."""
    import meshio

    sets = {k: np.asarray(mesh.node_sets[k]) for k in ("flat", "symx", "symy")}
    faces = np.asarray(mesh.face_sets["curved"])  # the contact surface, an element set of quadrilaterals
    curved = [np.zeros(0, dtype=np.int64), np.arange(faces.shape[0])]
    meshio.Mesh(mesh.points, [("hexahedron", mesh.cells), ("quad", faces)], point_sets=sets,
                cell_sets={"curved": curved}).write(mesh_file)
    text = f"""# hertz race problem, size {size} (written by benchmarks/peers/race.py)
[problem]
name = "hertz-{size}"

[[bodies]]
name = "ball"
element = "hex8"
material = {{ model = "svk", E = {E!r}, nu = {NU!r} }}
mesh = {{ file = "{mesh_file.name}" }}

[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[contact]]
slave = "ball.curved"
master = "floor"
penalty = {penalty!r}
weighting = "area"

[[dirichlet]]
set = "ball.flat"
components = "z"
value = {-D_MAX!r}

[[dirichlet]]
set = "ball.symx"
components = "x"

[[dirichlet]]
set = "ball.symy"
components = "y"

[steps]
count = {STEPS}

[output]
vtu = false
"""
    return text + (f"\n[solver]\nrtol = {rtol!r}\n" if rtol is not None else "")


def two_blocks_toml(size: str, penalty: float, rtol: float | None = None) -> str:
    """The problem file of one two_blocks size: benchmarks/problems/two_blocks_5k.toml with other element counts
    and penalty (same material, supports, 10 steps, no VTU); ``rtol``: Newton's relative tolerance if not the
    default."""
    bn, bz, pn, pz = TWO_BLOCKS[size]
    text = (ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml").read_text()
    for old, new in (('name = "two-blocks-5k"', f'name = "two-blocks-{size}"'),
                     ("nx = 10, ny = 10, nz = 5", f"nx = {bn}, ny = {bn}, nz = {bz}"),
                     ("nx = 11, ny = 11, nz = 5", f"nx = {pn}, ny = {pn}, nz = {pz}"),
                     ("penalty = 1.0e6", f"penalty = {penalty!r}"), ("count = 10", f"count = {STEPS}")):
        if old not in text:
            raise RuntimeError(f"two_blocks_5k.toml changed: {old!r} not found")
        text = text.replace(old, new, 1)
    if rtol is not None:
        text += f"\n[solver]\nrtol = {rtol!r}\n"
    return f"# two_blocks race problem, size {size} (written by benchmarks/peers/race.py)\n" + text


# -- preparing one race cell ------------------------------------------------------------------------------
class Cell:
    """One problem at one size: the input of every code and how to run and read each."""

    def __init__(self, problem: str, size: str, work: Path, args):
        self.problem, self.size, self.args = problem, size, args
        self.dir = work / f"{problem}_{size}"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.kdir = self.dir / "kratos"
        self.ccx_job = None
        if problem == "two_blocks":
            from covcontact.io.loader import load_problem

            self.penalty = args.two_blocks_penalty
            self.toml = self.dir / "problem.toml"
            self.toml.write_text(two_blocks_toml(size, self.penalty, args.ours_rtol))
            problem = load_problem(self.toml)
            info = write_case(replace(two_blocks_case(problem), linear_solver=args.kratos_solver), self.kdir)
            self.dofs, self.label = info.dofs, "base {0}x{0}x{1}, punch {2}x{2}x{3}".format(*TWO_BLOCKS[size])
            self.force_scale = 1.0  # the whole problem
            if args.ccx:
                text, _ = bodies_deck(problem, stress_scale=CCX_STRESS_SCALE)
                self.ccx_job = self.dir / "ccx" / "two_blocks.inp"
        else:
            self.penalty = args.hertz_penalty
            self.n = HERTZ[size]
            mesh = hertz_mesh(n=self.n, nr=self.n // 2)
            self.toml = self.dir / "problem.toml"
            self.toml.write_text(hertz_toml(mesh, self.dir / "ball.inp", size, self.penalty, args.ours_rtol))
            info = write_case(replace(hertz_case(mesh, E, NU, D_MAX, STEPS, self.penalty),
                                      linear_solver=args.kratos_solver), self.kdir)
            self.dofs, self.label = 3 * mesh.n_nodes, f"n={self.n}"
            self.kratos_extra_dofs = info.dofs - self.dofs
            self.force_scale = 4.0  # a quarter of the ball
            if args.ccx:
                text, _ = hertz_deck(mesh, "svk", E, NU, D_MAX, STEPS, self.penalty,
                                     stress_scale=CCX_STRESS_SCALE, frd=False)
                self.ccx_job = self.dir / "ccx" / "hertz.inp"
        if self.ccx_job is not None:
            self.ccx_job.parent.mkdir(exist_ok=True)
            self.ccx_job.write_text(text)
        self.ours_out = self.dir / "covcontact"

    # covcontact
    def ours_cmd(self) -> list[str]:
        cmd = [sys.executable, "-m", "covcontact", "run", str(self.toml), "--out", str(self.ours_out), "--quiet"]
        if self.args.ours_ranks is not None:  # else covcontact's own choice (--ranks auto)
            cmd += ["--ranks", str(self.args.ours_ranks)]
            cmd += ["--solver", "petsc-gamg"] if self.args.ours_ranks > 1 else []
        return cmd

    def run_ours(self) -> float:
        shutil.rmtree(self.ours_out, ignore_errors=True)
        ranks = self.args.ours_ranks or 1  # explicit ranks: one thread each; auto shares the threads out itself
        wall, _, proc = timed(self.ours_cmd(), env=thread_env(1 if ranks > 1 else self.args.threads))
        if proc.returncode not in (0, 1):
            raise RuntimeError(f"covcontact failed:\n{proc.stderr[-2000:]}")
        return wall

    def ours_record(self) -> dict:
        s = json.loads((self.ours_out / "summary.json").read_text())
        scale = self.force_scale
        return {"converged": bool(s["converged"]), "dofs": s["dofs"], "linear_solver": s["linear_solver"],
                "ranks": s.get("parallel", {}).get("ranks", 1),
                "iterations": s["total_iterations"], "iterations_per_step": [st["iterations"] for st in s["steps"]],
                "factorizations": sum(st.get("factorizations", 0) for st in s["steps"]),
                "krylov_iterations": sum(st.get("krylov_iterations", 0) for st in s["steps"]),
                "solve_s": s["wall_time_s"], "timing_s": s.get("timing", {}),
                "F": [scale * st["contact_force"][2] for st in s["steps"]]}

    # Kratos
    def run_kratos(self) -> float:
        (self.kdir / "results.json").unlink(missing_ok=True)
        cmd = [self.args.kratos_python, str(HERE / "kratos_run.py"), str(self.kdir), "--threads", str(self.args.threads)]
        wall, _, proc = timed(cmd, env=thread_env(self.args.threads))
        if not (self.kdir / "results.json").exists():
            raise RuntimeError(f"Kratos failed:\n{proc.stdout[-1500:]}\n{proc.stderr[-1500:]}")
        (self.kdir / "stdout.txt").write_text(proc.stdout)
        return wall

    def kratos_record(self) -> dict:
        r = read_results(self.kdir / "results.json")
        part, scale = "punch_zmax" if self.problem == "two_blocks" else "ball_flat", self.force_scale
        return {"converged": r.all_converged, "steps_converged": r.converged, "iterations": sum(r.iterations),
                "iterations_per_step": r.iterations, "solve_s": r.analysis_s, "threads_reported": r.threads,
                "version": r.version, "linear_solver": KRATOS_SOLVERS[self.args.kratos_solver],
                "F": (scale * r.force(part)).tolist()}

    # CalculiX
    def run_ccx(self) -> float:
        job = self.ccx_job.with_suffix("")
        wall, _, proc = timed(["ccx", "-i", job.name], cwd=job.parent, env=thread_env(self.args.threads))
        (job.parent / "stdout.txt").write_text(proc.stdout + proc.stderr)
        return wall

    def ccx_record(self) -> dict:
        job = self.ccx_job.with_suffix("")
        std = parse_stdout((job.parent / "stdout.txt").read_text())
        iters = parse_sta(job.with_suffix(".sta").read_text())
        dat = parse_dat(job.with_suffix(".dat").read_text())
        times = [t for t in dat.times if t in dat.rf]
        F = [-self.force_scale * dat.rf[t][2] / CCX_STRESS_SCALE for t in times]
        return {"converged": len(iters) == STEPS and not std["error"], "iterations": sum(iters),
                "iterations_per_step": iters, "solve_s": std["ccx_time_s"], "linear_solver": std["solver"],
                "cpus_reported": std["cpus"], "F": F}

    def codes(self) -> dict:
        c = {"covcontact": (self.run_ours, self.ours_record)}
        if self.args.kratos:
            c["kratos"] = (self.run_kratos, self.kratos_record)
        if self.ccx_job is not None:
            c["ccx"] = (self.run_ccx, self.ccx_record)
        return c


def race(cell: Cell, repeats: int) -> dict:
    codes = cell.codes()
    walls = {k: [] for k in codes}
    for _ in range(repeats):  # alternating, so that every code sees the same load on a shared machine
        for name, (run, _) in codes.items():
            walls[name].append(run())
    rec = {"problem": cell.problem, "size": cell.size, "mesh": cell.label, "dofs": cell.dofs,
           "penalty_area": cell.penalty, "codes": {}}
    if cell.problem == "hertz":
        rec["kratos_fixed_plane_dofs"] = cell.kratos_extra_dofs
    d = np.array([D_MAX * (k + 1) / STEPS for k in range(STEPS)])
    for name, (_, read) in codes.items():
        r = read()
        r["wall_s"] = [round(t, 3) for t in walls[name]]
        r["wall_median_s"] = round(statistics.median(walls[name]), 3)
        if cell.problem == "hertz" and len(r["F"]) == STEPS:
            r["F_over_FH"] = (np.array(r["F"]) / (C_HERTZ * d**1.5)).round(4).tolist()
        rec["codes"][name] = r
    ours = rec["codes"]["covcontact"]
    for name, r in rec["codes"].items():
        if name == "covcontact":
            continue
        r["time_ratio_over_covcontact"] = round(r["wall_median_s"] / ours["wall_median_s"], 3)
        if len(r["F"]) == len(ours["F"]):
            diff = np.array(r["F"]) / np.array(ours["F"]) - 1.0
            r["F_over_covcontact_minus_1"] = diff.round(6).tolist()
            r["F_diff_max"] = round(float(np.max(np.abs(diff))), 6)
    line = ", ".join(f"{n} {r['wall_median_s']:.2f} s ({r['iterations']} it)" for n, r in rec["codes"].items())
    print(f"{cell.problem} {cell.size} ({cell.dofs} dofs): {line}", file=sys.stderr, flush=True)
    return rec


def table(records: list[dict], threads: int) -> str:
    head = ("| problem | size | mesh | dofs | wall s covcontact | wall s Kratos | Kratos / cc | wall s ccx | ccx / cc"
            " | iterations cc / Kratos / ccx | converged steps Kratos | max abs(F/F_cc - 1) Kratos / ccx"
            " | F/F_H d=0.01 cc / Kratos / ccx |")
    rows = [f"threads: {threads}", "", head, "|" + "---|" * 13]
    for r in records:
        c = r["codes"]
        o, k, x = c["covcontact"], c.get("kratos"), c.get("ccx")
        it = f"{o['iterations']} / {k['iterations'] if k else '-'} / {x['iterations'] if x else '-'}"
        fh = "-"
        if r["problem"] == "hertz":
            fh = " / ".join(f"{v['F_over_FH'][-1]:.4f}" if v and "F_over_FH" in v else "-" for v in (o, k, x))
        fd = (f"{k.get('F_diff_max', float('nan')):.1e}" if k else "-") + " / " + (
            f"{x.get('F_diff_max', float('nan')):.1e}" if x else "-")
        conv = f"{sum(k['steps_converged'])}/{len(k['steps_converged'])}" if k else "-"
        rows.append(f"| {r['problem']} | {r['size']} | {r['mesh']} | {r['dofs']} | {o['wall_median_s']:.2f}"
                    f" | {k['wall_median_s'] if k else '-'} | {k['time_ratio_over_covcontact'] if k else '-'}"
                    f" | {x['wall_median_s'] if x else '-'} | {x['time_ratio_over_covcontact'] if x else '-'}"
                    f" | {it} | {conv} | {fd} | {fh} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--problems", default="two_blocks,hertz")
    ap.add_argument("--sizes", default="5k,35k", help="of 5k, 35k, 200k")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--kratos-python", default=os.environ.get("KRATOS_PYTHON"),
                    help="Python with the Kratos wheels (default: $KRATOS_PYTHON)")
    ap.add_argument("--kratos-solver", choices=sorted(KRATOS_SOLVERS), default="amgcl",
                    help="Kratos's linear solver (default amgcl, its fastest on these problems)")
    ap.add_argument("--no-ccx", dest="ccx", action="store_false", help="leave CalculiX out even if installed")
    ap.add_argument("--no-kratos", dest="kratos", action="store_false",
                    help="leave Kratos out (sizes where its runs take too long)")
    ap.add_argument("--two-blocks-penalty", type=float, default=2.5e5)
    ap.add_argument("--hertz-penalty", type=float, default=1e4)
    ap.add_argument("--keep", type=Path, help="keep inputs and results in this directory")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    ap.add_argument("--ours-rtol", type=float, default=None,
                    help="covcontact's Newton tolerance [solver] rtol (default: its own, 1e-8); e.g. 1e-5 races it at "
                         "the accuracy of CalculiX's default controls (peers/README.md)")
    ap.add_argument("--ours-ranks", type=int, default=None,
                    help="covcontact's --ranks: 1 runs one process of --threads threads, N > 1 N MPI ranks (the "
                         "--threads shared among them) with petsc-gamg (the `mpi` extra); default: covcontact's own "
                         "choice (one rank per thread where its solver auto picks petsc-gamg, else one process)")
    args = ap.parse_args(argv)
    if args.kratos and not args.kratos_python:
        print("give --kratos-python (or set KRATOS_PYTHON): the Python of an environment with Kratos", file=sys.stderr)
        return 2
    args.ccx = args.ccx and shutil.which("ccx") is not None
    problems = [p.strip() for p in args.problems.split(",")]
    sizes = [s.strip() for s in args.sizes.split(",")]
    t0 = time.perf_counter()
    records = []
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        byte_compile()  # covcontact's modules as an installed package has them (PYTHONDONTWRITEBYTECODE)
        warm = Cell("two_blocks", "5k", work / "warmup", args)  # fills numba's cache (not timed)
        warm.run_ours()
        for size in sizes:
            for problem in problems:
                records.append(race(Cell(problem, size, work, args), args.repeats))
    result = {"benchmark": "peers_race", "date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "machine": platform.machine(), "cpus": os.cpu_count(), "threads": args.threads,
              "covcontact_rtol": args.ours_rtol or SolverOptions().rtol, "covcontact_ranks": args.ours_ranks,
              "kratos_solver": args.kratos_solver,
              "repeats": args.repeats, "steps": STEPS,
              "kratos_version": records[0]["codes"]["kratos"]["version"] if records and args.kratos else None,
              "ccx_version": _ccx_version() if args.ccx else None, "covcontact": _covcontact_state(),
              "total_s": round(time.perf_counter() - t0, 1), "records": records}
    emit(result, args.out, table(records, args.threads))
    return 0


if __name__ == "__main__":
    sys.exit(main())
