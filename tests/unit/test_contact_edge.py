"""Edge and vertex contact points: the exact tangent against central differences of the residual, the
closest edge point recomputed for every perturbed position (docs/theory.md section 5: exact tangent, to
1e-6)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.contact.edge import edge_vertex_contact, free_direction
from covcontact.contact.surface import EDGE_DIR, EDGE_START, edge_closest_point
from covcontact.fem.shapes import NODES


def curved_facet(nen: int, rng) -> np.ndarray:
    nat = NODES["quad4" if nen == 4 else "quad9"]
    xyz = np.column_stack([nat[:, 0], nat[:, 1], 0.15 * nat[:, 0] ** 2 - 0.1 * nat[:, 0] * nat[:, 1]])
    return xyz + 0.03 * rng.standard_normal(xyz.shape)


def edge_residual(q: np.ndarray, nen: int, e: int, sign: float, eps: float, lam: float) -> np.ndarray:
    xyz = q[:-3].reshape(nen, 3)
    xs = q[-3:]
    c = np.empty(3)
    t, _ = edge_closest_point(xyz, e, xs, c)
    assert abs(t) < 1.0  # the point stays inside the edge
    xi = EDGE_START[e] + (t + 1.0) * EDGE_DIR[e]
    return edge_vertex_contact(xyz, xi, xs, sign, eps, lam)[0]


@pytest.mark.parametrize("nen", [4, 9])
@pytest.mark.parametrize("sign", [1.0, -1.0])
@pytest.mark.parametrize("lam", [0.0, 0.7])
@pytest.mark.parametrize("e", [1, 2])
def test_edge_tangent_matches_finite_differences(nen, sign, lam, e):
    rng = np.random.default_rng(nen + 10 * e)
    xyz = curved_facet(nen, rng)
    # a slave beyond the edge e, off the surface on the chosen side
    xi_c = EDGE_START[e] + 0.7 * EDGE_DIR[e]
    outward = np.array([1.0, 0.0, 0.0]) if e == 1 else np.array([0.0, 1.0, 0.0])
    xs = np.array([xi_c[0], xi_c[1], 0.1]) + 0.25 * outward + np.array([0.0, 0.0, 0.3 * sign])
    q = np.concatenate([xyz.ravel(), xs])
    c = np.empty(3)
    t, _ = edge_closest_point(xyz, e, xs, c)
    xi = EDGE_START[e] + (t + 1.0) * EDGE_DIR[e]
    assert free_direction(xi) == (0 if e in (0, 2) else 1)
    eps = 3.0
    R, K, g = edge_vertex_contact(xyz, xi, xs, sign, eps, lam)
    assert np.sign(g) == sign
    h = 1e-6
    K_fd = np.empty_like(K)
    for j in range(q.size):
        dq = np.zeros_like(q)
        dq[j] = h
        K_fd[:, j] = (edge_residual(q + dq, nen, e, sign, eps, lam) - edge_residual(q - dq, nen, e, sign, eps, lam)) / (2 * h)
    err = np.abs(K - K_fd).max() / np.abs(K).max()
    assert err < 1e-6, err
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    # the tangent without the sliding term (eps A^T A) is measurably wrong
    A_only = edge_vertex_contact(xyz, xi, xs, sign, eps, lam, vertex=True)[1]
    assert np.abs(A_only - K_fd).max() / np.abs(K).max() > 1e-3


@pytest.mark.parametrize("lam", [0.0, 0.5])
def test_vertex_tangent_matches_finite_differences(lam):
    rng = np.random.default_rng(3)
    xyz = curved_facet(9, rng)
    xi = np.array([1.0, 1.0])
    xs = xyz[2] + np.array([0.2, 0.3, -0.25])

    def res(q):
        return edge_vertex_contact(q[:-3].reshape(9, 3), xi, q[-3:], -1.0, 2.0, lam, vertex=True)[0]

    q = np.concatenate([xyz.ravel(), xs])
    R, K, g = edge_vertex_contact(xyz, xi, xs, -1.0, 2.0, lam, vertex=True)
    h = 1e-6
    K_fd = np.column_stack([(res(q + h * np.eye(q.size)[j]) - res(q - h * np.eye(q.size)[j])) / (2 * h)
                            for j in range(q.size)])
    assert np.abs(K - K_fd).max() / np.abs(K).max() < 1e-6
    assert g < 0.0
