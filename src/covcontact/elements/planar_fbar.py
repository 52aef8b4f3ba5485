"""F-bar planar bodies (plane strain and axisymmetric) for nearly incompressible and plastic solids, total
Lagrangian (docs/theory.md, "Planar bodies", "F-bar in the plane").

At every Gauss point the material sees a modified deformation gradient with the isochoric part of the local F and
a volume change J_z taken from a coarser space (de Souza Neto, Peric, Dutko & Owen 1996, Int. J. Solids Struct. 33,
3277-3296; de Souza Neto, Peric & Owen 2008, "Computational Methods for Plasticity", section 15.4):

- plane strain: F_bar = phi F on the in-plane block, F_bar33 = F33 = 1, phi = (J_z / J)^(1/2) (n = 2): the
  out-of-plane stretch stays 1, as plane strain demands, and det F_bar = J_z;
- axisymmetric: F_bar = phi F including the hoop stretch F33 = r / R, phi = (J_z / J)^(1/3) (n = 3), the 3D form:
  J = det F includes the hoop stretch, and so does J_z.

J_z by cell: quad4 the volume change of the element centre (xi = eta = 0; axisymmetric with the centre's hoop
stretch), the paper's element; quad8 and quad9 (3 x 3 points) J projected (L2 over the element, with the volume
measure t dA or 2 pi R dA) onto the linear functions 1, xi, eta, the F-bar analogue of the Q2/P1 mixed element (as
hex27 in ``covcontact.elements.fbar``); tri6 the element mean of J over its three points (the P2/P0 analogue). tri3
is constant-strain already (one point): F-bar cannot relieve it and the option refuses it.

The weak form is the spatial one of the paper, int sigma(F_bar) : grad_x eta dv over the current volume, pulled back:
f_ak = int B_a^{kJ} P*_kJ dV with P* = (J / J_z) tau_bar F^-T = phi^-m F S_bar (m = n - 2, F block diagonal), B the
planar kernel's 9-component gradient operator (the hoop row N_a / R for axisymmetry). Its exact tangent is

    K_ab = int B_a (A B_b^T + x q_b^T) dV,
    A_kJlL = phi^-m (delta_kl S_bar_LJ + phi^2 F_kI C_IJML F_lM),
    x_kJ = phi^-m (F_kI C_IJML Chat_ML - m (F S_bar)_kJ),   q_b = (g_z,b - g_b) / n,

with g_b = B_b . vec(F^-T) the spatial gradient of node b (d ln J = g_b . du_b), g_z,b that of ln J_z, and
Chat = F_bar^T F_bar (plane strain: its in-plane block), the derivative of E_bar along d ln phi. It is not symmetric.
Plane stress has no volume constraint to relieve (F33 is free) and takes no F-bar.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..fem.planar_cells import planar_shapes
from ..materials.hyperelastic import VOIGT, Material, material_energy
from ..materials.hyperelastic import VOIGT_PAIRS as _PAIRS
from ..materials.update import material_update_h
from .base import add_cauchy_pk2
from .planar import AXISYMMETRIC, PlanarBody, _gather, _geometry

__all__ = ["PLANAR_FBAR_CELLS", "PlanarFbarBody", "planar_fbar_chunk", "planar_fbar_gauss_fields"]

#: the planar cells with an F-bar form (tri3 has one point: nothing to relieve)
PLANAR_FBAR_CELLS = ("quad4", "quad8", "quad9", "tri6")


# ----------------------------------------------------------------------------------------------- kernels


@njit(cache=True)
def _point(Xe, ue, Ng, dNg, form, thick, G, H, F, Fi, B, gr):
    """Geometry of one point: F (3 x 3), J = det F, B (2 nen, 9), gr (2 nen,) = B . vec(F^-T) (d ln J = gr . du),
    and the volume factor wd0 = det J0 times t or 2 pi R (0 where det J0 <= 0, R <= 0 or J <= 0). Returns (wd0, J,
    R, flag) with flag 2 for a bad reference point, 1 for det F <= 0."""
    nen = Xe.shape[0]
    det, R = _geometry(Xe, ue, Ng, dNg, form, G, H)
    if not (det > 0.0) or (form == AXISYMMETRIC and not (R > 0.0)):
        return 0.0, 0.0, R, 2
    for i in range(3):
        for j in range(3):
            F[i, j] = H[i, j] + (1.0 if i == j else 0.0)
    J2 = F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    J = J2 * F[2, 2]
    if not (J > 0.0 and F[2, 2] > 0.0):
        return 0.0, J, R, 1
    for i in range(3):
        for j in range(3):
            Fi[i, j] = 0.0
    Fi[0, 0] = F[1, 1] / J2
    Fi[1, 1] = F[0, 0] / J2
    Fi[0, 1] = -F[0, 1] / J2
    Fi[1, 0] = -F[1, 0] / J2
    Fi[2, 2] = 1.0 / F[2, 2]
    for r in range(2 * nen):
        for c in range(9):
            B[r, c] = 0.0
    for a in range(nen):
        for k in range(2):
            for J_ in range(2):
                B[2 * a + k, 3 * k + J_] = G[a, J_]
        if form == AXISYMMETRIC:
            B[2 * a, 8] = Ng[a] / R
    for a in range(nen):
        for k in range(2):
            s = 0.0
            for J_ in range(2):
                s += G[a, J_] * Fi[J_, k]  # (F^-T)_kJ = Fi[J, k]
            if form == AXISYMMETRIC and k == 0:
                s += B[2 * a, 8] * Fi[2, 2]
            gr[2 * a + k] = s
    wd0 = det * (2.0 * math.pi * R if form == AXISYMMETRIC else thick)
    return wd0, J, R, 0


@njit(cache=True)
def _dilatation(Xe, ue, N, dN, w, Nc, dNc, Pv, volume, form, thick, G, H, F, Fi, B, gr, Jz, Gz, Mw, Hw):
    """The volume change J_z of every Gauss point and the gradient of its logarithm, Gz (ngp, 2 nen): volume 0 the
    centre's (Nc, dNc), 1 J projected (L2 with the volume measure) onto the functions Pv (ngp, m) of the element.
    Returns 0, 1 if det F <= 0 somewhere (or J_z <= 0), 2 if a reference point is bad."""
    nd = Gz.shape[1]
    ngp = w.size
    if volume == 0:
        wd0, J, R, flag = _point(Xe, ue, Nc, dNc, form, thick, G, H, F, Fi, B, gr)
        if flag != 0:
            return flag
        for g in range(ngp):
            Jz[g] = J
            for r in range(nd):
                Gz[g, r] = gr[r]
        return 0
    m = Pv.shape[1]
    for i in range(m):
        for j in range(m):
            Mw[i, j] = 0.0
        for r in range(nd):
            Hw[i, r] = 0.0
    c = np.zeros(m)
    for g in range(ngp):
        wd0, J, R, flag = _point(Xe, ue, N[g], dN[g], form, thick, G, H, F, Fi, B, gr)
        if flag != 0:
            return flag
        wd = w[g] * wd0
        for i in range(m):
            c[i] += wd * Pv[g, i] * J
            for j in range(m):
                Mw[i, j] += wd * Pv[g, i] * Pv[g, j]
            for r in range(nd):
                Hw[i, r] += wd * Pv[g, i] * J * gr[r]
    Minv = np.linalg.inv(Mw)
    rw = np.empty(m)
    for g in range(ngp):
        for j in range(m):
            s = 0.0
            for i in range(m):
                s += Pv[g, i] * Minv[i, j]
            rw[j] = s
        jb = 0.0
        for j in range(m):
            jb += rw[j] * c[j]
        Jz[g] = jb
        if not (jb > 0.0):
            return 1
        for r in range(nd):
            s = 0.0
            for j in range(m):
                s += rw[j] * Hw[j, r]
            Gz[g, r] = s / jb
    return 0


@njit(cache=True)
def _barred(F, H, J, Jz, n, Fb, Hb):
    """phi = (J_z / J)^(1/n), F_bar and H_bar = F_bar - I (n = 2: the in-plane block scaled, F_bar33 = F33); returns
    phi."""
    t = math.log(Jz / J) / n
    phi = math.exp(t)
    pm1 = math.expm1(t)
    for i in range(3):
        for j in range(3):
            if n == 2 and (i == 2 or j == 2):
                Fb[i, j] = F[i, j]
                Hb[i, j] = H[i, j]
            else:
                Fb[i, j] = phi * F[i, j]
                Hb[i, j] = phi * H[i, j] + (pm1 if i == j else 0.0)
    return phi


@njit(cache=True)
def _fbar_planar_element(kind, params, form, nexp, volume, thick, Xe, ue, N, dN, w, Nc, dNc, Pv, want_K, Ke, fe,
                         hist_n, hist):
    """Internal force fe (3 nen,) and exact tangent Ke (3 nen, 3 nen) of one planar F-bar element (z rows and columns
    zero). Returns 0, 1 if det F <= 0 or J_z <= 0 somewhere or the material failed, 2 if det J0 <= 0 or R <= 0."""
    nen = Xe.shape[0]
    nd = 2 * nen
    ngp = w.size
    m = Pv.shape[1]
    mexp = nexp - 2
    G = np.zeros((nen, 2))
    H = np.zeros((3, 3))
    F = np.zeros((3, 3))
    Fi = np.zeros((3, 3))
    Fb = np.zeros((3, 3))
    Hb = np.zeros((3, 3))
    B = np.zeros((nd, 9))
    gr = np.zeros(nd)
    Jz = np.empty(ngp)
    Gz = np.empty((ngp, nd))
    Mw = np.empty((max(m, 1), max(m, 1)))
    Hw = np.empty((max(m, 1), nd))
    S = np.empty(6)
    D = np.empty((6, 6))
    Pv9 = np.empty(9)
    x9 = np.empty(9)
    Ch = np.empty((3, 3))
    A9 = np.empty((9, 9))
    BA = np.empty((nd, 9))
    Bx = np.empty(nd)
    qv = np.empty(nd)
    fl = np.zeros(nd)
    Kl = np.zeros((nd, nd))
    for a in range(3 * nen):
        fe[a] = 0.0
    if want_K:
        for r in range(3 * nen):
            for c in range(3 * nen):
                Ke[r, c] = 0.0
    flag = _dilatation(Xe, ue, N, dN, w, Nc, dNc, Pv, volume, form, thick, G, H, F, Fi, B, gr, Jz, Gz, Mw, Hw)
    if flag != 0:
        for g in range(ngp):
            for k in range(hist.shape[1]):
                hist[g, k] = hist_n[g, k]
        return flag
    for g in range(ngp):
        wd0, J, R, pf = _point(Xe, ue, N[g], dN[g], form, thick, G, H, F, Fi, B, gr)
        if pf != 0:
            if flag == 0 or pf == 2:
                flag = pf
            for k in range(hist.shape[1]):
                hist[g, k] = hist_n[g, k]
            continue
        wd = w[g] * wd0
        phi = _barred(F, H, J, Jz[g], nexp, Fb, Hb)
        if material_update_h(kind, params, Fb, Hb, hist_n[g], hist[g], S, D) != 0 and flag == 0:
            flag = 1
        cm = phi ** (-mexp)
        # P* = phi^-m F S_bar
        for k in range(3):
            for J_ in range(3):
                Pv9[3 * k + J_] = cm * (F[k, 0] * S[VOIGT[0, J_]] + F[k, 1] * S[VOIGT[1, J_]]
                                        + F[k, 2] * S[VOIGT[2, J_]])
        for r in range(nd):
            s = 0.0
            for c in range(9):
                s += B[r, c] * Pv9[c]
            fl[r] += wd * s
        if not want_K:
            continue
        for i in range(3):
            for j in range(3):
                s = Fb[0, i] * Fb[0, j] + Fb[1, i] * Fb[1, j] + Fb[2, i] * Fb[2, j]
                Ch[i, j] = 0.0 if (nexp == 2 and (i == 2 or j == 2)) else s
        p2 = phi * phi
        for k in range(3):
            for J_ in range(3):
                # x_kJ = cm (F_kI C_IJML Chat_ML - m (F S)_kJ)
                s = 0.0
                for i in range(3):
                    fki = F[k, i]
                    if fki == 0.0:
                        continue
                    for M in range(3):
                        for L in range(3):
                            s += fki * D[VOIGT[i, J_], VOIGT[M, L]] * Ch[M, L]
                x9[3 * k + J_] = cm * s - mexp * Pv9[3 * k + J_]
                for l in range(3):
                    for L in range(3):
                        s = S[VOIGT[J_, L]] if k == l else 0.0
                        t = 0.0
                        for i in range(3):
                            fki = F[k, i]
                            if fki == 0.0:
                                continue
                            for M in range(3):
                                t += fki * D[VOIGT[i, J_], VOIGT[M, L]] * F[l, M]
                        A9[3 * k + J_, 3 * l + L] = cm * (s + p2 * t)
        for r in range(nd):
            qv[r] = (Gz[g, r] - gr[r]) / nexp
            s = 0.0
            for c in range(9):
                s += B[r, c] * x9[c]
            Bx[r] = s
            for c in range(9):
                s = 0.0
                for q in range(9):
                    s += B[r, q] * A9[q, c]
                BA[r, c] = s
        for r in range(nd):
            for c in range(nd):
                s = Bx[r] * qv[c]
                for q in range(9):
                    s += BA[r, q] * B[c, q]
                Kl[r, c] += wd * s
    for a in range(nen):
        fe[3 * a] = fl[2 * a]
        fe[3 * a + 1] = fl[2 * a + 1]
    if want_K:
        for a in range(nen):
            for k in range(2):
                for b in range(nen):
                    for l in range(2):
                        Ke[3 * a + k, 3 * b + l] = Kl[2 * a + k, 2 * b + l]
    return flag


@njit(parallel=True, cache=True)
def planar_fbar_chunk(kind, params, form, nexp, volume, thick, X, u, conn, e0, N, dN, w, Nc, dNc, Pv, want_K, Ke,
                      fe, flags, hist_n, hist):
    """Element buffers Ke (nc, nd, nd), fe (nc, nd) and flags (nc,) of elements e0 .. e0 + nc - 1."""
    nc = fe.shape[0]
    nen = conn.shape[1]
    Kdummy = np.empty((0, 0))
    for c in prange(nc):
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        _gather(X, u, conn, e0 + c, Xe, ue)
        Kc = Ke[c] if want_K else Kdummy
        flags[c] = _fbar_planar_element(kind, params, form, nexp, volume, thick, Xe, ue, N, dN, w, Nc, dNc, Pv,
                                        want_K, Kc, fe[c], hist_n[e0 + c], hist[e0 + c])


@njit(cache=True)
def planar_fbar_gauss_fields(kind, params, form, nexp, volume, thick, X, u, conn, N, dN, w, Nc, dNc, Pv, mode, out,
                             hist_n):
    """Per-element quantities with F_bar: mode 0 strain energy int W(F_bar) dV; 1 minimum det J0 (axisymmetric:
    min(det J0, R)); 2 volume averages of sigma(F_bar) (with the out-of-plane or hoop component 33), S_bar and
    E_bar (Voigt); 3 the Cauchy stress sigma(F_bar) of every Gauss point g in out[e, 6 g: 6 g + 6]."""
    ne = conn.shape[0]
    nen = conn.shape[1]
    nd = 2 * nen
    ngp = w.size
    m = Pv.shape[1]
    for e in range(ne):
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        G = np.zeros((nen, 2))
        H = np.zeros((3, 3))
        F = np.zeros((3, 3))
        Fi = np.zeros((3, 3))
        Fb = np.zeros((3, 3))
        Hb = np.zeros((3, 3))
        B = np.zeros((nd, 9))
        gr = np.zeros(nd)
        Jz = np.empty(ngp)
        Gz = np.empty((ngp, nd))
        Mw = np.empty((max(m, 1), max(m, 1)))
        Hw = np.empty((max(m, 1), nd))
        S = np.empty(6)
        D = np.empty((6, 6))
        hscr = np.empty(hist_n.shape[2])
        row = np.empty(12)
        _gather(X, u, conn, e, Xe, ue)
        for r in range(out.shape[1]):
            out[e, r] = 0.0
        if mode == 1:
            out[e, 0] = np.inf
            for g in range(ngp):
                det, R = _geometry(Xe, ue, N[g], dN[g], form, G, H)
                out[e, 0] = min(out[e, 0], det)
                if form == AXISYMMETRIC:
                    out[e, 0] = min(out[e, 0], R)
            continue
        if _dilatation(Xe, ue, N, dN, w, Nc, dNc, Pv, volume, form, thick, G, H, F, Fi, B, gr, Jz, Gz, Mw, Hw) != 0:
            if mode == 0:
                out[e, 0] = np.inf
            continue
        vol = 0.0
        for g in range(ngp):
            wd0, J, R, pf = _point(Xe, ue, N[g], dN[g], form, thick, G, H, F, Fi, B, gr)
            if pf != 0:
                continue
            wd = w[g] * wd0
            vol += wd
            _barred(F, H, J, Jz[g], nexp, Fb, Hb)
            if mode == 0:
                out[e, 0] += wd * material_energy(kind, params, Fb)
                continue
            material_update_h(kind, params, Fb, Hb, hist_n[e, g], hscr, S, D)
            if mode == 3:
                for r in range(12):
                    row[r] = 0.0
                add_cauchy_pk2(Fb, S, 1.0, row)
                for r in range(6):
                    out[e, 6 * g + r] = row[r]
                continue
            add_cauchy_pk2(Fb, S, wd, out[e])
            for I in range(6):
                i = _PAIRS[I, 0]
                j = _PAIRS[I, 1]
                cmn = Hb[i, j] + Hb[j, i] + Hb[0, i] * Hb[0, j] + Hb[1, i] * Hb[1, j] + Hb[2, i] * Hb[2, j]
                out[e, 12 + I] += wd * 0.5 * cmn
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol


# ----------------------------------------------------------------------------------------------- body


class PlanarFbarBody(PlanarBody):
    """A total-Lagrangian F-bar planar body (module docstring): plane strain or axisymmetric, quad4 (the centre's
    volume change), quad8 and quad9 (J projected onto 1, xi, eta), tri6 (the element mean of J). Full integration.

    Args:
        cell_type: "quad4", "quad8", "quad9" or "tri6".
        X, cells, material, thickness: as :class:`covcontact.elements.planar.PlanarBody`.
        formulation: "plane_strain" or "axisymmetric".
    """

    symmetric_tangent = False

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 formulation: str = "plane_strain", thickness: float = 1.0, chunk_bytes: int = 32 * 2**20) -> None:
        if cell_type not in PLANAR_FBAR_CELLS:
            raise ValueError(f"planar F-bar elements are {', '.join(PLANAR_FBAR_CELLS)}, got cell type {cell_type!r}")
        if formulation not in ("plane_strain", "axisymmetric"):
            raise ValueError(f"planar F-bar is for plane_strain and axisymmetric bodies (plane stress has no volume "
                             f"constraint to relieve), got {formulation!r}")
        super().__init__(cell_type, X, cells, material, formulation, thickness, "full", chunk_bytes)
        self.nexp = 2 if formulation == "plane_strain" else 3
        if cell_type == "quad4":
            self.volume = 0
            self.Pv = np.zeros((self.weights.size, 0))
        elif cell_type == "tri6":
            self.volume = 1
            self.Pv = np.ones((self.weights.size, 1))
        else:
            self.volume = 1
            self.Pv = np.ascontiguousarray(np.column_stack([np.ones(self.weights.size), self.points]))
        centre = np.array([[1 / 3, 1 / 3]]) if cell_type == "tri6" else np.zeros((1, 2))
        Nc, dNc = planar_shapes(cell_type, centre)
        self.Nc = np.ascontiguousarray(Nc[0])
        self.dNc = np.ascontiguousarray(dNc[0])

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        hist = state["hist"]
        hist_n = state["hist_n"] if "hist_n" in state else hist.copy()
        planar_fbar_chunk(self.material.kind, self.material.params, self.form, self.nexp, self.volume,
                          self.thickness, self.X, u, self.cells, e0, self.N, self.dNdxi, self.weights, self.Nc,
                          self.dNc, self.Pv, want_K, Ke, fe, flags, hist_n, hist)

    def _gauss_fields(self, u, mode, out, state) -> None:
        planar_fbar_gauss_fields(self.material.kind, self.material.params, self.form, self.nexp, self.volume,
                                 self.thickness, self.X, u, self.cells, self.N, self.dNdxi, self.weights, self.Nc,
                                 self.dNc, self.Pv, mode, out, state["hist"])
