"""Reading a large Abaqus / CalculiX deck: a block of n^3 C3D8 bricks ((n + 1)^3 nodes; n = 100: 1,030,301 nodes and
1,000,000 elements) written to a temporary folder, then timed: the cards and the model (``read_model``: every node,
element and set parsed), the whole import (``import_deck``: bodies, conditions, the problem and mesh files, and the
meshes built) and loading the imported problem with those meshes (what ``covcontact run DECK.inp`` does before it
solves).

    python benchmarks/deck_reading.py [--n 100] [--repeats 3] [--out results/deck_reading.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np


def write_deck(path: Path, n: int) -> tuple[int, int]:
    i, j, k = np.meshgrid(np.arange(n + 1), np.arange(n + 1), np.arange(n + 1), indexing="ij")
    X = np.column_stack([i.ravel(), j.ravel(), k.ravel()]) / n
    lab = np.arange(1, len(X) + 1)
    idx = lab.reshape(n + 1, n + 1, n + 1)
    a, b, c = (v.ravel() for v in np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij"))
    els = np.column_stack([idx[a, b, c], idx[a + 1, b, c], idx[a + 1, b + 1, c], idx[a, b + 1, c],
                           idx[a, b, c + 1], idx[a + 1, b, c + 1], idx[a + 1, b + 1, c + 1], idx[a, b + 1, c + 1]])
    with open(path, "w") as f:
        f.write("*NODE, NSET=NALL\n")
        np.savetxt(f, np.column_stack([lab, X]), fmt=["%d", "%.8f", "%.8f", "%.8f"], delimiter=", ")
        f.write("*ELEMENT, TYPE=C3D8, ELSET=EALL\n")
        np.savetxt(f, np.column_stack([np.arange(1, len(els) + 1), els]), fmt="%d", delimiter=", ")
        f.write("*NSET, NSET=BOTTOM\n")
        np.savetxt(f, lab[X[:, 2] == 0].reshape(-1, 1), fmt="%d")
        f.write("*MATERIAL, NAME=M\n*ELASTIC\n1000., 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=M\n*BOUNDARY\n"
                "BOTTOM, 1, 3\n*STEP, NLGEOM\n*STATIC\n*CLOAD\n1, 3, 1.\n*NODE PRINT, NSET=BOTTOM\nRF\n*END STEP\n")
    return len(X), len(els)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="results/deck_reading.json")
    args = ap.parse_args()
    from covcontact.io.deck_import import import_deck
    from covcontact.io.deck_model import read_model

    with tempfile.TemporaryDirectory() as tmp:
        deck = Path(tmp) / "block.inp"
        nodes, elements = write_deck(deck, args.n)
        from covcontact.io.bodies_input import preload
        from covcontact.io.loader import load_problem

        read, full, load = [], [], []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            read_model(deck)
            t1 = time.perf_counter()
            imported = import_deck(deck, Path(tmp) / "imported" / "block.toml")
            t2 = time.perf_counter()
            preload(imported.read)
            load_problem(imported.problem)
            t3 = time.perf_counter()
            read.append(t1 - t0)
            full.append(t2 - t1)
            load.append(t3 - t2)
        size = deck.stat().st_size
    out = {"nodes": nodes, "elements": elements, "deck_bytes": size, "repeats": args.repeats,
           "read_model_s": read, "read_model_median_s": statistics.median(read),
           "import_deck_s": full, "import_deck_median_s": statistics.median(full),
           "load_problem_s": load, "load_problem_median_s": statistics.median(load)}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(out, indent=1))
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
