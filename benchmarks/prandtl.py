"""Mesh convergence of Prandtl's flat punch: limit pressure (2 + pi) sigma_y / sqrt(3) on a J2 block.

The set-up and the measures are those of tests/verification/test_prandtl.py: the half block 5a x 5a, one
hex8 layer in plane strain, F-bar, J2 perfectly plastic (E = 1e4, sigma_y = 1, nu = 0.3), graded toward the
punch corner; a rigid meshed punch moved down by 0.0035 a in 14 steps; frictionless and rough (no slip
under the punch). Levels 0, 1, 2 (each halves every element; --levels to choose) and, with --stiffness, the
level-0 meshes at E / sigma_y = 1e3 (punch moved 10 times further) to show the finite-strain pile-up.

Per record: dofs, Newton iterations and cutbacks per step, wall time, the pressure per step, the plateau
(pressure at the last step) and its error against Prandtl's value. JSON on stdout or to --out, a Markdown
table on stderr.

    python benchmarks/prandtl.py --levels 0,1 --out prandtl.json
    python benchmarks/prandtl.py --out prandtl.json --stiffness
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from _report import emit
from test_prandtl import CASES, DELTA, P_PRANDTL, level_counts, pressures, prandtl_mesh, prandtl_problem


def one(level: int, case: str, e_over_sy: float = 1.0e4) -> dict:
    mesh = prandtl_mesh(level)
    delta = DELTA * 1.0e4 / e_over_sy
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = prandtl_problem(mesh, case, delta=delta, E_mod=e_over_sy).run(out=Path(tmp))
        wall = time.perf_counter() - t0
    m = pressures(res, delta=delta)
    n_p, n_o, n_z, h0 = level_counts(level)
    rec = {"level": level, "case": case, "E_over_sigma_y": e_over_sy, "elements": f"{n_p}+{n_o} x {n_z}",
           "h0_over_a": h0, "dofs": res.summary["dofs"], "converged": res.exit_code == 0,
           "iterations": m["iterations"], "cutbacks": m["cutbacks"], "wall_s": round(wall, 1),
           "delta_over_a": m["delta"].round(6).tolist(), "p_over_sigma_y": m["p"].round(5).tolist(),
           "plateau": round(m["plateau"], 4), "error": round(m["plateau"] / P_PRANDTL - 1.0, 4),
           "rise": round(m["rise"], 4), "corner_share": round(float(m["corner_share"][-1]), 4),
           "active_face": int(m["active_face"][-1])}
    print(f"level {level} {case} E/sy {e_over_sy:g}: {rec['dofs']} dofs, {rec['wall_s']} s, plateau "
          f"{rec['plateau']} ({rec['error']:+.2%})", file=sys.stderr, flush=True)
    return rec


def table(records: list[dict]) -> str:
    head = ("| level | elements (under + beyond x depth) | h0/a | dofs | case | E/sigma_y | plateau p/sigma_y"
            " | error | rise over the last 4 steps | Newton iterations (cutbacks) | time s |")
    rows = [head, "|" + "---|" * 11]
    for r in records:
        rows.append(f"| {r['level']} | {r['elements']} | 1/{round(1 / r['h0_over_a'])} | {r['dofs']}"
                    f" | {r['case']} | {r['E_over_sigma_y']:g} | {r['plateau']:.4f} | {r['error']:+.2%}"
                    f" | {r['rise']:.2%} | {sum(r['iterations'])} ({sum(r['cutbacks'])}) | {r['wall_s']} |")
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--levels", default="0,1,2", help="refinement levels, comma separated (default 0,1,2)")
    ap.add_argument("--stiffness", action="store_true", help="also level 0 at E / sigma_y = 1e3")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    records = [one(int(lv), case) for lv in args.levels.split(",") for case in CASES]
    if args.stiffness:
        records += [one(0, case, 1.0e3) for case in CASES]
    result = {"benchmark": "prandtl", "date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "machine": platform.machine(), "total_s": round(time.perf_counter() - t0, 1),
              "p_prandtl": P_PRANDTL, "records": records}
    emit(result, args.out, table(records))
    return 0 if all(r["converged"] for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
