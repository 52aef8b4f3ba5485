"""Side-by-side race with CalculiX on covcontact's verified Hertz problem.

The problem is that of tests/verification/test_hertz.py: the pole-graded quarter half-ball (R = 1,
E = 1, nu = 0.3, hex8, n elements around, nr = n/2 through the radius), symmetry planes, the flat
face moved down by d onto the rigid plane z = 0 in equal steps up to d = 0.01 R, area-weighted
penalty 1e4. covcontact solves it through the Python API in a child process; CalculiX (``ccx``)
solves the same mesh written as a deck by ``ccx_deck.hertz_deck`` (C3D8, node-to-surface penalty
contact with the same pressure-per-penetration slope, the plane a slab of fixed elements, one
NLGEOM step with fixed increments). Materials: "svk" against ``*ELASTIC`` under NLGEOM (the same
law) and "neo-hooke" against ``*HYPERELASTIC, NEO HOOKE`` with the same small-strain moduli.

Each run is timed as a whole process (start to exit, results written: VTU per step against the
.frd/.dat files), ``--repeats`` times alternating covcontact and ccx, the median kept. Both get
the same thread count (OMP/MKL/NUMBA/OpenBLAS and CCX_NPROC_* variables). Per record: wall times
and their ratio ccx / covcontact, each code's own solve time, Newton iterations, F / F_Hertz at
every step (CalculiX: the reaction of the flat face), the fits C1 and (C2, B), the contact radius
from the nodal pressures times the tributary areas, the central pressure error (as in
test_hertz.hertz_measures). JSON to --out (else stdout), a Markdown table on stderr.

    python benchmarks/peers/calculix_hertz.py --sizes 12,16,24 --out calculix_hertz.json
    python benchmarks/peers/calculix_hertz.py --quick
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))
sys.path.insert(0, str(HERE))

from ccx_deck import hertz_deck
from ccx_results import parse_dat, parse_sta, parse_stdout
from hertz_setup import C_HERTZ, D_MAX, E_STAR, NU, E, R, fit_hertz, hertz_measures, hertz_mesh

from covcontact.contact.surface import tributary_area

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _report import emit

PENALTY = 1e4
THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS", "OPENBLAS_NUM_THREADS",
               "CCX_NPROC_EQUATION_SOLVER", "CCX_NPROC_STIFFNESS", "CCX_NPROC_RESULTS", "NUMBER_OF_CPUS")


def timed(cmd: list[str], **kw) -> tuple[float, float, subprocess.CompletedProcess]:
    """Run a child process to its end: (wall s, CPU s = user + system of the child, result)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False, **kw)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), proc


def thread_env(threads: int) -> dict:
    env = dict(os.environ)
    env.update({k: str(threads) for k in THREAD_VARS})
    return env


# -- covcontact --------------------------------------------------------------------------------------
def worker(n: int, material: str, steps: int, out: str) -> int:
    """Child process: solve and write the results (VTU per step, summary.json)."""
    from hertz_setup import hertz_problem

    mesh = hertz_mesh(n=n, nr=n // 2)
    res = hertz_problem(mesh, material, steps=steps, penalty=PENALTY).run(out=Path(out), quiet=True)
    return res.exit_code


def run_ours(n: int, material: str, steps: int, out: Path, threads: int) -> tuple[float, float]:
    """(wall s, CPU s) of one covcontact run in a child process."""
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", str(n), material, str(steps), str(out)]
    wall, cpu, proc = timed(cmd, env=thread_env(threads))
    if proc.returncode not in (0, 1):
        raise RuntimeError(f"covcontact worker failed:\n{proc.stderr[-2000:]}")
    return wall, cpu


def ours_record(out: Path, mesh) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    m = hertz_measures(SimpleNamespace(summary=summary, out=out), mesh)
    return {"converged": bool(summary["converged"]), "dofs": summary["dofs"],
            "linear_solver": summary["linear_solver"], "iterations": summary["total_iterations"],
            "iterations_per_step": [s["iterations"] for s in summary["steps"]],
            "solve_s": summary["wall_time_s"], **_measures(m)}


# -- CalculiX ----------------------------------------------------------------------------------------
def run_ccx(job: Path, threads: int) -> tuple[float, float, str]:
    """(wall s, CPU s, stdout) of one ccx run."""
    wall, cpu, proc = timed(["ccx", "-i", job.name], cwd=job.parent, env=thread_env(threads))
    return wall, cpu, proc.stdout + proc.stderr


def ccx_measures(job: Path, mesh, scale: float, d_max: float = D_MAX) -> dict:
    """The measures of test_hertz.hertz_measures from the .dat file of a ccx run."""
    dat = parse_dat(job.with_suffix(".dat").read_text())
    times = [t for t in dat.times if t in dat.rf]
    d = np.array([d_max * t for t in times])
    F = np.array([-4.0 * dat.rf[t][2] / scale for t in times])
    C1, C2, B = fit_hertz(d, F)
    out = {"d": d, "F": F, "ratio": F / (C_HERTZ * d**1.5), "C1": C1 / C_HERTZ, "C2": C2 / C_HERTZ, "B": B,
           "active": np.array([len(dat.p.get(t, {})) for t in times])}
    curved = mesh.node_sets["curved"]
    area = tributary_area(mesh.points, mesh.face_sets["curved"])
    a_m, p_err = [], []
    for t, dk in zip(times, d, strict=True):
        x = mesh.points[curved] + np.array([dat.u[t][a + 1] for a in curved])
        p = np.array([dat.p.get(t, {}).get(a + 1, 0.0) for a in curved]) / scale
        r = np.hypot(x[:, 0], x[:, 1])
        f = p * area[curved]
        act = p > 0.0
        a_m.append(math.sqrt(2.5 * np.sum(f[act] * r[act] ** 2) / np.sum(f[act])))
        a = math.sqrt(R * dk)
        p0 = 2.0 * E_STAR * a / (math.pi * R)
        inner = r < 0.5 * a
        p_err.append(float(np.max(np.abs(p[inner] - p0 * np.sqrt(1.0 - (r[inner] / a) ** 2))) / p0))
    out["a_ratio"] = np.array(a_m) / np.sqrt(R * d)
    out["p_center_error"] = np.array(p_err)
    return out


def ccx_record(job: Path, log: str, mesh, steps: int, scale: float) -> dict:
    std = parse_stdout(log)
    iters = parse_sta(job.with_suffix(".sta").read_text())
    m = ccx_measures(job, mesh, scale)
    return {"converged": len(iters) == steps and not std["error"], "equations": std["equations"],
            "linear_solver": std["solver"], "cpus_reported": std["cpus"], "iterations": sum(iters),
            "iterations_per_step": iters, "solve_s": std["ccx_time_s"], **_measures(m)}


# -- both --------------------------------------------------------------------------------------------
def _measures(m: dict) -> dict:
    return {"d": m["d"].tolist(), "F": m["F"].tolist(), "ratio": m["ratio"].round(4).tolist(),
            "C1": round(m["C1"], 4), "C2": round(m["C2"], 4), "B": round(m["B"], 4),
            "active": m["active"].tolist(),
            "a_ratio": m["a_ratio"].round(4).tolist(),
            "a_error_max": round(float(np.max(np.abs(m["a_ratio"] - 1.0))), 4),
            "p_center_error": m["p_center_error"].round(4).tolist(),
            "p_center_error_max": round(float(np.max(m["p_center_error"])), 4)}


def race(n: int, material: str, args, work: Path) -> dict:
    mesh = hertz_mesh(n=n, nr=n // 2)
    job = work / f"hertz_n{n}_{material}.inp"
    text, info = hertz_deck(mesh, material, E, NU, D_MAX, args.steps, PENALTY, stress_scale=args.stress_scale)
    job.write_text(text)
    out = work / f"ours_n{n}_{material}"
    runs = {"ours": {"wall": [], "cpu": [], "solve": []}, "ccx": {"wall": [], "cpu": [], "solve": []}}
    log = ""
    for _ in range(args.repeats):  # alternating, so that both see the same load on a shared machine
        shutil.rmtree(out, ignore_errors=True)
        wall, cpu = run_ours(n, material, args.steps, out, args.threads)
        solve = json.loads((out / "summary.json").read_text())["wall_time_s"]
        for key, v in (("wall", wall), ("cpu", cpu), ("solve", solve)):
            runs["ours"][key].append(v)
        wall, cpu, log = run_ccx(job.with_suffix(""), args.threads)
        for key, v in (("wall", wall), ("cpu", cpu), ("solve", parse_stdout(log)["ccx_time_s"] or np.nan)):
            runs["ccx"][key].append(v)
    ours = ours_record(out, mesh)
    ccx = ccx_record(job.with_suffix(""), log, mesh, args.steps, args.stress_scale)
    for rec, key in ((ours, "ours"), (ccx, "ccx")):
        rec["wall_s"] = [round(t, 3) for t in runs[key]["wall"]]
        rec["cpu_s"] = [round(t, 3) for t in runs[key]["cpu"]]
        rec["solve_s_runs"] = [round(t, 3) for t in runs[key]["solve"]]
        rec["solve_s"] = round(statistics.median(runs[key]["solve"]), 3)
        rec["cpu_median_s"] = round(statistics.median(runs[key]["cpu"]), 3)
    mo, mc = statistics.median(runs["ours"]["wall"]), statistics.median(runs["ccx"]["wall"])
    F_diff = np.array(ccx["F"]) / np.array(ours["F"]) - 1.0 if len(ccx["F"]) == len(ours["F"]) else [np.nan]
    rec = {"cell": "hex8", "n": n, "nr": n // 2, "material": material,
           "ccx_material": "*ELASTIC (NLGEOM)" if material == "svk" else "*HYPERELASTIC, NEO HOOKE",
           "nodes": info.body_nodes, "elements": info.body_elements, "dofs": 3 * info.body_nodes,
           "ours": ours, "ccx": ccx,
           "wall_median_ours_s": round(mo, 3), "wall_median_ccx_s": round(mc, 3),
           "time_ratio_ccx_over_ours": round(mc / mo, 3),
           "cpu_ratio_ccx_over_ours": round(ccx["cpu_median_s"] / ours["cpu_median_s"], 3),
           "solve_ratio_ccx_over_ours": round(ccx["solve_s"] / ours["solve_s"], 3),
           "F_ccx_over_ours_minus_1_max": round(float(np.max(np.abs(F_diff))), 5)}
    print(f"n={n} {material}: covcontact {mo:.2f} s ({ours['iterations']} it), ccx {mc:.2f} s "
          f"({ccx['iterations']} it), ratio {mc / mo:.2f}, CPU ratio {rec['cpu_ratio_ccx_over_ours']:.2f}",
          file=sys.stderr, flush=True)
    return rec


def table(records: list[dict]) -> str:
    head = ("| mesh | material | dofs | wall s covcontact | wall s ccx | ccx / covcontact | CPU s cc / ccx"
            " | CPU ccx / cc | own solve s cc / ccx"
            " | iterations cc / ccx | F/F_H d=0.001 cc / ccx | F/F_H d=0.01 cc / ccx | C2 cc / ccx"
            " | max abs(a/sqrt(Rd)-1) cc / ccx | p error r<a/2 cc / ccx |")
    rows = [head, "|" + "---|" * 15]
    for r in records:
        o, c = r["ours"], r["ccx"]
        rows.append(
            f"| hex8 n={r['n']} | {r['material']} | {r['dofs']} | {r['wall_median_ours_s']:.2f}"
            f" | {r['wall_median_ccx_s']:.2f} | {r['time_ratio_ccx_over_ours']:.2f}"
            f" | {o['cpu_median_s']:.2f} / {c['cpu_median_s']:.2f} | {r['cpu_ratio_ccx_over_ours']:.2f}"
            f" | {o['solve_s']:.2f} / {c['solve_s']:.2f} | {o['iterations']} / {c['iterations']}"
            f" | {o['ratio'][0]:.3f} / {c['ratio'][0]:.3f} | {o['ratio'][-1]:.3f} / {c['ratio'][-1]:.3f}"
            f" | {o['C2']:.3f} / {c['C2']:.3f} | {o['a_error_max']:.3f} / {c['a_error_max']:.3f}"
            f" | {o['p_center_error_max']:.3f} / {c['p_center_error_max']:.3f} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="12,16,24", help="n of the mesh generator, comma separated")
    ap.add_argument("--materials", default="svk,neo-hooke")
    ap.add_argument("--steps", type=int, default=10, help="equal load steps up to d = 0.01 R")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--stress-scale", type=float, default=1e5,
                    help="stress unit of the CalculiX deck (its force checks hold constants of their own)")
    ap.add_argument("--quick", action="store_true", help="n = 12, svk, one repeat")
    ap.add_argument("--keep", type=Path, help="keep decks and results in this directory")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    ap.add_argument("--worker", nargs=4, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        n, material, steps, out = args.worker
        return worker(int(n), material, int(steps), out)
    if shutil.which("ccx") is None:
        print("ccx (CalculiX) not found on PATH", file=sys.stderr)
        return 2
    if args.quick:
        args.sizes, args.materials, args.repeats = "12", "svk", 1
    sizes = [int(s) for s in args.sizes.split(",")]
    materials = [m.strip() for m in args.materials.split(",")]
    t0 = time.perf_counter()
    records = []
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        # fill numba's on-disk cache once (not timed)
        run_ours(min(sizes), materials[0], 1, work / "warmup", args.threads)
        for n in sizes:
            for material in materials:
                records.append(race(n, material, args, work))
    result = {"benchmark": "calculix_hertz", "date": time.strftime("%Y-%m-%d"),
              "python": platform.python_version(), "machine": platform.machine(), "cpus": os.cpu_count(),
              "threads": args.threads, "repeats": args.repeats, "steps": args.steps,
              "stress_scale_ccx": args.stress_scale, "penalty": PENALTY,
              "ccx_version": _ccx_version(), "covcontact": _covcontact_state(), "total_s": round(time.perf_counter() - t0, 1),
              "d_over_R": [0.01 * (k + 1) / args.steps for k in range(args.steps)], "records": records}
    emit(result, args.out, table(records))
    ok = all(r["ours"]["converged"] and r["ccx"]["converged"] for r in records)
    return 0 if ok else 1


def _covcontact_state() -> dict:
    """Commit of the working tree (with "+dirty" when it holds changes) and the Newton options used."""
    from dataclasses import asdict

    from covcontact.problem import SolverOptions

    def git(*a: str) -> str:
        proc = subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True, check=False)
        return proc.stdout.strip() if proc.returncode == 0 else ""

    commit = git("rev-parse", "--short", "HEAD")
    dirty = bool(git("status", "--porcelain", "--untracked-files=no", "src"))
    return {"commit": commit + ("+dirty" if dirty else ""), "solver_options": asdict(SolverOptions())}


def _ccx_version() -> str:
    proc = subprocess.run(["ccx", "-v"], capture_output=True, text=True, check=False)
    words = (proc.stdout + proc.stderr).split()
    return words[words.index("Version") + 1] if "Version" in words else ""


if __name__ == "__main__":
    sys.exit(main())
