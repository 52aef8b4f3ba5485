"""The predictor of each step (``[solver] predictor``): Newton iterations, cutbacks and wall time of whole
runs of the path-dependent example problems (plastic or frictional) with ``"tangent"`` and with
``"extrapolate"`` (what the default ``"auto"`` chooses for them), plus ironing (benchmarks/ironing.py's
18 x 2 x 6 slab). Runs one after the other in this process, each problem compiled beforehand by an untimed
run; the seconds are ``problem.run``'s (summary.json ``wall_time_s``).

    python benchmarks/predictors.py --out predictors.json
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from _report import emit, run_record, runs_table

from covcontact.io.loader import load_problem

FILES = ("examples/friction/block_sliding.toml", "examples/plasticity/prandtl_punch.toml",
         "examples/plasticity/sphere_indentation.toml", "examples/plasticity/bend_and_release.toml",
         "examples/forming/wrap_and_release.toml")


def _ironing():
    from test_ironing import ironing_problem, slab_mesh

    return ironing_problem(slab_mesh(18, 2, 6))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="JSON output file (default: stdout)")
    args = ap.parse_args()
    makers = {Path(f).stem: (lambda f=f: load_problem(ROOT / f)) for f in FILES}
    makers["ironing"] = _ironing
    rows = []
    for name, make in makers.items():
        make().run(out=Path(tempfile.mkdtemp()))  # compile (untimed)
        for pred in ("tangent", "extrapolate"):
            p = make()
            p.solver = replace(p.solver, predictor=pred)
            p.output = replace(p.output, vtu=False)
            with tempfile.TemporaryDirectory() as tmp:
                s = p.run(out=Path(tmp)).summary
            rows.append({"problem": name, "predictor": pred, **run_record(s)})
            print(rows[-1], file=sys.stderr)
    emit({"machine": platform.node(), "python": platform.python_version(), "runs": rows}, args.out,
         runs_table(rows, "predictor"))


if __name__ == "__main__":
    main()
