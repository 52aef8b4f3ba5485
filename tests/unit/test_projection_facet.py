"""Closest point projection onto one facet (docs/theory.md section 4), property-based."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from covcontact.contact.geometry import facet_geometry
from covcontact.contact.projection import (
    _mono_geometry,
    facet_monomials,
    project_on_facet,
    project_on_facet_info,
)
from covcontact.fem.shapes import NODES

SETTINGS = settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def curved_quad9(seed, kappa1, kappa2, twist):
    """Biquadratic facet of size ~2 on z = -(k1 x^2 + k2 y^2 + t x y)/2 with perturbed nodes."""
    rng = np.random.default_rng(seed)
    P = NODES["quad9"].astype(float)
    xyz = np.column_stack([P[:, 0], P[:, 1], np.zeros(9)])
    xyz[:, :2] += 0.06 * rng.standard_normal((9, 2))
    x, y = xyz[:, 0], xyz[:, 1]
    xyz[:, 2] = -0.5 * (kappa1 * x**2 + kappa2 * y**2 + twist * x * y) + 0.02 * rng.standard_normal(9)
    return xyz


def geometry(xyz, xi):
    nen = xyz.shape[0]
    rho, rho_cov, n = np.empty(3), np.empty((2, 3)), np.empty(3)
    facet_geometry(
        xyz,
        xi[0],
        xi[1],
        np.empty(nen),
        np.empty((nen, 2)),
        np.empty((nen, 2, 2)),
        rho,
        rho_cov,
        np.empty((2, 2)),
        np.empty((2, 2)),
        n,
        np.empty((2, 2)),
    )
    return rho, rho_cov, n


def cold_start(xyz, xs):
    k = int(np.argmin(np.sum((xyz - xs) ** 2, axis=1)))
    return NODES["quad9"][k].astype(float).copy()


facets = st.builds(
    curved_quad9,
    st.integers(0, 10_000),
    st.floats(-0.6, 0.6),
    st.floats(-0.6, 0.6),
    st.floats(-0.3, 0.3),
)
near_points = st.tuples(st.floats(-0.95, 0.95), st.floats(-0.95, 0.95), st.floats(-0.4, 0.4))


@SETTINGS
@given(facets, near_points)
def test_residual_vanishes_and_starts_agree(xyz, p):
    """A point above/below the facet (|g| < 0.4 < focal distance >= 1/0.9): converged, F_i = 0."""
    xi_ref = np.array(p[:2])
    rho, rho_cov, n = geometry(xyz, xi_ref)
    xs = rho + p[2] * n
    xi = cold_start(xyz, xs)
    status, g = project_on_facet(xyz, xs, xi)
    assert status == 0
    rho, rho_cov, n = geometry(xyz, xi)
    d = xs - rho
    scale = max(np.linalg.norm(d), 1.0)
    for i in range(2):
        assert abs(d @ rho_cov[i]) <= 1e-10 * scale * np.linalg.norm(rho_cov[i])
    assert g == pytest.approx(d @ n, abs=1e-13)
    assert abs(g) == pytest.approx(np.linalg.norm(d), rel=1e-9, abs=1e-12)
    # warm start (a nearby previous answer) and the reference point give the same answer
    for start in (xi + 0.1, xi_ref.copy()):
        status2, g2 = project_on_facet(xyz, xs, start)
        assert status2 == 0
        np.testing.assert_allclose(start, xi, atol=1e-9)
        assert g2 == pytest.approx(g, abs=1e-12)


@SETTINGS
@given(facets, st.floats(0.9, 1.3), st.floats(-1.0, 1.0), st.integers(0, 3), st.floats(-0.3, 0.3))
def test_near_edges(xyz, t_out, t_along, edge, z):
    """Points just inside or outside an edge: converged, projection near that edge, never clipped."""
    xi_ref = np.array([[t_out, t_along], [-t_out, t_along], [t_along, t_out], [t_along, -t_out]][edge])
    rho, _, n = geometry(xyz, xi_ref)
    xs = rho + z * n
    xi = cold_start(xyz, xs)
    status, g = project_on_facet(xyz, xs, xi)
    assert status == 0 and np.isfinite(g)
    np.testing.assert_allclose(xi, xi_ref, atol=1e-8)


points_anywhere = st.tuples(
    st.floats(-1e6, 1e6, allow_nan=False),
    st.floats(-1e6, 1e6, allow_nan=False),
    st.floats(-1e6, 1e6, allow_nan=False),
)


@SETTINGS
@given(facets, points_anywhere, st.integers(1, 30), st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_never_nan_and_bounded_iterations(xyz, p, max_iter, xi_start):
    xi = np.array(xi_start)
    status, g, nit = project_on_facet_info(xyz, np.array(p), xi, max_iter, 1e-12)
    assert status in (0, 1)
    assert 1 <= nit <= max_iter
    assert np.isfinite(g) and np.all(np.isfinite(xi))


@SETTINGS
@given(st.integers(0, 10_000), st.floats(0.5, 0.9), st.floats(0.5, 3.0), st.floats(-0.5, 0.5))
def test_focal_side(seed, kappa, factor, shift):
    """Points on the concave side at and beyond the centre of curvature (c_ij not positive definite)."""
    xyz = curved_quad9(seed, -kappa, -kappa, 0.0)  # concave seen from the +z side
    xs = np.array([shift, -shift, factor / kappa])
    xi = np.array([0.3, -0.2])
    status, g, nit = project_on_facet_info(xyz, xs, xi, 30, 1e-12)
    assert status in (0, 1) and nit <= 30
    assert np.isfinite(g) and np.all(np.isfinite(xi))
    # wherever it stops, it is no farther than the start point
    rho0, _, _ = geometry(xyz, np.array([0.3, -0.2]))
    rho1, _, _ = geometry(xyz, xi)
    assert np.linalg.norm(xs - rho1) <= np.linalg.norm(xs - rho0) * (1 + 1e-12)


def test_quad4_flat_exact():
    xyz = np.array([[0.0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]])
    xi = np.zeros(2)
    status, g = project_on_facet(xyz, np.array([1.5, 0.25, -0.3]), xi)
    assert status == 0 and g == pytest.approx(-0.3)
    np.testing.assert_allclose(xi, [0.5, -0.5], atol=1e-14)


def test_degenerate_and_non_finite():
    xi = np.zeros(2)
    assert project_on_facet(np.zeros((4, 3)), np.ones(3), xi)[0] == 2
    line = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]])
    status, g = project_on_facet(line, np.ones(3), xi)
    assert status == 2 and np.isfinite(g) and np.all(np.isfinite(xi))
    xyz = curved_quad9(0, 0.3, 0.3, 0.0)
    xi = np.array([np.nan, 0.0])
    status, g = project_on_facet(xyz, np.array([0.1, 0.1, 0.1]), xi)
    assert status == 0 and np.all(np.isfinite(xi))  # a NaN start is replaced by the centre
    assert project_on_facet(xyz, np.array([np.inf, 0.0, 0.0]), np.zeros(2))[0] == 2


@pytest.mark.parametrize("nen", [4, 9])
def test_monomial_form_equals_the_shape_functions(nen):
    # the projection's Newton loop runs on the facet's monomial form: position and first and second derivatives
    # equal those of the Lagrange shape functions, inside and outside [-1, 1]^2
    rng = np.random.default_rng(nen)
    xyz = rng.normal(size=(nen, 3))
    c = np.empty((3, 3, 3))
    facet_monomials(xyz, c)
    G = np.empty((6, 3))
    N, dN, ddN = np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2))
    rho, rc, a, ac, n, h = np.empty(3), np.empty((2, 3)), np.empty((2, 2)), np.empty((2, 2)), np.empty(3), np.empty((2, 2))
    for x1, x2 in rng.uniform(-1.5, 1.5, (10, 2)):
        _mono_geometry.py_func(c, x1, x2, G)
        facet_geometry(xyz, x1, x2, N, dN, ddN, rho, rc, a, ac, n, h)
        dd = np.einsum("aij,ap->ijp", ddN, xyz)
        assert np.allclose(G[0], rho, atol=1e-13) and np.allclose(G[1:3], rc, atol=1e-13)
        assert np.allclose(G[3], dd[0, 0], atol=1e-13) and np.allclose(G[4], dd[0, 1], atol=1e-13)
        assert np.allclose(G[5], dd[1, 1], atol=1e-13)
