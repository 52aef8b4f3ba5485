"""Hertz contact: an elastic half-ball pressed onto a rigid plane.

Reference: H. Hertz, J. reine angew. Math. 92 (1882) 156-171; K. L. Johnson, Contact Mechanics (1985),
section 4.2. A sphere of radius R on a rigid plane, 1/E* = (1 - nu^2)/E, indentation d << R:
F = 4/3 E* R^(1/2) d^(3/2), contact radius a = sqrt(R d), p(r) = p0 sqrt(1 - r^2/a^2) with
p0 = 2 E* a / (pi R) = 3 F / (2 pi a^2).

Set-up: the quarter (x >= 0, y >= 0) of ``hemisphere_solid`` graded toward the pole, symmetry planes
x = 0 and y = 0, the flat face z = R moved down by d with its in-plane motion free (a clamped face
adds about 2 % of stiffness at d = 0.01 R), the curved face the slave of a rigid plane z = 0.

Hertz is the linear-elastic limit d/R -> 0. At d/R = 0.01 the strains under the contact are about
p0/E* = 6 %, and the first corrections to Hertz are of relative order sqrt(d/R): with Neo-Hooke the
force lies 1 % above Hertz at d = 0.001 R and about 5 % above at d = 0.01 R, with St. Venant-Kirchhoff
within about 1 % (converged meshes, docs/verification.md). The leading coefficient C of
F = C d^1.5 + B d^2, fitted over 0.001 <= d/R <= 0.01, is the Hertz coefficient for both laws.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hertz_setup import (  # noqa: F401  (the names other modules import from here)
    C_HERTZ,
    D_MAX,
    E_STAR,
    MATERIALS,
    NU,
    E,
    R,
    fit_hertz,
    grade_to_pole,
    hertz_measures,
    hertz_mesh,
    hertz_problem,
    quarter,
)

from covcontact.contact.surface import tributary_area
from covcontact.mesh import check_orientation


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One run per material on the CI mesh (hex8, n = 16: 7395 dofs, 10 steps up to d = 0.01 R)."""
    mesh = hertz_mesh()
    assert check_orientation(mesh) == []
    out = {}
    for material in MATERIALS:
        res = hertz_problem(mesh, material).run(out=tmp_path_factory.mktemp(material))
        assert res.exit_code == 0
        out[material] = hertz_measures(res, mesh)
    return out


def test_mesh_is_graded_and_exact():
    mesh = hertz_mesh()
    P = mesh.points
    curved = mesh.node_sets["curved"]
    assert np.allclose(np.linalg.norm(P[curved] - [0.0, 0.0, R], axis=1), R, atol=1e-12)
    assert np.allclose(P[mesh.node_sets["flat"], 2], R, atol=1e-12)
    # surface nodes along the x axis: eight within r < 0.13 R, so the contact radius 0.032 R to 0.1 R
    # spans 3 to 6 elements (the ungraded focus = 0.12, n = 12 mesh has 2.5 at a = 0.1 R)
    on_axis = curved[(np.abs(P[curved, 1]) < 1e-12) & (P[curved, 2] < 0.5 * R)]
    r = np.sort(P[on_axis, 0])
    assert np.count_nonzero(r < 0.13 * R) >= 8
    assert r[1] < 0.011 * R


@pytest.mark.parametrize("material", list(MATERIALS))
def test_force_indentation_leading_coefficient(runs, material):
    """C of F = C d^1.5 + B d^2 over 0.001 <= d/R <= 0.01 within 2 % of 4/3 E* sqrt(R) (measured:
    Neo-Hooke 0.996, St. Venant-Kirchhoff 1.000)."""
    m = runs[material]
    assert m["C2"] == pytest.approx(1.0, abs=0.02), m
    # the d^2 term is the first-order (sqrt(d/R)) correction: positive for both laws here
    assert m["B"] > 0.0


@pytest.mark.parametrize("material, d_upto, tol", [("svk", 0.01, 0.05), ("neo-hooke", 0.002, 0.05),
                                                    ("neo-hooke", 0.01, 0.08)])
def test_force_indentation_pointwise(runs, material, d_upto, tol):
    """F / F_Hertz(d) pointwise: St. Venant-Kirchhoff within 5 % up to d = 0.01 R (measured 0.998 to 1.024);
    Neo-Hooke within 5 % up to 0.002 R (1.010, 1.022) and within 8 % up to 0.01 R (max 1.067)."""
    m = runs[material]
    sel = m["d"] <= d_upto * R + 1e-12
    assert np.all(np.abs(m["ratio"][sel] - 1.0) < tol), m["ratio"]
    # the one-term fit (measured 1.021, 1.060) and the growth of the deviation with d
    assert m["C1"] == pytest.approx(1.0, abs=0.07)
    assert m["ratio"][-1] > m["ratio"][0]


@pytest.mark.parametrize("material", list(MATERIALS))
def test_contact_radius(runs, material):
    """a from the nodal forces within 4 % of sqrt(R d) at every step (measured: within 1.7 % for
    Neo-Hooke, 3.3 % for St. Venant-Kirchhoff)."""
    m = runs[material]
    assert np.all(np.abs(m["a_ratio"] - 1.0) < 0.04), m["a_ratio"]
    # the contact radius grows at every step
    assert np.all(np.diff(m["a_ratio"] * np.sqrt(m["d"])) > 0.0)


@pytest.mark.parametrize("material, tol", [("neo-hooke", 0.02), ("svk", 0.11)])
def test_central_pressure(runs, material, tol):
    """VTU contact_pressure against p0 sqrt(1 - r^2/a^2) for r < a/2, relative to p0. Neo-Hooke within
    0.7 % at every step; St. Venant-Kirchhoff falls below by 0.86 to 0.97 sqrt(d/R) (2.7 % at d = 0.001 R,
    9.5 % at 0.01 R), the finite-strain softening of that law in compression (the contact pressure is
    force per reference area)."""
    m = runs[material]
    assert np.all(m["p_center_error"] < tol), m["p_center_error"]
    if material == "svk":
        # the deviation scales like the strain, sqrt(d/R), not like a mesh error
        k = m["p_center_error"] / np.sqrt(m["d"] / R)
        assert np.all((k > 0.6) & (k < 1.1)), k


@pytest.mark.parametrize("typ", ["nts", "sts"])
def test_pressure_profile(tmp_path, typ):
    """The whole pressure distribution, not only the force: the nodal contact_pressure field against
    p0 sqrt(1 - r^2/a^2) at d = 0.01 R (Neo-Hooke, the CI mesh, 4 steps) within 3 % of p0 for r < 0.8 a, away
    from the edge of the contact zone, where the mesh's element size (about 0.1 a there) smears the drop of the
    square root; and the contact radius from the nodal forces (a_m, as in hertz_measures) within 3 % of
    sqrt(R d). Measured: node-to-surface 0.71 % (r < a/2), 0.82 % (r < 0.7 a), 2.51 % (r < 0.8 a);
    segment-to-surface (2 x 2 points per facet) 0.77 %, 0.77 %, 2.60 %; both 5.5 % to 5.7 % up to 0.9 a."""
    mesh = hertz_mesh()
    prob = hertz_problem(mesh, "neo-hooke", steps=(0.1, 0.3, 0.6, 1.0), vtu=False)
    prob.contacts[0].type = typ
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    model = res.model
    x = model.positions(res.u)
    pd = model.contact.point_data(model.system.n_nodes, res.state.contact)
    a = math.sqrt(R * D_MAX)
    p0 = 2.0 * E_STAR * a / (math.pi * R)
    r = np.hypot(x[:, 0], x[:, 1])
    p = pd["contact_pressure"]
    on = pd["contact_status"] >= 0
    sel = on & (r < 0.8 * a)
    assert sel.sum() > 30
    assert np.max(np.abs(p[sel] - p0 * np.sqrt(1.0 - (r[sel] / a) ** 2))) < 0.03 * p0
    f = p * tributary_area(mesh.points, mesh.face_sets["curved"])
    act = pd["contact_status"] > 0.5
    a_m = math.sqrt(2.5 * np.sum(f[act] * r[act] ** 2) / np.sum(f[act]))
    assert abs(a_m / a - 1.0) < 0.03, a_m / a
