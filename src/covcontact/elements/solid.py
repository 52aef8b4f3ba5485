"""Total-Lagrangian solid hexahedra (hex8, hex27; hex18 as a plain solid) with full Gauss integration.

Per Gauss point: J0 = dX/dxi, G = dN/dX = dN/dxi J0^-1, F = I + u^T G, S and D from the material,
first Piola-Kirchhoff P = F S. Internal force f_ak = int P_kj G_aj dV and tangent
K_ab,kl = int G_aj A_kjln G_bn dV with the first elasticity tensor
A_kjln = F_ki C_ijmn F_lm + delta_kl S_jn (material + geometric part in one).

Elements are processed in chunks: a parallel kernel fills per-element buffers, a serial scatter adds
them to the CSR data array through the node-pair ranks of :class:`covcontact.assembly.Pattern`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import get_num_threads, njit, prange, set_parallel_chunksize

from ..assembly.pattern import Pattern, scatter_matrices, scatter_vectors
from ..fem.quadrature import DEFAULT_RULE, gauss_tensor
from ..fem.shapes import NNODES, shape_functions
from ..materials.hyperelastic import VOIGT, Material, material_energy, material_response
from ..materials.hyperelastic import VOIGT_PAIRS as _PAIRS

SOLID_CELLS = ("hex8", "hex18", "hex27")
#: parallel blocks per thread and chunk (handed out dynamically, for load balance on shared cores)
BLOCKS_PER_THREAD = 8


@njit(cache=True, inline="always")
def _jacobian(Xe, dNg, J0, Ji):
    """J0[i, k] = sum_a X_ai dN_a/dxi_k, its inverse Ji; returns det J0 (Ji untouched if <= 0)."""
    nen = Xe.shape[0]
    for i in range(3):
        for k in range(3):
            s = 0.0
            for a in range(nen):
                s += Xe[a, i] * dNg[a, k]
            J0[i, k] = s
    c00 = J0[1, 1] * J0[2, 2] - J0[1, 2] * J0[2, 1]
    c01 = J0[1, 2] * J0[2, 0] - J0[1, 0] * J0[2, 2]
    c02 = J0[1, 0] * J0[2, 1] - J0[1, 1] * J0[2, 0]
    det = J0[0, 0] * c00 + J0[0, 1] * c01 + J0[0, 2] * c02
    if det <= 0.0:
        return det
    r = 1.0 / det
    # Ji = J0^-1, Ji[k, i] = dxi_k / dX_i
    Ji[0, 0] = c00 * r
    Ji[1, 0] = c01 * r
    Ji[2, 0] = c02 * r
    Ji[0, 1] = (J0[0, 2] * J0[2, 1] - J0[0, 1] * J0[2, 2]) * r
    Ji[1, 1] = (J0[0, 0] * J0[2, 2] - J0[0, 2] * J0[2, 0]) * r
    Ji[2, 1] = (J0[0, 1] * J0[2, 0] - J0[0, 0] * J0[2, 1]) * r
    Ji[0, 2] = (J0[0, 1] * J0[1, 2] - J0[0, 2] * J0[1, 1]) * r
    Ji[1, 2] = (J0[0, 2] * J0[1, 0] - J0[0, 0] * J0[1, 2]) * r
    Ji[2, 2] = (J0[0, 0] * J0[1, 1] - J0[0, 1] * J0[1, 0]) * r
    return det


@njit(cache=True, inline="always")
def _kinematics(dNg, Ji, ue, G, F):
    """G = dN/dX (nen, 3) and F = I + sum_a u_a (x) G_a."""
    nen = ue.shape[0]
    for a in range(nen):
        for j in range(3):
            G[a, j] = dNg[a, 0] * Ji[0, j] + dNg[a, 1] * Ji[1, j] + dNg[a, 2] * Ji[2, j]
    for i in range(3):
        for j in range(3):
            s = 1.0 if i == j else 0.0
            for a in range(nen):
                s += ue[a, i] * G[a, j]
            F[i, j] = s


@njit(cache=True)
def _element(kind, params, Xe, ue, dNdxi, w, want_K, Ke, fe, J0, Ji, G, F, S, D, P, T, A, Q):
    """Internal force fe (3 nen,) and tangent Ke (3 nen, 3 nen) of one element (overwritten).

    Returns 0, 1 if det F <= 0 at a Gauss point, 2 if det J0 <= 0 (that point is skipped).
    """
    nen = Xe.shape[0]
    nd = 3 * nen
    for r in range(nd):
        fe[r] = 0.0
    if want_K:
        for r in range(nd):
            for s in range(nd):
                Ke[r, s] = 0.0
    flag = 0
    for g in range(w.size):
        dNg = dNdxi[g]
        det = _jacobian(Xe, dNg, J0, Ji)
        if det <= 0.0:
            flag = 2
            continue
        _kinematics(dNg, Ji, ue, G, F)
        if material_response(kind, params, F, S, D) != 0 and flag == 0:
            flag = 1
        wd = w[g] * det
        # P = F S (scaled by the integration weight)
        for k in range(3):
            for j in range(3):
                P[k, j] = wd * (F[k, 0] * S[VOIGT[0, j]] + F[k, 1] * S[VOIGT[1, j]] + F[k, 2] * S[VOIGT[2, j]])
        for a in range(nen):
            for k in range(3):
                fe[3 * a + k] += P[k, 0] * G[a, 0] + P[k, 1] * G[a, 1] + P[k, 2] * G[a, 2]
        if not want_K:
            continue
        # T[k, j, m, n] = sum_i F_ki C_ijmn
        for k in range(3):
            for j in range(3):
                for m in range(3):
                    for n in range(3):
                        mn = VOIGT[m, n]
                        T[k, j, m, n] = (F[k, 0] * D[VOIGT[0, j], mn] + F[k, 1] * D[VOIGT[1, j], mn]
                                         + F[k, 2] * D[VOIGT[2, j], mn])
        # A[k, j, l, n] = wd (sum_m T_kjmn F_lm + delta_kl S_jn)
        for k in range(3):
            for j in range(3):
                for l in range(3):
                    for n in range(3):
                        v = T[k, j, 0, n] * F[l, 0] + T[k, j, 1, n] * F[l, 1] + T[k, j, 2, n] * F[l, 2]
                        if k == l:
                            v += S[VOIGT[j, n]]
                        A[k, j, l, n] = wd * v
        for a in range(nen):
            # Q[k, l, n] = sum_j G_aj A_kjln
            for k in range(3):
                for l in range(3):
                    for n in range(3):
                        Q[k, l, n] = G[a, 0] * A[k, 0, l, n] + G[a, 1] * A[k, 1, l, n] + G[a, 2] * A[k, 2, l, n]
            for b in range(a, nen):
                g0 = G[b, 0]
                g1 = G[b, 1]
                g2 = G[b, 2]
                for k in range(3):
                    for l in range(3):
                        Ke[3 * a + k, 3 * b + l] += Q[k, l, 0] * g0 + Q[k, l, 1] * g1 + Q[k, l, 2] * g2
    if want_K:
        for a in range(nen):
            for b in range(a + 1, nen):
                for k in range(3):
                    for l in range(3):
                        Ke[3 * b + l, 3 * a + k] = Ke[3 * a + k, 3 * b + l]
    return flag


@njit(parallel=True, cache=True)
def solid_chunk(kind, params, X, u, conn, e0, dNdxi, w, want_K, Ke, fe, flags, nblocks):
    """Element buffers Ke (nc, nd, nd), fe (nc, nd) and flags (nc,) of elements e0 .. e0 + nc - 1.

    The chunk is split into ``nblocks`` contiguous blocks (the parallel iterations), each with its
    own scratch arrays.
    """
    nc = fe.shape[0]
    nen = conn.shape[1]
    nblk = max(1, min(nblocks, nc))
    for t in prange(nblk):
        lo = t * nc // nblk
        hi = (t + 1) * nc // nblk
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        G = np.empty((nen, 3))
        J0 = np.empty((3, 3))
        Ji = np.empty((3, 3))
        F = np.empty((3, 3))
        S = np.empty(6)
        D = np.empty((6, 6))
        P = np.empty((3, 3))
        T = np.empty((3, 3, 3, 3))
        A = np.empty((3, 3, 3, 3))
        Q = np.empty((3, 3, 3))
        Kdummy = np.empty((0, 0))
        for c in range(lo, hi):
            e = e0 + c
            for a in range(nen):
                n = conn[e, a]
                for i in range(3):
                    Xe[a, i] = X[n, i]
                    ue[a, i] = u[n, i]
            Kc = Ke[c] if want_K else Kdummy
            flags[c] = _element(kind, params, Xe, ue, dNdxi, w, want_K, Kc, fe[c], J0, Ji, G, F, S, D, P,
                                T, A, Q)


@njit(parallel=True, cache=True)
def solid_gauss_fields(kind, params, X, u, conn, dNdxi, w, mode, out, nthreads):
    """Per-element Gauss-point quantities (serial per block, parallel over blocks).

    mode 0: out (ne, 1) strain energy int W dV; mode 1: out (ne, 1) minimum det J0;
    mode 2: out (ne, 18) volume averages of Cauchy stress, S and Green-Lagrange E (Voigt).
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    nblk = min(nthreads, ne)
    for t in prange(nblk):
        lo = t * ne // nblk
        hi = (t + 1) * ne // nblk
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        G = np.empty((nen, 3))
        J0 = np.empty((3, 3))
        Ji = np.empty((3, 3))
        F = np.empty((3, 3))
        S = np.empty(6)
        D = np.empty((6, 6))
        for e in range(lo, hi):
            for a in range(nen):
                n = conn[e, a]
                for i in range(3):
                    Xe[a, i] = X[n, i]
                    ue[a, i] = u[n, i]
            for r in range(out.shape[1]):
                out[e, r] = 0.0
            if mode == 1:
                out[e, 0] = np.inf
            vol = 0.0
            for g in range(w.size):
                det = _jacobian(Xe, dNdxi[g], J0, Ji)
                if mode == 1:
                    out[e, 0] = min(out[e, 0], det)
                    continue
                if det <= 0.0:
                    continue
                _kinematics(dNdxi[g], Ji, ue, G, F)
                wd = w[g] * det
                vol += wd
                if mode == 0:
                    out[e, 0] += wd * material_energy(kind, params, F)
                    continue
                material_response(kind, params, F, S, D)
                J = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
                     - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
                     + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
                rJ = wd / J if J > 0.0 else 0.0
                for I in range(6):
                    i = _PAIRS[I, 0]
                    j = _PAIRS[I, 1]
                    sig = 0.0
                    for k in range(3):
                        for m in range(3):
                            sig += F[i, k] * S[VOIGT[k, m]] * F[j, m]
                    out[e, I] += rJ * sig
                    out[e, 6 + I] += wd * S[I]
                    c = F[0, i] * F[0, j] + F[1, i] * F[1, j] + F[2, i] * F[2, j]
                    out[e, 12 + I] += wd * 0.5 * (c - (1.0 if i == j else 0.0))
            if mode == 2 and vol > 0.0:
                for r in range(18):
                    out[e, r] /= vol


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


def _rule(cell_type: str, rule) -> tuple[np.ndarray, np.ndarray]:
    if rule is None:
        return gauss_tensor(DEFAULT_RULE[cell_type])
    if len(rule) == 3 and all(isinstance(r, (int, np.integer)) for r in rule):
        return gauss_tensor(tuple(int(r) for r in rule))
    pts, w = rule
    return np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 3), np.ascontiguousarray(w, dtype=np.float64)


class SolidBody:
    """A total-Lagrangian solid body of one hexahedral cell type.

    Args:
        cell_type: "hex8", "hex27" or "hex18" (hex18 as a plain 3x3x2 solid).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, nen) connectivity (local node ids).
        material: a :mod:`covcontact.materials` material.
        rule: None (full integration), Gauss orders (n1, n2, n3) or (points, weights).
        chunk_bytes: size of the per-chunk element tangent buffer.
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 rule=None, chunk_bytes: int = 32 * 2**20) -> None:
        if cell_type not in SOLID_CELLS:
            raise ValueError(f"unknown solid cell type {cell_type!r}; known: {', '.join(SOLID_CELLS)}")
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
        self.points, self.weights = _rule(cell_type, rule)
        self.dNdxi = np.ascontiguousarray(shape_functions(cell_type, self.points)[1])
        nd = 3 * nen
        self.chunk = int(max(1, min(self.n_elements, chunk_bytes // (8 * nd * nd))))
        self._Ke = np.empty((0, nd, nd))
        self._fe = np.empty((0, nd))
        self._flags = np.empty(0, dtype=np.int64)
        self._ranks_key: tuple[Pattern, int] | None = None
        self._ranks = np.empty((0, nen, nen), dtype=np.int32)

    @property
    def n_nodes(self) -> int:
        return int(self.X.shape[0])

    @property
    def n_elements(self) -> int:
        return int(self.cells.shape[0])

    @property
    def nen(self) -> int:
        return int(self.cells.shape[1])

    def _u(self, u: np.ndarray) -> np.ndarray:
        u = np.ascontiguousarray(u, dtype=np.float64)
        if u.shape != self.X.shape:
            u = u.reshape(self.X.shape)
        return u

    def _fields(self, u: np.ndarray, mode: int, ncol: int) -> np.ndarray:
        out = np.empty((self.n_elements, ncol))
        if self.n_elements:
            solid_gauss_fields(self.material.kind, self.material.params, self.X, self._u(u), self.cells,
                               self.dNdxi, self.weights, mode, out, get_num_threads())
        return out

    def check_reference(self) -> list[int]:
        """Elements with det J0 <= 0 at some Gauss point (the caller raises)."""
        det = self._fields(np.zeros_like(self.X), 1, 1)[:, 0]
        return [int(e) for e in np.flatnonzero(~(det > 0.0))]

    def ranks(self, pattern: Pattern, node_offset: int = 0) -> np.ndarray:
        """Node-pair ranks of this body's cells in ``pattern`` (cached for the last pattern)."""
        key = (pattern, int(node_offset))
        if self._ranks_key is None or self._ranks_key[0] is not pattern or self._ranks_key[1] != key[1]:
            self._ranks = pattern.ranks(self.cells, node_offset)
            self._ranks_key = key
        return self._ranks

    def assemble(self, u: np.ndarray, data: np.ndarray, rhs: np.ndarray, pattern: Pattern | None,
                 node_offset: int = 0, want_K: bool = True) -> int:
        """Add internal forces to ``rhs`` and (if want_K) element tangents to the CSR ``data``.

        Dofs are 3 (node_offset + a) + i. Returns -1, or the first element with det F <= 0 (or
        det J0 <= 0) at a Gauss point; the outputs then stay finite but may be meaningless.
        """
        u = self._u(u)
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
            first_bad = self._assemble_chunks(u, data, rhs, node_ptr, ranks, off, nblocks, want_K)
        finally:
            set_parallel_chunksize(old_chunksize)
        return first_bad

    def _assemble_chunks(self, u, data, rhs, node_ptr, ranks, off, nblocks, want_K) -> int:
        kind, params = self.material.kind, self.material.params
        first_bad = -1
        for e0 in range(0, self.n_elements, self.chunk):
            nc = min(self.chunk, self.n_elements - e0)
            Ke = self._Ke[:nc] if want_K else self._Ke
            fe = self._fe[:nc]
            flags = self._flags[:nc]
            solid_chunk(kind, params, self.X, u, self.cells, e0, self.dNdxi, self.weights, want_K, Ke, fe,
                        flags, nblocks)
            scatter_vectors(rhs, self.cells, off, fe, e0)
            if want_K:
                scatter_matrices(data, node_ptr, self.cells, off, ranks, Ke, e0)
            if first_bad < 0:
                bad = np.flatnonzero(flags)
                if bad.size:
                    first_bad = e0 + int(bad[0])
        return first_bad

    def energy(self, u: np.ndarray) -> float:
        """Strain energy int W dV (inf if a Neo-Hooke element is inverted)."""
        return float(self._fields(u, 0, 1).sum())

    def stress(self, u: np.ndarray) -> SolidStress:
        """Element-averaged Cauchy, S and Green-Lagrange strain; nodal averaged Cauchy stress."""
        f = self._fields(u, 2, 18)
        cauchy = np.ascontiguousarray(f[:, :6])
        count = np.bincount(self.cells.ravel(), minlength=self.n_nodes).astype(np.float64)
        nodal = np.empty((self.n_nodes, 6))
        for I in range(6):
            nodal[:, I] = np.bincount(self.cells.ravel(), weights=np.repeat(cauchy[:, I], self.nen),
                                      minlength=self.n_nodes)
        nodal /= np.maximum(count, 1.0)[:, None]
        s = cauchy
        vm = np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2 + (s[:, 2] - s[:, 0]) ** 2)
                     + 3.0 * (s[:, 3] ** 2 + s[:, 4] ** 2 + s[:, 5] ** 2))
        return SolidStress(cauchy=cauchy, pk2=np.ascontiguousarray(f[:, 6:12]),
                           green_lagrange=np.ascontiguousarray(f[:, 12:]), cauchy_nodal=nodal, von_mises=vm)
