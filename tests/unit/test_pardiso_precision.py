"""PARDISO in single precision ([solver] factorization_precision): the factor in float32, every solve refined
by flexible GMRES in double precision to the accuracy of a double-precision solve; the "auto" rule; the fall
back to double precision; the same Newton iterations and results as double precision."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.solvers.linear import available, gmres_right, make_solver

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif("pardiso" not in available(), reason="pypardiso not installed")


def elastic_like(m: int) -> sp.csr_matrix:
    """An SPD matrix with the pattern of a 3D stiffness: a 7-point Laplacian on m^3 nodes, 3x3 node blocks."""
    T = sp.diags([-np.ones(m - 1), 2 * np.ones(m), -np.ones(m - 1)], [-1, 0, 1])
    eye = sp.identity(m)
    lap = sp.kron(sp.kron(T, eye), eye) + sp.kron(sp.kron(eye, T), eye) + sp.kron(sp.kron(eye, eye), T)
    A = sp.kron(lap, np.ones((3, 3)) + 3 * np.eye(3)).tocsr()
    A.setdiag(A.diagonal() * (1.0 + np.linspace(0.0, 1e3, A.shape[0])))  # condition number ~1e5: refinement works
    return A.tocsr()


def _relres(A, x, b) -> float:
    return float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))


@pytest.fixture(scope="module")
def system():
    A = elastic_like(12)  # 5,184 unknowns
    b = A @ np.random.default_rng(0).standard_normal(A.shape[0])
    return A, b


def test_single_factor_refined_to_double_accuracy(system):
    from covcontact.solvers.pardiso_backend import SINGLE_REFINE_RTOL

    A, b = system
    double = make_solver("pardiso")
    single = make_solver("pardiso", precision="single")
    x2 = double.solve(A, b)
    x1 = single.solve(A, b)
    assert single.single and single.iparm[27] == 1 and not double.single and double.iparm[27] == 0
    assert single._a.dtype == np.float32
    raw = single.precondition(b)  # the plain substitution: float32 rounding shows in its residual
    assert 1e-10 < _relres(A, raw, b) < 1e-4
    assert _relres(A, x1, b) <= SINGLE_REFINE_RTOL
    np.testing.assert_allclose(x1, x2, rtol=0, atol=1e-8 * np.abs(x2).max())
    assert single.refine_iterations >= 1
    report = single.precision_report()
    assert report == {"precision": "single", "single_factorizations": 1, "refinement_gmres_iterations":
                      single.refine_iterations}
    # several right-hand sides
    B = np.column_stack([b, 2.0 * b + 1.0])
    X = single.solve_factorized(B)
    assert max(_relres(A, X[:, j], B[:, j]) for j in range(2)) <= SINGLE_REFINE_RTOL


def test_flexible_gmres_needs_no_linear_preconditioner(system):
    """A single-precision substitution is not linear to double precision: GMRES that applies it once more to
    the combined basis misses 1e-12 by the float32 rounding; flexible GMRES reaches it."""
    A, b = system
    s = make_solver("pardiso", precision="single")
    s.factorize(A)
    x, _ = gmres_right(A, b, s.precondition, 1e-12, 10)
    xf, its = gmres_right(A, b, s.precondition, 1e-12, 10, flexible=True)
    assert x is None or _relres(A, x, b) > 1e-10
    assert xf is not None and _relres(A, xf, b) <= 1.01e-12 and its <= 5


def test_auto_rule(system, monkeypatch):
    """auto: double precision below PARDISO_SINGLE_FROM unknowns; above it single precision where the
    analysis finds a factorisation of at least SINGLE_MIN_FLOP_RATIO substitutions, else analysed again in
    double precision."""
    from covcontact.solvers import pardiso_backend

    A, b = system
    small = elastic_like(10)  # 3,000 unknowns
    s = make_solver("pardiso", precision="auto")
    s.factorize(small)
    assert small.shape[0] < pardiso_backend.PARDISO_SINGLE_FROM and not s.single and s.n_single == 0
    monkeypatch.setattr(pardiso_backend, "PARDISO_SINGLE_FROM", 1000)
    for min_ratio, single in ((0.0, True), (1e9, False)):
        monkeypatch.setattr(pardiso_backend, "SINGLE_MIN_FLOP_RATIO", min_ratio)
        s = make_solver("pardiso", precision="auto")
        x = s.solve(A, b)
        assert s.single == single and s.n_single == int(single) and s.iparm[27] == int(single)
        assert _relres(A, x, b) <= 1e-10
    assert make_solver("pardiso", matching=True, precision="single").precision_report() is None


def test_single_lu_for_nonsymmetric_matrices(system):
    """Friction makes the tangent non-symmetric: LU (mtype 11) in single precision, refined alike."""
    A, _ = system
    U = sp.triu(A, 1)
    N = (A + 0.3 * (U - U.T)).tocsr()
    N.sort_indices()
    b = N @ np.random.default_rng(1).standard_normal(N.shape[0])
    single = make_solver("pardiso", symmetric=False, precision="single")
    x = single.solve(N, b)
    assert single.mtype == 11 and single.single and single.iparm[27] == 1
    assert 1e-10 < _relres(N, single.precondition(b), b) < 1e-4
    assert _relres(N, x, b) <= 1e-10
    np.testing.assert_allclose(x, make_solver("pardiso", symmetric=False).solve(N, b), rtol=0,
                               atol=1e-8 * np.abs(x).max())


def test_falls_back_to_double_when_refinement_fails(system, monkeypatch):
    from covcontact.solvers import pardiso_backend

    A, b = system
    monkeypatch.setattr(pardiso_backend, "SINGLE_REFINE_RTOL", 0.0)  # a tolerance refinement cannot meet
    monkeypatch.setattr(pardiso_backend, "SINGLE_REFINE_BACKWARD", 0.0)
    s = make_solver("pardiso", precision="single")
    x = s.solve(A, b)
    assert s.single_given_up.startswith("refinement of a single-precision solve stopped")
    assert not s.single and s.iparm[27] == 0 and s._a.dtype == np.float64
    assert _relres(A, x, b) < 1e-12
    s.factorize(2.0 * A)  # the rest of the solver's life in double precision
    assert not s.single and s.n_single == 1
    assert s.precision_report()["single_given_up"] == s.single_given_up


def _block_run(precision: str, tmp: Path):
    """A 16^3 hex8 block (14,739 unknowns) pressed on a rigid plane, PARDISO, one load step."""
    from covcontact import problem as pb
    from covcontact.materials import SaintVenantKirchhoff
    from covcontact.mesh.generators import block

    mesh = block(1.0, 1.0, 1.0, 16, 16, 16, cell="hex8")
    problem = pb.Problem(
        name="block", bodies=[pb.Body("b", mesh, SaintVenantKirchhoff(E=1000.0, nu=0.3))],
        rigid=[pb.RigidBody("floor", shape="plane", params={"point": (0, 0, 0), "normal": (0, 0, 1)})],
        contacts=[pb.ContactPair("c", ("b", "zmin"), ("floor", ""), penalty=1e7, weighting="area")],
        dirichlet=[pb.Dirichlet("b", "zmax", (0, 1, 2), (0.0, 0.0, -0.01))],
        steps=pb.Steps.equal(2), output=pb.OutputOptions(vtu=False),
        solver=pb.SolverOptions(linear="pardiso", factorization_precision=precision, reuse_factorization=False))
    res = problem.run(out=tmp / precision, quiet=True)
    assert res.exit_code == 0
    return res


def test_newton_same_iterations_and_results(tmp_path):
    runs = {p: _block_run(p, tmp_path) for p in ("double", "single")}
    d, s = runs["double"].summary, runs["single"].summary
    assert [st["iterations"] for st in s["steps"]] == [st["iterations"] for st in d["steps"]]
    for a, b in zip(d["steps"], s["steps"], strict=True):
        np.testing.assert_allclose(b["residual_norms"][:-1], a["residual_norms"][:-1], rtol=1e-6)
        assert b["residual_norms"][-1] < 1e-8 * b["residual_norms"][0]
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-9,
                                   atol=1e-9 * np.linalg.norm(a["contact_force"]))
    u_d, u_s = runs["double"].u, runs["single"].u
    assert np.abs(u_s - u_d).max() <= 1e-9 * np.abs(u_d).max()
    assert "factorization_precision" not in d
    rep = s["factorization_precision"]
    assert rep["precision"] == "single" and rep["single_factorizations"] == sum(st["iterations"] for st in s["steps"])


def test_precision_in_the_input(tmp_path):
    text = (ROOT / "examples" / "contact" / "two_blocks.toml").read_text()
    path = tmp_path / "p.toml"
    for value in ("auto", "double", "single"):
        path.write_text(text + f'\n[solver]\nfactorization_precision = "{value}"\n')
        assert load_problem(path).solver.factorization_precision == value
    path.write_text(text + '\n[solver]\nfactorization_precision = "half"\n')
    with pytest.raises(InputError, match=r"solver\.factorization_precision"):
        load_problem(path)
    path.write_text(text + '\n[solver]\nlinear = "superlu"\nfactorization_precision = "single"\n')
    with pytest.raises(InputError, match=r'factorization_precision: "single" is PARDISO\'s; linear = \'superlu\''):
        load_problem(path)


def test_run_default_is_auto(tmp_path):
    """The default: "auto"; a small problem stays in double precision and its summary says nothing of it."""
    problem = load_problem(ROOT / "examples" / "contact" / "two_blocks.toml")
    assert problem.solver.factorization_precision == "auto"
    problem.solver = dataclasses.replace(problem.solver, linear="pardiso")
    problem.output.vtu = False
    res = problem.run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0 and "factorization_precision" not in res.summary


def test_threaded_lu_is_reproducible():
    """PARDISO on several threads with the thread count fixed (iparm[33], conditional numerical reproducibility):
    the same LU factorisation bit for bit at every run (without it, two threads gave 1e-15 differences in about
    half the runs, enough to change a frictional run's iterations)."""
    A = elastic_like(22)  # 31,944 unknowns: threaded
    U = sp.triu(A, 1)
    N = (A + 0.3 * (U - U.T)).tocsr()
    N.sort_indices()
    b = N @ np.random.default_rng(2).standard_normal(N.shape[0])
    xs = []
    for _ in range(12):
        s = make_solver("pardiso", symmetric=False, precision="double")
        xs.append(s.solve(N, b))
        assert s.iparm[33] >= 1
        s.close()
    assert all(np.array_equal(x, xs[0]) for x in xs[1:])


def test_reproducible_mode_in_the_input_and_the_solver(tmp_path):
    """[solver] reproducible (default true) reaches PARDISO through Newton: false leaves MKL's reproducible mode off
    (iparm[33] = 0) on a threaded matrix, the default sets it; the solve is right either way; a non-boolean is an
    input error naming the key."""
    text = (ROOT / "examples" / "contact" / "two_blocks.toml").read_text()
    path = tmp_path / "p.toml"
    assert load_problem(ROOT / "examples" / "contact" / "two_blocks.toml").solver.reproducible is True
    path.write_text(text + '\n[solver]\nreproducible = false\n')
    problem = load_problem(path)
    assert problem.solver.reproducible is False
    path.write_text(text + '\n[solver]\nreproducible = "no"\n')
    with pytest.raises(InputError, match=r"solver\.reproducible"):
        load_problem(path)

    from covcontact.solvers.model import Model
    from covcontact.solvers.newton import Newton

    A = elastic_like(16)  # 12,288 unknowns: threaded (PARDISO_SERIAL_BELOW)
    b = A @ np.random.default_rng(3).standard_normal(A.shape[0])
    for flag in (True, False):
        options = dataclasses.replace(problem.solver, reproducible=flag, linear="pardiso")
        s = Newton(Model(problem), options).linear
        x = s.solve(A, b)
        assert (s.iparm[33] >= 1) == flag
        assert _relres(A, x, b) < 1e-10
        s.close()


def test_single_with_another_solver_is_a_warning(tmp_path):
    """linear = "auto" may resolve to a solver without single precision: the run says so and goes on."""
    problem = load_problem(ROOT / "examples" / "contact" / "two_blocks.toml")
    problem.solver = dataclasses.replace(problem.solver, factorization_precision="single")
    problem.output.vtu = False
    res = problem.run(out=tmp_path / "o", quiet=True, solver="superlu")
    assert res.exit_code == 0
    said = 'factorization_precision = "single" is for PARDISO; the linear solver superlu factorises in double precision'
    assert res.summary["warnings"] == [said]
