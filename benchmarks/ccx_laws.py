"""Each pressure-overclosure law of *SURFACE BEHAVIOR, covcontact against CalculiX on one-element decks.

A punch (one C3D8, 1 x 1 x 0.5) starts at a clearance above a base (one C3D8, 2 x 2 x 1, its bottom held) and its top
is moved down step by step, from a clearance through touching to an overclosure; the punch's face is the slave
surface (element faces: each corner node carries a quarter of its area, as CalculiX's springs do; or its nodes as a
node surface, which CalculiX weights by the area of the master face under each node), the base's top the master. Each step prints the punch top's reaction (*NODE PRINT, TOTALS=ONLY) in both codes; the table gives
both per step and their difference relative to the largest force of the run. The steps sweep the clearance on
both sides of zero and across c0 (the laws' reach).

Install CalculiX first (``apt-get install calculix-ccx``); it is not a dependency.

    python benchmarks/ccx_laws.py [--out results/ccx_laws.json]
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import emit  # noqa: E402
from ccx_decks import dat_blocks  # noqa: E402

GAP0 = 0.004  # the punch's clearance at the start

#: law -> (pair type, *SURFACE BEHAVIOR lines, the punch's travel at each step end)
LAWS = {
    "LINEAR n2f (K, sigma_inf, c0)": ("NODE TO SURFACE", "PRESSURE-OVERCLOSURE=LINEAR\n1.0e4, 5.0, 2.0e-3",
                                      [0.0036, 0.0039, 0.0040, 0.0041, 0.0045, 0.0050]),
    "LINEAR n2f, node surface": ("NODE TO SURFACE*", "PRESSURE-OVERCLOSURE=LINEAR\n1.0e4, 5.0, 2.0e-3",
                                 [0.0039, 0.0040, 0.0041, 0.0045, 0.0050]),
    "EXPONENTIAL, node surface": ("NODE TO SURFACE*", "PRESSURE-OVERCLOSURE=EXPONENTIAL\n1.0e-3, 20.0",
                                  [0.0032, 0.0036, 0.0040, 0.0042]),
    "LINEAR f2f (K)": ("SURFACE TO SURFACE", "PRESSURE-OVERCLOSURE=LINEAR\n1.0e4",
                       [0.0039, 0.0041, 0.0045, 0.0050]),
    "EXPONENTIAL (c0, p0)": ("NODE TO SURFACE", "PRESSURE-OVERCLOSURE=EXPONENTIAL\n1.0e-3, 20.0",
                             [0.0028, 0.0032, 0.0036, 0.0040, 0.0042]),
    "TABULAR": ("NODE TO SURFACE", "PRESSURE-OVERCLOSURE=TABULAR\n0., 0.\n5., 0.0002\n40., 0.0006\n60., 0.002",
                [0.0038, 0.0041, 0.00415, 0.0044, 0.0050]),
    "TIED f2f (K)": ("SURFACE TO SURFACE", "PRESSURE-OVERCLOSURE=TIED\n1.0e4\n*FRICTION\n0.5, 1.0e4",
                     [-0.0005, 0.0005]),
}


def deck(pair: str, behavior: str, travel: list[float], gap0: float) -> str:
    """The deck: nodes 1-8 the base, 11-18 the punch; one step per travel. A pair type ending in * takes the punch's
    bottom nodes as a node surface (no area of their own: CalculiX weights them by the master face)."""
    slave = "2, S1"
    if pair.endswith("*"):
        pair, slave = pair[:-1], "NSLAV"
    base = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
    z0 = 1.0 + gap0
    punch = [(0.5, 0.5, z0), (1.5, 0.5, z0), (1.5, 1.5, z0), (0.5, 1.5, z0),
             (0.5, 0.5, z0 + 0.5), (1.5, 0.5, z0 + 0.5), (1.5, 1.5, z0 + 0.5), (0.5, 1.5, z0 + 0.5)]
    nodes = "".join(f"{i + 1}, {x}, {y}, {z}\n" for i, (x, y, z) in enumerate(base))
    nodes += "".join(f"{i + 11}, {x}, {y}, {z:.10g}\n" for i, (x, y, z) in enumerate(punch))
    text = f"""*NODE, NSET=NALL
{nodes}*ELEMENT, TYPE=C3D8, ELSET=BASE
1, 1, 2, 3, 4, 5, 6, 7, 8
*ELEMENT, TYPE=C3D8, ELSET=PUNCH
2, 11, 12, 13, 14, 15, 16, 17, 18
*NSET, NSET=BOTTOM
1, 2, 3, 4
*NSET, NSET=TOP
15, 16, 17, 18
*SURFACE, NAME=SMAST
1, S2
*NSET, NSET=NSLAV
11, 12, 13, 14
*SURFACE, NAME=SSLAV{", TYPE=NODE" if slave == "NSLAV" else ""}
{slave}
*MATERIAL, NAME=M
*ELASTIC
1000.0, 0.3
*SOLID SECTION, ELSET=BASE, MATERIAL=M
*SOLID SECTION, ELSET=PUNCH, MATERIAL=M
*CONTACT PAIR, INTERACTION=SI, TYPE={pair}
SSLAV, SMAST
*SURFACE INTERACTION, NAME=SI
*SURFACE BEHAVIOR, {behavior}
*BOUNDARY
BOTTOM, 1, 3
TOP, 1, 2
"""
    for k, w in enumerate(travel):
        text += f"""*STEP, NLGEOM, INC=1000
*STATIC
0.05, 1.0
*BOUNDARY
TOP, 3, 3, {-w:.10g}
*NODE PRINT, NSET=TOP, TOTALS=ONLY
RF
*END STEP
"""
    return text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    if shutil.which("ccx") is None:
        print("ccx (CalculiX) is not installed: apt-get install calculix-ccx", file=sys.stderr)
        return 2
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, (pair, behavior, travel) in LAWS.items():
            gap0 = 0.0 if name.startswith("TIED") else GAP0
            folder = Path(tmp) / f"law{len(rows)}"
            folder.mkdir()
            (folder / "d.inp").write_text(deck(pair, behavior, travel, gap0))
            subprocess.run(["ccx", "-i", "d"], cwd=folder, capture_output=True, text=True, timeout=600)
            theirs = _step_end_forces((folder / "d.dat").read_text(errors="replace"), len(travel))
            run = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", "d.inp", "--out", "ours", "--quiet"],
                                 cwd=folder, capture_output=True, text=True, timeout=900)
            dat = folder / "ours" / "d.dat"
            ours = _step_end_forces(dat.read_text(), len(travel)) if dat.is_file() else []
            scale = max([abs(v) for v in theirs + ours] + [1e-300])
            for k, w in enumerate(travel):
                a = theirs[k] if k < len(theirs) else None
                b = ours[k] if k < len(ours) else None
                rows.append({"law": name, "pair": pair, "overclosure": round(w - gap0, 10), "calculix": a,
                             "covcontact": b, "difference": None if a is None or b is None else abs(a - b) / scale,
                             "exit_code": run.returncode})
    lines = ["| law | overclosure | CalculiX | covcontact | difference / largest |", "|---|---|---|---|---|"]
    for r in rows:
        cells = ["-" if r[k] is None else f"{r[k]:.6g}" for k in ("calculix", "covcontact")]
        diff = "-" if r["difference"] is None else f"{r['difference']:.2e}"
        lines.append(f"| {r['law']} | {r['overclosure']:g} | {cells[0]} | {cells[1]} | {diff} |")
    emit({"benchmark": "ccx_laws", "rows": rows}, args.out, "\n".join(lines))
    return 0


def _step_end_forces(text: str, steps: int) -> list[float]:
    """The reaction of the punch's top at the end of each step: the totals block of the last time of each step
    (times 1, 2, ...), from the .dat table (a totals line, or the sum of the per-node rows)."""
    out = {}
    time = None
    for line in text.splitlines():
        if line.strip().startswith("total force") and "for set TOP and time" in line:
            time = float(line.split("time")[1])
        elif time is not None and line.strip():
            out[time] = float(line.split()[2])
            time = None
    if not out:  # (per-node rows: their sum)
        blocks = dat_blocks(text)
        out = {t: sum(v[2] for v in rows.values()) for (kind, _, t), rows in blocks.items() if kind == "forces"}
    ends = [out[t] for t in sorted(out) if abs(t - round(t)) < 1e-9 and round(t) >= 1]
    return ends[:steps]


if __name__ == "__main__":
    sys.exit(main())
