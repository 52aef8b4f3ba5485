"""Springback of the U-channel (examples/forming/uchannel.toml): the NUMISHEET'93 measures and pictures.

Run the problem first, then measure its output directory (and as many others as you like, e.g. meshes of
several sizes made with a copy of the file):

    covcontact run examples/forming/uchannel.toml --out results/uchannel          # about 5 minutes
    python examples/forming/uchannel_springback.py results/uchannel --plot results/uchannel/uchannel

Prints, per run, the springback measures of the benchmark from the blank's mid-surface (the mean of the
node columns through the thickness), at the end of the draw and after the release:

- theta1: the angle between the channel bottom and the sidewall, at the punch side;
- theta2: the angle between the sidewall and the flange, at the die side (both 90 degrees for the ideal
  channel), from the sidewall's chord and, in brackets, from the tangents of a circle fitted to it;
- rho: the radius of that circle (the sidewall curl).

The parts are taken on the formed shape: the bottom on the punch face, the sidewall between the two tool
corners (1 mm clear of their tangent lines), the flange on the die face; lines are fitted to bottom and
flange. With --plot PREFIX: PREFIX_shape.png (formed and sprung-back mid-surface with the tools) and
PREFIX_force.png (punch force against stroke for the whole blank). The problem file given with --problem
(default: the example beside this script) supplies the mesh; its tool geometry is the benchmark's (punch
half-width 35 mm, die opening 37 mm, both corner radii 5 mm).
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import meshio
import numpy as np

from covcontact.io.loader import load_problem

HERE = Path(__file__).resolve().parent
T = 0.78                                # sheet thickness (mm)
R_PUNCH = R_DIE = 5.0                   # corner radii
X_PUNCH, X_DIE = 35.0, 37.0             # punch half-width, die opening half-width


def midline(X: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The blank's mid-surface in the (x, z) plane, ordered by X: the mean of the four nodes of each column."""
    x = X + u
    cols = np.round(X[:, 0], 6)
    return np.array([x[cols == c][:, [0, 2]].mean(axis=0) for c in np.unique(cols)])


def _line(P: np.ndarray) -> np.ndarray:
    _, _, vt = np.linalg.svd(P - P.mean(axis=0))
    return vt[0]


def _circle(P: np.ndarray) -> tuple[np.ndarray, float]:
    A = np.c_[2.0 * P, np.ones(len(P))]
    sol = np.linalg.lstsq(A, (P**2).sum(axis=1), rcond=None)[0]
    return sol[:2], float(np.sqrt(sol[2] + sol[:2] @ sol[:2]))


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(math.acos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0)))


def springback_measures(X: np.ndarray, u_loaded: np.ndarray, u_final: np.ndarray, stroke: float,
                        margin: float = 1.0) -> dict:
    """NUMISHEET'93 springback measures from the mid-surface after release.

    The parts are chosen on the loaded shape (end of the stroke): the bottom, the mid-surface points on the
    punch face (x < 30 - margin); the sidewall, those between the two corners (x in (30, 42) and z from
    margin above the punch corner's upper tangent line to margin below the die corner's lower one);
    the flange, those on the die face (x > 42 + margin). After release: straight lines fitted to bottom and
    flange, a circle to the sidewall (radius rho; rho_sign +1 when the sidewall bulges outward);

    - theta1: the angle between the bottom (pointing to the centre) and the sidewall (pointing up from its
      lower end, tangent of the circle there), at the punch side;
    - theta2: the angle between the flange (pointing outward) and the sidewall (pointing down from its
      upper end, tangent of the circle there), at the die side;

    both 90 degrees for the ideal channel. ``theta1_chord``, ``theta2_chord``: the same with the sidewall's
    chord in place of the tangents. Needs a straight sidewall of a few elements (a stroke of about 20 mm
    or more); for short strokes ``theta1_chord`` alone is meaningful."""
    loaded, final = midline(X, u_loaded), midline(X, u_final)
    zb = 0.5 * T - stroke  # the mid-surface on the punch face at the end of the stroke
    bottom = loaded[:, 0] < 30.0 - margin
    side = ((loaded[:, 0] > 30.0) & (loaded[:, 0] < 42.0) & (loaded[:, 1] > zb + R_PUNCH + margin)
            & (loaded[:, 1] < zb + stroke - R_DIE - margin))
    flange = loaded[:, 0] > 42.0 + margin
    db = _line(final[bottom])
    db = db if db[0] < 0 else -db
    out = {"n_bottom": int(bottom.sum()), "n_side": int(side.sum()), "n_flange": int(flange.sum())}
    if flange.sum() >= 2:
        df = _line(final[flange])
        df = df if df[0] > 0 else -df
    S = final[side]
    if len(S) >= 2:
        lo, hi = S[np.argmin(S[:, 1])], S[np.argmax(S[:, 1])]
        chord = hi - lo
        out["theta1_chord"] = _angle(db, chord)
        if flange.sum() >= 2:
            out["theta2_chord"] = _angle(-chord, df)
    if len(S) >= 4:
        c, rho = _circle(S)

        def tangent(p, toward):
            r = p - c
            tv = np.array([-r[1], r[0]])
            return tv if tv @ (toward - p) > 0 else -tv

        out["rho"] = rho
        mid = S[len(S) // 2]
        out["rho_sign"] = float(-np.sign(chord[0] * (mid - lo)[1] - chord[1] * (mid - lo)[0]))
        out["theta1"] = _angle(db, tangent(lo, hi))
        if flange.sum() >= 2:
            out["theta2"] = _angle(tangent(hi, lo), df)
    return out


def load_run(problem_file: Path, out: Path) -> dict:
    """Reference points of the blank, its displacements at the end of the draw and at the end, the summary."""
    problem = load_problem(problem_file)
    blank = problem.bodies[0].mesh
    n = len(blank.points)
    summary = json.loads((out / "summary.json").read_text())
    steps = summary["steps"]
    k_draw = [s["step"] for s in steps if s["stage"] == "draw"][-1]
    stroke = -round(float(problem.stages[0].motions["punch"].apply(np.zeros((1, 3)), 1.0)[0, 2]), 2)

    def u(k):
        return meshio.read(out / f"step_{k:04d}.vtu").point_data["displacement"][:n]

    return {"X": blank.points, "u_loaded": u(k_draw), "u_final": u(steps[-1]["step"]), "summary": summary,
            "stroke": stroke}


def punch_force(summary: dict) -> tuple[np.ndarray, np.ndarray]:
    """Punch stroke fraction (load factor of the draw) and punch force on the half model (N) per draw step:
    the punch pair's (and, in runs of earlier versions of the example, its corner pair and the centre nodes
    that moved with it)."""
    steps = [s for s in summary["steps"] if s["stage"] == "draw"]
    lam = np.array([s["load_factor"] for s in steps])
    f = np.array([-(sum(p["contact_force"][2] for k, p in s["pairs"].items() if k.startswith("punch"))
                    + s["reactions"].get("blank.pin", [0.0, 0.0, 0.0])[2]) for s in steps])
    return lam, f


def plot(runs: list[tuple[str, dict]], prefix: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = runs[0][1]["stroke"]
    fig, ax = plt.subplots(figsize=(7, 5))
    th = np.linspace(0.0, np.pi / 2, 30)
    zp = T + 0.002 - d                    # the punch face at the end of the stroke
    ax.plot([0.0, X_PUNCH - R_PUNCH], [zp, zp], "k-", lw=1)
    ax.plot(X_PUNCH - R_PUNCH + R_PUNCH * np.sin(th), zp + R_PUNCH - R_PUNCH * np.cos(th), "k-", lw=1)
    ax.plot([X_PUNCH, X_PUNCH], [zp + R_PUNCH, 10.0], "k-", lw=1)
    ax.plot([X_DIE + R_DIE, 180.0], [0.0, 0.0], "k-", lw=1)
    ax.plot(X_DIE + R_DIE - R_DIE * np.sin(th), -R_DIE + R_DIE * np.cos(th), "k-", lw=1)
    ax.plot([X_DIE, X_DIE], [-R_DIE, -d - 5.0], "k-", lw=1, label="tools (end of stroke)")
    for label, r in runs:
        L, F = midline(r["X"], r["u_loaded"]), midline(r["X"], r["u_final"])
        line, = ax.plot(L[:, 0], L[:, 1], "--", lw=1, label=f"{label}: formed")
        ax.plot(F[:, 0], F[:, 1], "-", lw=1.5, color=line.get_color(), label=f"{label}: after springback")
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_xlim(-2.0, 180.0)
    ax.legend(fontsize=8, loc="lower right")
    ax.grid(alpha=0.3)
    ax.set_title("U-channel (NUMISHEET'93), half model: mid-surface")
    fig.tight_layout()
    fig.savefig(prefix + "_shape.png", dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6, 4))
    for label, r in runs:
        lam, f = punch_force(r["summary"])
        ax.plot(lam * r["stroke"], 2.0 * f / 1000.0, "-", lw=1, label=label)
    ax.set_xlabel("punch stroke (mm)")
    ax.set_ylabel("punch force, whole blank (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(prefix + "_force.png", dpi=110)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outputs", nargs="+", help="output directories of runs (LABEL=DIR to name a run)")
    ap.add_argument("--problem", nargs="+", default=[str(HERE / "uchannel.toml")],
                    help="the problem file the runs used (for the blank's mesh; default: the example): one for "
                         "all runs or one per run, in order")
    ap.add_argument("--plot", metavar="PREFIX", help="write PREFIX_shape.png and PREFIX_force.png")
    args = ap.parse_args()
    if len(args.problem) not in (1, len(args.outputs)):
        ap.error(f"--problem: give one file for all runs or one per run ({len(args.outputs)})")
    runs = []
    for k, item in enumerate(args.outputs):
        label, _, path = item.rpartition("=")
        r = load_run(Path(args.problem[k if len(args.problem) > 1 else 0]), Path(path))
        runs.append((label or Path(path).name, r))
        m0 = springback_measures(r["X"], r["u_loaded"], r["u_loaded"], r["stroke"])
        m = springback_measures(r["X"], r["u_loaded"], r["u_final"], r["stroke"])
        print(f"{runs[-1][0]}: stroke {r['stroke']:g} mm")
        for name, mm in (("formed", m0), ("sprung back", m)):
            print(f"  {name:12s} theta1 {mm.get('theta1_chord', math.nan):6.1f} ({mm.get('theta1', math.nan):5.1f}) deg"
                  f"   theta2 {mm.get('theta2_chord', math.nan):6.1f} ({mm.get('theta2', math.nan):5.1f}) deg"
                  f"   rho {mm.get('rho', math.nan):8.1f} mm")
    if args.plot:
        plot(runs, args.plot)


if __name__ == "__main__":
    main()
