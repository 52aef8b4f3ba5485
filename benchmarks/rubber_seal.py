"""The cost of near incompressibility on a rubber seal: the O-ring of examples/contact/oring_groove.toml (axisymmetric,
Mooney-Rivlin, squeezed 25 % in its groove in 20 steps) with its bulk modulus from compressible to nearly
incompressible, on F-bar and plain quad4 cells, each a whole ``covcontact run`` one after the other: Newton iterations
per increment, cutbacks, the lid force at the end, wall time and wall time per Newton iteration.

The example's material is c10 = 0.8, c01 = 0.2 (mu0 = 2), d1 = 5e-4 (K0 / mu0 = 2000); the variants change d1
(K0 = 2 / d1) and the cells' F-bar option.

    python benchmarks/rubber_seal.py [--variants ...] [--solver "line_search = true; predictor = 'extrapolate'"]
                                     [--out rubber_seal.json]

``--solver`` gives every variant those ``[solver]`` keys (';' between them).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import emit, run_variant  # noqa: E402

PROBLEM = Path(__file__).resolve().parents[1] / "examples" / "contact" / "oring_groove.toml"
MU0 = 2.0
D1 = "d1 = 0.0005"


def _d1(ratio: float) -> list[tuple[str, str]]:
    return [(D1, f"d1 = {2.0 / (ratio * MU0)!r}")]


#: name -> (K0 / mu0, replacements)
VARIANTS = {
    "compressible (nu 0.3), F-bar": (2.0 * 1.3 / (3.0 * 0.4), _d1(2.0 * 1.3 / (3.0 * 0.4))),
    "K0/mu0 100, F-bar": (100.0, _d1(100.0)),
    "K0/mu0 2000, F-bar (the example)": (2000.0, []),
    "K0/mu0 1e4, F-bar": (1e4, _d1(1e4)),
    "K0/mu0 1e5, F-bar": (1e5, _d1(1e5)),
    "compressible (nu 0.3), plain quad4": (2.0 * 1.3 / (3.0 * 0.4),
                                           _d1(2.0 * 1.3 / (3.0 * 0.4)) + [("options = { fbar = true }\n", "")]),
    "K0/mu0 2000, plain quad4": (2000.0, [("options = { fbar = true }\n", "")]),
}


def run(name: str, work: Path, solver: str = "") -> dict:
    ratio, subs = VARIANTS[name]
    if solver:
        keys = "\n".join(k.strip() for k in solver.split(";") if k.strip())
        subs = subs + [("[steps]", f"[solver]\n{keys}\n\n[steps]")]
    key = f"v{list(VARIANTS).index(name)}"
    summary, wall, code = run_variant(PROBLEM, subs, work, key)
    steps = summary["steps"]
    n, its = len(steps), sum(s["iterations"] for s in steps)
    last = steps[-1] if steps else {}
    lid = last.get("contact_force_on", {}).get("lid", [0.0, 0.0])[1]
    return {"variant": name, "solver": solver, "K0_over_mu0": ratio, "exit_code": code, "status": summary["status"], "increments": n,
            "iterations": its, "per_increment": round(its / max(n, 1), 2),
            "cutbacks": sum(s.get("cutbacks", 0) for s in steps), "lid_force": lid, "wall_s": round(wall, 2),
            "ms_per_iteration": round(1e3 * summary.get("wall_time_s", wall) / max(its, 1), 2)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default=None, help="comma-separated indices into the list (default: all): "
                    + "; ".join(f"{k}: {v}" for k, v in enumerate(VARIANTS)))
    ap.add_argument("--solver", default="", help="[solver] keys for every variant, ';' between them")
    ap.add_argument("--out", default=None, help="JSON file (default: stdout)")
    args = ap.parse_args(argv)
    names = list(VARIANTS) if args.variants is None else [list(VARIANTS)[int(k)] for k in args.variants.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        rows = [run(v, Path(tmp), args.solver) for v in names]
    lines = ["| variant | status | increments | Newton iterations | per increment | cutbacks | lid force | wall s | "
             "ms per iteration |", "|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['variant']} | {r['status']} | {r['increments']} | {r['iterations']} | {r['per_increment']} | "
              f"{r['cutbacks']} | {r['lid_force']:.6g} | {r['wall_s']} | {r['ms_per_iteration']} |" for r in rows]
    emit({"problem": PROBLEM.name, "runs": rows}, args.out, "\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
