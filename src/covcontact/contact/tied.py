"""Tied pairs (``law = "tied"``): slave points bonded to the master surface (docs/theory.md, section 14).

Each slave (a node, or a Gauss point of a slave facet for ``type = "sts"``) is tied in the reference
configuration to its closest point X_m(xi_0) on the master surface, if that lies within the tie tolerance; the
convective coordinates xi_0 and the facet never change. A vector penalty eps (x_s - x_m(xi_0)) keeps the pair of
points together in every direction (no opening, no sliding): with c = (-N_1(xi_0), ..., -N_n(xi_0), 1),

    R = eps c (x) d,    K = eps (c c^T) (x) I_3,    d = x_s - sum_b N_b(xi_0) x_b,

exact and constant, so a tied interface adds a linear multi-point constraint in penalty form.
"""

from __future__ import annotations

import numpy as np

from ..fem.shapes import shape_functions
from .driver import NO_CONTACT, closest_points
from .surface import MeshSurface, facet_sizes


def tie(X: np.ndarray, surface: MeshSurface, xs: np.ndarray, tolerance: float | None):
    """Tie slaves at reference positions xs (ns, 3) to ``surface`` at reference nodes X.

    Returns (facet (ns,) -1 where no master point lies within the tolerance, N (ns, nen) the master shape values
    at the tie point). ``tolerance`` None: 5 % of the mean master facet size.
    """
    sizes = facet_sizes(X, surface.faces)
    tol = 0.05 * float(sizes.mean()) if tolerance is None else float(tolerance)
    res = closest_points(X, surface, xs, float(sizes.max()), gmax=np.inf, min_cos=-1.0)
    ok = (res.kind != NO_CONTACT) & (np.abs(res.g) <= tol)
    facet = np.where(ok, res.facet, -1)
    cell = "quad4" if surface.nen == 4 else "quad9"
    xi = np.clip(res.xi, -1.0, 1.0)
    N = shape_functions(cell, xi)[0] if len(xi) else np.zeros((0, surface.nen))
    return facet.astype(np.int64), np.where(ok[:, None], N, 0.0)


def tied_blocks(xe: np.ndarray, faces: np.ndarray, N: np.ndarray, xs: np.ndarray, eps: np.ndarray,
                want_K: bool = True):
    """Residual and tangent of tied points: faces (m, nen) their master facets' nodes, N (m, nen) the tie point's
    shape values, xs (m, 3) the slaves, eps (m,). Returns (R (m, 3 (nen+1)), K or None, d (m, 3))."""
    m = len(xs)
    c = np.hstack([-N, np.ones((m, 1))])
    d = xs - np.einsum("ma,mai->mi", N, xe[faces])
    R = (eps[:, None, None] * c[:, :, None] * d[:, None, :]).reshape(m, -1)
    if not want_K:
        return R, None, d
    K = eps[:, None, None, None, None] * c[:, :, None, None, None] * c[:, None, None, :, None] * np.eye(3)[None, None,
                                                                                                         :, None, :]
    n = c.shape[1]
    return R, K.reshape(m, 3 * n, 3 * n), d
