"""Mesh convergence of the plane-strain Hertz check: an elastic cylinder (E = 1, nu = 0.3, R = 1) on a rigid plane.

The set-up and the measures are those of tests/verification/test_hertz2d.py: the quarter of
``half_cylinder_solid`` graded toward its lowest line (grade_angle 4.5, grade_depth 4, nr = n/2), one element
along the axis with u_y = 0 on both end faces, u_x = 0 on x = 0, the flat face moved down by d with its
in-plane motion free, area-weighted penalty 1e4; 8 equal steps to d = 0.01 R. Meshes hex8 n = 16, 32, 64 and
hex27 n = 8, 16, 32 (each refinement halves every element), both materials.

Per record: dofs, Newton iterations, wall time, and per step P, b_m / b_Hertz(P), the pressure deviation
over x < b/2 (relative to p0) and p(0)/p0; the fits C1 (P = C1 b^2), C2 (P = C2 b^2 + B b^3) relative to
pi E* / (4 R), and the small-strain limit r0 of b_m / b_Hertz = r0 + r1 b/R. Output: JSON on stdout or to
--out, a Markdown table on stderr, and with --plot a figure (pressure profiles at d = 0.01 R and
b_m / b_Hertz against b/R).

    python benchmarks/hertz2d.py --quick
    python benchmarks/hertz2d.py --out hertz2d.json --plot docs/img/hertz2d.png
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from _report import emit
from test_hertz2d import D_MAX, R, hertz2d_measures, hertz2d_mesh, hertz2d_problem

FULL = [("hex8", 16), ("hex8", 32), ("hex8", 64), ("hex27", 8), ("hex27", 16), ("hex27", 32)]
QUICK = [("hex8", 16), ("hex8", 32), ("hex27", 8)]
MATERIALS = ("neo-hooke", "svk")


def one(cell: str, n: int, material: str) -> dict:
    mesh = hertz2d_mesh(n=n, cell=cell)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = hertz2d_problem(mesh, material).run(out=Path(tmp))
        wall = time.perf_counter() - t0
        m = hertz2d_measures(res, mesh)
    rec = {"cell": cell, "n": n, "material": material, "dofs": res.summary["dofs"],
           "converged": res.exit_code == 0, "iterations": res.summary["total_iterations"],
           "wall_s": round(wall, 1), "d": m["d"].tolist(), "P": m["P"].round(6).tolist(),
           "b_over_R": (m["b"] / R).round(5).tolist(), "b_ratio": m["b_ratio"].round(4).tolist(),
           "b_ratio_max_dev": round(float(np.max(np.abs(m["b_ratio"] - 1.0))), 4),
           "b_limit": round(m["b_limit"], 4), "b_slope": round(m["b_slope"], 3),
           "C1": round(m["C1"], 4), "C2": round(m["C2"], 4),
           "p_error": m["p_error"].round(4).tolist(), "p_error_max": round(float(np.max(m["p_error"])), 4),
           "p_center": m["p_center"].round(4).tolist(), "profile": m["profile"]}
    print(f"{cell} n={n} {material}: {rec['dofs']} dofs, {rec['wall_s']} s, b_limit {rec['b_limit']},"
          f" C1 {rec['C1']}", file=sys.stderr, flush=True)
    return rec


def table(records: list[dict]) -> str:
    rows = [("| mesh | material | dofs | b_m/b_Hertz at d/R = 0.00125 ... 0.01 | r0 (b -> 0) | C1 | C2 "
            "| max p error x < b/2 | p(0)/p0 | Newton iterations | time s |"), "|" + "---|" * 11]
    for r in records:
        ratios = " ".join(f"{v:.3f}" for v in r["b_ratio"])
        pc = f"{min(r['p_center']):.3f} to {max(r['p_center']):.3f}"
        rows.append(f"| {r['cell']} n={r['n']} | {r['material']} | {r['dofs']} | {ratios} | {r['b_limit']:.3f}"
                    f" | {r['C1']:.3f} | {r['C2']:.3f} | {r['p_error_max']:.3f} | {pc} | {r['iterations']}"
                    f" | {r['wall_s']} |")
    return "\n".join(rows)


def plot(records: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    xs = np.linspace(0.0, 1.0, 200)
    ax1.plot(xs, np.sqrt(1.0 - xs**2), "k-", lw=1.5, label="Hertz")
    marks = {"hex8": "o", "hex27": "s"}
    for r in records:
        if r["material"] != "neo-hooke":
            continue
        pr = r["profile"]
        x, p = np.asarray(pr["x_over_b"]), np.asarray(pr["p_over_p0"])
        keep = x < 1.4
        ax1.plot(x[keep], p[keep], marks[r["cell"]], ms=3, label=f"{r['cell']} n={r['n']}")
    ax1.set_xlabel("x / b (b from P)")
    ax1.set_ylabel("p / p0")
    ax1.set_title(f"Neo-Hooke, d = {D_MAX:g} R")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    for r in records:
        if r["cell"] == "hex8" and r["n"] == max(q["n"] for q in records if q["cell"] == "hex8"):
            b = np.asarray(r["b_over_R"])
            (line,) = ax2.plot(b, r["b_ratio"], "o-", label=f"{r['material']}, hex8 n={r['n']}")
            ax2.plot([0.0, b.max()], [r["b_limit"], r["b_limit"] + r["b_slope"] * b.max()], "--", lw=0.8,
                     color=line.get_color())
    ax2.axhline(1.0, color="k", lw=1.0)
    ax2.set_xlim(left=0.0)
    ax2.set_xlabel("b / R")
    ax2.set_ylabel("b_m / b_Hertz(P)")
    ax2.set_title("half-width against load (dashed: linear fit)")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="hex8 n = 16, 32 and hex27 n = 8 only")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    ap.add_argument("--plot", type=Path, help="PNG of the pressure profiles and the half-widths")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    records = [one(cell, n, material) for cell, n in (QUICK if args.quick else FULL) for material in MATERIALS]
    result = {"benchmark": "hertz2d", "date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "machine": platform.machine(), "total_s": round(time.perf_counter() - t0, 1),
              "d_over_R": records[0]["d"], "records": records}
    emit(result, args.out, table(records))
    if args.plot:
        plot(records, args.plot)
    return 0 if all(r["converged"] for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
