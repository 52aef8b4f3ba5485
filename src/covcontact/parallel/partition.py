"""Partition of a problem over MPI ranks and the PETSc dof numbering that follows from it.

Elements of all bodies are split together by recursive coordinate bisection (RCB) of their reference
centroids, weighted by an estimate of their assembly cost; a node belongs to the lowest rank among its
elements. PETSc needs each rank to own a contiguous range of rows, so the nodes are renumbered rank by
rank (keeping the natural order inside a rank): PETSc dof ``3 p + i`` is node ``node_of[p]``, direction i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def rcb(points: np.ndarray, weights: np.ndarray, nparts: int) -> np.ndarray:
    """Part (0 .. nparts - 1) of every point: recursive bisection across the longest extent.

    A split into k and nparts - k parts (k = nparts // 2) cuts the sorted points where the weight
    reaches k / nparts of the total, so any number of parts gets balanced weights.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    weights = np.asarray(weights, dtype=np.float64)
    part = np.zeros(len(points), dtype=np.int64)
    stack = [(np.arange(len(points)), 0, int(nparts))]
    while stack:
        idx, first, n = stack.pop()
        if n <= 1 or idx.size == 0:
            part[idx] = first
            continue
        k = n // 2
        p = points[idx]
        axis = int(np.argmax(p.max(axis=0) - p.min(axis=0)))
        order = idx[np.lexsort((idx, p[:, axis]))]  # stable: ties by index
        cum = np.cumsum(weights[order])
        cut = int(np.searchsorted(cum, cum[-1] * k / n, side="left")) + 1
        cut = min(max(cut, 1), idx.size - 1) if idx.size > 1 else idx.size
        stack.append((order[:cut], first, k))
        stack.append((order[cut:], first + k, n - k))
    return part


def node_owners(n_nodes: int, cells: list[np.ndarray], parts: list[np.ndarray]) -> np.ndarray:
    """Lowest part among the elements of every node (0 for a node of no element)."""
    big = np.iinfo(np.int64).max
    owner = np.full(n_nodes, big, dtype=np.int64)
    for c, p in zip(cells, parts):
        np.minimum.at(owner, c.ravel(), np.repeat(p, c.shape[1]))
    owner[owner == big] = 0
    return owner


@dataclass
class DofLayout:
    """Global dofs (natural numbering, 3 a + i) against PETSc's rank-contiguous numbering.

    Attributes:
        rank, size: this rank and the number of ranks.
        n_dofs: number of global dofs.
        node_ranges: (size + 1,) PETSc node range of every rank (dofs: 3 x).
        to_petsc: (n_dofs,) PETSc dof of each natural dof.
        from_petsc: (n_dofs,) natural dof of each PETSc dof.
        X: (n_nodes, 3) reference coordinates in the natural numbering (rigid-body modes).
    """

    rank: int
    size: int
    n_dofs: int
    node_ranges: np.ndarray
    to_petsc: np.ndarray
    from_petsc: np.ndarray
    X: np.ndarray

    @classmethod
    def from_owners(cls, owner: np.ndarray, rank: int, size: int, X: np.ndarray) -> DofLayout:
        node_of = np.argsort(owner, kind="stable")
        new_of_node = np.empty_like(node_of)
        new_of_node[node_of] = np.arange(node_of.size)
        d = np.arange(3)
        to_petsc = (3 * new_of_node[:, None] + d).ravel()
        from_petsc = (3 * node_of[:, None] + d).ravel()
        ranges = np.zeros(size + 1, dtype=np.int64)
        np.cumsum(np.bincount(owner, minlength=size), out=ranges[1:])
        return cls(rank, size, 3 * owner.size, ranges, to_petsc, from_petsc, np.asarray(X, dtype=np.float64))

    @classmethod
    def serial(cls, n_dofs: int) -> DofLayout:
        """One rank, identity numbering (any n_dofs; X unknown)."""
        ident = np.arange(n_dofs)
        return cls(0, 1, n_dofs, np.array([0, (n_dofs + 2) // 3]), ident, ident, np.zeros((0, 3)))

    @property
    def lo(self) -> int:
        """First PETSc dof of this rank."""
        return int(min(3 * self.node_ranges[self.rank], self.n_dofs))

    @property
    def hi(self) -> int:
        """One past the last PETSc dof of this rank."""
        return int(min(3 * self.node_ranges[self.rank + 1], self.n_dofs))

    @property
    def owned(self) -> np.ndarray:
        """Natural dofs of this rank's PETSc rows, in PETSc order."""
        return self.from_petsc[self.lo: self.hi]

    def owned_coordinates(self) -> np.ndarray | None:
        """(n_owned_nodes, 3) reference coordinates of this rank's nodes in PETSc order (None if unknown)."""
        if self.X.shape[0] * 3 != self.n_dofs:
            return None
        return self.X[self.owned[::3] // 3]
