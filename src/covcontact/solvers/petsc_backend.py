"""PETSc backends (petsc4py): MUMPS LU / LDL^T and CG/GMRES + GAMG, serial or distributed over MPI.

- ``petsc``: KSP preonly + MUMPS; Cholesky (MUMPS LDL^T with pivoting, so indefinite tangents work) for
  symmetric matrices, LU otherwise (friction).
- ``petsc-gamg``: CG (GMRES if CG fails, and for non-symmetric matrices) preconditioned by PETSc's
  smoothed-aggregation GAMG with the rigid-body modes as near-null space.

Both accept a SciPy CSR matrix (one process, the interface of every backend) or the
:class:`covcontact.parallel.model.DistMatrix` of a distributed run: each rank's share of the tangent is
summed into one MPIAIJ matrix (block size 3) through PETSc's COO interface; the structure is set once per
pattern (``setPreallocationCOO``) and the values every iteration (``setValuesCOO``). The contact entries
keep a structure that only grows (entries of lost contacts stay as zeros), so the symbolic factorisation is
redone only when a new coupling appears. The solution is gathered to every rank.

Any PETSc option can be added with the prefix ``covcontact_`` through ``PETSC_OPTIONS`` (for example
``-covcontact_pc_factor_mat_solver_type superlu_dist`` or ``-covcontact_ksp_monitor``).
"""

from __future__ import annotations

import contextlib
import sys
import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from .linear import (
    LinearSolver,
    LinearSolverError,
    SingularMatrixError,
)

PREFIX = "covcontact_"


#: the GAMG options each petsc-gamg solver sets from its parameters (threshold, smooths, level_pc)
_GAMG_OPTIONS = ("pc_gamg_threshold", "pc_gamg_agg_nsmooths", "mg_levels_pc_type")
_USER: set[str] | None = None


def _user_options(opts) -> set[str]:
    """The ``_GAMG_OPTIONS`` that PETSC_OPTIONS or the command line set, read before covcontact writes any."""
    global _USER
    if _USER is None:
        _USER = {name for name in _GAMG_OPTIONS if opts.hasName(PREFIX + name)}
    return _USER


def petsc() -> Any:
    """The petsc4py PETSc module, initialised once without the command line (``PETSC_OPTIONS`` applies)."""
    from mpi4py import MPI  # noqa: F401  (mpi4py owns MPI_Init / MPI_Finalize)

    if "petsc4py.PETSc" not in sys.modules:
        import petsc4py

        petsc4py.init([sys.argv[0] if sys.argv and sys.argv[0] else "covcontact"])
    from petsc4py import PETSc

    return PETSc


def _version() -> str:
    import petsc4py

    return petsc4py.__version__


class _Operator:
    """One PETSc matrix, its COO structure and a KSP (one per structure)."""

    def __init__(self, comm, n_local: int, n_global: int, bs: int, rows: np.ndarray, cols: np.ndarray,
                 symmetric: bool):
        P = petsc()
        self.P = P
        self.comm = comm
        self.A = P.Mat().create(comm=comm)
        self.A.setSizes(((n_local, n_global), (n_local, n_global)), bsize=bs)
        self.A.setType(P.Mat.Type.AIJ)
        self.A.setPreallocationCOO(rows.astype(P.IntType), cols.astype(P.IntType))
        self.symmetric = symmetric
        self.ksp = None
        self.b = self.A.createVecLeft()
        self.x = self.A.createVecRight()
        self._all = None
        self._twin = None

    def set_values(self, v: np.ndarray, A=None) -> None:
        """The values of the COO entries, into A (default: this operator's matrix; or its ``twin``)."""
        A = self.A if A is None else A
        A.setValuesCOO(np.ascontiguousarray(v, dtype=self.P.ScalarType), addv=self.P.InsertMode.INSERT_VALUES)
        if self.symmetric:
            A.setOption(self.P.Mat.Option.SYMMETRIC, True)

    def twin(self):
        """A second matrix of the same COO structure (kept: a Krylov solve on a newer tangent than the one the
        preconditioner was built from sets its values, without a second COO analysis, 0.5 s at 2e5 dofs)."""
        if self._twin is None:
            self._twin = self.A.duplicate(copy=False)  # PETSc keeps the COO map in the duplicate
        return self._twin

    def gather(self, x) -> np.ndarray:
        """The whole vector x on every rank (PETSc order)."""
        if self.comm.getSize() == 1:
            return x.getArray(readonly=True).copy()
        if self._all is None:
            self._all = self.P.Scatter.toAll(x)
        sc, xall = self._all
        sc.scatter(x, xall, addv=self.P.InsertMode.INSERT_VALUES, mode=self.P.ScatterMode.FORWARD)
        return xall.getArray(readonly=True).copy()

    def load(self, b: np.ndarray, layout=None) -> None:
        """The right-hand side b (all dofs, replicated): this rank's rows of it, in PETSc order for a
        distributed ``layout``."""
        self.b.getArray()[:] = b if layout is None else b[layout.owned]

    def result(self, layout=None) -> np.ndarray:
        """The solution x, whole on every rank (in the dof order of a distributed ``layout``)."""
        xp = self.gather(self.x)
        if layout is None:
            return xp
        x = np.empty(layout.n_dofs)
        x[layout.from_petsc] = xp
        return x

    def destroy(self) -> None:
        for obj in (self.ksp, self.A, self._twin, self.b, self.x):
            if obj is not None:
                obj.destroy()
        if self._all is not None:
            for obj in self._all:
                obj.destroy()
        self.ksp = None


class PetscSolver(LinearSolver):
    """PETSc + MUMPS direct solver (``petsc``); serial on SciPy matrices, distributed on DistMatrix.

    Options: ``icntl`` dict of MUMPS ICNTL values (default {14: 50}: 50 % extra workspace).
    """

    name = "petsc"
    direct = True
    distributed = True

    @staticmethod
    def run_strategy():
        """The strategy of a run on this solver: the distributed model, one share per MPI rank."""
        from ..parallel.run import DistributedRun

        return DistributedRun()

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        P = petsc()
        if not P.Sys.hasExternalPackage("mumps"):
            return False, _version(), "PETSc built without MUMPS"
        return True, _version(), "PETSc + MUMPS LDL^T / LU; distributed under mpiexec"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, icntl: dict | None = None):
        super().__init__(symmetric, check_tol)
        self.P = petsc()
        self.icntl = {14: 50} if icntl is None else dict(icntl)
        self._op: _Operator | None = None
        self._dist = None  # the DistMatrix of the last factorisation
        self._structure = None
        self._ckey: np.ndarray | None = None
        self._values: np.ndarray | None = None  # the COO values of a distributed matrix (_dist_values)
        self._restored: np.ndarray | None = None  # contact keys from a checkpoint, for the next factorize
        self.iterations = 0  # Krylov iterations of the last solve
        self.krylov_iterations = 0  # and of all solves
        self.ranks = 1

    # -- KSP set-up (backend specific) ----------------------------------------------------------
    def _setup_ksp(self, op: _Operator) -> None:
        P = self.P
        ksp = P.KSP().create(comm=op.comm)
        ksp.setOptionsPrefix(PREFIX)
        ksp.setOperators(op.A)
        ksp.setType(P.KSP.Type.PREONLY)
        pc = ksp.getPC()
        pc.setType(P.PC.Type.CHOLESKY if self.symmetric else P.PC.Type.LU)
        pc.setFactorSolverType("mumps")
        pc.setFactorSetUpSolverType()
        F = pc.getFactorMatrix()
        for k, v in self.icntl.items():
            F.setMumpsIcntl(int(k), int(v))
        ksp.setErrorIfNotConverged(False)
        ksp.setFromOptions()
        op.ksp = ksp

    def _factor_op(self) -> None:
        """Factorise (or set up the preconditioner of) the current values; raises on failure."""
        op = self._op
        assert op is not None
        if op.ksp is None:
            self._setup_ksp(op)
        else:
            op.ksp.getPC().setReusePreconditioner(False)
            op.ksp.setOperators(op.A)
        err = None
        try:
            op.ksp.setUp()
        except self.P.Error as exc:
            err = exc
        reason = self._pc_failure(op) or (str(err) if err is not None else "")
        if op.comm.getSize() > 1:  # one decision for all ranks
            reason = op.comm.tompi4py().bcast(reason, root=0)
        if reason:
            raise SingularMatrixError(f"{self.name}: factorisation failed ({reason}); the matrix is "
                                      "singular or too ill-conditioned")

    def _pc_failure(self, op: _Operator) -> str:
        pc = op.ksp.getPC()
        try:
            failed = int(pc.getFailedReason())
        except AttributeError:  # older petsc4py
            failed = 0
        if failed:
            info = ""
            try:
                info = f", MUMPS INFOG(1) = {pc.getFactorMatrix().getMumpsInfog(1)}"
            except (self.P.Error, AttributeError):
                pass
            return f"PC failed reason {failed}{info}"
        return ""

    def _ksp_solve(self, op: _Operator) -> None:
        op.x.set(0.0)
        op.ksp.solve(op.b, op.x)
        reason = op.ksp.getConvergedReason()
        self.iterations = op.ksp.getIterationNumber()
        self.krylov_iterations += self.iterations
        if reason < 0:
            raise SingularMatrixError(f"{self.name}: solve failed (KSP reason {reason}); singular matrix?")

    # -- serial interface (SciPy CSR, one process) ----------------------------------------------
    def _analyze(self, K: sp.csr_matrix) -> None:
        self._release()
        rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
        self._op = _Operator(self.P.COMM_SELF, K.shape[0], K.shape[0], self._serial_block(K.shape[0]), rows,
                             K.indices, self.symmetric)
        self._prepare_serial(K.shape[0])

    def _serial_block(self, n: int) -> int:
        """The block size of a serial matrix of size n."""
        return 1

    def _prepare_serial(self, n: int) -> None:
        pass

    def _factor(self, K: sp.csr_matrix) -> None:
        self._dist = None
        self._op.set_values(K.data)
        self._factor_op()

    def _solve(self, b: np.ndarray) -> np.ndarray:
        if b.ndim == 2:
            return np.stack([self._solve(b[:, j]) for j in range(b.shape[1])], axis=1)
        op = self._op
        op.load(b)
        self._ksp_solve(op)
        return op.result()

    def _release(self) -> None:
        if self._op is not None:
            self._op.destroy()
        self._op = None
        self._structure = None
        self._ckey = None
        self._values = None

    # -- distributed interface (DistMatrix) -----------------------------------------------------
    def factorize(self, K) -> None:
        if not hasattr(K, "structure"):
            return super().factorize(K)
        if not K.eliminated:
            raise LinearSolverError("a distributed tangent must be eliminated before the solve")
        t0 = time.perf_counter()
        self.t_analyze = 0.0
        st, lay = K.structure, K.layout
        n = lay.n_dofs
        if self._restored is not None:  # a resumed run: the contact entries of the uninterrupted run's matrix
            self._structure, self._ckey, self._restored = st, self._restored, None
        same, ukey, inv, cv = self._dist_pattern(K)
        comm = K.comm
        if not same:
            ckey = ukey
            if self._structure is st and self._ckey is not None:
                union = np.union1d(self._ckey, ukey)
                if union.size <= 2 * ukey.size + 1000 or union.size == self._ckey.size:
                    ckey = union
            self._release()
            rows = np.concatenate([st.rows, st.diag, ckey // n])
            cols = np.concatenate([st.cols, st.diag, ckey % n])
            self._op = _Operator(self.P.Comm(comm), lay.hi - lay.lo, n, 3, rows, cols, self.symmetric)
            self._structure, self._ckey = st, ckey
            self._prepare_dist(K)
            self.n_analyses += 1
            self.t_analyze = time.perf_counter() - t0
        self.ranks = comm.size
        self._K = None
        self._dist = K
        self._op.set_values(self._dist_values(K, ukey, inv, cv))
        self._factor_op()
        self.n_factorizations += 1
        self.t_factor = time.perf_counter() - t0

    def history(self) -> dict[str, np.ndarray]:
        """The contact entries of the distributed matrix's structure (this rank's keys, row n + column): they
        grow with the contacts met, entries of lost contacts staying as zeros."""
        return {} if self._ckey is None or self._dist is None else {"linear.contact_keys": self._ckey.copy()}

    def restore_history(self, arrays: dict[str, np.ndarray]) -> None:
        keys = arrays.get("linear.contact_keys")
        self._restored = None if keys is None else np.asarray(keys, dtype=np.int64)

    def _dist_pattern(self, K) -> tuple[bool, np.ndarray, np.ndarray, np.ndarray]:
        """Whether the DistMatrix K fits the current matrix's structure (on every rank), and its unique
        contact keys (row n + column), the map of its contact entries onto them and their values."""
        ci, cj, cv = K.contact_triplets()
        key = ci.astype(np.int64) * K.layout.n_dofs + cj
        ukey, inv = np.unique(key, return_inverse=True)
        same = self._op is not None and self._structure is K.structure and self._ckey is not None
        if same:
            pos = np.searchsorted(self._ckey, ukey)
            same = bool(np.all(pos < self._ckey.size)) and bool(np.array_equal(self._ckey[np.minimum(
                pos, self._ckey.size - 1)], ukey))
        if K.comm.size > 1:
            same = K.comm.allreduce(same, op=_mpi_op("LAND"))
        return same, ukey, inv, cv

    def _dist_values(self, K, ukey: np.ndarray, inv: np.ndarray, cv: np.ndarray) -> np.ndarray:
        """The values of K on the current COO structure (body entries, unit diagonal, contact keys ``_ckey``: a
        superset of K's ``ukey``), in a buffer kept for that structure (no new pages at each solve)."""
        st, ckey = K.structure, self._ckey
        nb, nd = st.keep.size, st.diag.size
        if self._values is None or self._values.size != nb + nd + ckey.size:
            self._values = np.empty(nb + nd + ckey.size)
        v = self._values
        K.body_values(out=v[:nb])
        v[nb:nb + nd] = 1.0
        pos = np.searchsorted(ckey, ukey)
        v[nb + nd:] = np.bincount(pos[inv.ravel()], weights=cv, minlength=ckey.size)
        return v

    def _prepare_dist(self, K) -> None:
        pass

    def solve_factorized(self, b: np.ndarray) -> np.ndarray:
        if self._dist is None:
            return super().solve_factorized(b)
        b = np.asarray(b, dtype=np.float64)
        K = self._dist
        if b.shape != (K.shape[0],):
            raise ValueError(f"right-hand side of shape {b.shape} for a distributed matrix of size {K.shape[0]}")
        t0 = time.perf_counter()
        op, lay = self._op, K.layout
        op.load(b, lay)
        err = ""
        try:
            self._ksp_solve(op)
            res = self._dist_check(op)
            if self.direct and res > self.check_tol and np.isfinite(res):  # one step of refinement
                x0 = op.x.copy()
                r = op.b.duplicate()
                op.A.mult(x0, r)
                r.aypx(-1.0, op.b)
                b0 = op.b.copy()
                op.b.getArray()[:] = r.getArray(readonly=True)
                self._ksp_solve(op)
                op.x.axpy(1.0, x0)
                op.b.getArray()[:] = b0.getArray(readonly=True)
                for v in (x0, r, b0):
                    v.destroy()
                res = self._dist_check(op)
            if not res <= self.check_tol:
                err = (f"{self.name}: relative residual {res:.2e} > {self.check_tol:.0e} after the solve; the "
                       "matrix is singular or too ill-conditioned")
        except LinearSolverError as exc:
            err = str(exc)
        err = K.comm.bcast(err, root=0) if K.comm.size > 1 else err  # one decision for all ranks
        if err:
            raise (LinearSolverError if "no convergence" in err else SingularMatrixError)(err)
        x = op.result(lay)
        self.t_solve = time.perf_counter() - t0
        return x

    def _dist_check(self, op: _Operator) -> float:
        """Relative residual (or backward error, as in LinearSolver._check) of the PETSc solve."""
        P = self.P
        nx = op.x.norm()
        if not np.isfinite(nx):
            raise SingularMatrixError(f"{self.name}: the solution has non-finite entries; the matrix is singular")
        r = op.b.duplicate()
        op.A.mult(op.x, r)
        r.axpy(-1.0, op.b)
        nr, nb = r.norm(), op.b.norm()
        r.destroy()
        self.residual = nr / nb if nb > 0 else nr
        if self._K_norm is None:
            self._K_norm = op.A.norm(P.NormType.FROBENIUS)
        denom = self._K_norm * nx + nb
        self.backward_error = nr / denom if denom > 0 else nr
        if self.residual > self.check_tol and self.residual <= 1e-2 and self.backward_error <= 1e-11:
            return self.backward_error
        return self.residual

    def close(self) -> None:
        super().close()
        self._dist = None

    def __del__(self):
        with contextlib.suppress(Exception):  # interpreter shutdown
            self._release()


def _mpi_op(name: str):
    from mpi4py import MPI

    return getattr(MPI, name)
