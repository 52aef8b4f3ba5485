"""Impacts under gravity with the dynamic defaults (docs/verification.md, "Impacts with the dynamic defaults: a block
dropped on a floor, a ball bouncing").

Both problems give no ``method``, ``rho_inf`` or ``mass``: generalized-alpha with rho_inf = 1 and ``mass = "auto"``,
which resolves to ``"consistent-redistributed"`` (the contact-surface nodes massless, their mass moved to their
elements' other nodes; docs/theory.md section 20). The bodies' energy is E_b = kinetic + strain + contact -
external_work (gravity's work is in external_work); it may fall (the step's numerical losses) but must not rise.

References: free fall (closed form): a body released at rest a height h above a surface reaches it after
sqrt(2 h / g); a body leaving a surface at speed v rises by v^2 / (2 g) (its centre of mass moves by its weight
alone in flight). Hertz's impact (Johnson, Contact Mechanics, 1985, section 11.4, as in hertz_setup.py): the ball a
rigid mass m on the quasi-static Hertz compliance F = 4/3 E* sqrt(R) d^1.5; with its weight m g added to the
equation of motion m d'' = m g - F(d) (d the approach, d(0) = 0, d'(0) = v), integrated here numerically, for the
contact duration and the peak force (without the weight the closed forms of impact_reference).
"""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest
from hertz_setup import C_HERTZ, E, NU, hertz_mesh, impact_reference
from scipy.integrate import solve_ivp

from covcontact.io.loader import load_problem
from covcontact.materials import SaintVenantKirchhoff
from covcontact.problem import (
    Body,
    ContactPair,
    Dirichlet,
    Dynamics,
    InitialVelocity,
    OutputOptions,
    Problem,
    RigidBody,
)

# --- the block dropped on a floor
H, G_DROP, DT_DROP = 0.021, 1.0, 0.005
T_FALL = math.sqrt(2.0 * H / G_DROP)  # 0.2049
DROP = f"""
[problem]
name = "drop"
procedure = "dynamic"
dt = {DT_DROP}
t_end = 0.75
gravity = [0.0, 0.0, -{G_DROP}]
[[bodies]]
name = "floor"
material = {{ model = "svk", E = 4000.0, nu = 0.3, density = 1.0 }}
mesh = {{ generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 2, ny = 2, nz = 2, origin = [-0.5, -0.5, -0.5] }}
[[bodies]]
name = "block"
material = {{ model = "svk", E = 400.0, nu = 0.3, density = 1.0 }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 2, origin = [0.0, 0.0, {H}] }}
[[dirichlet]]
set = "floor.zmin"
components = "xyz"
value = 0.0
[[contact]]
slave = "block.zmin"
master = "floor.zmax"
penalty = 1.0e5
weighting = "area"
[output]
vtu = false
checkpoint_every = 100000
"""

# --- the ball bouncing on a rigid plane
V0 = 1e-3
T_C = impact_reference(V0)[0]          # Hertz's contact duration without the weight: 14.78
G_BALL = 2.0 * V0 / (1.5 * T_C)        # flight 2 V0 / g = 1.5 T_C between the bounces: g = 9.02e-5
DT_BALL = T_C / 20.0


def _episodes(steps):
    """(first, last) step index of every run of steps with the contact closed."""
    act = np.array([s["active_contacts"] > 0 for s in steps], dtype=int)
    d = np.diff(np.concatenate(([0], act, [0])))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def _bodies_energy(steps):
    """E_b = kinetic + strain + contact - external_work per step, and the energy in the system (the scale of
    balance_error: the larger of kinetic + strain + contact and |external_work|)."""
    e = np.array([[s["energy"][k] for k in ("kinetic", "strain", "contact", "external_work")] for s in steps])
    held = e[:, 0] + e[:, 1] + e[:, 2]
    return held - e[:, 3], np.maximum(held, np.abs(e[:, 3]))


def _hertz_with_weight(m: float, g: float, v: float) -> tuple[float, float]:
    """Johnson's quasi-static Hertz impact (section 11.4) with the weight: (contact duration, peak force) of
    m d'' = m g - C d^1.5, d(0) = 0, d'(0) = v, C = 4/3 E* sqrt(R)."""
    def leave(t, y):
        return y[0] if t > 0.0 else 1.0
    leave.terminal, leave.direction = True, -1
    sol = solve_ivp(lambda t, y: [y[1], g - C_HERTZ * max(y[0], 0.0) ** 1.5 / m], (0.0, 10.0 * T_C), [0.0, v],
                    events=leave, rtol=1e-10, atol=1e-14, dense_output=True)
    t_end = float(sol.t_events[0][0])
    d = sol.sol(np.linspace(0.0, t_end, 20001))[0]
    return t_end, float(C_HERTZ * np.max(np.maximum(d, 0.0)) ** 1.5)


def test_block_dropped_on_a_floor(tmp_path):
    """An elastic block (1 x 1 x 0.5, 2 x 2 x 2 hex8, E = 400, nu = 0.3, rho = 1) released at rest h = 0.021 above a
    deformable floor (2 x 2 x 0.5, 2 x 2 x 2 hex8, E = 4000, held at its bottom), g = 1, dt = 0.005 to t = 0.75,
    node-to-surface contact block bottom -> floor top (penalty 1e5 per area). Asserted: the first impact at the
    free-fall time sqrt(2 h / g) = 0.2049 within two steps (measured: the first step in contact ends at 0.205, the
    one before, at 0.200, has the gap h - g t^2 / 2 = 0.001 to 1.2e-5), two impacts (measured: in contact 0.205 to
    0.270 and 0.585 to 0.635), the bodies' energy never above its start (5.6e-6: the massless contact nodes
    balanced at the start, their static deflection) by more than 1 % of the energy in the system at any step
    (measured: at most 9e-6 of it; the largest fall 1.4 % of the impact energy, in contact), no energy_growth in
    summary.json, the energy balance within 1 % (measured -1.0e-4 to 5.2e-4).
    The block does not come to rest: nothing damps it (rho_inf = 1; rho_inf < 1 would damp only the high
    frequencies). It leaves the floor at about 0.77 of its impact speed (the flight time 0.315 between the
    impacts, g T / 2 against sqrt(2 g h)); the rest of the energy rings in the block and the floor."""
    path = tmp_path / "drop.toml"
    path.write_text(DROP)
    res = load_problem(path).run(out=tmp_path / "drop")
    assert res.exit_code == 0
    summary = res.summary
    assert summary["mass"] == {"stage1": "consistent-redistributed"}  # what "auto" resolves to with contact
    assert "energy_growth" not in summary, summary["energy_growth"]
    steps = summary["steps"]
    episodes = _episodes(steps)
    assert len(episodes) >= 2, episodes
    first = episodes[0][0]
    t = np.array([s["time"] for s in steps])
    assert abs(t[first] - T_FALL) <= 2.0 * DT_DROP, (t[first], T_FALL)
    # the free fall before it: the gap of the step before the impact
    assert steps[first - 1]["min_gap"] == pytest.approx(H - 0.5 * G_DROP * t[first - 1] ** 2, abs=1e-4)
    body, system = _bodies_energy(steps)
    # the start's energy (the static deflection of the massless contact nodes, balanced at the start: 5.6e-6) from
    # the first step's balance: balance_error = (E_b + contact_dissipation - E_0) / scale
    e1 = steps[0]["energy"]
    start = body[0] + e1["contact_dissipation"] - e1["balance_error"] * system[0]
    assert 0.0 <= start < 1e-3 * system.max()
    assert np.all(body <= start + 0.01 * system), (float(np.max((body - start) / system)), t[np.argmax(body / system)])
    assert max(abs(s["energy"]["balance_error"]) for s in steps) < 0.01


def test_ball_bounces_five_times(tmp_path):
    """The quarter half-ball of hertz_setup (R = 1, E = 1, nu = 0.3, St. Venant-Kirchhoff, density 1, symmetry
    planes), the coarse mesh hertz_mesh(8, 4) (369 nodes; the faceted half-ball's mass 1.942, 7 % below 2 pi / 3),
    touching the rigid plane z = 0 at t = 0 at V0 = 1e-3 downward under g = 9.02e-5 (a flight of 1.5 T_C between
    bounces, T_C = 14.78 Hertz's duration without the weight), dt = T_C / 20, 12.4 T_C (248 steps), penalty 1e4 per
    area. Rebound speeds from the apex heights of the centre of mass (the consistent mass's nodal weights) between
    the contacts: v_k = sqrt(2 g h_k). Asserted: five contacts (five closings, five openings, none shorter than
    0.8 of Hertz's duration: no chatter); the first contact's peak force within 2 % of Hertz's with the weight (the
    weight, a quarter of F_max, makes it 1.537 F_max and the contact 1.092 T_C; measured +0.45 %) and its end
    within 0.90 to 1.03 of that duration (measured: between 0.916 and 0.962; 0.940 to 0.962 with dt = T_C / 40;
    the coarse mesh, whose pole elements are 0.02 wide, carries the last small contacts stiffer); no rebound
    faster than the one before (1 %) nor than V0, and each bounce's restitution at least 0.98 (Hertz's impact at
    t_c of about five of the ball's periods is nearly elastic, Johnson 11.4); the bodies' energy never above its
    start by 1 % of the energy in the system; no energy_growth; the balance within 1 %. Measured restitutions
    v_k / v_(k-1): 0.9995, 0.9995, 0.9991, 0.9988, 0.9992 (v_5 = 0.9962 V0); the bodies' energy at most
    -0.09 % of its start in flight (it falls by up to 1.4 % in contact and comes back), balance within 3.2e-4."""
    mesh = hertz_mesh(8, 4)
    dyn = Dynamics(dt=DT_BALL, t_end=12.4 * T_C)  # the defaults: generalized-alpha, rho_inf = 1, mass = "auto"
    prob = Problem(
        name="bounce",
        bodies=[Body("ball", mesh, SaintVenantKirchhoff(E=E, nu=NU, density=1.0))],
        dirichlet=[Dirichlet("ball", "symx", (0,), (0.0,)), Dirichlet("ball", "symy", (1,), (0.0,))],
        rigid=[RigidBody("floor", shape="plane", params={"point": (0.0, 0.0, 0.0), "normal": (0.0, 0.0, 1.0)})],
        contacts=[ContactPair("floor", ("ball", "curved"), ("floor", ""), penalty=1e4, weighting="area")],
        steps=dyn.steps(), output=OutputOptions(vtu=True, checkpoint_every=100000), dynamics=dyn,
        gravity=(0.0, 0.0, -G_BALL), initial_velocity=[InitialVelocity("ball", "", (0.0, 0.0, -V0))],
    )
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    summary = res.summary
    assert summary["mass"] == {"stage1": "consistent-redistributed"}
    assert "energy_growth" not in summary, summary["energy_growth"]
    steps = summary["steps"]
    t = np.array([s["time"] for s in steps])

    episodes = _episodes(steps)
    assert len(episodes) == 5 and episodes[0][0] == 0 and episodes[-1][1] < len(steps) - 1, episodes

    w = np.asarray(res.model.system.mass(lumped=False).sum(axis=1)).ravel()[2::3]  # the nodes' consistent masses
    m = float(w.sum())  # the quarter's
    t_ref, f_ref = _hertz_with_weight(4.0 * m, G_BALL, V0)
    assert all(t[b] - t[a] + DT_BALL > 0.8 * t_ref for a, b in episodes)
    a, b = episodes[0]
    force = 4.0 * np.array([s["contact_force"][2] for s in steps])
    assert force[a:b + 1].max() == pytest.approx(f_ref, rel=0.02)
    assert 0.90 * t_ref < t[b + 1] and t[b] < 1.03 * t_ref, (t[b] / t_ref, t[b + 1] / t_ref)

    zc = np.array([w @ meshio.read(tmp_path / f"step_{s['step']:04d}.vtu").point_data["displacement"]
                   [:mesh.n_nodes, 2] for s in steps]) / m
    speeds = [V0]
    for k, (_, last) in enumerate(episodes):
        stop = episodes[k + 1][0] if k + 1 < len(episodes) else len(steps)
        j = last + 1 + int(np.argmax(zc[last + 1:stop]))
        assert last + 1 < j < stop - 1  # the apex inside the flight
        speeds.append(math.sqrt(2.0 * G_BALL * zc[j]))
    speeds = np.array(speeds)
    restitution = speeds[1:] / speeds[:-1]
    assert np.all(restitution <= 1.01), restitution
    assert np.all(speeds[1:] <= 1.01 * V0), speeds / V0
    assert np.all(restitution >= 0.98), restitution

    body, system = _bodies_energy(steps)
    e0 = 0.5 * m * V0**2
    assert np.all(body <= e0 + 0.01 * system), float(np.max((body - e0) / system))
    assert max(abs(s["energy"]["balance_error"]) for s in steps) < 0.01
