"""Linear solver registry: sparse direct and iterative backends behind one small interface.

Backends, in order of preference (``available()`` lists those usable on this machine):

- ``pardiso``: MKL PARDISO through the ``pypardiso`` package (x86-64). Symmetric matrices are
  factorised as LDL^T with Bunch-Kaufman pivoting (mtype -2, upper triangle), which also covers the
  indefinite tangents of buckling and contact; non-symmetric ones as LU (mtype 11).
- ``cholmod``: CHOLMOD supernodal Cholesky (scikit-sparse); symmetric only. An indefinite matrix
  falls back to the next LDL^T/LU backend for that factorisation.
- ``mumps``: MUMPS LDL^T / LU (python-mumps).
- ``superlu``: SciPy's SuperLU, always present; for symmetric matrices with the symmetric-mode
  options (MMD on A^T + A, diagonal pivots preferred), about 2.4x faster than ``spsolve``.
- ``cg-amg``: smoothed-aggregation AMG (pyamg) as preconditioner of CG (symmetric) or GMRES, with
  the rigid-body modes as near-null space once ``set_near_null_space`` (or ``set_geometry``) has been
  called: ``solver.set_near_null_space(rigid_body_modes(X, constrained))``. Every backend has both
  methods; the direct ones ignore them.

Every solver keeps its symbolic analysis while the sparsity pattern (indptr, indices) is unchanged,
records the time of its last analysis, factorisation and solve, checks the residual of each solve
and raises ``SingularMatrixError`` for a singular matrix or a non-finite solution.

The backend classes live in :mod:`covcontact.solvers.backends` and, for PARDISO and PETSc, in
:mod:`covcontact.solvers.pardiso_backend` and :mod:`covcontact.solvers.petsc_backend`. They import this module
(the base class); this module knows them by name only and imports the one asked for on first use, so there
is no import cycle. A new backend is a :class:`LinearSolver` subclass with a static ``probe()`` in its own
module of this package, registered by one :data:`REGISTRY` entry, e.g. ``"petsc": Backend("petsc_backend",
"PetscSolver", auto=False)``.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass
from functools import cache

import numpy as np
import scipy.sparse as sp
from numba import njit


@dataclass(frozen=True)
class Backend:
    """A registry entry: class ``cls`` of module ``module`` (of this package, imported on first use).

    Attributes:
        module: module name relative to :mod:`covcontact.solvers`.
        cls: a :class:`LinearSolver` subclass with a static ``probe()`` -> (available, version, note)
            that raises ImportError / OSError when its package is missing.
        auto: whether ``make_solver("auto")`` may choose it (direct solvers).
        symmetric_only: whether it refuses non-symmetric matrices.
    """

    module: str
    cls: str
    auto: bool = True
    symmetric_only: bool = False


#: all backends, in order of preference; a new backend is one more entry
REGISTRY: dict[str, Backend] = {
    "pardiso": Backend("pardiso_backend", "PardisoSolver"),
    "cholmod": Backend("backends", "CholmodSolver", symmetric_only=True),
    "mumps": Backend("backends", "MumpsSolver"),
    "superlu": Backend("backends", "SuperLUSolver"),
    "cg-amg": Backend("backends", "AMGSolver", auto=False),
    "petsc": Backend("petsc_backend", "PetscSolver", auto=False),
    "petsc-gamg": Backend("petsc_backend", "PetscGAMGSolver", auto=False),
}
BACKENDS = tuple(REGISTRY)
_DIRECT = tuple(name for name, b in REGISTRY.items() if b.auto)
class LinearSolverError(RuntimeError):
    """A linear solve failed (bad input, backend error, or no convergence)."""


class SingularMatrixError(LinearSolverError):
    """The matrix is singular (or numerically so) or the solution is not finite."""


# ----------------------------------------------------------------------------- availability


def backend_class(name: str) -> type[LinearSolver]:
    """The solver class of registered backend ``name`` (imports its module)."""
    b = REGISTRY[name]
    return getattr(importlib.import_module(f".{b.module}", __package__), b.cls)


@cache
def _probe(name: str) -> tuple[bool, str, str]:
    """(available, version, note) of one backend; imports it if possible."""
    if name not in REGISTRY:
        raise ValueError(name)
    try:
        return backend_class(name).probe()
    except (ImportError, OSError) as exc:
        return False, "", f"not installed ({exc.__class__.__name__}: {exc})"


def available() -> list[str]:
    """Backends usable here, in order of preference."""
    return [name for name in BACKENDS if _probe(name)[0]]


def describe() -> list[dict]:
    """One dict per backend (name, available, version, note), for ``covcontact info``."""
    out = []
    for name in BACKENDS:
        ok, version, note = _probe(name)
        out.append({"name": name, "available": ok, "version": version, "note": note})
    return out


def make_solver(name: str = "auto", symmetric: bool = True, **options) -> LinearSolver:
    """Create a linear solver.

    Args:
        name: a backend from ``BACKENDS`` or ``"auto"`` (the first direct backend available that
            handles the symmetry).
        symmetric: whether the matrices will be symmetric (they may still be indefinite).
        **options: backend options (``check_tol`` for all; ``spd``/``matching`` for pardiso;
            ``ordering`` for mumps; ``rtol``/``maxiter``/``blocksize`` for cg-amg).
    """
    key = name.lower().strip()
    if key == "auto":  # probe lazily: importing every optional backend costs time
        key = next(c for c in _DIRECT if (symmetric or not REGISTRY[c].symmetric_only) and _probe(c)[0])
    if key not in BACKENDS:
        raise ValueError(f"unknown linear solver {name!r}; available here: {', '.join(available())}")
    if not _probe(key)[0]:
        raise ValueError(
            f"linear solver {name!r} is not available here ({_probe(key)[2]}); "
            f"available: {', '.join(available())}"
        )
    if REGISTRY[key].symmetric_only and not symmetric:
        alt = [c for c in _DIRECT if not REGISTRY[c].symmetric_only]
        use = " or ".join([", ".join(alt[:-1]), alt[-1]] if len(alt) > 1 else alt)
        raise ValueError(f"{key} factorises symmetric matrices only; use {use}")
    return backend_class(key)(symmetric=symmetric, **options)


def gmres_right(A, b: np.ndarray, prec, tol: float, m: int, partial: bool = False, flexible: bool = False):
    """One cycle of GMRES(m) on A x = b from x = 0 with right preconditioning x = prec(y): the Arnoldi basis
    by classical Gram-Schmidt with one reorthogonalisation, Givens rotations for the least-squares problem.
    Returns (x or None if ||b - A x|| > tol ||b|| after m iterations, iterations); with ``partial`` the
    minimiser after m iterations is returned even when it misses the tolerance (None only at a breakdown).
    ``flexible`` keeps the preconditioned vectors and forms x from them (FGMRES): needed when prec is not
    linear to working precision, e.g. a substitution in single precision, where prec(sum y_j v_j) differs
    from sum y_j prec(v_j) by the single-precision rounding."""
    n = b.shape[0]
    beta = float(np.linalg.norm(b))
    if beta == 0.0:
        return np.zeros(n), 0
    V = np.empty((m + 1, n))
    Z = np.empty((m, n)) if flexible else None
    H = np.zeros((m + 1, m))
    cs = np.zeros(m)
    sn = np.zeros(m)
    g = np.zeros(m + 1)
    g[0] = beta
    V[0] = b / beta
    k = 0
    for j in range(m):
        z = prec(V[j])
        if Z is not None:
            Z[j] = z
        w = A @ z
        h = V[: j + 1] @ w
        w -= h @ V[: j + 1]
        h2 = V[: j + 1] @ w  # reorthogonalise once
        w -= h2 @ V[: j + 1]
        h += h2
        hn = float(np.linalg.norm(w))
        H[: j + 1, j] = h
        H[j + 1, j] = hn
        for i in range(j):  # the earlier rotations on the new column
            a, c = H[i, j], H[i + 1, j]
            H[i, j], H[i + 1, j] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c
        r = float(np.hypot(H[j, j], H[j + 1, j]))
        if r == 0.0:
            return None, j + 1
        cs[j], sn[j] = H[j, j] / r, H[j + 1, j] / r
        H[j, j], H[j + 1, j] = r, 0.0
        g[j + 1] = -sn[j] * g[j]
        g[j] = cs[j] * g[j]
        k = j + 1
        if abs(g[j + 1]) <= tol * beta:
            break
        if hn == 0.0:
            if partial:
                break
            return None, k
        V[j + 1] = w / hn
    if abs(g[k]) > tol * beta and not partial:
        return None, k
    y = np.linalg.solve(np.triu(H[:k, :k]), g[:k])
    return (y @ Z[:k] if Z is not None else prec(y @ V[:k])), k


def rigid_body_modes(X: np.ndarray, constrained: np.ndarray | None = None) -> np.ndarray:
    """The six rigid-body modes of the nodes ``X``: the near-null space of an elastic stiffness.

    Columns: the unit translations along x, y, z, then the infinitesimal rotations about the x, y, z
    axes through the centroid of ``X``, u = e_k x (x - c) / L, with L the root-mean-square distance of
    the nodes from the centroid, so that every column has entries of order one whatever the units.
    Row 3a+i belongs to direction i of node a.

    Args:
        X: (nnode, 3) node coordinates: the reference ones, or the current ones X + u for the tangent at
            a deformed state (whose kernel is spanned by rotations of the current configuration).
        constrained: either a bool mask (3 nnode,) of the Dirichlet-constrained dofs, whose rows are set
            to zero to match a matrix with those rows and columns eliminated (result (3 nnode, 6)); or
            an integer array of distinct global dofs, the unknowns of a reduced system (result
            (len(dofs), 6), rows in that order); or None: all dofs, nothing zeroed.
    """
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ValueError(f"node coordinates must have shape (nnode, 3), got {X.shape}")
    ndof = 3 * X.shape[0]
    mask = None
    if constrained is None:
        dofs = np.arange(ndof)
    else:
        c = np.asarray(constrained)
        if c.dtype == bool:
            if c.shape != (ndof,):
                raise ValueError(f"the constrained mask must have shape ({ndof},), got {c.shape}")
            dofs, mask = np.arange(ndof), c
        elif np.issubdtype(c.dtype, np.integer) and c.ndim == 1:
            dofs = c.astype(np.int64)
            if dofs.size and (dofs.min() < 0 or dofs.max() >= ndof or np.unique(dofs).size != dofs.size):
                raise ValueError(f"dofs must be distinct integers in [0, {ndof}); pass a constrained mask "
                                 "as a bool array")
        else:
            raise TypeError(f"constrained must be a bool mask or integer dofs, got {c.dtype} {c.shape}")
    node, i = dofs // 3, dofs % 3
    c0 = X.mean(axis=0) if X.shape[0] else np.zeros(3)
    L = float(np.sqrt(np.mean(np.sum((X - c0) ** 2, axis=1)))) if X.shape[0] else 0.0
    x = (X[node] - c0) / (L if L > 0.0 else 1.0)
    B = np.zeros((dofs.size, 6))
    rows = np.arange(dofs.size)
    B[rows, i] = 1.0
    for k in range(3):  # rotation about axis k: u = e_k x x
        rot = np.zeros((dofs.size, 3))
        rot[:, (k + 2) % 3] = x[:, (k + 1) % 3]
        rot[:, (k + 1) % 3] = -x[:, (k + 2) % 3]
        B[:, 3 + k] = rot[rows, i]
    if mask is not None:
        B[mask] = 0.0
    return B


@njit(cache=True)
def _dots(Q, k, v):  # pragma: no cover - compiled
    """Q[:, j] . v for j < k, each summed in index order (a fixed order: the same bits on every run)."""
    out = np.zeros(k)
    for j in range(k):
        acc = 0.0
        for i in range(v.size):
            acc += Q[i, j] * v[i]
        out[j] = acc
    return out


@njit(cache=True)
def _column_sums(X):  # pragma: no cover - compiled
    """The sums of X's columns, each in index order."""
    out = np.zeros(X.shape[1])
    for i in range(X.shape[0]):
        for d in range(X.shape[1]):
            out[d] += X[i, d]
    return out


def rigid_body_basis(coords: np.ndarray, sum_ranks=None) -> np.ndarray:
    """An orthonormal basis (3 m, 6) of the :func:`rigid_body_modes` at ``coords`` (m, 3), on a distributed run
    this rank's share of the nodes (``sum_ranks``: the sum of an array over the ranks, in a fixed order, e.g.
    parallel.comm.sum_all), rows x, y, z interleaved, the same bits on every run: the modes about the centroid
    of all ranks' nodes, orthonormalised by Gram-Schmidt twice over with every sum taken in a fixed order.
    (PETSc's MatNullSpaceCreateRigidBody sums with BLAS, whose rounding depends on where its vectors lie in
    memory: its modes, and with them GAMG's hierarchy, differed in the last bit between runs of the same
    problem.)"""

    def total(a: np.ndarray) -> np.ndarray:
        return sum_ranks(a) if sum_ranks is not None else np.asarray(a, dtype=np.float64)

    # one layout: numpy's reductions in rigid_body_modes add in an order that depends on it
    X = np.ascontiguousarray(coords, dtype=np.float64)
    n_all = total(np.array([float(X.shape[0])]))[0]
    B = rigid_body_modes(X - total(_column_sums(X)) / max(n_all, 1.0))
    Q = np.zeros_like(B)
    for k in range(B.shape[1]):
        v = B[:, k].copy()
        for _ in range(2):
            coef = total(_dots(Q, k, v))
            for j in range(k):  # elementwise: no sum whose order could vary
                v -= coef[j] * Q[:, j]
        norm = float(np.sqrt(total(_dots(v[:, None], 1, v))[0]))
        Q[:, k] = v / norm if norm > 0.0 else 0.0
    return Q


def near_null_candidates(B: np.ndarray | None, geometry: tuple | None, n: int) -> tuple[np.ndarray | None, bool]:
    """The near-null space an AMG backend hands to its set-up for a matrix of size n, and whether its rows
    are 3 dofs per node: the rigid-body modes of ``geometry`` = (points, dofs) when given (set by
    ``set_geometry``), else ``B`` (set by ``set_near_null_space``; full size 3 nnode), else (None, True)."""
    nodal = True
    if geometry is not None:
        B, nodal = rigid_body_modes(*geometry), geometry[1] is None
    if B is not None and B.shape[0] != n:
        raise ValueError(f"the near-null space has {B.shape[0]} rows, the matrix {n}")
    return B, nodal


# ----------------------------------------------------------------------------- common layer


def _near_null_array(B) -> np.ndarray | None:
    """B as a C-contiguous float64 (n, k) array with k >= 1 (a vector is one column), checked finite."""
    if B is None:
        return None
    B = np.array(B, dtype=np.float64, order="C", ndmin=1)
    if B.ndim == 1:
        B = B[:, None]
    if B.ndim != 2 or B.shape[1] == 0:
        raise ValueError(f"the near-null space must have shape (n, k), k >= 1, got {B.shape}")
    if not np.isfinite(B).all():
        raise ValueError("the near-null space has non-finite entries")
    return B


def _as_csr(K) -> sp.csr_matrix:
    """Canonical float64 CSR view (or copy) of K, checked for shape, finiteness and empty rows."""
    if not sp.issparse(K):
        raise TypeError(f"the matrix must be a scipy sparse matrix, got {type(K).__name__}")
    if K.format != "csr" or K.dtype != np.float64:
        K = sp.csr_matrix(K, dtype=np.float64)
    if K.shape[0] != K.shape[1]:
        raise ValueError(f"the matrix must be square, got shape {K.shape}")
    if not K.has_canonical_format:
        K = K.copy()
        K.sum_duplicates()
    empty = np.flatnonzero(np.diff(K.indptr) == 0)
    if empty.size:
        raise SingularMatrixError(
            f"the matrix is singular: {empty.size} empty row(s), first {empty[:5].tolist()} "
            "(unconstrained or unconnected dofs?)"
        )
    if not np.isfinite(K.data).all():
        raise LinearSolverError("the matrix has non-finite entries")
    return K


class LinearSolver:
    """Interface shared by all backends.

    Attributes:
        name: backend name.
        direct: True for a factorisation, False for an iterative method.
        t_analyze, t_factor, t_solve: seconds of the last symbolic analysis (0 when reused), the
            last ``factorize`` call (analysis included) and the last ``solve_factorized`` call.
        n_analyses, n_factorizations: counters.
        residual: relative residual ||K x - b|| / ||b|| of the last solve.
        backward_error: ||K x - b|| / (||K||_F ||x|| + ||b||) of the last solve (see ``_check``).
    """

    name = "base"
    direct = True

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        """(available, version, note) of this backend here; ImportError / OSError: not installed."""
        raise NotImplementedError

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6):
        self.symmetric = symmetric
        self.check_tol = check_tol
        self.t_analyze = self.t_factor = self.t_solve = 0.0
        self.n_analyses = self.n_factorizations = 0
        self.residual = float("nan")
        self.backward_error = float("nan")
        self._K_norm: float | None = None
        self._K: sp.csr_matrix | None = None
        self._indptr: np.ndarray | None = None
        self._indices: np.ndarray | None = None
        self.near_null_space: np.ndarray | None = None

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name} symmetric={self.symmetric}>"

    def new_step(self) -> None:
        """A load step (or its retry after a cutback) begins. A backend whose analysis depends on the matrix
        values, not only on its pattern, analyses again at the step's first factorisation, so that a step's
        results do not depend on the steps before it (a resumed run repeats the uninterrupted one)."""

    #: whether threaded factorisations must give the same bits on every run (``[solver] reproducible``; only
    #: PARDISO has a faster mode that does not)
    reproducible = True

    def history(self) -> dict[str, np.ndarray]:
        """What a checkpoint keeps of this solver (keys ``linear.*``): the part of the sparsity pattern that
        depends on the steps before, so that a resumed run analyses the uninterrupted run's pattern. None
        for the serial backends (the serial model keeps its contact couplings itself)."""
        return {}

    def restore_history(self, arrays: dict[str, np.ndarray]) -> None:
        """The ``history`` of a checkpoint, for the factorisations to come."""

    def checkpoint(self) -> tuple[dict, dict]:
        """This solver's part of a checkpoint (``covcontact.observer.Checkpointed``): its history."""
        return self.history(), {}

    def restore(self, arrays: dict, meta: dict) -> None:
        self.restore_history({k: v for k, v in arrays.items() if k.startswith("linear.")})

    def reuse_pays(self) -> bool:
        """Whether the factorisation of the last analysed pattern costs enough forward and backward
        substitutions to be worth reusing as a preconditioner (``reuse_factorization = "auto"``). A backend
        that cannot tell says yes."""
        return True

    def same_pattern(self, K: sp.csr_matrix) -> bool:
        """Whether K has the sparsity pattern of the last analysis."""
        if self._indptr is None or self._indices is None or K.shape[0] + 1 != self._indptr.size:
            return False
        return np.array_equal(K.indptr, self._indptr) and np.array_equal(K.indices, self._indices)

    def factorize(self, K) -> None:
        """Factorise K (CSR), reusing the symbolic analysis when the pattern is unchanged."""
        K = _as_csr(K)
        t0 = time.perf_counter()
        self.t_analyze = 0.0
        if not self.same_pattern(K):
            self._analyze(K)
            self._indptr, self._indices = K.indptr.copy(), K.indices.copy()
            self.n_analyses += 1
            self.t_analyze = time.perf_counter() - t0
        self._K = None
        self._K_norm = None
        self._factor(K)
        self._K = K
        self.n_factorizations += 1
        self.t_factor = time.perf_counter() - t0

    def solve_factorized(self, b: np.ndarray) -> np.ndarray:
        """Solve with the last factorisation; b is (n,) or (n, nrhs)."""
        if self._K is None:
            raise LinearSolverError("factorize() must succeed before solve_factorized()")
        b = np.asarray(b, dtype=np.float64)
        if b.shape[0] != self._K.shape[0] or b.ndim > 2:
            raise ValueError(f"right-hand side of shape {b.shape} for a matrix of size {self._K.shape[0]}")
        t0 = time.perf_counter()
        x = self._solve(b)
        res = self._check(b, x)
        if self.direct and res > self.check_tol and np.isfinite(res):
            x = x + self._solve(b - self._K @ x)  # one step of iterative refinement
            res = self._check(b, x)
        self.t_solve = time.perf_counter() - t0
        if res > self.check_tol:
            raise SingularMatrixError(
                f"{self.name}: relative residual {res:.2e} > {self.check_tol:.0e} after the solve; "
                f"the matrix is singular or too ill-conditioned{self._diagnosis()}"
            )
        return x

    def set_precision(self, precision: str) -> None:
        """The precision of the factorisations to come (``[solver] factorization_precision``): only PARDISO
        has a single-precision one; the other backends factorise in double precision whatever is asked."""

    def precision_report(self) -> dict | None:
        """What the run's summary says about single-precision factorisations (None: none possible)."""
        return None

    def precondition(self, b: np.ndarray) -> np.ndarray:
        """The last factorisation applied to b as a preconditioner (GMRES of inexact Newton): the backend's
        plain solve, without the residual check (and, for a single-precision factorisation, without the
        refinement to double precision)."""
        return self._solve(b)

    def solve(self, K, b: np.ndarray) -> np.ndarray:
        """Factorise K and solve K x = b."""
        self.factorize(K)
        return self.solve_factorized(b)

    def set_geometry(self, points: np.ndarray, dofs: np.ndarray | None = None) -> None:
        """Node coordinates (nnode, 3) and the global dofs of the unknowns (used by cg-amg)."""

    def set_near_null_space(self, B: np.ndarray | None) -> None:
        """Near-null space (n, k) of the matrices to come, e.g. ``rigid_body_modes(X, constrained)``.

        Rows match the rows of the matrix handed to ``solve``/``factorize``; ``None`` forgets it. Stored
        in ``near_null_space``; only the AMG backend uses it (the direct backends ignore it).
        """
        self.near_null_space = _near_null_array(B)

    def close(self) -> None:
        """Release the factorisation and the analysis (the next ``factorize`` analyses afresh)."""
        self._release()
        self._K = None
        self._indptr = self._indices = None

    def _check(self, b: np.ndarray, x: np.ndarray) -> float:
        """The error measure compared with ``check_tol``.

        Normally the relative residual ||K x - b|| / ||b|| (also stored in ``residual``). On the very
        ill-conditioned tangents of thin shells (cond ~ 1e12) a correct, backward-stable solve can leave a
        relative residual of 1e-5; such a solve is accepted when its normwise backward error
        ||K x - b|| / (||K||_F ||x|| + ||b||) is below 1e-11 and the relative residual below 1e-2. A
        singular system with an inconsistent right-hand side keeps a relative residual of order one and
        is still rejected.
        """
        if not np.isfinite(x).all():
            raise SingularMatrixError(
                f"{self.name}: the solution has non-finite entries; the matrix is singular"
                f"{self._diagnosis()}"
            )
        assert self._K is not None
        nb = np.linalg.norm(b, axis=0)
        r = np.linalg.norm(self._K @ x - b, axis=0)
        self.residual = float(np.max(np.where(nb > 0, r / np.where(nb > 0, nb, 1.0), r)))
        nx = np.linalg.norm(x, axis=0)
        denom = self._frobenius() * nx + nb
        self.backward_error = float(np.max(np.where(denom > 0, r / np.where(denom > 0, denom, 1.0), r)))
        if self.residual > self.check_tol and self.residual <= 1e-2 and self.backward_error <= 1e-11:
            return self.backward_error
        return self.residual

    def _frobenius(self) -> float:
        """||K||_F of the factorised matrix (cached until the next factorisation), for backward errors."""
        if self._K_norm is None:
            assert self._K is not None
            self._K_norm = float(np.linalg.norm(self._K.data))
        return self._K_norm

    def _diagnosis(self) -> str:
        return ""

    # backend hooks
    def _release(self) -> None:
        pass

    def _analyze(self, K: sp.csr_matrix) -> None:
        pass

    def _factor(self, K: sp.csr_matrix) -> None:
        raise NotImplementedError

    def _solve(self, b: np.ndarray) -> np.ndarray:
        raise NotImplementedError
