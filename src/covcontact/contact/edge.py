"""Contact of a slave node with an edge or a vertex of the master surface (the blind spots of
node-to-surface contact, see :mod:`covcontact.contact.driver`).

The contact point c is the closest point of the facet boundary: a fixed node (vertex) or the closest point
c(t*) of an edge curve (edge, t* = argmin |x_s - c(t)|). With D = x_s - c, the signed gap g = s |D| (s the
side the driver chose) and the normal n = s D / |D|, the energy is W = lam g + eps g^2 / 2 (lam the
augmented-Lagrangian multiplier, 0 for the pure penalty). Residual and exact tangent, q = (facet nodes,
slave):

    R = (lam + eps g) A^T n,        A = dD/dq = [-N_a(t) I ..., I]
    K = eps A^T n n^T A + (lam + eps g) / g (H0 - A^T n n^T A)
    H0 = A^T A - b b^T / phi_tt     (Hessian of |D|^2 / 2 with t* moving along the edge)
    b = -A^T c' + A_t^T D,  phi_tt = c'.c' - D.c'',  A_t = dA/dt

For a vertex, H0 = A^T A (the point does not move). Without the b b^T term (the earlier eps A^T A) the point
sliding along the edge is ignored and Newton converges only linearly.
"""

from __future__ import annotations

import numpy as np

from ..fem.shapes import shape_functions
from .laws import normal_pressure


def free_direction(xi: np.ndarray) -> int:
    """Element coordinate that runs along the edge holding xi (the other one is -1 or +1)."""
    return 0 if abs(abs(xi[1]) - 1.0) <= abs(abs(xi[0]) - 1.0) else 1


def edge_vertex_batch(xe: np.ndarray, conn: np.ndarray, xi: np.ndarray, g: np.ndarray, vertex: np.ndarray,
                      eps: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`edge_vertex_contact` of m points: ``conn`` (m, nen + 1) their facets' nodes then the slave, ``xi`` (m, 2)
    their contact points, ``g`` their projections' signed gaps (the side), ``vertex`` (m,) vertex points, ``eps`` and
    ``lam`` (m,) their laws. Returns residuals (m, 3 (nen + 1)), tangents and signed gaps."""
    m, n1 = conn.shape
    R = np.zeros((m, 3 * n1))
    K = np.zeros((m, 3 * n1, 3 * n1))
    gap = np.zeros(m)
    for j in range(m):
        R[j], K[j], gap[j] = edge_vertex_contact(xe[conn[j, :-1]], xi[j], xe[conn[j, -1]], 1.0 if g[j] >= 0.0 else -1.0,
                                                 float(eps[j]), float(lam[j]), vertex=bool(vertex[j]))
    return R, K, gap


def edge_vertex_contact(xyz: np.ndarray, xi: np.ndarray, xs: np.ndarray, sign: float, eps: float,
                        lam: float = 0.0, vertex: bool = False) -> tuple[np.ndarray, np.ndarray, float]:
    """Residual (3 (nen + 1),), tangent and signed gap of one edge or vertex contact point.

    Args:
        xyz: (nen, 3) facet nodes (quad4 or quad9, VTK order).
        xi: (2,) the contact point in the facet's element coordinates (on its boundary).
        xs: (3,) slave position.
        sign: +1 or -1, the side of the surface (g = sign |x_s - c|).
        eps: penalty; lam: multiplier (augmented Lagrangian).
        vertex: True for a vertex point (c fixed to a node).
    """
    nen = xyz.shape[0]
    cell = "quad4" if nen == 4 else "quad9"
    N, dN, ddN = shape_functions(cell, np.asarray(xi, float)[None, :])
    N, dN, ddN = N[0], dN[0], ddN[0]
    nd = 3 * (nen + 1)
    A = np.zeros((3, nd))
    for a in range(nen):
        A[:, 3 * a: 3 * a + 3] = -N[a] * np.eye(3)
    A[:, -3:] = np.eye(3)
    D = xs - N @ xyz
    dist = float(np.linalg.norm(D))
    g = sign * dist
    n = sign * D / dist if dist > 0.0 else np.zeros(3)
    f1 = normal_pressure(g, lam, eps)
    An = A.T @ n
    R = f1 * An
    H0 = A.T @ A
    if not vertex:
        k = free_direction(xi)
        c1 = dN[:, k] @ xyz
        c2 = ddN[:, k, k] @ xyz
        phi_tt = float(c1 @ c1 - D @ c2)
        if phi_tt > 1e-12 * float(c1 @ c1):
            At = np.zeros((3, nd))
            for a in range(nen):
                At[:, 3 * a: 3 * a + 3] = -dN[a, k] * np.eye(3)
            b = -A.T @ c1 + At.T @ D
            H0 = H0 - np.outer(b, b) / phi_tt
    if dist > 0.0:
        K = eps * np.outer(An, An) + (f1 / g) * (H0 - np.outer(An, An))
    else:
        K = eps * H0
    return R, K, g
