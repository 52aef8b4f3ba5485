"""Necking of a circular bar (Simo 1988; Simo 1992; Simo & Armero 1992; ANSYS VM318) under mesh and step
refinement: force-elongation curve, peak force against Considere's closed form, neck radius ratio against
elongation and at 14 mm against the published 0.399 (VM318), plastic incompressibility. Writes JSON.

The set-up is tests/verification/necking_setup.py (one eighth, F-bar hex8, J2 with saturation + linear
hardening, 7 mm per end); a run is "n x nz" (n x n elements over the quarter section, nz along the half
length, twice as fine at the neck as at the end) with an optional ":steps" (equal load steps to 14 mm,
--steps by default). Per run: the force and the neck radius ratio at every step, the peak force and where,
the neck and end radius ratios at 14 mm, Newton iterations, wall time, the largest difference between the
F-bar dilatation (det F at the element centroid) and the elastic one exp(J tr(sigma) / 3K), and the volume
change of the whole bar. JSON on stdout or to --out, a table on stderr; --plot DIR writes
necking_force.png and necking_radius.png there.

    python benchmarks/necking.py --out necking.json --plot docs/img
    python benchmarks/necking.py --meshes 4x12:28,4x12:56,4x12:112 --out necking_steps.json
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import meshio
import numpy as np
from _report import emit

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "verification"))
from necking_setup import (
    IMPERFECTION,
    NU,
    RADIUS,
    VM318_NECK_RATIO,
    VM318_U,
    E,
    considere_peak,
    necking_problem,
    results,
)

from covcontact.fem.quadrature import gauss_hex
from covcontact.fem.shapes import shape_functions


def _jacobians(cells: np.ndarray, points: np.ndarray, at: np.ndarray) -> np.ndarray:
    _, dN, _ = shape_functions("hex8", at)
    return np.linalg.det(np.einsum("enj,qnk->eqjk", points[cells], dN))


def one(n: int, nz: int, steps: int) -> dict:
    problem = necking_problem(n, nz, steps)
    problem.output.vtu = True
    mesh = problem.bodies[0].mesh
    X, cells = mesh.points, mesh.cells
    ring = np.flatnonzero((X[:, 2] == 0.0) & (np.abs(X[:, 1]) < 1e-9))
    k = int(ring[np.argmax(X[ring, 0])])
    gp, w = gauss_hex(2)
    V0 = float(np.sum(_jacobians(cells, X, gp) * w))
    J0 = _jacobians(cells, X, np.zeros((1, 3)))[:, 0]
    K = E / (3.0 * (1.0 - 2.0 * NU))
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        res = problem.run(out=out, quiet=True)
        wall = time.perf_counter() - t0
        files = sorted(Path(out).glob("step_*.vtu"))[1:]
        neck = []
        for f in files:
            neck.append(float((X[k, 0] + meshio.read(f).point_data["displacement"][k, 0]) / RADIUS))
        last = meshio.read(files[-1])
    x = X + last.point_data["displacement"]
    J = _jacobians(cells, x, np.zeros((1, 3)))[:, 0] / J0
    s = last.cell_data["cauchy"][0]
    J_el = np.exp(J * (s[:, 0] + s[:, 1] + s[:, 2]) / (3.0 * K))
    r = results(problem, res)
    r.update(mesh=f"{n}x{nz}", steps=steps, elements=n * n * nz, exit_code=res.exit_code,
             wall_s=round(wall, 1), neck_history=neck,
             neck_element_length_mm=float(np.min(np.diff(np.unique(X[:, 2])))),
             max_eps_p=float(last.cell_data["equivalent_plastic_strain"][0].max()),
             max_fbar_dilatation_error=float(np.abs(J - J_el).max()),
             volume_change=float(np.sum(_jacobians(cells, x, gp) * w)) / V0 - 1.0)
    return r


def plot(rows: list[dict], ref: dict, folder: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for r in rows:
        ax.plot([0.0] + r["elongation"], [0.0] + [f / 1e3 for f in r["force"]],
                label=f"{r['mesh']}, {r['steps']} steps")
    ax.axhline(ref["considere_peak_thinnest_N"] / 1e3, color="k", ls=":", lw=1,
               label="Considere, thinnest section")
    ax.set_xlabel("total elongation [mm]")
    ax.set_ylabel("force on the whole bar [kN]")
    ax.set_ylim(0.0, 85.0)
    ax.set_title("Necking of a circular bar: force against elongation")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(folder / "necking_force.png", dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for r in rows:
        ax.plot([0.0] + r["elongation"], [IMPERFECTION] + r["neck_history"],
                label=f"{r['mesh']}, {r['steps']} steps")
    ax.plot([14.0], [ref["vm318_neck_ratio"]], "k*", ms=10, label="VM318 (Simo 1992), 14 mm")
    ax.set_xlabel("total elongation [mm]")
    ax.set_ylabel("neck radius / 6.413")
    ax.set_title("Necking of a circular bar: radius in the middle")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(folder / "necking_radius.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="3x8,4x12,8x12,4x24,4x48",
                    help="n x nz[:steps] per run: n x n elements over the quarter section, nz along the half length")
    ap.add_argument("--steps", type=int, default=56, help="equal load steps to 14 mm (runs without ':steps')")
    ap.add_argument("--out", default=None)
    ap.add_argument("--plot", default=None, help="folder for necking_force.png and necking_radius.png")
    args = ap.parse_args()
    ref = {"considere_peak_thinnest_N": considere_peak(IMPERFECTION * RADIUS),
           "considere_peak_nominal_N": considere_peak(RADIUS),
           "vm318_neck_u_mm": VM318_U, "vm318_neck_ratio": VM318_NECK_RATIO,
           "vm318_source": "ANSYS Verification Manual VM318 (input deck vm318.dat in github.com/ansys/pymapdl), "
                           "after Simo 1992, CMAME 99, 61-112"}
    rows = []
    for spec in args.meshes.split(","):
        grid, _, steps = spec.partition(":")
        n, nz = (int(v) for v in grid.split("x"))
        rows.append(one(n, nz, int(steps) if steps else args.steps))
    if args.plot:
        plot(rows, ref, Path(args.plot))
    c = ref["considere_peak_thinnest_N"]
    table = "\n".join(
        f"{r['mesh']:>6}:{r['steps']:<4d}{r['elements']:5d} el  dz(neck) {r['neck_element_length_mm']:.3f} mm  "
        f"peak {r['peak_force'] / 1e3:6.2f} kN at {r['peak_elongation']:.2f} mm ({r['peak_force'] / c - 1:+.2%})  "
        f"neck {r['neck_ratio']:.4f} ({r['neck_ratio'] / VM318_NECK_RATIO - 1:+.1%} VM318)  "
        f"end {r['end_ratio']:.4f}  F(14) {r['force'][-1] / 1e3:5.2f} kN  dJ {r['max_fbar_dilatation_error']:.1e}  "
        f"dV/V {r['volume_change']:.2e}  {r['iterations']} it  {r['wall_s']} s  exit {r['exit_code']}"
        for r in rows)
    emit({"reference": ref, "runs": rows}, args.out, table)


if __name__ == "__main__":
    main()
