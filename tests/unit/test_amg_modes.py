"""Rigid-body modes as the near-null space of cg-amg: ``rigid_body_modes(X, constrained)`` spans the kernel
of an assembled elastic stiffness, vanishes on constrained dofs, and ``set_near_null_space`` (present on
every backend) cuts the Krylov iterations of cg-amg on the matrices of the normal run path."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from covcontact.assembly import Pattern
from covcontact.assembly.system import System
from covcontact.elements import SolidBody
from covcontact.materials import NeoHooke, SaintVenantKirchhoff
from covcontact.mesh.generators import block
from covcontact.problem import Body, Dirichlet, NodalForce, Problem
from covcontact.solvers.linear import available, make_solver, rigid_body_modes

AVAILABLE = available()
needs_amg = pytest.mark.skipif("cg-amg" not in AVAILABLE, reason="pyamg not installed (the `fast` extra)")


def free_stiffness(u_of_X=None, material=None):
    """Tangent of an unconstrained, distorted 3 x 2 x 2 hex8 block at u = u_of_X(X) (default 0)."""
    mesh = block(1.5, 1.0, 1.2, 3, 2, 2)
    rng = np.random.default_rng(7)
    X = mesh.points + 0.06 * rng.uniform(-1.0, 1.0, mesh.points.shape) + [3.0, -2.0, 5.0]
    body = SolidBody("hex8", X, mesh.cells, material or SaintVenantKirchhoff(E=200.0, nu=0.3))
    u = np.zeros_like(X) if u_of_X is None else u_of_X(X)
    P = Pattern(body.n_nodes, [mesh.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P) == -1
    return P.csr(data), X, u


def null_defect(K, B) -> float:
    """||K B||_F / (||K||_F ||B||_F)."""
    return float(np.linalg.norm(K @ B) / (sla.norm(K) * np.linalg.norm(B)))


def block_system(n: int = 10):
    """Tangent (after Dirichlet elimination by the System, as Newton solves it), right-hand side, nodes and
    constrained mask of an n x n x n hex8 unit cube clamped at x = 0 and loaded at x = 1."""
    mesh = block(1.0, 1.0, 1.0, n, n, n)
    material = SaintVenantKirchhoff(E=200.0, nu=0.3)
    problem = Problem(
        name="cube",
        bodies=[Body("cube", mesh, material)],
        dirichlet=[Dirichlet("cube", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))],
        forces=[NodalForce("cube", "xmax", (0.0, 0.3, -1.0), "total")],
    )
    system = System(problem.bodies, problem.rigid, problem.loads, problem.dirichlet)
    body = SolidBody("hex8", mesh.points, mesh.cells, material)
    P = Pattern(body.n_nodes, [mesh.cells])
    data = P.zeros()
    assert body.assemble(np.zeros_like(mesh.points), data, np.zeros(system.n_dofs), P) == -1
    K = system.eliminate(P.csr(data))
    rhs = system.f_ext.copy()
    rhs[system.constrained] = 0.0
    assert np.abs(rhs).sum() > 0
    return K, rhs, system.X, system.constrained.copy()


@pytest.fixture(scope="module")
def cube():
    return block_system(10)


def rel_residual(A, x, b) -> float:
    return float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))


# ----------------------------------------------------------------------------- the modes


def test_modes_span_the_kernel_of_the_stiffness():
    K, X, _ = free_stiffness()
    B = rigid_body_modes(X)
    assert B.shape == (K.shape[0], 6) and B.dtype == np.float64
    assert np.linalg.matrix_rank(B) == 6
    assert null_defect(K, B) < 1e-13
    # the kernel is exactly six-dimensional: B spans it (smallest eigenvalues against the rest)
    ev = np.linalg.eigvalsh(K.toarray())
    assert np.abs(ev[:6]).max() < 1e-12 * ev[-1] and ev[6] > 1e-6 * ev[-1]


def test_modes_scaled_to_order_one():
    """Columns of comparable size whatever the units and the position of the body."""
    _, X, _ = free_stiffness()
    for scale, shift in ((1.0, 0.0), (1e-3, 0.0), (1e4, -7e4)):
        norms = np.linalg.norm(rigid_body_modes(scale * X + shift), axis=0)
        assert norms.max() <= 2.0 * norms.min()
        assert norms[:3] == pytest.approx(np.sqrt(X.shape[0]))


def test_current_coordinates_give_the_kernel_of_a_rotated_tangent():
    """At a finite rigid rotation (stress-free) the tangent's kernel is spanned by the modes of X + u."""
    a = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    R = np.eye(3) + np.sin(0.9) * W + (1.0 - np.cos(0.9)) * W @ W
    for material in (SaintVenantKirchhoff(E=200.0, nu=0.3), NeoHooke(E=200.0, nu=0.3)):
        K, X, u = free_stiffness(lambda X: X @ R.T - X + [0.2, 0.1, -0.3], material)
        assert null_defect(K, rigid_body_modes(X + u)) < 1e-12
        assert null_defect(K, rigid_body_modes(X)) > 1e-3  # the reference rotations are not in it


def test_constrained_rows_are_zero_and_others_unchanged(cube):
    _, _, X, constrained = cube
    B = rigid_body_modes(X, constrained)
    full = rigid_body_modes(X)
    assert B.shape == full.shape == (3 * X.shape[0], 6)
    assert constrained.any() and not constrained.all()
    assert not B[constrained].any()
    np.testing.assert_array_equal(B[~constrained], full[~constrained])
    # partially constrained nodes: only their own rows vanish
    mask = np.zeros(3 * X.shape[0], dtype=bool)
    mask[[0, 4, 8]] = True  # x of node 0, y of node 1, z of node 2
    Bm = rigid_body_modes(X, mask)
    assert not Bm[mask].any() and np.abs(Bm[~mask] - full[~mask]).max() == 0.0
    # integer dofs: rows of a reduced system (the set_geometry convention)
    free = np.flatnonzero(~constrained)
    np.testing.assert_array_equal(rigid_body_modes(X, free), full[free])


def test_bad_arguments(cube):
    _, _, X, constrained = cube
    with pytest.raises(ValueError, match="shape"):
        rigid_body_modes(X, constrained[:-3])
    with pytest.raises(ValueError, match="bool"):  # a 0/1 integer array is not a mask
        rigid_body_modes(X, constrained.astype(int))
    with pytest.raises(ValueError, match="shape"):
        rigid_body_modes(X[:, :2])


# ----------------------------------------------------------------------------- the solvers


@pytest.mark.parametrize("name", AVAILABLE)
def test_every_backend_accepts_a_near_null_space(name, cube):
    K, rhs, X, constrained = cube
    s = make_solver(name)
    B = rigid_body_modes(X, constrained)
    s.set_near_null_space(B)
    np.testing.assert_array_equal(s.near_null_space, B)
    assert s.near_null_space is not B  # a copy: later changes of B do not leak in
    x = s.solve(K, rhs)
    assert rel_residual(K, x, rhs) < 1e-9
    if s.direct:  # ignored by direct solvers
        np.testing.assert_allclose(x, make_solver(name).solve(K, rhs), rtol=0, atol=1e-12 * np.abs(x).max())
    s.set_near_null_space(None)
    assert s.near_null_space is None
    with pytest.raises(ValueError, match="non-finite"):
        s.set_near_null_space(np.full((K.shape[0], 6), np.nan))


@needs_amg
def test_amg_with_modes_needs_fewer_iterations(cube):
    """The measured counts (pyamg 5.4: 38 plain, 20 plain with 3 x 3 blocks, 11 with the modes) are
    compared with a margin, not hard-coded."""
    K, rhs, X, constrained = cube
    plain = make_solver("cg-amg")
    x0 = plain.solve(K, rhs)
    blocks = make_solver("cg-amg", blocksize=3)  # same blocks, pyamg's 3 constants: isolates the rotations
    blocks.solve(K, rhs)
    rbm = make_solver("cg-amg")
    rbm.set_near_null_space(rigid_body_modes(X, constrained))
    x = rbm.solve(K, rhs)
    assert rbm._ml.levels[0].A.format == "bsr" and rbm._ml.levels[0].A.blocksize == (3, 3)
    assert plain._ml.levels[0].A.format == "csr"
    assert rel_residual(K, x, rhs) < 1e-9
    assert np.linalg.norm(x - x0) <= 1e-7 * np.linalg.norm(x0)
    print(f"Krylov iterations: plain {plain.iterations}, 3x3 blocks {blocks.iterations}, "
          f"rigid-body modes {rbm.iterations}")
    assert 0 < rbm.iterations
    assert 2 * rbm.iterations <= plain.iterations
    assert 4 * rbm.iterations <= 3 * blocks.iterations


@needs_amg
def test_amg_nonsymmetric_with_modes(cube):
    """GMRES on a friction-like non-symmetric tangent: the modes serve as left and right candidates."""
    K, rhs, X, constrained = cube
    U = sp.triu(K, 1).tocsr()
    S = (U - U.T).tocsr()
    rows = np.repeat(np.arange(S.shape[0]), np.diff(S.indptr))
    S.data[constrained[rows] | constrained[S.indices]] = 0.0  # keep the eliminated rows and columns
    A = (K + 0.3 * S).tocsr()
    plain = make_solver("cg-amg", symmetric=False)
    plain.solve(A, rhs)
    rbm = make_solver("cg-amg", symmetric=False)
    rbm.set_near_null_space(rigid_body_modes(X, constrained))
    x = rbm.solve(A, rhs)
    assert rel_residual(A, x, rhs) < 1e-9
    assert 0 < rbm.iterations < plain.iterations


@needs_amg
def test_amg_rebuilds_when_the_modes_change(cube):
    K, rhs, X, constrained = cube
    B = rigid_body_modes(X, constrained)
    ref_plain, ref_rbm = make_solver("cg-amg"), make_solver("cg-amg")
    ref_plain.solve(K, rhs)
    ref_rbm.set_near_null_space(B)
    ref_rbm.solve(K, rhs)
    s = make_solver("cg-amg")
    s.factorize(K)
    s.set_near_null_space(B)  # between factorize and solve: the next solve uses a new hierarchy
    s.solve_factorized(rhs)
    assert s.iterations == ref_rbm.iterations
    s.set_near_null_space(None)
    s.solve(K, rhs)
    assert s.iterations == ref_plain.iterations
    s.set_geometry(X)  # the older interface; the last call wins
    s.solve(K, rhs)
    assert s.iterations == ref_rbm.iterations
    s.set_near_null_space(B[:-3])
    with pytest.raises(ValueError, match="rows"):
        s.solve(K, rhs)


needs_gamg = pytest.mark.skipif("petsc-gamg" not in AVAILABLE, reason="petsc4py not installed (the `mpi` extra)")


@needs_gamg
def test_gamg_takes_the_modes_and_node_blocks(cube):
    """petsc-gamg on a SciPy matrix (one process): ``set_near_null_space`` gives GAMG the rigid-body modes and
    3 x 3 node blocks, which cut its CG iterations against its default (constants, scalar rows)."""
    K, rhs, X, constrained = cube
    plain = make_solver("petsc-gamg")
    x0 = plain.solve(K, rhs)
    rbm = make_solver("petsc-gamg")
    rbm.set_near_null_space(rigid_body_modes(X, constrained))
    x = rbm.solve(K, rhs)
    assert rbm._op.A.getBlockSize() == 3 and plain._op.A.getBlockSize() == 1
    assert rel_residual(K, x, rhs) < 1e-9
    assert np.linalg.norm(x - x0) <= 1e-7 * np.linalg.norm(x0)
    print(f"CG iterations: plain {plain.iterations}, rigid-body modes {rbm.iterations}")
    assert 0 < rbm.iterations and 2 * rbm.iterations <= plain.iterations
    rbm.set_geometry(X)  # the older interface; the last call wins (every dof a node's: blocks, no zero rows)
    rbm.solve(K, rhs)
    assert rbm._op.A.getBlockSize() == 3


@needs_gamg
def test_gamg_node_block_smoothing(cube):
    """petsc-gamg smooths each level with Chebyshev on the inverse 3 x 3 node blocks by default: fewer CG
    iterations than on the inverse diagonal, the same solution; each solver keeps its own choice."""
    K, rhs, X, constrained = cube
    runs = {}
    for level_pc in ("pbjacobi", "jacobi", "pbjacobi"):
        s = make_solver("petsc-gamg") if level_pc == "pbjacobi" else make_solver("petsc-gamg", level_pc=level_pc)
        s.set_near_null_space(rigid_body_modes(X, constrained))
        x = s.solve(K, rhs)
        assert rel_residual(K, x, rhs) < 1e-9
        smoother = s._op.ksp.getPC().getMGSmoother(1).getPC().getType()
        assert smoother == level_pc
        runs.setdefault(level_pc, []).append(s.iterations)
    print(f"CG iterations: node blocks {runs['pbjacobi']}, diagonal {runs['jacobi']}")
    assert runs["pbjacobi"][0] == runs["pbjacobi"][1] < runs["jacobi"][0]


AMG = [name for name in ("cg-amg", "petsc-gamg") if name in AVAILABLE]


@pytest.mark.parametrize("name", AMG)
def test_hierarchy_preconditions_a_later_matrix_of_the_same_pattern(name, cube):
    """Newton's inexact corrections: the hierarchy of one tangent preconditions CG on a later one of the same
    sparsity pattern (to the requested relative residual of the later matrix); a matrix with a new entry
    (a new contact coupling) does not fit, nor one of another size."""
    K, rhs, X, constrained = cube
    s = make_solver(name)
    s.set_near_null_space(rigid_body_modes(X, constrained))
    s.factorize(K)
    x, its = s.solve_preconditioned(K, rhs, 1e-6)
    assert x is not None and 0 < its and rel_residual(K, x, rhs) <= 1e-6
    K2 = K.copy()  # same pattern (explicit zeros included), other values: 1.3 K + a positive diagonal
    K2.data *= 1.3
    free = ~constrained
    K2.setdiag(np.where(free, K.diagonal() * 1.3 * (1.0 + 0.5 * np.cos(np.arange(K.shape[0])) ** 2), 1.0))
    assert s.preconditioner_fits(K2)
    x2, its2 = s.solve_preconditioned(K2, rhs, 1e-8)
    assert x2 is not None and rel_residual(K2, x2, rhs) <= 1.01e-8 and its2 > its
    assert rel_residual(K, x2, rhs) > 1e-3  # it solved K2, not K
    x3, its3 = s.solve_preconditioned(K2, rhs, 1e-8, maxiter=2)  # too few iterations: no answer
    assert x3 is None and its3 == 2
    K3 = K.tolil()
    i, j = np.flatnonzero(~constrained)[[0, -1]]
    K3[i, j] = K3[j, i] = 1e-3  # a coupling of two distant free dofs
    assert not s.preconditioner_fits(K3.tocsr())
    assert not s.preconditioner_fits(K[:-3, :-3].tocsr())
