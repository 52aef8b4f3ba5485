"""Contact pairs of one rank: every pass keeps only the slaves this rank owns.

The pairs are set up on the whole problem (penalties, tributary areas and automatic penalties see every
slave), then each pass is cut down to this rank's slaves: a deformable slave node goes with the owner of
the node, slaves of rigid meshes are split in contiguous blocks. Search and projection of a pass see the
whole master surface, since the node positions are replicated. What looks at all slaves (active counts,
Uzawa decisions, reports, output fields) is reduced over the ranks here.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.sparse as sp

from ..contact.element import CASES
from ..contact.friction import SLIP, STICK
from ..contact.manager import ContactManager
from .comm import count_all, gather_all, max_all


class DistributedContact(ContactManager):
    """A ContactManager over this rank's slaves; collective where the serial one looks at all slaves."""

    def __init__(self, problem, system, tangent: str, comm):
        super().__init__(problem, system, tangent)
        self.comm = comm
        rank, size = comm.rank, comm.size
        owner = system.owner
        local = []
        for p in self.passes:
            s = p.slaves
            own = np.empty(len(s), dtype=np.int64)
            deformable = s < self.N
            own[deformable] = owner[s[deformable]]
            rigid = np.flatnonzero(~deformable)
            own[rigid] = np.arange(rigid.size) * size // max(rigid.size, 1)
            keep = np.flatnonzero(own == rank)
            q = dataclasses.replace(p, slaves=s[keep], eps=p.eps[keep], area=p.area[keep],
                                    eps_t=p.eps_t[keep] if p.eps_t is not None else None)
            q.global_index = keep
            local.append(q)
        self.passes = local

    # -- collective counterparts of the serial methods ------------------------------------------
    def active_count(self) -> int:
        return count_all(self.comm, super().active_count())

    def _penetration(self, p) -> float:
        """The Uzawa test looks at the slaves of all ranks."""
        return max_all(self.comm, super()._penetration(p))

    def _global_norms(self, mats: list[sp.csr_matrix]) -> list[float]:
        """Frobenius norms of the sums over the ranks of the matrices ``mats`` (collective)."""
        mine = []
        for M in mats:
            C = M.tocoo()
            mine.append((C.row, C.col, C.data))
        out = []
        for k in range(len(mats)):
            parts = [g[k] for g in gather_all(self.comm, mine)] if self.comm.size > 1 else [mine[k]]
            rows = np.concatenate([p[0] for p in parts])
            cols = np.concatenate([p[1] for p in parts])
            vals = np.concatenate([p[2] for p in parts])
            S = sp.csr_matrix((vals, (rows, cols)), shape=mats[k].shape)
            out.append(float(sp.linalg.norm(S)) if S.nnz else 0.0)
        return out

    def step_report(self, x: np.ndarray, lam: float) -> dict:
        """The serial report, reduced over the ranks (collective)."""
        saved = [(p.g.copy(), p.force.copy(), p.state.copy()) for p in self.passes]
        _, _, parts = self.evaluate(x, lam, want_K=True, case=CASES["a"], want_parts=True)
        main, rot, curv, _ = parts
        nf, nr, nc = self._global_norms([main + rot + curv, rot, curv])
        contrib = {"rotational": nr / nf * 100 if nf > 0 else 0.0,
                   "curvature": nc / nf * 100 if nf > 0 else 0.0}
        for p, kept in zip(self.passes, saved):
            p.g, p.force, p.state = kept
        mine = []
        for p in self.passes:
            act = self._active(p)
            gmin = float(p.g.min()) if len(p.g) and np.isfinite(p.g.min()) else np.inf
            mine.append((int(act.sum()), int(np.count_nonzero(act & (p.state == STICK))),
                         int(np.count_nonzero(act & (p.state == SLIP))), gmin, p.force[act].sum(axis=0),
                         float(np.max(-p.g[act], initial=0.0))))
        every = gather_all(self.comm, mine)
        pairs = {}
        for k, p in enumerate(self.passes):
            rows = [e[k] for e in every]
            gmin = min(r_[3] for r_ in rows)
            force = np.sum([r_[4] for r_ in rows], axis=0)
            pairs[p.name] = {"active_contacts": sum(r_[0] for r_ in rows),
                             **({"stick": sum(r_[1] for r_ in rows), "slip": sum(r_[2] for r_ in rows)}
                                if p.mu > 0 else {}),
                             "min_gap": float(gmin) if np.isfinite(gmin) else None,
                             "contact_force": force.tolist(),
                             **({"augmentations": p.n_aug, "max_penetration": max(r_[5] for r_ in rows)}
                                if p.augmented else {})}
        total_force = np.sum([v["contact_force"] for v in pairs.values()], axis=0).tolist()
        gaps = [v["min_gap"] for v in pairs.values() if v["min_gap"] is not None]
        return {"active_contacts": sum(v["active_contacts"] for v in pairs.values()),
                "min_gap": min(gaps) if gaps else None, "contact_force": total_force,
                "contribution_percent": contrib, "pairs": pairs}

    def _node_fields(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Gap, pressure and status of every node from the slaves of all ranks (collective)."""
        gap = np.full(n, np.nan)
        pressure = np.zeros(n)
        status = np.full(n, -1.0)
        mine = []
        for p in self.passes:
            fn = np.linalg.norm(p.force, axis=1) / np.maximum(p.area, 1e-300)
            mine.append((p.slaves, p.g, self._active(p), fn))
        every = gather_all(self.comm, mine)
        for k in range(len(self.passes)):
            s = np.concatenate([e[k][0] for e in every])
            g = np.concatenate([e[k][1] for e in every])
            act = np.concatenate([e[k][2] for e in every])
            fn = np.concatenate([e[k][3] for e in every])
            sel = s < n
            gap[s[sel]] = np.where(np.isfinite(g[sel]), g[sel], np.nan)
            status[s[sel]] = np.where(act[sel], 1.0, 0.0)
            pressure[s[sel]] = np.where(act[sel], fn[sel], 0.0)
        return gap, pressure, status
