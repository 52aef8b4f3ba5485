"""Segment-to-surface on flat contact: the tube crushed flat (examples/contact/tube_crush.toml, whole with self-contact,
and tube_crush_half.toml) with every pair node-to-surface (as written), segment-to-surface on the points' gaps, and
segment-to-surface on the nodes' weighted gaps (``gap = "nodal"``, docs/theory.md section 16). Each variant a whole
``covcontact run`` (process start to exit), the variants of a problem alternating, ``--repeats`` rounds: increments,
Newton iterations, cutbacks, the plate force at travel 0.75, 0.9 and 0.975, median wall time and its ratio to
node-to-surface's. Writes JSON.

    python benchmarks/flat_contact.py [--problems tube_crush,tube_crush_half] [--repeats 2] [--out flat.json]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import emit, run_variant  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "contact"

#: variant -> replacements of the example's text (every pair is written with type = "nts")
VARIANTS = {
    "node-to-surface": [],
    "sts points": [('type = "nts"', 'type = "sts"')],
    "sts nodal gaps": [('type = "nts"', 'type = "sts"\ngap = "nodal"')],
}
TRAVELS = (0.75, 0.9, 1.0)


def record(summary: dict, wall: float, code: int) -> dict:
    steps = summary["steps"]
    force = {round(s["load_factor"], 9): s["contact_force_on"]["upper"][1] for s in steps if "contact_force_on" in s}
    return {"exit_code": code, "increments": len(steps), "iterations": sum(s["iterations"] for s in steps),
            "cutbacks": sum(s.get("cutbacks", 0) for s in steps), "wall_s": round(wall, 2),
            "plate_force": {str(t): force.get(t) for t in TRAVELS}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", default="tube_crush,tube_crush_half")
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--repeats", type=int, default=2, help="alternating rounds (the medians are reported)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    rows = []
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.problems.split(","):
            problem = EXAMPLES / f"{name}.toml"
            runs: dict[str, list[dict]] = {v: [] for v in args.variants.split(",")}
            for k in range(args.repeats):
                for v in runs:
                    work = Path(tmp) / f"{name}-{k}"
                    work.mkdir(exist_ok=True)
                    runs[v].append(record(*run_variant(problem, VARIANTS[v], work, v.replace(" ", "_"))))
            base = statistics.median(r["wall_s"] for r in runs[next(iter(runs))])
            for v, rs in runs.items():
                wall = statistics.median(r["wall_s"] for r in rs)
                row = dict(rs[0], problem=name, variant=v, wall_s=round(wall, 2), walls=[r["wall_s"] for r in rs],
                           ratio=round(wall / base, 2))
                rows.append(row)
                f = row["plate_force"]
                lines.append(f"{name:16s} {v:16s} {row['increments']:4d} incr {row['iterations']:5d} its "
                             f"{row['cutbacks']:2d} cutbacks {wall:7.1f} s (x{row['ratio']:.2f})  force "
                             + " / ".join(f"{f[str(t)]:.4g}" if f[str(t)] is not None else "-" for t in TRAVELS))
    emit({"problems": rows}, args.out, "\n".join(lines))


if __name__ == "__main__":
    main()
