"""Friction history on degenerate frames and across far facets (docs/theory.md section 7, "transfer_history").

A facet's continuation beyond its edges is its polynomial carried on; the quadrilaterals of a tri6 face's patch
(docs/theory.md section 19) fold there one facet size away, at their outer corner xi = (2, 2), where
rho_1 x rho_2 = 0. A slave that crossed a whole patch quadrilateral in a step had its old contact point projected
onto that fold: the frame there made ``facet_geometry`` divide by a metric determinant that cancellation had made
zero (ZeroDivisionError in the friction history transfer and in the friction kernel, which evaluates the old point).
"""

import numpy as np
import pytest

from covcontact.contact.facets import _patch_parameters
from covcontact.contact.friction import (
    HIST_SIZE,
    NEW,
    SLIP,
    STICK,
    friction_element,
    make_history,
    start_history,
    transfer_history,
)
from covcontact.contact.geometry import facet_geometry
from covcontact.contact.projection import project_on_facet


def kite(scale=1.0):
    """The patch quadrilateral (quad9) at the corner (0, 0) of the flat unit triangle's tri6 face: corners (0, 0),
    (1/2, 0), (1/3, 1/3) (the centroid), (0, 1/2); its continuation folds at xi = (2, 2)."""
    return np.ascontiguousarray(np.column_stack([scale * _patch_parameters(6)[0], np.zeros(9)]))


def frame(xyz, xi):
    nen = xyz.shape[0]
    rho, rc, a, ai, n = np.zeros(3), np.zeros((2, 3)), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros(3)
    area = facet_geometry(xyz, float(xi[0]), float(xi[1]), np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2)),
                          rho, rc, a, ai, n, np.empty((2, 2)))
    return area, rho, rc, a, ai, n


def traction_vector(h):
    rc = h[5:11].reshape(2, 3)
    return np.linalg.solve(rc @ rc.T, h[11:13]) @ rc


def fold_points():
    """Points on and near the fold of the kite's continuation (the diagonal xi1 = xi2 -> 2 and beside it)."""
    return [(t, s) for t in 2.0 - np.logspace(-12, -6, 61) for s in (t, t * (1.0 + 1e-9), 4.0 - t)]


def test_facet_frame_at_a_fold_is_degenerate_not_a_division_by_zero():
    """Near the fold the area element passes the degeneracy test while a_11 a_22 - a_12^2 has cancelled to zero or
    below: the frame is reported degenerate (area 0, n and a^ij zero) instead of dividing by it; elsewhere a^ij is
    finite and positive definite (the frame is ill-conditioned there, one reason the history keeps off it)."""
    xyz = kite()
    zero = 0
    for xi in fold_points():
        area, _, rc, a, ai, n = frame(xyz, xi)  # raised ZeroDivisionError for 86 of these 183 points before
        if area == 0.0:
            zero += 1
            assert not n.any() and not ai.any()
        else:
            assert np.all(np.isfinite(ai)) and ai[0, 0] > 0.0 and np.linalg.det(ai) > 0.0
            assert n @ [0.0, 0.0, 1.0] == pytest.approx(1.0)
    assert zero > 60  # the fold is met, not stepped around
    area, _, _, a, ai, _ = frame(xyz, (1.0, 1.0))  # the facet itself: a true frame
    assert area > 0.0
    np.testing.assert_allclose(ai @ a, np.eye(2), atol=1e-12)


def test_kernel_with_an_old_point_on_a_fold_is_frictionless_for_the_step():
    """The friction kernel evaluates the old traction at the old point xi_n: on a fold it takes the element as new
    (frictionless in this evaluation, normal force kept) instead of dividing by zero."""
    xyz = kite()
    xs = np.array([0.2, 0.1, -1e-3])
    xi = np.array([0.0, 0.0])
    assert project_on_facet(xyz, xs, xi)[0] == 0
    states = set()
    for xi_n in fold_points():
        if frame(xyz, xi_n)[0] != 0.0:
            continue
        R, K, ho = np.zeros(30), np.zeros((30, 30)), np.zeros(HIST_SIZE)
        g, st = friction_element(xyz, xs, xi, 100.0, 100.0, 0.3,
                                 make_history(np.array(xi_n), (0.1, 0.0)), R, K, ho)
        states.add(st)
        assert g == pytest.approx(-1e-3) and np.isfinite(R).all() and R[-1] == pytest.approx(-0.1)
    assert states == {NEW}


def test_transfer_beyond_the_fold_anchors_on_the_facet():
    """The old contact point (0.6, 0.6) lies beyond the kite's outer corner, the centroid (1/3, 1/3): on the
    continuation its projection runs into the fold. The history is anchored at the kite's closest point, the
    centroid (xi = (1, 1)), and the spring's stretch from the old point to the anchor goes into the traction:
    t_a = t_n - eps_t (rho_a - rho_n)."""
    xyz = kite()
    rho_n = np.array([0.6, 0.6, 0.0])
    t_n = np.array([0.3, -0.1, 0.0])
    h = make_history((0.0, 0.0), t_n[:2], rho_n, np.eye(3)[:2])  # base e1, e2: T_i = t_n . e_i
    xi = np.array([0.5, 0.5])
    assert project_on_facet(xyz, rho_n, xi)[0] != 0 or np.abs(xi).max() > 1.9  # the fold: the old way's point
    eps_t = 7.0
    h2 = transfer_history(h, xyz, xi0=[0.5, 0.5], eps_t=eps_t)
    assert h2[-1] == 1.0 and np.all(np.isfinite(h2))
    np.testing.assert_allclose(h2[0:2], [1.0, 1.0], atol=1e-9)
    centroid = np.array([1.0, 1.0, 0.0]) / 3.0
    np.testing.assert_allclose(h2[2:5], centroid, atol=1e-12)
    np.testing.assert_allclose(traction_vector(h2), t_n - eps_t * (centroid - rho_n), atol=1e-12)
    # without the slave's penalty the slip between the points is dropped: the traction vector is kept
    np.testing.assert_allclose(traction_vector(transfer_history(h, xyz, xi0=[0.5, 0.5])), t_n, atol=1e-12)


def test_transfer_near_the_facet_keeps_the_projection():
    """An old point within half a facet of the new one projects onto its continuation as before (the anchor is the
    old point itself, the traction vector kept): a slave moving onto the next facet."""
    P = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) * 0.5
    B = np.column_stack([P + [1.0, 0.0], np.zeros(4)])  # x in [0.5, 1.5]
    rho_n = np.array([0.4, 0.1, 0.0])  # 0.1 before its edge x = 0.5: xi = -1.2
    h = make_history((0.0, 0.0), (0.2, 0.05), rho_n, np.eye(3)[:2])
    h2 = transfer_history(h, B, xi0=[-1.0, 0.0], eps_t=50.0)
    np.testing.assert_allclose(h2[0:2], [-1.2, 0.2], atol=1e-12)
    np.testing.assert_allclose(h2[2:5], rho_n, atol=1e-12)
    np.testing.assert_allclose(traction_vector(h2), [0.2, 0.05, 0.0], atol=1e-12)


@pytest.mark.parametrize("mu", [5.0, 0.005])
def test_far_anchor_gives_the_kernel_the_same_traction(mu):
    """On an affine facet the kernel's slip a_ij dxi^j is exact, so a history anchored anywhere on it with the
    shifted traction acts exactly as the old point itself (at its coordinates on the continuation): the same
    residual, state, new traction and stiffness against the slave's motion, in stick (mu = 5) and slip
    (mu = 0.005). (The master columns differ: the two histories follow different material points of the master.)"""
    A = np.array([[0.0, 0.0, 0.0], [1.2, 0.1, 0.0], [1.5, 0.9, 0.0], [0.3, 0.8, 0.0]])  # a parallelogram
    rho_n = np.array([4.0, -2.5, 0.0])  # several facet sizes away
    T_n = np.array([0.4, -0.3])
    rc = np.array([[0.6, 0.05, 0.0], [0.15, 0.4, 0.0]])  # the base of the facet (affine: the same everywhere)
    xi_n = np.linalg.solve(rc[:, :2].T, rho_n[:2] - A.mean(axis=0)[:2])  # the old point's coordinates
    assert np.abs(xi_n).max() > 3.0
    eps_t = 0.05
    anchored = transfer_history(make_history(xi_n, T_n, rho_n, rc), A, xi0=[0.3, 0.2], eps_t=eps_t)
    assert np.abs(anchored[0:2]).max() == pytest.approx(1.0)  # on the facet's boundary
    exact = make_history(xi_n, T_n, rho_n, rc)
    xs = A.mean(axis=0) + [0.1, 0.05, -0.02]
    out = []
    for h in (anchored, exact):
        xi = np.array([0.0, 0.0])
        assert project_on_facet(A, xs, xi)[0] == 0
        R, K, ho = np.zeros(15), np.zeros((15, 15)), np.zeros(HIST_SIZE)
        g, st = friction_element(A, xs, xi, 30.0, eps_t, mu, h, R, K, ho)
        out.append((R, K, st, ho[11:13]))
    assert out[0][2] == out[1][2] == (STICK if mu > 1.0 else SLIP)
    np.testing.assert_allclose(out[0][0], out[1][0], rtol=1e-9, atol=1e-12 * np.abs(out[1][0]).max())
    np.testing.assert_allclose(out[0][1][:, 12:], out[1][1][:, 12:], rtol=1e-9, atol=1e-12 * np.abs(out[1][1]).max())
    np.testing.assert_allclose(out[0][3], out[1][3], rtol=1e-9)


def test_start_history_of_a_slave_beyond_the_fold():
    """A slave new to contact whose committed position projects beyond the facet's regular continuation sticks from
    the facet's closest point, with the spring's stretch to its own position as traction (zero at its own point)."""
    xyz = kite()
    xs = np.array([0.6, 0.6, 1e-3])
    h = start_history(xyz, xs, np.array([0.5, 0.5]), eps_t=3.0)
    assert h[-1] == 1.0
    np.testing.assert_allclose(h[0:2], [1.0, 1.0], atol=1e-9)
    t = traction_vector(h)
    np.testing.assert_allclose(t, -3.0 * (np.array([1.0, 1.0, 0.0]) / 3.0 - xs) * [1.0, 1.0, 0.0], atol=1e-12)
    # on the facet: its own projection, no traction (as before)
    h = start_history(xyz, np.array([0.1, 0.05, -1e-3]), np.array([0.0, 0.0]), eps_t=3.0)
    np.testing.assert_allclose(h[2:5], [0.1, 0.05, 0.0], atol=1e-12)
    np.testing.assert_allclose(h[11:13], 0.0, atol=1e-15)
