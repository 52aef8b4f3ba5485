"""Contact facets of tetrahedra and 20-node bricks: tri3, tri6 and quad8 faces as patches of quadrilaterals
(docs/theory.md, section 19).

The covariant geometry, the projection, the edge and vertex points and every tangent part are written for quad4
and quad9 facets. A face of another type is split, in its own parameter plane, into quadrilaterals whose nodes are
fixed points of the face (its nodes, or points at fixed parameters): each point is x_v = sum_a N_a(zeta_v) x_a, linear
in the face's nodes, and the patch interpolates the face exactly:

- tri3 -> three quad4 (vertex, edge midpoint, centroid, edge midpoint): an affine map of a bilinear one is bilinear;
- tri6 -> three quad9 on the same corners: a quadratic polynomial of a bilinear map is biquadratic;
- quad8 -> one quad9 whose centre is x_8 = sum_mid x_m / 2 - sum_corner x_c / 4: the serendipity space lies in the
  biquadratic one.

So the contact surface is the face itself (same points, normals and curvature), and residual and tangent of the
face's nodes follow from those of the patch nodes by the constant weights (R_a = sum_v N_a(zeta_v) R_v,
K_ab = sum_vw N_a(zeta_v) N_b(zeta_w) K_vw): the tangent stays exact. Patch points on a face's edge are shared with the
face across it (they depend on the edge's nodes alone), so the patches form one connected surface for the search,
the walks across edges and the edge and vertex points; the patches' inner edges are not creases (the face is
smooth across them).

The patch points that are not nodes are registered as virtual nodes (:class:`.points.VirtualPoints`, flagged as
master points): their positions follow the nodes, and element blocks are expanded onto the face nodes.
"""

from __future__ import annotations

import numpy as np

from ..fem.cells import FACE_BY_NODES, face_shapes
from ..fem.shapes import NODES, shape_functions

_TRI = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
_TRI_MID = 0.5 * (_TRI + np.roll(_TRI, -1, axis=0))  # midpoints of edges 0-1, 1-2, 2-0
_CENTROID = _TRI.mean(axis=0)
_QUAD = NODES["quad4"].astype(float)

#: corners of each sub-quadrilateral in the face's parameters (counter-clockwise, as the face)
_CORNERS = {
    "tri": np.array([[_TRI[i], _TRI_MID[i], _CENTROID, _TRI_MID[i - 1]] for i in range(3)]),
    "quad8": _QUAD[None],
}


def patch_count(nen: int) -> int:
    """Quadrilaterals per facet of ``nen`` nodes (1 for quad4, quad9 and quad8; 3 for tri3 and tri6)."""
    return 3 if nen in (3, 6) else 1


def patch_nen(nen: int) -> int:
    """Nodes of the patch quadrilaterals of a facet of ``nen`` nodes: 4 for quad4 and tri3, else 9."""
    return 4 if nen in (3, 4) else 9


def _patch_parameters(nen: int) -> np.ndarray:
    """(nsub, 4|9, 2): the face parameters zeta_v of the patch nodes of each sub-quadrilateral of a tri3, tri6 or
    quad8 face (the bilinear map of the sub-quadrilateral's corners)."""
    corners = _CORNERS["quad8" if nen == 8 else "tri"]
    Nq = shape_functions("quad4", NODES["quad4" if patch_nen(nen) == 4 else "quad9"].astype(float))[0]
    return np.einsum("vc,scd->svd", Nq, corners)


def patch_weights(nen: int) -> np.ndarray:
    """(nsub, 4|9, nen): the weights N_a(zeta_v) of the patch nodes v of each sub-quadrilateral on the face's nodes."""
    ftype = FACE_BY_NODES[nen]
    if ftype in ("quad4", "quad9"):
        return np.eye(nen)[None]
    zeta = _patch_parameters(nen)
    T = face_shapes(ftype, zeta.reshape(-1, 2))[0].reshape(*zeta.shape[:2], nen)
    T[np.abs(T) < 1e-14] = 0.0
    return T


def _edges(ftype: str) -> tuple[np.ndarray, np.ndarray]:
    """(corner parameters, corner pairs of the edges) of a face type."""
    if ftype == "quad8":
        return _QUAD, np.array([[0, 1], [1, 2], [2, 3], [3, 0]])
    return _TRI, np.array([[0, 1], [1, 2], [2, 0]])


def _classify(nen: int) -> list[tuple]:
    """Per patch node (sub, v): ("node", a) a node of the face; ("edge", ca, cb, s) a point at fraction s of the edge
    from corner ca to cb; ("inner", zx, zy) an inner point at those parameters."""
    T, zeta = patch_weights(nen), _patch_parameters(nen)
    qn = T.shape[1]
    cp, edges = _edges(FACE_BY_NODES[nen])
    out = []
    for s in range(T.shape[0]):
        for v in range(qn):
            row, z = T[s, v], zeta[s, v]
            a = int(np.argmax(np.abs(row)))
            if abs(row[a] - 1.0) < 1e-12 and np.abs(np.delete(row, a)).max() < 1e-12:
                out.append(("node", a))
                continue
            for ca, cb in edges:
                d, r = cp[cb] - cp[ca], z - cp[ca]
                if abs(d[0] * r[1] - d[1] * r[0]) < 1e-12:
                    out.append(("edge", int(ca), int(cb), float(r @ d / (d @ d))))
                    break
            else:
                out.append(("inner", float(z[0]), float(z[1])))
    return out


def quad_patches(faces: np.ndarray, points) -> tuple[np.ndarray, np.ndarray]:
    """The facets ``faces`` (nf, nen) as quadrilaterals: (quads (nf nsub, 4|9) node ids, parent (nf nsub,) the facet of
    each). quad4 and quad9 facets come back unchanged; the patch points of other facets are registered in ``points``
    (a :class:`.points.VirtualPoints`) as master points, each once (an edge's points are shared by its two faces)."""
    faces = np.asarray(faces, dtype=np.int64)
    nf, nen = faces.shape
    if nen in (4, 9):
        return faces, np.arange(nf)
    T = patch_weights(nen)
    nsub, qn = T.shape[:2]
    kinds = _classify(nen)
    quads = np.empty((nf, nsub * qn), dtype=np.int64)
    keys, cols = [], []
    scale = float(1 << 30)
    for j, kind in enumerate(kinds):
        if kind[0] == "node":
            quads[:, j] = faces[:, kind[1]]
            continue
        if kind[0] == "edge":
            ga, gb, s = faces[:, kind[1]], faces[:, kind[2]], np.full(nf, kind[3])
            flip = ga > gb
            key = np.column_stack([np.minimum(ga, gb), np.maximum(ga, gb),
                                   np.rint(np.where(flip, 1.0 - s, s) * scale).astype(np.int64)])
        else:
            key = np.column_stack([-1 - np.arange(nf), np.full(nf, round(kind[1] * scale)),
                                   np.full(nf, round(kind[2] * scale))])
        keys.append(key)
        cols.append(j)
    key = np.vstack(keys)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    # the first occurrence of each point: column cols[k // nf] of facet k % nf
    col = np.asarray(cols)[first // nf]
    fac = first % nf
    Tf = T.reshape(nsub * qn, nen)[col]  # (nu, nen) weights of each unique point
    ids = points.add(faces[fac], Tf, master=True)
    for k, j in enumerate(cols):
        quads[:, j] = ids[inverse[k * nf:(k + 1) * nf]]
    return quads.reshape(nf * nsub, qn), np.repeat(np.arange(nf), nsub)


def patch_gauss_points(X: np.ndarray, faces: np.ndarray, order: int) -> tuple:
    """Gauss points of the facets ``faces`` (nf, nen), ``order`` per direction on each patch quadrilateral.

    Returns (N (nsub ng, nen) the face shape values of each point, weight (nf, nsub ng) the reference area w_g J_g of
    each point).
    """
    from ..fem.quadrature import gauss_quad

    faces = np.asarray(faces, dtype=np.int64)
    nen = faces.shape[1]
    T = patch_weights(nen)
    qn = T.shape[1]
    pts, w = gauss_quad(order)
    Nq, dNq, _ = shape_functions("quad4" if qn == 4 else "quad9", pts)
    N = np.einsum("gv,sva->sga", Nq, T).reshape(-1, nen)
    dN = np.einsum("gvd,sva->sgad", dNq, T).reshape(-1, nen, 2)
    t = np.einsum("pad,fai->fpdi", dN, X[faces])
    jac = np.linalg.norm(np.cross(t[:, :, 0], t[:, :, 1]), axis=2)
    return N, jac * np.tile(w, T.shape[0])[None, :]
