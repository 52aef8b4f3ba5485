"""PETSc's CG (or GMRES) preconditioned by GAMG with the rigid-body modes (``petsc-gamg``), serial or
distributed over MPI; the PETSc set-up it shares with the direct ``petsc`` solver is in
:mod:`covcontact.solvers.petsc_backend`."""

from __future__ import annotations

import numpy as np

from .linear import LinearSolverError, _as_csr, near_null_candidates, rigid_body_basis
from .petsc_backend import _GAMG_OPTIONS, PREFIX, PetscSolver, _Operator, _user_options, _version, petsc


class PetscGAMGSolver(PetscSolver):
    """PETSc CG (GMRES for non-symmetric matrices, or when CG fails) + GAMG (``petsc-gamg``).

    The near-null space is the six rigid-body modes: from the node coordinates of a distributed run, or
    from ``set_near_null_space`` / ``set_geometry`` for a SciPy matrix. ``rtol``: relative residual of each
    solve; ``maxiter``; ``threshold``: GAMG's strength threshold; ``smooths``: smoothing steps of the
    prolongator (0: plain aggregation); ``level_pc``: the preconditioner of the Chebyshev smoother on each level
    (``pbjacobi``: the inverse diagonal node blocks). ``PETSC_OPTIONS`` with the prefix ``covcontact_``
    overrides each of them.
    """

    name = "petsc-gamg"
    direct = False

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        petsc()
        return True, _version(), "iterative: PETSc CG/GMRES + GAMG with rigid-body modes; distributed under mpiexec"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, rtol: float = 1e-10,
                 maxiter: int = 2000, threshold: float = 0.01, smooths: int = 0, level_pc: str = "pbjacobi"):
        super().__init__(symmetric, max(check_tol, 10 * rtol))
        self.rtol, self.maxiter, self.threshold, self.smooths = rtol, maxiter, threshold, smooths
        self.level_pc = level_pc
        self._geometry: tuple[np.ndarray, np.ndarray | None] | None = None
        self._near = None

    def set_geometry(self, points: np.ndarray, dofs: np.ndarray | None = None) -> None:
        self._geometry = (np.asarray(points, dtype=np.float64), dofs)
        self.near_null_space = None
        self._indptr = None  # a new near-null space: set up again

    def set_near_null_space(self, B: np.ndarray | None) -> None:
        super().set_near_null_space(B)
        self._geometry = None
        self._indptr = None

    def _serial_block(self, n: int) -> int:
        B, nodal = near_null_candidates(self.near_null_space, self._geometry, n)
        return 3 if B is not None and nodal and n % 3 == 0 else 1  # aggregates of whole nodes

    def _prepare_serial(self, n: int) -> None:
        self._near = None
        B, _ = near_null_candidates(self.near_null_space, self._geometry, n)
        if B is None:
            return
        P = self.P
        Q, _ = np.linalg.qr(B)
        vecs = [P.Vec().createWithArray(np.ascontiguousarray(Q[:, k]), comm=P.COMM_SELF) for k in range(Q.shape[1])]
        self._near = P.NullSpace().create(vectors=vecs, comm=P.COMM_SELF)
        self._op.A.setNearNullSpace(self._near)

    def _prepare_dist(self, K) -> None:
        P = self.P
        coords = K.layout.owned_coordinates()
        self._near = None
        if coords is None:
            return
        # the rigid-body modes, orthonormalised the same way on every run (rigid_body_basis); PETSc's own
        # MatNullSpaceCreateRigidBody gave modes that differed in the last bit from run to run
        from ..parallel.comm import sum_all

        basis = rigid_body_basis(coords, lambda a: sum_all(K.comm, a))
        self._near_columns = [np.ascontiguousarray(basis[:, k]) for k in range(basis.shape[1])]
        vecs = [P.Vec().createWithArray(col, size=(col.size, P.DECIDE), bsize=3, comm=self._op.comm)
                for col in self._near_columns]
        self._near = P.NullSpace().create(vectors=vecs, comm=self._op.comm)
        self._op.A.setNearNullSpace(self._near)

    def _setup_ksp(self, op: _Operator, method: str | None = None) -> None:
        P = self.P
        method = method or ("cg" if self.symmetric else "gmres")
        ksp = P.KSP().create(comm=op.comm)
        ksp.setOptionsPrefix(PREFIX)
        ksp.setOperators(op.A)
        ksp.setType(method)
        if method == "gmres":
            ksp.setGMRESRestart(100)
            ksp.setPCSide(P.PC.Side.RIGHT)  # the unpreconditioned residual is what rtol measures
        ksp.setNormType(P.KSP.NormType.UNPRECONDITIONED)
        ksp.setTolerances(rtol=self.rtol, atol=0.0, max_it=self.maxiter)
        pc = ksp.getPC()
        pc.setType(P.PC.Type.GAMG)
        # this solver's choices, unless PETSC_OPTIONS sets them (they stay in PETSc's options database until
        # the hierarchy is built, so each solver writes its own): plain aggregation by default (a quarter of
        # the set-up, cheaper cycles), Chebyshev on the inverse node blocks (3 x 3; the modes' blocks on
        # coarse levels): ~20 % fewer CG iterations (docs/performance.md)
        opts = P.Options()
        for name, value in zip(_GAMG_OPTIONS, (self.threshold, self.smooths, self.level_pc)):
            if name not in _user_options(opts):
                opts.setValue(PREFIX + name, value)
        ksp.setErrorIfNotConverged(False)
        ksp.setFromOptions()
        op.ksp = ksp
        self.method = method

    def _pc_failure(self, op: _Operator) -> str:
        return ""

    def preconditioner_fits(self, K) -> bool:
        """Whether the hierarchy of the last ``factorize`` can precondition K: same size and sparsity pattern
        (a new contact coupling needs a new one); collective for a distributed K."""
        if hasattr(K, "structure"):
            return self._dist is not None and K.shape == self._dist.shape and self._dist_pattern(K)[0]
        return self._K is not None and self._dist is None and self.same_pattern(_as_csr(K))

    def solve_preconditioned(self, K, b: np.ndarray, rtol: float, maxiter: int | None = None
                             ) -> tuple[np.ndarray | None, int]:
        """Solve K x = b (SciPy, one process, or distributed) to the relative residual ``rtol`` by CG (GMRES for a
        non-symmetric solver) preconditioned by the GAMG hierarchy of the last ``factorize`` (of K or an earlier
        matrix of the same size, whose hierarchy is kept): (x, its), x None when it does not converge within
        ``maxiter`` iterations (default: the solver's)."""
        op = self._op
        dist = hasattr(K, "structure")
        last = self._dist if dist else self._K
        if op is None or op.ksp is None or last is None or K.shape != last.shape:
            return None, 0
        layout = K.layout if dist else None
        A = op.A  # K's own matrix for the Krylov method (the preconditioner keeps the old one)
        if K is not last and dist:
            same, ukey, inv, cv = self._dist_pattern(K)
            if not same:
                return None, 0
            A = op.twin()
            op.set_values(self._dist_values(K, ukey, inv, cv), A)
        elif K is not last:  # the pattern of the last factorisation (preconditioner_fits): its COO order
            A = op.twin()
            op.set_values(_as_csr(K).data, A)
        ksp = op.ksp
        try:
            ksp.getPC().setReusePreconditioner(True)
            ksp.setOperators(A, op.A)
            ksp.setTolerances(rtol=rtol, max_it=self.maxiter if maxiter is None else maxiter)
            op.load(b, layout)
            op.x.set(0.0)
            ksp.setInitialGuessNonzero(False)
            ksp.solve(op.b, op.x)
            its, reason = ksp.getIterationNumber(), ksp.getConvergedReason()
            x = op.result(layout)
        finally:
            ksp.setOperators(op.A, op.A)
            ksp.setTolerances(rtol=self.rtol, max_it=self.maxiter)
        self.iterations = its
        self.krylov_iterations += its
        if reason < 0 or not np.isfinite(x).all():
            return None, its
        return x, its

    def _ksp_solve(self, op: _Operator) -> None:
        nb = op.b.norm()
        tries = ["cg", "gmres"] if op.ksp.getType() == "cg" else ["gmres"]
        total = 0
        for method in tries:
            if op.ksp.getType() != method:
                op.ksp.destroy()
                self._setup_ksp(op, method)
                op.ksp.setUp()
            op.x.set(0.0)
            op.ksp.setInitialGuessNonzero(False)
            for k in range(3):  # tighter tolerance if the true residual lags behind the recursive one
                op.ksp.setTolerances(rtol=self.rtol * 0.1**k)
                op.ksp.solve(op.b, op.x)
                op.ksp.setInitialGuessNonzero(True)
                total += op.ksp.getIterationNumber()
                reason = op.ksp.getConvergedReason()
                r = op.b.duplicate()
                op.A.mult(op.x, r)
                r.axpy(-1.0, op.b)
                nr = r.norm()
                r.destroy()
                if np.isfinite(nr) and nr <= self.rtol * nb:
                    self.iterations = total
                    self.krylov_iterations += total
                    op.ksp.setTolerances(rtol=self.rtol)
                    return
                if reason < 0 or not np.isfinite(nr):
                    break
        self.iterations = total
        self.krylov_iterations += total
        op.ksp.setTolerances(rtol=self.rtol)
        raise LinearSolverError(f"{self.name}: no convergence to {self.rtol:.0e} within {total} iterations "
                                "(singular, strongly indefinite or badly scaled matrix?)")
