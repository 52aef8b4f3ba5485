"""Linear solver backends registered in :mod:`covcontact.solvers.linear`: SuperLU, CHOLMOD, MUMPS and AMG (pyamg)
(PARDISO in :mod:`covcontact.solvers.pardiso_backend`, PETSc in :mod:`covcontact.solvers.petsc_backend`).

Each class implements the hooks of :class:`covcontact.solvers.linear.LinearSolver` (``_analyze``,
``_factor``, ``_solve``, ``_release``) and a static ``probe()`` -> (available, version, note) that imports
its optional package (ImportError / OSError mean "not installed"). Optional packages are imported only
inside ``probe`` and the solver, so importing this module is cheap.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .linear import (
    LinearSolver,
    LinearSolverError,
    SingularMatrixError,
    _as_csr,
    available,
    make_solver,
    near_null_candidates,
)

# ----------------------------------------------------------------------------- SuperLU


class SuperLUSolver(LinearSolver):
    """SciPy SuperLU. SuperLU offers no reuse of the analysis: every factorisation is complete.

    K^T is handed over as CSC (a free view of the CSR arrays) and solved transposed.
    """

    name = "superlu"

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        import scipy

        return True, scipy.__version__, "SciPy SuperLU (symmetric mode for symmetric matrices)"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, diag_pivot_thresh: float = 1e-3):
        super().__init__(symmetric, check_tol)
        self.diag_pivot_thresh = diag_pivot_thresh
        self._lu: Any = None

    def _factor(self, K: sp.csr_matrix) -> None:
        Kt = sp.csc_matrix((K.data, K.indices, K.indptr), shape=K.shape)
        self._lu = None
        try:
            if self.symmetric:
                self._lu = sla.splu(Kt, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=self.diag_pivot_thresh,
                                    options={"SymmetricMode": True})
            else:
                self._lu = sla.splu(Kt)
        except RuntimeError as exc:
            raise SingularMatrixError(f"superlu: {exc}") from exc

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return self._lu.solve(np.ascontiguousarray(b), trans="T")

    def _release(self) -> None:
        self._lu = None


# ----------------------------------------------------------------------------- CHOLMOD


class CholmodSolver(LinearSolver):
    """CHOLMOD supernodal Cholesky with the symbolic analysis kept per pattern.

    A matrix that is not positive definite is factorised by the ``fallback`` backend instead
    (``last_backend`` tells which one solved).
    """

    name = "cholmod"

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        import sksparse
        import sksparse.cholmod

        return True, getattr(sksparse, "__version__", ""), "CHOLMOD Cholesky, symmetric only"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6):
        if not symmetric:
            raise ValueError("cholmod factorises symmetric matrices only")
        super().__init__(symmetric, check_tol)
        self._factor_obj: Any = None
        self._fallback: LinearSolver | None = None
        self.last_backend = self.name

    def _analyze(self, K: sp.csr_matrix) -> None:
        from sksparse.cholmod import analyze

        self._factor_obj = analyze(sp.csc_matrix((K.data, K.indices, K.indptr), shape=K.shape))

    def _factor(self, K: sp.csr_matrix) -> None:
        from sksparse.cholmod import CholmodNotPositiveDefiniteError

        self.last_backend = self.name
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                self._factor_obj.cholesky_inplace(sp.csc_matrix((K.data, K.indices, K.indptr), shape=K.shape))
            return
        except (CholmodNotPositiveDefiniteError, Warning):
            pass
        if self._fallback is None:
            nxt = "mumps" if "mumps" in available() else "superlu"
            self._fallback = make_solver(nxt, symmetric=True, check_tol=self.check_tol)
        self._fallback.factorize(K)
        self.last_backend = self._fallback.name

    def _solve(self, b: np.ndarray) -> np.ndarray:
        if self.last_backend != self.name:
            assert self._fallback is not None
            return self._fallback._solve(b)
        return self._factor_obj(b)


# ----------------------------------------------------------------------------- MUMPS


class MumpsSolver(LinearSolver):
    """MUMPS (python-mumps): LDL^T with pivoting for symmetric matrices, LU otherwise."""

    name = "mumps"

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        import mumps

        if not hasattr(mumps, "Context"):
            return False, "", "the installed 'mumps' module is not python-mumps"
        return True, getattr(mumps, "__version__", ""), "MUMPS LDL^T / LU"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, ordering: str = "auto"):
        super().__init__(symmetric, check_tol)
        import mumps

        self._mumps = mumps
        self.ordering = ordering
        self._ctx = mumps.Context()
        self._fresh = False

    def _set(self, K: sp.csr_matrix) -> None:
        self._ctx.set_matrix(K, symmetric=self.symmetric)

    def _analyze(self, K: sp.csr_matrix) -> None:
        self._set(K)
        try:
            self._ctx.analyze(ordering=self.ordering)
        except self._mumps.MUMPSError as exc:
            raise LinearSolverError(f"mumps analysis: {exc}") from exc
        self._fresh = True

    def _factor(self, K: sp.csr_matrix) -> None:
        if not self._fresh:
            self._set(K)
        self._fresh = False
        try:
            self._ctx.factor(reuse_analysis=True)
        except self._mumps.MUMPSError as exc:
            cls = SingularMatrixError if exc.error in (-6, -10) else LinearSolverError
            raise cls(f"mumps factorisation: {exc}") from exc

    def _solve(self, b: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(self._ctx.solve(b))


# ----------------------------------------------------------------------------- AMG


class AMGSolver(LinearSolver):
    """pyamg smoothed aggregation as a preconditioner; CG for symmetric matrices (GMRES if CG does
    not converge, e.g. indefinite ones) and GMRES for non-symmetric ones. ``factorize`` builds the
    hierarchy; ``rtol`` is the relative residual reached by each solve; ``iterations`` counts the Krylov
    iterations of the last solve.

    Near-null space: ``set_near_null_space(B)`` (e.g. ``rigid_body_modes(X, constrained)`` for the full
    matrix with eliminated Dirichlet dofs) or ``set_geometry(points, dofs)``, whichever came last; without
    either pyamg's default (constants). The hierarchy is rebuilt when it changes. ``blocksize``:
    the matrix is handed to pyamg as BSR with 3 x 3 node blocks (aggregates of whole nodes) when it is
    None and a near-null space of full size 3 nnode is set, or when it is 3 (for a size divisible by 3);
    1 keeps CSR.
    """

    name = "cg-amg"
    direct = False

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        import pyamg

        return True, pyamg.__version__, "iterative: CG/GMRES + smoothed-aggregation AMG"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, rtol: float = 1e-10,
                 maxiter: int = 2000, blocksize: int | None = None):
        super().__init__(symmetric, max(check_tol, 10 * rtol))
        if blocksize not in (None, 1, 3):
            raise ValueError(f"blocksize must be None, 1 or 3, got {blocksize!r}")
        self.rtol, self.maxiter, self.blocksize = rtol, maxiter, blocksize
        self._geometry: tuple[np.ndarray, np.ndarray | None] | None = None
        self._ml: Any = None
        self._stale = False  # the near-null space changed since the hierarchy was built
        self.iterations = 0

    def set_geometry(self, points: np.ndarray, dofs: np.ndarray | None = None) -> None:
        self._geometry = (np.asarray(points, dtype=np.float64), dofs)
        self.near_null_space = None
        self._stale = True

    def set_near_null_space(self, B: np.ndarray | None) -> None:
        super().set_near_null_space(B)
        self._geometry = None
        self._stale = True

    def _factor(self, K: sp.csr_matrix) -> None:
        import pyamg

        B, nodal = near_null_candidates(self.near_null_space, self._geometry, K.shape[0])
        bs = self.blocksize or (3 if B is not None and nodal else 1)
        if K.shape[0] % bs:
            bs = 1
        A = K.tobsr(blocksize=(3, 3)) if bs == 3 else K  # BSR: aggregates of whole nodes
        sym = "symmetric" if self.symmetric else "nonsymmetric"
        self._ml = pyamg.smoothed_aggregation_solver(
            A, B=None if B is None else B.copy(), BH=None if B is None or self.symmetric else B.copy(),
            symmetry=sym, max_coarse=500 // bs,  # pyamg counts blocks: the coarsest level has <= 500 dofs
            coarse_solver="splu",  # the default dense pseudo-inverse costs minutes on a stalled 2500-dof level
            # no smoothing of the near-null space before aggregation: on a Hertz-ball tangent (36,627 dofs) it took
            # half the set-up (0.45 of 0.9 s) and saved 6 % of the CG iterations (docs/performance.md)
            improve_candidates=None,
        )
        self._stale = False

    def preconditioner_fits(self, K) -> bool:
        """Whether the hierarchy of the last ``factorize`` can precondition K: same size and sparsity pattern
        (a new contact coupling needs a new one)."""
        return self._ml is not None and not self._stale and self._K is not None and self.same_pattern(_as_csr(K))

    def solve_preconditioned(self, K, b: np.ndarray, rtol: float, maxiter: int | None = None
                             ) -> tuple[np.ndarray | None, int]:
        """Solve K x = b to the relative residual ``rtol`` by CG (GMRES for a non-symmetric solver) with the
        hierarchy of the last factorisation (of K or an earlier K of the same size) as preconditioner: (x, its),
        x None when it does not converge within ``maxiter`` iterations (default: the solver's)."""
        maxiter = self.maxiter if maxiter is None else maxiter
        if self._ml is None or self._stale or self._K is None or K.shape != self._K.shape:
            return None, 0
        M = self._ml.aspreconditioner(cycle="V")
        count = [0]

        def tick(_):
            count[0] += 1

        if self.symmetric:
            x, info = sla.cg(K, b, rtol=rtol, atol=0.0, maxiter=maxiter, M=M, callback=tick)
        else:
            x, info = sla.gmres(K, b, rtol=rtol, atol=0.0, restart=min(50, maxiter), M=M, callback=tick,
                                maxiter=max(1, maxiter // 50), callback_type="pr_norm")
        if info != 0 or not np.isfinite(x).all():
            return None, count[0]
        return x, count[0]

    def _solve(self, b: np.ndarray) -> np.ndarray:
        if b.ndim == 2:
            return np.stack([self._solve(b[:, j]) for j in range(b.shape[1])], axis=1)
        K = self._K
        assert K is not None
        if self._stale:  # a new near-null space since factorize: rebuild the hierarchy
            self._factor(K)
        M = self._ml.aspreconditioner(cycle="V")
        nb = np.linalg.norm(b)
        count = [0]

        def tick(_):
            count[0] += 1

        for accel in ["cg", "gmres"] if self.symmetric else ["gmres"]:
            x = np.zeros_like(b)
            for k in range(3):  # restart with a tighter tolerance if the true residual lags behind
                tol = self.rtol * 0.1**k
                if accel == "cg":
                    x, info = sla.cg(K, b, x0=x, rtol=tol, atol=0.0, maxiter=self.maxiter, M=M, callback=tick)
                else:
                    x, info = sla.gmres(K, b, x0=x, rtol=tol, atol=0.0, restart=50, M=M, callback=tick,
                                     maxiter=max(1, self.maxiter // 50), callback_type="pr_norm")
                if not np.isfinite(x).all():
                    break
                if np.linalg.norm(K @ x - b) <= self.rtol * nb:
                    self.iterations = count[0]
                    return x
                if info != 0:  # no convergence (or breakdown): try the next method
                    break
        self.iterations = count[0]
        raise LinearSolverError(
            f"cg-amg: no convergence to {self.rtol:.0e} within {count[0]} iterations "
            "(singular, strongly indefinite or badly scaled matrix?)"
        )
