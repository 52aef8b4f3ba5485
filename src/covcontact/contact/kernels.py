"""Compiled contact assembly kernel over many slave-facet pairs (the twin of ``node_to_surface``).

Case codes (``case`` argument), as in ``element.CASES``:

- ``CASE_A`` (0): main + rotational + curvature, the paper's full tangent (eq. 20);
- ``CASE_B`` (1): main + rotational;
- ``CASE_C`` (2): main + curvature;
- ``CASE_D`` (3): main only;
- ``CASE_EXACT`` (4): exact Hessian of the contact energy (adds the second-order terms).

Normal law: penalty, or augmented Lagrangian with the per-pair Uzawa multipliers ``lam_k`` (see
``element``).

Parts in ``P_out[:, k]`` follow ``PART_NAMES``: 0 main, 1 rotational, 2 curvature, 3 second order.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from covcontact.contact.element import (
    CASE_A,
    CASE_B,
    CASE_C,
    CASE_D,
    CASE_EXACT,
    CASES,
    PART_NAMES,
    element_core,
    new_work,
)

__all__ = ["CASES", "CASE_A", "CASE_B", "CASE_C", "CASE_D", "CASE_EXACT", "PART_NAMES", "contact_batch"]

_CHUNK = 16


@njit(cache=True, parallel=True)
def contact_batch(
    x_nodes, facet_conn, slave_ids, xi, eps, case, want_parts, R_out, K_out, P_out, g_out, lam_k=None
):
    """Residuals and tangents of npair slave-facet pairs of one facet type, parallel over pairs.

    Args:
        x_nodes: (nnode, 3) current positions of all nodes.
        facet_conn: (npair, n) int64 master facet node ids, n = 4 or 9 (VTK order).
        slave_ids: (npair,) int64 slave node ids.
        xi: (npair, 2) converged projections.
        eps: (npair,) penalty per pair (already weighted).
        case: CASE_A ... CASE_EXACT.
        want_parts: fill P_out with the four parts.
        R_out: (npair, 3(n+1)) out. K_out: (npair, 3(n+1), 3(n+1)) out.
        P_out: (npair, 4, 3(n+1), 3(n+1)) out, or a dummy (e.g. (1, 4, 1, 1)) if not want_parts.
        g_out: (npair,) out, geometric gaps (+inf at a degenerate facet point; zero R, K when
            lam_k + eps g > 0).
        lam_k: (npair,) augmented Lagrangian multipliers (<= 0) of the last Uzawa update, held
            fixed during Newton; None (default) or zeros: pure penalty.

    Local dof order of a pair: the n master nodes, then the slave (paper eq. 14).
    """
    npair, nen = facet_conn.shape
    nchunk = (npair + _CHUNK - 1) // _CHUNK
    # np.bool_: run-time values to numba, so element_core is compiled once for every caller, not per constant
    yes, no = np.bool_(True), np.bool_(False)
    for c in prange(nchunk):
        work = new_work()  # scratch per chunk of pairs, not per pair
        xyz = np.empty((nen, 3))
        xs = np.empty(3)
        lo = c * _CHUNK
        hi = min(npair, lo + _CHUNK)
        for k in range(lo, hi):
            for a in range(nen):
                node = facet_conn[k, a]
                for p in range(3):
                    xyz[a, p] = x_nodes[node, p]
            s = slave_ids[k]
            for p in range(3):
                xs[p] = x_nodes[s, p]
            lk = 0.0
            if lam_k is not None:
                lk = lam_k[k]
            if want_parts:
                g_out[k] = element_core(
                    xyz, xs, xi[k, 0], xi[k, 1], eps[k], case, yes, R_out[k], K_out[k], P_out[k], work, lk
                )
            else:
                g_out[k] = element_core(
                    xyz, xs, xi[k, 0], xi[k, 1], eps[k], case, no, R_out[k], K_out[k], P_out[0], work, lk
                )
