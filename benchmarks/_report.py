"""Shared output of the benchmark scripts: the JSON record to a file (or stdout), the table to stderr."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path


def emit(result: dict, out: Path | str | None, table: str) -> None:
    """Write ``result`` as JSON to ``out`` (stdout when None) and print ``table`` on stderr."""
    text = json.dumps(result, indent=1)
    if out:
        Path(out).write_text(text + "\n")
    else:
        print(text)
    print(table, file=sys.stderr)


def run_record(summary: dict) -> dict:
    """The figures of a whole run benchmarked by its summary.json: status, steps, Newton iterations, cutbacks
    and the seconds of the run."""
    steps = summary["steps"]
    return {"status": summary["status"], "steps": len(steps), "iterations": summary["total_iterations"],
            "cutbacks": sum(s["cutbacks"] for s in steps), "wall_s": round(summary["wall_time_s"], 2)}


def runs_table(rows: list[dict], key: str) -> str:
    """Markdown table of ``run_record`` rows of several problems, one column ``key`` telling the variants."""
    def cell(v):
        return f"{v:g}" if isinstance(v, float) else str(v)

    lines = [f"| problem | {key} | status | steps | Newton iterations | cutbacks | wall s |", "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['problem']} | {cell(r[key])} | {r['status']} | {r['steps']} | {r['iterations']} | {r['cutbacks']} | "
              f"{r['wall_s']} |" for r in rows]
    return "\n".join(lines)


def run_variant(problem: Path, replacements: list[tuple[str, str]], work: Path, name: str) -> tuple[dict, float, int]:
    """``covcontact run`` (a whole process) of ``problem`` with the text ``replacements`` (old, new) made, in ``work``:
    (its summary.json, the wall seconds, the exit code). A replacement whose old text is missing stops the script."""
    text = problem.read_text()
    for old, new in replacements:
        if old not in text:
            raise SystemExit(f"{Path(sys.argv[0]).name}: the variant {name!r} expects {old!r} in {problem}")
        text = text.replace(old, new)
    path = work / f"{name}.toml"
    path.write_text(text)
    out = work / name
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(path), "--out", str(out), "--quiet"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    return json.loads((out / "summary.json").read_text()), wall, proc.returncode
