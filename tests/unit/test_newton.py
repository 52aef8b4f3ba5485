"""Newton with cutbacks and line search on a problem whose full step inverts elements."""

from pathlib import Path

import numpy as np
import pytest

from covcontact.materials import NeoHooke
from covcontact.mesh.generators import block
from covcontact.problem import Body, Dirichlet, NodalForce, OutputOptions, Problem, SolverOptions, Steps


def squash(line_search: bool = False, steps: int = 1, max_cutbacks: int = 6) -> Problem:
    """A Neo-Hooke block compressed to 45 % of its height, clamped at both ends."""
    mesh = block(1.0, 1.0, 1.0, 3, 3, 3, cell="hex8")
    return Problem(
        name="squash",
        bodies=[Body("b", mesh, NeoHooke(E=10.0, nu=0.3))],
        dirichlet=[Dirichlet("b", "zmin", (0, 1, 2), (0.0, 0.0, 0.0)),
                   Dirichlet("b", "zmax", (0, 1, 2), (0.0, 0.0, -0.55))],
        steps=Steps.equal(steps),
        solver=SolverOptions(line_search=line_search, max_cutbacks=max_cutbacks),
        output=OutputOptions(vtu=False),
    )


def poke(force: float) -> Problem:
    """A soft Neo-Hooke cube on a clamped base, poked by a point force at the centre of its top."""
    mesh = block(1.0, 1.0, 1.0, 2, 2, 2, cell="hex8")
    p = mesh.points
    centre = np.flatnonzero((np.abs(p[:, 2] - 1) < 1e-9) & (np.abs(p[:, 0] - 0.5) < 1e-9)
                            & (np.abs(p[:, 1] - 0.5) < 1e-9))
    mesh.add_node_set("centre", centre)
    return Problem(name="poke", bodies=[Body("b", mesh, NeoHooke(E=10.0, nu=0.3))],
                   dirichlet=[Dirichlet("b", "zmin", (0, 1, 2), (0.0, 0.0, 0.0))],
                   forces=[NodalForce("b", "centre", (0.0, 0.0, -force))],
                   steps=Steps.equal(1), output=OutputOptions(vtu=False))


def test_inversion_triggers_cutbacks_then_converges(tmp_path):
    """The full step's predictor inverts an element; the step is cut back and then converges."""
    res = poke(4.0).run(out=tmp_path)
    s = res.summary["steps"][0]
    assert res.exit_code == 0 and s["converged"]
    assert s["cutbacks"] >= 1
    assert any("inverted" in r for r in s["cutback_reasons"]), s["cutback_reasons"]
    # the poked node went down by more than the element height (0.5) without any element inverting
    assert res.u.reshape(-1, 3)[res.model.problem.bodies[0].mesh.node_sets["centre"][0], 2] < -0.5


def test_cutback_budget_exhausted_keeps_converged_steps(tmp_path):
    prob = poke(4.0)
    prob.steps = Steps((0.05, 1.0))
    prob.solver = SolverOptions(max_cutbacks=0)
    res = prob.run(out=tmp_path)
    assert res.exit_code == 1
    assert res.summary["converged"] is False
    assert [s["converged"] for s in res.summary["steps"]] == [True, False]
    assert "inverted" in res.summary["steps"][-1]["failure"]


def test_line_search_gives_the_same_answer(tmp_path):
    a = squash(steps=4).run(out=tmp_path / "a")
    b = squash(steps=4, line_search=True).run(out=tmp_path / "b")
    assert a.exit_code == 0 and b.exit_code == 0
    assert np.allclose(a.u, b.u, atol=1e-9)


def test_energy_norm_and_residual_recorded(tmp_path):
    res = squash(steps=4).run(out=tmp_path)
    lines = (tmp_path / "convergence.csv").read_text().splitlines()[1:]
    assert len(lines) >= res.summary["total_iterations"]
    for s in res.summary["steps"]:
        r = s["residual_norms"]
        assert r[0] == pytest.approx(1.0) and r[-1] < 1e-8


def test_extrapolating_predictor_same_answer_fewer_iterations(tmp_path):
    """[solver] predictor = "extrapolate": the previous step's increment, scaled, as the first iterate; the
    same converged states as the tangent predictor, in fewer iterations on a friction problem (measured on
    examples/friction/block_sliding.toml: 22 against 47)."""
    import dataclasses

    from covcontact.io.loader import load_problem

    path = Path(__file__).resolve().parents[2] / "examples" / "friction" / "block_sliding.toml"
    runs = {}
    for pred in ("tangent", "extrapolate"):
        problem = load_problem(path)
        problem.solver = dataclasses.replace(problem.solver, predictor=pred)
        runs[pred] = problem.run(out=tmp_path / pred, quiet=True)
        assert runs[pred].exit_code == 0
    a, b = runs["tangent"], runs["extrapolate"]
    assert b.summary["total_iterations"] < 0.7 * a.summary["total_iterations"]
    assert np.allclose(a.u, b.u, atol=1e-8 * np.abs(a.u).max())
    for sa, sb in zip(a.summary["steps"], b.summary["steps"], strict=True):
        np.testing.assert_allclose(sb["contact_force"], sa["contact_force"], rtol=1e-6, atol=1e-9)
