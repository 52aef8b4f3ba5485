"""Linear shell obstacle course with the solid-shell elements (one element through the thickness).

References (MacNeal & Harder, Finite Elements in Analysis and Design 1 (1985) 3-20; Belytschko et al.,
CMAME 51 (1985) 221-258), as tabulated in docs/verification.md ("Shells", linear obstacle course):
- Scordelis-Lo roof: vertical displacement at the middle of the free edge 0.3024;
- pinched cylinder with rigid diaphragms: displacement under the load 1.8248e-5;
- pinched hemisphere with an 18 degree hole: displacement under the loads 0.0924 (0.093-0.094);
- thin limit: a simply supported square plate with thickness/span 1/1000 under uniform pressure gives the
  Kirchhoff (Navier series) centre deflection.

The code is geometrically nonlinear: the problems run as one step with a small load factor (EPS) and the
displacement is scaled back (the nonlinear part changes the results by about 1e-6 relative). The full
mesh-convergence tables come from ``benchmarks/shells.py`` (docs/verification.md, "Shells").
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import cylinder_patch, plate, sphere_patch
from covcontact.problem import (
    Body,
    Dirichlet,
    NodalForce,
    OutputOptions,
    Pressure,
    Problem,
    SolverOptions,
    Steps,
    Traction,
)

EPS = 1e-5
SCORDELIS_LO = 0.3024
PINCHED_CYLINDER = 1.8248e-5
PINCHED_HEMISPHERE = 0.0924

Case = tuple[Problem, Callable[[np.ndarray], float]]


def _body(mesh, material, options: dict) -> Body:
    return Body("shell", mesh, material, formulation="solid-shell", options=dict(options))


def scordelis_lo(n: int, cell: str = "hex8", **options) -> Case:
    """Quarter of the roof (R 25, L 50, t 0.25, 40 degrees, E 4.32e8, nu 0, self weight 90 per area)."""
    R, L, t = 25.0, 50.0, 0.25
    mesh = cylinder_patch(R, L / 2, 0.0, math.radians(40.0), t, n, n, cell=cell, axis="y")
    mesh.add_node_set("A", np.intersect1d(mesh.node_sets["angle1"], mesh.node_sets["end1"]))
    q = 90.0 * R / (R + t / 2)  # the weight per mid-surface area, applied on the outer surface
    prob = Problem(
        "scordelis-lo", [_body(mesh, SaintVenantKirchhoff(E=4.32e8, nu=0.0), options)],
        dirichlet=[Dirichlet("shell", "end0", (0, 2), (0.0, 0.0)),  # rigid diaphragm
                   Dirichlet("shell", "angle0", (0,), (0.0,)),  # symmetry at the crown
                   Dirichlet("shell", "end1", (1,), (0.0,))],  # symmetry at mid-span
        tractions=[Traction("shell", "outer", (0.0, 0.0, -q))],
        steps=Steps((EPS,)), output=OutputOptions(vtu=False))
    return prob, lambda u: -u.reshape(-1, 3)[mesh.node_sets["A"], 2].mean() / EPS


def pinched_cylinder(n: int, cell: str = "hex8", **options) -> Case:
    """One eighth of the cylinder (R 300, L 600, t 3, E 3e6, nu 0.3), P = 1: P/4 on the octant."""
    R, L, t = 300.0, 600.0, 3.0
    mesh = cylinder_patch(R, L / 2, 0.0, math.pi / 2, t, n, n, cell=cell, axis="z")
    mesh.add_node_set("A", np.intersect1d(mesh.node_sets["angle1"], mesh.node_sets["end1"]))
    prob = Problem(
        "pinched-cylinder", [_body(mesh, SaintVenantKirchhoff(E=3e6, nu=0.3), options)],
        dirichlet=[Dirichlet("shell", "end0", (0, 1), (0.0, 0.0)),  # rigid diaphragm
                   Dirichlet("shell", "end1", (2,), (0.0,)),
                   Dirichlet("shell", "angle0", (1,), (0.0,)),
                   Dirichlet("shell", "angle1", (0,), (0.0,))],
        forces=[NodalForce("shell", "A", (0.0, -0.25, 0.0), "total")],
        steps=Steps((EPS,)), output=OutputOptions(vtu=False))
    return prob, lambda u: -u.reshape(-1, 3)[mesh.node_sets["A"], 1].mean() / EPS


def pinched_hemisphere(n: int, cell: str = "hex8", **options) -> Case:
    """Quarter of the hemisphere (R 10, t 0.04, 18 degree hole, E 6.825e7, nu 0.3), F = 1 in and out."""
    R, t = 10.0, 0.04
    mesh = sphere_patch(R, math.radians(18.0), math.pi / 2, 0.0, math.pi / 2, t, n, n, cell=cell)
    ns = mesh.node_sets
    mesh.add_node_set("A", np.intersect1d(ns["theta1"], ns["phi0"]))
    mesh.add_node_set("B", np.intersect1d(ns["theta1"], ns["phi1"]))
    hole = np.intersect1d(np.intersect1d(ns["theta0"], ns["phi0"]), ns["inner"])
    mesh.add_node_set("zfix", hole[:1])  # one node: removes the rigid translation along z
    prob = Problem(
        "pinched-hemisphere", [_body(mesh, SaintVenantKirchhoff(E=6.825e7, nu=0.3), options)],
        dirichlet=[Dirichlet("shell", "phi0", (1,), (0.0,)), Dirichlet("shell", "phi1", (0,), (0.0,)),
                   Dirichlet("shell", "zfix", (2,), (0.0,))],
        forces=[NodalForce("shell", "A", (1.0, 0.0, 0.0), "total"),
                NodalForce("shell", "B", (0.0, -1.0, 0.0), "total")],
        steps=Steps((EPS,)), output=OutputOptions(vtu=False))
    return prob, lambda u: u.reshape(-1, 3)[mesh.node_sets["A"], 0].mean() / EPS


def navier_simply_supported(nu: float, terms: int = 201) -> float:
    """Centre deflection coefficient alpha of a simply supported square plate, w = alpha q a^4 / D
    (Navier double series, Timoshenko & Woinowsky-Krieger: 0.00406 for any nu)."""
    m = np.arange(1, terms + 1, 2, dtype=float)
    M, N = np.meshgrid(m, m)
    sign = np.sin(M * np.pi / 2) * np.sin(N * np.pi / 2)
    return float(16.0 / np.pi**6 * np.sum(sign / (M * N * (M**2 + N**2) ** 2)))


def thin_plate(n: int, cell: str = "hex8", thickness: float = 1e-3, **options) -> Case:
    """Quarter of a simply supported unit square plate (E 1e6, nu 0.3) under a pressure giving a centre
    deflection of 1e-3 t; returns the deflection over the Kirchhoff value."""
    a, E, nu = 1.0, 1e6, 0.3
    mesh = plate(a / 2, a / 2, thickness, n, n, cell=cell)
    mesh.add_node_set("C", np.intersect1d(mesh.node_sets["xmax"], mesh.node_sets["ymax"]))
    D = E * thickness**3 / (12.0 * (1.0 - nu**2))
    w_ref = 1e-3 * thickness
    q = w_ref * D / (navier_simply_supported(nu) * a**4)
    prob = Problem(
        "thin-plate", [_body(mesh, SaintVenantKirchhoff(E=E, nu=nu), options)],
        dirichlet=[Dirichlet("shell", "xmin", (2,), (0.0,)), Dirichlet("shell", "ymin", (2,), (0.0,)),
                   Dirichlet("shell", "xmax", (0,), (0.0,)), Dirichlet("shell", "ymax", (1,), (0.0,))],
        pressures=[Pressure("shell", "top", q)],
        steps=Steps((1.0,)), solver=SolverOptions(atol=1e-6), output=OutputOptions(vtu=False))
    return prob, lambda u: -u.reshape(-1, 3)[mesh.node_sets["C"], 2].mean() / w_ref


def solve(case: Case, out) -> tuple[float, dict]:
    """Run a case; returns the measured value and the run summary."""
    prob, measure = case
    res = prob.run(out=out, quiet=True)
    assert res.exit_code == 0, res.summary["steps"][-1].get("failure")
    return measure(res.u), res.summary


# ---------------------------------------------------------------------------------------------


def test_navier_coefficient():
    # Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, table 8: alpha = 0.00406
    assert navier_simply_supported(0.3) == pytest.approx(0.00406235, rel=1e-5)


@pytest.mark.parametrize("cell,n", [("hex8", 16), ("hex18", 8)])
def test_scordelis_lo(tmp_path, cell, n):
    w, summary = solve(scordelis_lo(n, cell), tmp_path)
    assert abs(w / SCORDELIS_LO - 1.0) < 0.02, w
    assert summary["total_iterations"] <= 3


def test_scordelis_lo_locks_without_cures(tmp_path):
    w, _ = solve(scordelis_lo(8, "hex8", eas=0, ans_shear=False, ans_thickness=False), tmp_path)
    assert w < 0.2 * SCORDELIS_LO  # measured 0.037: transverse shear and thickness locking
    w18, _ = solve(scordelis_lo(4, "hex18", eas=0, ans_shear=False, ans_thickness=False, ans_membrane=False),
                   tmp_path / "18")
    w18c, _ = solve(scordelis_lo(4, "hex18"), tmp_path / "18c")
    assert w18 < 0.9 * SCORDELIS_LO < w18c  # measured 0.250 against 0.305


@pytest.mark.parametrize("cell,n", [("hex8", 32), ("hex18", 16)])
def test_pinched_cylinder(tmp_path, cell, n):
    w, _ = solve(pinched_cylinder(n, cell), tmp_path)
    assert abs(w / PINCHED_CYLINDER - 1.0) < 0.02, w


@pytest.mark.parametrize("cell,n", [("hex8", 16), ("hex18", 8)])
def test_pinched_hemisphere(tmp_path, cell, n):
    w, _ = solve(pinched_hemisphere(n, cell), tmp_path)
    assert abs(w / PINCHED_HEMISPHERE - 1.0) < 0.02, w


@pytest.mark.parametrize("cell,n", [("hex8", 8), ("hex18", 4)])
def test_thin_plate_gives_kirchhoff_deflection(tmp_path, cell, n):
    ratio, _ = solve(thin_plate(n, cell), tmp_path)
    assert abs(ratio - 1.0) < 0.02, ratio
    locked, _ = solve(thin_plate(n, cell, eas=0), tmp_path / "locked")
    assert locked < 0.9  # Poisson thickness locking without EAS: (1 - 2 nu) / (1 - nu)^2 = 0.82
