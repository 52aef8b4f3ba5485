"""Linear solver registry: every backend available here solves SPD, symmetric indefinite and
non-symmetric systems, reuses its analysis, detects singular matrices, and coexists with numba."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from numba import njit, prange

from covcontact.fem.quadrature import gauss_hex
from covcontact.fem.shapes import NODES, shape_functions
from covcontact.solvers.linear import (
    BACKENDS,
    LinearSolverError,
    SingularMatrixError,
    available,
    describe,
    make_solver,
    rigid_body_modes,
)

AVAILABLE = available()
DIRECT = [n for n in AVAILABLE if make_solver(n).direct]
NONSYM = [n for n in AVAILABLE if n != "cholmod"]
RTOL = 1e-10


def grid_elasticity(nx: int, ny: int, nz: int, nu: float = 0.3):
    """Linear-elastic hex8 stiffness (E = 1) of a unit-cell grid; returns K (all dofs), points."""
    p, w = gauss_hex(2)
    _, dN, _ = shape_functions("hex8", p)
    lam, mu = nu / ((1 + nu) * (1 - 2 * nu)), 0.5 / (1 + nu)
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[range(6), range(6)] += [2 * mu] * 3 + [mu] * 3
    Ke = np.zeros((24, 24))
    for q in range(w.size):
        G = 2.0 * dN[q]  # unit cells: dxi/dx = 2
        B = np.zeros((6, 24))
        for a in range(8):
            gx, gy, gz = G[a]
            B[0, 3 * a], B[1, 3 * a + 1], B[2, 3 * a + 2] = gx, gy, gz
            B[3, 3 * a], B[3, 3 * a + 1] = gy, gx
            B[4, 3 * a + 1], B[4, 3 * a + 2] = gz, gy
            B[5, 3 * a], B[5, 3 * a + 2] = gz, gx
        Ke += B.T @ D @ B * w[q] / 8.0
    nid = np.arange((nx + 1) * (ny + 1) * (nz + 1)).reshape(nz + 1, ny + 1, nx + 1)
    off = ((NODES["hex8"] + 1) / 2).astype(int)
    i, j, k = (a.ravel() for a in np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij"))
    cells = np.stack([nid[k + o[2], j + o[1], i + o[0]] for o in off], axis=1)
    dofs = (3 * cells[:, :, None] + np.arange(3)).reshape(-1, 24)
    rows, cols = np.repeat(dofs, 24, axis=1).ravel(), np.tile(dofs, (1, 24)).ravel()
    n = 3 * nid.size
    K = sp.csr_matrix((np.tile(Ke.ravel(), len(cells)), (rows, cols)), shape=(n, n))
    K.sum_duplicates()
    z, y, x = np.meshgrid(np.arange(nz + 1), np.arange(ny + 1), np.arange(nx + 1), indexing="ij")
    return K, np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1).astype(float)


@pytest.fixture(scope="module")
def problem():
    """SPD stiffness (10 x 10 x 9 hex8, clamped at x = 0: 3300 dofs), its free dofs and nodes."""
    K, X = grid_elasticity(10, 10, 9)
    free = np.flatnonzero(X[np.arange(K.shape[0]) // 3, 0] > 0)
    Kf = K[free][:, free].tocsr()
    Kf.sort_indices()
    return Kf, free, X, K


@pytest.fixture(scope="module")
def indefinite(problem):
    """K - sigma I with sigma between the 5th and 6th eigenvalue: 5 negative eigenvalues."""
    K = problem[0]
    ev = np.sort(sla.eigsh(K, k=8, sigma=0.0, return_eigenvectors=False))
    A = K.copy()
    A.setdiag(A.diagonal() - 0.5 * (ev[4] + ev[5]))
    return A


@pytest.fixture(scope="module")
def nonsymmetric(problem):
    """K plus a skew part (friction-like) and a few one-sided couplings."""
    K = problem[0]
    U = sp.triu(K, 1)
    A = (K + 0.3 * (U - U.T)).tolil()
    rng = np.random.default_rng(3)
    for i, j in rng.integers(0, K.shape[0], size=(20, 2)):
        A[i, j] += 0.05
    A = A.tocsr()
    A.sort_indices()
    return A


def rel_residual(A, x, b) -> float:
    return float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))


def rhs(n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).standard_normal(n)


def test_superlu_always_available_and_order():
    assert "superlu" in AVAILABLE
    assert AVAILABLE == [n for n in BACKENDS if n in AVAILABLE]
    info = {d["name"]: d for d in describe()}
    assert list(info) == list(BACKENDS)
    for name, d in info.items():
        assert set(d) == {"name", "available", "version", "note"}
        assert d["available"] == (name in AVAILABLE)
        assert d["note"]


def test_auto_picks_first_direct():
    s = make_solver("auto")
    assert s.name == DIRECT[0] and s.direct
    s = make_solver("auto", symmetric=False)
    assert s.name == next(n for n in DIRECT if n != "cholmod")


def test_unknown_name_lists_available():
    with pytest.raises(ValueError) as exc:
        make_solver("umfpack")
    for name in AVAILABLE:
        assert name in str(exc.value)


def test_cholmod_refuses_nonsymmetric_or_is_absent():
    """CHOLMOD is Cholesky only: it refuses non-symmetric matrices; without scikit-sparse it is not offered."""
    if "cholmod" in AVAILABLE:
        with pytest.raises(ValueError, match="symmetric"):
            make_solver("cholmod", symmetric=False)
    else:
        with pytest.raises(ValueError, match="cholmod"):
            make_solver("cholmod")


@pytest.mark.parametrize("name", AVAILABLE)
def test_spd(name, problem):
    K = problem[0]
    assert K.shape[0] == 3300
    s = make_solver(name, symmetric=True)
    b = rhs(K.shape[0])
    x = s.solve(K, b)
    assert rel_residual(K, x, b) < RTOL
    assert s.residual < RTOL
    assert s.t_factor > 0 and s.t_solve > 0 and s.t_analyze >= 0
    # several right-hand sides at once
    B = np.stack([rhs(K.shape[0], k) for k in range(3)], axis=1)
    X = s.solve_factorized(B)
    assert X.shape == B.shape
    for k in range(3):
        assert rel_residual(K, X[:, k], B[:, k]) < RTOL


@pytest.mark.parametrize("name", AVAILABLE)
def test_symmetric_indefinite(name, indefinite):
    s = make_solver(name, symmetric=True)
    b = rhs(indefinite.shape[0], 1)
    x = s.solve(indefinite, b)
    assert rel_residual(indefinite, x, b) < RTOL
    if name == "pardiso":
        assert s.inertia == (indefinite.shape[0] - 5, 5)
    if name == "cholmod":
        assert s.last_backend != "cholmod"


@pytest.mark.parametrize("name", DIRECT)
def test_saddle_point(name, problem):
    """Symmetric indefinite with a zero diagonal block (ties u_i = u_j by multipliers)."""
    if name == "cholmod":
        pytest.skip("cholmod hands indefinite matrices to its fallback, tested in test_symmetric_indefinite")
    K = problem[0]
    n, m = K.shape[0], 40
    ij = np.random.default_rng(2).choice(n, size=(m, 2), replace=False)
    C = sp.csr_matrix((np.r_[np.ones(m), -np.ones(m)], (np.r_[np.arange(m), np.arange(m)], ij.T.ravel())),
                      shape=(m, n))
    A = sp.bmat([[K, C.T], [C, None]], format="csr")
    b = rhs(n + m, 4)
    x = make_solver(name, symmetric=True).solve(A, b)
    assert rel_residual(A, x, b) < RTOL


@pytest.mark.parametrize("name", NONSYM)
def test_nonsymmetric(name, nonsymmetric):
    assert abs(nonsymmetric - nonsymmetric.T).max() > 0.1
    s = make_solver(name, symmetric=False)
    b = rhs(nonsymmetric.shape[0], 5)
    x = s.solve(nonsymmetric, b)
    assert rel_residual(nonsymmetric, x, b) < RTOL


@pytest.mark.parametrize("name", AVAILABLE)
def test_pattern_reuse(name, problem):
    """New values on the same pattern: analysis kept, same answer as a fresh solver."""
    K = problem[0]
    b = rhs(K.shape[0], 6)
    s = make_solver(name)
    s.solve(K, b)
    assert s.n_analyses == 1
    K2 = K.copy()  # other values, same pattern (arrays equal, not identical), still symmetric
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    K2.data *= 1.0 + 0.1 * np.cos(rows + K.indices)
    K2.data[rows == K.indices] *= 1.3
    x2 = s.solve(K2, b)
    assert s.n_analyses == 1 and s.n_factorizations == 2 and s.t_analyze == 0.0
    x_fresh = make_solver(name).solve(K2, b)
    assert np.linalg.norm(x2 - x_fresh) <= 1e-8 * np.linalg.norm(x_fresh)
    assert rel_residual(K2, x2, b) < RTOL
    # a different pattern of the same size (stored zeros dropped) triggers a new analysis
    K3 = K2.copy()
    K3.eliminate_zeros()
    assert K3.nnz < K2.nnz
    x3 = s.solve(K3, b)
    assert s.n_analyses == 2
    assert np.linalg.norm(x3 - x2) <= 1e-8 * np.linalg.norm(x2)


@pytest.mark.parametrize("name", AVAILABLE)
def test_singular_raises(name, problem):
    """A floating body (no Dirichlet condition) with a generic load is singular."""
    K_all = problem[3]
    b = rhs(K_all.shape[0], 8)
    if make_solver(name).direct:
        with pytest.raises(SingularMatrixError):
            make_solver(name).solve(K_all, b)
    else:  # an iterative method cannot tell singular from slow: it reports no convergence
        with pytest.raises(LinearSolverError, match="no convergence"):
            make_solver(name, maxiter=200).solve(K_all, b)


@pytest.mark.parametrize("name", AVAILABLE)
def test_zero_row_raises(name, problem):
    K = problem[0].copy()
    K = K.tolil()
    K[5, :] = 0.0
    K[:, 5] = 0.0
    Kz = K.tocsr()
    Kz.eliminate_zeros()  # an empty row: caught before the backend is called
    with pytest.raises(SingularMatrixError, match="empty row"):
        make_solver(name).solve(Kz, rhs(Kz.shape[0]))


@pytest.mark.parametrize("name", DIRECT)
def test_explicit_zero_row_raises(name, problem):
    """A row of stored zeros: numerically singular."""
    K = problem[0].copy()
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    K.data[(rows == 5) | (K.indices == 5)] = 0.0
    with pytest.raises(SingularMatrixError):
        make_solver(name).solve(K, rhs(K.shape[0]))


def test_solve_before_factorize_and_after_close(problem):
    K = problem[0]
    s = make_solver("superlu")
    with pytest.raises(LinearSolverError):
        s.solve_factorized(np.ones(K.shape[0]))
    s.solve(K, np.ones(K.shape[0]))
    s.close()
    with pytest.raises(LinearSolverError):
        s.solve_factorized(np.ones(K.shape[0]))


def test_rigid_body_modes_are_null_space(problem):
    _, _, X, K_all = problem
    B = rigid_body_modes(X)
    assert B.shape == (K_all.shape[0], 6)
    assert np.linalg.matrix_rank(B) == 6
    assert np.abs(K_all @ B).max() < 1e-12 * np.abs(K_all).max() * np.abs(B).max()


def test_amg_uses_rigid_body_modes(problem):
    """Installed with the `fast` extra."""
    K, free, X, _ = problem
    b = rhs(K.shape[0], 9)
    plain = make_solver("cg-amg")
    plain.solve(K, b)
    rbm = make_solver("cg-amg")
    rbm.set_geometry(X, free)
    x = rbm.solve(K, b)
    assert rel_residual(K, x, b) < RTOL
    assert rbm.iterations < plain.iterations


@njit(parallel=True, cache=True)
def _prange_sum(x):
    s = 0.0
    for i in prange(x.size):
        s += np.sqrt(abs(x[i]))
    return s


@pytest.mark.parametrize("name", DIRECT)
def test_coexists_with_numba_threads(name, problem):
    """numba parallel kernels run before and after a (possibly threaded) factorisation."""
    import numba

    K = problem[0]
    v = np.linspace(-1.0, 1.0, 200_001)
    ref = float(np.sqrt(np.abs(v)).sum())
    assert _prange_sum(v) == pytest.approx(ref, rel=1e-12)
    s = make_solver(name)
    b = rhs(K.shape[0], 10)
    x = s.solve(K, b)
    assert numba.get_num_threads() >= 1
    assert _prange_sum(v) == pytest.approx(ref, rel=1e-12)
    assert rel_residual(K, s.solve(K, b), b) < RTOL
    np.testing.assert_allclose(s.solve_factorized(b), x, rtol=1e-12, atol=0)


@pytest.mark.skipif("pardiso" not in AVAILABLE, reason="pypardiso not installed")
def test_pardiso_spd_option_falls_back_on_indefinite(problem, indefinite):
    s = make_solver("pardiso", spd=True)
    K = problem[0]
    b = rhs(K.shape[0], 11)
    assert rel_residual(K, s.solve(K, b), b) < RTOL
    assert s.mtype == 2
    x = s.solve(indefinite, b)
    assert s.mtype == -2 and rel_residual(indefinite, x, b) < RTOL


def test_pardiso_upper_structure():
    """The upper triangle handed to PARDISO: scipy's triu with every missing diagonal entry added as a
    structural zero (position nnz), indices sorted, values found through the positions."""
    from covcontact.solvers.pardiso_backend import _upper_structure

    rng = np.random.default_rng(5)
    n = 300
    A = sp.random(n, n, density=0.03, random_state=rng, format="csr")
    A = (A + A.T).tocsr()
    A.setdiag(np.where(rng.random(n) < 0.2, 0.0, 1.0 + rng.random(n)))
    A.eliminate_zeros()  # about a fifth of the diagonal absent from the pattern
    A.sort_indices()
    missing = np.flatnonzero(A.diagonal() == 0.0)
    assert missing.size > 20
    ia, ja, pos = _upper_structure(A)
    U = sp.triu(A + sp.csr_matrix((np.full(missing.size, 7.0), (missing, missing)), shape=A.shape)).tocsr()
    U.sort_indices()
    assert ia.dtype == ja.dtype == np.int32
    np.testing.assert_array_equal(ia, U.indptr)
    np.testing.assert_array_equal(ja, U.indices)
    values = np.append(A.data, 0.0)[pos]
    expected = U.data.copy()
    expected[np.isin(np.arange(U.nnz), [U.indptr[i] for i in missing])] = 0.0  # the structural zeros
    np.testing.assert_array_equal(values, expected)
    assert (pos == A.nnz).sum() == missing.size
