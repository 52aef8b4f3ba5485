"""Solid-shell verification tables: linear obstacle course, EAS / ANS studies, nonlinear benchmarks, cost.

The problem set-ups are those of the verification tests (tests/verification/test_shell_obstacle.py and
test_shell_nonlinear.py), run here on finer meshes and with the locking cures switched on and off. Prints
markdown tables (the "Shells" section of docs/verification.md) and writes JSON with --out.

    python benchmarks/shells.py                 # everything (about 10 minutes on 2 cores)
    python benchmarks/shells.py --only obstacle eas --out shells.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

import test_shell_nonlinear as nl
import test_shell_obstacle as ob

TMP = Path(tempfile.mkdtemp(prefix="shells-"))
OFF = {"hex8": {"eas": 0, "ans_shear": False, "ans_thickness": False},
       "hex18": {"eas": 0, "ans_shear": False, "ans_thickness": False, "ans_membrane": False}}
MESHES = {"hex8": [4, 8, 16, 32], "hex18": [2, 4, 8, 16]}
LINEAR = {
    "Scordelis-Lo roof": (ob.scordelis_lo, ob.SCORDELIS_LO),
    "pinched cylinder": (ob.pinched_cylinder, ob.PINCHED_CYLINDER),
    "pinched hemisphere": (ob.pinched_hemisphere, ob.PINCHED_HEMISPHERE),
    "thin plate t/a = 1/1000": (ob.thin_plate, 1.0),
}


def timed(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def linear_value(builder, n, cell, **opts) -> float:
    try:
        value, _ = ob.solve(builder(n, cell, **opts), TMP / "lin")
    except AssertionError as exc:  # a failed run (e.g. a singular locked system) is reported, not fatal
        print(f"  run failed: {exc}", file=sys.stderr)
        return float("nan")
    return float(value)


def obstacle() -> dict:
    rows = {}
    print("\n### Linear obstacle course (normalised by the reference value)\n")
    for name, (builder, ref) in LINEAR.items():
        print(f"{name} (reference {ref:g})\n")
        print("| element | mesh | defaults | cures off | time (s) |\n|---|---|---|---|---|")
        for cell in ("hex8", "hex18"):
            for n in MESHES[cell]:
                v, dt = timed(linear_value, builder, n, cell)
                v0 = linear_value(builder, n, cell, **OFF[cell])
                rows.setdefault(name, []).append({"cell": cell, "n": n, "value": v, "off": v0, "time_s": dt})
                print(f"| {cell} | {n}x{n} | {v / ref:.4f} | {v0 / ref:.4f} | {dt:.2f} |")
        print()
    return rows


def eas_study() -> dict:
    """Number of EAS modes (and the hex18 membrane tying) against the linear cases on coarse meshes."""
    cases = {"hex8": ([0, 1, 3, 5, 7], 8), "hex18": ([0, 1, 3, 4, 9], 4)}
    out = {}
    print("\n### EAS modes and ANS variants (value / reference)\n")
    head = " | ".join(LINEAR)
    print(f"| element, options | {head} |\n|---|" + "---|" * len(LINEAR))
    for cell, (modes, n) in cases.items():
        variants = [{"eas": e} for e in modes]
        if cell == "hex18":
            variants += [{"eas": 3, "ans_membrane": False}, {"eas": 3, "ans_shear": False}]
        else:
            variants += [{"eas": 7, "ans_shear": False}, {"eas": 7, "ans_thickness": False}]
        for opts in variants:
            vals = [linear_value(b, n, cell, **opts) / ref for b, ref in LINEAR.values()]
            out[f"{cell} {n}x{n} {opts}"] = vals
            print(f"| {cell} {n}x{n} {opts} | " + " | ".join(f"{v:.4f}" for v in vals) + " |")
    return out


def cost() -> dict:
    """Assembly time per element (residual + tangent, and residual only) for each EAS setting."""
    from covcontact.assembly import Pattern
    from covcontact.elements import SolidBody
    from covcontact.elements.solidshell import SolidShellBody
    from covcontact.materials import NeoHooke, SaintVenantKirchhoff
    from covcontact.mesh.generators import cylinder_patch

    out = {}
    print("\n### Assembly cost (microseconds per element, 2 threads)\n")
    print("| element | options | material | K + r | r only |\n|---|---|---|---|---|")
    for cell, n in (("hex8", 64), ("hex18", 32)):
        mesh = cylinder_patch(10.0, 10.0, 0.0, math.pi / 2, 0.1, n, n, cell=cell)
        rng = np.random.default_rng(0)
        u = 1e-3 * rng.standard_normal(mesh.points.shape)
        P = Pattern(mesh.n_nodes, [mesh.cells])
        variants = [("solid (no cures)", None)] if cell == "hex8" else []
        variants += [(f"eas={e}", {"eas": e}) for e in ((0, 1, 5, 7) if cell == "hex8" else (0, 1, 3, 9))]
        for label, opts in variants:
            for mat in (SaintVenantKirchhoff(E=1e5, nu=0.3), NeoHooke(E=1e5, nu=0.3)):
                if opts is None:
                    body = SolidBody(cell, mesh.points, mesh.cells, mat)
                else:
                    body = SolidShellBody(cell, mesh.points, mesh.cells, mat, **opts)
                times = []
                for want_K in (True, False):
                    data, r = P.zeros(), np.zeros(P.n_dofs)
                    body.assemble(u, data, r, P, want_K=want_K)  # warm-up
                    ts = []
                    for _ in range(3):
                        data[:] = 0.0
                        r[:] = 0.0
                        t0 = time.perf_counter()
                        body.assemble(u, data, r, P, want_K=want_K)
                        ts.append(time.perf_counter() - t0)
                    times.append(1e6 * float(np.median(ts)) / mesh.n_cells)
                out[f"{cell} {label} {mat.name}"] = times
                print(f"| {cell} | {label} | {mat.name} | {times[0]:.1f} | {times[1]:.1f} |")
    return out


def nonlinear() -> dict:
    out = {}
    print("\n### Geometrically nonlinear benchmarks\n")
    print("Cantilever under end shear (Sze 3.1), tip -U, W at P/Pmax = 1 (reference 3.286, 6.698):\n")
    print("| element | mesh | steps | -U | W | iterations | time (s) |\n|---|---|---|---|---|---|---|")
    for cell, nx in (("hex8", 8), ("hex8", 16), ("hex8", 32), ("hex18", 4), ("hex18", 8)):
        prob, measure = nl.cantilever_shear(nx, cell, steps=10)
        res, dt = timed(nl.run, prob, TMP / "cs")
        U, W = measure(res.u)
        out[f"cantilever {cell} {nx}"] = (U, W, res.summary["total_iterations"])
        print(f"| {cell} | {nx}x1 | 10 | {U:.4f} | {W:.4f} | {res.summary['total_iterations']} | {dt:.1f} |")

    print("\nDead end couple F h L / EI = 4 (arc angle phi = 4 cos phi = 1.25235):\n")
    print("| element | mesh | phi | circle deviation / rho | iterations |\n|---|---|---|---|---|")
    for cell, nx in (("hex8", 8), ("hex8", 16), ("hex18", 4), ("hex18", 8)):
        prob, mesh, _, _ = nl.end_couple(nx, cell)
        res = nl.run(prob, TMP / "mc")
        X = mesh.points
        x = X + res.u.reshape(-1, 3)
        bot = np.flatnonzero(np.isclose(X[:, 2], 0.0))
        top = np.flatnonzero(np.isclose(X[:, 2], 0.1))
        bot, top = bot[np.lexsort((X[bot, 1], X[bot, 0]))], top[np.lexsort((X[top, 1], X[top, 0]))]
        mid, fibre = 0.5 * (x[bot] + x[top]), (x[top] - x[bot])[-1]
        phi = math.atan2(-fibre[0], fibre[2])
        e = mid[-1]
        rho = (e[0] ** 2 + (e[2] - 0.05) ** 2) / (2.0 * (e[2] - 0.05))
        dev = float(np.abs(np.hypot(mid[:, 0], mid[:, 2] - 0.05 - rho) - rho).max() / rho)
        out[f"couple {cell} {nx}"] = (phi, dev)
        print(f"| {cell} | {nx}x1 | {phi:.5f} | {dev:.1e} | {res.summary['total_iterations']} |")

    print("\nSlit annular plate (Sze 3.3), W_A, W_B at the full load (reference 13.891, 17.528), 20 steps:\n")
    print("| element | mesh | W_A | W_B | iterations | time (s) |\n|---|---|---|---|---|---|")
    for cell, m in (("hex8", (6, 30)), ("hex8", (10, 60)), ("hex18", (3, 15)), ("hex18", (6, 30))):
        prob, measure = nl.slit_annular_plate(*m, cell=cell, steps=20)
        res, dt = timed(nl.run, prob, TMP / "sa")
        wa, wb = measure(res.u)
        out[f"annulus {cell} {m}"] = (wa, wb, res.summary["total_iterations"])
        print(f"| {cell} | {m[0]}x{m[1]} | {wa:.3f} | {wb:.3f} | {res.summary['total_iterations']} | {dt:.1f} |")

    return out


def pullout() -> dict:
    out = {}
    print("\nPull-out of an open cylinder (Sze 3.5), 40 equal steps to P_max with line search (the shell snaps"
          " near P/Pmax = 0.5):\n")
    ref = {0.25: (2.180, 3.087, 3.310), 0.5: (2.473, 3.653, 3.718), 1.0: (2.768, 4.551, 3.269)}
    print("| element | mesh | P/Pmax | W_A | -U_B | -U_C | reference | iterations |\n|---|---|---|---|---|---|---|---|")
    for cell, m in (("hex8", (16, 12)), ("hex8", (24, 16)), ("hex18", (8, 6))):
        for frac, r in ref.items():
            steps = max(1, round(40 * frac))
            prob, measure = nl.pullout(*m, cell=cell, factors=[frac * (k + 1) / steps for k in range(steps)])
            prob.solver.line_search = True
            try:
                res = nl.run(prob, TMP / "po")
            except AssertionError as exc:
                print(f"| {cell} | {m[0]}x{m[1]} | {frac} | failed: {exc} | | | | |")
                continue
            v = measure(res.u)
            out[f"pullout {cell} {m} {frac}"] = (*v, res.summary["total_iterations"])
            print(f"| {cell} | {m[0]}x{m[1]} | {frac} | {v[0]:.3f} | {v[1]:.3f} | {v[2]:.3f} | "
                  f"{r[0]}, {r[1]}, {r[2]} | {res.summary['total_iterations']} |")
    return out


def main() -> None:
    parts = {"obstacle": obstacle, "eas": eas_study, "cost": cost, "nonlinear": nonlinear, "pullout": pullout}
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=list(parts), default=list(parts))
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    results = {name: parts[name]() for name in args.only}
    if args.out is not None:
        args.out.write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    main()
