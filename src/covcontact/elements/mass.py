"""Mass matrices of the solid cells (docs/theory.md, section 20).

Total Lagrangian: the mass is that of the reference configuration and constant, M_ab = int rho N_a N_b dV0 (times
the 3 x 3 identity per node pair). Each cell type is integrated with a rule exact for N_a N_b on an affine cell (the
stiffness rules are not: the 4-point rule of tet10 and the reduced rules): hex8 2 x 2 x 2, hex18 3 x 3 x 2, hex27
and hex20 3 x 3 x 3, tet4 4 points, tet10 11 points (Keast, degree 4), wedge6 3 x 2. Solid-shells are isoparametric
bricks, so their mass is the same integral over their volume (their thickness direction is the element's third).

Lumped mass: HRZ (Hinton, Rock and Zienkiewicz 1976): the diagonal of the consistent element matrix scaled so that
the element's mass is kept, m_a = M_aa m_e / sum_b M_bb. It is positive for every cell type (row sums are not: the
corner rows of tet10 and hex20 sum to zero or less).

Redistributed mass (Khenous, Laborde and Renard 2008, Eur. J. Mech. A/Solids 27, 918-932): the lumped mass with the
nodes of the contact surfaces made massless, their mass moved to the other nodes of their elements. The contact
boundary then has no inertia of its own: an impact does not make it rattle between open and closed, and the
time-discrete problem keeps its energy (docs/theory.md, section 20).

Consistent redistributed mass: the consistent mass in the elements away from the contact surfaces, the redistributed
lumped mass in the elements that have a node on them. The contact boundary has no inertia as with the redistributed
mass, and the interior keeps the consistent mass, whose dispersion partly cancels that of the trapezoidal and
generalized-alpha rules: an impact leaves less of its energy in the bar's ringing (docs/theory.md, section 20).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..fem import cells as other_cells
from ..fem.quadrature import gauss_tensor
from ..fem.shapes import shape_functions

#: the mass rule of each cell type: tensor Gauss points per direction (bricks) or a rule's point count
MASS_RULE = {"hex8": (2, 2, 2), "hex18": (3, 3, 2), "hex27": (3, 3, 3), "hex20": 27, "tet4": 4, "tet10": 11,
             "wedge6": 6}


def _rule(cell_type: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(N (np, nen), dN (np, nen, 3), weights (np,)) of the mass rule."""
    rule = MASS_RULE[cell_type]
    if cell_type in other_cells.CELLS:
        pts, w = other_cells.rule(cell_type, rule)
        N, dN = other_cells.shapes(cell_type, pts)
        return N, dN, w
    pts, w = gauss_tensor(rule)
    N, dN, _ = shape_functions(cell_type, pts)
    return N, dN, w


def element_masses(cell_type: str, X: np.ndarray, cells: np.ndarray, density: float) -> np.ndarray:
    """Consistent scalar element mass matrices (ne, nen, nen): rho int N_a N_b dV0."""
    N, dN, w = _rule(cell_type)
    J = np.einsum("eai,paj->epij", X[cells], dN)
    dV = np.linalg.det(J) * w[None, :]  # (ne, np)
    return density * np.einsum("ep,pa,pb->eab", dV, N, N)


def lump(Me: np.ndarray) -> np.ndarray:
    """HRZ lumping of element mass matrices (ne, nen, nen) -> (ne, nen) diagonals keeping each element's mass."""
    diag = np.einsum("eaa->ea", Me)
    total = Me.sum(axis=(1, 2))
    return diag * (total / diag.sum(axis=1))[:, None]


def redistribute(cells: np.ndarray, m: np.ndarray, massless: np.ndarray) -> np.ndarray:
    """Lumped element masses (ne, nen) with the mass of the ``massless`` nodes (a boolean mask over the node ids)
    moved to the element's other nodes in proportion to theirs: each element keeps its mass. An element whose nodes
    are all massless keeps its masses."""
    zero = massless[cells]
    keep = m * ~zero
    total, left = m.sum(axis=1), keep.sum(axis=1)
    scale = np.divide(total, left, out=np.ones_like(total), where=left > 0)
    return np.where((left > 0)[:, None], keep * scale[:, None], m)


def assemble_mass(n_nodes: int, blocks: list[tuple[np.ndarray, np.ndarray]], lumped: bool,
                  massless: np.ndarray | None = None, consistent_interior: bool = False) -> sp.csr_matrix:
    """The scalar (node by node) mass matrix of element blocks [(cells + offset, Me (ne, nen, nen))], consistent or
    HRZ-lumped (with the mass of the ``massless`` nodes redistributed, :func:`redistribute`); with
    ``consistent_interior`` (and ``massless``) the elements without a massless node keep their consistent matrices.
    The dof matrix is its Kronecker product with the 3 x 3 identity."""
    if consistent_interior and massless is not None:
        split = []
        for cells, Me in blocks:
            touch = massless[cells].any(axis=1)
            split.append(((cells[touch], Me[touch]), (cells[~touch], Me[~touch])))
        edge = assemble_mass(n_nodes, [a for a, _ in split], True, massless)
        return (edge + assemble_mass(n_nodes, [b for _, b in split], False)).tocsr()
    rows, cols, vals = [], [], []
    for cells, Me in blocks:
        if lumped:
            m = lump(Me)
            if massless is not None:
                m = redistribute(cells, m, massless)
            rows.append(cells.ravel())
            cols.append(cells.ravel())
            vals.append(m.ravel())
        else:
            nen = cells.shape[1]
            rows.append(np.repeat(cells, nen, axis=1).ravel())
            cols.append(np.tile(cells, (1, nen)).ravel())
            vals.append(Me.ravel())
    if not rows:
        return sp.csr_matrix((n_nodes, n_nodes))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n_nodes, n_nodes))


def dof_matrix(M_nodes: sp.csr_matrix) -> sp.csr_matrix:
    """The dof mass matrix (3 n, 3 n) of a scalar node mass matrix: M_(3a+i, 3b+j) = M_ab delta_ij."""
    return sp.kron(M_nodes, sp.identity(3, format="csr"), format="csr")
