"""A rubber ball pressed flat between two rigid plates (docs/verification.md, "Rubber ball pressed flat";
examples/contact/rubber_ball.toml).

Set-up: a ball of radius R = 10 mm as an axisymmetric body (x the radius, y the axis), Neo-Hooke rubber given as
Mooney-Rivlin with c01 = 0 (c10 = 0.5 MPa: mu0 = 1 MPa; d1 = 0.001: K0 = 2 / d1 = 2000 mu0) on F-bar quad4 cells,
pressed between two rigid frictionless flat plates to a total approach delta (the change of the distance between
the plates) of 30 % of the diameter D = 2 R, in 15 steps (delta / D = 1, 2, 3, 4, 5, 7.5, 10, ..., 30 %). By symmetry
the quarter x >= 0, y >= 0: the equator y = 0 held axially, the axis x = 0 held radially, the upper plate moved down
by delta / 2, frictionless node-to-surface contact of the quarter circle against it, penalty 1e4 per area. The mesh
is the quarter_disc generator's quad4 O-grid quarter, graded toward the pole (0, R): n cells along the quarter
circle.

References. Small approach: Hertz (1882), J. reine angew. Math. 92, 156-171; K. L. Johnson, Contact Mechanics
(1985), section 4.2. Each plate presses a sphere of radius R with approach d = delta / 2 (the ball's centre does not
move) and F = 4/3 E* R^(1/2) d^(3/2), E* = E / (1 - nu^2) = 4 mu0 for the incompressible rubber (E = 3 mu0,
nu = 1/2). Large approach: no closed form; the same run on a mesh with twice the cells per direction.

Measured (n = 16, 32, 64, 128; 160, 640, 2,560, 10,240 cells): F / F_Hertz at delta / D = 1, 2, 3 % 1.049, 1.051,
1.069 (n = 16), 1.031, 1.046, 1.061 (32), 1.033, 1.046, 1.060 (64): the finite-strain stiffening grows with the
contact radius; the leading coefficient C2 of F = C2 d^1.5 + B d^2 fitted over those three steps
(test_hertz_axisymmetric.py's measure) is 0.995, 0.986, 0.990, 0.993 of Hertz's 4/3 E* R^(1/2). At 30 %
F / F_Hertz = 1.44. The n = 16 force differs from n = 32's by at most 1.75 % over the 15 steps (1.53 % at the
tabulated 5 .. 30 %), n = 32 from n = 64 by at most 0.40 %, n = 64 from n = 128 by at most 0.10 %. The equator's
reaction equals the plate's contact force to 1e-7 (relative), the penetration stays below 2.6e-4 of the plate's
travel, the ball's volume changes by less than 1e-4. Plain quad4 (no F-bar) locks: 2.71 times Hertz at 1 % (n = 16).
The example (the generator's quarter disc, 16 cells along the arc, 6 across the rim, not graded) lies within 1.0 % of
the graded n = 32 at 5 .. 30 %. `python tests/verification/test_rubber_ball.py N` prints the run of
n = N step by step.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.materials.rubber import rubber_from_keys
from covcontact.mesh import Mesh
from covcontact.mesh.faces import check_orientation
from covcontact.mesh.generators_planar import quarter_disc
from covcontact.motion import RigidMotion
from covcontact.problem import Body, ContactPair, Dirichlet, OutputOptions, Problem, RigidBody, SolverOptions, Steps

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "contact" / "rubber_ball.toml"
R, MU0 = 10.0, 1.0
E_STAR = 4.0 * MU0                                          # E / (1 - nu^2), E = 3 mu0, nu = 1/2
APPROACH = (1.0, 2.0, 3.0, 4.0, 5.0, 7.5, 10.0, 12.5, 15.0, 17.5, 20.0, 22.5, 25.0, 27.5, 30.0)  # delta / D in %
TABULATED = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)


def hertz(delta: float) -> float:
    """Hertz's force of each plate at the total approach delta (each contact's approach delta / 2)."""
    return 4.0 / 3.0 * E_STAR * math.sqrt(R) * (0.5 * delta) ** 1.5


def quarter_ball(n: int, beta: float = 3.0, gamma: float = 2.0) -> Mesh:
    """The quarter disc of radius R about the origin (the quarter_disc generator: n cells along the quarter circle,
    3 n / 8 across the rim), its nodes moved toward the pole (0, R) in polar coordinates about the centre as
    hertz_setup.grade_to_pole moves the 3D ball's (the circle, the axis and the equator map onto themselves): the
    angle from the pole, a fraction x of the quarter, becomes x + w (sinh(beta x) / sinh(beta) - x), w the new radius
    over R; the depth s = 1 - r / R becomes sinh(gamma s) / sinh(gamma). Sets: "arc" (edge and node set), node sets
    "axis" (x = 0) and "equator" (y = 0)."""
    m = quarter_disc(R, n, 3 * n // 8, cell="quad4")
    X = m.points.copy()
    tol = 1e-9 * R
    r = np.hypot(X[:, 0], X[:, 1])
    x = np.arctan2(X[:, 0], X[:, 1]) / (0.5 * math.pi)     # 0 at the pole, 1 at the equator
    r_new = R * (1.0 - np.sinh(gamma * (1.0 - r / R)) / math.sinh(gamma))
    theta = 0.5 * math.pi * (x + r_new / R * (np.sinh(beta * x) / math.sinh(beta) - x))
    on_axis, on_equator = X[:, 0] == 0.0, X[:, 1] == 0.0
    X[:, 0], X[:, 1] = r_new * np.sin(theta), r_new * np.cos(theta)
    X[on_axis, 0] = 0.0
    X[on_equator, 1] = 0.0
    q = Mesh(X, "quad4", m.cells)
    q.add_face_set("arc", m.face_sets["arc"])
    q.add_node_set("arc", m.node_sets["arc"])
    q.add_node_set("axis", np.flatnonzero(on_axis))
    q.add_node_set("equator", np.flatnonzero(on_equator))
    return q


def revolved_volume(points: np.ndarray, cells: np.ndarray) -> float:
    """Volume of the quad4 cells revolved about the y axis: 2 pi times int x dA (exact for straight edges)."""
    x, y = points[cells][..., 0], points[cells][..., 1]
    x1, y1 = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
    return float(2.0 * math.pi * np.sum((x + x1) * (x * y1 - x1 * y)) / 6.0)


def ball_problem(mesh: Mesh) -> Problem:
    top = APPROACH[-1] / 100.0 * 2.0 * R
    rubber = rubber_from_keys("mooney-rivlin", {"c10": 0.5 * MU0, "c01": 0.0, "d1": 2.0 / (2000.0 * MU0)})
    plate = RigidBody("plate", shape="plane", params={"point": (0.0, R, 0.0), "normal": (0.0, -1.0, 0.0)},
                      motion=RigidMotion(translation=(0.0, -0.5 * top, 0.0)))
    return Problem(
        name="rubber-ball", bodies=[Body("ball", mesh, rubber, formulation="axisymmetric", options={"fbar": True})],
        dirichlet=[Dirichlet("ball", "axis", (0,), (0.0,)), Dirichlet("ball", "equator", (1,), (0.0,))],
        rigid=[plate], contacts=[ContactPair("plate", ("ball", "arc"), ("plate", ""), penalty=1e4, weighting="area")],
        steps=Steps(tuple(a / APPROACH[-1] for a in APPROACH)), solver=SolverOptions(line_search=True),
        output=OutputOptions(vtu=False, pictures=False))


def measure(n: int, out: Path) -> dict:
    """Run the quarter ball of ``n`` (results in ``out``): per step the approach (in % of D), the plate's force, the
    equator's reaction and the penetration; the volume change at the end."""
    mesh = quarter_ball(n)
    assert check_orientation(mesh) == []
    res = ball_problem(mesh).run(out=out, quiet=True)
    assert res.exit_code == 0 and res.summary["converged"], n
    steps = [s for s in res.summary["steps"] if s["converged"]]
    x = res.model.system.X[:mesh.n_nodes] + res.u.reshape(-1, 3)[:mesh.n_nodes]
    return {"a": np.array([APPROACH[-1] * s["load_factor"] for s in steps]),
            "F": np.array([-s["pairs"]["plate"]["contact_force"][1] for s in steps]),
            "reaction": np.array([s["reactions"]["ball.equator"][1] for s in steps]),
            "penetration": np.array([-s["pairs"]["plate"]["min_gap"] for s in steps]),
            "dV": revolved_volume(x, mesh.cells) / revolved_volume(mesh.points, mesh.cells) - 1.0,
            "cells": len(mesh.cells), "dofs": res.summary["dofs"]}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {n: measure(n, tmp_path_factory.mktemp(f"ball{n}")) for n in (16, 32)}
    for n, r in out.items():
        assert r["a"] == pytest.approx(APPROACH)
        ratios = r["F"] / np.array([hertz(p / 100.0 * 2.0 * R) for p in r["a"]])
        print(f"ball n = {n}: F / F_Hertz", ", ".join(f"{p:g} %: {v:.4f}" for p, v in zip(r["a"], ratios)))
    return out


@pytest.mark.parametrize("n", [16, 32])
def test_small_approach_against_hertz(runs, n):
    """At delta / D = 1, 2, 3 % the force is within 9 % of Hertz's and above it (measured 1.031 .. 1.069: the
    stiffening of finite strain, growing with the contact radius); the leading coefficient C2 of F = C2 d^1.5 + B d^2
    over those steps (d = delta / 2) within 3 % of Hertz's 4/3 E* R^(1/2) (measured 0.995, 0.986)."""
    r = runs[n]
    d = r["a"][:3] / 100.0 * R                                 # each contact's approach delta / 2
    ratio = r["F"][:3] / np.array([hertz(2.0 * v) for v in d])
    assert np.all((ratio > 1.0) & (ratio < 1.09)), ratio
    C2, _ = np.linalg.lstsq(np.stack([d**1.5, d**2], axis=1), r["F"][:3], rcond=None)[0]
    assert C2 / (4.0 / 3.0 * E_STAR * math.sqrt(R)) == pytest.approx(1.0, abs=0.03)


@pytest.mark.parametrize("n", [16, 32])
def test_force_grows_beyond_hertz(runs, n):
    """The force grows at every step, and its ratio to Hertz's at every tabulated approach 5 .. 30 % (Hertz's
    small-strain force falls ever further behind: measured 1.08 at 5 %, 1.44 at 30 %)."""
    r = runs[n]
    assert np.all(np.diff(r["F"]) > 0.0)
    at = [list(r["a"]).index(p) for p in TABULATED]
    ratio = r["F"][at] / np.array([hertz(p / 100.0 * 2.0 * R) for p in TABULATED])
    assert np.all(np.diff(ratio) > 0.0) and ratio[0] > 1.0, ratio


@pytest.mark.parametrize("n", [16, 32])
def test_force_balance_penetration_and_volume(runs, n):
    """The equator's reaction equals the plate's contact force (measured to 1e-7 relative); the penetration stays
    below 1e-3 of the plate's travel delta / 2 (measured 2.5e-4 at most, at 1 %); the nearly incompressible ball's
    volume at 30 % within 5e-4 of its start (measured 2e-5, 5e-5)."""
    r = runs[n]
    assert r["reaction"] == pytest.approx(r["F"], rel=1e-6)
    assert np.all(r["penetration"] < 1e-3 * r["a"] / 100.0 * R), r["penetration"]
    assert abs(r["dV"]) < 5e-4


def test_coarse_against_fine(runs):
    """n = 16 against n = 32 (twice the cells per direction): within 2.5 % at every step (measured 1.75 % at most,
    at 1 %; 1.53 % at the tabulated 5 .. 30 %; n = 32 against n = 64 within 0.40 %)."""
    diff = runs[16]["F"] / runs[32]["F"] - 1.0
    print("n = 16 against n = 32:", ", ".join(f"{p:g} %: {100 * v:+.2f} %" for p, v in zip(APPROACH, diff)))
    assert np.all(np.abs(diff) < 0.025), diff


def test_example(runs, tmp_path):
    """The example (the quarter_disc generator's mesh, 16 cells along the arc, not graded) converges; the plate's
    force balances the equator's reaction; at the tabulated 5 .. 30 % it lies within 2 % of the graded n = 32 quarter
    disc (measured within 1.0 %)."""
    assert main(["run", str(EXAMPLE), "--out", str(tmp_path), "--quiet"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["converged"]
    steps = summary["steps"]
    a = np.array([s["load_factor"] for s in steps])            # the example's load factor is delta / D in %
    assert a == pytest.approx(APPROACH)
    F = np.array([-s["pairs"]["plate"]["contact_force"][1] for s in steps])
    held = np.array([s["reactions"]["ball.ymin"][1] for s in steps])
    assert held == pytest.approx(F, rel=1e-6)
    at = [APPROACH.index(p) for p in TABULATED]
    assert F[at] == pytest.approx(runs[32]["F"][at], rel=0.02)


if __name__ == "__main__":  # python tests/verification/test_rubber_ball.py N [OUT]: the run of n = N, per step
    import sys
    import tempfile

    n = int(sys.argv[1])
    r = measure(n, Path(sys.argv[2]) if len(sys.argv) > 2 else Path(tempfile.mkdtemp()))
    print(f"n = {n}: {r['cells']} cells, {r['dofs']} dofs; volume change {r['dV']:.2e}")
    for p, F, reac, g in zip(r["a"], r["F"], r["reaction"], r["penetration"]):
        print(f"delta/D {p:5.1f} %  F {F:10.5f} N  F/F_Hertz {F / hertz(p / 100.0 * 2.0 * R):.4f}  "
              f"reaction/F - 1 {reac / F - 1.0:+.1e}  penetration/travel {g / (p / 100.0 * R):.1e}")
