"""The geometrically nonlinear shell benchmarks of Sze, Liu & Lo (2004) at every tabulated load level.

Runs the solid-shell set-ups of tests/verification/test_shell_nonlinear.py (3.1 cantilever under end shear, 3.2 the
strip rolled into a circle by a follower end moment, 3.3 slit annular plate, 3.5 pull-out of an open cylinder) with
results written at each load fraction of the published tables (tests/verification/sze2004.py), and compares. The
error of a curve is the largest |value - reference| over its points divided by the largest reference value of that
curve (the tabulated values pass through zero, where a relative error means nothing). Prints a markdown table and
writes JSON with --out.

    python benchmarks/sze_curves.py                    # every problem and mesh (several minutes on 2 cores)
    python benchmarks/sze_curves.py --only 3.1 3.2 --out sze.json
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

import sze2004 as ref  # noqa: E402
import test_shell_nonlinear as nl  # noqa: E402


TMP = Path(tempfile.mkdtemp(prefix="sze-"))


def _case(name: str, cell: str, mesh):
    """(problem, measure, table, load fractions to run) of one benchmark and mesh."""
    if name == "3.1":
        prob, measure = nl.cantilever_shear(mesh[0], cell)
        return prob, measure, ref.CANTILEVER_SHEAR
    if name == "3.2":
        prob, measure = nl.end_moment(mesh[0])
        return prob, measure, {k / 20: nl.strip_circle(k / 20) for k in range(1, 21)}
    if name == "3.3":
        prob, measure = nl.slit_annular_plate(*mesh, cell=cell)
        return prob, measure, ref.SLIT_ANNULUS
    prob, measure = nl.pullout(*mesh, cell=cell)
    prob.solver.line_search = True
    return prob, measure, ref.PULLOUT


def curve(name: str, cell: str, mesh, per_point: int) -> dict:
    """Run one benchmark with ``per_point`` equal steps between tabulated fractions; the values at each."""
    prob, measure, table = _case(name, cell, mesh)
    t0 = time.perf_counter()
    got, want, res = nl.run_curve(prob, measure, table, TMP / f"{name}-{cell}-{'x'.join(map(str, mesh))}", per_point)
    seconds = time.perf_counter() - t0
    err = nl.curve_error(got, want).tolist() if len(got) else []
    return {"points": len(got), "of": len(table), "error": err, "worst": max(err) if err else float("nan"),
            "iterations": res.summary["total_iterations"], "seconds": seconds, "exit_code": res.exit_code,
            "values": got.tolist(), "reference": want.tolist()}


CASES = {
    "3.1": [("hex8", (16,)), ("hex8", (32,)), ("hex18", (8,))],
    "3.2": [("hex8", (16,)), ("hex8", (32,)), ("hex8", (64,))],
    "3.3": [("hex8", (6, 30)), ("hex8", (10, 60)), ("hex18", (6, 30))],
    "3.5": [("hex8", (16, 12)), ("hex8", (24, 16)), ("hex18", (8, 6))],
}
COLUMNS = {"3.1": "-U, W", "3.2": "-U, W", "3.3": "W_A, W_B", "3.5": "W_A, -U_B, -U_C"}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=list(CASES), default=list(CASES))
    ap.add_argument("--per-point", type=int, default=1, help="equal steps between tabulated load fractions")
    ap.add_argument("--out", type=Path, default=None)
    args = ap.parse_args()
    results = {}
    print("| problem | element | mesh | points | error per curve (of the largest value) | iterations | time (s) |")
    print("|---|---|---|---|---|---|---|")
    for name in args.only:
        for cell, mesh in CASES[name]:
            r = curve(name, cell, mesh, args.per_point)
            results[f"{name} {cell} {'x'.join(map(str, mesh))}"] = r
            errs = " / ".join(f"{100 * e:.2f} %" for e in r["error"])
            print(f"| {name} ({COLUMNS[name]}) | {cell} | {'x'.join(map(str, mesh))} | {r['points']} of {r['of']} | "
                  f"{errs} | {r['iterations']} | {r['seconds']:.1f} |", flush=True)
    if args.out is not None:
        args.out.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
