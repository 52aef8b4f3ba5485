"""Lame's thick cylinder under internal pressure, as a planar body (docs/verification.md, "Planar bodies").

Closed form (Timoshenko and Goodier, Theory of Elasticity, 3rd ed., section 33; linear elasticity, inner radius a,
outer b, internal pressure p, free outer surface): sigma_r = A (1 - b^2 / r^2), sigma_theta = A (1 + b^2 / r^2) with
A = p a^2 / (b^2 - a^2), and

- plane strain (eps_z = 0; an axisymmetric tube with fixed ends): u_r = (1 + nu) A / E ((1 - 2 nu) r + b^2 / r);
- free ends (sigma_z = 0; an axisymmetric tube whose end may move): u_r = A / E ((1 - nu) r + (1 + nu) b^2 / r).

A small load (p / E = 1e-5) makes the finite-strain solution the linear one to well within the tolerance. quad8 cells:
a quarter annulus of 8 x 4 (plane strain), a wall of 8 x 2 cells (axisymmetric). Checked: the radial displacement
at the inner radius and the hoop stress at every Gauss point against the closed form at that point, within 0.5 %
of the hoop stress at the bore.
"""

from __future__ import annotations

import textwrap

import meshio
import numpy as np
import pytest

from covcontact.io.loader import load_problem

A_IN, B_OUT, E, NU, P = 1.0, 2.0, 1000.0, 0.3, 0.01
CA = P * A_IN**2 / (B_OUT**2 - A_IN**2)


def u_plane_strain(r):
    return (1 + NU) * CA / E * ((1 - 2 * NU) * r + B_OUT**2 / r)


def u_free_ends(r):
    return CA / E * ((1 - NU) * r + (1 + NU) * B_OUT**2 / r)


def hoop(r):
    return CA * (1 + B_OUT**2 / r**2)


BODY = {
    "plane_strain": 'mesh = { generator = "annulus", r_inner = 1.0, r_outer = 2.0, nr = 8, nt = 4 }',
    "axisymmetric": 'mesh = { generator = "rectangle", lx = 1.0, ly = 0.5, nx = 8, ny = 2, origin = [1.0, 0.0] }',
}
HOLD = {
    "plane_strain": [("angle0", "y"), ("angle1", "x")],
    "fixed_ends": [("ymin", "y"), ("ymax", "y")],
    "free_ends": [("ymin", "y")],
}


def run(tmp_path, case: str):
    form = "plane_strain" if case == "plane_strain" else "axisymmetric"
    inner = "inner" if form == "plane_strain" else "xmin"
    conds = "\n".join(f'[[dirichlet]]\nset = "tube.{s}"\ncomponents = "{c}"\nvalue = 0.0\n' for s, c in HOLD[case])
    text = textwrap.dedent(f"""
        [problem]
        name = "lame_{case}"

        [[bodies]]
        name = "tube"
        formulation = "{form}"
        element = "quad8"
        {BODY[form]}
        material = {{ model = "svk", E = {E}, nu = {NU} }}

        [[pressure]]
        set = "tube.{inner}"
        value = {P}
        """) + conds
    path = tmp_path / f"{case}.toml"
    path.write_text(text)
    prob = load_problem(path)
    res = prob.run(out=tmp_path / case)
    assert res.exit_code == 0
    return prob, res


@pytest.mark.parametrize("case", ["plane_strain", "fixed_ends", "free_ends"])
def test_lame_thick_cylinder(tmp_path, case):
    prob, res = run(tmp_path, case)
    u = np.asarray(res.u).reshape(-1, 3)
    body = res.model.system.blocks[0].solid
    X = body.X
    r = np.hypot(X[:, 0], X[:, 1])
    bore = np.isclose(r, A_IN)
    ur = (u[bore, 0] * X[bore, 0] + u[bore, 1] * X[bore, 1]) / r[bore]
    exact_u = u_free_ends(A_IN) if case == "free_ends" else u_plane_strain(A_IN)
    err_u = np.abs(ur / exact_u - 1).max()
    assert err_u < 5e-3
    assert np.all(u[:, 2] == 0.0)
    # hoop stress at the Gauss points: sigma_33 (axisymmetric), or sigma_tt = n_t . sigma n_t (plane strain)
    sig = body.gauss_cauchy(u[: body.n_nodes])
    g = body.gauss_points()
    rg = np.hypot(g[..., 0], g[..., 1]) if case == "plane_strain" else g[..., 0]
    if case == "plane_strain":
        c, s = g[..., 0] / rg, g[..., 1] / rg
        st = s * s * sig[..., 0] + c * c * sig[..., 1] - 2 * s * c * sig[..., 3]
    else:
        st = sig[..., 2]
    err_s = np.abs(st - hoop(rg)).max() / hoop(A_IN)
    assert err_s < 5e-3
    print(f"{case}: u_r(a) error {err_u:.2e}, hoop stress error {err_s:.2e} (of sigma_theta(a))")
    vtu = meshio.read(sorted((tmp_path / case).glob("step_*.vtu"))[-1])
    assert vtu.cells[0].type == "quad8" and "cauchy" in vtu.cell_data
