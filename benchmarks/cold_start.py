"""First run against warm run: how much of a new installation's first run is numba compiling.

Each problem runs as a whole process (``python -m covcontact run P --out TMP --quiet``) twice with the same,
initially empty, numba cache directory (NUMBA_CACHE_DIR): the first run compiles every kernel it meets and
writes the cache, the second loads it. With ``--compile-step`` a third, again empty, cache directory is
first filled by ``covcontact compile`` (timed) and then the problem runs once more: the first run of an
installation that ran the compile step (its stderr is checked for the compile notice). Then ``--kernels`` runs the first problem once more in-process with
a fresh cache and numba's compile events recorded: the compile time per kernel (inclusive of the kernels it
compiles on the way). With ``--install`` the README's two commands are timed as a new user meets them instead: a new
virtual environment, ``pip install ROOT[fast]`` in it (the build compiles the kernels into the wheel, setup.py;
``--install-no-compile`` sets COVCONTACT_COMPILE_AT_INSTALL=0 for the comparison), then each problem's first and
second run with that installation and no NUMBA_CACHE_DIR. Writes JSON.

    python benchmarks/cold_start.py --out cold_start.json
    python benchmarks/cold_start.py --compile-step --out cold_start.json
    python benchmarks/cold_start.py --problems examples/paper/sphere_q9.toml --kernels
    python benchmarks/cold_start.py --install --out cold_start_install.json
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _report import emit

ROOT = Path(__file__).resolve().parents[1]
PROBLEMS = [ROOT / "examples" / "paper" / "sphere_q9.toml", ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml"]


def timed_run(problem: Path | None, cache: str) -> tuple[float, int, str]:
    """Wall time, exit code and stderr of ``covcontact run problem`` (``covcontact compile`` for None)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    with tempfile.TemporaryDirectory() as out:
        cmd = ["compile"] if problem is None else ["run", str(problem), "--out", out, "--quiet"]
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "covcontact", *cmd], env=env, capture_output=True, text=True,
                              check=False)
        return time.perf_counter() - t0, proc.returncode, proc.stderr


def install_rows(problems: list[Path], compile_at_install: bool) -> list[dict]:
    """A new virtual environment, the package installed into it as the README says (timed), then each problem's
    first and second run there (the installation's own cache, no NUMBA_CACHE_DIR)."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    env["COVCONTACT_COMPILE_AT_INSTALL"] = "1" if compile_at_install else "0"
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        venv = Path(tmp) / "venv"
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
        py = str(venv / "bin" / "python")
        t0 = time.perf_counter()
        subprocess.run([py, "-m", "pip", "install", "-q", f"{ROOT}[fast]"], env=env, check=True, cwd=tmp)
        install = time.perf_counter() - t0
        for problem in problems:
            times, codes, notices = [], [], []
            for _ in range(2):
                with tempfile.TemporaryDirectory() as out:
                    t0 = time.perf_counter()
                    proc = subprocess.run([py, "-m", "covcontact", "run", str(problem), "--out", out, "--quiet"],
                                          env=env, cwd=tmp, capture_output=True, text=True, check=False)
                    times.append(time.perf_counter() - t0)
                    codes.append(proc.returncode)
                    notices.append("compiling" in proc.stderr)
            rows.append({"problem": str(problem.relative_to(ROOT)) if problem.is_relative_to(ROOT) else str(problem),
                         "compile_at_install": compile_at_install, "install_s": round(install, 1),
                         "first_run_s": round(times[0], 2), "warm_run_s": round(times[1], 2),
                         "ratio": round(times[0] / times[1], 2), "first_run_compiled": notices[0],
                         "exit_codes": codes})
            install = 0.0  # (the installation is timed once, on the first problem's row)
    return rows


def kernel_times(problem: Path) -> list[dict]:
    """Compile time per kernel of one run with an empty cache (benchmarks/compile_profile.py, a child process):
    seconds inclusive of the kernels first compiled inside it, exclusive_s without them."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "kernels.json"
        subprocess.run([sys.executable, str(Path(__file__).with_name("compile_profile.py")), "--problem", str(problem),
                        "--out", str(out), "--top", "0"], capture_output=True, text=True, check=True)
        rows = json.loads(out.read_text())["kernels"]
    return [{"kernel": r["kernel"], "seconds": round(r["inclusive_s"], 2), "exclusive_s": round(r["exclusive_s"], 2)}
            for r in sorted(rows, key=lambda r: -r["inclusive_s"])]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--problems", nargs="*", type=Path, default=PROBLEMS)
    ap.add_argument("--repeats", type=int, default=1, help="cold/warm pairs per problem (median reported)")
    ap.add_argument("--compile-step", action="store_true",
                    help="also time `covcontact compile` into an empty cache and the first run after it")
    ap.add_argument("--kernels", action="store_true", help="also the compile time per kernel (first problem)")
    ap.add_argument("--install", action="store_true",
                    help="time a new virtual environment's pip install and first runs instead (minutes, network)")
    ap.add_argument("--install-no-compile", action="store_true",
                    help="with --install: build without compiling the kernels (COVCONTACT_COMPILE_AT_INSTALL=0)")
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    if args.install:
        rows = install_rows(args.problems, not args.install_no_compile)
        table = "\n".join(f"{r['problem']:50s} install {r['install_s']:6.1f} s  first {r['first_run_s']:7.1f} s  "
                          f"warm {r['warm_run_s']:6.1f} s  ratio {r['ratio']:.2f}  compiled at first run: "
                          f"{r['first_run_compiled']}" for r in rows)
        emit({"python": platform.python_version(), "machine": platform.machine(), "install": rows}, args.out, table)
        return
    rows = []
    for problem in args.problems:
        cold, warm = [], []
        for _ in range(args.repeats):
            with tempfile.TemporaryDirectory() as cache:
                c, code_c, _ = timed_run(problem, cache)
                w, code_w, _ = timed_run(problem, cache)
            cold.append(c)
            warm.append(w)
        cold.sort()
        warm.sort()
        row = {"problem": str(problem.relative_to(ROOT)) if problem.is_relative_to(ROOT) else str(problem),
               "first_run_s": round(cold[len(cold) // 2], 2), "warm_run_s": round(warm[len(warm) // 2], 2),
               "exit_codes": [code_c, code_w]}
        row["ratio"] = round(row["first_run_s"] / row["warm_run_s"], 2)
        if args.compile_step:
            with tempfile.TemporaryDirectory() as cache:
                step, code_s, _ = timed_run(None, cache)
                after, code_a, err = timed_run(problem, cache)
            row.update(compile_step_s=round(step, 2), first_run_after_compile_s=round(after, 2),
                       ratio_after_compile=round(after / row["warm_run_s"], 2),
                       compiled_during_run="compiling" in err, exit_codes_compile=[code_s, code_a])
        rows.append(row)
    result = {"python": platform.python_version(), "machine": platform.machine(), "problems": rows}
    if args.kernels:
        result["kernels"] = kernel_times(args.problems[0])[:40]
    table = "\n".join(f"{r['problem']:50s} first {r['first_run_s']:7.1f} s  warm {r['warm_run_s']:6.1f} s  "
                      f"ratio {r['ratio']:.1f}" + (f"  compile step {r['compile_step_s']:.1f} s, then first run "
                                                   f"{r['first_run_after_compile_s']:.1f} s (ratio "
                                                   f"{r['ratio_after_compile']:.2f})" if "compile_step_s" in r else "")
                      for r in rows)
    emit(result, args.out, table)


if __name__ == "__main__":
    main()
