"""Contact smoothing (``[[contact]] smoothing``) on the forming and friction problems: Newton iterations,
cutbacks and wall time of whole runs, each problem without smoothing and with the given band widths.

Problems: the U-channel example (its own smoothing replaced), block sliding, the Prandtl punch, sphere
indentation, two blocks and ironing (the 18 x 2 x 6 slab of benchmarks/ironing.py). Every run is made once,
one after the other in this process (numba compiled beforehand by a first, untimed run of each problem);
the table gives the counts and the seconds of ``problem.run`` (summary.json ``wall_time_s``).

    python benchmarks/smoothing.py --out smoothing.json
    python benchmarks/smoothing.py --quick          # without the U-channel
"""

from __future__ import annotations

import argparse
import copy
import platform
import sys
import tempfile
import tomllib
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from _report import emit, run_record, runs_table

from covcontact.io.loader import problem_from_dict

#: problem file and the band widths to try (lengths of the problem's units)
FILES = {
    "uchannel": ("examples/forming/uchannel.toml", (0.01, 0.05)),
    "block_sliding": ("examples/friction/block_sliding.toml", (1e-4, 1e-3)),
    "prandtl_punch": ("examples/plasticity/prandtl_punch.toml", (1e-4, 1e-3)),
    "sphere_indentation": ("examples/plasticity/sphere_indentation.toml", (1e-3, 1e-2)),
    "two_blocks": ("examples/contact/two_blocks.toml", (1e-4, 1e-3)),
}


def _file_problem(path: str, band: float):
    raw = tomllib.loads((ROOT / path).read_text())
    raw = copy.deepcopy(raw)
    for c in raw.get("contact", []):
        c["smoothing"] = band
    raw["output"] = {**raw.get("output", {}), "vtu": False}
    return problem_from_dict(raw, ROOT / path)


def _ironing_problem(band: float):
    from test_ironing import ironing_problem, slab_mesh

    p = ironing_problem(slab_mesh(18, 2, 6))
    return replace(p, contacts=[replace(c, smoothing=band) for c in p.contacts])


def _measure(make, band: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        res = make(band).run(out=Path(tmp))
    return {"smoothing": band, **run_record(res.summary)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="JSON output file (default: stdout)")
    ap.add_argument("--quick", action="store_true", help="leave out the U-channel")
    args = ap.parse_args()
    cases = {k: ((lambda b, f=f: _file_problem(f, b)), bands) for k, (f, bands) in FILES.items()
             if not (args.quick and k == "uchannel")}
    cases["ironing"] = (_ironing_problem, (1e-3, 1e-2))
    rows = []
    for name, (make, bands) in cases.items():
        make(0.0).run(out=Path(tempfile.mkdtemp()))  # compile (untimed)
        for band in (0.0, *bands):
            r = {"problem": name, **_measure(make, band)}
            rows.append(r)
            print(r, file=sys.stderr)
    emit({"machine": platform.node(), "python": platform.python_version(), "runs": rows}, args.out,
         runs_table(rows, "smoothing"))


if __name__ == "__main__":
    main()
