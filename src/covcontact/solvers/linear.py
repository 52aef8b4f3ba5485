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

from .krylov import gmres_right  # noqa: F401  (part of this module's interface)
from .nullspace import (  # noqa: F401  (part of this module's interface)
    _near_null_array,
    near_null_candidates,
    rigid_body_basis,
    rigid_body_modes,
)


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
    "petsc-gamg": Backend("petsc_gamg", "PetscGAMGSolver", auto=False),
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


# ----------------------------------------------------------------------------- common layer


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
