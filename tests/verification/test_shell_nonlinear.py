"""Geometrically nonlinear shell benchmarks with the solid-shell elements (dead loads, load control).

Reference values: K.Y. Sze, X.H. Liu, S.H. Lo, "Popular benchmark problems for geometric nonlinear
analysis of shells", Finite Elements in Analysis and Design 40 (2004) 1551-1569, doi
10.1016/j.finel.2003.11.001 (their tables, as transcribed in the MBDyn test suite, tests/plates/sze2004):
- 3.1 cantilever under an end shear force (L 10, b 1, h 0.1, E 1.2e6, nu 0, P_max = 4):
  tip -U / W = 1.604 / 4.933 at P/P_max = 0.5 and 3.286 / 6.698 at 1;
- 3.3 slit annular plate under a lifting line force (R_i 6, R_o 10, h 0.03, E 21e6, nu 0, 0.8 per
  length): W_A (inner) / W_B (outer) = 10.468 / 13.768 at 0.5 and 13.891 / 17.528 at 1 (their table 4);
- 3.5 pull-out of an open-ended cylinder (R 4.953, L 10.35, h 0.094, E 10.5e6, nu 0.3125,
  P_max = 40000): W_A, -U_B, -U_C = 1.707, 2.217, 2.293 at P/P_max = 0.1; 2.079, 2.904, 3.106 at 0.2;
  2.376, 3.443, 3.632 at 0.4 (beyond about 0.5 the shell snaps; see benchmarks/shells.py).
The end moment (3.2) rolls the strip into a circle only as a follower moment: a follower pressure on the end face
that varies linearly through the thickness (``profile``) is one; its reference is the closed form of the
inextensible strip, whose curvature is M / EI (Sze et al. tabulate it at M / M_max = 0.05, 0.1, ..., 1). With dead
loads a dead force couple on the end fibres bends the strip into a circular arc whose end rotation solves
phi = F h cos(phi) L / (E I) (the dead-moment elastica).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import cylinder_patch, plate
from covcontact.problem import Body, Dirichlet, NodalForce, OutputOptions, Pressure, Problem, SolverOptions, Steps

SZE_CANTILEVER = {0.5: (1.604, 4.933), 1.0: (3.286, 6.698)}
SZE_ANNULUS = {0.5: (10.468, 13.768), 1.0: (13.891, 17.528)}
SZE_PULLOUT = {0.1: (1.707, 2.217, 2.293), 0.2: (2.079, 2.904, 3.106), 0.4: (2.376, 3.443, 3.632)}


def edge_forces(mesh, nodes: np.ndarray, coord: np.ndarray, total: np.ndarray, name: str) -> list[NodalForce]:
    """Consistent nodal forces of a uniform line load ``total`` spread along ``coord`` over the edge
    nodes (both layers share each station); adds one node set per station."""
    nodes = np.asarray(nodes)
    c = coord[nodes]
    st = np.unique(np.round(c, 9))
    quad = mesh.cell_type == "hex18"
    w = np.zeros(st.size)
    for e in range((st.size - 1) // 2 if quad else st.size - 1):
        if quad:
            L = st[2 * e + 2] - st[2 * e]
            w[2 * e: 2 * e + 3] += np.array([1.0, 4.0, 1.0]) * L / 6.0
        else:
            w[e: e + 2] += 0.5 * (st[e + 1] - st[e])
    w /= w.sum()
    loads = []
    for k, v in enumerate(st):
        sel = nodes[np.abs(c - v) < 1e-9]
        mesh.add_node_set(f"{name}{k}", sel)
        loads.append(NodalForce("shell", f"{name}{k}", tuple(np.asarray(total) * w[k] / sel.size)))
    return loads


def _solver(atol: float = 1e-5) -> SolverOptions:
    # Thin shells: the residual cannot fall below ~ eps E A (round-off of the thickness stresses), far
    # above rtol R_0 under small load increments; the force criterion is relative to the load (atol)
    # and the energy criterion (etol) does the rest.
    return SolverOptions(rtol=1e-10, atol=atol, max_iterations=30)


def run(prob: Problem, out):
    res = prob.run(out=out, quiet=True)
    assert res.exit_code == 0, res.summary["steps"][-1].get("failure")
    return res


def cantilever_shear(nx: int, cell: str = "hex8", steps: int = 10, **options):
    L, b, h, E, P = 10.0, 1.0, 0.1, 1.2e6, 4.0
    mesh = plate(L, b, h, nx, 1, cell=cell)
    loads = edge_forces(mesh, mesh.node_sets["xmax"], mesh.points[:, 1], np.array([0.0, 0.0, P]), "tip")
    prob = Problem("sze-3.1", [Body("shell", mesh, SaintVenantKirchhoff(E=E, nu=0.0), "solid-shell", options)],
                   dirichlet=[Dirichlet("shell", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))], forces=loads,
                   steps=Steps.equal(steps), solver=_solver(1e-8), output=OutputOptions(vtu=False))
    tip = mesh.node_sets["xmax"]
    return prob, lambda u: (-u.reshape(-1, 3)[tip, 0].mean(), u.reshape(-1, 3)[tip, 2].mean())


def end_couple(nx: int, cell: str = "hex8", k: float = 4.0, steps: int = 8, **options):
    """Dead force couple F (top fibre -x, bottom +x) on the end of a clamped strip, F h L / EI = k."""
    L, b, h, E = 12.0, 1.0, 0.1, 1.2e6
    EI = E * b * h**3 / 12.0
    F = k * EI / (h * L)
    mesh = plate(L, b, h, nx, 1, cell=cell)
    ns = mesh.node_sets
    y = mesh.points[:, 1]
    loads = (edge_forces(mesh, np.intersect1d(ns["xmax"], ns["top"]), y, np.array([-F, 0.0, 0.0]), "top")
             + edge_forces(mesh, np.intersect1d(ns["xmax"], ns["bottom"]), y, np.array([F, 0.0, 0.0]), "bot"))
    prob = Problem("couple", [Body("shell", mesh, SaintVenantKirchhoff(E=E, nu=0.0), "solid-shell", options)],
                   dirichlet=[Dirichlet("shell", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))], forces=loads,
                   steps=Steps.equal(steps), solver=_solver(1e-8), output=OutputOptions(vtu=False))
    return prob, mesh, F, EI


def slit_annular_plate(nr: int, nt: int, cell: str = "hex8", steps: int = 20, **options):
    Ri, Ro, h, E = 6.0, 10.0, 0.03, 21e6
    mesh = plate(Ro - Ri, 2.0 * math.pi, h, nr, nt, cell=cell)
    x, theta, z = mesh.points.T.copy()
    r = Ri + x
    mesh.points = np.ascontiguousarray(np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=1))
    free = mesh.node_sets["ymax"]  # theta = 2 pi, the loaded side of the slit; theta = 0 is clamped
    loads = edge_forces(mesh, free, r, np.array([0.0, 0.0, 0.8 * (Ro - Ri)]), "line")
    A, B = free[np.abs(r[free] - Ri) < 1e-9], free[np.abs(r[free] - Ro) < 1e-9]
    prob = Problem("sze-3.3", [Body("shell", mesh, SaintVenantKirchhoff(E=E, nu=0.0), "solid-shell", options)],
                   dirichlet=[Dirichlet("shell", "ymin", (0, 1, 2), (0.0, 0.0, 0.0))], forces=loads,
                   steps=Steps.equal(steps), solver=_solver(), output=OutputOptions(vtu=False))
    return prob, lambda u: (u.reshape(-1, 3)[A, 2].mean(), u.reshape(-1, 3)[B, 2].mean())


def pullout(nc: int, nl: int, cell: str = "hex8", factors=(0.1, 0.2, 0.3, 0.4), **options):
    """One eighth of the cylinder: axis y, mid-section y = L/2 (symmetry), free end y = 0, the load
    P/4 at A (mid-section, top); B mid-section at 90 degrees, C free end at 90 degrees."""
    R, L, h, E, nu, P = 4.953, 10.35, 0.094, 10.5e6, 0.3125, 40000.0
    mesh = cylinder_patch(R, L / 2, 0.0, math.pi / 2, h, nc, nl, cell=cell, axis="y")
    ns = mesh.node_sets
    mesh.add_node_set("A", np.intersect1d(ns["end1"], ns["angle0"]))
    mesh.add_node_set("B", np.intersect1d(ns["end1"], ns["angle1"]))
    mesh.add_node_set("C", np.intersect1d(ns["end0"], ns["angle1"]))
    prob = Problem("sze-3.5", [Body("shell", mesh, SaintVenantKirchhoff(E=E, nu=nu), "solid-shell", options)],
                   dirichlet=[Dirichlet("shell", "angle0", (0,), (0.0,)), Dirichlet("shell", "angle1", (2,), (0.0,)),
                              Dirichlet("shell", "end1", (1,), (0.0,))],
                   forces=[NodalForce("shell", "A", (0.0, 0.0, P / 4), "total")],
                   steps=Steps(tuple(factors)), solver=_solver(), output=OutputOptions(vtu=False))

    def measure(u):
        U = u.reshape(-1, 3)
        return U[ns["A"], 2].mean(), -U[ns["B"], 0].mean(), -U[ns["C"], 0].mean()

    return prob, measure


def run_curve(prob: Problem, measure, table: dict, out, per_point: int = 1):
    """Run ``prob`` with ``per_point`` equal steps between the tabulated load fractions of ``table`` (fraction ->
    reference values), results written at each; returns (measured, reference) arrays over the fractions reached
    (all of them unless the run stopped early) and the run's result."""
    import xml.etree.ElementTree as ET

    import meshio

    points = sorted(table)
    factors, prev = [], 0.0
    for f in points:
        factors += [prev + (f - prev) * (k + 1) / per_point for k in range(per_point)]
        prev = f
    prob.steps = Steps(tuple(factors))
    prob.output = OutputOptions(vtu=True)
    res = prob.run(out=out, quiet=True)
    files = {round(float(d.get("timestep")), 9): d.get("file") for d in ET.parse(Path(out) / "result.pvd").iter("DataSet")}
    got, want = [], []
    for f in points:
        if round(f, 9) not in files:
            break
        got.append(measure(meshio.read(Path(out) / files[round(f, 9)]).point_data["displacement"]))
        want.append(table[f])
    return np.abs(np.array(got)), np.abs(np.array(want)), res


def curve_error(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    """Per curve (column): the largest |measured - reference| over its points over its largest reference value."""
    return np.abs(got - want).max(axis=0) / np.abs(want).max(axis=0)


# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("cell,nx", [("hex8", 16), ("hex18", 8)])
def test_cantilever_end_shear(tmp_path, cell, nx):
    for frac, steps in ((0.5, 5), (1.0, 10)):
        prob, measure = cantilever_shear(nx, cell, steps=steps)
        prob.steps = Steps.equal(steps, frac)
        res = run(prob, tmp_path / str(frac))
        mU, W = measure(res.u)
        rU, rW = SZE_CANTILEVER[frac]
        assert abs(mU / rU - 1.0) < 0.01 and abs(W / rW - 1.0) < 0.01, (frac, mU, W)
    for s in res.summary["steps"]:  # Newton: quadratic convergence to the round-off floor
        r = s["residual_norms"]
        assert s["iterations"] <= 10 and r[-1] < max(1e-7, 1e-8 * max(r[:2])) and min(r[-3:]) < 1e-3 * max(r[-5:-2])


@pytest.mark.parametrize("cell,nx", [("hex8", 16), ("hex18", 8)])
def test_cantilever_end_shear_at_every_tabulated_point(tmp_path, cell, nx):
    """Sze 3.1 at all 20 tabulated load levels (one step each): -U and W within 0.5 % of the curve's largest value
    (measured 0.22 % / 0.10 % for hex8 16 x 1, 0.12 % / 0.04 % for hex18 8 x 1)."""
    from sze2004 import CANTILEVER_SHEAR

    prob, measure = cantilever_shear(nx, cell)
    got, want, res = run_curve(prob, measure, CANTILEVER_SHEAR, tmp_path)
    assert res.exit_code == 0 and len(got) == 20
    assert np.all(curve_error(got, want) < 0.005), curve_error(got, want)


@pytest.mark.parametrize("cell,nx", [("hex8", 16), ("hex18", 8)])
def test_dead_end_couple_bends_strip_into_circular_arc(tmp_path, cell, nx):
    k = 4.0
    prob, mesh, F, EI = end_couple(nx, cell, k=k)
    res = run(prob, tmp_path)
    X = mesh.points
    x = X + res.u.reshape(-1, 3)
    h, L = 0.1, 12.0
    bot = np.flatnonzero(np.isclose(X[:, 2], 0.0))
    top = np.flatnonzero(np.isclose(X[:, 2], h))
    bot = bot[np.lexsort((X[bot, 1], X[bot, 0]))]
    top = top[np.lexsort((X[top, 1], X[top, 0]))]
    mid = 0.5 * (x[bot] + x[top])
    fibre = (x[top] - x[bot])[-1]
    phi = math.atan2(-fibre[0], fibre[2])
    # circle through the clamped mid-surface point (0, y, h/2) tangent to x: centre (0, y, h/2 + rho)
    e = mid[-1]
    rho = (e[0] ** 2 + (e[2] - h / 2) ** 2) / (2.0 * (e[2] - h / 2))
    dev = np.abs(np.hypot(mid[:, 0], mid[:, 2] - h / 2 - rho) - rho).max()
    assert dev <= 1e-4 * rho  # a circle up to the local effect of the concentrated end forces
    phi_ref = brentq(lambda p: p - k * math.cos(p), 0.0, math.pi / 2)  # phi = F h cos(phi) L / EI
    assert abs(phi / phi_ref - 1.0) < 2e-3, (phi, phi_ref)
    assert abs(rho * phi / L - 1.0) < 2e-3  # the mid-surface keeps its length
    M = F * fibre[2]  # moment of the dead couple on the rotated end fibre
    assert abs((phi / L) / (M / EI) - 1.0) < 2e-3  # curvature = M / EI


def end_moment(nx: int, steps: int = 20):
    """Sze 3.2: the strip (L 12, b 1, h 0.1, E 1.2e6, nu 0) clamped, M_max = 2 pi EI / L at its end as a follower
    pressure linear through the thickness, p = M 12 (Z - h / 2) / (b h^3); measures the tip's mid-surface (-U, W)."""
    L, b, h, E = 12.0, 1.0, 0.1, 1.2e6
    EI = E * b * h ** 3 / 12.0
    mesh = plate(L, b, h, nx, 1, cell="hex8")
    profile = (-6.0 / (b * h * h), 0.0, 0.0, 12.0 / (b * h ** 3))
    prob = Problem("sze-3.2", [Body("shell", mesh, SaintVenantKirchhoff(E=E, nu=0.0), "solid-shell", {})],
                   dirichlet=[Dirichlet("shell", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))],
                   pressures=[Pressure("shell", "xmax", 2.0 * math.pi * EI / L, follower=True, profile=profile)],
                   steps=Steps.equal(steps), solver=_solver(1e-8), output=OutputOptions(vtu=False))
    tip = mesh.node_sets["xmax"]
    return prob, lambda u: (-u.reshape(-1, 3)[tip, 0].mean(), u.reshape(-1, 3)[tip, 2].mean())


def strip_circle(fraction: float) -> tuple[float, float]:
    """(-U, W) of the tip of the inextensible strip of Sze 3.2 under M = fraction M_max (curvature M / EI)."""
    L = 12.0
    k = fraction * 2.0 * math.pi / L
    return L - math.sin(k * L) / k, (1.0 - math.cos(k * L)) / k


def test_follower_end_moment_rolls_strip_into_a_circle(tmp_path):
    """Sze 3.2: the strip (L 12, b 1, h 0.1, E 1.2e6, nu 0) under an end moment up to M_max = 2 pi EI / L, which rolls
    it into a full circle: M as a follower pressure on the end face, p = M 12 (Z - h / 2) / (b h^3) (``profile``),
    20 equal steps. At every tabulated M / M_max the tip's mid-surface displacement against the closed form
    -U = L - sin(kL) / k, W = (1 - cos(kL)) / k with k = M / EI: within 1 % of L on 32 hex8 solid-shells (measured
    0.74 % at the full circle, where the error is largest; 2.79 % with 16, 0.25 % with 64)."""
    prob, measure = end_moment(32)
    got, want, res = run_curve(prob, measure, {k / 20: strip_circle(k / 20) for k in range(1, 21)}, tmp_path)
    assert res.exit_code == 0 and len(got) == 20
    worst = float(np.abs(got - want).max() / 12.0)
    assert worst < 0.01, worst


@pytest.mark.parametrize("cell,mesh", [("hex8", (6, 30)), ("hex18", (3, 15))])
def test_slit_annular_plate(tmp_path, cell, mesh):
    prob, measure = slit_annular_plate(*mesh, cell=cell, steps=20)
    res = run(prob, tmp_path)
    wa, wb = measure(res.u)
    ra, rb = SZE_ANNULUS[1.0]
    # coarse meshes (Sze et al. used 10 x 80 shell elements): 3-4 % low, 1 % on 10 x 60 (report)
    assert -0.05 < wa / ra - 1.0 < 0.01 and -0.05 < wb / rb - 1.0 < 0.01, (wa, wb)
    assert res.summary["total_iterations"] < 700


def test_pullout_of_open_cylinder(tmp_path):
    out = {}
    for frac, ref in SZE_PULLOUT.items():
        factors = [f for f in (0.1, 0.2, 0.3, 0.4) if f <= frac]
        prob, measure = pullout(16, 12, "hex8", factors=factors)
        res = run(prob, tmp_path / str(frac))
        out[frac] = measure(res.u)
        for got, want in zip(out[frac], ref, strict=True):
            assert abs(got / want - 1.0) < 0.015, (frac, out[frac])
    assert res.summary["total_iterations"] <= 60  # measured 48 (20 in the first step)
