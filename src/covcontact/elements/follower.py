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


def _rule(nfn: int, planar: bool):
    """(N, dN, weights) of a face (3D) or an edge (planar) of ``nfn`` nodes: the rules of the dead loads."""
    if not planar:
        return any_face(nfn)
    from ..fem.planar_cells import line_shapes
    from ..fem.quadrature import gauss_1d

    s, w = gauss_1d(2 if nfn == 2 else 3)
    N, dN = line_shapes(nfn, s)
    return N, dN, w


def point_factors(X: np.ndarray, faces: np.ndarray, profile, planar: bool = False,
                  weights: np.ndarray | None = None) -> np.ndarray | None:
    """The factor c + g . X_g of a pressure's ``profile`` (c, gx, gy, gz) at each integration point of the faces
    (or edges), X_g the point's reference position, times the interpolated nodal ``weights`` (nf, nfn) of faces that
    are pieces of larger ones (``Mesh.face_weights``); None without either (a uniform pressure)."""
    if profile is None and weights is None:
        return None
    N = _rule(faces.shape[1], planar)[0]
    out = 1.0
    if profile is not None:
        Xg = np.einsum("pa,fai->fpi", N, X[faces])
        out = float(profile[0]) + Xg @ np.asarray(profile[1:], dtype=float)
    if weights is not None:
        out = out * (weights @ N.T)
    return out


def face_blocks(x: np.ndarray, faces: np.ndarray, p: float, want_K: bool = True, factor: np.ndarray | None = None):
    """Residual blocks (nf, 3 nfn) and tangents (nf, 3 nfn, 3 nfn) or None of the pressure ``p`` (times ``factor``
    (nf, n_points) where it varies over the faces) on the current faces ``faces`` (node ids into the current
    positions ``x``; quad4, quad8, quad9, tri3, tri6)."""
    N, dN, w = any_face(faces.shape[1])
    xf = x[faces]  # (nf, nfn, 3)
    t1 = np.einsum("pa,fai->fpi", dN[:, :, 0], xf)
    t2 = np.einsum("pa,fai->fpi", dN[:, :, 1], xf)
    nf, nfn = faces.shape
    pw = p * np.broadcast_to(w[None, :] if factor is None else w[None, :] * factor, (nf, len(w)))
    R = np.einsum("pa,fp,fpi->fai", N, pw, np.cross(t1, t2)).reshape(nf, 3 * nfn)
    if not want_K:
        return R, None
    A = np.einsum("fp,pa,pb,fpij->faibj", pw, N, dN[:, :, 1], _skew(t1))
    A -= np.einsum("fp,pa,pb,fpij->faibj", pw, N, dN[:, :, 0], _skew(t2))
    return R, A.reshape(nf, 3 * nfn, 3 * nfn)


def edge_blocks(x: np.ndarray, edges: np.ndarray, p: float, formulation: str, thickness: float,
                want_K: bool = True, factor: np.ndarray | None = None):
    """The same for the current edges of a planar body (2 or 3 nodes): per unit thickness times ``thickness``
    (plane strain, plane stress) or over the full circumference at the current radius (axisymmetric)."""
    ne, nfn = edges.shape
    N, dN, w = _rule(nfn, True)
    if factor is not None:
        w = w[None, :] * factor
    xe = x[edges]
    tang = np.einsum("pa,eai->epi", dN, xe)
    Qt = np.stack([tang[..., 1], -tang[..., 0], np.zeros_like(tang[..., 0])], axis=2)  # (ne, np, 3)
    axisym = formulation == "axisymmetric"
    if axisym:
        c = 2.0 * np.pi * np.einsum("pa,ea->ep", N, xe[:, :, 0])
    else:
        c = np.full((ne, N.shape[0]), float(thickness))
    w = np.broadcast_to(w, c.shape)
    R = (p * np.einsum("pa,ep,epi->eai", N, c * w, Qt)).reshape(ne, 3 * nfn)
    if not want_K:
        return R, None
    Q = np.zeros((3, 3))
    Q[0, 1], Q[1, 0] = 1.0, -1.0
    A = np.einsum("pa,ep,pb,ij->eaibj", N, p * c * w, dN, Q)
    if axisym:
        er = np.array([1.0, 0.0, 0.0])
        A += np.einsum("pa,ep,pb,epi,j->eaibj", N, p * 2.0 * np.pi * w, N, Qt, er)
    return R, A.reshape(ne, 3 * nfn, 3 * nfn)


class FollowerSet:
    """The follower pressures of a problem on the global numbering of ``system``: ``blocks(x, values)`` gives the
    element blocks (connectivity, residual, tangent) of every such load at its current value (a dict load key ->
    pressure)."""

    def __init__(self, system, loads: dict):
        from .planar import FORMULATIONS

        self.items = []  # (key, global face nodes, planar formulation or "", thickness, point factors or None)
        for key, load in loads.items():
            body = system.bodies[load.body]
            local = body.mesh.face_sets[load.set]
            form = body.formulation if getattr(body, "formulation", "solid") in FORMULATIONS else ""
            factor = point_factors(body.mesh.points, local, getattr(load, "profile", None), bool(form),
                                   body.mesh.face_weights.get(load.set))
            self.items.append((key, np.ascontiguousarray(local + system.offset(load.body), dtype=np.int64), form,
                               float(body.options.get("thickness", 1.0)) if form else 1.0, factor))

    def blocks(self, x: np.ndarray, values: dict, want_K: bool = True) -> list:
        """One block per kind of face (or edge) and thickness: the loads' pressures folded into the point factors, so
        that a deck's hundreds of one-face pressures cost one call."""
        groups: dict = {}
        for key, faces, form, t, factor in self.items:
            p = float(values.get(key, 0.0))
            if p == 0.0:
                continue
            n_points = _rule(faces.shape[1], bool(form))[2].size
            f = p * (np.ones((faces.shape[0], n_points)) if factor is None else factor)
            groups.setdefault((form, t, faces.shape[1]), []).append((faces, f))
        out = []
        for (form, t, _), parts in groups.items():
            faces = np.concatenate([f for f, _ in parts]) if len(parts) > 1 else parts[0][0]
            factor = np.concatenate([c for _, c in parts]) if len(parts) > 1 else parts[0][1]
            R, K = (edge_blocks(x, faces, 1.0, form, t, want_K, factor) if form
                    else face_blocks(x, faces, 1.0, want_K, factor))
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
