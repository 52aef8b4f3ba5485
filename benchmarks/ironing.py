"""Ironing (Puso & Laursen 2004, example 2): a rigid cylindrical die pressed 1.4 into a Neo-Hookean slab and slid 4.

The set-up is that of tests/verification/test_ironing.py at full size: slab 9 x 4 x 3 (the half y >= 0
modelled, u_y = 0 on y = 0), E = 1, nu = 0.3, bottom fixed; rigid die of radius 3 (axis along y) centred 2.5
from the slab's left end, down by 1.4 over the pseudo time 0 to 0.2, then along +x by 4 up to 1.5; Coulomb
friction mu = 0.3, area-weighted penalties eps_N (normal) and eps_T = eps_N / 10 (tangential). Runs: hex8
slab meshes 18 x 2 x 6 and 36 x 4 x 12 elements (element size 0.5, 0.25), frictionless on the finer mesh,
and eps_N = 30 on the finer mesh. (54 x 6 x 18 stalls near the end of the press, at a depth of 1.36 to
1.38: docs/verification.md, "Ironing".)

Per run: the die force history of the whole slab (Fx the drag along the sliding, Fz the pressing force)
against the pseudo time, the force balance, and the peak and plateau values (means over the die moved 2
to 4). Output: JSON (histories and summary) on stdout or to --out, a Markdown table on stderr, and with
--plot the history figure.

    python benchmarks/ironing.py --quick
    python benchmarks/ironing.py --out ironing.json --plot docs/img/ironing.png
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
from test_ironing import (
    EPS_N,
    EPS_T,
    MU,
    die_path,
    ironing_history,
    ironing_problem,
    ironing_summary,
    slab_mesh,
)

# (label, mesh divisions, mu, eps_N, press steps, slide steps)
FULL = [("18x2x6", (18, 2, 6), MU, EPS_N, 20, 80), ("36x4x12", (36, 4, 12), MU, EPS_N, 20, 80),
        ("36x4x12 frictionless", (36, 4, 12), 0.0, EPS_N, 20, 80),
        ("36x4x12 eps_N=30", (36, 4, 12), MU, 3.0 * EPS_N, 20, 80)]
QUICK = [FULL[0], ("18x2x6 frictionless", (18, 2, 6), 0.0, EPS_N, 20, 80)]


def one(label: str, div: tuple[int, int, int], mu: float, eps_n: float, n_press: int, n_slide: int) -> dict:
    motion = die_path()
    prob = ironing_problem(slab_mesh(*div), mu, n_press, n_slide, eps_n, motion,
                           tangential_penalty=EPS_T * eps_n / EPS_N)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        res = prob.run(out=Path(tmp))
        wall = time.perf_counter() - t0
    hist = ironing_history(res.summary, motion)
    rec = {"label": label, "divisions": list(div), "mu": mu, "eps_N": eps_n, "eps_T": EPS_T * eps_n / EPS_N,
           "steps": n_press + n_slide, "dofs": res.summary["dofs"], "converged": res.exit_code == 0,
           "iterations": res.summary["total_iterations"],
           "cutbacks": int(sum(s["cutbacks"] for s in res.summary["steps"])), "wall_s": round(wall, 1),
           "balance_max": float(max(h["balance"] for h in hist)), "history": hist}
    if rec["converged"]:
        rec["summary"] = ironing_summary(hist)
    print(f"{label}: {rec['dofs']} dofs, {rec['wall_s']} s, {rec['iterations']} iterations, "
          f"{rec['cutbacks']} cutbacks, {rec.get('summary')}", file=sys.stderr, flush=True)
    return rec


def table(records: list[dict]) -> str:
    rows = [("| run | dofs | Fz at press end | Fz max | Fx max | Fz plateau | Fx plateau | Fx/Fz plateau "
            "| Newton iterations (cutbacks) | time s |"), "|" + "---|" * 10]
    for r in records:
        s = r.get("summary")
        if s is None:
            rows.append(f"| {r['label']} | {r['dofs']} | failed | | | | | | {r['iterations']} ({r['cutbacks']})"
                        f" | {r['wall_s']} |")
            continue
        lo, hi = s["ratio_range"]
        rows.append(f"| {r['label']} | {r['dofs']} | {s['Fz_press']:.3f} | {s['Fz_max']:.3f} | {s['Fx_max']:.3f}"
                    f" | {s['Fz_plateau']:.3f} | {s['Fx_plateau']:.3f} | {s['ratio_plateau']:.3f}"
                    f" ({lo:.3f} to {hi:.3f}) | {r['iterations']} ({r['cutbacks']}) | {r['wall_s']} |")
    return "\n".join(rows)


def plot(records: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, r in enumerate(records):
        t = [h["t"] for h in r["history"]]
        style = "--" if r["mu"] == 0.0 else "-"
        color = f"C{k}"
        ax.plot(t, [h["Fz"] for h in r["history"]], style, color=color, label=f"Fz {r['label']}")
        ax.plot(t, [h["Fx"] for h in r["history"]], style, color=color, alpha=0.6, lw=1.0,
                label=f"Fx {r['label']}")
    ax.axvline(0.2, color="k", lw=0.6, ls=":")
    ax.set_xlabel("pseudo time (press 0 to 0.2, slide 0.2 to 1.5)")
    ax.set_ylabel("die force on the slab (whole slab)")
    ax.set_title("Ironing: rigid die R = 3, depth 1.4, slide 4, Neo-Hooke E = 1, nu = 0.3")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="the 18 x 2 x 6 mesh with and without friction")
    ap.add_argument("--out", type=Path, help="JSON file (default: stdout)")
    ap.add_argument("--plot", type=Path, help="PNG of the die force histories")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    records = [one(*case) for case in (QUICK if args.quick else FULL)]
    result = {"benchmark": "ironing", "date": time.strftime("%Y-%m-%d"), "python": platform.python_version(),
              "machine": platform.machine(), "total_s": round(time.perf_counter() - t0, 1), "records": records}
    emit(result, args.out, table(records))
    if args.plot:
        plot(records, args.plot)
    return 0 if all(r["converged"] for r in records) else 1


if __name__ == "__main__":
    sys.exit(main())
