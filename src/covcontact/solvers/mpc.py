"""Nonlinear multi-point constraints by exact elimination: ``[[mpc]]`` (a deck's *MPC PLANE, STRAIGHT, BEAM;
docs/theory.md, "Nonlinear multi-point constraints").

Each constraint is a function g(y) = 0 of the positions y of a few nodes (g scalar or a short vector) with one
dependent position component per equation, z, the rest w: g(w, z(w)) = 0 fixes z as a function of w, and z is
eliminated as a linear equation's dependent dof is (``covcontact.solvers.constraints``), only the map is nonlinear:

- ``"plane"``: nodes a, b, c and x; g = (b - a) . ((c - a) x (x - a)), x stays in the plane of a, b, c. Dependent:
  x's component along which the reference normal (a - c) x (b - c) is largest (CalculiX's planempc.f).
- ``"straight"``: nodes a, b and x; with d = b - a, r = x - a and k the component in which the reference d is
  largest, g_j = r_j d_k - r_k d_j for the two j != k: x stays on the line through a and b. Dependent: x_j.
- ``"beam"``: nodes a and b; g = |a - b|^2 - L0^2, their distance stays L0. Dependent: a's component in which the
  reference a - b is largest (CalculiX's beammpc.f).

With G_w, G_z the derivatives of g, Z = dz/dw = -G_z^-1 G_w. The residual of the independent dofs is P^T R (P the
map du = P dw: identity on the independent dofs, the rows Z at the dependent ones) and the tangent
P^T K P + sum_i mu_i E^T H_i E, with H_i the Hessian of g_i in y, E = dy/dw = [I; Z] and mu = -G_z^-T f, f the
residual at the dependent dofs (the second derivative of z(w) from differentiating g(w, z(w)) = 0 twice): symmetric.
The dependent dofs drop out (treated as constrained) and are set from the others before every evaluation
(``complete``: Newton on g for z, one exact step for the plane and the line, which are linear in z).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..assembly.system import InvertedElementError
from ..loads import KINDS, dependent_components
from .constraints import unit_diagonal

class UnsolvableConstraint(InvertedElementError):
    """A beam constraint with no solution at a trial displacement (the independent components alone already
    stretch the two nodes apart beyond their distance): like an inverted element, the correction is shortened."""

    def __init__(self, name: str):
        RuntimeError.__init__(self, f"the multi-point constraint {name} has no solution at this trial "
                                    f"displacement (the nodes' other components already exceed its length)")
        self.body, self.element = name, -1


def _skew(v: np.ndarray) -> np.ndarray:
    """[v]_x per row: (G, 3) -> (G, 3, 3), [v]_x w = v x w."""
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def _difference_map(n_nodes: int, pairs: list[tuple[int, int]]) -> np.ndarray:
    """L with L y = the stacked differences y_j - y_i for (i, j) in ``pairs`` (3 rows each)."""
    L = np.zeros((3 * len(pairs), 3 * n_nodes))
    eye = np.eye(3)
    for m, (i, j) in enumerate(pairs):
        L[3 * m: 3 * m + 3, 3 * i: 3 * i + 3] -= eye
        L[3 * m: 3 * m + 3, 3 * j: 3 * j + 3] += eye
    return L


_PLANE_L = _difference_map(4, [(0, 1), (0, 2), (0, 3)])    # p = b - a, q = c - a, r = x - a
_LINE_L = _difference_map(3, [(0, 1), (0, 2)])              # d = b - a, r = x - a


def plane_constraint(y: np.ndarray):
    """g, dg/dy, d2g/dy2 of the plane constraint for positions y (G, 12): shapes (G, 1), (G, 1, 12), (G, 1, 12, 12)."""
    p, q, r = y[:, 3:6] - y[:, 0:3], y[:, 6:9] - y[:, 0:3], y[:, 9:12] - y[:, 0:3]
    g = np.einsum("gi,gi->g", p, np.cross(q, r))
    grad = np.concatenate([np.cross(q, r), np.cross(r, p), np.cross(p, q)], axis=1) @ _PLANE_L
    H = np.zeros((y.shape[0], 9, 9))
    H[:, 0:3, 3:6], H[:, 3:6, 0:3] = -_skew(r), _skew(r)   # d2 (p . q x r) / dp dq = -[r]_x
    H[:, 3:6, 6:9], H[:, 6:9, 3:6] = -_skew(p), _skew(p)
    H[:, 6:9, 0:3], H[:, 0:3, 6:9] = -_skew(q), _skew(q)
    H = np.einsum("ai,gab,bj->gij", _PLANE_L, H, _PLANE_L)
    return g[:, None], grad[:, None, :], H[:, None]


def line_constraint(y: np.ndarray, k: np.ndarray):
    """The two line constraints g_j = r_j d_k - r_k d_j (j != k, ascending) for positions y (G, 9) and the base
    components k (G,): shapes (G, 2), (G, 2, 9), (G, 2, 9, 9)."""
    G = y.shape[0]
    d, r = y[:, 3:6] - y[:, 0:3], y[:, 6:9] - y[:, 0:3]
    rows = np.arange(G)
    js = np.stack([(k + 1) % 3, (k + 2) % 3], axis=1)
    js.sort(axis=1)
    g = np.zeros((G, 2))
    grad = np.zeros((G, 2, 6))
    H = np.zeros((G, 2, 6, 6))
    for m in range(2):
        j = js[:, m]
        g[:, m] = r[rows, j] * d[rows, k] - r[rows, k] * d[rows, j]
        grad[rows, m, k] += r[rows, j]
        grad[rows, m, j] -= r[rows, k]
        grad[rows, m, 3 + j] += d[rows, k]
        grad[rows, m, 3 + k] -= d[rows, j]
        H[rows, m, k, 3 + j] += 1.0
        H[rows, m, 3 + j, k] += 1.0
        H[rows, m, j, 3 + k] -= 1.0
        H[rows, m, 3 + k, j] -= 1.0
    return g, grad @ _LINE_L, np.einsum("ai,gmab,bj->gmij", _LINE_L, H, _LINE_L)


def beam_constraint(y: np.ndarray, L0sq: np.ndarray):
    """g = |a - b|^2 - L0^2 for positions y (G, 6): shapes (G, 1), (G, 1, 6), (G, 1, 6, 6)."""
    e = y[:, 0:3] - y[:, 3:6]
    g = np.einsum("gi,gi->g", e, e) - L0sq
    grad = np.concatenate([2.0 * e, -2.0 * e], axis=1)
    block = np.kron(np.array([[1.0, -1.0], [-1.0, 1.0]]), 2.0 * np.eye(3))
    H = np.broadcast_to(block, (y.shape[0], 1, 6, 6))
    return g[:, None], grad[:, None, :], H


class _Family:
    """The constraints of one kind: their nodes (G, n_nodes; global), the dependent positions within y (G, m) and
    what the kind's function needs (the base component of a line, a beam's squared length)."""

    def __init__(self, kind: str, nodes: np.ndarray, dep: np.ndarray, names: list[str], X: np.ndarray):
        self.kind, self.nodes, self.dep, self.names = kind, nodes, dep, names
        G, nn = nodes.shape
        n = 3 * nn
        self.dofs = (3 * nodes[:, :, None] + np.arange(3)).reshape(G, n)     # global dof of each entry of y
        self.X = X[nodes].reshape(G, n)
        free = np.ones((G, n), dtype=bool)
        free[np.arange(G)[:, None], dep] = False
        self.indep = np.nonzero(free)[1].reshape(G, n - dep.shape[1])      # local positions of w
        if kind == "straight":
            self.k = np.argmax(np.abs(self.X[:, 0:3] - self.X[:, 3:6]), axis=1)
        if kind == "beam":
            self.L0sq = np.sum((self.X[:, 0:3] - self.X[:, 3:6]) ** 2, axis=1)

    def evaluate(self, y: np.ndarray):
        if self.kind == "plane":
            return plane_constraint(y)
        if self.kind == "straight":
            return line_constraint(y, self.k)
        return beam_constraint(y, self.L0sq)

    def split(self, A: np.ndarray):
        """(A at w, A at z) along the last axis of a per-group array (G, ..., n)."""
        G = A.shape[0]
        shape = (G,) + (1,) * (A.ndim - 2)
        iw = self.indep.reshape(shape + (-1,))
        iz = self.dep.reshape(shape + (-1,))
        return np.take_along_axis(A, np.broadcast_to(iw, A.shape[:-1] + iw.shape[-1:]), -1), \
            np.take_along_axis(A, np.broadcast_to(iz, A.shape[:-1] + iz.shape[-1:]), -1)


class NonlinearMPCs:
    """The ``[[mpc]]`` constraints of a problem (``covcontact.loads.MPC``) on the dofs of ``system``."""

    #: P^T K P plus a symmetric second-order part
    symmetric = True

    def __init__(self, mpcs, system):
        n = system.n_dofs
        self.n = n
        groups: dict[str, tuple[list, list, list]] = {}
        for c in mpcs:
            nodes = [int(system.global_nodes(b, s)[0]) for b, s in c.nodes[:KINDS[c.kind]]]
            rest = [int(v) for b, s in c.nodes[KINDS[c.kind]:] for v in system.global_nodes(b, s)
                    if int(v) not in nodes]
            rest = list(dict.fromkeys(rest))
            for extra in ([[]] if c.kind == "beam" else [[v] for v in rest]):
                these = nodes + extra
                dep = dependent_components(c.kind, system.X[these])
                gl, gd, gn = groups.setdefault(c.kind, ([], [], []))
                gl.append(these)
                gd.append([3 * i + k for i, k in dep])
                gn.append(c.name)
        self.families = [_Family(kind, np.asarray(gl, dtype=np.int64), np.asarray(gd, dtype=np.int64), gn, system.X)
                         for kind, (gl, gd, gn) in groups.items()]
        self.mask = np.zeros(n, dtype=bool)
        for f in self.families:
            self.mask[np.take_along_axis(f.dofs, f.dep, 1).ravel()] = True
        self.dependent = np.flatnonzero(self.mask)
        keep = np.flatnonzero(~self.mask)
        self._keep = sp.csr_matrix((np.ones(keep.size), (keep, keep)), shape=(n, n))
        self.unit = unit_diagonal(self.mask, system)
        self._u = np.zeros(n)

    def complete(self, u: np.ndarray) -> None:
        """Set the dependent dofs of ``u`` (in place) so that every constraint holds."""
        for f in self.families:
            y = f.X + u[f.dofs]
            rows = np.arange(y.shape[0])[:, None]
            if f.kind != "beam":  # (linear in z: one step is exact)
                g, grad, _ = f.evaluate(y)
                y[rows, f.dep] -= np.linalg.solve(f.split(grad)[1], g[..., None])[..., 0]
            else:
                for _ in range(30):
                    g, grad, _ = f.evaluate(y)
                    if np.all(np.abs(g[:, 0]) <= 1e-13 * f.L0sq):
                        break
                    y[rows, f.dep] -= np.linalg.solve(f.split(grad)[1], g[..., None])[..., 0]
                else:
                    raise UnsolvableConstraint(f.names[int(np.argmax(np.abs(g[:, 0]) / f.L0sq))])
            if not np.all(np.isfinite(y)):
                raise UnsolvableConstraint(f.names[0])
            d = np.take_along_axis(f.dofs, f.dep, 1)
            u[d.ravel()] = (y[rows, f.dep] - f.X[rows, f.dep]).ravel()
        self._u = u.copy()

    def _parts(self):
        """Per family: Z (G, m, nw), E-blocks and the Hessians at the displacement of the last ``complete``."""
        out = []
        for f in self.families:
            y = f.X + self._u[f.dofs]
            _, grad, H = f.evaluate(y)
            Gw, Gz = f.split(grad)
            Z = -np.linalg.solve(Gz, Gw)
            out.append((f, Z, Gz, H))
        return out

    def _map(self, parts):
        rows, cols, vals = [], [], []
        for f, Z, _, _ in parts:
            dz = np.take_along_axis(f.dofs, f.dep, 1)                 # (G, m)
            dw = np.take_along_axis(f.dofs, f.indep, 1)               # (G, nw)
            rows.append(np.broadcast_to(dz[:, :, None], Z.shape).ravel())
            cols.append(np.broadcast_to(dw[:, None, :], Z.shape).ravel())
            vals.append(Z.ravel())
        P = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(self.n, self.n)) + self._keep
        return P.tocsr()

    def mass(self, M):
        """P^T M P: the dependent dofs' mass on the independent ones."""
        P = self._map(self._parts())
        return (P.T @ M @ P).tocsr()

    def lift(self, a: np.ndarray) -> np.ndarray:
        """P a: a rate of the independent dofs at every dof (to first order)."""
        return self._map(self._parts()) @ a

    def transform(self, R: np.ndarray, K):
        """(P^T R, P^T K P + sum_i mu_i E^T H_i E) (K may be None)."""
        parts = self._parts()
        P = self._map(parts)
        Pt = P.T.tocsr()
        Rn = Pt @ R
        if K is None:
            return Rn, None
        K = Pt @ K @ P + self.unit
        rows, cols, vals = [], [], []
        for f, Z, Gz, H in parts:
            G, m, nw = Z.shape
            n = f.dofs.shape[1]
            fz = R[np.take_along_axis(f.dofs, f.dep, 1)]                # (G, m): the forces at the dependent dofs
            mu = -np.linalg.solve(np.transpose(Gz, (0, 2, 1)), fz[..., None])[..., 0]
            E = np.zeros((G, n, nw))
            gi = np.arange(G)[:, None]
            E[gi, f.indep, np.arange(nw)[None, :]] = 1.0
            E[gi[:, :, None], f.dep[:, :, None], np.arange(nw)[None, None, :]] = Z
            Kg = np.einsum("gm,gyw,gmyv,gvx->gwx", mu, E, H, E)
            dw = np.take_along_axis(f.dofs, f.indep, 1)
            rows.append(np.broadcast_to(dw[:, :, None], Kg.shape).ravel())
            cols.append(np.broadcast_to(dw[:, None, :], Kg.shape).ravel())
            vals.append(Kg.ravel())
        K = (K + sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                               shape=K.shape)).tocsr()
        K.sort_indices()
        return Rn, K
