"""Topology of a master surface made of mesh facets (quad4 or quad9).

A :class:`MeshSurface` holds the facets (global node ids, VTK order, corners counter-clockwise seen
from outside so that ``rho_1 x rho_2`` points out of the body) and the connectivity the contact
search and the projection driver need:

- edge adjacency: local edge ``e`` of a facet runs from corner ``e`` to corner ``(e + 1) % 4``
  (quad9: mid-node ``4 + e``); ``nbr_facet[f, e]`` is the facet across it and ``nbr_edge[f, e]`` that
  facet's local edge, both -1 on a boundary edge (and on a non-manifold edge shared by more than two
  facets, which the driver then treats as a boundary);
- node-to-facet incidence as CSR (``node_ptr``, ``node_facets``) over every facet node;
- ``node_on_boundary``: nodes of boundary (or non-manifold) edges.

Positions are not stored: they change every iteration and are passed to the functions that need them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from ..fem.cells import any_face
from ..fem.shapes import IDX, NODES, lagrange1d, shape_functions
from .geometry import bilinear_coefficients

#: element coordinates of the start of local edge e and its direction (edge parameter t in [-1, 1])
EDGE_START = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
EDGE_DIR = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])


@dataclass
class MeshSurface:
    """Facets of a master surface and their adjacency.

    Args:
        faces: (nf, 4) or (nf, 9) global node ids, outward ordered.
        n_nodes: number of global nodes (defaults to ``faces.max() + 1``).
    """

    faces: np.ndarray
    n_nodes: int = -1
    nbr_facet: np.ndarray = field(init=False, repr=False)
    nbr_edge: np.ndarray = field(init=False, repr=False)
    node_ptr: np.ndarray = field(init=False, repr=False)
    node_facets: np.ndarray = field(init=False, repr=False)
    node_on_boundary: np.ndarray = field(init=False, repr=False)
    n_nonmanifold: int = field(init=False, default=0)

    def __post_init__(self) -> None:
        faces = np.ascontiguousarray(self.faces, dtype=np.int64)
        if faces.ndim != 2 or faces.shape[1] not in (4, 9):
            raise ValueError(f"faces must be (nf, 4) or (nf, 9), got {faces.shape}")
        if faces.size and faces.min() < 0:
            raise ValueError("faces contain negative node ids")
        self.faces = faces
        if self.n_nodes < 0:
            self.n_nodes = int(faces.max()) + 1 if faces.size else 0
        elif faces.size and faces.max() >= self.n_nodes:
            raise ValueError("faces reference nodes beyond n_nodes")
        self._build_adjacency()
        self._build_incidence()

    @property
    def nen(self) -> int:
        """Nodes per facet (4 or 9)."""
        return int(self.faces.shape[1])

    @property
    def n_facets(self) -> int:
        return int(self.faces.shape[0])

    @property
    def cell_type(self) -> str:
        return "quad4" if self.nen == 4 else "quad9"

    @property
    def nodes(self) -> np.ndarray:
        """Sorted global ids of the nodes on the surface."""
        return np.flatnonzero(np.diff(self.node_ptr) > 0)

    def _build_adjacency(self) -> None:
        nf = self.faces.shape[0]
        c = self.faces[:, :4]
        a, b = c, np.roll(c, -1, axis=1)
        key = (np.minimum(a, b) * np.int64(self.n_nodes) + np.maximum(a, b)).ravel()
        order = np.argsort(key, kind="stable")
        sk = key[order]
        # runs of equal edge keys
        brk = np.flatnonzero(np.diff(sk) != 0) + 1
        starts = np.concatenate(([0], brk))
        lengths = np.diff(np.concatenate((starts, [sk.size])))
        nbr_facet = np.full(4 * nf, -1, dtype=np.int64)
        nbr_edge = np.full(4 * nf, -1, dtype=np.int64)
        s2 = starts[lengths == 2]
        i, j = order[s2], order[s2 + 1]
        nbr_facet[i], nbr_edge[i] = j // 4, j % 4
        nbr_facet[j], nbr_edge[j] = i // 4, i % 4
        self.nbr_facet = nbr_facet.reshape(nf, 4)
        self.nbr_edge = nbr_edge.reshape(nf, 4)
        self.n_nonmanifold = int(np.count_nonzero(lengths > 2))
        # boundary nodes: both corners (and the quad9 mid-node) of every unpaired edge
        bf, be = np.nonzero(self.nbr_facet < 0)
        on_b = np.zeros(self.n_nodes, dtype=np.bool_)
        on_b[self.faces[bf, be]] = True
        on_b[self.faces[bf, (be + 1) % 4]] = True
        if self.nen == 9:
            on_b[self.faces[bf, 4 + be]] = True
        self.node_on_boundary = on_b

    def _build_incidence(self) -> None:
        nen = self.faces.shape[1]
        flat = self.faces.ravel()
        order = np.argsort(flat, kind="stable")
        counts = np.bincount(flat, minlength=self.n_nodes)
        self.node_ptr = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
        self.node_facets = (order // nen).astype(np.int64)

    def facets_of_node(self, node: int) -> np.ndarray:
        """Facets that contain global node ``node``."""
        return self.node_facets[self.node_ptr[node] : self.node_ptr[node + 1]]

    def vertex_normals(self, x_nodes: np.ndarray) -> np.ndarray:
        """Outward unit normal per node: the average of the unit normals of its facets at that node.

        Returns (n_nodes, 3); zero rows for nodes not on the surface.
        """
        x = np.asarray(x_nodes, dtype=np.float64)
        _, dN, _ = shape_functions(self.cell_type, NODES[self.cell_type])
        xf = x[self.faces]  # (nf, nen, 3)
        t = np.einsum("pad,fai->fpdi", dN, xf)  # (nf, nen pts, 2, 3)
        n = np.cross(t[:, :, 0, :], t[:, :, 1, :])
        ln = np.linalg.norm(n, axis=2, keepdims=True)
        n = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)
        out = np.zeros((self.n_nodes, 3))
        for k in range(3):
            out[:, k] = np.bincount(self.faces.ravel(), n[:, :, k].ravel(), minlength=self.n_nodes)
        ln = np.linalg.norm(out, axis=1, keepdims=True)
        return np.divide(out, ln, out=np.zeros_like(out), where=ln > 0)


def tributary_area(x_nodes: np.ndarray, faces: np.ndarray, n_gauss: int | None = None) -> np.ndarray:
    """Per-node area of a surface: the integral of N_a over the facets around node a.

    Args:
        x_nodes: (n, 3) positions.
        faces: (nf, 4|9) global node ids (or the 3, 6, 8 of tri3, tri6, quad8 faces: slave nodes of other cells).
        n_gauss: Gauss points per direction (default 3 for quad4, 4 for quad9; the face rule of the others).

    Returns:
        (n,) areas; they sum to the surface area integrated with the same rule.
    """
    faces = np.asarray(faces, dtype=np.int64)
    x = np.asarray(x_nodes, dtype=np.float64)
    nen = faces.shape[1]
    N, dN, w = any_face(nen, n_gauss or (3 if nen == 4 else 4))
    xf = x[faces]
    t = np.einsum("pad,fai->fpdi", dN, xf)
    jac = np.linalg.norm(np.cross(t[:, :, 0, :], t[:, :, 1, :]), axis=2)  # (nf, npts)
    contrib = np.einsum("fp,p,pa->fa", jac, w, N)
    return np.bincount(faces.ravel(), contrib.ravel(), minlength=x.shape[0])


#: the share of a tri6 and a quad8 face's area that each of its nodes takes as a node-to-surface slave (CalculiX's
#: spring areas of node-to-face penalty contact): tri6 corners 0 and mid-nodes 1/3, the nodal forces of a uniform
#: pressure (so a uniform pressure crosses the contact uniformly); quad8 corners 1/100 and mid-nodes 24/100, where
#: those nodal forces (-1/12, 1/3) would pull at the corners
SLAVE_AREA_SHARES = {6: np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]) / 3.0,
                     8: np.array([1.0, 1.0, 1.0, 1.0, 24.0, 24.0, 24.0, 24.0]) / 100.0}


def slave_area(x_nodes: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Per-node area of the slave nodes of a surface (node-to-surface contact: the penalty per area and the contact
    pressure of a node take it); non-negative, summing to the surface's area.

    Faces of linear cells and quad9 faces: the integral of N_a over the faces around node a (``tributary_area``).
    tri6 and quad8 faces, whose corner shape functions integrate to zero (tri6) or to -1/12 of the face (quad8), so
    that a corner node would take no or a pulling force: each face's area (its own rule) shared out in the fixed
    proportions ``SLAVE_AREA_SHARES`` (CalculiX's): a tri6 corner node takes none (it carries no contact force, as in
    CalculiX; an area-weighted pass leaves such nodes out).

    Args:
        x_nodes: (n, 3) positions. faces: (nf, nen) node ids of one face type.

    Returns:
        (n,) areas (zero off the faces).
    """
    faces = np.asarray(faces, dtype=np.int64)
    nen = faces.shape[1]
    if nen not in SLAVE_AREA_SHARES:
        return tributary_area(x_nodes, faces)
    x = np.asarray(x_nodes, dtype=np.float64)
    _, dN, w = any_face(nen)
    t = np.einsum("pad,fai->fpdi", dN, x[faces])
    area = np.linalg.norm(np.cross(t[:, :, 0, :], t[:, :, 1, :]), axis=2) @ w  # (nf,)
    contrib = area[:, None] * SLAVE_AREA_SHARES[nen][None, :]
    return np.bincount(faces.ravel(), contrib.ravel(), minlength=x.shape[0])


# Lagrange (p(-1), p(0), p(1)) -> Bernstein control values of a 1D quadratic
_L2B = np.array([[1.0, 0.0, 0.0], [-0.5, 2.0, -0.5], [0.0, 0.0, 1.0]])
# quad9 node -> (i, j) position in a 3 x 3 grid ordered -1, 0, 1 per direction
_Q9_GRID = np.array([[0, 2, 1][k] for k in IDX["quad9"].ravel()]).reshape(9, 2)


@njit(cache=True, error_model="numpy", parallel=True)
def _boxes_kernel(x, faces, l2b, q9grid, lo, hi):
    nf, nen = faces.shape
    for f in prange(nf):
        if nen == 4:
            for p in range(3):
                a = x[faces[f, 0], p]
                b = a
                for k in range(1, 4):
                    v = x[faces[f, k], p]
                    a = min(a, v)
                    b = max(b, v)
                lo[f, p] = a
                hi[f, p] = b
        else:
            grid = np.empty((3, 3))
            tmp = np.empty((3, 3))
            for p in range(3):
                for k in range(9):
                    grid[q9grid[k, 0], q9grid[k, 1]] = x[faces[f, k], p]
                for i in range(3):  # control net = L2B grid L2B^T
                    for j in range(3):
                        tmp[i, j] = l2b[i, 0] * grid[0, j] + l2b[i, 1] * grid[1, j] + l2b[i, 2] * grid[2, j]
                a = np.inf
                b = -np.inf
                for i in range(3):
                    for j in range(3):
                        v = tmp[i, 0] * l2b[j, 0] + tmp[i, 1] * l2b[j, 1] + tmp[i, 2] * l2b[j, 2]
                        a = min(a, v)
                        b = max(b, v)
                lo[f, p] = a
                hi[f, p] = b


def facet_boxes(x_nodes: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Axis-aligned boxes that contain each facet (not only its nodes).

    A bilinear facet lies in the convex hull of its corners. A biquadratic facet lies in the convex
    hull of its Bernstein control net, computed here from the nine Lagrange nodes, so the box is a
    rigorous bound even where the surface bulges beyond its nodes.

    Returns:
        lo, hi: (nf, 3) each.
    """
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    x = np.ascontiguousarray(x_nodes, dtype=np.float64)
    lo = np.empty((faces.shape[0], 3))
    hi = np.empty((faces.shape[0], 3))
    if faces.shape[0]:
        _boxes_kernel(x, faces, _L2B, _Q9_GRID, lo, hi)
    return lo, hi


@njit(cache=True, error_model="numpy", parallel=True)
def _sizes_kernel(x, faces, out):
    for f in prange(faces.shape[0]):
        d1 = 0.0
        d2 = 0.0
        for p in range(3):
            d1 += (x[faces[f, 2], p] - x[faces[f, 0], p]) ** 2
            d2 += (x[faces[f, 3], p] - x[faces[f, 1], p]) ** 2
        out[f] = np.sqrt(max(d1, d2))


def facet_sizes(x_nodes: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Characteristic size per facet: the longer of its two corner diagonals (quadrilaterals), its longest edge
    (triangles: tri3, tri6)."""
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if faces.shape[1] in (3, 6):
        c = np.asarray(x_nodes)[faces[:, :3]]
        return np.linalg.norm(c - np.roll(c, -1, axis=1), axis=2).max(axis=1)
    out = np.empty(faces.shape[0])
    if faces.shape[0]:
        _sizes_kernel(np.ascontiguousarray(x_nodes, dtype=np.float64), faces, out)
    return out


# ---------------------------------------------------------------------------------------------
# compiled point helpers on one facet (used by the projection driver)

_IDX4 = IDX["quad4"]
_IDX9 = IDX["quad9"]


@njit(cache=True, error_model="numpy", inline="always")
def gather_facet(x, faces, f, xyz):
    """Copy the node positions of facet f into xyz (nen, 3)."""
    for a in range(faces.shape[1]):
        for p in range(3):
            xyz[a, p] = x[faces[f, a], p]


@njit(cache=True, error_model="numpy", inline="always")
def facet_frame_inline(xyz, xi1, xi2, rho, t1, t2, nrm):
    """``facet_frame`` for hot loops: a quad4 is evaluated in place from its corners (no call, so no reference
    counts for the arrays passed), other facets by a call to ``facet_frame``."""
    if xyz.shape[0] != 4:
        facet_frame(xyz, xi1, xi2, rho, t1, t2, nrm)
        return
    for p in range(3):
        a, b, c, d = bilinear_coefficients(xyz[0, p], xyz[1, p], xyz[2, p], xyz[3, p])
        t1[p] = b + d * xi2
        t2[p] = c + d * xi1
        rho[p] = a + b * xi1 + c * xi2 + d * xi1 * xi2
    _unit_normal(t1, t2, nrm)


@njit(cache=True, error_model="numpy", inline="always")
def _unit_normal(t1, t2, nrm):
    nrm[0] = t1[1] * t2[2] - t1[2] * t2[1]
    nrm[1] = t1[2] * t2[0] - t1[0] * t2[2]
    nrm[2] = t1[0] * t2[1] - t1[1] * t2[0]
    ln = np.sqrt(nrm[0] ** 2 + nrm[1] ** 2 + nrm[2] ** 2)
    for p in range(3):
        nrm[p] = nrm[p] / ln if ln > 0.0 else 0.0


@njit(cache=True, error_model="numpy")
def facet_frame(xyz, xi1, xi2, rho, t1, t2, nrm):
    """rho(xi), rho_1, rho_2 and the unit normal there (zero normal at a degenerate point)."""
    _frame_lagrange(xyz, xi1, xi2, rho, t1, t2)
    _unit_normal(t1, t2, nrm)


@njit(cache=True, error_model="numpy", inline="always")
def _frame_lagrange(xyz, xi1, xi2, rho, t1, t2):
    """rho, rho_1, rho_2 by the shape-function sums (any facet type)."""
    nen = xyz.shape[0]
    order = 1 if nen == 4 else 2
    for p in range(3):
        rho[p] = 0.0
        t1[p] = 0.0
        t2[p] = 0.0
    for a in range(nen):
        i = _IDX4[a, 0] if nen == 4 else _IDX9[a, 0]
        j = _IDX4[a, 1] if nen == 4 else _IDX9[a, 1]
        v1, d1, _ = lagrange1d(order, i, xi1)
        v2, d2, _ = lagrange1d(order, j, xi2)
        for p in range(3):
            rho[p] += v1 * v2 * xyz[a, p]
            t1[p] += d1 * v2 * xyz[a, p]
            t2[p] += v1 * d2 * xyz[a, p]


@njit(cache=True, error_model="numpy", inline="always")
def _edge_eval(xyz, e, t, r, r1, r2):
    """Point, first and second derivative of the curve of local edge e at parameter t."""
    a0 = e
    a1 = (e + 1) % 4
    if xyz.shape[0] == 4:
        for p in range(3):
            r[p] = 0.5 * (1.0 - t) * xyz[a0, p] + 0.5 * (1.0 + t) * xyz[a1, p]
            r1[p] = 0.5 * (xyz[a1, p] - xyz[a0, p])
            r2[p] = 0.0
    else:
        for p in range(3):
            x0 = xyz[a0, p]
            x1 = xyz[a1, p]
            xm = xyz[4 + e, p]
            r[p] = 0.5 * t * (t - 1.0) * x0 + 0.5 * t * (t + 1.0) * x1 + (1.0 - t * t) * xm
            r1[p] = (t - 0.5) * x0 + (t + 0.5) * x1 - 2.0 * t * xm
            r2[p] = x0 + x1 - 2.0 * xm


@njit(cache=True, error_model="numpy")
def edge_closest_point(xyz, e, xs, c):
    """Closest point c on the curve of local edge e of a facet, edge parameter t in [-1, 1].

    Local edge e runs from corner e (t = -1) to corner (e + 1) % 4 (t = +1), through mid-node 4 + e
    on a quad9. 1D Newton on (x_s - r(t)) . r'(t) = 0 from t = 0 (Gauss-Newton where the second
    derivative is not positive), clamped to [-1, 1], then compared with both ends.

    Returns:
        (t, squared distance); c (3,) out.
    """
    r = np.empty(3)
    r1 = np.empty(3)
    r2 = np.empty(3)
    t = 0.0
    for _ in range(30):
        _edge_eval(xyz, e, t, r, r1, r2)
        fp = 0.0
        aa = 0.0
        bb = 0.0
        for p in range(3):
            d = xs[p] - r[p]
            fp -= d * r1[p]
            aa += r1[p] * r1[p]
            bb += d * r2[p]
        if not (aa > 0.0):
            break
        fpp = aa - bb
        dt = -fp / fpp if fpp > 1e-12 * aa else -fp / aa
        if not np.isfinite(dt):
            break
        tn = min(max(t + min(max(dt, -1.0), 1.0), -1.0), 1.0)
        done = abs(tn - t) < 1e-13
        t = tn
        if done:
            break
    best_t = 0.0
    best_d2 = np.inf
    for k in range(3):
        tk = t if k == 0 else (-1.0 if k == 1 else 1.0)
        _edge_eval(xyz, e, tk, r, r1, r2)
        d2 = (xs[0] - r[0]) ** 2 + (xs[1] - r[1]) ** 2 + (xs[2] - r[2]) ** 2
        if d2 < best_d2:
            best_d2 = d2
            best_t = tk
            for p in range(3):
                c[p] = r[p]
    return best_t, best_d2
