"""Springs and dashpots between nodes, or from a node to ground (``[[spring]]``, ``[[dashpot]]``; a deck's SPRINGA,
SPRING1, SPRING2 and DASHPOTA elements; docs/theory.md, "Springs and dashpots").

Two kinds, as CalculiX defines them (its springforc_n2f.f and springstiff_n2f.f):

- ``"axial"`` (SPRINGA, DASHPOTA): along the current line between its nodes a and b (or from node a to a fixed
  point, the ``anchor``), d = x_b - x_a, L = |d|, n = d / L. The spring's force f(e) of the elongation e = L - L0
  acts on b as +f n and on a as -f n (internal forces); its tangent on (a, b) is [[A, -A], [-A, A]] with
  A = f'(e) n n^T + (f / L)(I - n n^T), the second term the geometric stiffness of the turning line. The dashpot's
  force is c (n . w) n on b with w = v_b - v_a (the anchor at rest), and with dv/du = s (the time integrator's
  gamma / (beta dt)) A = c [s n n^T + ((n . w) (I - n n^T) + n w^T (I - n n^T)) / L] (not symmetric).
- ``"dof"`` (SPRING1, SPRING2): dof i of node a to dof j of node b (or to ground), fixed directions n_a, n_b (the
  global axes): the value e = u_a . n_a - u_b . n_b, the forces f(e) n_a on a and -f(e) n_b on b, the tangent
  f'(e) [[n_a n_a^T, -n_a n_b^T], [-n_b n_a^T, n_b n_b^T]]; a dashpot the same with c (v_a . n_a - v_b . n_b) and
  c s for f'.

f is linear, f = k e, or a table of (elongation, force) points, linear between them and constant beyond the ends (as
CalculiX's NONLINEAR springs: zero slope there). Springs and dashpots have no history (the state rule holds
trivially): the forces are functions of the displacements and, for dashpots, of the velocities.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: the kinds of springs and dashpots
KINDS = ("axial", "dof")


@dataclass
class Spring:
    """A spring (``[[spring]]``): ``nodes`` one or two (body, node set); two sets hold one node each, one set any
    number of nodes (each gets its own spring to ground). ``kind`` "axial" (with one set: to the fixed point
    ``anchor``) or "dof" (``dofs``: the component 0..2 of each node). ``stiffness`` k, or ``table`` of
    (elongation, force) points."""

    nodes: tuple[tuple[str, str], ...]
    kind: str = "axial"
    stiffness: float | None = None
    table: tuple[tuple[float, float], ...] | None = None
    dofs: tuple[int, ...] = ()
    anchor: tuple[float, float, float] | None = None
    name: str = ""


@dataclass
class Dashpot:
    """A linear dashpot (``[[dashpot]]``): nodes, kind, dofs and anchor as a :class:`Spring`'s; force c times the
    relative velocity (along the line, or of the dofs). Acts in dynamic stages only."""

    nodes: tuple[tuple[str, str], ...]
    coefficient: float
    kind: str = "axial"
    dofs: tuple[int, ...] = ()
    anchor: tuple[float, float, float] | None = None
    name: str = ""


class Law:
    """f(e), f'(e) and the energy int_0^e f: linear (``stiffness``) or piecewise linear through ``table``
    ((elongation, force) points, elongations increasing), constant beyond its ends."""

    def __init__(self, stiffness=None, table=None):
        self.k = None if stiffness is None else np.asarray(stiffness, dtype=float)  # (one per member, or one for all)
        if table is not None:
            t = np.asarray(table, dtype=float)
            self.x, self.f = t[:, 0].copy(), t[:, 1].copy()
            # G(e) = int_{x0}^e f (constant f0 below x0): its values at the points
            self.G = np.concatenate([[0.0], np.cumsum(0.5 * (self.f[1:] + self.f[:-1]) * np.diff(self.x))])

    def __call__(self, e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.k is not None:
            return self.k * e, self.k * np.ones_like(e)
        x, f = self.x, self.f
        i = np.searchsorted(x, e, side="right") - 1    # the point at or before e (CalculiX's ident)
        inside = (i >= 0) & (i < x.size - 1)
        j = np.clip(i, 0, x.size - 2)
        slope = (f[j + 1] - f[j]) / (x[j + 1] - x[j])
        force = np.where(i < 0, f[0], np.where(i >= x.size - 1, f[-1], f[j] + slope * (e - x[j])))
        return force, np.where(inside, slope, 0.0)

    def _G(self, e: np.ndarray) -> np.ndarray:
        x, f = self.x, self.f
        i = np.clip(np.searchsorted(x, e, side="right") - 1, 0, x.size - 1)
        fe = self(e)[0]
        below = e < x[0]
        return np.where(below, f[0] * (e - x[0]), self.G[i] + 0.5 * (f[i] + fe) * (e - x[i]))

    def energy(self, e: np.ndarray) -> np.ndarray:
        if self.k is not None:
            return 0.5 * self.k * e * e
        return self._G(e) - self._G(np.zeros_like(e))


@dataclass
class _Group:
    """Springs (or dashpots) of one kind and one law, flattened: nodes a (m,), b (m,) (-1: ground); axial: the anchor
    P (m, 3) and the reference length L0 (m,); dof: the directions na, nb (m, 3)."""

    kind: str
    law: Law | None          # (dashpots: None, ``c`` their coefficient)
    a: np.ndarray
    b: np.ndarray
    P: np.ndarray
    L0: np.ndarray
    na: np.ndarray
    nb: np.ndarray
    c: float | np.ndarray = 0.0


def _merged(groups: list[_Group]) -> list[_Group]:
    """The groups with the linear members of each kind merged into one (a stiffness or coefficient per member), so
    that many springs cost one vectorised evaluation; tables stay a group each."""
    out = [g for g in groups if g.law is not None and g.law.k is None]
    for kind in KINDS:
        lin = [g for g in groups if g.kind == kind and (g.law is None or g.law.k is not None)]
        if not lin:
            continue
        cat = {f: np.concatenate([getattr(g, f) for g in lin]) for f in ("a", "b", "P", "L0", "na", "nb")}
        if lin[0].law is None:  # (dashpots)
            c = np.concatenate([np.full(g.a.size, g.c) for g in lin])
            out.append(_Group(kind, None, c=c, **cat))
        else:
            k = np.concatenate([np.broadcast_to(g.law.k, g.a.shape) for g in lin])
            out.append(_Group(kind, Law(k), **cat))
    return out


def _skew_free(n: np.ndarray) -> np.ndarray:
    """I - n n^T per row of n (m, 3)."""
    return np.eye(3)[None] - n[:, :, None] * n[:, None, :]


def _blocks(a: np.ndarray, b: np.ndarray, Ra: np.ndarray, Rb: np.ndarray, Kaa, Kab, Kba, Kbb):
    """The element blocks (conn, R, K) of the two-node members (b >= 0) and of the grounded ones (node a alone)."""
    out = []
    two = b >= 0
    if two.any():
        conn = np.stack([a[two], b[two]], axis=1)
        R = np.concatenate([Ra[two], Rb[two]], axis=1)
        K = None
        if Kaa is not None:
            K = np.zeros((int(two.sum()), 6, 6))
            K[:, :3, :3], K[:, :3, 3:], K[:, 3:, :3], K[:, 3:, 3:] = Kaa[two], Kab[two], Kba[two], Kbb[two]
        out.append((conn, R, K))
    if (~two).any():
        out.append((a[~two][:, None], Ra[~two], None if Kaa is None else Kaa[~two]))
    return out


class SpringSet:
    """The springs and dashpots of a problem on the global numbering of ``system``
    (``covcontact.assembly.system.System``): their forces and tangents as element blocks, their energy."""

    def __init__(self, springs, dashpots, system):
        self.springs = _merged([self._group(s, system, Law(s.stiffness, s.table)) for s in springs])
        self.dashpots = _merged([self._group(d, system, None, d.coefficient) for d in dashpots])
        #: the tangent is symmetric (an axial dashpot's is not)
        self.symmetric = not any(g.kind == "axial" for g in self.dashpots)

    @staticmethod
    def _group(item, system, law, c: float = 0.0) -> _Group:
        a = system.global_nodes(*item.nodes[0]).astype(np.int64)
        if len(item.nodes) > 1:
            b = system.global_nodes(*item.nodes[1]).astype(np.int64)
        else:
            b = np.full(a.size, -1, dtype=np.int64)
        X = system.X
        P = np.tile(np.asarray(item.anchor if item.anchor is not None else (0.0, 0.0, 0.0), float), (a.size, 1))
        na, nb = np.zeros((a.size, 3)), np.zeros((a.size, 3))
        L0 = np.zeros(a.size)
        if item.kind == "axial":
            Xb = np.where((b >= 0)[:, None], X[np.maximum(b, 0)], P)
            L0 = np.linalg.norm(Xb - X[a], axis=1)
        else:
            na[:, item.dofs[0]] = 1.0
            if len(item.dofs) > 1:
                nb[:, item.dofs[1]] = 1.0
        return _Group(item.kind, law, a, b, P, L0, na, nb, float(c))

    def couplings(self) -> list[np.ndarray]:
        """The node pairs the members couple (m, 2), for the tangent's sparsity pattern."""
        out = [np.stack([g.a[g.b >= 0], g.b[g.b >= 0]], axis=1) for g in self.springs + self.dashpots]
        return [c for c in out if len(c)]

    # -- springs ------------------------------------------------------------------------------------
    @staticmethod
    def _line(g: _Group, x: np.ndarray):
        xb = np.where((g.b >= 0)[:, None], x[np.maximum(g.b, 0)], g.P)
        d = xb - x[g.a]
        L = np.linalg.norm(d, axis=1)
        if np.any(L <= 0.0):
            k = int(np.flatnonzero(L <= 0.0)[0])
            raise FloatingPointError(f"an axial spring or dashpot at node {int(g.a[k])} has zero length (its ends "
                                     f"coincide): its direction is undefined")
        return d, L, d / L[:, None]

    def spring_blocks(self, x: np.ndarray, u: np.ndarray, want_K: bool) -> list:
        """(conn, R, K) blocks of the springs at positions ``x`` (n_nodes, 3), displacements ``u`` (n_nodes, 3)."""
        out = []
        for g in self.springs:
            if g.kind == "axial":
                d, L, n = self._line(g, x)
                f, df = g.law(L - g.L0)
                Rb = f[:, None] * n
                A = None
                if want_K:
                    nn = n[:, :, None] * n[:, None, :]
                    A = df[:, None, None] * nn + (f / L)[:, None, None] * (np.eye(3)[None] - nn)
                out += _blocks(g.a, g.b, -Rb, Rb, A, None if A is None else -A, None if A is None else -A, A)
            else:
                ub = np.where((g.b >= 0)[:, None], u[np.maximum(g.b, 0)], 0.0)
                e = np.einsum("mi,mi->m", u[g.a], g.na) - np.einsum("mi,mi->m", ub, g.nb)
                f, df = g.law(e)
                out += _blocks(g.a, g.b, f[:, None] * g.na, -f[:, None] * g.nb, *self._dof_K(g, df, want_K))
        return out

    @staticmethod
    def _dof_K(g: _Group, k: np.ndarray, want_K: bool):
        if not want_K:
            return None, None, None, None
        outer = lambda p, q: k[:, None, None] * p[:, :, None] * q[:, None, :]  # noqa: E731
        return outer(g.na, g.na), -outer(g.na, g.nb), -outer(g.nb, g.na), outer(g.nb, g.nb)

    def energy(self, x: np.ndarray, u: np.ndarray) -> float:
        """The springs' stored energy sum int_0^e f."""
        total = 0.0
        for g in self.springs:
            if g.kind == "axial":
                e = self._line(g, x)[1] - g.L0
            else:
                ub = np.where((g.b >= 0)[:, None], u[np.maximum(g.b, 0)], 0.0)
                e = np.einsum("mi,mi->m", u[g.a], g.na) - np.einsum("mi,mi->m", ub, g.nb)
            total += float(np.sum(g.law.energy(e)))
        return total

    # -- dashpots -----------------------------------------------------------------------------------
    def dashpot_blocks(self, x: np.ndarray, v: np.ndarray, s: float, want_K: bool) -> list:
        """(conn, R, K) blocks of the dashpots at positions ``x`` and velocities ``v`` (n_nodes, 3); ``s`` = dv/du
        (the integrator's gamma / (beta dt)), which the tangent takes."""
        out = []
        for g in self.dashpots:
            vb = np.where((g.b >= 0)[:, None], v[np.maximum(g.b, 0)], 0.0)
            if g.kind == "axial":
                d, L, n = self._line(g, x)
                w = vb - v[g.a]
                nw = np.einsum("mi,mi->m", n, w)
                c = np.broadcast_to(g.c, g.a.shape)
                Rb = (c * nw)[:, None] * n
                A = None
                if want_K:
                    Pm = _skew_free(n)
                    Pw = np.einsum("mij,mj->mi", Pm, w)
                    turn = (nw[:, None, None] * Pm + n[:, :, None] * Pw[:, None, :]) / L[:, None, None]
                    A = c[:, None, None] * (s * n[:, :, None] * n[:, None, :] + turn)
                out += _blocks(g.a, g.b, -Rb, Rb, A, None if A is None else -A, None if A is None else -A, A)
            else:
                rate = np.einsum("mi,mi->m", v[g.a], g.na) - np.einsum("mi,mi->m", vb, g.nb)
                c = np.broadcast_to(g.c, g.a.shape)
                f = c * rate
                out += _blocks(g.a, g.b, f[:, None] * g.na, -f[:, None] * g.nb, *self._dof_K(g, c * s, want_K))
        return out


def add_blocks(blocks: list, r: np.ndarray, K=None, pattern=None) -> None:
    """r += the blocks' residuals; with ``K`` (a CSR over ``pattern``, covcontact.assembly.pattern.Pattern) the
    tangents into its data."""
    for conn, R, Ke in blocks:
        dofs = (3 * conn[:, :, None] + np.arange(3)).reshape(len(conn), -1)
        np.add.at(r, dofs.ravel(), R.ravel())
        if K is not None and Ke is not None:
            pattern.scatter(K.data, conn, np.ascontiguousarray(Ke))


def spring_set(problem, system) -> SpringSet | None:
    """The SpringSet of ``problem``'s springs and dashpots, None without any."""
    springs, dashpots = getattr(problem, "springs", None) or [], getattr(problem, "dashpots", None) or []
    return SpringSet(springs, dashpots, system) if springs or dashpots else None
