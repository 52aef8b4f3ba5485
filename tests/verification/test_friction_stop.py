"""A block sliding to rest on a rigid plane with Coulomb friction (dynamic stage; docs/verification.md, "Friction
at rest in a dynamic stage").

Reference: a rigid block of mass m launched at v0 on a plane with friction coefficient mu under gravity g slides
with the deceleration mu g (the friction force mu m g) and stops at t_s = v0 / (mu g), after the distance
v0^2 / (2 mu g); then it stays at rest (the static friction holds it). Set-up: a block 1 x 1 x 0.5 (3 x 3 x 2 hex8,
SVK, E = 1e4, nu = 0.3, density 1, m = 0.5) on a rigid plane (node-to-surface, penalty 1e5 per area, mu = 0.3),
gravity 10: a static stage under its weight, then a dynamic stage of 0.5 with dt = 0.005 and v0 = 1 on every node
(t_s = 1/3, distance 1/6).

Generalized-alpha with rho_inf = 0 removes the ringing of the block on the contact penalty (period 0.014, under
three steps): the friction force is mu m g at every step of the slide. The trapezoidal rule (Newmark) keeps it,
the block rocks and rattles on the plane, and the nodes that touch down again slide without friction for that
step (no history: state NEW), so the block stops 2 to 7 % late; what is checked there is Newton.

The bug this guards against: once the block stopped, full Newton corrections carried the bottom nodes across
their narrow stick band (slip one way, slip the other way and back: a two-cycle that the stick/slip codes do
not show), 20 to 190 iterations per step with cutbacks; a dynamic stage with friction now takes Newton's
corrections with the secant line search (covcontact.solvers.dynamics.Dynamic.advance). Measured: at most 7
(consistent), 8 (lumped), 10 (redistributed) iterations per step after the stop with the trapezoidal rule,
at most 8 with rho_inf = 0, none cut back.
"""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem

MU, G, V0, M = 0.3, 10.0, 1.0, 0.5
T_STOP = V0 / (MU * G)  # 1/3
DISTANCE = V0 ** 2 / (2.0 * MU * G)  # 1/6
DT = 0.005

BLOCK = """
[problem]
name = "friction-stop"
gravity = [0.0, 0.0, -10.0]
[[bodies]]
name = "block"
material = { model = "svk", E = 1.0e4, nu = 0.3, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 3, ny = 3, nz = 2 }
[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[contact]]
slave = "block.zmin"
master = "floor"
penalty = 1.0e5
weighting = "area"
friction = 0.3
[[initial_velocity]]
body = "block"
value = [1.0, 0.0, 0.0]
[[stages]]
name = "slide"
procedure = "dynamic"
dt = 0.005
t_end = 0.5
METHOD
mass = "MASS"
[output]
vtu = false
"""


def run(tmp_path, method: str, mass: str):
    path = tmp_path / "block.toml"
    path.write_text(BLOCK.replace("METHOD", method).replace("MASS", mass))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    steps = [s for s in res.summary["steps"] if s.get("stage") == "slide"]
    t = np.array([s["time"] for s in steps]) - 1.0  # (the static stage ends at 1)
    force = np.array([s["contact_force"] for s in steps])  # on the block
    return res, steps, t, force


def test_block_stops_at_the_coulomb_time(tmp_path):
    """rho_inf = 0: every bottom node slips with the friction force mu N and N = m g (to 2 %, the start's ringing
    decays) until the stop at v0 / (mu g) (the first step in which a node sticks; within 2 dt, the start loses
    half a step of friction), then the block is at rest after v0^2 / (2 mu g), the kinetic energy m v0^2 / 2 gone
    into frictional dissipation; at most 8 Newton iterations per step and no cutback."""
    res, steps, t, force = run(tmp_path, 'method = "generalized-alpha"\nrho_inf = 0.0', "consistent")
    slip = np.array([s["pairs"]["contact1"]["slip"] for s in steps])
    t_stop = t[np.argmax(slip < 16)]
    assert T_STOP <= t_stop <= T_STOP + 2 * DT
    before = t < t_stop
    assert np.all(slip[before] == 16)
    np.testing.assert_allclose(-force[before, 0], MU * force[before, 2], rtol=1e-5)
    np.testing.assert_allclose(force[before, 1], 0.0, atol=1e-8)
    np.testing.assert_allclose(force[before, 2], M * G, rtol=0.02)
    assert np.mean(force[before, 2]) == pytest.approx(M * G, rel=2e-3)
    assert np.all(slip[t > t_stop + 10 * DT] == 0)  # stuck for good once the ringing on the stick springs decayed
    v = res.state.dynamics["v"].reshape(-1, 3)
    assert np.abs(v).max() < 0.01 * V0
    u = res.u.reshape(-1, 3)
    assert u[:, 0].mean() == pytest.approx(DISTANCE, rel=0.02)
    assert np.ptp(u[:, 0]) < 1e-3 * DISTANCE  # (it moved as a whole)
    assert sum(s["cutbacks"] for s in steps) == 0
    assert max(s["iterations"] for s in steps) <= 8
    # the energy account: the contact took the kinetic energy m v0^2 / 2 out as frictional dissipation
    energy = steps[-1]["energy"]
    assert energy["contact_dissipation"] == pytest.approx(0.5 * M * V0 ** 2, rel=5e-3)
    assert abs(energy["balance_error"]) < 2e-3


@pytest.mark.parametrize("mass", ["consistent", "lumped", "redistributed"])
def test_newton_at_rest_with_the_trapezoidal_rule(tmp_path, mass):
    """Newmark: the block slides the distance v0^2 / (2 mu g) to within 3 % and then stays at rest (its
    momentum, integrated from the contact force by the trapezoidal rule, below 5 % of m v0 from 0.36 on), and
    Newton converges at every step after the stop in at most 10 iterations, 6 on average, with no cutback (it
    took up to 190 iterations and cutbacks before)."""
    res, steps, t, force = run(tmp_path, 'method = "newmark"', mass)
    assert sum(s["cutbacks"] for s in steps) == 0
    after = [s["iterations"] for s, ts in zip(steps, t) if ts > T_STOP + 2 * DT]
    assert max(after) <= 10 and np.mean(after) <= 6.0
    u = res.u.reshape(-1, 3)
    assert u[:, 0].mean() == pytest.approx(DISTANCE, rel=0.03)
    dt = np.diff(np.r_[0.0, t])
    p = M * V0 + np.cumsum(0.5 * dt * (np.r_[0.0, force[:-1, 0]] + force[:, 0]))  # (no friction at the start)
    assert np.abs(p[t > 0.36]).max() < 0.05 * M * V0
