"""Contact history as plain arrays: one ``PassState`` per contact pass (a pair or one side of a two-pass pair).

A state is either *committed* (the converged end of the last load step) or a *trial* (what an evaluation
at some displacement produced). Evaluation reads a committed state (and optionally the trial of the
previous Newton iteration as its starting point) and returns a new trial; it never writes into the
states it is given (docs/theory.md section 10).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .friction import HIST_SIZE


@dataclass
class PassState:
    """Per slave node of one pass (ns nodes).

    facet, xi: contact point (facet -1 and xi 0 without one; analytic masters keep facet -1);
    edge_lock: a slave held on a master edge or corner (see :mod:`.edgelock`), -1 free, -2 released
    in the current step;
    gap: geometric gap g (+inf without a contact point); force: (ns, 3) contact force on the node;
    status: friction state (0 open, 1 stick, 2 slip, 3 new); multiplier: Uzawa multiplier lam_k <= 0;
    hist, hist_facet: friction history (last converged tangential traction and contact point, on the
    facet ``hist_facet``); n_aug: Uzawa updates made in the current step.
    """

    facet: np.ndarray
    xi: np.ndarray
    gap: np.ndarray
    force: np.ndarray
    status: np.ndarray
    multiplier: np.ndarray
    hist: np.ndarray
    hist_facet: np.ndarray
    edge_lock: np.ndarray
    n_aug: int = 0

    @classmethod
    def empty(cls, ns: int) -> PassState:
        return cls(facet=np.full(ns, -1, dtype=np.int64), xi=np.zeros((ns, 2)), gap=np.full(ns, np.inf),
                   force=np.zeros((ns, 3)), status=np.zeros(ns, dtype=np.int64), multiplier=np.zeros(ns),
                   hist=np.zeros((ns, HIST_SIZE)), hist_facet=np.full(ns, -1, dtype=np.int64),
                   edge_lock=np.full(ns, -1, dtype=np.int64))

    def copy(self) -> PassState:
        return PassState(**{f.name: (getattr(self, f.name).copy() if f.name != "n_aug" else self.n_aug)
                            for f in fields(self)})

    def arrays(self, prefix: str) -> dict[str, np.ndarray]:
        return {f"{prefix}.{f.name}": np.asarray(getattr(self, f.name)) for f in fields(self)}

    @classmethod
    def from_arrays(cls, data, prefix: str) -> PassState:
        kw = {f.name: np.array(data[f"{prefix}.{f.name}"]) for f in fields(cls) if f"{prefix}.{f.name}" in data
              or f.name != "edge_lock"}
        kw.setdefault("edge_lock", np.full(len(kw["facet"]), -1, dtype=np.int64))  # checkpoints before edge locks
        kw["n_aug"] = int(kw["n_aug"])
        return cls(**kw)


@dataclass
class ContactState:
    """The states of all passes and the node positions of the last commit (``x``, extended numbering:
    deformable nodes, then the nodes of rigid meshes), on which friction history is transferred when a
    slave moves onto another facet."""

    passes: list[PassState]
    x: np.ndarray | None = None

    def copy(self) -> ContactState:
        return ContactState([p.copy() for p in self.passes], None if self.x is None else self.x.copy())

    def arrays(self) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        for k, p in enumerate(self.passes):
            out.update(p.arrays(f"contact.{k}"))
        if self.x is not None:
            out["contact.x"] = self.x
        return out

    @classmethod
    def from_arrays(cls, data, n_passes: int) -> ContactState:
        passes = [PassState.from_arrays(data, f"contact.{k}") for k in range(n_passes)]
        x = np.array(data["contact.x"]) if "contact.x" in data else None
        return cls(passes, x)
