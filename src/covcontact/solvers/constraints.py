"""Linear multi-point constraints by elimination (docs/theory.md, "Multi-point constraints").

Each equation sum_k c_k u_k = 0 names its first dof d as the dependent one: u_d = sum_{k > 0} a_k u_k with
a_k = -c_k / c_d. With T the (n x n) map u = T v (identity on the other dofs, row d holding the a_k, column d
zero) the residual and the tangent become T^T R and T^T K T: the dependent dofs drop out (their rows and columns
are zero, and the solver treats them as constrained), the others carry the forces the constraint hands over.
After every change of u the dependent dofs are set from the independent ones (``complete``), so every
evaluation is made at a displacement that satisfies the constraints exactly.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


class LinearConstraints:
    """The equations of a problem (``covcontact.loads.Equation``) on the dofs of ``system``."""

    def __init__(self, equations, system):
        n = system.n_dofs
        dep, rows, cols, vals = [], [], [], []
        for eq in equations:
            (b0, s0, c0, k0), *rest = eq.terms
            d = 3 * int(system.global_nodes(b0, s0)[0]) + c0
            dep.append(d)
            for b, s, c, k in rest:
                rows.append(d)
                cols.append(3 * int(system.global_nodes(b, s)[0]) + c)
                vals.append(-k / k0)
        self.dependent = np.asarray(dep, dtype=np.int64)
        self.mask = np.zeros(n, dtype=bool)
        self.mask[self.dependent] = True
        A = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))  # (repeated terms summed)
        # chains (an eliminated dof among another equation's terms): substitute until no row refers to one (the input
        # has no cycles, so this ends within as many rounds as there are equations)
        drop = sp.diags(np.where(self.mask, 0.0, 1.0))
        for _ in range(len(dep) + 1):
            B = A[:, self.dependent]
            if B.nnz == 0:
                break
            A = (A @ drop + B @ A[self.dependent]).tocsr()
            A.eliminate_zeros()
        keep = np.where(self.mask, 0.0, 1.0)
        self.T = (sp.diags(keep) + A).tocsr()
        self.Tt = self.T.T.tocsr()
        self.rows = A[self.dependent].tocsr()
        self.unit = sp.diags(self.mask.astype(float)).tocsr()  # (the dependent dofs' diagonal: kept in the pattern)

    def complete(self, u: np.ndarray) -> None:
        """Set the dependent dofs of ``u`` (in place) from the others."""
        u[self.dependent] = self.rows @ u

    def transform(self, R: np.ndarray, K):
        """(T^T R, T^T K T) (K may be None)."""
        R = self.Tt @ R
        if K is not None:
            K = (self.Tt @ K @ self.T + self.unit).tocsr()
            K.sort_indices()
        return R, K
