"""Linear solvers on covcontact stiffness matrices: factor + solve time of every available backend.

Cases (hex8, St. Venant-Kirchhoff tangent at a deformed state, clamped on the face x = 0 by deleting
those rows and columns):

    plate    60 x 60 x 2 elements, 32,940 dofs
    block20  20 x 20 x 20 elements, 26,460 dofs
    block30  30 x 30 x 30 elements, 86,490 dofs

The parent builds each matrix once (numba kernels) and writes it to a temporary .npz; every
(case, backend) then runs in a fresh process, so that its peak memory is its own. A run times a
fresh solver (analysis + factorisation + solve) and a second factorisation of the same pattern
with new values (what a Newton iteration pays), median of --repeats (one repeat and no second
factorisation when a run takes longer than 30 s). Backends slower than --limit seconds on block20
are skipped on block30. ``spsolve`` is SciPy's plain spsolve, a reference on the smaller cases.

    python benchmarks/solvers.py --out solvers.json
    python benchmarks/solvers.py --cases plate --backends pardiso,superlu
    python benchmarks/solvers.py --npz K.npz          # a matrix of your own (scipy save_npz or --save)
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

CASES = {"plate": ((60, 60, 2), (60.0, 60.0, 2.0)), "block20": ((20, 20, 20), (20.0, 20.0, 20.0)),
         "block30": ((30, 30, 30), (30.0, 30.0, 30.0))}
SLOW_SINGLE_REPEAT = 30.0


def deformed_state(X: np.ndarray) -> np.ndarray:
    """A smooth deformation vanishing at x = 0: 1 % stretch, bending in z and a twist about x."""
    L = float(np.ptp(X[:, 0]))
    s = X[:, 0] / L
    c = X.mean(axis=0)
    u = np.zeros_like(X)
    u[:, 0] = 0.01 * X[:, 0]
    u[:, 2] = 0.02 * L * s**2
    th = 0.1 * s
    y, z = X[:, 1] - c[1], X[:, 2] - c[2]
    u[:, 1] += (np.cos(th) - 1) * y - np.sin(th) * z
    u[:, 2] += np.sin(th) * y + (np.cos(th) - 1) * z
    return u


def build_case(name: str) -> dict:
    """Tangent K and internal force b on the free dofs, with node coordinates and free dof numbers."""
    from covcontact.assembly import Pattern
    from covcontact.elements import SolidBody
    from covcontact.materials import SaintVenantKirchhoff
    from covcontact.mesh.generators import block

    (nx, ny, nz), (lx, ly, lz) = CASES[name]
    mesh = block(lx, ly, lz, nx, ny, nz, "hex8")
    X = mesh.points
    t0 = time.perf_counter()
    P = Pattern(X.shape[0], [mesh.cells])
    body = SolidBody("hex8", X, mesh.cells, SaintVenantKirchhoff(E=1000.0, nu=0.3))
    data, rhs = P.zeros(), np.zeros(P.n_dofs)
    if body.assemble(deformed_state(X), data, rhs, P) != -1:
        raise RuntimeError("inverted element in the deformed state")
    fixed = np.zeros(P.n_dofs, dtype=bool)
    fixed[(3 * mesh.node_sets["xmin"][:, None] + np.arange(3)).ravel()] = True
    free = np.flatnonzero(~fixed)
    K = P.csr(data)[free][:, free].tocsr()
    K.sort_indices()
    return {"K": K, "b": rhs[free], "points": X, "dofs": free, "assembly_s": time.perf_counter() - t0}


def save_case(path: Path, case: dict) -> None:
    K = case["K"]
    np.savez(path, K_data=K.data, K_indices=K.indices, K_indptr=K.indptr, K_shape=np.array(K.shape),
             b=case["b"], points=case.get("points", np.zeros((0, 3))), dofs=case.get("dofs", np.zeros(0)))


def load_case(path: str) -> dict:
    z = np.load(path)
    if "format" in z:  # written by scipy.sparse.save_npz
        K = sp.load_npz(path).tocsr()
        b = np.ones(K.shape[0])
        return {"K": K, "b": b, "points": np.zeros((0, 3)), "dofs": np.zeros(0, dtype=np.int64)}
    K = sp.csr_matrix((z["K_data"], z["K_indices"], z["K_indptr"]), shape=tuple(z["K_shape"]))
    b = z["b"] if "b" in z else np.ones(K.shape[0])
    return {"K": K, "b": b, "points": z["points"], "dofs": z["dofs"].astype(np.int64)}


def _make(backend: str):
    from covcontact.solvers.linear import make_solver

    name, _, opt = backend.partition(":")
    return make_solver(name, symmetric=True, **({opt: True} if opt else {}))


def run_single(path: str, backend: str, repeats: int) -> dict:
    """Time one backend on one matrix (in this process)."""
    case = load_case(path)
    K, b = case["K"], case["b"]
    if not np.linalg.norm(b) > 0:
        b = np.ones(K.shape[0])
    rec: dict = {"backend": backend, "n_dofs": K.shape[0], "nnz": int(K.nnz)}
    first, again = [], []
    for _ in range(repeats):
        if backend == "spsolve":
            import scipy.sparse.linalg as sla

            t0, c0 = time.perf_counter(), time.process_time()
            x = sla.spsolve(K.tocsc(), b)
            first.append({"total": time.perf_counter() - t0, "cpu": time.process_time() - c0})
            rec["residual"] = float(np.linalg.norm(K @ x - b) / np.linalg.norm(b))
        else:
            s = _make(backend)
            if case["points"].shape[0]:
                s.set_geometry(case["points"], case["dofs"])
            t0, c0 = time.perf_counter(), time.process_time()
            s.factorize(K)
            x = s.solve_factorized(b)
            first.append({"total": time.perf_counter() - t0, "cpu": time.process_time() - c0,
                          "analyze": s.t_analyze, "factor": s.t_factor, "solve": s.t_solve})
            if first[-1]["total"] <= SLOW_SINGLE_REPEAT:
                K2 = K.copy()  # same pattern, other values: the analysis is reused
                K2.data *= 1.01
                t0, c0 = time.perf_counter(), time.process_time()
                s.factorize(K2)
                s.solve_factorized(b)
                again.append({"total": time.perf_counter() - t0, "cpu": time.process_time() - c0,
                              "factor": s.t_factor, "solve": s.t_solve})
            rec["residual"] = s.residual
            rec["n_analyses"] = s.n_analyses
            for key in ("inertia", "n_perturbed", "iterations", "last_backend"):
                if hasattr(s, key):
                    rec[key] = getattr(s, key)
            s.close()
        if first[-1]["total"] > SLOW_SINGLE_REPEAT:
            break
    rec["repeats"] = len(first)
    rec["first"] = {k: round(float(np.median([r[k] for r in first])), 4) for k in first[0]}
    rec["first_min_total"] = round(min(r["total"] for r in first), 4)  # least disturbed by other load
    if again:
        rec["refactor"] = {k: round(float(np.median([r[k] for r in again])), 4) for k in again[0]}
    rec["peak_rss_gib"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20, 3)
    rec["loadavg_1min"] = round(os.getloadavg()[0], 2)
    return rec


def spawn(path: str, backend: str, repeats: int, timeout: float) -> dict:
    cmd = [sys.executable, __file__, "--single", path, backend, "--repeats", str(repeats)]
    try:
        res = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"backend": backend, "error": f"timeout after {timeout:.0f} s"}
    if res.returncode != 0:
        return {"backend": backend, "error": res.stderr[-1500:]}
    return json.loads(res.stdout.strip().splitlines()[-1])


def table(records: list[dict]) -> str:
    """Markdown table: wall seconds of the first run (analysis included), its analysis part, a
    refactorisation + solve on the same pattern, one solve, CPU seconds of the first run."""
    cols = ["case", "backend", "dofs", "first", "analysis", "refactor", "solve", "cpu first", "peak GiB",
            "load", "residual"]
    lines = ["| " + " | ".join(cols) + " |", "|" + "|".join("---" for _ in cols) + "|"]
    nan = float("nan")
    for r in records:
        if "first" not in r:
            why = r.get("skipped") or (r.get("error", "").strip().splitlines() or [""])[-1]
            lines.append(f"| {r['case']} | {r['backend']} | | {why[:80]} |" + " |" * (len(cols) - 4))
            continue
        f, g = r["first"], r.get("refactor", {})
        vals = [f["total"], f.get("analyze", nan), g.get("total", nan), g.get("solve", f.get("solve", nan)),
                f.get("cpu", nan)]
        cells = [r["case"], r["backend"], str(r["n_dofs"])] + [
            "-" if np.isnan(v) else (f"{v:.3f}" if v < 0.1 else f"{v:.2f}") for v in vals
        ] + [f"{r['peak_rss_gib']:.2f}", f"{r.get('loadavg_1min', nan):.1f}", f"{r['residual']:.0e}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES), help="comma separated, from " + ", ".join(CASES))
    ap.add_argument("--npz", nargs="*", default=[], help="benchmark these matrices instead of the cases")
    ap.add_argument("--backends", help="comma separated (default: all available; 'pardiso:spd' = mtype 2)")
    ap.add_argument("--no-reference", action="store_true", help="skip the plain spsolve reference")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--limit", type=float, default=60.0, help="skip block30 above this time on block20")
    ap.add_argument("--timeout", type=float, default=900.0, help="per (case, backend) process")
    ap.add_argument("--save", help="directory to keep the built matrices as .npz")
    ap.add_argument("--out", help="write the JSON here")
    ap.add_argument("--single", nargs=2, metavar=("NPZ", "BACKEND"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.single:
        print(json.dumps(run_single(args.single[0], args.single[1], args.repeats)))
        return 0

    from covcontact.solvers.linear import available, describe

    backends = args.backends.split(",") if args.backends else available()
    tmp = Path(args.save) if args.save else Path(tempfile.mkdtemp(prefix="cc-solvers-"))
    tmp.mkdir(parents=True, exist_ok=True)
    jobs = [(Path(p).stem, p) for p in args.npz] or [(c, None) for c in args.cases.split(",")]
    records: list[dict] = []
    built: dict[str, dict] = {}
    for case, path in jobs:
        if path is None:
            data = build_case(case)
            path = str(tmp / f"{case}.npz")
            save_case(Path(path), data)
            built[case] = {"n_dofs": data["K"].shape[0], "nnz": int(data["K"].nnz),
                           "assembly_s": round(data["assembly_s"], 3)}
            print(f"{case}: {built[case]}", file=sys.stderr)
        names = list(backends)
        if not args.no_reference and case in ("plate", "block20"):
            names.append("spsolve")
        for be in names:
            prev = [r for r in records if r["case"] == "block20" and r["backend"] == be and "first" in r]
            if case == "block30" and prev and prev[0]["first"]["total"] > args.limit:
                records.append({"case": case, "backend": be, "skipped":
                                f"{prev[0]['first']['total']:.0f} s on block20 > --limit {args.limit:.0f} s"})
            elif case == "block30" and be == "spsolve":
                continue
            else:
                records.append({"case": case, **spawn(path, be, args.repeats, args.timeout)})
            print(json.dumps(records[-1]), file=sys.stderr)
    if not args.save:
        for f in tmp.glob("*.npz"):
            f.unlink()
        tmp.rmdir()
    out = {
        "benchmark": "linear solvers",
        "date": time.strftime("%Y-%m-%d"),
        "machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                    "memory_gib": round(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30, 1),
                    "loadavg_1min": round(os.getloadavg()[0], 2)},
        "solvers": describe(),
        "cases": built,
        "records": records,
    }
    if args.out:
        with open(args.out, "w") as f:
            f.write(json.dumps(out, indent=1) + "\n")
    print(table(records))
    return 0


if __name__ == "__main__":
    sys.exit(main())
