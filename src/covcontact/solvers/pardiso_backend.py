"""MKL PARDISO (through the ``pypardiso`` package's MKL), registered in :mod:`covcontact.solvers.linear` as
``pardiso``: LDL^T / LU with the analysis kept while the pattern is unchanged, a factorisation in single or double
precision (single refined to double-precision accuracy by flexible GMRES), reproducible on several threads.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import glob
import os
import platform
import site
import sys
from functools import lru_cache

import numpy as np
import scipy.sparse as sp
from numba import njit

from .linear import LinearSolver, LinearSolverError, SingularMatrixError, gmres_right

_PARDISO_ERRORS = {
    -1: "input inconsistent",
    -2: "not enough memory",
    -3: "reordering problem",
    -4: "zero pivot (numerical factorisation or iterative refinement problem)",
    -5: "unclassified internal error",
    -6: "reordering failed",
    -7: "diagonal matrix is singular",
    -8: "32-bit integer overflow",
    -9: "not enough memory for out-of-core",
}


@lru_cache(maxsize=1)
def _mkl_runtime() -> ctypes.CDLL:
    """MKL's single dynamic library (mkl_rt), loaded once.

    Looked for where the ``mkl`` package that ``pypardiso`` depends on puts it (``lib`` under the environment's
    prefix or the user base), then by the system's library search; ``PYPARDISO_MKL_RT`` names it explicitly.
    pypardiso's own look-up (a recursive walk of the environment, about 0.2 s each time) is the last resort:
    a run's start-up is part of its wall time.
    """
    explicit = os.environ.get("PYPARDISO_MKL_RT")
    candidates = [explicit] if explicit else []
    for base in (sys.prefix, site.USER_BASE):
        for lib in ("lib", "lib64", "Lib", "Library/bin"):
            candidates += sorted(glob.glob(os.path.join(base, lib, "*mkl_rt*")), key=len)
    for path in candidates:
        with contextlib.suppress(OSError):
            return ctypes.CDLL(path)
    found = ctypes.util.find_library("mkl_rt")  # runs ldconfig: only when the environment has none
    if found:
        with contextlib.suppress(OSError):
            return ctypes.CDLL(found)
    import pypardiso  # its recursive search of the environment

    return pypardiso.PyPardisoSolver().libmkl


@lru_cache(maxsize=1)
def _pardiso_function():
    """The ``pardiso`` entry point of the MKL runtime."""
    fn = _mkl_runtime()["pardiso"]  # a fresh function pointer: our own argtypes
    i32p = ctypes.POINTER(ctypes.c_int32)
    fn.argtypes = [ctypes.c_void_p] + [i32p] * 5 + [ctypes.c_void_p] + [i32p] * 6 + [ctypes.c_void_p] * 2 + [i32p]
    fn.restype = None
    return fn


@lru_cache(maxsize=1)
def _mkl_local_threads():
    """MKL's ``mkl_set_num_threads_local`` (None if the runtime lacks it): sets the calling thread's MKL thread
    count and returns the previous setting (0: the global one)."""
    try:
        fn = _mkl_runtime()["MKL_Set_Num_Threads_Local"]
    except (AttributeError, KeyError, OSError):
        return None
    fn.argtypes = [ctypes.c_int]
    fn.restype = ctypes.c_int
    return fn


@lru_cache(maxsize=1)
def _mkl_max_threads() -> int:
    """The number of threads MKL uses outside covcontact's thread-local settings."""
    try:
        fn = _mkl_runtime()["MKL_Get_Max_Threads"]
    except (AttributeError, KeyError, OSError):
        return 1
    fn.argtypes = []
    fn.restype = ctypes.c_int
    return int(fn())


#: below this many unknowns PARDISO runs on one thread: measured on hex8 block and plate tangents (2 cores,
#: benchmarks/newton_iteration.py with MKL_NUM_THREADS=1 and 2), two threads factorise 5-40 % slower and
#: substitute 2-10 times slower up to about 1e4 unknowns and factorise faster from 1.5e4 on (docs/performance.md)
PARDISO_SERIAL_BELOW = 12_000

#: ``reuse_factorization = "auto"`` reuses a PARDISO factorisation when it needs at least this many times the
#: floating-point operations of one forward and backward substitution (4 per non-zero of the factor), twice as
#: many when PARDISO runs on several threads (its factorisation gains from them, its substitution hardly).
#: Measured on one thread (docs/performance.md, "Factorisation reuse"): reuse saved time on the 4,770-dof two
#: blocks (ratio 70) and the 5,085-dof Hertz ball (112) and cost time on the 1,782- and 3,774-dof plates of the
#: paper study (24 and 39), where GMRES needs more iterations than a factorisation is worth.
REUSE_MIN_FLOP_RATIO = 50.0

#: ``precision = "auto"`` factorises in single precision from this many unknowns on (see PardisoSolver) ...
PARDISO_SINGLE_FROM = 4_000
#: ... where the factorisation needs at least this many times the flops of a substitution (``flop_ratio``).
#: Measured whole runs (benchmarks/newton_iteration.py problems, 2 cores; docs/performance.md): single
#: precision took 7 % longer on a plate of ratio 83 (39,366 unknowns; each refinement needs 1-2 GMRES
#: iterations there) and 6-25 % less time on plates of ratio 107 and 155 and blocks of 127 to 328; on one
#: thread 14-20 % less on the Hertz ball of 5,085 unknowns (ratio 112) and blocks of 6,591 and 10,125 (105, 135).
SINGLE_MIN_FLOP_RATIO = 100.0
#: a single-precision factorisation's solve is refined by GMRES in double precision to this relative residual
SINGLE_REFINE_RTOL = 1e-10
#: ... or until the normwise backward error ||K x - b|| / (||K||_F ||x|| + ||b||) is this small (what a
#: double-precision factorisation leaves on the ill-conditioned tangents of thin shells)
SINGLE_REFINE_BACKWARD = 1e-15
#: ... within this many GMRES iterations; else the factorisation is redone in double precision
SINGLE_REFINE_MAX = 20


def _upper_structure(K: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """CSR structure (ia, ja int32) of the upper triangle of K (sorted indices, as ``_as_csr`` leaves them)
    with every diagonal entry present, and for each entry its position in K.data (K.nnz for a structural
    zero on the diagonal)."""
    return _upper_kernel(K.indptr.astype(np.int64), K.indices.astype(np.int32), K.shape[0])


@njit(cache=True)
def _upper_kernel(indptr, indices, n):  # pragma: no cover - compiled
    nnz = indptr[n]
    ia = np.zeros(n + 1, dtype=np.int32)
    for i in range(n):  # count the upper entries, a missing diagonal included
        c = 0
        diag = False
        for p in range(indptr[i], indptr[i + 1]):
            if indices[p] >= i:
                c += 1
                diag = diag or indices[p] == i
        ia[i + 1] = ia[i] + c + (0 if diag else 1)
    ja = np.empty(ia[n], dtype=np.int32)
    pos = np.empty(ia[n], dtype=np.int64)
    for i in range(n):
        q = ia[i]
        first = indptr[i]
        while first < indptr[i + 1] and indices[first] < i:
            first += 1
        if first == indptr[i + 1] or indices[first] != i:  # a structural zero first: the others lie right of i
            ja[q] = i
            pos[q] = nnz
            q += 1
        for p in range(first, indptr[i + 1]):
            ja[q] = indices[p]
            pos[q] = p
            q += 1
    return ia, ja, pos


class PardisoSolver(LinearSolver):
    """MKL PARDISO with the analysis (phase 11) redone only when the pattern changes.

    Options: ``spd=True`` uses Cholesky (mtype 2; falls back to -2 if the matrix is not positive
    definite); ``matching=True`` adds weighted matching and scaling to LDL^T and LU (saddle-point
    matrices with zero diagonal blocks).

    ``precision``: ``"double"``; ``"single"``, the matrix factorised in single precision (PARDISO's
    iparm[27]: about half the time and half the memory of the factor) and each solve refined in double
    precision by GMRES preconditioned with that factor, to a relative residual of ``SINGLE_REFINE_RTOL`` (or
    the backward error of a double-precision solve); or ``"auto"``, single precision from
    ``PARDISO_SINGLE_FROM`` unknowns on where the analysis finds a factorisation at least
    ``SINGLE_MIN_FLOP_RATIO`` substitutions dear (else it is analysed again in double precision). If the
    refinement misses its tolerance in
    ``SINGLE_REFINE_MAX`` iterations the solver factorises in double precision from then on
    (``single_given_up`` says why). Symmetric (LDL^T) and non-symmetric (LU, friction) matrices alike;
    ``matching`` (saddle points) always uses double precision.
    """

    name = "pardiso"

    @staticmethod
    def probe() -> tuple[bool, str, str]:
        if platform.machine().lower() not in ("x86_64", "amd64"):
            return False, "", "MKL PARDISO needs x86-64"
        from importlib.metadata import PackageNotFoundError, version

        try:
            ver = version("pypardiso")
        except PackageNotFoundError as exc:  # MKL alone is not enough: pypardiso is the declared route to it
            raise ImportError("pypardiso is not installed") from exc
        _pardiso_function()
        return True, ver, "MKL PARDISO: LDL^T (mtype -2) / LU (11), in double or single precision"

    def __init__(self, symmetric: bool = True, check_tol: float = 1e-6, spd: bool = False,
                 matching: bool = False, precision: str = "double"):
        super().__init__(symmetric, check_tol)
        self.set_precision(precision)
        self._fn = _pardiso_function()
        self.mtype = (2 if spd else -2) if symmetric else 11
        self.matching = matching
        self.single = False  # the current analysis and factorisation are in single precision
        self.single_given_up = ""  # why single precision was given up for the rest of this solver's life
        self.refine_iterations = 0  # GMRES iterations of the refinements since the solver was made
        self.n_single = 0  # factorisations in single precision
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        self._n = 0
        self._a = np.zeros(1)
        self._ia = self._ja = np.zeros(1, dtype=np.int32)
        self._pos: np.ndarray | None = None
        self._pad = False
        self.n_perturbed = 0
        self.flop_ratio = 0.0  # factorisation flops over substitution flops of the last analysis
        self.inertia: tuple[int, int] | None = None

    def _set_iparm(self) -> None:
        ip = self.iparm
        ip[:] = 0
        ip[0] = 1  # user-supplied parameters
        ip[1] = 2  # METIS nested dissection
        ip[7] = 0  # iterative refinement: automatic (2 steps after perturbed pivots)
        ip[34] = 1  # zero-based indexing
        # conditional numerical reproducibility: the threads fixed, so that the threaded factorisation adds in a
        # fixed order (without it, LU on two threads differed by 1e-15 between runs, enough to change a
        # frictional run's iterations; the same time, docs/performance.md)
        ip[33] = 1 if self._n < PARDISO_SERIAL_BELOW else max(_mkl_max_threads(), 1)
        if not self.reproducible:  # [solver] reproducible = false: the faster substitutions, bits may vary
            ip[33] = 0
        ip[17] = ip[18] = -1  # report the factors' non-zeros and the factorisation's Mflop (phase 11)
        ip[27] = 1 if self.single else 0  # single precision: the values and right-hand sides as float32
        if self.mtype == 11:
            # pivot perturbation 1e-13; scaling and weighted matching only when asked for (saddle points): they
            # make the analysis depend on the values of the matrix analysed, so that a later step's LU would
            # depend on the step at which the pattern was analysed (a resumed run differed by 1e-14); on
            # friction tangents they changed neither the time nor the residual (docs/performance.md)
            ip[9] = 13
            ip[10] = ip[12] = 1 if self.matching else 0
        else:
            ip[9] = 8  # pivot perturbation 1e-8
            ip[20] = 1  # Bunch-Kaufman 1x1 and 2x2 pivots
            if self.matching:
                ip[10], ip[12] = 1, 1

    def _call(self, phase: int, b: np.ndarray | None = None, x: np.ndarray | None = None) -> int:
        err = ctypes.c_int32(0)
        nrhs = 1 if b is None or b.ndim == 1 else b.shape[1]
        dummy = np.zeros(1)
        c = ctypes.c_int32

        def ref(v):
            return ctypes.byref(c(v))

        i32p = ctypes.POINTER(ctypes.c_int32)
        local = _mkl_local_threads() if 0 < self._n < PARDISO_SERIAL_BELOW else None
        previous = local(1) if local is not None else None
        try:
            self._fn(self.pt.ctypes.data, ref(1), ref(1), ref(self.mtype), ref(phase), ref(self._n),
                     self._a.ctypes.data, self._ia.ctypes.data_as(i32p), self._ja.ctypes.data_as(i32p),
                     None, ref(nrhs), self.iparm.ctypes.data_as(i32p), ref(0),
                     (dummy if b is None else b).ctypes.data, (dummy if x is None else x).ctypes.data,
                     ctypes.byref(err))
        finally:
            if local is not None:
                local(previous)
        return err.value

    def _values(self, K: sp.csr_matrix) -> np.ndarray:
        """Values in PARDISO's structure (float32 in single precision); kept alive, PARDISO refines with
        them in phase 33."""
        if self._pos is None:
            a = K.data.copy()
        elif self._pad:
            a = np.append(K.data, 0.0)[self._pos]
        else:
            a = K.data[self._pos]
        return a.astype(np.float32) if self.single else a

    def new_step(self) -> None:
        if self.matching:  # weighted matching and scaling: the analysis reads the values
            self._indptr = self._indices = None

    def set_precision(self, precision: str) -> None:
        if precision not in ("double", "single", "auto"):
            raise ValueError(f'precision must be "double", "single" or "auto", got {precision!r}')
        self.precision = precision

    def precision_report(self) -> dict | None:
        if self.matching:
            return None
        report = {"precision": self.precision, "single_factorizations": self.n_single,
                  "refinement_gmres_iterations": self.refine_iterations}
        if self.single_given_up:
            report["single_given_up"] = self.single_given_up
        return report

    def _wants_single(self, n: int) -> bool:
        if self.matching or self.single_given_up:
            return False
        return self.precision == "single" or (self.precision == "auto" and n >= PARDISO_SINGLE_FROM)

    def _analyze(self, K: sp.csr_matrix, same_pattern: bool = False, single: bool | None = None) -> None:
        """Phase 11; ``same_pattern``: K has the pattern of the last analysis (a new mtype or precision), whose
        PARDISO structure is kept; ``single``: the precision (default: ``_wants_single``)."""
        self._release()
        self._n = K.shape[0]
        self.single = self._wants_single(self._n) if single is None else single
        if not same_pattern and self.mtype == 11:
            self._ia, self._ja, self._pos = K.indptr.astype(np.int32), K.indices.astype(np.int32), None
        elif not same_pattern:
            self._ia, self._ja, self._pos = _upper_structure(K)
            self._pad = bool((self._pos == K.nnz).any())
        self._set_iparm()
        self._a = self._values(K)
        err = self._call(11)
        if err:
            self._release()
            raise LinearSolverError(f"pardiso analysis failed: {_PARDISO_ERRORS.get(err, err)}")
        # factorisation Mflop over the flops of one substitution (iparm 18 and 17, reported by phase 11)
        self.flop_ratio = max(float(self.iparm[18]), 0.0) * 1e6 / (4.0 * max(float(self.iparm[17]), 1.0))
        if self.single and self.precision == "auto" and self.flop_ratio < SINGLE_MIN_FLOP_RATIO:
            self._analyze(K, same_pattern=True, single=False)  # refinement would cost what single saves

    def reuse_pays(self) -> bool:
        threaded = self._n >= PARDISO_SERIAL_BELOW and _mkl_max_threads() > 1
        return self.flop_ratio >= REUSE_MIN_FLOP_RATIO * (2.0 if threaded else 1.0)

    def _factor(self, K: sp.csr_matrix) -> None:
        self._a = self._values(K)
        err = self._call(22)
        if err == -4 and self.mtype == 2:  # not positive definite: continue with LDL^T
            self.mtype = -2
            self._analyze(K, same_pattern=True)
            err = self._call(22)
        if err:
            cls = SingularMatrixError if err in (-4, -7) else LinearSolverError
            raise cls(f"pardiso factorisation failed: {_PARDISO_ERRORS.get(err, err)}")
        self.n_single += self.single
        self.n_perturbed = int(self.iparm[13])
        self.inertia = (int(self.iparm[21]), int(self.iparm[22])) if self.mtype == -2 else None

    def _substitute(self, b: np.ndarray) -> np.ndarray:
        """Forward and backward substitution with the factor, in its precision; float64 out."""
        bf = np.array(b, dtype=np.float32 if self.single else np.float64, order="F")
        x = np.zeros_like(bf, order="F")
        err = self._call(33, bf, x)
        if err:
            raise LinearSolverError(f"pardiso solve failed: {_PARDISO_ERRORS.get(err, err)}")
        return np.ascontiguousarray(x, dtype=np.float64)

    def precondition(self, b: np.ndarray) -> np.ndarray:
        return self._substitute(b)

    def _solve(self, b: np.ndarray) -> np.ndarray:
        if not self.single:
            return self._substitute(b)
        if b.ndim == 2:
            return np.column_stack([self._solve(b[:, j]) for j in range(b.shape[1])])
        K = self._K
        assert K is not None
        x = self._substitute(b)
        r = b - K @ x
        nb, nr = float(np.linalg.norm(b)), float(np.linalg.norm(r))
        if nr <= SINGLE_REFINE_RTOL * nb:
            return x
        d, its = gmres_right(K, r, self._substitute, SINGLE_REFINE_RTOL * nb / nr, SINGLE_REFINE_MAX,
                             partial=True, flexible=True)
        self.refine_iterations += its
        if d is not None and np.isfinite(d).all():
            x = x + d
            nr = float(np.linalg.norm(b - K @ x))
            if nr <= SINGLE_REFINE_RTOL * nb or nr <= SINGLE_REFINE_BACKWARD * (
                    self._frobenius() * float(np.linalg.norm(x)) + nb):
                return x
        # the single-precision factor is too poor for this matrix: double precision from now on
        self.single_given_up = (f"refinement of a single-precision solve stopped at a relative residual "
                                f"{nr / nb:.1e} after {its} GMRES iterations")
        self.single = False
        self._analyze(K, same_pattern=True)
        self._factor(K)
        self.n_factorizations += 1
        return self._substitute(b)

    def _diagnosis(self) -> str:
        return f" ({self.n_perturbed} perturbed pivots)" if self.n_perturbed else ""

    def _release(self) -> None:
        if self._n and self.pt.any():
            self._call(-1)
        self.pt[:] = 0

    def __del__(self):
        with contextlib.suppress(Exception):  # interpreter shutdown
            self.close()
