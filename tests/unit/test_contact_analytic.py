"""Rigid analytic master surfaces (plane, cylinder, sphere) and rigid motions.

Conventions from docs/theory.md section 3 (convex seen from outside: h negative definite, a circle of
radius R by angle has a_11 = R^2, h_11 = -R) and section 5 (rigid master: rotational part zero, exact
tangent = eps H (n(x)n + (a^ij - c^ij) rho_i(x)rho_j), the exact Hessian of 1/2 eps <g>^2).
"""

import numpy as np
import pytest

from covcontact.contact import CASES, Cylinder, Plane, RigidMotion, Sphere
from covcontact.motion import rotation_matrix
from profile_cases import profiles

EPS_N = 3.0
MOTION = RigidMotion(translation=(0.1, 0.2, -0.3), rotation=(0.2, -0.4, 0.3), center=(1.0, 0.0, 0.0))
LAM = 0.7


def surfaces():
    return {
        "plane": Plane((0.1, 0.2, 0.3), (1.0, 2.0, 3.0), MOTION),
        "cyl_out": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, True, MOTION),
        "cyl_in": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, False, MOTION),
        "sph_out": Sphere((0.3, 0.0, 0.0), 1.5, True, MOTION),
        "sph_in": Sphere((0.3, 0.0, 0.0), 1.5, False, MOTION),
        **profiles(MOTION),
    }


NAMES = list(surfaces())
POINTS = [np.array([0.7, -0.4, 0.9]), np.array([-1.1, 0.3, 2.2]), np.array([0.2, 1.9, -0.8])]


def slave_at(surf, point, g):
    pr = surf.project(point, lam=LAM)
    return pr.rho + g * pr.normal


def fd_tangent(surf, xs, h=1e-6):
    K = np.zeros((3, 3))
    for k in range(3):
        xp, xm = xs.copy(), xs.copy()
        xp[k] += h
        xm[k] -= h
        K[:, k] = (
            surf.contact(xp, EPS_N, "exact", LAM).residual - surf.contact(xm, EPS_N, "exact", LAM).residual
        )
        K[:, k] /= 2 * h
    return K


def rel(A, B):
    return np.linalg.norm(A - B) / np.linalg.norm(B)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("ip", range(len(POINTS)))
@pytest.mark.parametrize("g", [-1e-1, -1e-2, -1e-3])
def test_exact_tangent_matches_fd(name, ip, g):
    surf = surfaces()[name]
    xs = slave_at(surf, POINTS[ip], g)
    r = surf.contact(xs, EPS_N, "exact", LAM)
    assert r.gap == pytest.approx(g, rel=1e-8)
    assert rel(r.tangent, fd_tangent(surf, xs)) < 1e-6
    assert not np.any(r.parts["rotational"])
    np.testing.assert_allclose(sum(r.parts.values()), r.tangent, atol=1e-14 * EPS_N)
    for P in r.parts.values():
        np.testing.assert_allclose(P, P.T, atol=1e-15 * EPS_N)
    # residual = gradient of 1/2 eps <g>^2 and the slave is pushed out along n
    np.testing.assert_allclose(r.residual, EPS_N * g * r.normal, rtol=1e-7)


@pytest.mark.parametrize("name", ["cyl_out", "cyl_in", "sph_out", "sph_in", "ext_ridge", "rev_die"])
def test_case_a_second_order_and_flipped_curvature(name):
    surf = surfaces()[name]
    diffs = []
    for g in (-1e-2, -5e-3):
        r = surf.contact(slave_at(surf, POINTS[0], g), EPS_N, "exact", LAM)
        P = r.parts
        Ka = surf.contact(slave_at(surf, POINTS[0], g), EPS_N, "a", LAM).tangent
        np.testing.assert_allclose(Ka, P["main"] + P["curvature"], atol=1e-14 * EPS_N)
        diffs.append(np.linalg.norm(Ka - r.tangent))
        err_a = rel(Ka, r.tangent)
        err_d = rel(P["main"], r.tangent)
        err_flip = rel(P["main"] - P["curvature"], r.tangent)
        assert err_a < err_d < err_flip
    assert 3.0 <= diffs[0] / diffs[1] <= 5.0


def test_rigid_case_identities():
    # rigid master: a) = c) and b) = d) (docs/theory.md section 5)
    surf = surfaces()["sph_out"]
    xs = slave_at(surf, POINTS[1], -0.05)
    K = {name: surf.contact(xs, EPS_N, name, LAM).tangent for name in CASES}
    np.testing.assert_array_equal(K["a"], K["c"])
    np.testing.assert_array_equal(K["b"], K["d"])
    assert rel(K["d"], K["a"]) > 1e-3


@pytest.mark.parametrize("name", NAMES)
def test_positive_gap_gives_zeros(name):
    surf = surfaces()[name]
    r = surf.contact(slave_at(surf, POINTS[2], 0.03), EPS_N, "exact", LAM)
    assert r.gap == pytest.approx(0.03, rel=1e-8)
    assert not np.any(r.residual) and not np.any(r.tangent)


def test_cylinder_and_sphere_sign_conventions():
    R = 2.0
    cyl = Cylinder((0, 0, 0), (0, 0, 1), R)
    pr = cyl.project(np.array([3.0, 0.0, 0.5]))
    assert pr.gap == pytest.approx(1.0)
    np.testing.assert_allclose(pr.normal, [1, 0, 0], atol=1e-15)
    assert pr.a_cov[0, 0] == pytest.approx(R**2) and pr.h_cov[0, 0] == pytest.approx(-R)
    np.testing.assert_allclose(np.cross(*pr.rho_cov) / np.linalg.norm(np.cross(*pr.rho_cov)), pr.normal)
    hollow = Cylinder((0, 0, 0), (0, 0, 1), R, outside=False)
    pr = hollow.project(np.array([1.5, 0.0, 0.5]))
    assert pr.gap == pytest.approx(0.5)
    np.testing.assert_allclose(pr.normal, [-1, 0, 0], atol=1e-15)
    assert pr.h_cov[0, 0] == pytest.approx(R)
    np.testing.assert_allclose(np.cross(*pr.rho_cov) / np.linalg.norm(np.cross(*pr.rho_cov)), pr.normal)
    sph = Sphere((0, 0, 0), R)
    rng = np.random.default_rng(0)
    for _ in range(20):
        x = rng.standard_normal(3) * 3
        pr = sph.project(x)
        assert pr.gap == pytest.approx(np.linalg.norm(x) - R)
        np.testing.assert_allclose(pr.normal, x / np.linalg.norm(x), atol=1e-14)
        assert np.all(np.linalg.eigvalsh(pr.h_cov) < 0)
        np.testing.assert_allclose(pr.h_cov, -pr.a_cov / R, atol=1e-13)
        # the chart keeps the point away from its poles: sin(theta) >= sqrt(2/3)
        assert np.sin(pr.xi[0]) >= np.sqrt(2 / 3) - 1e-12
        np.testing.assert_allclose(
            np.cross(*pr.rho_cov) / np.linalg.norm(np.cross(*pr.rho_cov)), pr.normal, atol=1e-14
        )


@pytest.mark.parametrize("name", NAMES)
def test_projection_is_closest_point(name):
    surf = surfaces()[name]
    rng = np.random.default_rng(1)
    for _ in range(10):
        x = rng.uniform(-2, 2, 3)
        pr = surf.project(x, lam=LAM)
        d = x - pr.rho
        assert abs(np.dot(d, pr.rho_cov[0])) < 1e-12 * max(1, np.linalg.norm(d)) * np.linalg.norm(
            pr.rho_cov[0]
        )
        assert abs(np.dot(d, pr.rho_cov[1])) < 1e-12 * max(1, np.linalg.norm(d)) * np.linalg.norm(
            pr.rho_cov[1]
        )
        assert np.dot(d, pr.normal) == pytest.approx(pr.gap, abs=1e-12)
        np.testing.assert_allclose(pr.rho_cov @ pr.rho_cov.T, pr.a_cov, atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_batch_matches_single(name):
    surf = surfaces()[name]
    rng = np.random.default_rng(2)
    xs = rng.uniform(-2.5, 2.5, (45, 3))
    eps = rng.uniform(1, 4, 45)
    out = surf.evaluate(xs, eps, "exact", LAM)
    for k in range(45):
        r = surf.contact(xs[k], eps[k], "exact", LAM)
        assert out.gap[k] == pytest.approx(r.gap, abs=1e-14)
        np.testing.assert_allclose(out.residual[k], r.residual, atol=1e-14)
        np.testing.assert_allclose(out.tangent[k], r.tangent, atol=1e-13)
        np.testing.assert_allclose(out.normal[k], r.normal, atol=1e-15)
    if name != "plane":
        assert np.any(out.gap < 0) and np.any(out.gap > 0)


def test_rigid_motion():
    m = RigidMotion(translation=(1.0, 0, 0), rotation=(0, 0, np.pi / 2), center=(1.0, 1.0, 0))
    np.testing.assert_allclose(m.apply([2.0, 1.0, 5.0], 0.0), [2.0, 1.0, 5.0])
    # quarter turn about the z axis through (1, 1, 0), then shift by (1, 0, 0)
    np.testing.assert_allclose(m.apply([2.0, 1.0, 5.0], 1.0), [2.0, 2.0, 5.0], atol=1e-15)
    X = np.random.default_rng(3).standard_normal((6, 3))
    Y = m.apply(X, 0.3)
    assert Y.shape == X.shape
    np.testing.assert_allclose(np.linalg.norm(Y[0] - Y[1]), np.linalg.norm(X[0] - X[1]))
    for w in ([0.3, -1.2, 2.0], [1e-10, 0, 0], [0, 0, 0]):
        Q = rotation_matrix(w)
        np.testing.assert_allclose(Q @ Q.T, np.eye(3), atol=1e-14)
        assert np.linalg.det(Q) == pytest.approx(1.0)
        np.testing.assert_allclose(Q @ np.asarray(w, float), w, atol=1e-14)  # the axis is fixed
    with pytest.raises(ValueError):
        RigidMotion(translation=(1.0, 2.0))


def test_surface_moves_with_motion():
    m = RigidMotion(translation=(0, 0, -1.0))
    sph = Sphere((0, 0, 0), 1.0, motion=m)
    assert sph.project(np.array([0, 0, 1.5]), lam=0.0).gap == pytest.approx(0.5)
    assert sph.project(np.array([0, 0, 1.5]), lam=0.5).gap == pytest.approx(1.0)
    with pytest.raises(ValueError):
        Sphere((0, 0, 0), -1.0)
    with pytest.raises(ValueError):
        Plane((0, 0, 0), (0, 0, 0))
