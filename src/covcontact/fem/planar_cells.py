"""Shape functions, integration rules and edge tables of the planar cells (quad4, quad8, quad9, tri3, tri6) of
plane strain, plane stress and axisymmetric bodies (``covcontact.elements.planar``).

Node orders follow VTK (and meshio, Gmsh, Abaqus): quad4 corners (-1, -1), (1, -1), (1, 1), (-1, 1); quad8 the
corners, then the mid-nodes of the edges 0-1, 1-2, 2-3, 3-0; quad9 the quad8 and the centre; tri3 (0, 0), (1, 0),
(0, 1); tri6 the corners, then the mid-nodes of 0-1, 1-2, 2-0. Cells are counter-clockwise in the x-y plane.
"""

from __future__ import annotations

import numpy as np

from .cells import _triangle_rule, face_shapes
from .quadrature import gauss_quad
from .shapes import shape_functions

PLANAR_CELLS = ("quad4", "quad8", "quad9", "tri3", "tri6")
PLANAR_NNODES = {"quad4": 4, "quad8": 8, "quad9": 9, "tri3": 3, "tri6": 6}
#: the cells that take integration = "reduced" (quad8: 2 x 2 points, as CPE8R, CPS8R, CAX8R)
REDUCED_CELLS = ("quad8",)

#: the edges of each cell, outward ordered: start and end corner counter-clockwise around the cell (the body on the
#: left, so the outward normal is the edge tangent turned clockwise), then the mid-node; edge k is Abaqus's face
#: S(k+1)
EDGES = {
    "quad4": np.array([[0, 1], [1, 2], [2, 3], [3, 0]], dtype=np.int64),
    "quad8": np.array([[0, 1, 4], [1, 2, 5], [2, 3, 6], [3, 0, 7]], dtype=np.int64),
    "quad9": np.array([[0, 1, 4], [1, 2, 5], [2, 3, 6], [3, 0, 7]], dtype=np.int64),
    "tri3": np.array([[0, 1], [1, 2], [2, 0]], dtype=np.int64),
    "tri6": np.array([[0, 1, 3], [1, 2, 4], [2, 0, 5]], dtype=np.int64),
}
#: natural coordinates of the cell centres (for orientation checks)
CENTRE = {"quad4": (0.0, 0.0), "quad8": (0.0, 0.0), "quad9": (0.0, 0.0), "tri3": (1 / 3, 1 / 3),
          "tri6": (1 / 3, 1 / 3)}

def _dunavant5() -> tuple[np.ndarray, np.ndarray]:
    """7 points of degree 5 on the unit triangle (area 1/2)."""
    a1, b1 = 0.059715871789770, 0.470142064105115
    a2, b2 = 0.797426985353087, 0.101286507323456
    bary = [(1 / 3, 1 / 3, 1 / 3), (a1, b1, b1), (b1, a1, b1), (b1, b1, a1), (a2, b2, b2), (b2, a2, b2), (b2, b2, a2)]
    w = [0.225] + [0.132394152788506] * 3 + [0.125939180544827] * 3
    return np.array([[p[1], p[2]] for p in bary]), 0.5 * np.array(w)


def planar_rule(cell_type: str, integration: str = "full") -> tuple[np.ndarray, np.ndarray]:
    """(points (n, 2), weights (n,)) of the stiffness rule: quad4 2 x 2, quad8 and quad9 3 x 3 (quad8 reduced:
    2 x 2), tri3 1 point, tri6 3 points; ``integration = "mass"``: a rule exact for R N_a N_b on an affine cell."""
    if cell_type not in PLANAR_CELLS:
        raise ValueError(f"unknown planar cell type {cell_type!r}; known: {', '.join(PLANAR_CELLS)}")
    if integration == "mass":
        if cell_type in ("tri3", "tri6"):
            return _dunavant5()
        return gauss_quad(2 if cell_type == "quad4" else 3)
    if integration == "reduced":
        if cell_type not in REDUCED_CELLS:
            raise ValueError(f"reduced integration is for {', '.join(REDUCED_CELLS)} (as CPE8R), not {cell_type}")
        return gauss_quad(2)
    if integration != "full":
        raise ValueError(f"integration must be \"full\" or \"reduced\", got {integration!r}")
    if cell_type == "quad4":
        return gauss_quad(2)
    if cell_type in ("quad8", "quad9"):
        return gauss_quad(3)
    if cell_type == "tri3":
        return np.array([[1 / 3, 1 / 3]]), np.array([0.5])
    return _triangle_rule()


def planar_shapes(cell_type: str, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N (npts, nen) and dN/dxi (npts, nen, 2) of a planar cell at natural ``points`` (npts, 2)."""
    p = np.ascontiguousarray(np.atleast_2d(points), dtype=np.float64)
    if cell_type in ("quad4", "quad9"):
        N, dN, _ = shape_functions(cell_type, p)
        return np.ascontiguousarray(N), np.ascontiguousarray(dN)
    N, dN = face_shapes(cell_type, p)
    return np.ascontiguousarray(N), np.ascontiguousarray(dN)


def reference_jacobians(cell_type: str, X: np.ndarray, cells: np.ndarray, points: np.ndarray | None = None):
    """det(dX/dxi) (in-plane) of every cell at natural ``points`` (default the full rule), (nelem, npts)."""
    pts = planar_rule(cell_type)[0] if points is None else np.atleast_2d(points)
    _, dN = planar_shapes(cell_type, pts)
    J = np.einsum("eai,paj->epij", X[cells][:, :, :2], dN)
    return J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]


def line_shapes(nfn: int, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N (n, nfn) and dN/ds of a 2-node (ends -1, 1) or 3-node (ends, then the mid-node at 0) edge."""
    if nfn == 2:
        return np.stack([0.5 * (1 - s), 0.5 * (1 + s)], axis=1), np.stack([-0.5 + 0 * s, 0.5 + 0 * s], axis=1)
    N = np.stack([0.5 * s * (s - 1), 0.5 * s * (s + 1), 1 - s * s], axis=1)
    dN = np.stack([s - 0.5, s + 0.5, -2 * s], axis=1)
    return N, dN
