"""Parallel element loops of the solid-shell elements: assembly buffers and per-element fields.

The element mathematics is in :mod:`covcontact.elements.solidshell_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..materials.hyperelastic import material_energy
from .base import add_cauchy_pk2, block_range, gather
from .solid import _jacobian, _kinematics
from .solidshell_kernels import FLAG_INVERTED, FLAG_REFERENCE, _element, _local_solve, _prepare, _stretch


@njit(cache=True)
def _scratch(conn, dNp, w, eas_comp):
    """Per-block work arrays: Xe, ue (nen, 3) and the grouped work arrays of the element kernels."""
    nen = conn.shape[1]
    npt = dNp.shape[0]
    ng = w.size
    neas = eas_comp.size
    nd = 3 * nen
    ne = max(neas, 1)
    ws3 = (np.empty((npt, 3, 3)), np.empty((npt, 3, 3)), np.empty((npt, 3, 3)))
    ws4 = (np.empty((ng, 6, 6)), np.empty((ng, 6, 6)))
    ws2 = (np.empty((npt, 6)), np.empty((ng, 6)), np.empty((ng, 6)), np.empty((ng, 6)))
    wsg = (np.empty((ng, 6, ne)), np.empty(ng))
    wv = (np.empty((3, 3)), np.empty((3, 3)), np.empty((6, 6)), np.empty((3, 3)), np.empty(6), np.empty(ne),
          np.empty((ne, ne)), np.empty((ne, ne)), np.empty(ne), np.empty(ne), np.empty(ne), np.empty((6, nd)),
          np.empty((6, nd)), np.empty((6, nd)), np.empty((6, ne)), np.empty((nd, ne)),
          np.zeros(ne, dtype=np.int64))
    return np.empty((nen, 3)), np.empty((nen, 3)), ws3, ws4, ws2, wsg, wv


@njit(parallel=True, cache=True)
def solidshell_chunk(kind, params, X, u, conn, e0, alpha, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp,
                     eas_val, want_K, Ke, fe, flags, nblocks, hist_n, hist):
    """Element buffers Ke (nc, nd, nd), fe (nc, nd), flags (nc,) of elements e0 .. e0 + nc - 1.

    alpha (nelem, neas) holds the EAS parameters: read as the start of the local Newton, overwritten
    with the solution. hist_n, hist (nelem, ng, nh): committed (read) and trial (written) material
    history; they may be the same array (each element copies its committed values first); nh = 0 for
    hyperelastic materials.
    """
    nc = fe.shape[0]
    nblk = max(1, min(nblocks, nc))
    for t in prange(nblk):
        lo, hi = block_range(t, nc, nblk)
        Xe, ue, ws3, ws4, ws2, wsg, wv = _scratch(conn, dNp, w, eas_comp)
        hne = np.empty((w.size, hist.shape[2]))
        Kdummy = np.empty((0, 0))
        for c in range(lo, hi):
            e = e0 + c
            gather(X, u, conn, e, Xe, ue)
            Kc = Ke[c] if want_K else Kdummy
            flags[c] = _element(kind, params, Xe, ue, alpha[e], dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp,
                                eas_val, want_K, Kc, fe[c], ws3, ws4, ws2, wsg, wv, hist_n[e], hist[e], hne)


@njit(cache=True)
def solidshell_fields(kind, params, X, u, conn, alpha, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp, eas_val,
                      mode, out, hist_n):
    """Per-element quantities at the solved EAS parameters, with hist_n (ne, ng, nh) as the committed
    material history (read only; the trial goes to scratch).

    mode 0: out (ne, 1) strain energy int W(E) dV (inf if E is not admissible); mode 1: out (ne, 1)
    minimum det J0 over the centre and all evaluation points; mode 2: out (ne, 18) volume averages of
    Cauchy stress (pushed forward with the compatible F), S and the assumed strain E (Voigt); mode 3: out
    (ne, 7 ng) per Gauss point its Cauchy stress (6) and current volume det F w det J0 (shell resultants).
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    npt = dNp.shape[0]
    ng = w.size
    Xe, ue, ws3, ws4, ws2, wsg, wv = _scratch(conn, dNp, w, eas_comp)
    hne = np.empty((ng, hist_n.shape[2]))
    htr = np.empty((ng, hist_n.shape[2]))
    Gx = np.empty((nen, 3))
    Fc = np.empty((3, 3))
    row = np.zeros(12)
    Gp, gp, _sig = ws3
    Tg, D = ws4
    Ep, S, Et, Ec = ws2
    Gam, detg = wsg
    J0, Ji, T0, F, En, h, H, Hf, dal, _a0, _x, _Bn, _Bc, _DB, _DG, _Kua, piv = wv
    for e in range(ne):
        gather(X, u, conn, e, Xe, ue)
        for r in range(out.shape[1]):
            out[e, r] = 0.0
        if mode == 1:
            dmin = _jacobian(Xe, dNc, J0, Ji)
            for p in range(npt):
                dmin = min(dmin, _jacobian(Xe, dNp[p], J0, Ji))
            out[e, 0] = dmin
            continue
        flag = _prepare(Xe, ue, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp, eas_val, Gp, gp, Ep, Tg, Ec,
                        Gam, detg, J0, Ji, T0, En, F)
        for g in range(ng):
            for k in range(hne.shape[1]):
                hne[g, k] = hist_n[e, g, k]
        if flag != FLAG_REFERENCE:
            f2 = _local_solve(kind, params, w, Ec, Gam, detg, alpha[e], S, D, h, H, Hf, dal, Et, F,
                              hne, htr, piv)
            if f2 != 0:
                flag = f2
        if flag != 0 and (mode == 0 or flag != FLAG_INVERTED):
            if mode == 0:
                out[e, 0] = np.inf
            continue
        vol = 0.0
        for g in range(ng):
            wd = w[g] * detg[g]
            vol += wd
            if mode == 0:
                if _stretch(Et[g], F):
                    out[e, 0] += wd * material_energy(kind, params, F)
                else:
                    out[e, 0] = np.inf
                continue
            # Cauchy stress with the compatible F = I + sum_a u_a (x) dN_a/dX at the Gauss point
            _jacobian(Xe, dNp[g], J0, Ji)
            _kinematics(dNp[g], Ji, ue, Gx, Fc)
            if mode == 3:
                add_cauchy_pk2(Fc, S[g], 1.0, row)
                for I in range(6):
                    out[e, 7 * g + I] = row[I]
                    row[I] = 0.0
                    row[6 + I] = 0.0
                out[e, 7 * g + 6] = wd * np.linalg.det(Fc)
                continue
            add_cauchy_pk2(Fc, S[g], wd, out[e])
            for I in range(6):
                out[e, 12 + I] += wd * (Et[g, I] if I < 3 else 0.5 * Et[g, I])
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol
