"""Necking of a circular bar (Simo 1988; Simo & Armero 1992) under mesh refinement: force-elongation curve,
peak force against Considere's closed form, neck radius ratio at 14 mm. Writes JSON.

    python benchmarks/necking.py --out necking.json
    python benchmarks/necking.py --meshes 3x8,4x12 --steps 28
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from _report import emit

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "verification"))
from necking_setup import IMPERFECTION, RADIUS, considere_peak, necking_problem, results


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="3x8,4x12,6x16,8x24",
                    help="n x nz per run: n x n elements over the quarter section, nz along the half length")
    ap.add_argument("--steps", type=int, default=56, help="equal load steps to 14 mm")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    rows = []
    for spec in args.meshes.split(","):
        n, nz = (int(v) for v in spec.split("x"))
        problem = necking_problem(n, nz, args.steps)
        t0 = time.perf_counter()
        with tempfile.TemporaryDirectory() as out:
            res = problem.run(out=out, quiet=True)
        r = results(problem, res)
        r.update(mesh=spec, elements=n * n * nz, exit_code=res.exit_code, wall_s=round(time.perf_counter() - t0, 1))
        rows.append(r)
    ref = {"considere_peak_thinnest_N": considere_peak(IMPERFECTION * RADIUS),
           "considere_peak_nominal_N": considere_peak(RADIUS)}
    table = "\n".join(f"{r['mesh']:>6} {r['elements']:5d} el  peak {r['peak_force'] / 1e3:7.2f} kN at "
                      f"{r['peak_elongation']:.2f} mm ({r['peak_force'] / ref['considere_peak_thinnest_N'] - 1:+.2%})"
                      f"  neck ratio {r['neck_ratio']:.4f}  end {r['end_ratio']:.4f}  F(14) "
                      f"{r['force'][-1] / 1e3:6.2f} kN  {r['iterations']} it  {r['wall_s']} s" for r in rows)
    emit({"reference": ref, "steps": args.steps, "runs": rows}, args.out, table)


if __name__ == "__main__":
    main()
