"""Contact pairs of one rank: every pass keeps only the slaves this rank owns.

The pairs are set up on the whole problem (penalties, tributary areas and automatic penalties see every
slave), then each pass is cut down to this rank's slaves: a deformable slave node goes with the owner of
the node, slaves of rigid meshes are split in contiguous blocks. Search and projection of a pass see the
whole master surface, since the node positions are replicated. What looks at all slaves (active counts,
Uzawa decisions, reports, output fields) is reduced over the ranks here.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..contact.manager import ContactManager
from .comm import count_all, gather_all, max_all


class DistributedContact(ContactManager):
    """A ContactManager over this rank's slaves; collective where the serial one looks at all slaves."""

    def __init__(self, problem, system, tangent: str | None, comm):
        super().__init__(problem, system, tangent)
        self.comm = comm
        rank, size = comm.rank, comm.size
        owner = system.owner
        local = []
        for p in self.passes:
            if p.nodal and size > 1:  # (a node's weighted gap takes the points of all its facets, on any rank)
                raise ValueError(f"contact {p.pair}: gap = \"nodal\" runs in one process: leave out --ranks")
            s = p.slaves
            own = np.empty(len(s), dtype=np.int64)
            deformable = s < self.N
            own[deformable] = owner[s[deformable]]
            # a segment-to-surface point goes with the owner of its facet's first node, if deformable
            pts = self.points
            virtual = s >= pts.offset
            first = pts.conn[s[virtual] - pts.offset, 0] if virtual.any() else np.zeros(0, dtype=np.int64)
            on_body = np.flatnonzero(virtual)[first < self.N]
            own[on_body] = owner[first[first < self.N]]
            deformable[on_body] = True
            rigid = np.flatnonzero(~deformable)
            own[rigid] = np.arange(rigid.size) * size // max(rigid.size, 1)
            keep = np.flatnonzero(own == rank)
            local.append(p.subset(keep))
        self.passes = local
        self.enabled = [True] * len(self.passes)
        self._cache = [None] * len(self.passes)

    # -- collective counterparts of the serial methods ------------------------------------------
    def active_count(self, state) -> int:
        return count_all(self.comm, super().active_count(state))

    def opened_closed(self, a, b) -> int:
        return count_all(self.comm, super().opened_closed(a, b))

    def _penetration(self, p, t) -> float:
        """The Uzawa test looks at the slaves of all ranks."""
        return max_all(self.comm, super()._penetration(p, t))

    def _release(self, trial):
        """Edge locks are released on each rank's slaves; if any rank releases one, every rank solves again."""
        new = super()._release(trial)
        if count_all(self.comm, int(new is not None)) and new is None:
            new = trial.copy()
        return new

    def gather(self, rows: list) -> list[list]:
        return gather_all(self.comm, rows)

    def global_norms(self, mats: list[sp.csr_matrix]) -> list[float]:
        """Frobenius norms of the sums over the ranks of the matrices ``mats`` (collective)."""
        mine = []
        for M in mats:
            C = M.tocoo()
            mine.append((C.row, C.col, C.data))
        out = []
        every = gather_all(self.comm, mine) if self.comm.size > 1 else [mine]
        for k in range(len(mats)):
            parts = [g[k] for g in every]
            rows = np.concatenate([p[0] for p in parts])
            cols = np.concatenate([p[1] for p in parts])
            vals = np.concatenate([p[2] for p in parts])
            S = sp.csr_matrix((vals, (rows, cols)), shape=mats[k].shape)
            out.append(float(sp.linalg.norm(S)) if S.nnz else 0.0)
        return out
