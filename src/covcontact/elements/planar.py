"""Planar bodies: plane strain, plane stress and axisymmetric total-Lagrangian elements (docs/theory.md, "Planar
bodies").

The body lies in the x-y plane (axisymmetric: x the radius R, y the axis, as Abaqus and CalculiX). Cells: quad4,
quad8, quad9, tri3, tri6 (VTK node orders). Per Gauss point the in-plane block of F is I + grad u (2 x 2) and
the out-of-plane stretch F33 is

- plane strain: 1;
- axisymmetric: r / R = (X + u_x) / X, the hoop stretch (X the reference radius of the point);
- plane stress: the value for which S33 = 0, found by a local Newton iteration around the material's 3D point
  routine (``covcontact.materials.update.material_update_h``; elasticity and J2 plasticity), whose tangent is
  then condensed exactly, D_ab - D_a3 D_3b / D_33 (the material's algorithmic tangent at the converged F33, so
  that plasticity's return mapping from the committed history enters consistently).

Every material enters through its 3D routine with a 3 x 3 F whose out-of-plane shears are zero. The volume element is
t dA (plane, t the reference thickness) or 2 pi R dA (axisymmetric: the full circumference, so that internal and
reaction forces, nodal forces, pressures and body forces are totals over 360 degrees, as Abaqus and CalculiX give
an axisymmetric model's point forces).

Internal force per node a, component k in {x, y}: f_ak = int (P_kJ G_aJ + [k = x, axisymmetric] P_33 N_a / R) dV,
and its tangent the same with the first elasticity tensor A_kJlL = F_kI C_IJML F_lM + delta_kl S_JL. The nodes
keep three dofs in the system: the elements give zero z-components and the system holds every z-dof of a planar
body at zero (``covcontact.assembly.system.System.planar_dofs``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ..fem.planar_cells import (
    EDGES,
    PLANAR_CELLS,
    line_shapes,
    planar_rule,
    planar_shapes,
    reference_jacobians,
)
from ..fem.quadrature import gauss_1d
from ..materials.hyperelastic import VOIGT, Material, material_energy
from ..materials.hyperelastic import VOIGT_PAIRS as _PAIRS
from ..materials.update import material_update_h
from .base import ElementBody, add_cauchy_pk2

__all__ = ["AXISYMMETRIC", "EDGES", "FORMULATIONS", "PLANAR_CELLS", "PLANE_STRAIN", "PLANE_STRESS", "PlanarBody",
           "edge_load_vector", "planar_masses", "planar_rule", "planar_shapes"]

FORMULATIONS = ("plane_strain", "plane_stress", "axisymmetric")
PLANE_STRAIN, PLANE_STRESS, AXISYMMETRIC = 0, 1, 2

#: local Newton on F33 (plane stress): absolute tolerance on the update of F33 and iteration limit
PS_TOL = 1e-13
PS_MAXIT = 40


def _weight_factor(formulation: str, thickness: float, R: np.ndarray) -> np.ndarray:
    if formulation == "axisymmetric":
        return 2.0 * math.pi * R
    return np.full_like(R, float(thickness))


def planar_masses(cell_type: str, X: np.ndarray, cells: np.ndarray, density: float, formulation: str,
                  thickness: float = 1.0) -> np.ndarray:
    """Consistent scalar element mass matrices (ne, nen, nen): rho int N_a N_b dV0 with dV0 = t dA or 2 pi R dA."""
    pts, w = planar_rule(cell_type, "mass")
    N, dN = planar_shapes(cell_type, pts)
    Xe = X[cells][:, :, :2]
    J = np.einsum("eai,paj->epij", Xe, dN)
    det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    R = np.einsum("pa,ea->ep", N, Xe[:, :, 0])
    dV = det * w[None, :] * _weight_factor(formulation, thickness, R)
    return density * np.einsum("ep,pa,pb->eab", dV, N, N)


def edge_load_vector(X: np.ndarray, edges: np.ndarray, formulation: str, thickness: float = 1.0,
                     area_only: bool = False) -> np.ndarray:
    """Integral of N_a n ds times t (plane) or 2 pi R (axisymmetric) over reference edges, (nnode, 3); n = the edge
    tangent turned clockwise, (t_y, -t_x, 0) (outward for an outward-ordered edge), of the length of the tangent.
    A dead pressure p gives nodal forces -p times this. ``area_only``: the integral of N_a |n| ds times t or 2 pi R
    (the nodal areas, repeated in the 3 columns)."""
    nfn = edges.shape[1]
    s, w = gauss_1d(2 if nfn == 2 else 3)
    N, dN = line_shapes(nfn, s)
    xe = X[edges]  # (ne, nfn, 3)
    tang = np.einsum("pa,eai->epi", dN, xe)
    n = np.stack([tang[..., 1], -tang[..., 0], np.zeros_like(tang[..., 0])], axis=2)
    R = np.einsum("pa,ea->ep", N, xe[:, :, 0])
    n = n * (w[None, :] * _weight_factor(formulation, thickness, R))[..., None]
    if area_only:
        n = np.repeat(np.linalg.norm(n, axis=2, keepdims=True), 3, axis=2)
    fa = np.einsum("pa,epi->eai", N, n)
    out = np.zeros_like(X)
    np.add.at(out, edges.ravel(), fa.reshape(-1, 3))
    return out


# ----------------------------------------------------------------------------------------------- kernels


@njit(cache=True)
def _point_response(kind, params, form, F, H, hist_n, hist, S, D):
    """S and D of the material at F (in-plane block and, but for plane stress, F33 set by the caller); plane stress:
    F33 (and H33 = F33 - 1) such that S33 = 0 by Newton's method on H33, then D condensed (D_ab - D_a3 D_3b / D_33,
    row and column 3 zero). Returns the material's status, or 2 if the local iteration failed."""
    if form != PLANE_STRESS:
        return material_update_h(kind, params, F, H, hist_n, hist, S, D)
    h = 0.0
    done = False
    for _ in range(PS_MAXIT):
        H[2, 2] = h
        F[2, 2] = 1.0 + h
        status = material_update_h(kind, params, F, H, hist_n, hist, S, D)
        if status != 0:
            return status
        d33 = D[2, 2] * (1.0 + h)  # dS33/dH33 = D_33 dE33/dH33, E33 = H33 + H33^2 / 2
        if not (d33 > 0.0):
            return 2
        dh = -S[2] / d33
        if abs(dh) <= PS_TOL:
            done = True
            break
        while 1.0 + h + dh <= 0.0:
            dh *= 0.5
        h += dh
    if not done:
        return 2
    d33 = D[2, 2]
    for a in range(6):
        if a == 2:
            continue
        for b in range(6):
            if b != 2:
                D[a, b] -= D[a, 2] * D[2, b] / d33
    for a in range(6):
        D[a, 2] = 0.0
        D[2, a] = 0.0
    return 0


@njit(cache=True)
def _geometry(Xe, ue, Ng, dNg, form, G, H):
    """G = dN/dX (nen, 2), the displacement gradient H (3 x 3; H33 of plane strain and axisymmetry, zero for plane
    stress until the local iteration) and (det J0, R) at one point; det J0 <= 0 or R <= 0 (axisymmetric): the caller
    skips the point."""
    nen = Xe.shape[0]
    j00 = 0.0
    j01 = 0.0
    j10 = 0.0
    j11 = 0.0
    R = 0.0
    ur = 0.0
    for a in range(nen):
        j00 += Xe[a, 0] * dNg[a, 0]
        j01 += Xe[a, 0] * dNg[a, 1]
        j10 += Xe[a, 1] * dNg[a, 0]
        j11 += Xe[a, 1] * dNg[a, 1]
        R += Ng[a] * Xe[a, 0]
        ur += Ng[a] * ue[a, 0]
    det = j00 * j11 - j01 * j10
    for i in range(3):
        for j in range(3):
            H[i, j] = 0.0
    if not (det > 0.0) or (form == AXISYMMETRIC and not (R > 0.0)):
        return det, R
    r = 1.0 / det
    i00 = j11 * r
    i01 = -j01 * r
    i10 = -j10 * r
    i11 = j00 * r
    for a in range(nen):
        G[a, 0] = dNg[a, 0] * i00 + dNg[a, 1] * i10
        G[a, 1] = dNg[a, 0] * i01 + dNg[a, 1] * i11
    for i in range(2):
        for j in range(2):
            s = 0.0
            for a in range(nen):
                s += ue[a, i] * G[a, j]
            H[i, j] = s
    if form == AXISYMMETRIC:
        H[2, 2] = ur / R
    return det, R


@njit(cache=True)
def _planar_element(kind, params, form, thick, Xe, ue, N, dN, w, want_K, Ke, fe, hist_n, hist):
    """Internal force fe (3 nen,) and tangent Ke (3 nen, 3 nen) of one planar element (z rows and columns zero);
    returns 0, 1 if a material point failed (det F <= 0, no convergence), 2 if det J0 <= 0 or R <= 0."""
    nen = Xe.shape[0]
    nd = 2 * nen
    F = np.zeros((3, 3))
    H = np.zeros((3, 3))
    S = np.empty(6)
    D = np.empty((6, 6))
    G = np.zeros((nen, 2))
    B = np.zeros((nd, 9))
    Pv = np.empty(9)
    A9 = np.empty((9, 9))
    BA = np.empty((nd, 9))
    fl = np.zeros(nd)
    Kl = np.zeros((nd, nd))
    flag = 0
    for g in range(w.size):
        det, R = _geometry(Xe, ue, N[g], dN[g], form, G, H)
        if not (det > 0.0) or (form == AXISYMMETRIC and not (R > 0.0)):
            flag = 2
            continue
        wd = w[g] * det * (2.0 * math.pi * R if form == AXISYMMETRIC else thick)
        for i in range(3):
            for j in range(3):
                F[i, j] = H[i, j] + (1.0 if i == j else 0.0)
        if _point_response(kind, params, form, F, H, hist_n[g], hist[g], S, D) != 0 and flag == 0:
            flag = 1
        for r in range(nd):
            for c in range(9):
                B[r, c] = 0.0
        for a in range(nen):
            for k in range(2):
                for J in range(2):
                    B[2 * a + k, 3 * k + J] = G[a, J]
            if form == AXISYMMETRIC:
                B[2 * a, 8] = N[g, a] / R
        for k in range(3):
            for J in range(3):
                Pv[3 * k + J] = F[k, 0] * S[VOIGT[0, J]] + F[k, 1] * S[VOIGT[1, J]] + F[k, 2] * S[VOIGT[2, J]]
        for r in range(nd):
            s = 0.0
            for c in range(9):
                s += B[r, c] * Pv[c]
            fl[r] += wd * s
        if not want_K:
            continue
        for k in range(3):
            for J in range(3):
                for l in range(3):
                    for L in range(3):
                        s = S[VOIGT[J, L]] if k == l else 0.0
                        for i in range(3):
                            fki = F[k, i]
                            if fki == 0.0:
                                continue
                            for m in range(3):
                                s += fki * D[VOIGT[i, J], VOIGT[m, L]] * F[l, m]
                        A9[3 * k + J, 3 * l + L] = s
        for r in range(nd):
            for c in range(9):
                s = 0.0
                for q in range(9):
                    s += B[r, q] * A9[q, c]
                BA[r, c] = s
        for r in range(nd):
            for c in range(nd):
                s = 0.0
                for q in range(9):
                    s += BA[r, q] * B[c, q]
                Kl[r, c] += wd * s
    for a in range(nen):
        fe[3 * a] = fl[2 * a]
        fe[3 * a + 1] = fl[2 * a + 1]
        fe[3 * a + 2] = 0.0
    if want_K:
        for r in range(3 * nen):
            for c in range(3 * nen):
                Ke[r, c] = 0.0
        for a in range(nen):
            for k in range(2):
                for b in range(nen):
                    for l in range(2):
                        Ke[3 * a + k, 3 * b + l] = Kl[2 * a + k, 2 * b + l]
    return flag


@njit(cache=True)
def _gather(X, u, conn, e, Xe, ue):
    for a in range(conn.shape[1]):
        n = conn[e, a]
        for i in range(3):
            Xe[a, i] = X[n, i]
            ue[a, i] = u[n, i]


@njit(parallel=True, cache=True)
def planar_chunk(kind, params, form, thick, X, u, conn, e0, N, dN, w, want_K, Ke, fe, flags, hist_n, hist):
    """Element buffers Ke (nc, nd, nd), fe (nc, nd) and flags (nc,) of elements e0 .. e0 + nc - 1."""
    nc = fe.shape[0]
    nen = conn.shape[1]
    Kdummy = np.empty((0, 0))
    for c in prange(nc):
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        _gather(X, u, conn, e0 + c, Xe, ue)
        Kc = Ke[c] if want_K else Kdummy
        flags[c] = _planar_element(kind, params, form, thick, Xe, ue, N, dN, w, want_K, Kc, fe[c],
                                   hist_n[e0 + c], hist[e0 + c])


@njit(cache=True)
def planar_gauss_fields(kind, params, form, thick, X, u, conn, N, dN, w, mode, out, hist_n):
    """Per-element quantities: mode 0 strain energy int W dV; 1 minimum det J0 (axisymmetric: min(det J0, R)); 2
    volume averages of Cauchy stress (with the out-of-plane or hoop component 33), S and Green-Lagrange E (Voigt); 3
    the Cauchy stress of every Gauss point g in out[e, 6 g: 6 g + 6]."""
    ne = conn.shape[0]
    nen = conn.shape[1]
    for e in range(ne):
        Xe = np.empty((nen, 3))
        ue = np.empty((nen, 3))
        G = np.zeros((nen, 2))
        H = np.zeros((3, 3))
        F = np.zeros((3, 3))
        S = np.empty(6)
        D = np.empty((6, 6))
        hscr = np.empty(hist_n.shape[2])
        row = np.empty(12)
        _gather(X, u, conn, e, Xe, ue)
        for r in range(out.shape[1]):
            out[e, r] = 0.0
        if mode == 1:
            out[e, 0] = np.inf
        vol = 0.0
        for g in range(w.size):
            det, R = _geometry(Xe, ue, N[g], dN[g], form, G, H)
            if mode == 1:
                out[e, 0] = min(out[e, 0], det)
                if form == AXISYMMETRIC:
                    out[e, 0] = min(out[e, 0], R)
                continue
            if not (det > 0.0) or (form == AXISYMMETRIC and not (R > 0.0)):
                continue
            wd = w[g] * det * (2.0 * math.pi * R if form == AXISYMMETRIC else thick)
            vol += wd
            for i in range(3):
                for j in range(3):
                    F[i, j] = H[i, j] + (1.0 if i == j else 0.0)
            _point_response(kind, params, form, F, H, hist_n[e, g], hscr, S, D)
            if mode == 0:
                out[e, 0] += wd * material_energy(kind, params, F)
                continue
            if mode == 3:
                for r in range(12):
                    row[r] = 0.0
                add_cauchy_pk2(F, S, 1.0, row)
                for r in range(6):
                    out[e, 6 * g + r] = row[r]
                continue
            add_cauchy_pk2(F, S, wd, out[e])
            for I in range(6):
                i = _PAIRS[I, 0]
                j = _PAIRS[I, 1]
                cm = H[i, j] + H[j, i] + H[0, i] * H[0, j] + H[1, i] * H[1, j] + H[2, i] * H[2, j]
                out[e, 12 + I] += wd * 0.5 * cm
        if mode == 2 and vol > 0.0:
            for r in range(18):
                out[e, r] /= vol


# ----------------------------------------------------------------------------------------------- body


class PlanarBody(ElementBody):
    """A total-Lagrangian planar body of one cell type (module docstring).

    Args:
        cell_type: "quad4", "quad8", "quad9", "tri3" or "tri6".
        X: (nnode, 3) reference coordinates (z = 0; axisymmetric: x >= 0, the radius).
        cells: (nelem, nen) connectivity, counter-clockwise in the x-y plane.
        material: a :mod:`covcontact.materials` material.
        formulation: "plane_strain", "plane_stress" or "axisymmetric".
        thickness: the reference thickness of the two plane cases (ignored for axisymmetry).
        integration: "full", or "reduced" for quad8 (2 x 2 points).
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 formulation: str = "plane_strain", thickness: float = 1.0, integration: str = "full",
                 chunk_bytes: int = 32 * 2**20) -> None:
        if cell_type not in PLANAR_CELLS:
            raise ValueError(f"unknown planar cell type {cell_type!r}; known: {', '.join(PLANAR_CELLS)}")
        if formulation not in FORMULATIONS:
            raise ValueError(f"formulation must be one of {', '.join(FORMULATIONS)}, got {formulation!r}")
        if not float(thickness) > 0.0:
            raise ValueError(f"thickness must be positive, got {thickness!r}")
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        self.formulation = formulation
        self.form = FORMULATIONS.index(formulation)
        self.thickness = float(thickness)
        self.integration = integration
        self.points, self.weights = planar_rule(cell_type, integration)
        self.N, self.dNdxi = planar_shapes(cell_type, self.points)

    def new_state(self) -> dict[str, np.ndarray]:
        """Material history per Gauss point, ``hist`` (nelem, ngp, n_hist)."""
        return {"hist": np.zeros((self.n_elements, self.weights.size, getattr(self.material, "n_hist", 0)))}

    def gauss_volumes(self) -> np.ndarray:
        """(nelem, ngp) reference volume w_g det J0 times t or 2 pi R of every Gauss point."""
        if getattr(self, "_gauss_volumes", None) is None:
            det = reference_jacobians(self.cell_type, self.X, self.cells, self.points)
            R = np.einsum("pa,ea->ep", self.N, self.X[self.cells][:, :, 0])
            self._gauss_volumes = det * self.weights[None, :] * _weight_factor(self.formulation, self.thickness, R)
        return self._gauss_volumes

    def gauss_points(self) -> np.ndarray:
        """(nelem, ngp, 2) reference x-y coordinates of the Gauss points (axisymmetric: R, Z)."""
        return np.einsum("pa,eai->epi", self.N, self.X[self.cells][:, :, :2])

    def gauss_cauchy(self, u: np.ndarray, state: dict | None = None) -> np.ndarray:
        """(nelem, ngp, 6) Cauchy stress at every Gauss point (Voigt 11, 22, 33, 12, 23, 13; 33 the out-of-plane or
        hoop stress) at displacement u and history ``state`` (default: the reference state)."""
        return self._fields(u, 3, 6 * self.weights.size, state).reshape(self.n_elements, -1, 6)

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        hist = state["hist"]
        hist_n = state["hist_n"] if "hist_n" in state else hist.copy()
        planar_chunk(self.material.kind, self.material.params, self.form, self.thickness, self.X, u, self.cells, e0,
                     self.N, self.dNdxi, self.weights, want_K, Ke, fe, flags, hist_n, hist)

    def _gauss_fields(self, u, mode, out, state) -> None:
        planar_gauss_fields(self.material.kind, self.material.params, self.form, self.thickness, self.X, u,
                            self.cells, self.N, self.dNdxi, self.weights, mode, out, state["hist"])

