"""The Cauchy stress at every Gauss point of a body (the deck's *EL PRINT table; docs/input.md, "Abaqus and CalculiX
decks"), from the same kernel that averages it over the element: called once per Gauss point with a one-point rule
(the point's own derivatives, weight and history), whose average is that point's value."""

from __future__ import annotations

import numpy as np

from .composite import CompositeBody
from .solid import SolidBody, solid_gauss_fields


def point_stresses(solid, u: np.ndarray, state: dict | None = None) -> np.ndarray:
    """(n_elements, n_points, 6) Cauchy stress (xx, yy, zz, xy, yz, xz) at the Gauss points of a solid body at its
    displacement ``u`` (nnode, 3) and element history ``state``; NaN past a cell's own points (a body whose cell types
    mix). A ValueError for formulations other than the plain solid and incompatible modes (F-bar, solid-shell)."""
    state = solid.new_state() if state is None else state
    if isinstance(solid, CompositeBody):
        rows = [point_stresses(part, u, solid._views(k, state)[0]) for k, part in enumerate(solid.parts)]
        out = np.full((solid.n_elements, max(r.shape[1] for r in rows), 6), np.nan)
        for idx, r in zip(solid.index, rows):
            out[idx, : r.shape[1]] = r
        return out
    if hasattr(solid, "point_stresses"):  # (an element body with its own Gauss-point stresses: incompatible modes)
        return solid.point_stresses(u, state)
    if not isinstance(solid, SolidBody):
        raise ValueError(f"stresses at Gauss points are for solid elements, not {type(solid).__name__}")
    u = solid._u(u)
    ngp = solid.weights.size
    out = np.empty((solid.n_elements, ngp, 6))
    buf = np.empty((solid.n_elements, 18))
    hist = state["hist"]
    for g in range(ngp):
        if solid.n_elements:
            solid_gauss_fields(solid.material.kind, solid.material.params, solid.X, u, solid.cells,
                               np.ascontiguousarray(solid.dNdxi[g: g + 1]), np.ascontiguousarray(solid.weights[g: g + 1]),
                               2, buf, np.ascontiguousarray(hist[:, g: g + 1]))
        out[:, g] = buf[:, :6]
    return out


def point_plastic_strains(solid, state: dict | None = None) -> np.ndarray | None:
    """(n_elements, n_points) equivalent plastic strain at the Gauss points (the J2 history), NaN past a cell's own
    points; None for a body without plastic history. Zero in the elastic parts of a composite body."""
    from ..materials.plasticity import H_ALPHA, J2

    state = solid.new_state() if state is None else state
    if isinstance(solid, CompositeBody):
        rows = [point_plastic_strains(part, solid._views(k, state)[0]) for k, part in enumerate(solid.parts)]
        if all(r is None for r in rows):
            return None
        width = max(p.weights.size for p in solid.parts)
        out = np.full((solid.n_elements, width), np.nan)
        for idx, r, part in zip(solid.index, rows, solid.parts):
            out[idx, : part.weights.size] = 0.0 if r is None else r
        return out
    hist = state.get("hist")
    if hist is None or getattr(solid, "material", None) is None or solid.material.kind != J2:
        return None
    return np.array(hist[:, :, H_ALPHA])
