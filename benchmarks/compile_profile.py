"""Where numba's compile time goes: the warm-up problems of ``covcontact compile`` in one process with an empty
kernel cache, numba's compile events recorded per kernel (the time of its compilation, inclusive and exclusive of
the kernels first compiled inside it, and how many versions were compiled). Writes JSON; prints the costliest
kernels to stderr.

    python benchmarks/compile_profile.py --out compile.json             # all ten warm-up problems (minutes)
    python benchmarks/compile_profile.py --only "F-bar" --top 20        # the problems whose label contains TEXT
    python benchmarks/compile_profile.py --problem examples/contact/two_blocks.toml   # one problem file's run

"Exclusive" still contains the optimisation of the code a kernel calls: numba links every called kernel into the
caller's module and optimises it there again (docs/performance.md, "Less to compile").
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time

from _report import emit

_CHILD = "COVCONTACT_COMPILE_PROFILE_CHILD"


def profile(only: str | None, problem: str | None = None) -> dict:
    from numba.core import event

    rec = event.RecordingListener()
    event.register("numba:compile", rec)
    t0 = time.perf_counter()
    if problem:
        from covcontact.io.loader import load_problem

        with tempfile.TemporaryDirectory() as out:
            load_problem(problem).run(out=out, quiet=True)
        problems = [(problem, time.perf_counter() - t0)]
    else:
        from covcontact import warmup

        problems = warmup.warm(quiet=True, only=only)
    total = time.perf_counter() - t0
    stack: list[list] = []
    kernels: dict[str, dict] = {}
    for ts, e in rec.buffer:
        d = e.data.get("dispatcher") if e.data else None
        name = f"{d.py_func.__module__}.{d.py_func.__qualname__}" if d is not None else str(e.data)
        if e.is_start:
            stack.append([name, ts, 0.0])
            continue
        name, start, nested = stack.pop()
        k = kernels.setdefault(name, {"kernel": name, "exclusive_s": 0.0, "inclusive_s": 0.0, "compiles": 0})
        k["inclusive_s"] += ts - start
        k["exclusive_s"] += ts - start - nested
        k["compiles"] += 1
        if stack:
            stack[-1][2] += ts - start
    rows = sorted(kernels.values(), key=lambda r: -r["exclusive_s"])
    return {"benchmark": "compile_profile", "total_s": total, "compile_s": sum(r["exclusive_s"] for r in rows),
            "problems": [{"label": lab, "seconds": s} for lab, s in problems], "kernels": rows,
            "date": time.strftime("%Y-%m-%d"), "cpus": os.cpu_count()}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None, help="write the JSON here (default: stdout)")
    ap.add_argument("--only", default=None, help="only the warm-up problems whose label contains TEXT")
    ap.add_argument("--problem", default=None, help="profile this problem file's run instead of the warm-up")
    ap.add_argument("--top", type=int, default=30, help="how many kernels to print to stderr")
    args = ap.parse_args()
    if not os.environ.get(_CHILD):  # numba reads its cache folder at import: a child process with an empty one
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache, COVCONTACT_KEEP_KERNEL_CACHE="1", **{_CHILD: "1"})
            return subprocess.run([sys.executable, *sys.argv], env=env, check=False).returncode
    out = profile(args.only, args.problem)
    lines = [f"total {out['total_s']:.1f} s, compiling {out['compile_s']:.1f} s; exclusive / inclusive s, versions:"]
    lines += [f"{r['exclusive_s']:8.1f} {r['inclusive_s']:8.1f} {r['compiles']:3d}  {r['kernel']}"
              for r in out["kernels"][: args.top]]
    emit(out, args.out, "\n".join(lines))
    return 0

if __name__ == "__main__":
    sys.exit(main())
