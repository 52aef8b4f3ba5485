"""Central differences of a model's residual in chosen dofs: the columns the constraint tests (equations, rigid
links, couplings, nonlinear MPCs) hold their reduced tangents against."""

from __future__ import annotations

import numpy as np


def column_errors(model, u: np.ndarray, lam: float, committed, K: np.ndarray, columns, h: float = 1e-6) -> dict:
    """{dof: max |(R(u + h e_j) - R(u - h e_j)) / (2 h) - K[:, j]|} for each dof j of ``columns`` (the residual of
    ``model.evaluate`` at load factor ``lam`` from the state ``committed``; ``K`` dense)."""
    out = {}
    for j in columns:
        up, um = u.copy(), u.copy()
        up[j] += h
        um[j] -= h
        col = (model.evaluate(up, lam, committed, want_K=False)[0]
               - model.evaluate(um, lam, committed, want_K=False)[0]) / (2 * h)
        out[int(j)] = float(np.abs(col - K[:, j]).max())
    return out
