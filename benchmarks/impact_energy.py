"""What the dynamic defaults cost and what they keep: the steel bar hitting a rigid wall flat
(tests/verification/test_bar_impact.py ``STEEL``: 40 hex8, 130 steps) and the block dropped on a deformable floor
under gravity (tests/verification/test_bounce_and_drop.py ``DROP``: 150 steps) with the default mass ("auto", the
consistent redistributed mass where there is contact) against the redistributed lumped mass and the consistent mass
(the default before), each a whole ``covcontact run`` process, alternating, ``--repeats`` times. Per problem and
variant: median wall time, Newton iterations and factorisations per step, the contact's status changes, whether
the run said that the energy grew, and for the bar the kinetic energy after the impact over before (mean over the
steps after the release; exact 1).

    python benchmarks/impact_energy.py --out impact_energy.json [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _report import emit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from test_bar_impact import STEEL  # noqa: E402
from test_bounce_and_drop import DROP  # noqa: E402

E0 = 0.5 * 8000.0 * 0.2 * 1e-4 * 10.0 ** 2  # the bar's kinetic energy before the impact
VARIANTS = {"auto (default)": "", "redistributed": 'mass = "redistributed"\n', "consistent": 'mass = "consistent"\n'}


PROBLEMS = {"bar": STEEL, "drop": DROP}


def problem(folder: Path, which: str, name: str, extra: str) -> Path:
    path = folder / f"{which}-{name.split()[0]}.toml"
    text = PROBLEMS[which]
    path.write_text(text.replace('procedure = "dynamic"\n', 'procedure = "dynamic"\n' + extra, 1))
    return path


def measure(path: Path, out: Path) -> dict:
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(path), "--out", str(out), "--quiet"],
                          capture_output=True, text=True)
    wall = time.perf_counter() - t0
    s = json.loads((out / "summary.json").read_text())
    steps = s["steps"]
    active = [st["active_contacts"] > 0 for st in steps]
    last = max(i for i, a in enumerate(active) if a)
    after = [st["energy"]["kinetic"] / E0 for st in steps[last + 5:]] or [float("nan")]
    return {"wall_s": wall, "exit_code": proc.returncode, "steps": len(steps), "iterations": s["total_iterations"],
            "factorizations": sum(st["factorizations"] for st in steps),
            "status_changes": sum(a != b for a, b in zip(active, active[1:])),
            "kinetic_after": statistics.fmean(after), "mass": s.get("mass"), "energy_growth": "energy_growth" in s}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    keys = [(p, v) for p in PROBLEMS for v in VARIANTS]
    runs: dict[tuple, list[dict]] = {k: [] for k in keys}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        paths = {(p, v): problem(folder, p, v, VARIANTS[v]) for p, v in keys}
        measure(paths[keys[0]], folder / "warm")  # compiled kernels
        for r in range(args.repeats):
            for key, path in paths.items():
                runs[key].append(measure(path, folder / f"{path.stem}{r}"))
    out = {"problems": {"bar": "steel bar on a rigid wall, 40 hex8, 130 steps",
                        "drop": "block dropped on a deformable floor under gravity, 150 steps"},
           "repeats": args.repeats, "variants": {}}
    rows = ["| problem | mass | median wall s (ratio to redistributed) | Newton iterations per step | factorisations per "
            "step | status changes | kinetic energy after / before | energy growth said |",
            "|---|---|---|---|---|---|---|---|"]
    for (p, name), rs in runs.items():
        base = statistics.median(x["wall_s"] for x in runs[(p, "redistributed")])
        wall = statistics.median(x["wall_s"] for x in rs)
        first = rs[0]
        rec = {"median_wall_s": round(wall, 3), "ratio_to_redistributed": round(wall / base, 3),
               "steps": first["steps"], "iterations_per_step": round(first["iterations"] / first["steps"], 3),
               "factorizations_per_step": round(first["factorizations"] / first["steps"], 3),
               "status_changes": first["status_changes"],
               "kinetic_after": round(first["kinetic_after"], 4) if p == "bar" else None,
               "mass": first["mass"], "energy_growth": first["energy_growth"],
               "exit_codes": [x["exit_code"] for x in rs]}
        out["variants"][f"{p}: {name}"] = rec
        rows.append(f"| {p} | {name} | {rec['median_wall_s']} ({rec['ratio_to_redistributed']}) | "
                    f"{rec['iterations_per_step']} | {rec['factorizations_per_step']} | {rec['status_changes']} | "
                    f"{rec['kinetic_after'] if p == 'bar' else ''} | {'yes' if rec['energy_growth'] else 'no'} |")
    emit(out, args.out, "\n".join(rows))


if __name__ == "__main__":
    main()
