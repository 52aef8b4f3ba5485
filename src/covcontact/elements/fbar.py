"""F-bar hexahedra (hex8, hex27) for nearly incompressible and plastic solids, total Lagrangian.

hex27 (3 x 3 x 3 Gauss points) takes for J_c at each Gauss point the volume change J projected (L2 over the
element) onto the linear functions 1, xi, eta, zeta: the F-bar analogue of the Q2/P1 mixed element, four
volume constraints per element instead of 27. A single J_c per element would leave the quadratic conformal
displacement modes (u = 2 (b . x) x - |x|^2 b, whose strain is a pure dilatation linear in x) without
stiffness. hex27 has the spatial form only.

de Souza Neto, Peric, Dutko & Owen (1996), "Design of simple low order finite elements for large strain
analysis of nearly incompressible solids", Int. J. Solids Struct. 33, 3277-3296: at every Gauss point the
material sees the modified deformation gradient

    F_bar = phi F,   phi = (J_c / J)^(1/3),   J = det F,   J_c = det F_c,

F_c the deformation gradient at the element centre (xi = 0). F_bar has the isochoric part of the local F
and the volume change of the centre, so the 2 x 2 x 2 rule no longer imposes eight incompressibility
constraints per element but one. A homogeneous deformation gives F_bar = F (patch test), a rigid rotation
gives F_bar = R.

Two weak forms (``form``), both with S_bar = S(F_bar) from ``material_update`` (docs/theory.md, section
"F-bar hexahedra", has the derivation); g_a = F^-T G_a and g0_a = F_c^-T G_a(centre) are the spatial
gradients of the shape functions at the Gauss point and at the centre, tau_bar = F_bar S_bar F_bar^T:

- ``"spatial"`` (default): the weak form of the paper, int sigma_bar : grad_x eta dv over the current
  volume, pulled back to the reference configuration: f_a = int (J / J_c) tau_bar g_a dV
  = int phi^-1 F S_bar G_a dV. It passes the patch test on any mesh; it is not the gradient of a
  potential and its exact tangent is non-symmetric for every material.
- ``"variational"``: the virtual work of S_bar on the variation of E_bar = (F_bar^T F_bar - I)/2,
  f_a = int [tau_bar g_a + tr(tau_bar)/3 (g0_a - g_a)] dV. For a hyperelastic material this is the
  gradient of int W(F_bar) dV and the exact tangent is symmetric (non-symmetric only where D = dS/dE is).
  It passes the patch test only where int G_a dV = V G_a(centre) holds (parallelepipeds, meshes extruded
  from a planar quadrilateral mesh); on a generally distorted hexahedral mesh a homogeneous state leaves
  out-of-balance forces at interior nodes of the order of the pressure times the distortion.

The exact tangent (all F-bar terms, including the coupling to every node through F_c) is assembled as a
full element matrix; :attr:`FbarBody.symmetric_tangent` says whether it is symmetric (variational form
with a symmetric D).

Material history per Gauss point: ``new_state()`` returns {"hist": (nelem, 8, n_hist)}. ``_chunk`` reads the
committed history from ``state["hist_n"]`` when present (as :meth:`ElementBody.kernel_state` provides it)
and writes the trial into ``state["hist"]``; without ``hist_n`` the array ``hist`` is both (each point's
committed values are copied to a scratch array before the trial overwrites them).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..fem import cells as other_cells
from ..fem.quadrature import gauss_tensor
from ..fem.shapes import shape_functions
from ..materials.hyperelastic import VOIGT, Material, material_energy
from ..materials.hyperelastic import VOIGT_PAIRS as _PAIRS
from ..materials.update import material_update
from .base import ElementBody, add_cauchy_pk2, block_range, f_times_d, gather, inverse3
from .solid import _jacobian, _kinematics

__all__ = ["FBAR_CELLS", "FBAR_FORMS", "FbarBody", "fbar_chunk", "fbar_gauss_fields"]

#: the cell types with an F-bar form
FBAR_CELLS = ("hex8", "hex27", "hex20", "tet10")
#: weak forms by name -> kernel code
FBAR_FORMS = {"variational": 0, "spatial": 1}


# ----------------------------------------------------------------------------- compiled pieces


@njit(cache=True, inline="always")
def _spatial_gradients(Fi, G, g):
    """g_a = F^-T G_a, i.e. g[a, i] = sum_j Fi[j, i] G[a, j] (dN_a/dx)."""
    for a in range(G.shape[0]):
        for i in range(3):
            g[a, i] = Fi[0, i] * G[a, 0] + Fi[1, i] * G[a, 1] + Fi[2, i] * G[a, 2]


@njit(cache=True, inline="always")
def _centre(Xe, ue, dNc, J0, Ji, Gc, Fc, Fi, g0):
    """Deformation gradient at the element centre: returns (det J0, det F_c) and g0_a = F_c^-T G_a(centre)
    (only when both are positive)."""
    detc = _jacobian(Xe, dNc, J0, Ji)
    if not (detc > 0.0):
        return detc, 0.0
    _kinematics(dNc, Ji, ue, Gc, Fc)
    Jc = inverse3(Fc, Fi)
    if Jc > 0.0:
        _spatial_gradients(Fi, Gc, g0)
    return detc, Jc


@njit(cache=True)
def _projected_dilatation(Xe, ue, dNdxi, w, Pv, J0, Ji, G, F, Fi, g, Jb, G0, Mw, Hw):
    """The volume change J projected onto the linear functions P = (1, xi, eta, zeta) of the element (L2 over
    the reference volume): Jb[gp] = P(gp) . c with M c = int P J dV0, M = int P P^T dV0, and its gradients
    G0[gp, a] (d ln Jb[gp] = G0[gp, a] . du_a). Mw (4, 4) and Hw (4, nen, 3) are scratch.
    Returns (smallest det J0, smallest Jb); the latter 0 when det F <= 0 at a point."""
    nen = Xe.shape[0]
    m = Pv.shape[1]
    dmin = np.inf
    for i in range(m):
        for j in range(m):
            Mw[i, j] = 0.0
        for a in range(nen):
            for k in range(3):
                Hw[i, a, k] = 0.0
    c = np.zeros(m)
    for gp in range(w.size):
        det = _jacobian(Xe, dNdxi[gp], J0, Ji)
        dmin = min(dmin, det)
        if not (det > 0.0):
            return det, 0.0
        _kinematics(dNdxi[gp], Ji, ue, G, F)
        J = inverse3(F, Fi)
        if not (J > 0.0):
            return dmin, 0.0
        _spatial_gradients(Fi, G, g)
        wd = w[gp] * det
        for i in range(m):
            c[i] += wd * Pv[gp, i] * J
            for j in range(m):
                Mw[i, j] += wd * Pv[gp, i] * Pv[gp, j]
            for a in range(nen):
                for k in range(3):
                    Hw[i, a, k] += wd * Pv[gp, i] * J * g[a, k]
    Minv = np.linalg.inv(Mw)
    jmin = np.inf
    for gp in range(w.size):
        # row r = P(gp)^T M^-1
        r = np.zeros(m)
        for i in range(m):
            for j in range(m):
                r[j] += Pv[gp, i] * Minv[i, j]
        jb = 0.0
        for j in range(m):
            jb += r[j] * c[j]
        Jb[gp] = jb
        jmin = min(jmin, jb)
        if not (jb > 0.0):
            continue
        for a in range(nen):
            for k in range(3):
                t = 0.0
                for j in range(m):
                    t += r[j] * Hw[j, a, k]
                G0[gp, a, k] = t / jb
    return dmin, jmin


@njit(cache=True)
def _fbar_element(kind, params, form, volume, Xe, ue, dNdxi, dNc, w, Pv, want_K, Ke, fe, hist_n, hist, hn,
                  J0, Ji, Fi, G, Gc, g, g0, q, F, Fc, Fb, S, D, FS, T, A, Q, x, y, Jb, G0, Mw, Hw):
    """Internal force fe (24,) and exact tangent Ke (24, 24) of one F-bar hex8 (both overwritten).

    hist_n (ngp, nh) committed history (read), hist (ngp, nh) trial (written); hn (nh,) scratch.
    Returns 0, 1 if det F <= 0 at the centre or at a Gauss point or the material failed, 2 if det J0 <= 0
    (such points are skipped; at the centre the whole element is). ``volume``: 0 the volume change of the
    centre (J_c), 1 J projected onto the linear functions Pv (ngp, 4) of the element (hex27; spatial form
    only; Jb (ngp,), G0 (ngp, nen, 3), Mw, Hw scratch).
    """
    nen = Xe.shape[0]
    nd = 3 * nen
    nh = hn.shape[0]
    for r in range(nd):
        fe[r] = 0.0
    if want_K:
        for r in range(nd):
            for s in range(nd):
                Ke[r, s] = 0.0
    if volume == 0:
        detc, Jc = _centre(Xe, ue, dNc, J0, Ji, Gc, Fc, Fi, g0)
    else:
        detc, Jc = _projected_dilatation(Xe, ue, dNdxi, w, Pv, J0, Ji, G, F, Fi, g, Jb, G0, Mw, Hw)
    if not (detc > 0.0 and Jc > 0.0):
        for gp in range(w.size):
            for k in range(nh):
                hist[gp, k] = hist_n[gp, k]
        return 2 if not (detc > 0.0) else 1
    flag = 0
    for gp in range(w.size):
        dNg = dNdxi[gp]
        det = _jacobian(Xe, dNg, J0, Ji)
        J = 0.0
        if not (det > 0.0):
            flag = 2
        else:
            _kinematics(dNg, Ji, ue, G, F)
            J = inverse3(F, Fi)
            if not (J > 0.0) and flag == 0:
                flag = 1
        if not (det > 0.0 and J > 0.0):
            for k in range(nh):
                hist[gp, k] = hist_n[gp, k]
            continue
        _spatial_gradients(Fi, G, g)
        gz = g0 if volume == 0 else G0[gp]
        Jz = Jc if volume == 0 else Jb[gp]
        for a in range(nen):
            for i in range(3):
                q[a, i] = (gz[a, i] - g[a, i]) / 3.0
        phi = (Jz / J) ** (1.0 / 3.0)
        for i in range(3):
            for j in range(3):
                Fb[i, j] = phi * F[i, j]
        for k in range(nh):
            hn[k] = hist_n[gp, k]
        if material_update(kind, params, Fb, hn, hist[gp], S, D) != 0 and flag == 0:
            flag = 1
        wd = w[gp] * det
        # FS = F S_bar; f_a += sc FS G_a (+ p q_a), sc = wd phi^2 (variational) or wd / phi (spatial)
        sc = wd * phi * phi if form == 0 else wd / phi
        for k in range(3):
            for j in range(3):
                FS[k, j] = F[k, 0] * S[VOIGT[0, j]] + F[k, 1] * S[VOIGT[1, j]] + F[k, 2] * S[VOIGT[2, j]]
        p = 0.0  # tr(tau_bar) wd (variational form)
        if form == 0:
            for k in range(3):
                for j in range(3):
                    p += sc * FS[k, j] * F[k, j]
        for a in range(nen):
            for k in range(3):
                t = sc * (FS[k, 0] * G[a, 0] + FS[k, 1] * G[a, 1] + FS[k, 2] * G[a, 2])
                fe[3 * a + k] += t + p * q[a, k]
                x[a, k] = t  # t_a, used below by the variational form
        if not want_K:
            continue
        f_times_d(F, D, T)  # T[k, j, m, n] = sum_i F_ki C_ijmn
        # A[k, j, l, n] = c1 sum_m T_kjmn F_lm + c2 delta_kl S_jn
        if form == 0:
            c1 = wd * phi * phi * phi * phi
            c2 = wd * phi * phi
        else:
            c1 = wd * phi
            c2 = wd / phi
        for k in range(3):
            for j in range(3):
                for l in range(3):
                    for n in range(3):
                        v = c1 * (T[k, j, 0, n] * F[l, 0] + T[k, j, 1, n] * F[l, 1] + T[k, j, 2, n] * F[l, 2])
                        if k == l:
                            v += c2 * S[VOIGT[j, n]]
                        A[k, j, l, n] = v
        # rank-one F-bar terms:
        # Ke[ak, bl] += x_ak q_bl + q_ak y_bl + cq q_ak q_bl - pg (g0_bk g0_al - g_bk g_al)
        cq = 0.0
        pg = 0.0
        if form == 0:
            # x_a = G_a . (A : F) + t_a, y_b = (F : A) . G_b + t_b, cq = F : A : F + p, pg = p / 3
            for k in range(3):
                for j in range(3):
                    r1 = 0.0
                    r2 = 0.0
                    for l in range(3):
                        for n in range(3):
                            r1 += A[k, j, l, n] * F[l, n]
                            r2 += F[l, n] * A[l, n, k, j]
                    Q[0, k, j] = r1  # (A : F)_kj
                    Q[1, k, j] = r2  # (F : A)_kj
                    cq += F[k, j] * r1
            cq += p
            pg = p / 3.0
            for a in range(nen):
                for k in range(3):
                    t = x[a, k]
                    x[a, k] = t + G[a, 0] * Q[0, k, 0] + G[a, 1] * Q[0, k, 1] + G[a, 2] * Q[0, k, 2]
                    y[a, k] = t + G[a, 0] * Q[1, k, 0] + G[a, 1] * Q[1, k, 1] + G[a, 2] * Q[1, k, 2]
        else:
            # x_ak = sum_j G_aj (wd phi (T : C)_kj - wd / phi (F S)_kj), C = F^T F; y = 0
            for k in range(3):
                for j in range(3):
                    tc = 0.0
                    for m in range(3):
                        for n in range(3):
                            cmn = F[0, m] * F[0, n] + F[1, m] * F[1, n] + F[2, m] * F[2, n]
                            tc += T[k, j, m, n] * cmn
                    Q[0, k, j] = wd * phi * tc - sc * FS[k, j]
            for a in range(nen):
                for k in range(3):
                    x[a, k] = G[a, 0] * Q[0, k, 0] + G[a, 1] * Q[0, k, 1] + G[a, 2] * Q[0, k, 2]
                    y[a, k] = 0.0
        for a in range(nen):
            # Q[k, l, n] = sum_j G_aj A_kjln
            for k in range(3):
                for l in range(3):
                    for n in range(3):
                        Q[k, l, n] = (G[a, 0] * A[k, 0, l, n] + G[a, 1] * A[k, 1, l, n]
                                      + G[a, 2] * A[k, 2, l, n])
            for b in range(nen):
                Gb0 = G[b, 0]
                Gb1 = G[b, 1]
                Gb2 = G[b, 2]
                for k in range(3):
                    for l in range(3):
                        v = Q[k, l, 0] * Gb0 + Q[k, l, 1] * Gb1 + Q[k, l, 2] * Gb2
                        v += x[a, k] * q[b, l] + q[a, k] * y[b, l] + cq * q[a, k] * q[b, l]
                        if form == 0:
                            v -= pg * (g0[b, k] * g0[a, l] - g[b, k] * g[a, l])
                        Ke[3 * a + k, 3 * b + l] += v
    return flag


@njit(cache=True)
def _projection_work(ngp, nen, m):
    """Scratch of the projected volume change: Jb (ngp,), G0 (ngp, nen, 3), Mw (m, m), Hw (m, nen, 3)."""
    return np.empty(ngp), np.empty((ngp, nen, 3)), np.empty((m, m)), np.empty((m, nen, 3))


@njit(cache=True)
def _work(nen, nh):
    """Per-block scratch arrays of the F-bar kernels."""
    return (np.empty(nh), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty((nen, 3)),
            np.empty((nen, 3)), np.empty((nen, 3)), np.empty((nen, 3)), np.empty((nen, 3)), np.empty((3, 3)),
            np.empty((3, 3)), np.empty((3, 3)), np.empty(6), np.empty((6, 6)))


@njit(parallel=True, cache=True)
def fbar_chunk(kind, params, form, volume, X, u, conn, e0, dNdxi, dNc, w, Pv, want_K, Ke, fe, flags, nblocks,
               hist_n, hist):
    """Element buffers Ke (nc, 24, 24), fe (nc, 24) and flags (nc,) of elements e0 .. e0 + nc - 1.

    The chunk is split into ``nblocks`` contiguous blocks (the parallel iterations), each with its own
    scratch arrays. hist_n, hist (nelem, ngp, nh): committed and trial material history (may be the same
    array: each point's committed values are copied before the update).
    """
    nc = fe.shape[0]
    nen = conn.shape[1]
    nblk = max(1, min(nblocks, nc))
    for t in prange(nblk):
        lo, hi = block_range(t, nc, nblk)
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        hn, J0, Ji, Fi, G, Gc, g, g0, q, F, Fc, Fb, S, D = _work(nen, hist.shape[2])
        FS = np.empty((3, 3))
        T = np.empty((3, 3, 3, 3))
        A = np.empty((3, 3, 3, 3))
        Q = np.empty((3, 3, 3))
        x = np.empty((nen, 3))
        y = np.empty((nen, 3))
        Kdummy = np.empty((0, 0))
        Jb, G0, Mw, Hw = _projection_work(w.size, nen, Pv.shape[1])
        for c in range(lo, hi):
            gather(X, u, conn, e0 + c, Xe, ue)
            Kc = Ke[c] if want_K else Kdummy
            flags[c] = _fbar_element(kind, params, form, volume, Xe, ue, dNdxi, dNc, w, Pv, want_K, Kc, fe[c],
                                     hist_n[e0 + c], hist[e0 + c], hn, J0, Ji, Fi, G, Gc, g, g0, q, F, Fc, Fb,
                                     S, D, FS, T, A, Q, x, y, Jb, G0, Mw, Hw)


@njit(cache=True)
def fbar_gauss_fields(kind, params, volume, X, u, conn, dNdxi, dNc, w, Pv, mode, out, hist_n):
    """Per-element Gauss-point quantities of F-bar hex8 (serial: see ``ElementBody._gauss_fields``).

    mode 0: out (ne, 1) strain energy int W(F_bar) dV (inf where det F or det F_c <= 0);
    mode 1: out (ne, 1) minimum det J0 over the Gauss points and the centre;
    mode 2: out (ne, 18) volume averages of the Cauchy stress sigma(F_bar), S(F_bar) and
    E_bar = (F_bar^T F_bar - I) / 2 (Voigt), with hist_n (ne, ngp, nh) as the committed history.
    """
    ne = conn.shape[0]
    nen = conn.shape[1]
    Xe = np.empty((nen, 3))
    ue = np.empty((nen, 3))
    hn, J0, Ji, Fi, G, Gc, g, g0, q, F, Fc, Fb, S, D = _work(nen, hist_n.shape[2])
    hscr = np.empty(hist_n.shape[2])
    Jb, G0, Mw, Hw = _projection_work(w.size, nen, Pv.shape[1])
    for e in range(ne):
        gather(X, u, conn, e, Xe, ue)
        for r in range(out.shape[1]):
            out[e, r] = 0.0
        detc, Jc = _centre(Xe, ue, dNc, J0, Ji, Gc, Fc, Fi, g0)
        if mode == 1:
            out[e, 0] = detc
            for gp in range(w.size):
                out[e, 0] = min(out[e, 0], _jacobian(Xe, dNdxi[gp], J0, Ji))
            continue
        if not (detc > 0.0):
            continue
        if volume != 0:
            detc, Jc = _projected_dilatation(Xe, ue, dNdxi, w, Pv, J0, Ji, G, F, Fi, g, Jb, G0, Mw, Hw)
            if not (detc > 0.0):
                continue
        vol = 0.0
        for gp in range(w.size):
            det = _jacobian(Xe, dNdxi[gp], J0, Ji)
            if not (det > 0.0):
                continue
            _kinematics(dNdxi[gp], Ji, ue, G, F)
            wd = w[gp] * det
            vol += wd
            J = inverse3(F, Fi)
            if not (J > 0.0 and Jc > 0.0):
                if mode == 0:
                    out[e, 0] = np.inf
                continue
            phi = ((Jc if volume == 0 else Jb[gp]) / J) ** (1.0 / 3.0)
            for i in range(3):
                for j in range(3):
                    Fb[i, j] = phi * F[i, j]
            if mode == 0:
                out[e, 0] += wd * material_energy(kind, params, Fb)
                continue
            for k in range(hn.shape[0]):
                hn[k] = hist_n[e, gp, k]
            material_update(kind, params, Fb, hn, hscr, S, D)
            add_cauchy_pk2(Fb, S, wd, out[e])
            for I in range(6):
                i = _PAIRS[I, 0]
                j = _PAIRS[I, 1]
                c = Fb[0, i] * Fb[0, j] + Fb[1, i] * Fb[1, j] + Fb[2, i] * Fb[2, j]
                out[e, 12 + I] += wd * 0.5 * (c - (1.0 if i == j else 0.0))
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol


# ----------------------------------------------------------------------------- body


class FbarBody(ElementBody):
    """A total-Lagrangian F-bar hex8 body (2 x 2 x 2 Gauss points, F_bar from the centre's volume change).

    Args:
        cell_type: "hex8" (the only cell type; the argument keeps the signature of the other bodies).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, 8) connectivity (local node ids).
        material: a :mod:`covcontact.materials` material; its ``n_hist`` (0 if absent) is the history length
            per Gauss point.
        form: "spatial" (default): the weak form of de Souza Neto et al. (1996), int sigma(F_bar) : grad_x eta
            dv; passes the patch test on any mesh, non-symmetric tangent. "variational": the virtual work of
            S(F_bar) on the variation of E(F_bar), the gradient of int W(F_bar) dV for hyperelastic materials
            with a symmetric tangent, but the patch test holds only on parallelepiped or extruded meshes.
        chunk_bytes: size of the per-chunk element tangent buffer.

    State: ``new_state()`` = {"hist": zeros((nelem, 8, n_hist))}. An assembly reads the committed history from
    ``state["hist_n"]`` if given (read only), else from ``state["hist"]``, and writes the trial into
    ``state["hist"]``. :meth:`energy` is int W(F_bar) dV (the potential of the residual only for the
    variational form); :meth:`stress` averages sigma(F_bar), S(F_bar) and E(F_bar) over each element.
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 form: str = "spatial", chunk_bytes: int = 32 * 2**20) -> None:
        if cell_type not in FBAR_CELLS:
            raise ValueError(f"F-bar elements are {', '.join(FBAR_CELLS)}, got cell type {cell_type!r}")
        if form not in FBAR_FORMS:
            raise ValueError(f"unknown F-bar form {form!r}; known: {', '.join(FBAR_FORMS)}")
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        self.form = form
        if cell_type in other_cells.CELLS:
            self.points, self.weights = other_cells.rule(cell_type)
            self.dNdxi = np.ascontiguousarray(other_cells.shapes(cell_type, self.points)[1])
        else:
            n = 2 if cell_type == "hex8" else 3
            self.points, self.weights = gauss_tensor((n, n, n))
            self.dNdxi = np.ascontiguousarray(shape_functions(cell_type, self.points)[1])
        #: 0: the centre's volume change (hex8, the paper's element); 1: J projected (L2 over the element) onto
        #: the linear functions (1, xi, eta, zeta) (hex27 and hex20, the F-bar analogue of Q2/P1 and of C3D20H's
        #: linear pressure: a constant volume change per element would leave the quadratic conformal modes,
        #: whose dilatation is linear, without stiffness), or onto the constants (tet10, the mean dilatation:
        #: the analogue of the stable P2/P0 pair; its four points would make a linear projection the identity)
        self.volume = 0 if cell_type == "hex8" else 1
        if self.volume == 0:
            self.Pv = np.zeros((self.weights.size, 0))
        elif cell_type == "tet10":
            self.Pv = np.ones((self.weights.size, 1))
        else:
            self.Pv = np.ascontiguousarray(np.column_stack([np.ones(self.weights.size), self.points]))
        if self.volume != 0 and form != "spatial":
            raise ValueError(f"F-bar {cell_type} has the spatial form only (form = \"spatial\")")
        if cell_type in other_cells.CELLS:  # the centre: the reference tetrahedron's centroid, the cube's origin
            centre = np.full((1, 3), 0.25 if cell_type == "tet10" else 0.0)
            self.dNc = np.ascontiguousarray(other_cells.shapes(cell_type, centre)[1][0])
        else:
            self.dNc = np.ascontiguousarray(shape_functions(cell_type, np.zeros((1, 3)))[1][0])

    @property
    def n_hist(self) -> int:
        """Material history length per Gauss point."""
        return int(getattr(self.material, "n_hist", 0))

    @property
    def symmetric_tangent(self) -> bool:
        """Whether the element tangent is symmetric: the variational form with a material whose D = dS/dE
        is symmetric (hyperelastic, associative plasticity); never for the spatial form."""
        return self.form == "variational"

    def new_state(self) -> dict[str, np.ndarray]:
        """Material history per Gauss point, ``hist`` (nelem, 8, n_hist); n_hist = 0 for hyperelastic
        materials."""
        return {"hist": np.zeros((self.n_elements, self.weights.size, self.n_hist))}

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        # committed history: hist_n when the caller passes it (kernel_state), else hist itself (the kernel
        # copies each point's committed values before overwriting them with the trial)
        hist = state["hist"]
        hist_n = state.get("hist_n", hist)
        fbar_chunk(self.material.kind, self.material.params, FBAR_FORMS[self.form], self.volume, self.X, u,
                   self.cells, e0, self.dNdxi, self.dNc, self.weights, self.Pv, want_K, Ke, fe, flags, nblocks,
                   hist_n, hist)

    def _gauss_fields(self, u, mode, out, state) -> None:
        fbar_gauss_fields(self.material.kind, self.material.params, self.volume, self.X, u, self.cells, self.dNdxi,
                          self.dNc, self.weights, self.Pv, mode, out, state["hist"])

