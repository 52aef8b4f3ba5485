"""Inexact Newton with factorisation reuse ([solver] reuse_factorization): GMRES preconditioned by the last
factorisation gives the same Newton iterations and the same results as a factorisation per iteration, with
fewer factorisations (docs/performance.md, "Factorisation reuse")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.problem import Steps
from covcontact.solvers.linear import available

ROOT = Path(__file__).resolve().parents[2]


def _run(path: Path, reuse: bool, tmp: Path):
    problem = load_problem(path)
    problem.solver = dataclasses.replace(problem.solver, reuse_factorization=reuse, linear="superlu")
    res = problem.run(out=tmp / ("reuse" if reuse else "plain"), quiet=True, tangent="exact")
    assert res.exit_code == 0
    return res.summary


@pytest.mark.parametrize("example", ["contact/two_blocks.toml", "contact/block_on_sphere.toml",
                                     "friction/block_sliding.toml"])
def test_same_iterations_and_results_with_fewer_factorizations(tmp_path, example):
    path = ROOT / "examples" / example
    plain, reuse = _run(path, False, tmp_path), _run(path, True, tmp_path)
    assert [s["iterations"] for s in reuse["steps"]] == [s["iterations"] for s in plain["steps"]]
    assert [s["factorizations"] for s in plain["steps"]] == [s["iterations"] for s in plain["steps"]]
    n_plain = sum(s["factorizations"] for s in plain["steps"])
    n_reuse = sum(s["factorizations"] for s in reuse["steps"])
    assert n_reuse < n_plain and sum(s["krylov_iterations"] for s in reuse["steps"]) > 0
    for a, b in zip(plain["steps"], reuse["steps"], strict=True):
        # components that vanish (sliding's lateral one) are zero to Newton's tolerance, relative to the force
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-6,
                                   atol=1e-9 * np.linalg.norm(a["contact_force"]))
        assert b["residual_norms"][-1] <= 1e-8 or b["residual_norms"][-1] <= 10 * a["residual_norms"][-1]


def test_one_factorisation_per_step_on_the_hertz_ball(tmp_path):
    """The goal of factorisation reuse: a factorisation per load step (no cutbacks here) while every step takes
    the iterations of exact Newton; per-step counts and times in summary.json."""
    import sys

    sys.path.insert(0, str(ROOT / "tests" / "verification"))
    from hertz_setup import hertz_mesh, hertz_problem

    runs = {}
    for reuse in (False, True):
        problem = hertz_problem(hertz_mesh(10, 5), "svk", steps=5, vtu=False)
        problem.solver = dataclasses.replace(problem.solver, reuse_factorization=reuse)
        runs[reuse] = problem.run(out=tmp_path / str(reuse), quiet=True).summary
    plain, reuse = runs[False]["steps"], runs[True]["steps"]
    assert [s["iterations"] for s in reuse] == [s["iterations"] for s in plain]
    assert [s["factorizations"] for s in reuse] == [1] * len(reuse)
    assert all(s["krylov_iterations"] > 0 and s["krylov_s"] > 0 and s["factor_s"] > 0 for s in reuse)
    assert all(s["krylov_iterations"] == 0 and s["krylov_s"] == 0 for s in plain)
    for a, b in zip(plain, reuse, strict=True):
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-8,
                                   atol=1e-10 * np.linalg.norm(a["contact_force"]))
    rows = (tmp_path / "True" / "convergence.csv").read_text().splitlines()
    assert {r.split(",")[5] for r in rows[1:]} >= {"factor", "krylov"}


@pytest.mark.skipif("pardiso" not in available(), reason="pypardiso not installed (the other backends always reuse)")
def test_auto_reuses_only_expensive_pardiso_factorisations():
    """reuse_factorization = "auto": PARDISO reports the factorisation's flops against one substitution's; a
    small bulky tangent (3 dofs per node, 8^3 nodes) is not worth reusing, a larger one (14^3) is."""
    import scipy.sparse as sp

    from covcontact.solvers.linear import make_solver
    from covcontact.solvers.pardiso_backend import REUSE_MIN_FLOP_RATIO

    def elastic_like(m):
        T = sp.diags([-np.ones(m - 1), 2 * np.ones(m), -np.ones(m - 1)], [-1, 0, 1])
        eye = sp.identity(m)
        lap = sp.kron(sp.kron(T, eye), eye) + sp.kron(sp.kron(eye, T), eye) + sp.kron(sp.kron(eye, eye), T)
        return sp.kron(lap, np.ones((3, 3)) + 3 * np.eye(3)).tocsr()

    ratios = []
    for m in (8, 14):
        solver = make_solver("pardiso")
        solver.factorize(elastic_like(m))
        ratios.append(solver.flop_ratio)
        assert solver.reuse_pays() == (solver.flop_ratio >= REUSE_MIN_FLOP_RATIO)
    assert ratios[0] < REUSE_MIN_FLOP_RATIO <= ratios[1], ratios


def test_reuse_option_in_the_input(tmp_path):
    text = (ROOT / "examples" / "contact" / "two_blocks.toml").read_text()
    for value, ok in (('"auto"', True), ("false", True), ('"sometimes"', False), ("1", False)):
        path = tmp_path / "p.toml"
        path.write_text(text + f"\n[solver]\nreuse_factorization = {value}\n")
        if ok:
            assert load_problem(path).solver.reuse_factorization == ("auto" if value == '"auto"' else False)
        else:
            from covcontact.io.validate import InputError

            with pytest.raises(InputError, match=r"solver\.reuse_factorization: must be true, false or \"auto\""):
                load_problem(path)


AMG = [name for name in ("cg-amg", "petsc-gamg") if name in available()]


@pytest.mark.parametrize("amg", AMG)
def test_amg_stops_cg_at_the_forcing_term(tmp_path, amg):
    """cg-amg (pyamg) and petsc-gamg (PETSc's GAMG, the distributed model on one process) with reuse on: CG
    stopped at Newton's forcing term on the step's hierarchy (the two blocks' tangent changes little within a
    step, so one hierarchy per step); the Newton iterations and the results are those of a hierarchy and a
    1e-10 solve per iteration."""
    path = ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml"
    runs = {}
    for reuse in (False, True):
        problem = load_problem(path)
        problem.solver = dataclasses.replace(problem.solver, reuse_factorization=reuse, linear=amg)
        problem.steps = Steps((0.1, 0.2, 0.3))  # the first three of its ten steps
        res = problem.run(out=tmp_path / str(reuse), quiet=True)
        assert res.exit_code == 0
        runs[reuse] = res.summary["steps"]
    plain, reuse = runs[False], runs[True]
    assert [s["iterations"] for s in reuse] == [s["iterations"] for s in plain]
    assert [s["factorizations"] for s in reuse] == [1] * len(reuse)
    assert [s["factorizations"] for s in plain] == [s["iterations"] for s in plain]
    assert all(s["krylov_iterations"] > 0 for s in reuse) and all(s["krylov_iterations"] == 0 for s in plain)
    for a, b in zip(plain, reuse, strict=True):
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-8,
                                   atol=1e-8 * np.linalg.norm(a["contact_force"]))


@pytest.mark.parametrize("amg", AMG)
def test_amg_builds_new_hierarchies_on_the_hertz_ball(tmp_path, amg):
    """On the Hertz ball the contact zone changes the tangent between iterations (new couplings, or CG on the
    step's hierarchy needing more than twice the first correction's iterations): later corrections build
    their own hierarchies; the Newton iterations stay those of the solver's own solves."""
    import sys

    sys.path.insert(0, str(ROOT / "tests" / "verification"))
    from hertz_setup import hertz_mesh, hertz_problem

    runs = {}
    for reuse in (False, True):
        problem = hertz_problem(hertz_mesh(10, 5), "svk", steps=2, vtu=False)
        problem.solver = dataclasses.replace(problem.solver, reuse_factorization=reuse, linear=amg)
        runs[reuse] = problem.run(out=tmp_path / str(reuse), quiet=True).summary["steps"]
    plain, reuse = runs[False], runs[True]
    assert [s["iterations"] for s in reuse] == [s["iterations"] for s in plain]
    assert any(1 < s["factorizations"] for s in reuse)
    for a, b in zip(plain, reuse, strict=True):  # both within Newton's relative residual of 1e-8
        assert a["residual_norms"][-1] <= 1e-8 and b["residual_norms"][-1] <= 1e-8
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-7,
                                   atol=1e-10 * np.linalg.norm(a["contact_force"]))
