"""Equations with a right-hand side (``[[equation]] value``, stage ``targets``; docs/input.md, "[[equation]]"):
sum_k c_k u_k = b, b ramped from 0 to ``value`` over the first stage and moved on by the stages' targets as a
Dirichlet value is. The eliminated dof takes b / c_1 beside the others' share, through chains too."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

BAR = """
[problem]
name = "bar"
[[bodies]]
name = "a"
element = "hex8"
mesh = { generator = "block", lx = 2.0, ly = 1.0, lz = 1.0, nx = 2, ny = 1, nz = 1 }
material = { model = "svk", E = 1000.0, nu = 0.3 }
sets = { p = { nodes = [2] }, q = { nodes = [1] } }
[[dirichlet]]
set = "a.xmin"
components = "xyz"
PULL
[steps]
count = 3
"""


def _run(tmp_path, pull: str, name: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(BAR.replace("PULL", pull))
    res = load_problem(path).run(out=tmp_path / name, quiet=True)
    assert res.exit_code == 0
    return res


def test_one_term_equation_is_the_dirichlet_condition(tmp_path):
    """u_x(p) = 0.1 given as 2 u_x(p) = 0.2 (an equation) and as a Dirichlet condition: the same displacements and
    support reactions at every step to Newton's tolerance (1e-8 of the largest; the two start their steps differently:
    the Dirichlet increment with the tangent predictor, the equation's at its dof alone; measured 2.3e-10)."""
    eq = _run(tmp_path, '[[equation]]\nterms = [["a.p", "x", 2.0]]\nvalue = 0.2\n', "eq")
    bc = _run(tmp_path, '[[dirichlet]]\nset = "a.p"\ncomponents = "x"\nvalue = 0.1\n', "bc")
    assert np.abs(eq.u - bc.u).max() < 1e-8 * np.abs(bc.u).max()
    assert eq.u.reshape(-1, 3)[2, 0] == pytest.approx(0.1, abs=1e-14)
    for s, t in zip(eq.summary["steps"], bc.summary["steps"], strict=True):
        assert s["reactions"]["a.xmin"] == pytest.approx(t["reactions"]["a.xmin"], rel=1e-7, abs=1e-7)


def test_chained_equations_and_stage_targets(tmp_path):
    """u_x(p) - u_x(q) = 0.05 (p eliminated) and u_x(q) = 0.1 (q eliminated): p moves 0.15 at the first stage's end;
    a second stage takes the first equation's right-hand side to 0.1 (a target): p moves 0.2, q stays at 0.1."""
    pull = ('[[equation]]\nname = "gap"\nterms = [["a.p", "x", 1.0], ["a.q", "x", -1.0]]\nvalue = 0.05\n'
            '[[equation]]\nterms = [["a.q", "x", 1.0]]\nvalue = 0.1\n'
            '[[stages]]\nname = "more"\ntargets = { gap = 0.1 }\nsteps = { count = 2 }\n')
    res = _run(tmp_path, pull, "chain")
    first = [s for s in res.summary["steps"] if s["stage"] == res.summary["steps"][0]["stage"]]
    assert len(first) == 3 and len(res.summary["steps"]) == 5
    U = res.u.reshape(-1, 3)
    assert U[2, 0] == pytest.approx(0.2, abs=1e-14) and U[1, 0] == pytest.approx(0.1, abs=1e-14)


def test_right_hand_side_in_a_dynamic_problem_is_one_line(tmp_path):
    """A right-hand side with dynamic stages is refused in one line naming the equation (the eliminated dof's
    velocity would miss its rate)."""
    text = BAR.replace("PULL", '[[equation]]\nterms = [["a.p", "x", 1.0]]\nvalue = 0.1\n').replace(
        'name = "bar"\n', 'name = "bar"\nprocedure = "dynamic"\ndt = 0.1\nt_end = 0.2\n').replace(
        "nu = 0.3 }", "nu = 0.3, density = 1.0 }").replace("[steps]\ncount = 3\n", "")
    path = tmp_path / "d.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"equation\[0\]\.value: a right-hand side .* dynamic stages"):
        load_problem(path)


def test_reduce_matrix_is_the_triple_product():
    """solvers.constraints.reduce_matrix forms T^T K T (T = diag(keep) + A, A's rows at the dependent dofs) from K's
    entries and thin products: equal to the product with the n x n map to round-off, on an unsymmetric random K with
    dependents that refer to each other's neighbours, with an extra matrix added."""
    import scipy.sparse as sp

    from covcontact.solvers.constraints import reduce_matrix

    rng = np.random.default_rng(3)
    n = 40
    K = sp.random(n, n, density=0.2, random_state=4, format="csr") + sp.eye(n)
    dependent = np.array([3, 11, 25, 31])
    keep = np.ones(n)
    keep[dependent] = 0.0
    A = sp.lil_matrix((n, n))
    for d in dependent:
        for c in rng.choice(np.flatnonzero(keep), 3, replace=False):
            A[d, c] = rng.standard_normal()
    A = A.tocsr()
    T = sp.diags(keep) + A
    extra = sp.random(n, n, density=0.05, random_state=5, format="csr")
    want = (T.T @ K @ T + extra).toarray()
    got = reduce_matrix(K, keep.astype(bool), dependent, A[dependent], extra).toarray()
    np.testing.assert_allclose(got, want, atol=1e-13 * np.abs(want).max())
