"""Contact contributions into the global system: element blocks and the coupling pattern.

An evaluation of the contact pairs yields blocks of contact elements: node lists in the extended numbering
(deformable nodes, then rigid-mesh nodes; a facet's nodes then the slave), element residuals and tangents.
Rigid nodes carry no unknowns: their rows and columns are dropped. The tangent entries go into one CSR
pattern of the bodies and the contact couplings seen so far (:class:`CouplingPattern`); the pattern is
rebuilt only when an element couples two nodes it does not hold yet, so while the contact coupling is
unchanged the matrix keeps its pattern and a direct solver keeps its symbolic analysis.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..assembly.pattern import Pattern, scatter_matrices


@dataclass
class ElementBlocks:
    """Contact element contributions of one evaluation; ``N`` deformable nodes (dofs 3 N)."""

    N: int
    conn: list[np.ndarray] = field(default_factory=list)   # (m, nen) extended node ids
    R: list[np.ndarray] = field(default_factory=list)      # (m, 3 nen)
    K: list[np.ndarray | None] = field(default_factory=list)  # (m, 3 nen, 3 nen) or None
    points: object = None  # the segment-to-surface points (.points.VirtualPoints), expanded onto their nodes

    def add(self, conn: np.ndarray, R: np.ndarray, K: np.ndarray | None) -> None:
        if len(conn) and self.points is not None and self.points.count and conn.max() >= self.points.offset:
            conn, R, K = self.points.expand(np.asarray(conn, dtype=np.int64), R, K)
        if len(conn):
            self.conn.append(np.ascontiguousarray(conn, dtype=np.int64))
            self.R.append(R)
            self.K.append(K)

    def _dofs(self, conn: np.ndarray) -> np.ndarray:
        """(m, nen) node ids -> (m, 3 nen) dofs, -1 for rigid nodes."""
        d = (3 * conn[:, :, None] + np.arange(3)[None, None, :]).reshape(conn.shape[0], -1)
        d[np.repeat(conn >= self.N, 3, axis=1)] = -1
        return d

    def residual(self) -> np.ndarray:
        r = np.zeros(3 * self.N)
        for conn, R in zip(self.conn, self.R):
            d = self._dofs(conn)
            keep = d >= 0
            np.add.at(r, d[keep], R[keep])
        return r

    def local(self):
        """Per block: node ids with rigid nodes replaced by a deformable node of the same element, and
        the element tangents with the rows and columns of rigid nodes zeroed (what the pattern sees)."""
        for conn, K in zip(self.conn, self.K):
            if K is None:
                continue
            rigid = conn >= self.N
            if not rigid.any():
                yield conn, K
                continue
            keep = rigid.all(axis=1)
            conn, K, rigid = conn[~keep], K[~keep], rigid[~keep]
            first = np.argmin(rigid, axis=1)  # a deformable node of each element
            eff = np.where(rigid, conn[np.arange(len(conn)), first][:, None], conn)
            mask = np.repeat(~rigid, 3, axis=1).astype(float)
            yield np.ascontiguousarray(eff), np.ascontiguousarray(K * mask[:, :, None] * mask[:, None, :])

    def csr(self) -> sp.csr_matrix:
        """The tangent as a CSR matrix of its own (reports and distributed assembly)."""
        n = 3 * self.N
        rows, cols, vals = [], [], []
        for conn, K in zip(self.conn, self.K):
            if K is None:
                continue
            d = self._dofs(conn)
            nd = d.shape[1]
            rr = np.repeat(d, nd, axis=1)
            cc = np.tile(d, (1, nd))
            mask = (rr >= 0) & (cc >= 0)
            rows.append(rr[mask])
            cols.append(cc[mask])
            vals.append(K.reshape(len(conn), -1)[mask])
        if not rows:
            return sp.csr_matrix((n, n))
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n))


class CouplingPattern:
    """The bodies' pattern grown by every contact coupling met so far (grow-only)."""

    def __init__(self, n_nodes: int, body_blocks: list[np.ndarray], pattern: Pattern | None = None):
        self.n_nodes = n_nodes
        self.body_blocks = body_blocks
        self.contact_blocks: list[np.ndarray] = []
        self.pattern = pattern if pattern is not None else Pattern(n_nodes, body_blocks)
        self.rebuilds = 0

    def covering(self, blocks: ElementBlocks) -> tuple[Pattern, list]:
        """The pattern holding every coupling of ``blocks`` (rebuilt if one is new) and the
        (conn, ranks, K) triples to scatter."""
        local = list(blocks.local())
        ranks = [self.pattern.ranks(conn, strict=False) for conn, _ in local]
        missing = [conn[(rk < 0).any(axis=(1, 2))] for (conn, _), rk in zip(local, ranks)]
        missing = [m for m in missing if len(m)]
        if missing:
            self.contact_blocks.extend(missing)
            self.pattern = Pattern(self.n_nodes, self.body_blocks + self.contact_blocks)
            self.rebuilds += 1
            ranks = [self.pattern.ranks(conn) for conn, _ in local]
        return self.pattern, [(conn, rk, K) for (conn, K), rk in zip(local, ranks)]

    def arrays(self) -> dict[str, np.ndarray]:
        """The contact couplings met so far, for a checkpoint: a resumed run rebuilds the same pattern, so its
        matrices have the structure (structural zeros included) and its factorisations the ordering of the
        uninterrupted run's, and its results are those bit for bit."""
        return {f"coupling.{i}": block for i, block in enumerate(self.contact_blocks)}

    def restore(self, arrays: dict[str, np.ndarray]) -> None:
        """The couplings of :meth:`arrays` (a checkpoint's); the pattern rebuilt with them."""
        blocks = [np.asarray(arrays[f"coupling.{i}"], dtype=np.int64) for i in range(len(arrays))]
        if blocks:
            self.contact_blocks = blocks
            self.pattern = Pattern(self.n_nodes, self.body_blocks + self.contact_blocks)

    @staticmethod
    def scatter(data: np.ndarray, pattern: Pattern, triples: list) -> None:
        for conn, ranks, K in triples:
            scatter_matrices(data, pattern.node_ptr, conn, np.int64(0), ranks, K, 0)
