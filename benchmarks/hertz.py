"""Mesh convergence of the Hertz check: an elastic half-ball (E = 1, nu = 0.3, R = 1) on a rigid plane.

The set-up, the pole-graded quarter mesh and the measures are those of tests/verification/test_hertz.py:
the quarter of ``hemisphere_solid`` (focus = 1, nr = n/2) graded toward the pole, symmetry planes, the
flat face moved down by d with its in-plane motion free, area-weighted penalty 1e4. For every mesh
(hex8 n = 16, 24, 32; hex27 n = 8, 12: each refinement scales every element by the same factor) and
both materials, the flat face is moved to d/R = 0.001, 0.002, 0.004, 0.006, 0.008, 0.01. A "baseline"
record repeats the first experiment: hex8 n = 12, focus = 0.12, ungraded, the flat face clamped.

Per record: dofs, Newton iterations, wall time, F / F_Hertz(d) per step, the one-term fit C1 of
F = C1 d^1.5 and the two-term fit (C2, B) of F = C2 d^1.5 + B d^2 (C relative to 4/3 E* sqrt(R)), the
contact radius from the nodal forces over sqrt(R d), and the largest deviation of the contact pressure
from Hertz's p(r) over r < a/2 (relative to p0). Output: JSON on stdout or to --out; a Markdown table
on stderr.

    python benchmarks/hertz.py --quick
    python benchmarks/hertz.py --out hertz.json
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
from hertz_setup import (
    hertz_measures,
    hertz_mesh,
    hertz_problem,
    quarter,
)

from covcontact.mesh import hemisphere_solid

FACTORS = (0.1, 0.2, 0.4, 0.6, 0.8, 1.0)
FULL = [("hex8", 16, ("svk", "neo-hooke")), ("hex8", 24, ("svk", "neo-hooke")), ("hex8", 32, ("neo-hooke",)),
        ("hex27", 8, ("svk", "neo-hooke")), ("hex27", 12, ("svk", "neo-hooke"))]
QUICK = [("hex8", 16, ("svk", "neo-hooke")), ("hex27", 8, ("neo-hooke",))]


def one(mesh, material: str, label: dict, clamp: bool = False) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = hertz_problem(mesh, material, steps=FACTORS, clamp=clamp).run(out=Path(tmp))
        wall = time.perf_counter() - t0
        m = hertz_measures(res, mesh)
    small = m["d"] <= 0.004 + 1e-12
    rec = dict(label, material=material, clamp=clamp, dofs=res.summary["dofs"], converged=res.exit_code == 0,
               iterations=res.summary["total_iterations"], wall_s=round(wall, 1),
               d=m["d"].tolist(), ratio=m["ratio"].round(4).tolist(),
               C1=round(m["C1"], 4), C2=round(m["C2"], 4), B=round(m["B"], 4),
               ratio_max_d_le_0_004=round(float(np.max(np.abs(m["ratio"][small] - 1.0))), 4),
               ratio_max=round(float(np.max(np.abs(m["ratio"] - 1.0))), 4),
               a_ratio=m["a_ratio"].round(4).tolist(),
               a_error_max=round(float(np.max(np.abs(m["a_ratio"] - 1.0))), 4),
               p_center_error=m["p_center_error"].round(4).tolist(),
               p_center_error_max=round(float(np.max(m["p_center_error"])), 4))
    print(f"{label} {material}: {rec['dofs']} dofs, {rec['wall_s']} s, C1 {rec['C1']}, C2 {rec['C2']}",
          file=sys.stderr, flush=True)
    return rec


def table(records: list[dict]) -> str:
    head = ("| mesh | material | dofs | F/F_H at d/R = " + ", ".join(f"{f * 0.01:g}" for f in FACTORS)
            + " | C1 | C2 | max abs(a/sqrt(Rd) - 1) | max p error r < a/2 | iterations | time s |")
    rows = [head, "|" + "---|" * 10]
    for r in records:
        mesh = (f"{r['cell']} n={r['n']}" + (" graded" if r["graded"] else f" focus={r['focus']}")
                + (" clamped" if r["clamp"] else ""))
        ratios = " ".join(f"{v:.3f}" for v in r["ratio"])
        rows.append(f"| {mesh} | {r['material']} | {r['dofs']} | {ratios} | {r['C1']:.3f} | {r['C2']:.3f}"
                    f" | {r['a_error_max']:.3f} | {r['p_center_error_max']:.3f} | {r['iterations']}"
                    f" | {r['wall_s']} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="hex8 n = 16 and hex27 n = 8 only")
    ap.add_argument("--no-baseline", action="store_true", help="skip the ungraded, clamped first set-up")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    records = []
    if not args.no_baseline:
        mesh = quarter(hemisphere_solid(1.0, n=12, cell="hex8", focus=0.12))
        base = {"cell": "hex8", "n": 12, "nr": 6, "graded": False, "focus": 0.12}
        records.append(one(mesh, "neo-hooke", base, clamp=True))
    for cell, n, materials in QUICK if args.quick else FULL:
        mesh = hertz_mesh(n=n, nr=n // 2, cell=cell)
        for material in materials:
            label = {"cell": cell, "n": n, "nr": n // 2, "graded": True, "focus": 1.0}
            records.append(one(mesh, material, label))
    result = {"benchmark": "hertz", "date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "machine": platform.machine(), "total_s": round(time.perf_counter() - t0, 1),
              "d_over_R": [0.01 * f for f in FACTORS], "records": records}
    emit(result, args.out, table(records))
    return 0 if all(r["converged"] for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
