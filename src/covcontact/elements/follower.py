"""Follower pressures: a pressure that acts on the current (deformed) faces, normal to them, as CalculiX and Abaqus
apply face pressures in geometrically nonlinear steps (docs/theory.md, "Follower pressures").

A face with nodes x_a and shape functions N_a(xi, eta) carries the nodal forces

    f_a = -p int N_a (x,xi  x  x,eta) dxi deta

(positive p pushes into the body: x,xi x x,eta is the outward normal times the area element of an outward-ordered
face). In the residual r = f_int - f_ext they enter as +p int N_a n da, and their tangent, the load stiffness,
follows from d(t1 x t2) = t1 x dt2 - t2 x dt1 with t1 = x,xi = N_b,xi x_b, t2 = x,eta:

    K_ab = p int N_a (N_b,eta [t1]x - N_b,xi [t2]x) dxi deta,   [a]x v = a x v.

It is not symmetric (it is on a closed surface or with the face's boundary held; Schweizerhof & Ramm 1984).
Planar bodies: an edge's normal is its tangent t = x,s turned clockwise, (t_y, -t_x), times the reference
thickness (plane strain and plane stress) or 2 pi r, r = N_b x_b the current radius (axisymmetric), so that

    K_ab = p int N_a w (c Q N_b,s + c' (Q t) (x) e_r N_b) ds,   Q = [[0, 1], [-1, 0]],

c = t or 2 pi r and c' = 0 or 2 pi. Everything is vectorised over the faces of a set (numpy); the blocks go into the
system as element blocks (``covcontact.elements.springs.add_blocks``).
"""

from __future__ import annotations

import numpy as np

from ..fem.cells import any_face


def _skew(a: np.ndarray) -> np.ndarray:
    """[a]x of the vectors a (..., 3): (..., 3, 3) with [a]x v = a x v."""
    S = np.zeros(a.shape + (3,))
    S[..., 0, 1], S[..., 0, 2] = -a[..., 2], a[..., 1]
    S[..., 1, 0], S[..., 1, 2] = a[..., 2], -a[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -a[..., 1], a[..., 0]
    return S


def face_blocks(x: np.ndarray, faces: np.ndarray, p: float, want_K: bool = True):
    """Residual blocks (nf, 3 nfn) and tangents (nf, 3 nfn, 3 nfn) or None of the pressure ``p`` on the current
    faces ``faces`` (node ids into the current positions ``x``; quad4, quad8, quad9, tri3, tri6)."""
    N, dN, w = any_face(faces.shape[1])
    xf = x[faces]  # (nf, nfn, 3)
    t1 = np.einsum("pa,fai->fpi", dN[:, :, 0], xf)
    t2 = np.einsum("pa,fai->fpi", dN[:, :, 1], xf)
    n = np.cross(t1, t2) * w[None, :, None]
    nf, nfn = faces.shape
    R = (p * np.einsum("pa,fpi->fai", N, n)).reshape(nf, 3 * nfn)
    if not want_K:
        return R, None
    pw = p * w
    A = np.einsum("p,pa,pb,fpij->faibj", pw, N, dN[:, :, 1], _skew(t1))
    A -= np.einsum("p,pa,pb,fpij->faibj", pw, N, dN[:, :, 0], _skew(t2))
    return R, A.reshape(nf, 3 * nfn, 3 * nfn)


def edge_blocks(x: np.ndarray, edges: np.ndarray, p: float, formulation: str, thickness: float,
                want_K: bool = True):
    """The same for the current edges of a planar body (2 or 3 nodes): per unit thickness times ``thickness``
    (plane strain, plane stress) or over the full circumference at the current radius (axisymmetric)."""
    from ..fem.planar_cells import line_shapes
    from ..fem.quadrature import gauss_1d

    ne, nfn = edges.shape
    s, w = gauss_1d(2 if nfn == 2 else 3)
    N, dN = line_shapes(nfn, s)
    xe = x[edges]
    tang = np.einsum("pa,eai->epi", dN, xe)
    Qt = np.stack([tang[..., 1], -tang[..., 0], np.zeros_like(tang[..., 0])], axis=2)  # (ne, np, 3)
    axisym = formulation == "axisymmetric"
    if axisym:
        c = 2.0 * np.pi * np.einsum("pa,ea->ep", N, xe[:, :, 0])
    else:
        c = np.full((ne, len(w)), float(thickness))
    R = (p * np.einsum("pa,ep,epi->eai", N, c * w[None, :], Qt)).reshape(ne, 3 * nfn)
    if not want_K:
        return R, None
    Q = np.zeros((3, 3))
    Q[0, 1], Q[1, 0] = 1.0, -1.0
    A = np.einsum("pa,ep,pb,ij->eaibj", N, p * c * w[None, :], dN, Q)
    if axisym:
        er = np.array([1.0, 0.0, 0.0])
        A += np.einsum("pa,p,pb,epi,j->eaibj", N, p * 2.0 * np.pi * w, N, Qt, er)
    return R, A.reshape(ne, 3 * nfn, 3 * nfn)


class FollowerSet:
    """The follower pressures of a problem on the global numbering of ``system``: ``blocks(x, values)`` gives the
    element blocks (connectivity, residual, tangent) of every such load at its current value (a dict load key ->
    pressure)."""

    def __init__(self, system, loads: dict):
        from ..assembly.system import is_planar

        self.items = []  # (key, global face nodes, planar formulation or "", thickness)
        for key, load in loads.items():
            body = system.bodies[load.body]
            faces = body.mesh.face_sets[load.set] + system.offset(load.body)
            form = body.formulation if is_planar(body) else ""
            self.items.append((key, np.ascontiguousarray(faces, dtype=np.int64), form,
                               float(body.options.get("thickness", 1.0)) if form else 1.0))

    def blocks(self, x: np.ndarray, values: dict, want_K: bool = True) -> list:
        out = []
        for key, faces, form, t in self.items:
            p = float(values.get(key, 0.0))
            if p == 0.0:
                continue
            R, K = edge_blocks(x, faces, p, form, t, want_K) if form else face_blocks(x, faces, p, want_K)
            out.append((faces, R, K))
        return out

    def force(self, x: np.ndarray, values: dict) -> np.ndarray:
        """The external forces (n_dofs,) the pressures exert at the positions x (minus their residual)."""
        f = np.zeros(x.size)
        for faces, R, _ in self.blocks(x, values, want_K=False):
            dofs = (3 * faces[:, :, None] + np.arange(3)).reshape(len(faces), -1)
            np.add.at(f, dofs.ravel(), -R.ravel())
        return f


def follower_set(stages, system) -> FollowerSet | None:
    """The FollowerSet of the follower pressures of a StagePlan, None without any."""
    return FollowerSet(system, stages.followers) if stages.followers else None
