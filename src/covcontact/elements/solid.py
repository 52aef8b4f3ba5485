"""Total-Lagrangian solid hexahedra (hex8, hex27; hex18 as a plain solid) with full Gauss integration.

Per Gauss point: J0 = dX/dxi, G = dN/dX = dN/dxi J0^-1, F = I + u^T G, S and D from the material,
first Piola-Kirchhoff P = F S. Internal force f_ak = int P_kj G_aj dV and tangent
K_ab,kl = int G_aj A_kjln G_bn dV with the first elasticity tensor
A_kjln = F_ki C_ijmn F_lm + delta_kl S_jn (material + geometric part in one).

Elements are processed in chunks: a parallel kernel fills per-element buffers, a serial scatter adds
them to the CSR data array through the node-pair ranks of :class:`covcontact.assembly.Pattern`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..fem import cells as other_cells
from ..fem.quadrature import DEFAULT_RULE, gauss_tensor
from ..fem.shapes import shape_functions
from ..materials.hyperelastic import VOIGT, Material, material_energy
from ..materials.hyperelastic import VOIGT_PAIRS as _PAIRS
from ..materials.update import material_update_h
from .base import BLOCKS_PER_THREAD, ElementBody, SolidStress, add_cauchy_pk2, block_range, gather, inverse3

__all__ = ["BLOCKS_PER_THREAD", "SOLID_CELLS", "SolidBody", "SolidStress", "solid_chunk", "solid_gauss_fields"]

SOLID_CELLS = ("hex8", "hex18", "hex27", *other_cells.CELLS)


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
    return inverse3(J0, Ji)


@njit(cache=True, inline="always")
def _deformation_gradient(ue, G, F, node_last):
    """F = I + sum_a u_a (x) G_a from G[a, j] = dN_a/dX_j, or from G[j, a] if node_last (a constant at each call
    site: the branch folds away once inlined)."""
    for i in range(3):
        for j in range(3):
            s = 1.0 if i == j else 0.0
            for a in range(ue.shape[0]):
                s += ue[a, i] * (G[j, a] if node_last else G[a, j])
            F[i, j] = s


@njit(cache=True, inline="always")
def _displacement_gradient(ue, G, F, H, node_last):
    """H = sum_a u_a (x) G_a (from the displacements: every digit of a small strain) and F = I + H."""
    for i in range(3):
        for j in range(3):
            s = 0.0
            for a in range(ue.shape[0]):
                s += ue[a, i] * (G[j, a] if node_last else G[a, j])
            H[i, j] = s
            F[i, j] = s + (1.0 if i == j else 0.0)


@njit(cache=True, inline="always")
def _kinematics(dNg, Ji, ue, G, F):
    """G = dN/dX (nen, 3) and F = I + sum_a u_a (x) G_a."""
    for a in range(ue.shape[0]):
        for j in range(3):
            G[a, j] = dNg[a, 0] * Ji[0, j] + dNg[a, 1] * Ji[1, j] + dNg[a, 2] * Ji[2, j]
    _deformation_gradient(ue, G, F, False)


@njit(cache=True, inline="always")
def _gradients_t(dNg, Ji, ue, Gt, F):
    """Gt = (dN/dX)^T (3, nen), node index last (the tangent loops run over nodes in SIMD lanes), and
    F = I + sum_a u_a (x) G_a."""
    for j in range(3):
        j0 = Ji[0, j]
        j1 = Ji[1, j]
        j2 = Ji[2, j]
        for a in range(ue.shape[0]):
            Gt[j, a] = dNg[a, 0] * j0 + dNg[a, 1] * j1 + dNg[a, 2] * j2
    _deformation_gradient(ue, Gt, F, True)


@njit(cache=True, inline="always")
def _first_elasticity(F, S, D, wd, T, A):
    """The first elasticity tensor times the weight, A[l, k, 3 j + n] = wd A_kjln (A_kjln = sum_im F_ki C_ijmn
    F_lm + delta_kl S_jn) from the material's S and D (Voigt). Scratch T (3, 3, 9): first C[m, i, 3 j + n] =
    C_ijmn, then T[m, k, 3 j + n] = sum_i F_ki C_ijmn; the 9-long last axes are contiguous (SIMD lanes)."""
    C = A  # A's storage holds C until T is formed
    for m in range(3):
        for i in range(3):
            for j in range(3):
                for n in range(3):
                    C[m, i, 3 * j + n] = D[VOIGT[i, j], VOIGT[m, n]]
    for m in range(3):
        for k in range(3):
            f0 = F[k, 0]
            f1 = F[k, 1]
            f2 = F[k, 2]
            for jn in range(9):
                T[m, k, jn] = f0 * C[m, 0, jn] + f1 * C[m, 1, jn] + f2 * C[m, 2, jn]
    for l in range(3):
        f0 = F[l, 0]
        f1 = F[l, 1]
        f2 = F[l, 2]
        for k in range(3):
            for jn in range(9):
                A[l, k, jn] = wd * (f0 * T[0, k, jn] + f1 * T[1, k, jn] + f2 * T[2, k, jn])
        for j in range(3):
            for n in range(3):
                A[l, l, 3 * j + n] += wd * S[VOIGT[j, n]]


@njit(cache=True)
def _element(kind, params, Xe, ue, dNdxi, w, want_K, Ke, fe, J0, Ji, Gt, F, S, D, P, T, A, Q, Kt, hist_n, hist):
    """Internal force fe (3 nen,) and tangent Ke (3 nen, 3 nen) of one element (overwritten); the material
    history of its Gauss points: hist_n (ngp, nh) committed (read), hist (ngp, nh) trial (written).

    The tangent is summed over the Gauss points as Kt[a, k, l, b] with the node b last, so that the
    innermost loops (over the nodes a of Q, over b of Kt) are contiguous and run in SIMD lanes; Ke gets
    Kt's blocks b >= a and their mirror images (exactly symmetric).
    Scratch: Gt (3, nen), Q (3, 3, 3, nen), Kt (nen, 3, 3, nen).

    Returns 0, 1 if det F <= 0 at a Gauss point, 2 if det J0 <= 0 (that point is skipped).
    """
    nen = Xe.shape[0]
    nd = 3 * nen
    H = np.empty((3, 3))
    for r in range(nd):
        fe[r] = 0.0
    if want_K:
        for a in range(nen):
            for k in range(3):
                for l in range(3):
                    for b in range(nen):
                        Kt[a, k, l, b] = 0.0
    flag = 0
    for g in range(w.size):
        dNg = dNdxi[g]
        det = _jacobian(Xe, dNg, J0, Ji)
        if det <= 0.0:
            flag = 2
            continue
        _gradients_t(dNg, Ji, ue, Gt, F)
        _displacement_gradient(ue, Gt, F, H, True)
        if material_update_h(kind, params, F, H, hist_n[g], hist[g], S, D) != 0 and flag == 0:
            flag = 1
        wd = w[g] * det
        # P = F S (scaled by the integration weight)
        for k in range(3):
            for j in range(3):
                P[k, j] = wd * (F[k, 0] * S[VOIGT[0, j]] + F[k, 1] * S[VOIGT[1, j]] + F[k, 2] * S[VOIGT[2, j]])
        for a in range(nen):
            for k in range(3):
                fe[3 * a + k] += P[k, 0] * Gt[0, a] + P[k, 1] * Gt[1, a] + P[k, 2] * Gt[2, a]
        if not want_K:
            continue
        _first_elasticity(F, S, D, wd, T, A)
        # Q[k, l, n, a] = sum_j G_aj A_kjln
        for k in range(3):
            for l in range(3):
                for n in range(3):
                    a0 = A[l, k, n]
                    a1 = A[l, k, 3 + n]
                    a2 = A[l, k, 6 + n]
                    for a in range(nen):
                        Q[k, l, n, a] = a0 * Gt[0, a] + a1 * Gt[1, a] + a2 * Gt[2, a]
        # Kt[a, k, l, b] += sum_n Q[k, l, n, a] G_bn
        for a in range(nen):
            for k in range(3):
                for l in range(3):
                    q0 = Q[k, l, 0, a]
                    q1 = Q[k, l, 1, a]
                    q2 = Q[k, l, 2, a]
                    for b in range(nen):
                        Kt[a, k, l, b] += q0 * Gt[0, b] + q1 * Gt[1, b] + q2 * Gt[2, b]
    if want_K:
        for a in range(nen):
            for b in range(a, nen):
                for k in range(3):
                    for l in range(3):
                        v = Kt[a, k, l, b]
                        Ke[3 * a + k, 3 * b + l] = v
                        Ke[3 * b + l, 3 * a + k] = v
    return flag


@njit(cache=True)
def _work(nen):
    """Per-block work arrays Xe, ue, G (nen, 3), J0, Ji, F (3, 3), S (6,), D (6, 6)."""
    return (np.empty((nen, 3)), np.empty((nen, 3)), np.empty((nen, 3)), np.empty((3, 3)), np.empty((3, 3)),
            np.empty((3, 3)), np.empty(6), np.empty((6, 6)))


@njit(parallel=True, cache=True)
def solid_chunk(kind, params, X, u, conn, e0, dNdxi, w, want_K, Ke, fe, flags, nblocks, hist_n, hist):
    """Element buffers Ke (nc, nd, nd), fe (nc, nd) and flags (nc,) of elements e0 .. e0 + nc - 1.

    The chunk is split into ``nblocks`` contiguous blocks (the parallel iterations), each with its
    own scratch arrays. hist_n, hist (nelem, ngp, nh): committed and trial material history.
    """
    nc = fe.shape[0]
    nen = conn.shape[1]
    nblk = max(1, min(nblocks, nc))
    for t in prange(nblk):
        lo, hi = block_range(t, nc, nblk)
        Xe, ue, _, J0, Ji, F, S, D = _work(nen)
        Gt = np.empty((3, nen))
        P = np.empty((3, 3))
        T = np.empty((3, 3, 9))
        A = np.empty((3, 3, 9))
        Q = np.empty((3, 3, 3, nen))
        Kt = np.empty((nen, 3, 3, nen))
        Kdummy = np.empty((0, 0))
        for c in range(lo, hi):
            gather(X, u, conn, e0 + c, Xe, ue)
            Kc = Ke[c] if want_K else Kdummy
            flags[c] = _element(kind, params, Xe, ue, dNdxi, w, want_K, Kc, fe[c], J0, Ji, Gt, F, S, D, P,
                                T, A, Q, Kt, hist_n[e0 + c], hist[e0 + c])


@njit(cache=True)
def solid_gauss_fields(kind, params, X, u, conn, dNdxi, w, mode, out, hist_n):
    """Per-element Gauss-point quantities (serial: see ``ElementBody._gauss_fields``).

    mode 0: out (ne, 1) strain energy int W dV; mode 1: out (ne, 1) minimum det J0;
    mode 2: out (ne, 18) volume averages of Cauchy stress, S and Green-Lagrange E (Voigt), with the
    material history hist_n (ne, ngp, nh) as the committed one.
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    Xe, ue, G, J0, Ji, F, S, D = _work(nen)
    H = np.empty((3, 3))
    hscr = np.empty(hist_n.shape[2])
    for e in range(ne):
        gather(X, u, conn, e, Xe, ue)
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
            _displacement_gradient(ue, G, F, H, False)
            material_update_h(kind, params, F, H, hist_n[e, g], hscr, S, D)
            add_cauchy_pk2(F, S, wd, out[e])
            for I in range(6):
                i = _PAIRS[I, 0]
                j = _PAIRS[I, 1]
                cm = H[i, j] + H[j, i] + H[0, i] * H[0, j] + H[1, i] * H[1, j] + H[2, i] * H[2, j]
                out[e, 12 + I] += wd * 0.5 * cm
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol


def _rule(cell_type: str, rule) -> tuple[np.ndarray, np.ndarray]:
    if cell_type in other_cells.CELLS and (rule is None or isinstance(rule, (int, np.integer))):
        return other_cells.rule(cell_type, rule)
    if rule is None:
        return gauss_tensor(DEFAULT_RULE[cell_type])
    if len(rule) == 3 and all(isinstance(r, (int, np.integer)) for r in rule):
        return gauss_tensor(tuple(int(r) for r in rule))
    pts, w = rule
    return np.ascontiguousarray(pts, dtype=np.float64).reshape(-1, 3), np.ascontiguousarray(w, dtype=np.float64)


class SolidBody(ElementBody):
    """A total-Lagrangian solid body of one hexahedral cell type.

    Args:
        cell_type: "hex8", "hex27" or "hex18" (hex18 as a plain 3x3x2 solid).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, nen) connectivity (local node ids).
        material: a :mod:`covcontact.materials` material.
        rule: None (full integration), Gauss orders (n1, n2, n3) or (points, weights); for tet4, tet10, wedge6 and
            hex20 the number of points of one of their rules.
        chunk_bytes: size of the per-chunk element tangent buffer.
        integration: "full", or "reduced" for hex20 (2 x 2 x 2 points, as C3D20R).
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 rule=None, chunk_bytes: int = 32 * 2**20, integration: str = "full") -> None:
        if cell_type not in SOLID_CELLS:
            raise ValueError(f"unknown solid cell type {cell_type!r}; known: {', '.join(SOLID_CELLS)}")
        if integration == "reduced":
            if cell_type != "hex20":
                raise ValueError(f"reduced integration is for hex20 (C3D20R), not {cell_type}")
            rule = 8
        elif integration != "full":
            raise ValueError(f"integration must be \"full\" or \"reduced\", got {integration!r}")
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        self.points, self.weights = _rule(cell_type, rule)
        dN = other_cells.shapes(cell_type, self.points)[1] if cell_type in other_cells.CELLS else \
            shape_functions(cell_type, self.points)[1]
        self.dNdxi = np.ascontiguousarray(dN)

    def new_state(self) -> dict[str, np.ndarray]:
        """Material history per Gauss point, ``hist`` (nelem, ngp, n_hist); n_hist = 0 for hyperelastic
        materials."""
        return {"hist": np.zeros((self.n_elements, self.weights.size, getattr(self.material, "n_hist", 0)))}

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        hist = state["hist"]
        hist_n = state["hist_n"] if "hist_n" in state else hist.copy()
        solid_chunk(self.material.kind, self.material.params, self.X, u, self.cells, e0, self.dNdxi,
                    self.weights, want_K, Ke, fe, flags, nblocks, hist_n, hist)

    def _gauss_fields(self, u, mode, out, state) -> None:
        solid_gauss_fields(self.material.kind, self.material.params, self.X, u, self.cells, self.dNdxi,
                           self.weights, mode, out, state["hist"])
