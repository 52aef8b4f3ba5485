"""Newton with cutbacks and line search on a problem whose full step inverts elements."""

import zlib
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

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


def test_inversion_is_backtracked_inside_newton(tmp_path):
    """The full step's predictor inverts an element: Newton halves that correction (and any later one that
    inverts) until every element is valid and converges in the one step, without a cutback; the answer is
    the one reached with cutbacks (two half steps)."""
    res = poke(4.0).run(out=tmp_path / "one")
    s = res.summary["steps"][0]
    assert res.exit_code == 0 and s["converged"] and s["cutbacks"] == 0
    assert s["backtracks"] >= 1
    # the poked node went down by more than the element height (0.5) without any element inverting
    centre = res.model.problem.bodies[0].mesh.node_sets["centre"][0]
    assert res.u.reshape(-1, 3)[centre, 2] < -0.5
    prob = poke(4.0)
    prob.steps = Steps.equal(4)
    ref = prob.run(out=tmp_path / "four")
    np.testing.assert_allclose(res.u, ref.u, atol=1e-8)


def test_inversion_past_the_backtracks_cuts_back_and_exhausted_cutbacks_keep_converged_steps(tmp_path,
                                                                                            monkeypatch):
    """With no backtracking left, an inverting correction cuts the increment back; with no cutbacks left
    either, the run stops with the converged steps kept (exit 1) and says why."""
    from covcontact.solvers import newton

    monkeypatch.setattr(newton, "MAX_BACKTRACKS", 0)
    res = poke(4.0).run(out=tmp_path / "cut")
    s = res.summary["steps"][0]
    assert res.exit_code == 0 and s["cutbacks"] >= 1
    assert any("inverted" in r and "(centre at " in r for r in s["cutback_reasons"]), s["cutback_reasons"]
    prob = poke(4.0)
    prob.steps = Steps((0.05, 1.0))
    prob.solver = SolverOptions(max_cutbacks=0)
    res = prob.run(out=tmp_path / "stop")
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
    same converged states as the tangent predictor, in no more iterations on a friction problem
    (examples/friction/block_sliding.toml: 22 against 24; 22 against 47 while a trial traction on the Coulomb
    cone stuck, see docs/performance.md "Predictors")."""
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
    assert b.summary["total_iterations"] < a.summary["total_iterations"]
    assert np.allclose(a.u, b.u, atol=1e-8 * np.abs(a.u).max())
    for sa, sb in zip(a.summary["steps"], b.summary["steps"], strict=True):
        # components that vanish by symmetry are compared at the solver's tolerance of the force's size
        scale = float(np.linalg.norm(sa["contact_force"]))
        np.testing.assert_allclose(sb["contact_force"], sa["contact_force"], rtol=1e-6, atol=1e-8 * scale)


class _NoisyLinearModel:
    """K u = lam f with a residual that cannot fall below ``floor`` (a stand-in for round-off, as in thin
    shells: eps_mach E A per node): R(u) = K u - lam f + floor * r(u), r of unit norm."""

    symmetric = True

    def __init__(self, floor: float):
        rng = np.random.default_rng(0)
        A = rng.standard_normal((6, 6))
        self.K = sp.csr_matrix(A @ A.T + 6.0 * np.eye(6))
        self.f = rng.standard_normal(6)
        self.free = np.ones(6, dtype=bool)
        self.floor = floor

    def near_null_space(self):
        return None

    def start_step(self, committed):
        return committed

    def begin_step(self):
        pass

    def prescribed(self, lam):
        return np.zeros(6)

    def external(self, lam):
        return lam * self.f

    def eliminate(self, K):
        return K

    def active_count(self, trial):
        return 0

    def evaluate(self, u, lam, committed, guess, want_K=True, timing=None):
        noise = np.random.default_rng(zlib.crc32(u.tobytes())).standard_normal(6)  # changes with every u
        R = self.K @ u - lam * self.f + self.floor * noise / np.linalg.norm(noise)
        return R, self.K, guess


def test_step_starting_almost_converged_stops_at_the_round_off_floor():
    """A step whose first iterate is already within 1e-6 of the solution (as after the extrapolating
    predictor) has its relative references (R_0, R_1, the first energy) near the floor itself; it must
    converge once the residual is below rtol of the force scale and has stopped falling, not run out of
    iterations."""
    from covcontact.solvers.newton import Newton

    model = _NoisyLinearModel(floor=1e-10)
    u = np.linalg.solve(model.K.toarray(), model.f) + 1e-6          # almost the solution at lam = 1
    newton = Newton(model, SolverOptions(rtol=1e-8, atol=1e-14, max_iterations=25), linear="superlu")
    out, _ = newton.step(u, 0.0, 1.0, None)
    assert out.converged, out.reason
    assert out.iterations <= 4
    r = out.residual_norms
    assert r[-1] < 1e-8 * np.linalg.norm(model.f) and r[-1] >= 0.5 * r[-2]
    assert np.linalg.norm(model.K @ u - model.f) < 1e-9
    # a residual that is still falling fast is not taken for the floor
    model.floor = 0.0
    u = np.linalg.solve(model.K.toarray(), model.f) + 1e-6
    out, _ = newton.step(u, 0.0, 1.0, None)
    assert out.converged and out.residual_norms[-1] < 1e-13



def test_a_cycling_iteration_is_recognised():
    """Residual norms that repeat with a period of 2..4 iterations three times over (to 1e-6) are a cycle (an
    active set going round, as measured on the U-channel's flange: 3.65e-2, 11.26, 3.46, ...); a converging or
    merely oscillating-and-falling sequence is not."""
    from covcontact.solvers.newton import _cycle

    cyc = [5.0, 4.0] + [3.648597e-02, 1.125925e+01, 3.455922e+00] * 3 + [3.648596e-02]
    assert _cycle(cyc) == 3
    assert _cycle([1.0] + [2.0, 1.5] * 3 + [2.0]) == 2
    assert _cycle([1.0, 2.0, 1.5] * 2) == 0  # two periods are not enough
    assert _cycle([2.0 * 0.9 ** k for k in range(20)]) == 0  # falling
    assert _cycle([1.0, 2.0, 1.5, 2.0, 1.5 * (1 + 1e-5), 2.0, 1.5, 2.0]) == 0  # a period differs beyond 1e-6


def test_a_diverging_iteration_is_recognised():
    """Residual norms that grew in three iterations in a row to above the step's reference, from the fourth iteration
    on, lead away (an extrapolated start of a plastic wire bent round a tool, measured: 411, 140, 79, 139, 130, 187,
    234, 370, 706, ... for 24 iterations); a contact step that rises twice and then converges (10.7, 19.1, 1.2e-2,
    0.14, 60, 1.4e-2, 1.4e-7, measured on two blocks) and a rise that stays below the reference do not."""
    from covcontact.solvers.newton import _diverging

    wire = [411.1, 139.6, 78.8, 138.9, 129.9, 187.1, 233.9, 370.2, 706.1]
    assert [_diverging(wire[:k], 411.1) for k in range(5, 10)] == [False, False, False, False, True]
    blocks = [10.7, 19.1, 1.16e-2, 0.139, 60.0, 1.36e-2, 1.37e-7]
    assert not any(_diverging(blocks[:k], 19.1) for k in range(2, 8))
    assert not _diverging([1.0, 0.5, 0.1, 0.2, 0.3, 0.4], 1.0)  # three rises, below the reference
    assert _diverging([1.0, 0.5, 0.1, 0.2, 0.3, 1.4], 1.0)
