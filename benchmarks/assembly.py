"""Assembly throughput of the solid elements: residual + tangent into the global CSR pattern.

For each cell type and mesh size (a structured unit cube, n^3 elements) a fresh process builds the
pattern, computes the element ranks, then times `SolidBody.assemble` (median of 3 repeats after one
warm-up) with and without the tangent. Each record holds the times, elements per second, the CSR
size and the resident peak memory of that process. Output: JSON on stdout or to --out.

    python benchmarks/assembly.py --quick
    python benchmarks/assembly.py --out assembly.json --max-gib 12
    python benchmarks/assembly.py --cells hex8 --material j2 --formulation fbar   # plastic F-bar hex8
    python benchmarks/assembly.py --single hex8 40 --material j2 --formulation solid-shell  # plastic solid-shells
    python benchmarks/assembly.py --cells hex8 --formulation incompatible   # incompatible modes (C3D8I)

With ``--material j2`` the body is stretched 1 % (beyond yield) from the virgin state, so every Gauss point
runs the return mapping; the time includes the copy of the history arrays that an evaluation makes.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import time

import numpy as np

SIZES = {"hex8": [10, 22, 46, 100], "hex27": [10, 22, 46, 64], "hex20": [10, 22, 46], "tet10": [10, 22, 32],
         "tet4": [10, 22, 46], "wedge6": [10, 22, 46]}
QUICK = {"hex8": [10, 22], "hex27": [6, 10], "hex20": [6, 10], "tet10": [6, 10], "tet4": [10, 22], "wedge6": [10, 22]}
#: approximate bytes per element of pattern (data + indices), ranks and mesh, structured cube (n^3 bricks)
BYTES_PER_ELEMENT = {"hex8": 12 * 9 * 27 + 4 * 64 + 100, "hex27": 12 * 9 * 512 + 4 * 729 + 800,
                     "hex20": 12 * 9 * 300 + 4 * 400 + 600, "tet10": 6 * (12 * 9 * 60 + 4 * 100 + 300),
                     "tet4": 6 * (12 * 9 * 8 + 4 * 16 + 100), "wedge6": 2 * (12 * 9 * 20 + 4 * 36 + 100)}


def cube(cell: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n^3 bricks of ``cell`` on the unit cube, VTK node order: hex8 or hex27, or those split (tet4, tet10: six
    tetrahedra per brick; wedge6: two wedges) or trimmed (hex20)."""
    from covcontact.fem.shapes import IDX
    from covcontact.mesh.convert import SOURCE, convert
    from covcontact.mesh.mesh import Mesh

    if cell in SOURCE:
        X, cells = cube(SOURCE[cell], n)
        m = convert(Mesh(X, SOURCE[cell], cells), cell)
        return m.points, m.cells

    p = 1 if cell == "hex8" else 2
    m = p * n + 1
    pos = np.array([0, p, 1])
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    base = p * np.stack([i.T.ravel(), j.T.ravel(), k.T.ravel()], axis=1)
    g = base[:, None, :] + pos[IDX[cell]][None, :, :]
    cells = (g[..., 0] + m * (g[..., 1] + m * g[..., 2])).astype(np.int64)
    a, b, c = np.meshgrid(np.arange(m), np.arange(m), np.arange(m), indexing="ij")
    X = np.stack([a.T.ravel(), b.T.ravel(), c.T.ravel()], axis=1) / (m - 1.0)
    return np.ascontiguousarray(X), cells


def peak_rss_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # ru_maxrss is in KiB on Linux


def timed(fn, repeats: int) -> tuple[float, float]:
    """Median wall and CPU seconds of ``fn`` over ``repeats`` runs after one warm-up."""
    fn()
    wall, cpu = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)), float(np.median(cpu))


def run_single(cell: str, n: int, repeats: int, material: str = "svk", formulation: str = "solid") -> dict:
    import numba

    from covcontact.assembly import Pattern
    from covcontact.elements import SolidBody
    from covcontact.elements.fbar import FbarBody
    from covcontact.elements.incompatible import IncompatibleBody
    from covcontact.elements.solidshell import SolidShellBody
    from covcontact.materials import J2Plasticity, SaintVenantKirchhoff

    t0 = time.perf_counter()
    X, cells = cube(cell, n)
    t_mesh = time.perf_counter() - t0
    t0 = time.perf_counter()
    P = Pattern(X.shape[0], [cells])
    t_pattern = time.perf_counter() - t0
    mat = (J2Plasticity(E=210e3, nu=0.3, yield_stress=250.0, hardening={"law": "linear", "modulus": 1000.0})
           if material == "j2" else SaintVenantKirchhoff(E=210e3, nu=0.3))
    if formulation == "solid-shell":  # the third element direction is the thickness; J2: 5 Gauss points
        body = SolidShellBody(cell, X, cells, mat)
    else:
        kind = {"fbar": FbarBody, "incompatible": IncompatibleBody}.get(formulation, SolidBody)
        body = kind(cell, X, cells, mat)
    state = body.new_state()
    t0 = time.perf_counter()
    body.ranks(P)
    t_ranks = time.perf_counter() - t0
    u = 1e-3 * np.random.default_rng(0).standard_normal(X.shape)
    if material == "j2":  # 1 % stretch along x (beyond yield everywhere, 250 / 210e3 = 0.12 %) plus noise
        u = 1e-2 * X * [1.0, 0.0, 0.0] + 1e-4 * u / n
    data = P.zeros()
    rhs = np.zeros(P.n_dofs)

    def full() -> None:
        data[:] = 0.0
        rhs[:] = 0.0
        assert body.assemble(u, data, rhs, P, state=body.kernel_state(state, state)) == -1

    def residual() -> None:
        rhs[:] = 0.0
        assert body.assemble(u, data, rhs, P, want_K=False, state=body.kernel_state(state, state)) == -1

    w_full, c_full = timed(full, repeats)
    w_res, _ = timed(residual, repeats)
    ne = cells.shape[0]
    return {
        "cell": cell, "material": material, "formulation": formulation, "n": n, "n_elements": ne, "n_nodes": int(X.shape[0]),
        "n_dofs": P.n_dofs, "nnz": P.nnz, "chunk": body.chunk, "threads": numba.get_num_threads(),
        "mesh_s": round(t_mesh, 4), "pattern_s": round(t_pattern, 4), "ranks_s": round(t_ranks, 4),
        "assemble_s": round(w_full, 4), "assemble_cpu_s": round(c_full, 4),
        "assemble_el_per_s": round(ne / w_full), "assemble_nodes_per_s": round(X.shape[0] / w_full),
        "residual_s": round(w_res, 4),
        "residual_el_per_s": round(ne / w_res), "csr_gib": round(12 * P.nnz / 2**30, 3),
        "ranks_gib": round(body.ranks(P).nbytes / 2**30, 3), "peak_rss_gib": round(peak_rss_gib(), 3),
        "loadavg_1min": round(os.getloadavg()[0], 2),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="small meshes only")
    ap.add_argument("--out", help="write the JSON here instead of stdout")
    ap.add_argument("--cells", default="hex8,hex27", help="comma separated cell types")
    ap.add_argument("--max-gib", type=float, default=12.0, help="skip meshes estimated above this memory")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--material", default="svk", choices=("svk", "j2"),
                    help="j2: J2 plasticity in a plastic state (return mapping included)")
    ap.add_argument("--formulation", default="solid",
                    choices=("solid", "fbar", "solid-shell", "incompatible"))
    ap.add_argument("--single", nargs=2, metavar=("CELL", "N"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.single:
        print(json.dumps(run_single(args.single[0], int(args.single[1]), args.repeats, args.material,
                                    args.formulation)))
        return 0
    sizes = QUICK if args.quick else SIZES
    records = []
    for cell in args.cells.split(","):
        for n in sizes[cell]:
            est = BYTES_PER_ELEMENT[cell] * n**3 / 2**30  # per brick
            if est > args.max_gib:
                records.append({"cell": cell, "n": n, "n_elements": n**3, "skipped":
                                f"estimated {est:.1f} GiB > --max-gib {args.max_gib}"})
                continue
            cmd = [sys.executable, __file__, "--single", cell, str(n), "--repeats", str(args.repeats),
                   "--material", args.material, "--formulation", args.formulation]
            res = subprocess.run(cmd, check=False, capture_output=True, text=True)
            if res.returncode != 0:
                records.append({"cell": cell, "n": n, "n_elements": n**3, "error": res.stderr[-2000:]})
            else:
                records.append(json.loads(res.stdout.strip().splitlines()[-1]))
            print(json.dumps(records[-1]), file=sys.stderr)
    out = {"benchmark": "assembly", "machine": {"cpus": os.cpu_count(), "python": platform.python_version()},
           "records": records}
    text = json.dumps(out, indent=1)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
