"""Contact search + projection throughput: slave nodes per second against a wavy master surface.

A structured quad4 (or quad9) surface z = a sin(x) cos(y) with about as many facets as slaves; the slaves
lie within a fraction of a facet size of the surface. Times the global search (bucket grid), the cold
projection (no history) and the warm projection (previous facet and xi given) after a warm-up: wall time
(median of 3) with all threads, and per core (process time of one thread, best of 7). Writes JSON; the
growth of the time with n shows the n log n behaviour.

Slaves are numbered at random (``--numbering random``, the default: the worst case for memory traffic) or
along the surface as mesh nodes are (``coherent``: rows of facets, along y within a row).

    python benchmarks/contact_search.py --out search.json [--max 1000000] [--quad9] [--numbering coherent]
    python benchmarks/contact_search.py --per-core 200000 [--quad9] [--numbering coherent]   # one size, 1 thread
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import numba
import numpy as np

from covcontact.contact.driver import project_slaves
from covcontact.contact.search import candidates
from covcontact.contact.surface import MeshSurface


def wavy_surface(m: int, quad9: bool):
    """(points, faces) of an m x m facet surface on [0, 10]^2."""
    k = 2 * m + 1 if quad9 else m + 1
    s = np.linspace(0.0, 10.0, k)
    X, Y = np.meshgrid(s, s, indexing="ij")
    Z = 0.3 * np.sin(X) * np.cos(Y)
    pts = np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)
    idx = np.arange(k * k).reshape(k, k)
    faces = []
    step = 2 if quad9 else 1
    for i in range(0, k - 1, step):
        for j in range(0, k - 1, step):
            if quad9:
                faces.append([idx[i, j], idx[i + 2, j], idx[i + 2, j + 2], idx[i, j + 2], idx[i + 1, j],
                              idx[i + 2, j + 1], idx[i + 1, j + 2], idx[i, j + 1], idx[i + 1, j + 1]])
            else:
                faces.append([idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]])
    return pts, np.array(faces, dtype=np.int64)


def _times(fn, repeats, clock) -> list[float]:
    times = []
    for _ in range(repeats):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return times


def median_time(fn, repeats=3) -> float:
    return float(np.median(_times(fn, repeats, time.perf_counter)))


def best_cpu_time(fn, repeats=7) -> float:
    return float(np.min(_times(fn, repeats, time.process_time)))


def problem(n: int, quad9: bool, numbering: str, rng):
    m = max(int(np.sqrt(n)), 2)
    pts, faces = wavy_surface(m, quad9)
    surf = MeshSurface(faces, n_nodes=len(pts))
    h = 10.0 / m
    xy = rng.uniform(0.0, 10.0, size=(n, 2))
    z = 0.3 * np.sin(xy[:, 0]) * np.cos(xy[:, 1]) + rng.uniform(-0.3, 0.1, n) * h
    xs = np.ascontiguousarray(np.column_stack([xy, z]))
    if numbering == "coherent":  # rows of facets, along y within a row (as a structured mesh numbers its nodes)
        xs = np.ascontiguousarray(xs[np.lexsort((xs[:, 1], np.floor(xs[:, 0] / h)))])
    return pts, surf, xs, 0.5 * h


def run(n: int, quad9: bool, rng, numbering: str = "random", timer=median_time) -> dict:
    pts, surf, xs, margin = problem(n, quad9, numbering, rng)
    ptr, fac = candidates(pts, surf, xs, margin)
    res = project_slaves(pts, surf, xs, ptr, fac)
    t_search = timer(lambda: candidates(pts, surf, xs, margin))
    t_cold = timer(lambda: project_slaves(pts, surf, xs, ptr, fac))
    t_warm = timer(lambda: project_slaves(pts, surf, xs, ptr, fac, res.facet, res.xi))
    found = int(np.count_nonzero(res.kind > 0))
    return {"slaves": n, "facets": int(surf.n_facets), "facet_type": "quad9" if quad9 else "quad4",
            "numbering": numbering, "search_s": t_search, "projection_cold_s": t_cold, "projection_warm_s": t_warm,
            "slaves_per_s_search_cold": n / (t_search + t_cold), "slaves_per_s_warm": n / t_warm,
            "candidates_per_slave": len(fac) / n, "found": found}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None)
    ap.add_argument("--max", type=int, default=1_000_000)
    ap.add_argument("--quad9", action="store_true")
    ap.add_argument("--numbering", choices=("random", "coherent"), default="random")
    ap.add_argument("--per-core", type=int, default=0, metavar="N",
                    help="only N slaves, one numba thread, process time (best of 7) instead of wall time")
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    run(1000, args.quad9, rng)  # compile
    rows = []
    if args.per_core:
        numba.set_num_threads(1)
        row = run(args.per_core, args.quad9, rng, args.numbering, best_cpu_time)
        row["per_core"] = True
        rows.append(row)
        print(json.dumps(row), flush=True)
    n = 1000
    while not args.per_core and n <= args.max:
        rows.append(run(n, args.quad9, rng, args.numbering))
        print(json.dumps(rows[-1]), flush=True)
        n *= 10
    out = {"benchmark": "contact_search", "machine": platform.machine(), "threads": numba.get_num_threads(),
           "date": time.strftime("%Y-%m-%d"), "rows": rows}
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(out, fh, indent=2)


if __name__ == "__main__":
    main()
