"""A body of several materials: element sets of one mesh, each with its own material, bonded through their shared
nodes (docs/theory.md, section 18).

:class:`CompositeBody` holds one element body per material over the same nodes (the cells of its element set) and
answers as one body: its element history arrays run over all cells in mesh order (a part reads and writes its
rows; an array whose per-point length differs between the materials, the plastic history next to an elastic part,
is as wide as the widest and a part uses its leading columns), its stresses, energies and plastic fields are the
parts' in mesh order, and the first bad element it reports is a mesh index.
"""

from __future__ import annotations

import numpy as np

from .base import CellCounts, ElementBody, stress_from_fields


class CompositeBody(CellCounts):
    """Element bodies ``parts`` over the same nodes, part k holding the cells ``index[k]`` of the body (of one
    material and one cell type each).

    Args:
        parts: (element indices of the body, the element body of those cells) per material and cell type; every
            element in one part.
    """

    def __init__(self, parts: list[tuple[np.ndarray, ElementBody]]):
        self.index = [np.asarray(idx, dtype=np.int64) for idx, _ in parts]
        self.parts = [body for _, body in parts]
        self._n = int(sum(len(idx) for idx in self.index))
        covered = np.bincount(np.concatenate(self.index), minlength=self._n) if self.index else []
        if self._n and not np.all(covered == 1):
            raise ValueError("every cell of a composite body must lie in exactly one part")
        first = self.parts[0]
        self.X = first.X
        types = {b.cell_type for b in self.parts}
        #: the cell type of the parts, "mixed" when they differ
        self.cell_type = first.cell_type if len(types) == 1 else "mixed"
        #: (nelem, nen) all cells in body order when the parts have one number of nodes per cell, else None
        self.cells = None
        if len({b.cells.shape[1] for b in self.parts}) == 1:
            self.cells = np.empty((self._n, first.cells.shape[1]), dtype=np.int64)
            for idx, b in zip(self.index, self.parts):
                self.cells[idx] = b.cells
        from ..materials.plasticity import J2

        plastic = [b.material for b in self.parts if b.material.kind == J2]
        #: the materials of the parts; ``material`` is a plastic one if any (what the plastic reports ask)
        self.materials = [b.material for b in self.parts]
        self.material = plastic[0] if plastic else first.material
        self.HINTS = tuple(sorted({h for b in self.parts for h in b.HINTS}))
        self.symmetric_tangent = all(b.symmetric_tangent for b in self.parts)
        self.dNdxi, self.weights = getattr(first, "dNdxi", None), getattr(first, "weights", None)
        #: per part, the per-element shape of each of its state arrays
        self._tails = [{key: arr.shape[1:] for key, arr in b.new_state().items()} for b in self.parts]

    @property
    def n_elements(self) -> int:
        return self._n

    @property
    def nen(self) -> int:
        return max(b.nen for b in self.parts)

    def incidence(self) -> tuple[np.ndarray, np.ndarray]:
        pairs = [b.incidence() for b in self.parts]
        return (np.concatenate([idx[e] for idx, (e, _) in zip(self.index, pairs)]),
                np.concatenate([n for _, n in pairs]))

    # -- state ----------------------------------------------------------------------------------
    def new_state(self) -> dict[str, np.ndarray]:
        states = [b.new_state() for b in self.parts]
        out: dict[str, np.ndarray] = {}
        for key in sorted({k for s in states for k in s}):
            tails = [s[key].shape[1:] for s in states if key in s]
            tail = tuple(max(t[d] for t in tails) for d in range(len(tails[0])))
            arr = np.zeros((self.n_elements, *tail))
            for idx, s in zip(self.index, states):
                if key in s:
                    arr[(idx, *(slice(0, n) for n in s[key].shape[1:]))] = s[key]
            out[key] = arr
        return out

    def kernel_state(self, committed: dict[str, np.ndarray], guess: dict[str, np.ndarray]) -> dict:
        return ElementBody.kernel_state(self, committed, guess)  # (reads self.HINTS only)

    trial_of = staticmethod(ElementBody.trial_of)

    def _views(self, k: int, state: dict[str, np.ndarray]) -> tuple[dict, dict]:
        """Part k's rows of ``state`` (copies, cut to the part's own widths) and where they came from."""
        own = self._tails[k]
        sub, where = {}, {}
        for key, arr in state.items():
            base = key.removesuffix("_n")
            if base not in own:
                continue
            sel = (self.index[k], *(slice(0, n) for n in own[base]))
            sub[key] = np.ascontiguousarray(arr[sel])
            where[key] = sel
        return sub, where

    # -- evaluation -----------------------------------------------------------------------------
    def assemble(self, u: np.ndarray, data: np.ndarray, rhs: np.ndarray, pattern, node_offset: int = 0,
                 want_K: bool = True, state: dict | None = None) -> int:
        """As :meth:`ElementBody.assemble`, part by part; the trial history goes back into ``state``."""
        state = self.new_state() if state is None else state
        bad = []
        for k, body in enumerate(self.parts):
            sub, where = self._views(k, state)
            e = body.assemble(u, data, rhs, pattern, node_offset, want_K, sub)
            for key, sel in where.items():
                if not key.endswith("_n"):
                    state[key][sel] = sub[key]
            if e >= 0:
                bad.append(int(self.index[k][e]))
        return min(bad) if bad else -1

    def _gather(self, rows_of_part) -> np.ndarray:
        """The parts' rows in body order (rows of different widths, e.g. Gauss points of two cell types: padded
        with zeros to the widest)."""
        rows = [rows_of_part(k) for k in range(len(self.parts))]
        tail = tuple(max(r.shape[d] for r in rows) for d in range(1, rows[0].ndim))
        out = np.zeros((self.n_elements, *tail))
        for idx, r in zip(self.index, rows):
            out[(idx, *(slice(0, n) for n in r.shape[1:]))] = r
        return out

    def energy(self, u: np.ndarray, state: dict | None = None) -> float:
        state = self.new_state() if state is None else state
        return float(sum(b.energy(u, self._views(k, state)[0]) for k, b in enumerate(self.parts)))

    def stress(self, u: np.ndarray, state: dict | None = None):
        state = self.new_state() if state is None else state
        f = self._gather(lambda k: self.parts[k]._fields(u, 2, 18, self._views(k, state)[0]))
        return stress_from_fields(f, self.incidence(), self.n_nodes)

    def check_reference(self) -> list[int]:
        return sorted(int(self.index[k][e]) for k, b in enumerate(self.parts) for e in b.check_reference())

    def gauss_volumes(self) -> np.ndarray:
        return self._gather(lambda k: self.parts[k].gauss_volumes())

    def plastic_fields(self, state: dict) -> dict[str, np.ndarray]:
        """The parts' plastic cell fields in mesh order (zero in the elastic parts)."""
        fields = [b.plastic_fields(self._views(k, state)[0]) for k, b in enumerate(self.parts)]
        out = {}
        for key in sorted({k for f in fields for k in f}):
            arr = np.zeros(self.n_elements)
            for idx, f in zip(self.index, fields):
                if key in f:
                    arr[idx] = f[key]
            out[key] = arr
        return out

    def plastic_work(self, state: dict) -> float:
        return float(sum(b.plastic_work(self._views(k, state)[0]) for k, b in enumerate(self.parts)))
