"""Segment-to-surface and self-contact: what they cost against node-to-surface.

Three measurements, each written to the JSON record:

1. ``per_point``: the contact evaluation (search from a warm cache, projection, kernels, expansion onto the facet
   nodes, residual and tangent blocks) of the two-blocks problem (benchmarks/problems/two_blocks_5k.toml) at its
   converged first step, per slave: node-to-surface per slave node, segment-to-surface per Gauss point (2 x 2 per
   facet). Median of ``--repeats`` evaluations after a warm-up.
2. ``race``: the whole ``covcontact run`` of the same problem (process start to exit, the race's measure), with
   ``type = "nts"`` and ``type = "sts"``, alternating, ``--repeats`` times each; medians and their ratio.
3. ``self_search``: one self-contact iteration's search on a surface of ``--facets`` quad4 facets, every node a
   slave: two wavy sheets 0.02 apart facing each other (a sheet folded onto itself), merged into one surface. The
   candidate boxes, the excluded facets and the facing test, and the projection, as a self-contact pass runs them
   each Newton iteration (the boxes are cached between iterations in a run; timed here anyway).

    python benchmarks/sts.py --out sts.json [--repeats 5] [--facets 100000]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _report import emit
from contact_search import wavy_surface

from covcontact.contact.driver import project_slaves
from covcontact.contact.search import candidates
from covcontact.contact.selfcontact import drop_excluded, excluded_facets, facet_normals, slave_normals
from covcontact.contact.surface import MeshSurface, facet_sizes
from covcontact.io.loader import load_problem

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = ROOT / "benchmarks" / "problems"
PROBLEM = PROBLEMS / "two_blocks_5k.toml"


def variant(folder: Path, typ: str, problem: Path = PROBLEM) -> Path:
    text = problem.read_text()
    path = folder / f"two_blocks_{typ}.toml"
    path.write_text(text.replace("[[contact]]\n", f'[[contact]]\ntype = "{typ}"\n', 1))
    return path


def per_point(folder: Path, typ: str, repeats: int, problem: Path = PROBLEM) -> dict:
    prob = load_problem(variant(folder, typ, problem))
    prob.steps.factors = prob.steps.factors[:1]
    prob.output.vtu = False
    res = prob.run(out=folder / f"out_{typ}")
    model = res.model
    x = model.positions(res.u)
    lam = res.summary["steps"][-1]["load_factor"]
    cm = model.contact
    cm.evaluate(x, lam, res.state.contact)  # warm: compiled kernels, search cache
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        cm.evaluate(x, lam, res.state.contact)
        times.append(time.perf_counter() - t0)
    slaves = sum(p.ns for p in cm.passes)
    active = cm.active_count(res.state.contact)
    t = statistics.median(times)
    return {"problem": problem.stem, "type": typ, "slaves": slaves, "active": active, "evaluation_s": t, "per_slave_us": 1e6 * t / slaves}


def whole_run(path: Path, out: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(path), "--out", str(out), "--quiet"],
                   check=True)
    return time.perf_counter() - t0


def race(folder: Path, repeats: int) -> dict:
    paths = {typ: variant(folder, typ) for typ in ("nts", "sts")}
    times: dict[str, list[float]] = {"nts": [], "sts": []}
    for typ, path in paths.items():  # warm the compiled kernels' cache
        whole_run(path, folder / f"warm_{typ}")
    for k in range(repeats):
        for typ in (("nts", "sts") if k % 2 == 0 else ("sts", "nts")):
            times[typ].append(whole_run(paths[typ], folder / f"race_{typ}"))
    med = {typ: statistics.median(v) for typ, v in times.items()}
    return {"wall_s": times, "median_s": med, "ratio_sts_nts": med["sts"] / med["nts"]}


def self_search(n_facets: int, repeats: int) -> dict:
    m = round(float(np.sqrt(n_facets / 2)))
    lower, faces = wavy_surface(m, quad9=False)
    upper = lower + [0.0, 0.0, 0.02]
    pts = np.vstack([lower, upper])
    faces = np.vstack([faces, faces[:, ::-1] + len(lower)])  # the upper sheet faces down
    surface = MeshSurface(faces, n_nodes=len(pts))
    slaves = np.unique(faces)
    t0 = time.perf_counter()
    excl = excluded_facets(faces, len(pts), slave_nodes=slaves)
    setup = time.perf_counter() - t0
    x = pts

    def once():
        margin = float(facet_sizes(x, faces).max())
        ptr, fac = candidates(x, surface, x[slaves], margin)
        fn = facet_normals(x, faces)
        own = slave_normals(x, surface, slaves, None, fn)
        ptr, fac = drop_excluded(np.ascontiguousarray(ptr, np.int64), np.ascontiguousarray(fac, np.int64), excl,
                                 own, fn, np.zeros(len(slaves)))
        return project_slaves(x, surface, x[slaves], ptr, fac, max_hops=0, tol_inside=1e-4)

    once()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = once()
        times.append(time.perf_counter() - t0)
    return {"facets": len(faces), "slaves": len(slaves), "setup_s": setup, "iteration_s": statistics.median(times),
            "contacts_found": int(np.count_nonzero(res.kind))}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--facets", type=int, default=100_000)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        pp = [per_point(folder, typ, args.repeats, PROBLEMS / f"{name}.toml") for name in ("two_blocks_5k",
                                                                                            "two_blocks_30k")
              for typ in ("nts", "sts")]
        rc = race(folder, args.repeats)
    ss = self_search(args.facets, args.repeats)
    result = {"per_point": pp, "race": rc, "self_search": ss}
    table = "\n".join([
        "| problem | type | slaves | active | evaluation s | per slave us |", "|---|---|---|---|---|---|",
        *[f"| {r['problem']} | {r['type']} | {r['slaves']} | {r['active']} | {r['evaluation_s']:.4f} | {r['per_slave_us']:.2f} |"
          for r in pp],
        "", (f"whole run, median of {args.repeats}: nts {rc['median_s']['nts']:.2f} s, sts {rc['median_s']['sts']:.2f} s,"
             f" ratio {rc['ratio_sts_nts']:.2f}"),
        (f"self-contact search: {ss['facets']} facets, {ss['slaves']} slaves, {ss['iteration_s']:.3f} s per iteration "
         f"(set-up {ss['setup_s']:.3f} s), contacts found {ss['contacts_found']}")])
    emit(result, args.out, table)


if __name__ == "__main__":
    main()
