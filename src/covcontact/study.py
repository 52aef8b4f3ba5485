"""``covcontact study``: one run per tangent case, tabulated in the layout of the paper's Table 1."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import numpy as np

from .io.output import atomic_write_text

CASE_TITLES = {"a": "a: main + rotational + curvature", "b": "b: main + rotational",
               "c": "c: main + curvature", "d": "d: main only", "exact": "exact Hessian"}


def step_ranges(steps: list[dict]) -> list[dict]:
    """Group consecutive converged steps with the same iteration count (the paper's 'No l.s.' column)."""
    rows: list[dict] = []
    cum = 0
    for s in steps:
        cum += s["iterations"]
        eps = s.get("contribution_percent", {})
        if rows and rows[-1]["iterations"] == s["iterations"] and rows[-1]["converged"] == s["converged"]:
            row = rows[-1]
            row["last"] = s["step"]
        else:
            row = {"first": s["step"], "last": s["step"], "iterations": s["iterations"],
                   "converged": s["converged"], "eps_rot_max": 0.0, "eps_curv_max": 0.0}
            rows.append(row)
        row["cumulative"] = cum
        row["eps_rot_max"] = max(row["eps_rot_max"], eps.get("rotational", 0.0))
        row["eps_curv_max"] = max(row["eps_curv_max"], eps.get("curvature", 0.0))
    return rows


def _fmt_range(r: dict) -> str:
    return str(r["first"]) if r["first"] == r["last"] else f"{r['first']}-{r['last']}"


def write_tables(results: dict[str, dict], out: Path, title: str) -> None:
    """table.md (ranges per case, Table 1 layout) and table.csv (every step of every case)."""
    lines = [f"# {title}", "",
             "Newton iterations per load step for each tangent case. Ranges group consecutive load steps with",
             "the same iteration count; eps is the paper's contribution norm ||K - K^(part)|| / ||K|| * 100 %",
             "of the rotational and the curvature part of the assembled contact tangent at the converged state",
             "(largest value in the range).", ""]
    for case, summary in results.items():
        lines += [f"## Case {CASE_TITLES.get(case, case)}", "",
                  f"total iterations {summary['total_iterations']}, converged {summary['converged']}, "
                  f"wall time {summary['wall_time_s']:.1f} s", "",
                  "| load steps | iterations | cumulative | eps rotational % | eps curvature % |",
                  "|---|---|---|---|---|"]
        for r in step_ranges(summary["steps"]):
            flag = "" if r["converged"] else " (failed)"
            lines.append(f"| {_fmt_range(r)}{flag} | {r['iterations']} | {r['cumulative']} | "
                         f"{r['eps_rot_max']:.4g} | {r['eps_curv_max']:.4g} |")
        lines.append("")
    atomic_write_text(out / "table.md", "\n".join(lines))
    csv = ["case,step,load_factor,iterations,cumulative,converged,cutbacks,eps_rotational,eps_curvature"]
    for case, summary in results.items():
        cum = 0
        for s in summary["steps"]:
            cum += s["iterations"]
            eps = s.get("contribution_percent", {})
            csv.append(f"{case},{s['step']},{s['load_factor']:.8g},{s['iterations']},{cum},"
                       f"{int(s['converged'])},{s['cutbacks']},{eps.get('rotational', '')},"
                       f"{eps.get('curvature', '')}")
    atomic_write_text(out / "table.csv", "\n".join(csv) + "\n")


_STYLES = [("o", "-"), ("s", "--"), ("^", "-."), ("D", ":"), ("v", (0, (5, 1, 1, 1))), ("x", (0, (1, 1)))]


def plot_iterations(results: dict[str, dict], path: Path, title: str) -> None:
    """Iterations per step and cumulative, one curve per case. Cases whose iteration counts coincide are
    drawn with their own marker and line style, slightly offset sideways, and the legend says which ones
    coincide (otherwise the later curve hides the earlier one)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    series = {case: [s["iterations"] for s in summary["steps"]] for case, summary in results.items()}
    cases = list(results)
    width = 0.12
    for k, (case, summary) in enumerate(results.items()):
        steps = np.array([s["step"] for s in summary["steps"]], dtype=float)
        its = series[case]
        cum = np.cumsum(its) if its else np.zeros(0)
        same = [c for c in cases if c != case and series[c] == its]
        note = f" = {', '.join(same)}" if same else ""
        marker, line = _STYLES[k % len(_STYLES)]
        shift = (k - (len(cases) - 1) / 2) * width if same else 0.0
        every = max(1, len(steps) // 25)
        ax1.step(steps + shift, its, where="mid", linestyle=line, marker=marker, markevery=every, markersize=4,
                 label=f"case {case}{note}")
        total = int(cum[-1]) if len(cum) else 0
        ax2.plot(steps + shift, cum, linestyle=line, marker=marker, markevery=every, markersize=4,
                 label=f"case {case} ({total}){note}")
    ax1.set_xlabel("load step")
    ax1.set_ylabel("Newton iterations")
    ax2.set_xlabel("load step")
    ax2.set_ylabel("cumulative iterations")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    tmp = path.with_name("." + path.name + ".tmp.png")
    fig.savefig(tmp, dpi=120)
    plt.close(fig)
    tmp.replace(path)


def run_study(problem, cases: list[str], out: Path, solver: str | None = None, quiet: bool = True) -> int:
    """Run ``problem`` once per case into ``out/<case>`` and write the tables and the plot."""
    out.mkdir(parents=True, exist_ok=True)
    results: dict[str, dict] = {}
    code = 0
    for case in cases:
        if not quiet:
            print(f"case {case}", file=sys.stderr, flush=True)
        prob = copy.copy(problem)
        res = prob.run(out=out / case, tangent=case, quiet=quiet, solver=solver)
        results[case] = res.summary
        code = max(code, res.exit_code)
    title = f"{problem.name}: influence of the tangent parts on convergence"
    write_tables(results, out, title)
    plot_iterations(results, out / "iterations.png", title)
    if not quiet:
        print(f"study results in {out}", file=sys.stderr)
    return code
