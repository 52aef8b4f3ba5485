"""Linear multi-point constraints by elimination (docs/theory.md, "Multi-point constraints").

Each equation sum_k c_k u_k = 0 names its first dof d as the dependent one: u_d = sum_{k > 0} a_k u_k with
a_k = -c_k / c_d. With T the (n x n) map u = T v (identity on the other dofs, row d holding the a_k, column d
zero) the residual and the tangent become T^T R and T^T K T: the dependent dofs drop out (their rows and columns
are zero, and the solver treats them as constrained), the others carry the forces the constraint hands over.
After every change of u the dependent dofs are set from the independent ones (``complete``), so every
evaluation is made at a displacement that satisfies the constraints exactly.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def reduce_matrix(K, keep: np.ndarray, dependent: np.ndarray, rows, extra=None) -> sp.csr_matrix:
    """T^T K T for T = diag(keep) + A, A zero but in the rows ``dependent`` (``rows``: those rows, |D| x n), keep 0
    at the dependent dofs and 1 elsewhere: E K E + E K_:D A_D + A_D^T K_D: E + A_D^T K_DD A_D with E = diag(keep).
    The product is formed on K's entries (those in a dependent row or column dropped) and thin matrices, not as two
    products with n x n matrices; ``extra`` (sparse, n x n) is added with the thin terms."""
    K = K.tocsr()
    E = keep.astype(bool)
    data = np.where(np.repeat(E, np.diff(K.indptr)) & E[K.indices], K.data, 0.0)
    out = sp.csr_matrix((data, K.indices, K.indptr), shape=K.shape)
    small = extra
    if len(dependent):
        rows = sp.csr_matrix(rows)
        KD = K[:, dependent]                         # (n, |D|)
        DK = K[dependent, :]                         # (|D|, n)
        Ed = sp.diags(keep.astype(float))
        small = Ed @ (KD @ rows) + (rows.T @ DK) @ Ed + rows.T @ (DK[:, dependent] @ rows) + (
            0 if extra is None else extra)
    if small is not None:
        out = out + small                            # (one sum of K's size)
    out = out.tocsr()
    out.sort_indices()
    return out


def unit_diagonal(mask: np.ndarray, system) -> sp.csr_matrix:
    """The diagonal that a constraint layer adds to its reduced tangent so that the held dofs keep their diagonal
    in the pattern: 1 at its dependent dofs (``mask``) and at the z-dofs of planar bodies (held: their zero diagonal,
    which the reduction P^T K P drops, kept as 1)."""
    on = mask.astype(float)
    planar = getattr(system, "planar_dofs", np.zeros(0, dtype=np.int64))
    if len(planar):
        on[planar] = 1.0
    return sp.diags(on).tocsr()


class LinearConstraints:
    """The equations of a problem (``covcontact.loads.Equation``) on the dofs of ``system``."""

    #: T^T K T keeps K's symmetry
    symmetric = True

    def __init__(self, equations, system, indices=None):
        n = system.n_dofs
        dep, rows, cols, vals = [], [], [], []
        self.n = n
        #: each equation's place in the problem's list (the right-hand sides come by it) and its first coefficient
        self.indices = np.arange(len(equations)) if indices is None else np.asarray(indices, dtype=np.int64)
        self.first = np.array([eq.terms[0][3] for eq in equations], dtype=float)
        for eq in equations:
            (b0, s0, c0, k0), *rest = eq.terms
            d = 3 * int(system.global_nodes(b0, s0)[0]) + c0
            dep.append(d)
            for b, s, c, k in rest:
                rows.append(d)
                cols.append(3 * int(system.global_nodes(b, s)[0]) + c)
                vals.append(-k / k0)
        self.dependent = np.asarray(dep, dtype=np.int64)
        self.mask = np.zeros(n, dtype=bool)
        self.mask[self.dependent] = True
        A = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))  # (repeated terms summed)
        # chains (an eliminated dof among another equation's terms): substitute until no row refers to one (the input
        # has no cycles, so this ends within as many rounds as there are equations)
        drop = sp.diags(np.where(self.mask, 0.0, 1.0))
        self._chain = []  # the substitutions made, for the right-hand sides' offsets (set_rhs)
        for _ in range(len(dep) + 1):
            B = A[:, self.dependent]
            if B.nnz == 0:
                break
            self._chain.append(B.tocsr())
            A = (A @ drop + B @ A[self.dependent]).tocsr()
            A.eliminate_zeros()
        keep = np.where(self.mask, 0.0, 1.0)
        self.T = (sp.diags(keep) + A).tocsr()
        self.Tt = self.T.T.tocsr()
        self.rows = A[self.dependent].tocsr()
        self.unit = unit_diagonal(self.mask, system)
        self.offset = np.zeros(len(dep))  # u_d = rows u + offset: the right-hand sides' share (set_rhs)

    def set_rhs(self, rhs: np.ndarray) -> None:
        """The right-hand sides b of the problem's equations (by their place in its list): the dependent dofs get
        b / c_d beside the others' share, passed on through the chains as the terms are."""
        o = np.zeros(self.n)
        o[self.dependent] = np.asarray(rhs, dtype=float)[self.indices] / self.first
        for B in self._chain:
            o = o + B @ o[self.dependent]
        self.offset = o[self.dependent]

    def complete(self, u: np.ndarray) -> None:
        """Set the dependent dofs of ``u`` (in place) from the others (and the right-hand sides)."""
        u[self.dependent] = self.rows @ u + self.offset

    def mass(self, M):
        """T^T M T: the mass of the independent dofs."""
        return (self.Tt @ M @ self.T).tocsr()

    def lift(self, a: np.ndarray) -> np.ndarray:
        """T a: a rate (velocity, acceleration) of the independent dofs at every dof."""
        return self.T @ a

    def transform(self, R: np.ndarray, K):
        """(T^T R, T^T K T) (K may be None)."""
        R = self.Tt @ R
        if K is not None:
            K = reduce_matrix(K, ~self.mask, self.dependent, self.rows, self.unit)
        return R, K


class RigidLinks:
    """Node sets of deformable bodies attached to rigid bodies with a reference node (``[[rigid]]`` ``attach``;
    docs/theory.md, "Multi-point constraints").

    An attached node follows its rigid body: u_i = t + (R(theta) - I) Y_i with Y_i = X_i - X_ref and (t, theta)
    the displacements of the body's nodes A and B, so delta u_i = delta t - [R Y_i]_x T(theta) delta theta
    (``covcontact.contact.reference``). With P that map (identity on the other dofs, zero columns at the attached
    ones) the residual becomes P^T R: A takes the sum of the attached nodes' forces f_i, B takes T^T sum R Y_i x f_i;
    the tangent P^T K P plus the part from the rotation's second derivative on B,
    sum T^T [f_i]_x [R Y_i]_x T + d(T^T m)/d theta with m = sum R Y_i x f_i. The attached dofs drop out (the solver
    treats them as constrained) and are set from (t, theta) before every evaluation (``complete``).

    A body may hold only some components of its attached nodes (``attached_components``, a deck's *KINEMATIC with
    some of the dofs 1-3): only those are eliminated (nonlinear equations u_ik = [t + (R(theta) - I) Y_i]_k, as
    CalculiX's kinematic coupling writes them); the others stay unknowns of their own. P has rows at the eliminated
    dofs alone, and the second-order part takes the forces there alone (it is linear in the f_i).
    """

    #: the second-order part on theta is not symmetric
    symmetric = False

    def __init__(self, system):
        n = system.n_dofs
        self.n = n
        self.links = []  # (reference body, attached global nodes, Y, the components that follow the body)
        self.mask = np.zeros(n, dtype=bool)
        for ref in system.reference:
            nodes = np.asarray(getattr(ref, "attached", ()), dtype=np.int64)
            if nodes.size == 0:
                continue
            comps = np.asarray(getattr(ref, "attached_components", (0, 1, 2)), dtype=np.int64)
            self.links.append((ref, nodes, system.X[nodes] - ref.origin, comps))
            self.mask[(3 * nodes[:, None] + comps).ravel()] = True
        self.dependent = np.flatnonzero(self.mask)
        keep = np.flatnonzero(~self.mask)
        self._keep = sp.csr_matrix((np.ones(keep.size), (keep, keep)), shape=(n, n))
        self.unit = unit_diagonal(self.mask, system)
        # every attached node of every link at once: its link, its Y, the components it follows
        self._node = np.concatenate([nodes for _, nodes, _, _ in self.links]) if self.links else np.zeros(0, int)
        self._link = np.concatenate([np.full(len(nodes), k) for k, (_, nodes, _, _) in enumerate(self.links)]) \
            if self.links else np.zeros(0, int)
        self._Y = np.vstack([Y for _, _, Y, _ in self.links]) if self.links else np.zeros((0, 3))
        follows = np.zeros((len(self._node), 3), dtype=bool)
        start = 0
        for _, nodes, _, comps in self.links:
            follows[start: start + len(nodes), comps] = True
            start += len(nodes)
        self._rows, self._comps = np.nonzero(follows)     # (attached node, component) of every eliminated dof
        self._A = np.array([ref.A for ref, *_ in self.links], dtype=np.int64)
        self._B = np.array([ref.B for ref, *_ in self.links], dtype=np.int64)
        self._theta = np.zeros((len(self.links), 3))  # each body's rotation vector at the last ``complete``
        # the bodies' dofs (t, theta): their diagonal kept in the pattern (a component no eliminated dof depends on,
        # such as a translation a partial coupling does not hold, has no entries; prescribed, it needs its diagonal)
        self._ref_dofs = np.array([3 * node + k for ref, *_ in self.links for node in (ref.A, ref.B)
                                   for k in range(3)], dtype=np.int64)

    def complete(self, u: np.ndarray) -> None:
        """Set the attached nodes' displacements (in place) from their bodies' (t, theta)."""
        u3 = u.reshape(-1, 3)
        self._theta = u3[self._B].copy()
        ry = np.einsum("nij,nj->ni", _rotations(self._theta)[self._link], self._Y)
        new = u3[self._A][self._link] + ry - self._Y
        u3[self._node[self._rows], self._comps] = new[self._rows, self._comps]

    def _map(self):
        """P (n x n) at the displacement of the last ``complete``, the attached nodes' R Y_i and the links' T."""
        from ..contact.reference import skew

        T = _tangents(self._theta)
        ry = np.einsum("nij,nj->ni", _rotations(self._theta)[self._link], self._Y)
        B = -np.einsum("nij,njk->nik", skew(ry), T[self._link])[self._rows, self._comps]   # (eliminated dofs, 3)
        r0 = 3 * self._node[self._rows] + self._comps
        link = self._link[self._rows]
        rows = np.concatenate([r0, np.repeat(r0, 3)])
        cols = np.concatenate([3 * self._A[link] + self._comps, (3 * self._B[link][:, None] + np.arange(3)).ravel()])
        vals = np.concatenate([np.ones(r0.size), B.ravel()])
        P = sp.csr_matrix((vals, (rows, cols)), shape=(self.n, self.n)) + self._keep
        return P.tocsr(), ry, T

    def mass(self, M):
        """P^T M P at the displacement of the last ``complete``: the attached nodes' mass on their bodies' (t, theta)."""
        P = self._map()[0]
        return (P.T @ M @ P).tocsr()

    def lift(self, a: np.ndarray) -> np.ndarray:
        """P a: a rate of the independent dofs at every dof (the attached nodes' from their bodies'; to first order:
        without the centripetal part, which the rates at rest, where this is used, do not have)."""
        return self._map()[0] @ a

    def transform(self, R: np.ndarray, K):
        """(P^T R, P^T K P + the rotation's second-order part) (K may be None)."""
        from ..contact.reference import skew

        P, ry, T = self._map()
        Rn = P.T.tocsr() @ R
        if K is None:
            return Rn, None
        f = np.zeros((len(self._node), 3))
        f[self._rows, self._comps] = R.reshape(-1, 3)[self._node[self._rows], self._comps]   # (eliminated ones)
        m = len(self.links)
        S = np.zeros((m, 3, 3))
        np.add.at(S, self._link, np.einsum("nij,njk->nik", skew(f), skew(ry)))
        moment = np.zeros((m, 3))
        np.add.at(moment, self._link, np.cross(ry, f))
        G = np.einsum("lji,ljk,lkm->lim", T, S, T) + np.einsum("li,lijk->ljk", moment, _tangent_derivatives(self._theta))
        b = 3 * self._B[:, None] + np.arange(3)                       # (m, 3)
        G = sp.csr_matrix((G.ravel(), (np.repeat(b, 3, axis=1).ravel(), np.tile(b, (1, 3)).ravel())), shape=K.shape)
        K = reduce_matrix(K, ~self.mask, self.dependent, P[self.dependent], self.unit + G)
        return Rn, _with_diagonal(K, self._ref_dofs)


def _rotations(theta: np.ndarray) -> np.ndarray:
    """(m, 3, 3) rotation matrices of the rotation vectors ``theta`` (m, 3): motion.rotation_matrix, batched."""
    from ..contact.reference import skew

    K = skew(theta)
    t = np.linalg.norm(theta, axis=1)
    small = t < 1e-8
    ts = np.where(small, 1.0, t)
    s = np.where(small, 1.0 - t * t / 6.0, np.sin(ts) / ts)
    c = np.where(small, 0.5 - t * t / 24.0, (1.0 - np.cos(ts)) / (ts * ts))
    return np.eye(3) + s[:, None, None] * K + c[:, None, None] * (K @ K)


def _tangents(theta: np.ndarray) -> np.ndarray:
    """(m, 3, 3) T(theta) of contact.reference.tangent_map, batched (real or complex theta)."""
    from ..contact.reference import skew

    K = skew(theta)
    t2 = np.einsum("mi,mi->m", theta, theta)
    small = np.abs(t2) < 1e-6
    t2s = np.where(small, 1.0, t2)
    t = np.sqrt(t2s)
    a = np.where(small, 0.5 - t2 / 24.0 + t2 * t2 / 720.0, (1.0 - np.cos(t)) / t2s)
    b = np.where(small, 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0, (t - np.sin(t)) / (t2s * t))
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


def _tangent_derivatives(theta: np.ndarray) -> np.ndarray:
    """(m, 3, 3, 3) D[l, i] = d(T(theta_l)^T e_i)/d theta (contact.reference.tangent_map_derivatives, batched), by
    complex steps."""
    h = 1e-30
    out = np.zeros(theta.shape + (3, 3))
    for k in range(3):
        th = theta.astype(complex)
        th[:, k] += 1j * h
        out[:, :, :, k] = _tangents(th).imag / h
    return out


def _with_diagonal(K, dofs: np.ndarray):
    """K with the diagonal entries of ``dofs`` in its pattern (explicit zeros where they were missing)."""
    missing = [int(i) for i in dofs if i not in K.indices[K.indptr[i]: K.indptr[i + 1]]]
    if not missing:
        return K
    C = K.tocoo()
    K = sp.coo_matrix((np.concatenate([C.data, np.zeros(len(missing))]),
                       (np.concatenate([C.row, missing]), np.concatenate([C.col, missing]))), shape=K.shape).tocsr()
    K.sort_indices()
    return K


class ChainedConstraints:
    """Several kinds of constraints together, ``layers`` in the order their dependent dofs are set (rigid links,
    then nonlinear MPCs, then linear equations: each may read the dofs the ones before set): u = T(m(g(w))), so the
    residual is P_g^T P_m^T T^T R and every layer's second-order part takes the forces handed to it."""

    def __init__(self, *layers):
        self.layers = layers
        self.mask = np.logical_or.reduce([c.mask for c in layers])
        self.symmetric = all(c.symmetric for c in layers)

    def complete(self, u: np.ndarray) -> None:
        for c in self.layers:
            c.complete(u)

    def set_rhs(self, rhs: np.ndarray) -> None:
        for c in self.layers:
            if hasattr(c, "set_rhs"):
                c.set_rhs(rhs)

    def transform(self, R: np.ndarray, K):
        for c in reversed(self.layers):
            R, K = c.transform(R, K)
        return R, K

    def mass(self, M):
        for c in reversed(self.layers):
            M = c.mass(M)
        return M

    def lift(self, a: np.ndarray) -> np.ndarray:
        for c in self.layers:
            a = c.lift(a)
        return a
