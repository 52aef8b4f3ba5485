"""Forming as users write it: the V-bend of benchmarks/problems/vbend.toml and its variants, each a whole
``covcontact run`` one after the other: increments, Newton iterations (and how many of them went into attempts that
were given up and retried or cut back), iterations per increment, cutbacks, wall time.

Variants: as written (line search on, friction 0.1), without the line search, without friction, an elastic strip
(Neo-Hooke, frictionless), with the pairs' contact smoothing of 0.05 mm (docs/input.md, "Smoothed contact"), and with
the tangent predictor instead of the extrapolated start.

    python benchmarks/forming.py [--variants as-written,no-line-search] [--out forming.json]
"""

from __future__ import annotations

import argparse
import csv
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import emit, run_variant  # noqa: E402

PROBLEM = Path(__file__).resolve().parent / "problems" / "vbend.toml"

#: the variants: (old text, new text) replacements of the problem file
VARIANTS = {
    "as-written": [],
    "no-line-search": [("line_search = true", "line_search = false")],
    "no-friction": [("friction = 0.1", "friction = 0.0")],
    "elastic": [("friction = 0.1", "friction = 0.0"),
                ('material = { model = "j2", E = 210000.0, nu = 0.3, hardening = { law = "swift", K = 550.0, '
                 'eps0 = 0.01, n = 0.22 } }', 'material = { model = "neo-hooke", E = 210000.0, nu = 0.3 }'),
                ("thickness_points = 5", "thickness_points = 2")],
    "smoothing": [("friction = 0.1", "friction = 0.1\nsmoothing = 0.05")],
    "tangent-predictor": [("line_search = true", "line_search = true\npredictor = \"tangent\"")],
}


def attempts(path: Path) -> tuple[int, int]:
    """(iterations of attempts given up, steps with such attempts) from a run's convergence.csv."""
    per_step: dict[int, list[int]] = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            step, it = int(row["step"]), int(row["iteration"])
            if it == 0:
                per_step.setdefault(step, []).append(0)
            else:
                per_step[step][-1] = it
    return sum(sum(v[:-1]) for v in per_step.values()), sum(len(v) > 1 for v in per_step.values())


def run(name: str, work: Path) -> dict:
    summary, wall, code = run_variant(PROBLEM, VARIANTS[name], work, name)
    steps = summary["steps"]
    wasted, retried = attempts(work / name / "convergence.csv")
    n, its = len(steps), sum(s["iterations"] for s in steps)
    return {"variant": name, "exit_code": code, "status": summary["status"], "increments": n,
            "iterations": its, "per_increment": round(its / max(n, 1), 2), "given_up": wasted,
            "steps_retried": retried, "cutbacks": sum(s.get("cutbacks", 0) for s in steps), "wall_s": round(wall, 2)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", default=",".join(VARIANTS), help="comma-separated, of: " + ", ".join(VARIANTS))
    ap.add_argument("--out", default=None, help="JSON file (default: stdout)")
    args = ap.parse_args(argv)
    names = [v.strip() for v in args.variants.split(",") if v.strip()]
    bad = [v for v in names if v not in VARIANTS]
    if bad:
        ap.error(f"unknown variant {bad[0]!r} (one of {', '.join(VARIANTS)})")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [run(v, Path(tmp)) for v in names]
    lines = ["| variant | status | increments | Newton iterations | per increment | in attempts given up (steps) | "
             "cutbacks | wall s |", "|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['variant']} | {r['status']} | {r['increments']} | {r['iterations']} | {r['per_increment']} | "
              f"{r['given_up']} ({r['steps_retried']}) | {r['cutbacks']} | {r['wall_s']} |" for r in rows]
    emit({"problem": str(PROBLEM.name), "runs": rows}, args.out, "\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
