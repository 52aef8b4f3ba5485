"""Hexahedra with incompatible modes (C3D8I): the enhanced-assumed-strain hex8 at finite strain.

Total Lagrangian, 2 x 2 x 2 Gauss points, 8 nodes plus nine element-internal parameters alpha. The material
sees the enhanced deformation gradient (Simo & Armero 1992)

    F = I + sum_a u_a (x) G_a + sum_k alpha_k (x) b_k,   b_k(xi) = (j0 / j(xi)) (-2 xi_k) J0^-T e_k,

G_a = dN_a/dX, alpha_k (3,) = alpha[3 k: 3 k + 3] the parameters of mode k (k = 0, 1, 2 for xi, eta, zeta),
J0 = dX/dxi and j0 = det J0 at the element centre, j = det dX/dxi at the Gauss point. b_k is the gradient of the
incompatible displacement mode (1 - xi_k^2) alpha_k (Wilson, Taylor, Doherty & Ghaboussi 1973) with the Jacobian
frozen at the centre and scaled by j0 / j (Taylor, Beresford & Wilson 1976): int b_k dV = j0 J0^-T e_k int -2 xi_k
dxi = 0 on any hexahedron, so a homogeneous deformation leaves alpha = 0 and the element passes the patch test;
on a parallelepiped b_k is exactly the gradient of the mode, and the element is the classical incompatible-mode
brick (exact in pure bending).

Equations per element: with P = F S(F) (first Piola-Kirchhoff, the material through ``material_update_h``),

    f_a = int P G_a dV,   h_k = int P b_k dV = 0,

the parameters alpha solved from h = 0 by a local Newton inside every assembly (started from the trial of the
previous iteration, a hint) and condensed: K = K_uu - K_ua K_aa^-1 K_au, every block int G A G dV with the first
elasticity tensor A_kjln = F_ki C_ijmn F_lm + delta_kl S_jn. The eight nodes and the three modes are eleven
"nodes" with gradient vectors (G_a, b_k) to the kernels. For hyperelastic materials f is the gradient of
int W(F) dV at the solved alpha and K its Hessian (symmetric). Materials with history (J2) run the return
mapping from the committed history at every local iterate; the trial history is that of the solved alpha.

State (:meth:`IncompatibleBody.new_state`): ``alpha`` (nelem, 9), a hint (the start of the local Newton; the
residual depends on u and the committed history only), and ``hist`` (nelem, 8, n_hist) for materials with
history. docs/theory.md, section "Hexahedra with incompatible modes".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..fem.quadrature import gauss_tensor
from ..fem.shapes import shape_functions
from ..materials.hyperelastic import VOIGT_PAIRS, Material, material_energy
from ..materials.update import material_update_h
from .base import ElementBody, add_cauchy_pk2, block_range, gather
from .solid import _displacement_gradient, _first_elasticity, _jacobian
from .solidshell_dense import _factor, _solve

__all__ = ["IncompatibleBody", "incompatible_chunk", "incompatible_fields"]

#: element flags: 0 ok, 1 det F <= 0 or the material failed at a Gauss point, 2 det J0 <= 0, 3 local Newton failed
FLAG_INVERTED = 1
FLAG_REFERENCE = 2
FLAG_LOCAL = 3
#: the local Newton stops when the change of the enhanced gradient |b dalpha| <= LOCAL_TOL max |H| (or LOCAL_ATOL)
#: and evaluates once more at the result
LOCAL_TOL = 1e-11
LOCAL_ATOL = 1e-15
LOCAL_MAXIT = 30
#: step halvings of the local line search
LOCAL_HALVINGS = 30
#: nodes, modes, "nodes" of the kernels (nodes + modes), parameters
NEN = 8
NMODE = 3
NN = NEN + NMODE
NALPHA = 3 * NMODE


# ----------------------------------------------------------------------------- compiled pieces


@njit(cache=True)
def _gradients(Xe, dNdxi, dNc, pts, w, J0, Ji, Jc, Gt, wdv):
    """Gt (ngp, 3, 11): Gt[g, j, a] = dN_a/dX_j of the nodes (a < 8) and the enhanced gradients b_k of the modes
    (a = 8 + k) at Gauss point g; wdv (ngp,) = w_g det J0(xi_g). Returns (0 or FLAG_REFERENCE, det J0 at the centre).
    """
    detc = _jacobian(Xe, dNc, J0, Jc)
    if not (detc > 0.0):
        return FLAG_REFERENCE, detc
    for g in range(w.size):
        det = _jacobian(Xe, dNdxi[g], J0, Ji)
        if not (det > 0.0):
            return FLAG_REFERENCE, detc
        wdv[g] = w[g] * det
        for j in range(3):
            j0 = Ji[0, j]
            j1 = Ji[1, j]
            j2 = Ji[2, j]
            for a in range(NEN):
                Gt[g, j, a] = dNdxi[g, a, 0] * j0 + dNdxi[g, a, 1] * j1 + dNdxi[g, a, 2] * j2
        r = detc / det
        for k in range(NMODE):
            c = -2.0 * r * pts[g, k]
            for j in range(3):
                Gt[g, j, NEN + k] = c * Jc[k, j]
    return 0, detc


@njit(cache=True)
def _evaluate(kind, params, Ue, Gt, wdv, first, want_K, hne, hist, F, H, S, D, T, A, Q, Kt, fa):
    """Forces and tangent at the "nodal" values Ue (11, 3) (displacements, then the mode parameters): fa[3 a + k]
    = int P_kj G_aj dV for a >= first and, if want_K, Kt[a, k, l, b] = int G_aj A_kjln G_bn dV for a, b >= first.
    Material history: hne (ngp, nh) committed (read), hist (ngp, nh) trial (written).

    Returns (flag, max |H| over the Gauss points, int W dV): flag FLAG_INVERTED when the material fails at a point;
    the energy for materials without history (hyperelastic; 0 for the others)."""
    for r in range(3 * first, 3 * NN):
        fa[r] = 0.0
    if want_K:
        for a in range(first, NN):
            for k in range(3):
                for l in range(3):
                    for b in range(first, NN):
                        Kt[a, k, l, b] = 0.0
    flag = 0
    hmax = 0.0
    energy = 0.0
    for g in range(wdv.size):
        G = Gt[g]
        _displacement_gradient(Ue, G, F, H, True)
        for i in range(3):
            for j in range(3):
                hmax = max(hmax, abs(H[i, j]))
        if material_update_h(kind, params, F, H, hne[g], hist[g], S, D) != 0:
            flag = FLAG_INVERTED
        wd = wdv[g]
        if hne.shape[1] == 0:
            energy += wd * material_energy(kind, params, F)
        for k in range(3):
            # P[k, j] = wd (F S)_kj, row k
            p0 = wd * (F[k, 0] * S[0] + F[k, 1] * S[3] + F[k, 2] * S[5])
            p1 = wd * (F[k, 0] * S[3] + F[k, 1] * S[1] + F[k, 2] * S[4])
            p2 = wd * (F[k, 0] * S[5] + F[k, 1] * S[4] + F[k, 2] * S[2])
            for a in range(first, NN):
                fa[3 * a + k] += p0 * G[0, a] + p1 * G[1, a] + p2 * G[2, a]
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
                    for a in range(first, NN):
                        Q[k, l, n, a] = a0 * G[0, a] + a1 * G[1, a] + a2 * G[2, a]
        for a in range(first, NN):
            for k in range(3):
                for l in range(3):
                    q0 = Q[k, l, 0, a]
                    q1 = Q[k, l, 1, a]
                    q2 = Q[k, l, 2, a]
                    for b in range(first, NN):
                        Kt[a, k, l, b] += q0 * G[0, b] + q1 * G[1, b] + q2 * G[2, b]
    return flag, hmax, energy


@njit(cache=True)
def _mode_block(Kt, Kaa):
    """Kaa (9, 9): the mode-mode block of Kt, Kaa[3 p + i, 3 q + l] = Kt[8 + p, i, l, 8 + q]."""
    for p in range(NMODE):
        for i in range(3):
            for q in range(NMODE):
                for l in range(3):
                    Kaa[3 * p + i, 3 * q + l] = Kt[NEN + p, i, l, NEN + q]


@njit(cache=True)
def _local_solve(kind, params, Ue, start, from_zero, Gt, wdv, want_K, hne, hist, ws):
    """Solve h(alpha) = 0 from alpha = start (9,) (or 0 if from_zero) by a damped Newton, until the change of the enhanced gradient is
    <= LOCAL_TOL max |H| (or LOCAL_ATOL); then that last step and one more evaluation of everything (forces of all
    "nodes", Kt if want_K) at the result, which Ue[8:] holds. Returns the flag.

    Hyperelastic materials (no history): h is the gradient of Pi(alpha) = int W dV, and the step is a descent
    direction of Pi (Newton's, with K_aa shifted by tau I where it is not positive definite) halved until Pi
    decreases by the Armijo fraction 1e-4 (a full step that halves |h| is taken as it is). Materials with history:
    Newton's step halved until |h| decreases. A step at which the material fails is halved too."""
    (_Ue, _Gt, _wdv, _J0, _Ji, _Jc, F, H, S, D, T, A, Q, Kt, fa, Kaa, Kf, base, dal, _a0, piv, _X, _hne) = ws
    ng = wdv.size
    hyper = hne.shape[1] == 0
    # np.bool_: run-time values to numba (a literal True or False compiles the callee once more per constant)
    yes, no = np.bool_(True), np.bool_(False)
    for k in range(NMODE):
        for i in range(3):
            Ue[NEN + k, i] = 0.0 if from_zero else start[3 * k + i]
    f, hmax, energy = _evaluate(kind, params, Ue, Gt, wdv, NEN, yes, hne, hist, F, H, S, D, T, A, Q, Kt, fa)
    if f != 0:
        return f
    hn = 0.0
    for m in range(NALPHA):
        hn += fa[3 * NEN + m] ** 2
    for _it in range(LOCAL_MAXIT):
        _mode_block(Kt, Kaa)
        if hyper:
            mode = _factor(Kaa, NALPHA, Kf, piv, no)
            dg = 0.0
            for m in range(NALPHA):
                dg = max(dg, abs(Kaa[m, m]))
            tau = 1e-8 * dg
            while mode == 0 and tau <= 1e8 * dg:
                _mode_block(Kt, Kaa)
                for m in range(NALPHA):
                    Kaa[m, m] += tau
                mode = _factor(Kaa, NALPHA, Kf, piv, no)
                tau *= 10.0
        else:
            mode = _factor(Kaa, NALPHA, Kf, piv, yes)
        if mode == 0:
            return FLAG_LOCAL
        slope = 0.0
        for m in range(NALPHA):
            dal[m] = -fa[3 * NEN + m]
        _solve(Kf, piv, NALPHA, dal, mode)
        for m in range(NALPHA):
            slope += fa[3 * NEN + m] * dal[m]
        dmax = 0.0
        for g in range(ng):
            for i in range(3):
                for j in range(3):
                    s = 0.0
                    for k in range(NMODE):
                        s += dal[3 * k + i] * Gt[g, j, NEN + k]
                    dmax = max(dmax, abs(s))
        if not np.isfinite(dmax):
            return FLAG_LOCAL
        if dmax <= LOCAL_TOL * hmax or dmax <= LOCAL_ATOL:
            for k in range(NMODE):
                for i in range(3):
                    Ue[NEN + k, i] += dal[3 * k + i]
            f, _, _ = _evaluate(kind, params, Ue, Gt, wdv, 0, want_K, hne, hist, F, H, S, D, T, A, Q, Kt, fa)
            return f
        for k in range(NMODE):
            for i in range(3):
                base[3 * k + i] = Ue[NEN + k, i]
        step = 1.0
        accepted = False
        for _ls in range(LOCAL_HALVINGS):
            for k in range(NMODE):
                for i in range(3):
                    Ue[NEN + k, i] = base[3 * k + i] + step * dal[3 * k + i]
            f, hmax, enew = _evaluate(kind, params, Ue, Gt, wdv, NEN, yes, hne, hist, F, H, S, D, T, A, Q, Kt,
                                      fa)
            if f == 0:
                hnew = 0.0
                for m in range(NALPHA):
                    hnew += fa[3 * NEN + m] ** 2
                if hyper:
                    accepted = enew <= energy + 1e-4 * step * slope or (step == 1.0 and hnew <= 0.25 * hn)
                else:
                    accepted = hnew <= (1.0 - 1e-4 * step) ** 2 * hn
                if accepted:
                    hn = hnew
                    energy = enew
                    break
            step *= 0.5
        if not accepted:
            return FLAG_LOCAL
    return FLAG_LOCAL


@njit(cache=True)
def _work(nh):
    """Per-block scratch of the element kernels (one tuple; unpacked in :func:`_element`)."""
    ng = 8
    return (np.empty((NN, 3)), np.empty((ng, 3, NN)), np.empty(ng), np.empty((3, 3)), np.empty((3, 3)),
            np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty(6), np.empty((6, 6)), np.empty((3, 3, 9)),
            np.empty((3, 3, 9)), np.empty((3, 3, 3, NN)), np.empty((NN, 3, 3, NN)), np.empty(3 * NN),
            np.empty((NALPHA, NALPHA)), np.empty((NALPHA, NALPHA)), np.empty(NALPHA), np.empty(NALPHA),
            np.empty(NALPHA), np.zeros(NALPHA, dtype=np.int64), np.empty((NALPHA, 3 * NEN)), np.empty((ng, nh)))


@njit(cache=True)
def _element(kind, params, Xe, ue, alpha, dNdxi, dNc, pts, w, want_K, Ke, fe, hist_n, hist, ws):
    """Internal force fe (24,) and condensed tangent Ke (24, 24) of one element (overwritten); alpha (9,) read as
    the start of the local Newton and overwritten with its solution. hist_n (8, nh) committed history (read; may be
    the same array as hist: it is copied first), hist (8, nh) trial (written).

    A failed element (flag != 0) gets fe = 0, Ke = 0, alpha back to its start and hist = hist_n. Returns the flag.
    """
    (Ue, Gt, wdv, J0, Ji, Jc, F, H, S, D, T, A, Q, Kt, fa, Kaa, Kf, h, dal, a0, piv, X, hne) = ws
    nh = hist.shape[1]
    for g in range(w.size):
        for k in range(nh):
            hne[g, k] = hist_n[g, k]
    finite = True
    nonzero = False
    for m in range(NALPHA):
        finite = finite and np.isfinite(alpha[m])
        nonzero = nonzero or alpha[m] != 0.0
    for m in range(NALPHA):
        a0[m] = alpha[m] if finite else 0.0
    flag, _ = _gradients(Xe, dNdxi, dNc, pts, w, J0, Ji, Jc, Gt, wdv)
    if flag == 0:
        for a in range(NEN):
            for i in range(3):
                Ue[a, i] = ue[a, i]
        flag = _local_solve(kind, params, Ue, a0, np.bool_(False), Gt, wdv, want_K, hne, hist, ws)
        if flag != 0 and finite and nonzero:  # the start from the hint failed: once more from alpha = 0
            flag = _local_solve(kind, params, Ue, a0, np.bool_(True), Gt, wdv, want_K, hne, hist, ws)
    nd = 3 * NEN
    if flag != 0:
        for m in range(NALPHA):
            alpha[m] = a0[m]
        for g in range(w.size):
            for k in range(nh):
                hist[g, k] = hne[g, k]
        for r in range(nd):
            fe[r] = 0.0
        if want_K:
            for r in range(nd):
                for c in range(nd):
                    Ke[r, c] = 0.0
        return flag
    for k in range(NMODE):
        for i in range(3):
            alpha[3 * k + i] = Ue[NEN + k, i]
    for r in range(nd):
        fe[r] = fa[r]
    if not want_K:
        return 0
    # condensation: Ke = K_uu - K_ua K_aa^-1 K_au
    _mode_block(Kt, Kaa)
    mode = _factor(Kaa, NALPHA, Kf, piv, np.bool_(True))
    if mode == 0:
        for r in range(nd):
            fe[r] = 0.0
            for c in range(nd):
                Ke[r, c] = 0.0
        return FLAG_LOCAL
    for b in range(NEN):
        for l in range(3):
            for q in range(NMODE):
                for i in range(3):
                    h[3 * q + i] = Kt[NEN + q, i, l, b]
            _solve(Kf, piv, NALPHA, h, mode)
            for m in range(NALPHA):
                X[m, 3 * b + l] = h[m]
    for a in range(NEN):
        for k in range(3):
            for b in range(NEN):
                for l in range(3):
                    s = Kt[a, k, l, b]
                    for q in range(NMODE):
                        for i in range(3):
                            s -= Kt[a, k, i, NEN + q] * X[3 * q + i, 3 * b + l]
                    Ke[3 * a + k, 3 * b + l] = s
    return 0


@njit(parallel=True, cache=True)
def incompatible_chunk(kind, params, X, u, conn, e0, alpha, dNdxi, dNc, pts, w, want_K, Ke, fe, flags, nblocks,
                       hist_n, hist):
    """Element buffers Ke (nc, 24, 24), fe (nc, 24), flags (nc,) of elements e0 .. e0 + nc - 1.

    alpha (nelem, 9): read as the start of the local Newton, overwritten with its solution. hist_n, hist
    (nelem, 8, nh): committed (read) and trial (written) material history, possibly the same array; nh = 0 for
    hyperelastic materials.
    """
    nc = fe.shape[0]
    nblk = max(1, min(nblocks, nc))
    for t in prange(nblk):
        lo, hi = block_range(t, nc, nblk)
        Xe = np.empty((NEN, 3))
        ue = np.empty((NEN, 3))
        ws = _work(hist.shape[2])
        Kdummy = np.empty((0, 0))
        for c in range(lo, hi):
            e = e0 + c
            gather(X, u, conn, e, Xe, ue)
            Kc = Ke[c] if want_K else Kdummy
            flags[c] = _element(kind, params, Xe, ue, alpha[e], dNdxi, dNc, pts, w, want_K, Kc, fe[c], hist_n[e],
                                hist[e], ws)


@njit(cache=True)
def incompatible_fields(kind, params, X, u, conn, alpha, dNdxi, dNc, pts, w, mode, out, hist_n):
    """Per-element quantities at the solved mode parameters (alpha (ne, 9): the start, overwritten with the
    solution; the caller passes a copy), hist_n (ne, 8, nh) the committed history (read only).

    mode 0: out (ne, 1) strain energy int W(F) dV (inf where the element fails); mode 1: out (ne, 1) minimum det J0
    over the centre and the Gauss points; mode 2: out (ne, 18) volume averages of the Cauchy stress, S and the
    Green-Lagrange strain of the enhanced F (Voigt); mode 3: out (ne, 48) the Cauchy stress at each Gauss point.
    """
    ne = conn.shape[0]
    Xe = np.empty((NEN, 3))
    ue = np.empty((NEN, 3))
    nh = hist_n.shape[2]
    ws = _work(nh)
    (Ue, Gt, wdv, J0, Ji, Jc, F, H, S, D, _T, _A, _Q, _Kt, _fa, _Kaa, _Kf, _h, _dal, _a0, _piv, _Xm, _hne) = ws
    htr = np.empty((w.size, nh))
    hscr = np.empty(nh)
    fe = np.empty(3 * NEN)
    Kdummy = np.empty((0, 0))
    row = np.empty(18)
    no = np.bool_(False)  # run-time value: _element compiled once (a literal False adds a version)
    for e in range(ne):
        gather(X, u, conn, e, Xe, ue)
        for r in range(out.shape[1]):
            out[e, r] = 0.0
        if mode == 1:
            dmin = _jacobian(Xe, dNc, J0, Ji)
            for g in range(w.size):
                dmin = min(dmin, _jacobian(Xe, dNdxi[g], J0, Ji))
            out[e, 0] = dmin
            continue
        if _element(kind, params, Xe, ue, alpha[e], dNdxi, dNc, pts, w, no, Kdummy, fe, hist_n[e], htr,
                    ws) != 0:
            if mode == 0:
                out[e, 0] = np.inf
            continue
        vol = 0.0
        for g in range(w.size):
            _displacement_gradient(Ue, Gt[g], F, H, True)
            wd = wdv[g]
            vol += wd
            if mode == 0:
                out[e, 0] += wd * material_energy(kind, params, F)
                continue
            material_update_h(kind, params, F, H, hist_n[e, g], hscr, S, D)
            if mode == 3:
                for r in range(18):
                    row[r] = 0.0
                add_cauchy_pk2(F, S, 1.0, row)
                for r in range(6):
                    out[e, 6 * g + r] = row[r]
                continue
            add_cauchy_pk2(F, S, wd, out[e])
            for I in range(6):
                i = VOIGT_PAIRS[I, 0]
                j = VOIGT_PAIRS[I, 1]
                cm = H[i, j] + H[j, i] + H[0, i] * H[0, j] + H[1, i] * H[1, j] + H[2, i] * H[2, j]
                out[e, 12 + I] += wd * 0.5 * cm
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol


# ----------------------------------------------------------------------------- body


class IncompatibleBody(ElementBody):
    """A body of hex8 with incompatible modes (C3D8I; the module docstring has the formulation).

    Args:
        cell_type: "hex8" (the only cell type; the argument keeps the signature of the other bodies).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, 8) connectivity (local node ids).
        material: a :mod:`covcontact.materials` material; its ``n_hist`` (0 if absent) is the history length per
            Gauss point.
        chunk_bytes: size of the per-chunk element tangent buffer.

    State: ``new_state()`` = {"alpha": zeros((nelem, 9))} plus {"hist": zeros((nelem, 8, n_hist))} for a material
    with history. ``alpha`` is a hint (:attr:`HINTS`): an assembly starts its local Newton from it and writes the
    solution back; ``hist`` is history: read from ``state["hist_n"]`` when given (as :meth:`kernel_state` provides
    it), else from ``state["hist"]`` itself, and the trial written into ``state["hist"]``. :meth:`stress` and
    :meth:`energy` read ``state`` and write nothing.
    """

    HINTS = ("alpha",)

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 chunk_bytes: int = 32 * 2**20) -> None:
        if cell_type != "hex8":
            raise ValueError(f"incompatible modes are for hex8 cells (C3D8I), got cell type {cell_type!r}")
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        self.points, self.weights = gauss_tensor((2, 2, 2))
        self.points = np.ascontiguousarray(self.points)
        self.dNdxi = np.ascontiguousarray(shape_functions("hex8", self.points)[1])
        self.dNc = np.ascontiguousarray(shape_functions("hex8", np.zeros((1, 3)))[1][0])

    @property
    def n_hist(self) -> int:
        """Material history length per Gauss point (0 for hyperelastic materials)."""
        return int(getattr(self.material, "n_hist", 0))

    def new_state(self) -> dict[str, np.ndarray]:
        """The mode parameters ``alpha`` (nelem, 9), zero in the reference state, and for a material with history
        ``hist`` (nelem, 8, n_hist)."""
        st = {"alpha": np.zeros((self.n_elements, NALPHA))}
        if self.n_hist:
            st["hist"] = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        return st

    def _hist(self, state) -> tuple[np.ndarray, np.ndarray]:
        """(committed, trial) history arrays of ``state``: ``hist_n`` if given (read only), else ``hist`` itself."""
        if self.n_hist == 0:
            h = np.zeros((self.n_elements, self.weights.size, 0))
            return h, h
        hist = state.get("hist")
        if hist is None:  # a state with the start values only: virgin material
            hist = state["hist"] = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        return state.get("hist_n", hist), hist

    def _alpha(self, state) -> np.ndarray:
        alpha = state.get("alpha")
        if alpha is None:
            alpha = state["alpha"] = np.zeros((self.n_elements, NALPHA))
        return alpha

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        hist_n, hist = self._hist(state)
        incompatible_chunk(self.material.kind, self.material.params, self.X, u, self.cells, e0, self._alpha(state),
                           self.dNdxi, self.dNc, self.points, self.weights, want_K, Ke, fe, flags, nblocks, hist_n,
                           hist)

    def _gauss_fields(self, u, mode, out, state) -> None:
        # the history of ``state`` is read as the committed one; alpha is copied (the local solve writes it)
        hist_n = state.get("hist") if self.n_hist else None
        if hist_n is None:
            hist_n = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        alpha = state["alpha"].copy() if "alpha" in state else np.zeros((self.n_elements, NALPHA))
        incompatible_fields(self.material.kind, self.material.params, self.X, u, self.cells, alpha, self.dNdxi,
                            self.dNc, self.points, self.weights, mode, out, hist_n)

    def point_stresses(self, u: np.ndarray, state: dict | None = None) -> np.ndarray:
        """(nelem, 8, 6) Cauchy stress (Voigt 11, 22, 33, 12, 23, 13) at the Gauss points (the first direction of
        the element's coordinates fastest) at the solved mode parameters."""
        return self._fields(u, 3, 6 * self.weights.size, state).reshape(self.n_elements, self.weights.size, 6)
