"""The seed paper's numerical study (Table 1): every example of examples/paper/, once per tangent case.

For each study ``covcontact study`` is run (cases a, b, c, d, exact; 100 load steps) into
``OUT/<study>/`` (table.md, table.csv, iterations.png, one result folder per case with its pictures), and
one JSON record is collected: per case the Newton iterations of every step, the total, the wall time, the
largest contribution norms eps of the rotational and curvature parts, and the last step's contact state.

Robustness variants (``--variants``) repeat the four rigid-slave examples with a second penalty (x 0.1) and
a second, finer mesh (plate and rigid body about 1.5 times finer in each direction), with the cases a, b, c
and d.

    python benchmarks/paper_study.py --out results/paper --json paper_study.json
    python benchmarks/paper_study.py --only sphere_q9 --cases a,d
    python benchmarks/paper_study.py --variants-only --json paper_variants.json
    python benchmarks/paper_study.py --report paper_study.json   # markdown tables of a JSON record
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "paper"
STUDIES = ("sphere_q9", "sphere_q4", "cylinder_q9", "cylinder_q4", "sphere_q9_analytic", "cylinder_q9_analytic")
CASES = ("a", "b", "c", "d", "exact")

# robustness variants: (study, variant name, {key path in the TOML: new value})
VARIANTS = (
    ("sphere_q9", "penalty-1e3", {"contact.0.penalty": 1.0e3}),
    ("sphere_q9", "mesh-fine", {"bodies.0.mesh.nx": 27, "bodies.0.mesh.ny": 12,
                                "rigid.0.mesh.n_phi": 72, "rigid.0.mesh.n_theta": 18}),
    ("sphere_q4", "penalty-1e3", {"contact.0.penalty": 1.0e3}),
    # 54 x 24 (the plain 1.5 x refinement) stops at step 86: a slave node rests on a facet edge (an edge
    # point, whose tangent ignores the point's motion along the edge) and Newton converges only linearly
    ("sphere_q4", "mesh-fine", {"bodies.0.mesh.nx": 48, "bodies.0.mesh.ny": 21,
                                "rigid.0.mesh.n_phi": 72, "rigid.0.mesh.n_theta": 18}),
    ("cylinder_q9", "penalty-1e3", {"contact.0.penalty": 1.0e3}),
    ("cylinder_q9", "mesh-fine", {"bodies.0.mesh.nx": 24, "bodies.0.mesh.ny": 6,
                                  "rigid.0.mesh.n_circ": 48, "rigid.0.mesh.n_len": 10}),
    ("cylinder_q4", "penalty-1e3", {"contact.0.penalty": 1.0e3}),
    ("cylinder_q4", "mesh-fine", {"bodies.0.mesh.nx": 48, "bodies.0.mesh.ny": 12,
                                  "rigid.0.mesh.n_circ": 48, "rigid.0.mesh.n_len": 10}),
)
VARIANT_CASES = ("a", "b", "c", "d")


def load_study(name: str, mods: dict | None = None):
    """The Problem of examples/paper/<name>.toml with ``mods`` applied to the raw TOML (validated)."""
    from covcontact.io.loader import problem_from_dict

    path = EXAMPLES / f"{name}.toml"
    raw = tomllib.loads(path.read_text())
    for key, value in (mods or {}).items():
        *parents, last = key.split(".")
        d = raw
        for p in parents:
            d = d[int(p)] if p.isdigit() else d[p]
        d[last] = value
    return problem_from_dict(raw, path)


def case_record(summary: dict) -> dict:
    steps = summary["steps"]
    eps = [s.get("contribution_percent", {}) for s in steps]
    last = steps[-1] if steps else {}
    return {
        "converged": summary["converged"],
        "total_iterations": summary["total_iterations"],
        "wall_time_s": round(summary["wall_time_s"], 2),
        "dofs": summary["dofs"],
        "iterations": [s["iterations"] for s in steps],
        "cutbacks": sum(s.get("cutbacks", 0) for s in steps),
        "eps_rotational_max": max((e.get("rotational", 0.0) for e in eps), default=0.0),
        "eps_curvature_max": max((e.get("curvature", 0.0) for e in eps), default=0.0),
        "eps_rotational": [e.get("rotational", 0.0) for e in eps],
        "eps_curvature": [e.get("curvature", 0.0) for e in eps],
        "active_contacts_last": last.get("active_contacts"),
        "min_gap_last": last.get("min_gap"),
        "contact_force_last": last.get("contact_force"),
        "timing": summary.get("timing", {}),
    }


def run_one(name: str, cases: list[str], out: Path, mods: dict | None = None, label: str = "") -> dict:
    from covcontact.study import run_study

    problem = load_study(name, mods)
    if mods:
        problem.output.pictures = False
        problem.output.every = 100
    folder = out / (name + (f"-{label}" if label else ""))
    t0 = time.perf_counter()
    code = run_study(problem, cases, folder, quiet=True)
    wall = time.perf_counter() - t0
    rec = {"study": name, "variant": label or "main", "modifications": mods or {}, "problem": problem.name,
           "steps": len(problem.steps.factors), "exit_code": code, "wall_time_s": round(wall, 2),
           "folder": str(folder), "cases": {}}
    for case in cases:
        summary = json.loads((folder / case / "summary.json").read_text())
        rec["cases"][case] = case_record(summary)
    totals = ", ".join(f"{c} {r['total_iterations']} ({r['wall_time_s']:.0f} s)" for c, r in rec["cases"].items())
    print(f"{name} {label or 'main'}: {totals}; loadavg {os.getloadavg()[0]:.1f}", file=sys.stderr, flush=True)
    return rec


def _ranges(iterations: list[int], eps: list[float]) -> list[tuple[str, int, int, float]]:
    """(load-step range, iterations, cumulative, largest eps in the range): the paper's Table 1 rows."""
    from covcontact.study import step_ranges

    steps = [{"step": k + 1, "iterations": n, "converged": True, "contribution_percent": {"rotational": e}}
             for k, (n, e) in enumerate(zip(iterations, eps))]
    return [(str(r["first"]) if r["first"] == r["last"] else f"{r['first']}-{r['last']}", r["iterations"],
             r["cumulative"], r["eps_rot_max"]) for r in step_ranges(steps)]


def table1(rec: dict, cases: tuple[str, ...] = ("a", "b", "d")) -> str:
    """One study in the layout of the paper's Table 1: per case the step ranges, iterations, cumulative;
    for case a also the largest eps of the rotational part in the range (percent)."""
    cols = {c: _ranges(rec["cases"][c]["iterations"], rec["cases"][c]["eps_rotational"])
            for c in cases if c in rec["cases"]}
    head, rule = [], []
    for c in cols:
        head += [f"{c}: steps", "No.", "Cum."] + (["eps rot. %"] if c == "a" else [])
        rule += ["---"] * (4 if c == "a" else 3)
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(rule) + "|"]
    for i in range(max(len(v) for v in cols.values())):
        row = []
        for c, v in cols.items():
            if i < len(v):
                row += [v[i][0], str(v[i][1]), str(v[i][2])] + ([f"{v[i][3]:.3g}"] if c == "a" else [])
            else:
                row += [""] * (4 if c == "a" else 3)
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def summary_table(record: dict) -> str:
    """Totals per study and case, the largest eps, and the wall time per case."""
    lines = [("| study | variant | dofs | a | b | c | d | exact | eps rot. max % | eps curv. max % | "
              "wall time per case, s (a / b / c / d / exact) |"), "|" + "---|" * 11]
    for rec in record["studies"]:
        cs = rec["cases"]
        tot = [str(cs[c]["total_iterations"]) + ("" if cs[c]["converged"] else " (failed)") if c in cs else "-"
               for c in CASES]
        a = cs.get("a") or next(iter(cs.values()))
        walls = " / ".join(f"{cs[c]['wall_time_s']:.0f}" if c in cs else "-" for c in CASES)
        lines.append(f"| {rec['study']} | {rec['variant']} | {a['dofs']} | " + " | ".join(tot) +
                     f" | {a['eps_rotational_max']:.3g} | {a['eps_curvature_max']:.3g} | {walls} |")
    return "\n".join(lines)


def report(record: dict) -> str:
    parts = ["## Totals", "", summary_table(record), ""]
    for rec in record["studies"]:
        if rec["variant"] == "main":
            parts += [f"## {rec['study']} ({rec['problem']})", "", table1(rec), ""]
    return "\n".join(parts)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="comma separated studies, from " + ", ".join(STUDIES))
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--variants", action="store_true", help="also the robustness variants")
    ap.add_argument("--variants-only", action="store_true", help="only the robustness variants")
    ap.add_argument("--out", default="results/paper", help="result folders")
    ap.add_argument("--json", help="write the JSON record here (default: OUT/paper_study.json)")
    ap.add_argument("--report", nargs="+", metavar="JSON", help="print markdown tables of JSON records")
    args = ap.parse_args(argv)
    if args.report:
        merged = {"studies": [rec for path in args.report for rec in json.loads(Path(path).read_text())["studies"]]}
        print(report(merged))
        return 0
    from numba import get_num_threads

    from covcontact import __version__

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    only = args.only.split(",") if args.only else list(STUDIES)
    unknown = [s for s in only if s not in STUDIES]
    if unknown:
        ap.error(f"unknown studies: {', '.join(unknown)}")
    cases = args.cases.split(",")
    record = {"benchmark": "paper_study", "covcontact": __version__, "python": platform.python_version(),
              "machine": platform.machine(), "cpus": os.cpu_count(), "numba_threads": get_num_threads(),
              "started": time.strftime("%Y-%m-%dT%H:%M:%S"), "studies": []}
    json_path = Path(args.json) if args.json else out / "paper_study.json"

    def save() -> None:
        tmp = json_path.with_name("." + json_path.name + ".tmp")
        tmp.write_text(json.dumps(record, indent=1) + "\n")
        tmp.replace(json_path)

    if not args.variants_only:
        for name in only:
            record["studies"].append(run_one(name, cases, out))
            save()
    if args.variants or args.variants_only:
        for name, label, mods in VARIANTS:
            if name in only:
                record["studies"].append(run_one(name, list(VARIANT_CASES), out, mods, label))
                save()
    save()
    print(f"JSON in {json_path}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
