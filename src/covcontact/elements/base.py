"""What every hexahedral body shares: input checks, chunked assembly, rank cache, energy, stress output.

:class:`ElementBody` holds the generic layer; a subclass sets its element tables and implements two
kernel calls, :meth:`ElementBody._chunk` (element buffers of one chunk) and
:meth:`ElementBody._gauss_fields` (per-element Gauss-point quantities). The compiled helpers below are
the pieces the parallel element loops of the subclasses have in common.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import get_num_threads, njit, set_parallel_chunksize

from ..assembly.pattern import Pattern, scatter_matrices, scatter_vectors
from ..fem.cells import NNODES as _OTHER_NNODES
from ..fem.shapes import NNODES as _TENSOR_NNODES
from ..materials.hyperelastic import VOIGT, VOIGT_PAIRS, Material

NNODES = {**_TENSOR_NNODES, **_OTHER_NNODES, "quad8": 8, "tri3": 3, "tri6": 6}  # (the last: planar cells)

#: parallel blocks per thread and chunk (handed out dynamically, for load balance on shared cores)
BLOCKS_PER_THREAD = 8


# ----------------------------------------------------------------------------- compiled helpers


@njit(cache=True, inline="always")
def block_range(t, n, nblk):
    """Items lo .. hi - 1 of block t when n items are split into nblk contiguous blocks."""
    return t * n // nblk, (t + 1) * n // nblk


@njit(cache=True, inline="always")
def f_times_d(F, D, T):
    """T[k, j, m, n] = sum_i F_ki C_ijmn for the material tangent D (Voigt, 6 x 6) of the elements'
    first elasticity tensor."""
    for k in range(3):
        for j in range(3):
            for m in range(3):
                for n in range(3):
                    mn = VOIGT[m, n]
                    T[k, j, m, n] = (F[k, 0] * D[VOIGT[0, j], mn] + F[k, 1] * D[VOIGT[1, j], mn]
                                     + F[k, 2] * D[VOIGT[2, j], mn])


@njit(cache=True, inline="always")
def inverse3(A, Ai):
    """Ai = A^-1 of a 3 x 3 matrix by cofactors; returns det A (Ai untouched unless det A > 0)."""
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    if not (det > 0.0):
        return det
    r = 1.0 / det
    Ai[0, 0] = c00 * r
    Ai[1, 0] = c01 * r
    Ai[2, 0] = c02 * r
    Ai[0, 1] = (A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]) * r
    Ai[1, 1] = (A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]) * r
    Ai[2, 1] = (A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]) * r
    Ai[0, 2] = (A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]) * r
    Ai[1, 2] = (A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]) * r
    Ai[2, 2] = (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]) * r
    return det


@njit(cache=True, inline="always")
def gather(X, u, conn, e, Xe, ue):
    """Reference coordinates Xe (nen, 3) and displacements ue (nen, 3) of the nodes of element e."""
    for a in range(conn.shape[1]):
        n = conn[e, a]
        for i in range(3):
            Xe[a, i] = X[n, i]
            ue[a, i] = u[n, i]


@njit(cache=True, inline="always")
def add_cauchy_pk2(F, S, wd, row):
    """row[0:6] += wd sigma (Cauchy stress J^-1 F S F^T; 0 if det F <= 0), row[6:12] += wd S (Voigt)."""
    J = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
         - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
         + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    rJ = wd / J if J > 0.0 else 0.0
    for I in range(6):
        i = VOIGT_PAIRS[I, 0]
        j = VOIGT_PAIRS[I, 1]
        sig = 0.0
        for k in range(3):
            for m in range(3):
                sig += F[i, k] * S[VOIGT[k, m]] * F[j, m]
        row[I] += rJ * sig
        row[6 + I] += wd * S[I]


# ----------------------------------------------------------------------------- output


@dataclass
class SolidStress:
    """Stress and strain of a solid body (Voigt order 11, 22, 33, 12, 23, 13; tensor shear E_12).

    Attributes:
        cauchy: (nelem, 6) Cauchy stress averaged over each element.
        pk2: (nelem, 6) second Piola-Kirchhoff stress averaged over each element.
        green_lagrange: (nelem, 6) Green-Lagrange strain averaged over each element.
        cauchy_nodal: (nnode, 6) Cauchy stress averaged at the nodes over the adjacent elements.
        von_mises: (nelem,) von Mises equivalent of ``cauchy``.
    """

    cauchy: np.ndarray
    pk2: np.ndarray
    green_lagrange: np.ndarray
    cauchy_nodal: np.ndarray
    von_mises: np.ndarray

    def cell_data(self) -> dict[str, np.ndarray]:
        """Cell fields by output name."""
        return {"cauchy": self.cauchy, "pk2": self.pk2, "green_lagrange": self.green_lagrange,
                "von_mises": self.von_mises}

    def point_data(self) -> dict[str, np.ndarray]:
        """Point fields by output name."""
        return {"cauchy_nodal": self.cauchy_nodal}


# ----------------------------------------------------------------------------- body


class CellCounts:
    """Node, element and node-per-element counts of a body with reference coordinates ``X`` and ``cells``."""

    X: np.ndarray
    cells: np.ndarray

    @property
    def n_nodes(self) -> int:
        return int(self.X.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.cells.shape[0])

    @property
    def nen(self) -> int:
        return int(self.cells.shape[1])

    def incidence(self) -> tuple[np.ndarray, np.ndarray]:
        """(element, node) of every node of every cell, flat."""
        return np.repeat(np.arange(self.n_elements), self.cells.shape[1]), self.cells.ravel()

    def element_nodes(self, elements: np.ndarray) -> np.ndarray:
        """The sorted distinct nodes of ``elements``."""
        els, nodes = self.incidence()
        return np.unique(nodes[np.isin(els, np.asarray(elements, dtype=np.int64))])


class ElementBody(CellCounts):
    """Generic body of one hexahedral cell type (the subclass checks ``cell_type`` first).

    Args:
        cell_type: a key of :data:`covcontact.fem.shapes.NNODES`.
        X: (nnode, 3) reference coordinates.
        cells: (nelem, nen) connectivity (local node ids).
        material: a :mod:`covcontact.materials` material.
        chunk_bytes: size of the per-chunk element tangent buffer.
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 chunk_bytes: int = 32 * 2**20) -> None:
        self.cell_type = cell_type
        self.X = np.ascontiguousarray(X, dtype=np.float64)
        self.cells = np.ascontiguousarray(cells, dtype=np.int64)
        nen = NNODES[cell_type]
        if self.X.ndim != 2 or self.X.shape[1] != 3:
            raise ValueError(f"X must have shape (nnode, 3), got {self.X.shape}")
        if self.cells.ndim != 2 or self.cells.shape[1] != nen:
            raise ValueError(f"{cell_type} cells must have shape (nelem, {nen}), got {self.cells.shape}")
        if self.cells.size and (self.cells.min() < 0 or self.cells.max() >= self.X.shape[0]):
            raise ValueError(f"cells refer to nodes outside [0, {self.X.shape[0]})")
        self.material = material
        nd = 3 * nen
        self.chunk = int(max(1, min(self.n_elements, chunk_bytes // (8 * nd * nd))))
        self._Ke = np.empty((0, nd, nd))
        self._fe = np.empty((0, nd))
        self._flags = np.empty(0, dtype=np.int64)
        self._ranks_key: tuple[Pattern, int] | None = None
        self._ranks = np.empty((0, nen, nen), dtype=np.int32)

    # -- kernel calls (subclass) ----------------------------------------------------------------
    def _chunk(self, u: np.ndarray, e0: int, want_K: bool, Ke: np.ndarray, fe: np.ndarray,
               flags: np.ndarray, nblocks: int, state: dict[str, np.ndarray]) -> None:
        """Fill Ke (nc, nd, nd) if want_K, fe (nc, nd), flags (nc,) for elements e0 .. e0 + nc - 1; the
        arrays of ``state`` (see :meth:`new_state`) are read as the start and overwritten with the trial."""
        raise NotImplementedError

    def _gauss_fields(self, u: np.ndarray, mode: int, out: np.ndarray, state: dict[str, np.ndarray]) -> None:
        """Per-element fields into out (nelem, ncol): mode 0 energy, 1 min det J0, 2 stress (18).

        The compiled field kernels of the element families are serial loops: they run once per output step
        (or per step for the energy of a dynamic run), and a parallel kernel that calls the material library
        costs numba about three times the compile time of a serial one (about a minute over the families on
        a new installation's first run; docs/performance.md, "Cold start")."""
        raise NotImplementedError

    #: state keys that are only the starting point of a local iteration (read from the guess, e.g. the
    #: EAS parameters); every other key is history (read from the committed state)
    HINTS: tuple[str, ...] = ()

    def new_state(self) -> dict[str, np.ndarray]:
        """The element history of this body at the reference state, as named arrays (none here;
        solid-shells hold their EAS parameters)."""
        return {}

    def kernel_state(self, committed: dict[str, np.ndarray], guess: dict[str, np.ndarray]) -> dict:
        """The arrays an assembly works on (docs/theory.md section 10): for a hint key a copy of the
        guess; for a history key ``k`` the committed array as ``k + "_n"`` (read only) and a copy of it as
        ``k`` (overwritten with the trial). :meth:`trial_of` strips the read-only keys again."""
        out: dict[str, np.ndarray] = {}
        for k, v in committed.items():
            if k in self.HINTS:
                out[k] = guess[k].copy()
            else:
                out[k] = v.copy()
                out[k + "_n"] = v
        return out

    @staticmethod
    def trial_of(kernel_state: dict) -> dict[str, np.ndarray]:
        return {k: v for k, v in kernel_state.items() if not k.endswith("_n")}

    #: whether the element tangent is symmetric (F-bar elements: not in general)
    symmetric_tangent = True

    def gauss_volumes(self) -> np.ndarray:
        """(nelem, ngp) reference volume w_g det J0 of every Gauss point (bodies with ``dNdxi``; computed
        once)."""
        if getattr(self, "_gauss_volumes", None) is None:
            J0 = np.einsum("eai,gak->egik", self.X[self.cells], self.dNdxi)
            self._gauss_volumes = np.linalg.det(J0) * self.weights[None, :]
        return self._gauss_volumes

    def plastic_fields(self, state: dict) -> dict[str, np.ndarray]:
        """Cell fields of a plastic material (``equivalent_plastic_strain``: volume average over the Gauss
        points; ``yield_flag``: 1 where a Gauss point yielded in the last step) from ``state``; empty for
        materials without plastic history."""
        from ..materials.plasticity import H_ALPHA, H_FLAG, J2

        hist = state.get("hist")
        if hist is None or self.material.kind != J2:
            return {}
        vol = self.gauss_volumes()
        return {"equivalent_plastic_strain": (hist[:, :, H_ALPHA] * vol).sum(axis=1) / vol.sum(axis=1),
                "yield_flag": hist[:, :, H_FLAG].max(axis=1)}

    def plastic_work(self, state: dict) -> float:
        """Plastic work int w_p dV of the body in ``state`` (0 without plastic history)."""
        from ..materials.plasticity import H_WP, J2

        hist = state.get("hist")
        if hist is None or self.material.kind != J2:
            return 0.0
        return float((hist[:, :, H_WP] * self.gauss_volumes()).sum())

    # -- evaluation -----------------------------------------------------------------------------
    def _u(self, u: np.ndarray) -> np.ndarray:
        u = np.ascontiguousarray(u, dtype=np.float64)
        return u if u.shape == self.X.shape else u.reshape(self.X.shape)

    def _fields(self, u: np.ndarray, mode: int, ncol: int, state: dict | None = None) -> np.ndarray:
        out = np.empty((self.n_elements, ncol))
        if self.n_elements:
            self._gauss_fields(self._u(u), mode, out, self.new_state() if state is None else state)
        return out

    def check_reference(self) -> list[int]:
        """Elements with det J0 <= 0 at some evaluation point (the caller raises)."""
        det = self._fields(np.zeros_like(self.X), 1, 1)[:, 0]
        return [int(e) for e in np.flatnonzero(~(det > 0.0))]

    def ranks(self, pattern: Pattern, node_offset: int = 0) -> np.ndarray:
        """Node-pair ranks of this body's cells in ``pattern`` (cached for the last pattern)."""
        if self._ranks_key is None or self._ranks_key[0] is not pattern or self._ranks_key[1] != node_offset:
            self._ranks = pattern.ranks(self.cells, node_offset)
            self._ranks_key = (pattern, int(node_offset))
        return self._ranks

    def assemble(self, u: np.ndarray, data: np.ndarray, rhs: np.ndarray, pattern: Pattern | None,
                 node_offset: int = 0, want_K: bool = True, state: dict | None = None) -> int:
        """Add internal forces to ``rhs`` and (if want_K) element tangents to the CSR ``data``.

        Dofs are 3 (node_offset + a) + i. ``state`` holds the element history arrays (:meth:`new_state`;
        the EAS parameters of solid-shells): read as the starting point and overwritten with the trial
        values at ``u``; the caller passes a copy of what it must keep. Returns -1, or the first element with an
        inadmissible strain (det F <= 0), det J0 <= 0 or a failed local solve at a Gauss point; the
        outputs then stay finite but may be meaningless.
        """
        u = self._u(u)
        state = self.new_state() if state is None else state
        nd = 3 * self.nen
        if rhs.dtype != np.float64 or rhs.ndim != 1 or rhs.size < 3 * (node_offset + self.n_nodes):
            raise ValueError("rhs must be float64 (ndofs,) covering this body's dofs")
        if want_K:
            if pattern is None:
                raise ValueError("want_K needs the pattern")
            if data.shape != (pattern.nnz,) or data.dtype != np.float64:
                raise ValueError(f"data must be float64 of shape ({pattern.nnz},)")
            ranks = self.ranks(pattern, node_offset)
            node_ptr = pattern.node_ptr
        else:
            ranks = self._ranks
            node_ptr = np.zeros(1, dtype=np.int64)
        if self._fe.shape[0] != self.chunk:
            self._fe = np.empty((self.chunk, nd))
            self._flags = np.empty(self.chunk, dtype=np.int64)
        if want_K and self._Ke.shape[0] != self.chunk:
            self._Ke = np.empty((self.chunk, nd, nd))
        off = np.int64(node_offset)
        nblocks = BLOCKS_PER_THREAD * get_num_threads()
        old_chunksize = set_parallel_chunksize(1)  # blocks handed out dynamically (shared cores)
        try:
            first_bad = -1
            for e0 in range(0, self.n_elements, self.chunk):
                nc = min(self.chunk, self.n_elements - e0)
                Ke = self._Ke[:nc] if want_K else self._Ke
                fe = self._fe[:nc]
                flags = self._flags[:nc]
                self._chunk(u, e0, want_K, Ke, fe, flags, nblocks, state)
                scatter_vectors(rhs, self.cells, off, fe, e0)
                if want_K:
                    scatter_matrices(data, node_ptr, self.cells, off, ranks, Ke, e0)
                if first_bad < 0:
                    bad = np.flatnonzero(flags)
                    if bad.size:
                        first_bad = e0 + int(bad[0])
        finally:
            set_parallel_chunksize(old_chunksize)
        return first_bad

    def energy(self, u: np.ndarray, state: dict | None = None) -> float:
        """Strain energy int W dV (inf if a strain is inadmissible, e.g. an inverted Neo-Hooke element)."""
        return float(self._fields(u, 0, 1, state).sum())

    def stress(self, u: np.ndarray, state: dict | None = None) -> SolidStress:
        """Element-averaged Cauchy stress, S and Green-Lagrange strain; nodal averaged Cauchy stress at
        displacement u and element history ``state`` (default: the reference state)."""
        return stress_from_fields(self._fields(u, 2, 18, state), self.incidence(), self.n_nodes)


def stress_from_fields(f: np.ndarray, incidence: tuple[np.ndarray, np.ndarray], n_nodes: int) -> SolidStress:
    """The stresses of the element fields ``f`` (nelem, 18: Cauchy, S, Green-Lagrange, Voigt): the Cauchy stress
    averaged at the nodes of the cells (``incidence``: (element, node) of every node of every cell) and the von
    Mises stress."""
    els, nodes = incidence
    cauchy = np.ascontiguousarray(f[:, :6])
    count = np.bincount(nodes, minlength=n_nodes).astype(np.float64)
    nodal = np.empty((n_nodes, 6))
    for I in range(6):
        nodal[:, I] = np.bincount(nodes, weights=cauchy[els, I], minlength=n_nodes)
    nodal /= np.maximum(count, 1.0)[:, None]
    s = cauchy
    vm = np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2 + (s[:, 2] - s[:, 0]) ** 2)
                 + 3.0 * (s[:, 3] ** 2 + s[:, 4] ** 2 + s[:, 5] ** 2))
    return SolidStress(cauchy=cauchy, pk2=np.ascontiguousarray(f[:, 6:12]),
                       green_lagrange=np.ascontiguousarray(f[:, 12:]), cauchy_nodal=nodal, von_mises=vm)
