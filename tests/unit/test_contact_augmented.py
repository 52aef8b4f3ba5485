"""Augmented Lagrangian (Uzawa) normal law in the compiled contact kernels.

Reference: docs/theory.md section 8: lam_N = <lam_k + eps_N g> replaces eps_N <g> in
R_c and in the factors of K_rot and K_curv; the energy is W = 1/(2 eps_N) <lam_k + eps_N g>^2 and the
exact tangent its Hessian, eps_N H grad g (x) grad g + lam_N hess g (g the geometric gap).
"""

import numpy as np
import pytest

from covcontact.contact import (
    CASES,
    PART_NAMES,
    Cylinder,
    Plane,
    RigidMotion,
    Sphere,
    contact_batch,
    node_to_surface,
)
from covcontact.contact.geometry import facet_geometry
from covcontact.fem.shapes import NODES

EPS_N = 7.0
LAM_K = -0.35  # lam_k / eps_N = -0.05
FACETS = [(4, False), (4, True), (9, False), (9, True)]
XI0 = np.array([0.23, -0.31])


def make_facet(nen, curved, seed):
    """Perturbed quad4/quad9 facet of size ~2, rigidly rotated; curved: convex dome."""
    rng = np.random.default_rng(seed)
    P = NODES["quad4" if nen == 4 else "quad9"].astype(float)
    xyz = np.column_stack([P[:, 0], P[:, 1], np.zeros(nen)])
    xyz[:, :2] += 0.08 * rng.standard_normal((nen, 2))
    if curved:
        x, y = xyz[:, 0], xyz[:, 1]
        xyz[:, 2] = -(x**2 + 0.5 * y**2 + 0.3 * x * y) / 3.0 + 0.03 * rng.standard_normal(nen)
    th = rng.uniform(0, 2 * np.pi)
    Q = np.array([[np.cos(th), 0, np.sin(th)], [0, 1, 0], [-np.sin(th), 0, np.cos(th)]])
    return xyz @ Q.T + rng.uniform(-1, 1, 3)


def slave_at(xyz, xi, g):
    nen = xyz.shape[0]
    rho, n = np.empty(3), np.empty(3)
    facet_geometry(
        xyz, xi[0], xi[1], np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2)), rho,
        np.empty((2, 3)), np.empty((2, 2)), np.empty((2, 2)), n, np.empty((2, 2)),
    )  # fmt: skip
    return rho + g * n


def energy(g, lam_k, eps=EPS_N):
    """W = 1/(2 eps) <lam_k + eps g>^2."""
    return 0.5 / eps * min(lam_k + eps * g, 0.0) ** 2


def rel(A, B):
    return np.linalg.norm(A - B) / np.linalg.norm(B)


def facet_fd(xyz, xs, xi, lam_k, h=1e-6):
    """Central differences (re-projecting from xi) of the residual and of the energy W."""
    nen = xyz.shape[0]
    x = np.concatenate([xyz.ravel(), xs])
    K = np.zeros((x.size, x.size))
    dW = np.zeros(x.size)
    for k in range(x.size):
        rs = []
        for s in (1.0, -1.0):
            y = x.copy()
            y[k] += s * h
            rs.append(node_to_surface(y[:-3].reshape(nen, 3), y[-3:], EPS_N, "exact", xi, lam_k))
        K[:, k] = (rs[0].residual - rs[1].residual) / (2 * h)
        dW[k] = (energy(rs[0].gap, lam_k) - energy(rs[1].gap, lam_k)) / (2 * h)
    return K, dW


@pytest.mark.parametrize("nen,curved", FACETS)
@pytest.mark.parametrize("g", [-2e-2, -1e-3, 2e-2])
def test_facet_exact_tangent_and_residual_match_fd(nen, curved, g):
    xyz = make_facet(nen, curved, seed=nen + 10 * curved)
    xs = slave_at(xyz, XI0, g)
    r = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=LAM_K)
    assert r.gap == pytest.approx(g, abs=1e-12)
    lam_n = LAM_K + EPS_N * g
    assert lam_n < 0.0  # active, also at the positive gap g = 2e-2
    K_fd, dW = facet_fd(xyz, xs, r.xi, LAM_K)
    assert rel(r.tangent, K_fd) < 1e-6
    assert rel(r.residual, dW) < 1e-6
    # the slave is pushed out along n with |lam_N|
    np.testing.assert_allclose(r.residual[-3:], lam_n * r.normal, rtol=1e-12)
    np.testing.assert_allclose(sum(r.parts.values()), r.tangent, atol=1e-13 * EPS_N)
    for P in list(r.parts.values()) + [r.tangent]:
        np.testing.assert_allclose(P, P.T, atol=1e-13 * EPS_N)


@pytest.mark.parametrize("nen,curved", FACETS)
def test_facet_affine_in_multiplier_and_penalty_limit(nen, curved):
    xyz = make_facet(nen, curved, seed=3 + nen + curved)
    xs = slave_at(xyz, XI0, -2e-2)
    r0 = node_to_surface(xyz, xs, EPS_N, "exact")
    rz = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=0.0)
    rzn = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=-0.0)
    for r in (rz, rzn):  # lam_k = 0 is the penalty element, bit for bit
        np.testing.assert_array_equal(r.residual, r0.residual)
        np.testing.assert_array_equal(r.tangent, r0.tangent)
        for k in PART_NAMES:
            np.testing.assert_array_equal(r.parts[k], r0.parts[k])
    # R = lam_N grad g and K = eps H grad g grad g + lam_N hess g: affine in lam_k while active
    r1 = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=LAM_K)
    r2 = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=2 * LAM_K)
    np.testing.assert_allclose(r2.residual - r0.residual, 2 * (r1.residual - r0.residual), atol=1e-13)
    np.testing.assert_allclose(r2.tangent - r0.tangent, 2 * (r1.tangent - r0.tangent), atol=1e-12)
    np.testing.assert_allclose(r1.parts["main"], r0.parts["main"], atol=1e-14 * EPS_N)
    for k in ("rotational", "curvature"):  # factors eps g -> lam_N
        np.testing.assert_allclose(
            r1.parts[k], r0.parts[k] * (LAM_K + EPS_N * r0.gap) / (EPS_N * r0.gap), atol=1e-13 * EPS_N
        )


@pytest.mark.parametrize("nen,curved", [(4, True), (9, True)])
def test_facet_activity_decided_by_multiplier(nen, curved):
    xyz = make_facet(nen, curved, seed=7)
    g = 0.03
    xs = slave_at(xyz, XI0, g)
    on = node_to_surface(xyz, xs, EPS_N, "a", multiplier=LAM_K)  # -0.35 + 0.21 < 0: active
    assert on.gap == pytest.approx(g, abs=1e-12)
    np.testing.assert_allclose(on.residual[-3:], (LAM_K + EPS_N * g) * on.normal, rtol=1e-12)
    assert np.linalg.norm(on.tangent) > EPS_N
    for lam_k in (-0.1, 0.0):  # lam_k + eps g > 0: inactive
        off = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=lam_k)
        assert off.gap == pytest.approx(g, abs=1e-12)
        assert not np.any(off.residual) and not np.any(off.tangent)
        assert not any(np.any(P) for P in off.parts.values())
    for bad in (0.1, np.nan):
        with pytest.raises(ValueError):
            node_to_surface(xyz, xs, EPS_N, multiplier=bad)


@pytest.mark.parametrize("nen,curved", FACETS)
def test_facet_case_a_vs_exact_is_second_order(nen, curved):
    # with g_e = g + lam_k / eps fixed, the dropped second-order terms scale with g
    xyz = make_facet(nen, curved, seed=11 + nen)
    ge = -0.05
    d = []
    for g in (-1e-2, -1e-3):
        xs = slave_at(xyz, XI0, g)
        lam_k = EPS_N * (ge - g)
        ra = node_to_surface(xyz, xs, EPS_N, "a", multiplier=lam_k)
        re = node_to_surface(xyz, xs, EPS_N, "exact", multiplier=lam_k)
        P = re.parts
        np.testing.assert_allclose(ra.tangent, P["main"] + P["rotational"] + P["curvature"], atol=1e-13)
        np.testing.assert_allclose(re.tangent - ra.tangent, P["second_order"], atol=1e-13)
        d.append(rel(ra.tangent, re.tangent))
    assert d[0] < 5e-3
    assert 5.0 < d[0] / d[1] < 20.0


@pytest.mark.parametrize("nen", [4, 9])
def test_batch_kernel_with_multipliers_matches_single(nen):
    rng = np.random.default_rng(nen)
    xyz = make_facet(nen, True, seed=100 + nen)
    npair = 21  # not a multiple of the chunk size
    gaps = rng.uniform(-0.05, 0.06, npair)
    xs = np.array([slave_at(xyz, rng.uniform(-0.9, 0.9, 2), gk) for gk in gaps])
    X = np.vstack([xyz, xs])
    conn = np.tile(np.arange(nen, dtype=np.int64), (npair, 1))
    sid = np.arange(nen, nen + npair, dtype=np.int64)
    eps = rng.uniform(1.0, 5.0, npair)
    lam = -rng.uniform(0.0, 0.2, npair)
    m = 3 * (nen + 1)
    singles = [node_to_surface(xyz, xs[k], eps[k], "exact", multiplier=lam[k]) for k in range(npair)]
    xi = np.array([s.xi for s in singles])
    out = [np.zeros((npair, m)), np.zeros((npair, m, m)), np.zeros((npair, 4, m, m)), np.zeros(npair)]
    R, K, P, g = out
    contact_batch(X, conn, sid, xi, eps, CASES["exact"], True, R, K, P, g, lam)
    for k, s in enumerate(singles):
        assert g[k] == pytest.approx(s.gap, abs=1e-14)
        np.testing.assert_allclose(R[k], s.residual, atol=1e-13)
        np.testing.assert_allclose(K[k], s.tangent, atol=1e-12)
        np.testing.assert_allclose(P[k], np.array([s.parts[n] for n in PART_NAMES]), atol=1e-12)
    active = lam + eps * g <= 0
    assert np.any(active & (g > 0)) and np.any(~active)
    assert not np.any(R[~active]) and np.all(np.any(R[active] != 0, axis=1))
    # zero multipliers and the default (None) give the penalty kernel, bit for bit
    R0, K0, g0 = np.zeros((npair, m)), np.zeros((npair, m, m)), np.zeros(npair)
    contact_batch(X, conn, sid, xi, eps, CASES["exact"], False, R0, K0, P[:1], g0)
    contact_batch(X, conn, sid, xi, eps, CASES["exact"], False, R, K, P[:1], g, np.zeros(npair))
    np.testing.assert_array_equal(R, R0)
    np.testing.assert_array_equal(K, K0)


# ---- rigid analytic masters --------------------------------------------------------------------

MOTION = RigidMotion(translation=(0.1, 0.2, -0.3), rotation=(0.2, -0.4, 0.3), center=(1.0, 0.0, 0.0))
LOAD = 0.7
SURFACES = {
    "plane": Plane((0.1, 0.2, 0.3), (1.0, 2.0, 3.0), MOTION),
    "cyl_out": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, True, MOTION),
    "cyl_in": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, False, MOTION),
    "sph_out": Sphere((0.3, 0.0, 0.0), 1.5, True, MOTION),
    "sph_in": Sphere((0.3, 0.0, 0.0), 1.5, False, MOTION),
}


def analytic_slave(surf, g):
    pr = surf.project(np.array([0.7, -0.4, 0.9]), lam=LOAD)
    return pr.rho + g * pr.normal


@pytest.mark.parametrize("name", list(SURFACES))
@pytest.mark.parametrize("g", [-2e-2, -1e-3, 2e-2])
def test_analytic_exact_tangent_and_residual_match_fd(name, g):
    surf = SURFACES[name]
    xs = analytic_slave(surf, g)
    r = surf.contact(xs, EPS_N, "exact", LOAD, multiplier=LAM_K)
    assert r.gap == pytest.approx(g, abs=1e-12)
    h = 1e-6
    K_fd, dW = np.zeros((3, 3)), np.zeros(3)
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        rp = surf.contact(xs + e, EPS_N, "exact", LOAD, multiplier=LAM_K)
        rm = surf.contact(xs - e, EPS_N, "exact", LOAD, multiplier=LAM_K)
        K_fd[:, k] = (rp.residual - rm.residual) / (2 * h)
        dW[k] = (energy(rp.gap, LAM_K) - energy(rm.gap, LAM_K)) / (2 * h)
    assert rel(r.tangent, K_fd) < 1e-6
    assert rel(r.residual, dW) < 1e-6
    np.testing.assert_allclose(r.residual, (LAM_K + EPS_N * g) * r.normal, rtol=1e-12)
    np.testing.assert_allclose(sum(r.parts.values()), r.tangent, atol=1e-14 * EPS_N)
    for P in r.parts.values():
        np.testing.assert_allclose(P, P.T, atol=1e-15 * EPS_N)
    ra = surf.contact(xs, EPS_N, "a", LOAD, multiplier=LAM_K)
    assert rel(ra.tangent, r.tangent) < 2e-3  # rigid master: differs by the O(g g_e) second order part
    r0 = surf.contact(xs, EPS_N, "exact", LOAD)
    np.testing.assert_array_equal(surf.contact(xs, EPS_N, "exact", LOAD, multiplier=0.0).tangent, r0.tangent)


@pytest.mark.parametrize("name", list(SURFACES))
def test_analytic_batch_with_multipliers(name):
    surf = SURFACES[name]
    rng = np.random.default_rng(5)
    gaps = rng.uniform(-0.05, 0.06, 40)
    base = [surf.project(p, lam=LOAD) for p in rng.uniform(-2.5, 2.5, (40, 3))]
    xs = np.array([b.rho + gk * b.normal for b, gk in zip(base, gaps, strict=True)])
    eps = rng.uniform(1.0, 5.0, 40)
    lam = -rng.uniform(0.0, 0.2, 40)
    out = surf.evaluate(xs, eps, "exact", LOAD, multiplier=lam)
    for k in range(40):
        r = surf.contact(xs[k], eps[k], "exact", LOAD, multiplier=lam[k])
        np.testing.assert_allclose(out.residual[k], r.residual, atol=1e-14)
        np.testing.assert_allclose(out.tangent[k], r.tangent, atol=1e-13)
    active = lam + eps * out.gap <= 0
    assert np.any(active & (out.gap > 0)) and np.any(~active)
    assert not np.any(out.residual[~active]) and np.all(np.any(out.residual[active] != 0, axis=1))
    pen = surf.evaluate(xs, eps, "exact", LOAD)
    zero = surf.evaluate(xs, eps, "exact", LOAD, multiplier=0.0)
    np.testing.assert_array_equal(zero.tangent, pen.tangent)
    np.testing.assert_array_equal(zero.residual, pen.residual)
    with pytest.raises(ValueError):
        surf.evaluate(xs, eps, "exact", LOAD, multiplier=0.5)
