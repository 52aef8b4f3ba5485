"""Inexact Newton with factorisation reuse ([solver] reuse_factorization): GMRES preconditioned by the last
factorisation gives the same Newton iterations and the same results as a factorisation per iteration, with
fewer factorisations (docs/performance.md, "Factorisation reuse")."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem

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
        np.testing.assert_allclose(b["contact_force"], a["contact_force"], rtol=1e-6, atol=1e-9)
        assert b["residual_norms"][-1] <= 1e-8 or b["residual_norms"][-1] <= 10 * a["residual_norms"][-1]
