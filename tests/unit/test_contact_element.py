"""Tangent checks of the covariant contact element (docs/verification.md "Contact element and contact
problems").

Reference for all signs: docs/theory.md sections 3-5 (exact Hessian of W_c = 1/2 eps <g>^2).
"""

import numpy as np
import pytest

from covcontact.contact import CASES, PART_NAMES, contact_batch, node_to_surface
from covcontact.contact.element import contact_element
from covcontact.contact.geometry import facet_geometry, surface_shapes
from covcontact.contact.projection import project_on_facet
from covcontact.fem.shapes import NODES, shape_functions

EPS_N = 7.0
FACETS = [(4, False), (4, True), (9, False), (9, True)]


def make_facet(nen, curved, seed):
    """A valid, perturbed quad4/quad9 facet of size ~2; curved: a convex dome, h negative definite."""
    rng = np.random.default_rng(seed)
    P = NODES["quad4" if nen == 4 else "quad9"].astype(float)
    xyz = np.column_stack([P[:, 0], P[:, 1], np.zeros(nen)])
    xyz[:, :2] += 0.08 * rng.standard_normal((nen, 2))
    if curved:
        R = 1.5
        x, y = xyz[:, 0], xyz[:, 1]
        xyz[:, 2] = -(x**2 + 0.5 * y**2 + 0.3 * x * y) / (2 * R) + 0.03 * rng.standard_normal(nen)
    # a rigid rotation and shift so that nothing depends on the global axes
    th = rng.uniform(0, 2 * np.pi)
    Q = np.array([[np.cos(th), 0, np.sin(th)], [0, 1, 0], [-np.sin(th), 0, np.cos(th)]])
    return xyz @ Q.T + rng.uniform(-1, 1, 3)


def geom(xyz, xi):
    nen = xyz.shape[0]
    out = {
        "N": np.empty(nen),
        "dN": np.empty((nen, 2)),
        "ddN": np.empty((nen, 2, 2)),
        "rho": np.empty(3),
        "rho_cov": np.empty((2, 3)),
        "a_cov": np.empty((2, 2)),
        "a_con": np.empty((2, 2)),
        "n": np.empty(3),
        "h_cov": np.empty((2, 2)),
    }
    out["area"] = facet_geometry(xyz, xi[0], xi[1], *out.values())
    return out


def slave_at(xyz, xi, g):
    """Slave point whose projection is xi with normal gap g."""
    G = geom(xyz, xi)
    return G["rho"] + g * G["n"]


def residual(x, nen, xi_start, eps=EPS_N):
    """Residual with re-projection, for dof vector x (master nodes first, slave last)."""
    xyz = x[:-3].reshape(nen, 3).copy()
    xs = x[-3:].copy()
    xi = xi_start.copy()
    status, _ = project_on_facet(xyz, xs, xi)
    assert status == 0
    m = 3 * (nen + 1)
    R, K, P = np.zeros(m), np.zeros((m, m)), np.zeros((1, 1, 1))
    g = contact_element(xyz, xs, xi, eps, CASES["exact"], False, R, K, P)
    return R, g


def fd_tangent(xyz, xs, xi, h=1e-6):
    x = np.concatenate([xyz.ravel(), xs])
    m = x.size
    K = np.zeros((m, m))
    for k in range(m):
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        K[:, k] = (residual(xp, xyz.shape[0], xi)[0] - residual(xm, xyz.shape[0], xi)[0]) / (2 * h)
    return K


def rel(A, B):
    return np.linalg.norm(A - B) / np.linalg.norm(B)


def case_sum(P, *names):
    return sum(P[n] for n in names)


def test_surface_shapes_match_fem_shapes():
    pts = np.array([[0.3, -0.7], [1.4, 0.2]])
    for cell, nen in (("quad4", 4), ("quad9", 9)):
        N, dN, ddN = shape_functions(cell, pts)
        for p in range(2):
            n, dn, ddn = np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2))
            surface_shapes(nen, pts[p, 0], pts[p, 1], n, dn, ddn)
            np.testing.assert_allclose(n, N[p], atol=1e-14)
            np.testing.assert_allclose(dn, dN[p], atol=1e-14)
            np.testing.assert_allclose(ddn, ddN[p], atol=1e-14)


def test_geometry_signs_on_a_sphere_patch():
    # quad9 facet on a sphere of radius R (outward node order): h negative definite, h ~ -a / R,
    # Weingarten n_,i = -h_ij a^jk rho_k (docs/theory.md section 3)
    R = 3.0
    P = NODES["quad9"] * 0.4
    z = np.sqrt(R**2 - P[:, 0] ** 2 - P[:, 1] ** 2)
    xyz = np.column_stack([P[:, 0], P[:, 1], z])
    xi = np.array([0.2, -0.1])
    G = geom(xyz, xi)
    assert G["n"][2] > 0.99
    assert np.all(np.linalg.eigvalsh(G["h_cov"]) < 0)
    np.testing.assert_allclose(G["h_cov"], -G["a_cov"] / R, rtol=2e-2)
    d = 1e-6
    for i in range(2):
        e = np.zeros(2)
        e[i] = d
        dn = (geom(xyz, xi + e)["n"] - geom(xyz, xi - e)["n"]) / (2 * d)
        weingarten = -G["h_cov"][i] @ G["a_con"] @ G["rho_cov"]
        np.testing.assert_allclose(dn, weingarten, atol=1e-8)


@pytest.mark.parametrize("nen,curved", FACETS)
@pytest.mark.parametrize("g", [-1e-1, -1e-2, -1e-3])
def test_exact_tangent_matches_fd(nen, curved, g):
    xyz = make_facet(nen, curved, seed=nen + 10 * curved)
    xi0 = np.array([0.23, -0.31])
    xs = slave_at(xyz, xi0, g)
    r = node_to_surface(xyz, xs, EPS_N, "exact")
    assert r.status == 0 and r.inside
    np.testing.assert_allclose(r.xi, xi0, atol=1e-10)
    assert r.gap == pytest.approx(g, rel=1e-9)
    Kfd = fd_tangent(xyz, xs, r.xi)
    assert rel(r.tangent, Kfd) < 1e-6
    # the parts add up to the exact Hessian
    assert rel(case_sum(r.parts, *PART_NAMES), r.tangent) < 1e-13


@pytest.mark.parametrize("nen,curved", FACETS)
def test_residual_is_gradient_of_penalty_energy(nen, curved):
    xyz = make_facet(nen, curved, seed=3 + nen)
    xs = slave_at(xyz, np.array([-0.4, 0.5]), -0.03)
    r = node_to_surface(xyz, xs, EPS_N, "a")
    x = np.concatenate([xyz.ravel(), xs])
    h = 1e-6
    grad = np.zeros(x.size)
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += h
        xm[k] -= h
        gp = residual(xp, nen, r.xi)[1]
        gm = residual(xm, nen, r.xi)[1]
        grad[k] = 0.5 * EPS_N * (min(gp, 0) ** 2 - min(gm, 0) ** 2) / (2 * h)
    assert rel(r.residual, grad) < 1e-7
    # the force on the slave pushes it out of the master: -R(slave) = eps |g| n
    np.testing.assert_allclose(-r.residual[-3:], EPS_N * abs(r.gap) * r.normal, rtol=1e-12)


@pytest.mark.parametrize("nen,curved", FACETS)
def test_case_a_is_second_order_in_g(nen, curved):
    xyz = make_facet(nen, curved, seed=20 + nen + curved)
    xi0 = np.array([0.1, 0.35])
    diffs = []
    for g in (-1e-2, -5e-3):
        r = node_to_surface(xyz, slave_at(xyz, xi0, g), EPS_N, "exact")
        Ka = case_sum(r.parts, "main", "rotational", "curvature")
        diffs.append(np.linalg.norm(Ka - r.tangent))
        np.testing.assert_allclose(Ka - r.tangent, -r.parts["second_order"], atol=1e-12 * np.linalg.norm(Ka))
    assert 3.0 <= diffs[0] / diffs[1] <= 5.0


@pytest.mark.parametrize("nen,curved", FACETS)
def test_parts_symmetric_and_case_identities(nen, curved):
    xyz = make_facet(nen, curved, seed=40 + nen)
    xs = slave_at(xyz, np.array([0.6, -0.2]), -0.05)
    res = {name: node_to_surface(xyz, xs, EPS_N, name) for name in CASES}
    P = res["exact"].parts
    for name in PART_NAMES:
        assert np.linalg.norm(P[name] - P[name].T) <= 1e-14 * np.linalg.norm(P["main"])
    expect = {
        "a": ("main", "rotational", "curvature"),
        "b": ("main", "rotational"),
        "c": ("main", "curvature"),
        "d": ("main",),
        "exact": PART_NAMES,
    }
    scale = np.linalg.norm(P["main"])
    for name, names in expect.items():
        assert np.abs(res[name].tangent - case_sum(P, *names)).max() <= 1e-14 * scale
        np.testing.assert_array_equal(res[name].residual, res["exact"].residual)
    # the main part is eps A^T (n x n) A: rank one
    assert np.linalg.matrix_rank(P["main"], tol=1e-10 * scale) == 1
    if not curved:
        assert np.abs(P["curvature"]).max() < 1e-12 * scale


@pytest.mark.parametrize("nen", [4, 9])
def test_flipped_curvature_is_worse(nen):
    # docs/theory.md section 5: a flipped curvature sign is worse than leaving the part out
    xyz = make_facet(nen, True, seed=60 + nen)
    r = node_to_surface(xyz, slave_at(xyz, np.array([0.3, 0.2]), -1e-2), EPS_N, "exact")
    P, K = r.parts, r.tangent
    err_a = rel(P["main"] + P["rotational"] + P["curvature"], K)
    err_b = rel(P["main"] + P["rotational"], K)
    err_flip = rel(P["main"] + P["rotational"] - P["curvature"], K)
    assert err_a < err_b < err_flip
    assert err_flip > 1.5 * err_b


@pytest.mark.parametrize("nen,curved", FACETS)
def test_positive_gap_gives_zeros(nen, curved):
    xyz = make_facet(nen, curved, seed=80 + nen)
    r = node_to_surface(xyz, slave_at(xyz, np.array([0.0, 0.1]), 0.02), EPS_N, "exact")
    assert r.gap == pytest.approx(0.02, rel=1e-9)
    assert not np.any(r.residual) and not np.any(r.tangent)
    assert all(not np.any(p) for p in r.parts.values())


def test_inside_flag_and_xi0():
    xyz = make_facet(9, True, seed=5)
    r = node_to_surface(xyz, slave_at(xyz, np.array([1.2, 0.0]), -0.01), EPS_N, "a")
    assert r.status == 0 and not r.inside and r.xi[0] == pytest.approx(1.2, abs=1e-9)
    r2 = node_to_surface(xyz, slave_at(xyz, np.array([0.5, 0.5]), -0.01), EPS_N, "a", xi0=[0.4, 0.6])
    assert r2.inside and np.allclose(r2.xi, 0.5, atol=1e-10)


def test_input_validation():
    xyz = make_facet(4, False, seed=1)
    xs = np.zeros(3)
    with pytest.raises(ValueError, match="master_xyz"):
        node_to_surface(xyz[:3], xs, 1.0)
    with pytest.raises(ValueError, match="slave_xyz"):
        node_to_surface(xyz, np.zeros(2), 1.0)
    with pytest.raises(ValueError, match="parts"):
        node_to_surface(xyz, xs, 1.0, parts="e")
    with pytest.raises(ValueError, match="eps_n"):
        node_to_surface(xyz, xs, 0.0)
    with pytest.raises(ValueError, match="non-finite"):
        node_to_surface(xyz, np.array([0.0, np.nan, 0.0]), 1.0)
    with pytest.raises(ValueError, match="degenerate"):
        node_to_surface(np.zeros((4, 3)), xs, 1.0)


@pytest.mark.parametrize("nen", [4, 9])
def test_batch_kernel_matches_single_element(nen):
    rng = np.random.default_rng(nen)
    xyz = make_facet(nen, True, seed=100 + nen)
    npair = 37  # not a multiple of the chunk size
    xs = np.array([slave_at(xyz, rng.uniform(-0.9, 0.9, 2), rng.uniform(-0.1, 0.02)) for _ in range(npair)])
    X = np.vstack([xyz, xs])
    conn = np.tile(np.arange(nen, dtype=np.int64), (npair, 1))
    sid = np.arange(nen, nen + npair, dtype=np.int64)
    eps = rng.uniform(1.0, 5.0, npair)
    m = 3 * (nen + 1)
    singles = []
    xi = np.zeros((npair, 2))
    for k in range(npair):
        singles.append(node_to_surface(xyz, xs[k], eps[k], "a"))
        xi[k] = singles[k].xi
    for name, case in CASES.items():
        R, K, P, g = (
            np.zeros((npair, m)),
            np.zeros((npair, m, m)),
            np.zeros((npair, 4, m, m)),
            np.zeros(npair),
        )
        contact_batch(X, conn, sid, xi, eps, case, True, R, K, P, g)
        R2, K2, g2 = np.zeros((npair, m)), np.zeros((npair, m, m)), np.zeros(npair)
        contact_batch(X, conn, sid, xi, eps, case, False, R2, K2, np.zeros((1, 4, 1, 1)), g2)
        np.testing.assert_array_equal(K, K2)
        np.testing.assert_array_equal(g, g2)
        for k in range(npair):
            s = singles[k]
            assert g[k] == pytest.approx(s.gap, abs=1e-14)
            np.testing.assert_allclose(R[k], s.residual, atol=1e-13)
            np.testing.assert_allclose(P[k], np.array([s.parts[n] for n in PART_NAMES]), atol=1e-12)
            expect = node_to_surface(xyz, xs[k], eps[k], name, xi0=s.xi).tangent
            np.testing.assert_allclose(K[k], expect, atol=1e-12)
    assert np.any(g < 0) and np.any(g > 0)
