"""Springs and dashpots ([[spring]], [[dashpot]]; a deck's SPRINGA, SPRING1, SPRING2, DASHPOTA with *SPRING and
*DASHPOT; docs/theory.md, "Springs and dashpots"): closed forms of bars on springs, the tangents against central
differences at a rotated configuration, a mass on a spring oscillating at sqrt(k / m) and decaying at c / (2 m), decks
against CalculiX 2.20, and the input errors."""

from __future__ import annotations

import contextlib
import io
import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem, problem_from_dict
from covcontact.io.validate import InputError
from covcontact.motion import rotation_matrix
from covcontact.observer import Observer
from covcontact.solvers.run import solve_problem


def _stretch(stress: float, E: float) -> float:
    """St. Venant-Kirchhoff (nu = 0) uniaxial stretch l under the nominal stress: E/2 (l^3 - l) = stress."""
    roots = np.roots([E / 2.0, 0.0, -E / 2.0, -stress])
    return float(roots[np.isreal(roots) & (roots.real > 0.5)].real[0])


# ------------------------------------------------------------------------------------------------ statics

BAR = """
[problem]
name = "bar-on-springs"
[[bodies]]
name = "bar"
element = "hex8"
material = { model = "svk", E = 10000.0, nu = 0.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 4.0, nx = 1, ny = 1, nz = 4 }
[[dirichlet]]
set = "bar.zmin"
components = "xy"
[[spring]]
type = "dof"
nodes = ["bar.zmin"]
dofs = ["z"]
stiffness = 25.0
[[force]]
set = "bar.zmax"
value = [0.0, 0.0, 20.0]
distribution = "total"
"""


def test_bar_on_a_spring_to_ground(tmp_path):
    """A bar (L = 4, A = 1, E = 1e4, nu = 0) on four ground springs of 25 (SPRING1: dof z) under its base, pulled by
    F = 20: the base moves F / k = 0.2 and the top F / k + L (l - 1) with the St. Venant-Kirchhoff stretch
    E/2 (l^3 - l) = F / A (1e-10), which is F (1/k + L / (E A)) to the stretch's second order (1.2e-4 here)."""
    path = tmp_path / "bar.toml"
    path.write_text(BAR)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    u = res.u.reshape(-1, 3)
    mesh = load_problem(path).bodies[0].mesh
    base, top = mesh.node_sets["zmin"], mesh.node_sets["zmax"]
    F, k, L, E = 20.0, 100.0, 4.0, 1.0e4
    assert np.allclose(u[base, 2], F / k, rtol=0, atol=1e-10)
    exact = F / k + L * (_stretch(F, E) - 1.0)
    assert np.allclose(u[top, 2], exact, rtol=0, atol=1e-10)
    assert u[top, 2].mean() == pytest.approx(F * (1.0 / k + L / E), rel=2e-4)


BLOCKS = """
[problem]
name = "two-blocks"
[[bodies]]
name = "low"
element = "hex8"
material = { model = "svk", E = 500.0, nu = 0.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }
[bodies.sets]
c1 = { closest = [0.0, 0.0, 1.0] }
c2 = { closest = [1.0, 0.0, 1.0] }
c3 = { closest = [1.0, 1.0, 1.0] }
c4 = { closest = [0.0, 1.0, 1.0] }
[[bodies]]
name = "high"
element = "hex8"
material = { model = "svk", E = 500.0, nu = 0.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1, origin = [0.0, 0.0, 2.5] }
[bodies.sets]
c1 = { closest = [0.0, 0.0, 2.5] }
c2 = { closest = [1.0, 0.0, 2.5] }
c3 = { closest = [1.0, 1.0, 2.5] }
c4 = { closest = [0.0, 1.0, 2.5] }
[[dirichlet]]
set = "low.zmin"
[[dirichlet]]
set = "high.zmax"
components = "xy"
[[force]]
set = "high.zmax"
value = [0.0, 0.0, 60.0]
distribution = "total"
[steps]
count = 2
"""


def test_two_blocks_joined_by_axial_springs_pulled_apart(tmp_path):
    """Two unit blocks 1.5 apart joined corner to corner by four axial springs (SPRINGA) of 40, the upper one pulled
    by F = 60: each spring carries F / 4 along its line, so the gap opens by F / (4 k) and the top moves that plus
    both blocks' St. Venant-Kirchhoff stretch (1e-10); the support carries F (1e-8, Newton's tolerance)."""
    springs = "".join(f'[[spring]]\nnodes = ["low.c{i}", "high.c{i}"]\nstiffness = 40.0\n' for i in range(1, 5))
    path = tmp_path / "blocks.toml"
    path.write_text(BLOCKS + springs)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    prob = load_problem(path)
    u = res.u.reshape(-1, 3)
    n_low = prob.bodies[0].mesh.n_nodes
    top = prob.bodies[1].mesh.node_sets["zmax"] + n_low
    low_top = prob.bodies[0].mesh.node_sets["zmax"]
    F, k, E = 60.0, 40.0, 500.0
    l = _stretch(F, E)
    assert np.allclose(u[low_top, 2], l - 1.0, atol=1e-10)
    assert np.allclose(u[top, 2], 2.0 * (l - 1.0) + F / (4 * k), atol=1e-10)
    assert np.abs(u[:, :2]).max() < 1e-10
    assert res.summary["steps"][-1]["reactions"]["low.zmin"][2] == pytest.approx(-F, rel=1e-8)


# ------------------------------------------------------------------------------------------------ tangents

def _two_blocks(extra: dict) -> dict:
    block = {"element": "hex8", "material": {"model": "svk", "E": 1.0, "nu": 0.3, "density": 1.0}}
    raw = {"problem": {"name": "tangent"},
           "bodies": [{"name": "a", **block, "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0,
                                                      "nx": 1, "ny": 1, "nz": 1},
                       "sets": {"c": {"closest": [1.0, 1.0, 1.0]}, "d": {"closest": [0.0, 1.0, 1.0]}}},
                      {"name": "b", **block, "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0,
                                                      "nx": 1, "ny": 1, "nz": 1, "origin": [0.5, 0.2, 2.0]},
                       "sets": {"c": {"closest": [0.5, 0.2, 2.0]}, "d": {"closest": [1.5, 1.2, 2.0]}}}],
           "dirichlet": [{"set": "a.zmin", "components": "z"}]}
    raw.update(extra)
    return raw


SPRINGS = {"spring": [
    {"nodes": ["a.c", "b.c"], "stiffness": 7.0},
    {"nodes": ["a.d", "b.d"], "table": [[-5.0, -3.0], [0.0, 0.5], [5.0, 20.0]]},
    {"nodes": ["b.zmax"], "anchor": [0.3, 0.4, 5.0], "stiffness": 3.0},
    {"type": "dof", "nodes": ["a.c", "b.d"], "dofs": ["x", "y"], "stiffness": 5.0},
    {"type": "dof", "nodes": ["b.zmax"], "dofs": ["z"], "table": [[-5.0, -1.0], [5.0, 9.0]]}]}


def _rotated(model, seed: int, scale: float = 0.1) -> np.ndarray:
    """A displacement that turns everything by about 1.2 rad and perturbs it."""
    X = model.system.X
    R = rotation_matrix(np.array([0.4, -0.9, 0.6]))
    return ((X @ R.T - X) + scale * np.random.default_rng(seed).standard_normal(X.shape)).ravel()


def _dense(blocks, n: int) -> tuple[np.ndarray, np.ndarray]:
    from covcontact.elements.springs import add_blocks

    r = np.zeros(n)
    add_blocks(blocks, r)
    K = np.zeros((n, n))
    for conn, _, Ke in blocks:
        if Ke is None:
            continue
        d = (3 * conn[:, :, None] + np.arange(3)).reshape(len(conn), -1)
        for de, ke in zip(d, Ke):
            K[np.ix_(de, de)] += ke
    return r, K


def test_spring_tangent_against_central_differences(tmp_path):
    """Axial springs (two-node, to an anchor, a table) and dof springs at a configuration turned by 1.2 rad and
    perturbed (stretched and compressed springs, so the geometric stiffness f / L (I - n n^T) counts): their own
    tangent, and the model's (bodies + springs), against central differences of the residuals, within 1e-6 of the
    largest entry; leaving out the geometric part fails the same check."""
    from covcontact.elements.springs import SpringSet
    from covcontact.solvers.model import Model

    model = Model(problem_from_dict(_two_blocks(SPRINGS), tmp_path / "t.toml"))
    assert model.symmetric
    springs, n = model.springs, model.n_dofs
    u = _rotated(model, 1)
    x = model.positions(u)
    _, K = _dense(springs.spring_blocks(x, u.reshape(-1, 3), True), n)
    axial = [g for g in springs.springs if g.kind == "axial"]
    assert len(axial) == 2  # (the linear ones merged, the table alone)
    e = np.concatenate([SpringSet._line(g, x)[1] - g.L0 for g in axial])
    assert np.abs(e).min() > 0.05  # (stretched or compressed: the geometric part is not zero)

    def residual(uu):
        return _dense(springs.spring_blocks(model.positions(uu), uu.reshape(-1, 3), False), n)[0]

    h = 1e-6
    D = np.column_stack([(residual(u + h * ej) - residual(u - h * ej)) / (2 * h) for ej in np.eye(n)])
    assert np.abs(D - K).max() <= 1e-6 * np.abs(K).max()
    # the geometric stiffness matters here: without it the check fails
    K2 = K.copy()
    for g in axial:
        _, L, nn = SpringSet._line(g, x)
        f = g.law(L - g.L0)[0]
        geo = (f / L)[:, None, None] * (np.eye(3) - nn[:, :, None] * nn[:, None, :])
        for a, b, G in zip(g.a, g.b, geo):
            for p, q, sign in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
                if p >= 0 and q >= 0:
                    K2[3 * p: 3 * p + 3, 3 * q: 3 * q + 3] -= sign * G
    assert np.abs(D - K2).max() > 1e-3 * np.abs(K).max()
    # the model's tangent: bodies and springs in one pattern
    state = model.initial_state()
    R0, KM, _ = model.evaluate(u, 1.0, state)
    KM = KM.toarray()
    DM = np.column_stack([(model.evaluate(u + h * ej, 1.0, state, want_K=False)[0]
                           - model.evaluate(u - h * ej, 1.0, state, want_K=False)[0]) / (2 * h) for ej in np.eye(n)])
    assert np.abs(DM - KM).max() <= 1e-6 * np.abs(KM).max()
    assert isinstance(springs, SpringSet)


def test_dashpot_tangent_against_central_differences(tmp_path):
    """The dynamic residual's tangent with axial dashpots (two-node and to an anchor: the turning line's terms, not
    symmetric) and a dof dashpot, v = v(u) by the HHT integrator (dv/du = gamma / (beta dt)), at a turned configuration
    with random velocities: the dashpots' own tangent and the whole dynamic tangent against central differences,
    within 1e-6 of the largest entry."""
    from covcontact.solvers.dynamics import DynamicModel, Integrator
    from covcontact.solvers.model import Model

    extra = {"problem": {"name": "dash", "procedure": "dynamic", "dt": 0.1, "t_end": 1.0},
             "spring": [{"nodes": ["a.c", "b.c"], "stiffness": 7.0}],
             "dashpot": [{"nodes": ["a.c", "b.c"], "coefficient": 3.0},
                         {"nodes": ["b.zmax"], "anchor": [0.3, 0.4, 5.0], "coefficient": 2.0},
                         {"type": "dof", "nodes": ["a.c", "b.d"], "dofs": ["x", "z"], "coefficient": 4.0}]}
    model = Model(problem_from_dict(_two_blocks(extra), tmp_path / "d.toml"))
    assert model.symmetric is False
    n = model.n_dofs
    rng = np.random.default_rng(2)
    u0 = _rotated(model, 2, 0.05)
    integ = Integrator.of("hht", 0.8)
    dt = 0.1
    s = integ.gamma / (integ.beta * dt)
    v0 = rng.standard_normal(n)

    def forces(uu):
        from covcontact.elements.springs import add_blocks

        r = np.zeros(n)
        add_blocks(model.springs.dashpot_blocks(model.positions(uu), (v0 + s * (uu - u0)).reshape(-1, 3), s,
                                                False), r)
        return r

    u = u0 + 0.02 * rng.standard_normal(n)
    _, Kd = _dense(model.springs.dashpot_blocks(model.positions(u), (v0 + s * (u - u0)).reshape(-1, 3), s, True), n)
    h = 1e-6
    D = np.column_stack([(forces(u + h * ej) - forces(u - h * ej)) / (2 * h) for ej in np.eye(n)])
    assert np.abs(D - Kd).max() <= 1e-6 * np.abs(Kd).max()
    assert np.abs(Kd - Kd.T).max() > 1e-3 * np.abs(Kd).max()  # (not symmetric)
    dyn = {"u": u0, "v": v0, "a": rng.standard_normal(n), "r": np.zeros(n), "f": np.zeros(n),
           "work": np.array(0.0), "time": np.array(0.0), "rc": np.zeros(n), "wc": np.array(0.0)}
    state = model.initial_state().but(dynamics=dyn, lam=0.0)
    dm = DynamicModel(model, model.system.mass(), integ, 1.0)
    lam = dt
    _, K, _ = dm.evaluate(u, lam, state)
    K = K.toarray()
    D = np.column_stack([(dm.evaluate(u + h * ej, lam, state, want_K=False)[0]
                          - dm.evaluate(u - h * ej, lam, state, want_K=False)[0]) / (2 * h) for ej in np.eye(n)])
    assert np.abs(D - K).max() <= 1e-6 * np.abs(K).max()


# ------------------------------------------------------------------------------------------------ dynamics

def _oscillator(dt: float, t_end: float, c: float | None) -> dict:
    """A unit block (mass 1, stiff) held in x and y, on four axial springs of pi^2 to anchors 1 below its base
    corners (omega = 2 pi, T = 1), started at 1e-3 upward; with ``c``: four axial dashpots of c beside them."""
    corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    sets = {f"c{i}": {"closest": [x, y, 1.0]} for i, (x, y) in enumerate(corners)}
    raw = {"problem": {"name": "oscillator", "procedure": "dynamic", "dt": dt, "t_end": t_end, "method": "newmark"},
           "bodies": [{"name": "m", "element": "hex8",
                       "material": {"model": "svk", "E": 1.0e6, "nu": 0.0, "density": 1.0},
                       "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 1, "ny": 1, "nz": 1,
                                "origin": [0.0, 0.0, 1.0]}, "sets": sets}],
           "dirichlet": [{"set": "m.all", "components": "xy"}],
           "spring": [{"nodes": [f"m.c{i}"], "anchor": [x, y, 0.0], "stiffness": math.pi ** 2}
                      for i, (x, y) in enumerate(corners)],
           "initial_velocity": [{"body": "m", "value": [0.0, 0.0, 1e-3]}],
           "output": {"vtu": False, "checkpoint_every": 10000}}
    if c is not None:
        raw["dashpot"] = [{"nodes": [f"m.c{i}"], "anchor": [x, y, 0.0], "coefficient": c}
                          for i, (x, y) in enumerate(corners)]
    return raw


class _Height(Observer):
    def __init__(self):
        self.t, self.w = [0.0], [0.0]

    def increment_converged(self, run, inc):
        d = inc.state.dynamics
        self.t.append(float(d["time"]))
        self.w.append(float(d["u"].reshape(-1, 3)[:, 2].mean()))


def _history(tmp_path, raw):
    obs = _Height()
    res = solve_problem(problem_from_dict(raw, tmp_path / "osc.toml"), out=tmp_path / "o", observers=[obs])
    assert res.exit_code == 0
    return np.array(obs.t), np.array(obs.w), res


def _extrema(t, w):
    """Times and values of the interior extrema of w (parabolas through three samples)."""
    out = []
    for k in range(1, len(w) - 1):
        if (w[k] - w[k - 1]) * (w[k + 1] - w[k]) < 0:
            h = t[k + 1] - t[k]
            a = 0.5 * (w[k + 1] - 2 * w[k] + w[k - 1]) / h ** 2
            b = 0.5 * (w[k + 1] - w[k - 1]) / h
            out.append((t[k] - b / (2 * a), w[k] - b * b / (4 * a)))
    return np.array(out)


def test_mass_on_springs_oscillates_at_sqrt_k_over_m(tmp_path):
    """Mass 1 on springs of 4 pi^2 in all, trapezoidal rule with dt = T / 100: the zero crossings lie T / 2 apart with
    T = 2 pi sqrt(m / k) = 1 within 1e-3 (the rule's own period error is (omega dt)^2 / 12 = 3.3e-4), the amplitude
    v0 / omega is kept (1e-3) and the energy balances (1e-9)."""
    t, w, res = _history(tmp_path, _oscillator(0.01, 1.06, None))
    s = np.sign(w[1:])
    k = np.flatnonzero(s[:-1] != s[1:]) + 1
    tz = t[k] - w[k] * (t[k + 1] - t[k]) / (w[k + 1] - w[k])
    assert len(tz) == 2
    assert tz[1] - tz[0] == pytest.approx(0.5, rel=1e-3)
    assert tz[0] == pytest.approx(0.5, rel=1e-3)
    ext = _extrema(t, w)
    assert np.abs(ext[:, 1]).max() == pytest.approx(1e-3 / (2 * math.pi), rel=1e-3)
    assert abs(res.summary["steps"][-1]["energy"]["balance_error"]) < 1e-9


def test_dashpots_damp_at_c_over_2m(tmp_path):
    """The same with four dashpots of c = 0.05 pi (zeta = 0.05): successive extrema decay as exp(-sigma t) with
    sigma = c_total / (2 m) = 0.1 pi (within 1e-2), they lie half a damped period pi / omega_d apart
    (omega_d = sqrt(omega^2 - sigma^2), 1e-3), and the dashpots' dissipation closes the energy balance (1e-9)."""
    t, w, res = _history(tmp_path, _oscillator(0.01, 1.36, 0.05 * math.pi))
    ext = _extrema(t, w)
    assert len(ext) == 3
    sigma = -np.polyfit(ext[:, 0], np.log(np.abs(ext[:, 1])), 1)[0]
    assert sigma == pytest.approx(0.1 * math.pi, rel=1e-2)
    omega_d = math.sqrt(4 * math.pi ** 2 - (0.1 * math.pi) ** 2)
    assert np.diff(ext[:, 0]).mean() == pytest.approx(math.pi / omega_d, rel=1e-3)
    energy = res.summary["steps"][-1]["energy"]
    assert energy["damping"] > 0.5 * 0.5e-6 * 0.9 and abs(energy["balance_error"]) < 1e-9


def test_damped_run_resumes_exactly(tmp_path, monkeypatch):
    """The state rule: a damped run stopped by a signal at its 9th time step and resumed ends where the uninterrupted
    one ends (displacements, the dashpots' dissipation, the iterations), the springs and dashpots holding no history
    beyond the dynamic state's velocities and dissipation."""
    import json

    from covcontact.solvers import run as run_module
    from covcontact.solvers.signals import Interrupted

    raw = _oscillator(0.02, 0.4, 0.05 * math.pi)
    raw["output"] = {"vtu": False}  # (a checkpoint after every step)
    problem = problem_from_dict(raw, tmp_path / "osc.toml")
    ref = problem.run(out=tmp_path / "ref")
    advance = run_module.Newton.advance
    calls = {"n": 0}

    def stopping(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 9:
            raise Interrupted(15)
        return advance(self, *args, **kwargs)

    monkeypatch.setattr(run_module.Newton, "advance", stopping)
    assert problem.run(out=tmp_path / "cut").exit_code == 143
    monkeypatch.setattr(run_module.Newton, "advance", advance)
    resumed = problem.run(out=tmp_path / "cut", resume=True)
    assert resumed.exit_code == 0
    np.testing.assert_allclose(resumed.u, ref.u, rtol=1e-10, atol=1e-14)
    a = json.loads((tmp_path / "ref" / "summary.json").read_text())["steps"]
    b = json.loads((tmp_path / "cut" / "summary.json").read_text())["steps"]
    assert [s["iterations"] for s in a] == [s["iterations"] for s in b]
    assert b[-1]["energy"]["damping"] == pytest.approx(a[-1]["energy"]["damping"], rel=1e-10)


# ------------------------------------------------------------------------------------------------ decks

def _static_deck(path: Path) -> None:
    """A column (two C3D8, E = 2000, nu = 0) on SPRING1 ground springs (dof 3) under its base, a C3D8 block hung 1
    above it by crossing SPRINGA springs, a NONLINEAR SPRINGA pair and a SPRING2 pair (3, 3), and SPRINGA springs from
    the block's top to held nodes of no element above it; y held everywhere, the block's top pulled up and sideways
    (16 and 16 in all): large displacements and turning springs."""
    nodes = {}

    def node(x, y, z):
        nodes[len(nodes) + 1] = (x, y, z)
        return len(nodes)

    A = {(i, j, k): node(float(i), float(j), float(k)) for k in range(3) for j in range(2) for i in range(2)}
    B = {(i, j, k): node(float(i), float(j), 3.0 + k) for k in range(2) for j in range(2) for i in range(2)}
    g1, g2 = node(0.0, 0.0, 6.0), node(0.0, 1.0, 6.0)

    def hexa(M, k):
        return [M[(0, 0, k)], M[(1, 0, k)], M[(1, 1, k)], M[(0, 1, k)],
                M[(0, 0, k + 1)], M[(1, 0, k + 1)], M[(1, 1, k + 1)], M[(0, 1, k + 1)]]

    def row(*v):
        return ", ".join(map(str, v))

    base = [A[(i, j, 0)] for j in (0, 1) for i in (0, 1)]
    top = [B[(i, j, 1)] for j in (0, 1) for i in (0, 1)]
    body = list(A.values()) + list(B.values())
    lines = ["*HEADING", "springs of each type", "*NODE, NSET=NALL"]
    lines += [f"{n}, {x:.1f}, {y:.1f}, {z:.1f}" for n, (x, y, z) in nodes.items()]
    lines += ["*ELEMENT, TYPE=C3D8, ELSET=COL", row(1, *hexa(A, 0)), row(2, *hexa(A, 1))]
    lines += ["*ELEMENT, TYPE=C3D8, ELSET=BLK", row(3, *hexa(B, 0))]
    lines += ["*ELEMENT, TYPE=SPRING1, ELSET=EGROUND"] + [row(10 + q, n) for q, n in enumerate(base)]
    lines += ["*ELEMENT, TYPE=SPRINGA, ELSET=ECROSS", row(20, A[(0, 0, 2)], B[(1, 0, 0)]),
              row(21, A[(1, 0, 2)], B[(0, 0, 0)]), row(22, A[(0, 1, 2)], B[(1, 1, 0)]),
              row(23, A[(1, 1, 2)], B[(0, 1, 0)])]
    lines += ["*ELEMENT, TYPE=SPRINGA, ELSET=ENONLIN", row(30, A[(0, 0, 2)], B[(0, 0, 0)]),
              row(31, A[(0, 1, 2)], B[(0, 1, 0)])]
    lines += ["*ELEMENT, TYPE=SPRING2, ELSET=ETWO", row(40, A[(1, 0, 2)], B[(1, 0, 0)]),
              row(41, A[(1, 1, 2)], B[(1, 1, 0)])]
    lines += ["*ELEMENT, TYPE=SPRINGA, ELSET=EANCHOR", row(50, B[(0, 0, 1)], g1), row(51, B[(0, 1, 1)], g2)]
    lines += ["*NSET, NSET=BASE", row(*base), "*NSET, NSET=GROUND", row(g1, g2),
              "*NSET, NSET=BODYN", row(*body[:10]), row(*body[10:])]
    lines += ["*BOUNDARY", "BASE, 1, 2", "NALL, 2, 2", "GROUND, 1, 3",
              "*MATERIAL, NAME=STEEL", "*ELASTIC", "2000.0, 0.0",
              "*SOLID SECTION, ELSET=COL, MATERIAL=STEEL", "*SOLID SECTION, ELSET=BLK, MATERIAL=STEEL",
              "*SPRING, ELSET=EGROUND", "3", "100.0", "*SPRING, ELSET=ECROSS", "", "40.0",
              "*SPRING, ELSET=ENONLIN, NONLINEAR", "0.0, 0.0", "5.0, 0.1", "8.0, 0.5", "9.0, 2.0",
              "*SPRING, ELSET=ETWO", "3, 3", "25.0", "*SPRING, ELSET=EANCHOR", "", "15.0",
              "*STEP, NLGEOM", "*STATIC", "0.25, 1.0", "*CLOAD"]
    lines += [row(n, 3, "10.0") for n in top] + [row(n, 1, "4.0") for n in top]
    lines += ["*NODE PRINT, NSET=BODYN", "U", "*NODE PRINT, NSET=BASE", "RF", "*END STEP"]
    path.write_text("\n".join(lines) + "\n")


#: CalculiX 2.20 (ccx -i on _static_deck's deck): U of the column's and the block's nodes and RF of the base at time
#: 1 (nodes 1..20; the mesh is symmetric in y, so nodes 2k-1 and 2k+1 of a level agree: listed once per x)
CCX_STATIC_U = {1: (0.0, 1.822322e-01), 2: (0.0, 2.002690e-02), 5: (2.092363e-01, 2.088967e-01),
                6: (1.862454e-01, -4.945070e-03), 9: (4.581146e-01, 2.138667e-01), 10: (4.140382e-01, -2.499434e-02),
                13: (9.029520e-01, 4.527480e-01), 14: (8.299347e-01, 1.115123e-01),
                17: (1.249737e+00, 4.140549e-01), 18: (1.191557e+00, 6.539720e-02)}
CCX_STATIC_RF = {1: -1.049361e+01, 2: 2.671627e+00}
#: the y-mirror of each node listed (same x and z: nodes 3, 4 of a level mirror 1, 2)
_MIRROR = {1: 3, 2: 4, 5: 7, 6: 8, 9: 11, 10: 12, 13: 15, 14: 16, 17: 19, 18: 20}


def _dat_blocks(path: Path) -> dict:
    out, cur = {}, None
    for ln in path.read_text().splitlines():
        m = re.match(r"\s*(displacements|forces) \(.*\) for set (\S+) and time\s+(\S+)", ln)
        if m:
            cur = (m.group(1), m.group(2), round(float(m.group(3)), 9))
            out[cur] = {}
            continue
        f = ln.split()
        if cur is not None and len(f) == 4 and f[0].isdigit():
            out[cur][int(f[0])] = np.array([float(v) for v in f[1:]])
    return out


def _run_deck(deck: Path, out: Path, *extra) -> tuple[int, str]:
    from covcontact.cli import main

    buf = io.StringIO()
    with contextlib.redirect_stderr(buf):
        code = main(["run", str(deck), "--out", str(out), "--quiet", *extra])
    return code, buf.getvalue()


def _ccx(tmp_path: Path, deck: Path) -> dict | None:
    """The .dat blocks of a fresh CalculiX run of ``deck`` (None when ccx is not installed)."""
    if not shutil.which("ccx"):
        return None
    d = tmp_path / "ccx"
    d.mkdir(exist_ok=True)
    (d / deck.name).write_text(deck.read_text())
    subprocess.run(["ccx", "-i", deck.stem], cwd=d, capture_output=True, timeout=120, check=True)
    return _dat_blocks(d / f"{deck.stem}.dat")


def test_deck_springs_of_each_type_against_calculix(tmp_path):
    """_static_deck's deck (SPRING1, SPRINGA two-node, NONLINEAR and to held nodes of no element, SPRING2) run as a
    deck: U of every body node and RF of the base at time 1 equal CalculiX 2.20's (stored above, and a fresh ccx run when
    installed) to its printed digits (1e-6 absolute); the spring elements make no bodies (COL and BLK only)."""
    deck = tmp_path / "springs.inp"
    _static_deck(deck)
    code, err = _run_deck(deck, tmp_path / "o")
    assert code == 0, err
    toml = (tmp_path / "o" / "deck" / "springs.toml").read_text()
    assert toml.count("[[bodies]]") == 2 and toml.count("[[spring]]") == 1 + 4 + 2 + 2 + 2  # (SPRING1: one set)
    ours = _dat_blocks(tmp_path / "o" / "springs.dat")
    U, RF = ours[("displacements", "BODYN", 1.0)], ours[("forces", "BASE", 1.0)]
    for n, (ux, uz) in CCX_STATIC_U.items():
        for m in (n, _MIRROR[n]):
            assert np.abs(U[m] - [ux, 0.0, uz]).max() < 1e-6, (m, U[m], ux, uz)
    for n, fx in CCX_STATIC_RF.items():
        assert abs(RF[n][0] - fx) < 1e-5 and abs(RF[n][2]) < 1e-6
    fresh = _ccx(tmp_path, deck)
    if fresh is not None:
        for key in (("displacements", "BODYN", 1.0), ("forces", "BASE", 1.0)):
            for m, row in fresh[key].items():
                assert np.abs(ours[key][m] - row).max() < 1e-5 * max(1.0, np.abs(row).max()), (key, m)


DASH_DECK = """*HEADING
a block of mass 1 on four axial springs and dashpots to held nodes below it: omega = 2 pi, zeta = 0.05
*NODE, NSET=NALL
1, 0.0, 0.0, 1.0
2, 1.0, 0.0, 1.0
3, 1.0, 1.0, 1.0
4, 0.0, 1.0, 1.0
5, 0.0, 0.0, 2.0
6, 1.0, 0.0, 2.0
7, 1.0, 1.0, 2.0
8, 0.0, 1.0, 2.0
11, 0.0, 0.0, 0.0
12, 1.0, 0.0, 0.0
13, 1.0, 1.0, 0.0
14, 0.0, 1.0, 0.0
*ELEMENT, TYPE=C3D8, ELSET=MASS
1, 1, 2, 3, 4, 5, 6, 7, 8
*ELEMENT, TYPE=SPRINGA, ELSET=ESPRING
21, 11, 1
22, 12, 2
23, 13, 3
24, 14, 4
*ELEMENT, TYPE=DASHPOTA, ELSET=EDASH
31, 11, 1
32, 12, 2
33, 13, 3
34, 14, 4
*NSET, NSET=BLOCK
1, 2, 3, 4, 5, 6, 7, 8
*NSET, NSET=GROUND
11, 12, 13, 14
*NSET, NSET=TOP
5, 6, 7, 8
*BOUNDARY
GROUND, 1, 3
BLOCK, 1, 2
*MATERIAL, NAME=EL
*ELASTIC
1.0e5, 0.0
*DENSITY
1.0
*SOLID SECTION, ELSET=MASS, MATERIAL=EL
*SPRING, ELSET=ESPRING

9.869604401089358
*DASHPOT, ELSET=EDASH

0.15707963267948966
*STEP, NLGEOM, INC=1000
*DYNAMIC, DIRECT
0.02, 1.0
*CLOAD
TOP, 3, 0.25
*NODE PRINT, NSET=TOP, FREQUENCY=5
U
*END STEP
"""

#: CalculiX 2.20 (ccx -i on DASH_DECK): u_z of the block's top (node 5) every 5th increment (t = 0.1, 0.2, ..., 1.0)
CCX_DASH = [4.727087e-03, 1.677532e-02, 3.125406e-02, 4.267281e-02, 4.700034e-02, 4.306917e-02, 3.283163e-02,
            2.044909e-02, 1.062293e-02, 6.825722e-03]


def test_deck_dashpots_against_calculix(tmp_path):
    """DASH_DECK (SPRINGA and DASHPOTA to held nodes of no element, *DYNAMIC, DIRECT with CalculiX's HHT alpha
    -0.05, a step load): the top's u_z at the ten printed times equal CalculiX 2.20's within 1e-4 of the largest
    (stored above, and a fresh ccx run when installed); the dashpots dissipate (summary.json energy.damping)."""
    deck = tmp_path / "dash.inp"
    deck.write_text(DASH_DECK)
    code, err = _run_deck(deck, tmp_path / "o")
    assert code == 0, err
    ours = _dat_blocks(tmp_path / "o" / "dash.dat")
    uz = [ours[("displacements", "TOP", round(0.1 * k, 9))][5][2] for k in range(1, 11)]
    assert np.abs(np.array(uz) - CCX_DASH).max() < 1e-4 * max(CCX_DASH)
    fresh = _ccx(tmp_path, deck)
    if fresh is not None:
        ref = [fresh[("displacements", "TOP", round(0.1 * k, 9))][5][2] for k in range(1, 11)]
        assert np.abs(np.array(uz) - ref).max() < 1e-4 * max(ref)
    import json

    energy = json.loads((tmp_path / "o" / "summary.json").read_text())["steps"][-1]["energy"]
    assert energy["damping"] > 0.0


CURVE_DECK = """*NODE, NSET=NALL
1, 0.0, 0.0, 0.0
2, 1.0, 0.0, 0.0
3, 1.0, 1.0, 0.0
4, 0.0, 1.0, 0.0
5, 0.0, 0.0, 1.0
6, 1.0, 0.0, 1.0
7, 1.0, 1.0, 1.0
8, 0.0, 1.0, 1.0
100, 5.0, 5.0, 5.0
101, 6.0, 5.0, 5.0
*ELEMENT, TYPE=C3D8, ELSET=B
1, 1, 2, 3, 4, 5, 6, 7, 8
*ELEMENT, TYPE=SPRING2, ELSET=E2
10, 100, 1
11, 101, 2
12, 100, 3
13, 101, 4
*ELEMENT, TYPE=SPRING1, ELSET=E1
20, 5
21, 6
22, 7
23, 8
*NSET, NSET=BOT
1, 2, 3, 4
*NSET, NSET=TOP
5, 6, 7, 8
*NSET, NSET=BODY
1, 2, 3, 4, 5, 6, 7, 8
*BOUNDARY
BODY, 1, 2
100, 1, 3
101, 1, 3
*MATERIAL, NAME=M
*ELASTIC
100.0, 0.0
*SOLID SECTION, ELSET=B, MATERIAL=M
*SPRING, ELSET=E2, NONLINEAR
3, 3
-4.0, -1.0
0.0, 0.0
2.0, 0.1
3.0, 1.0
*SPRING, ELSET=E1
3
7.0
*STEP, NLGEOM
*STATIC
0.5, 1.0
*CONTROLS, PARAMETERS=FIELD, FIELD=DISPLACEMENT
1e-9, 1e-9
*CLOAD
BOT, 3, -2.5
TOP, 3, -1.0
*NODE PRINT, NSET=BODY
U, RF
*END STEP
"""

#: CalculiX 2.20 (ccx -i on CURVE_DECK, its residual tolerance set to 1e-9 by *CONTROLS): u_z of the bottom and the top
CCX_CURVE = (-2.113380e-01, -1.966131e-01)


def test_deck_spring2_from_a_held_node_with_a_curve(tmp_path):
    """SPRING2 (3, 3) elements whose first node is a held node of no element and whose NONLINEAR curve is passed
    (force -f(-e) on the second node: the curve turned about the origin), and SPRING1 elements of one *SPRING written
    as one [[spring]] over a node set: u_z of the bottom and the top equal CalculiX 2.20's (1e-6), and the closed form
    of the St. Venant-Kirchhoff block between its springs (1e-9)."""
    deck = tmp_path / "curve.inp"
    deck.write_text(CURVE_DECK)
    code, err = _run_deck(deck, tmp_path / "o")
    assert code == 0, err
    toml = (tmp_path / "o" / "deck" / "curve.toml").read_text()
    assert toml.count("[[spring]]") == 4 + 1
    U = _dat_blocks(tmp_path / "o" / "curve.dat")[("displacements", "BODY", 1.0)]
    ub, ut = U[1][2], U[5][2]
    assert all(U[n][2] == pytest.approx(ub, abs=1e-12) for n in (2, 3, 4))
    assert abs(ub - CCX_CURVE[0]) < 1e-6 and abs(ut - CCX_CURVE[1]) < 1e-6
    # the block's nominal stress P = E/2 (l^2 - 1) l, l = 1 + ut - ub; top: P/4 + 7 ut = -1; bottom: the spring's
    # force f(-ub) on the curve (0, 0), (0.1, 2), (1, 3) carries 2.5 - P/4
    import json

    labels = json.loads((tmp_path / "o" / "deck" / "curve.nodes.json").read_text())["bodies"]
    u = np.load(tmp_path / "o" / "checkpoint.npz")["u"].reshape(-1, 3)   # (the converged state, unrounded)
    order = [lab for name in labels for lab in labels[name]]
    ub, ut = u[order.index(1), 2], u[order.index(5), 2]
    lam = 1.0 + ut - ub
    P = 50.0 * (lam * lam - 1.0) * lam
    assert P / 4 + 7.0 * ut == pytest.approx(-1.0, abs=1e-9)
    assert 2.0 + (-ub - 0.1) / 0.9 == pytest.approx(2.5 - P / 4, abs=1e-9)
    fresh = _ccx(tmp_path, deck)
    if fresh is not None:
        ref = fresh[("displacements", "BODY", 1.0)]
        assert abs(ref[1][2] - ub) < 1e-6 and abs(ref[5][2] - ut) < 1e-6


# ------------------------------------------------------------------------------------------------ errors

def test_spring_input_errors(tmp_path):
    """Problem-file mistakes: one line each naming the key."""
    base = BAR.replace('[[spring]]\ntype = "dof"\nnodes = ["bar.zmin"]\ndofs = ["z"]\nstiffness = 25.0\n', "SPRING")
    base = base.replace('mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 4.0, nx = 1, ny = 1, nz = 4 }\n',
                        'mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 4.0, nx = 1, ny = 1, nz = 4 }\n'
                        'sets = { p = { closest = [0.0, 0.0, 4.0] }, q = { closest = [1.0, 0.0, 4.0] } }\n')
    cases = {
        '[[spring]]\nnodes = ["bar.zmin", "bar.p"]\nstiffness = 1.0\n': "holds 4 nodes; the ends of a two-node spring",
        '[[spring]]\nnodes = ["bar.zmin"]\nstiffness = 1.0\n': "missing: an axial member with one node set",
        '[[spring]]\nnodes = ["bar.p", "bar.p"]\nstiffness = 1.0\n': "both ends are the same node",
        '[[spring]]\nnodes = ["bar.p", "bar.q"]\nstiffness = 1.0\ntable = [[0.0, 0.0], [1.0, 1.0]]\n':
            "give exactly one of 'stiffness'",
        '[[spring]]\nnodes = ["bar.p", "bar.q"]\ntable = [[0.0, 0.0], [0.0, 1.0]]\n': "must increase strictly",
        '[[spring]]\nnodes = ["bar.p", "bar.q"]\ntable = [[0.0, 0.0]]\n': "at least two [elongation, force]",
        '[[spring]]\nnodes = ["bar.p", "bar.q"]\nstiffness = -1.0\n': "must be > 0",
        '[[spring]]\nnodes = ["bar.p", "bar.q"]\nstiffness = 1.0\ndofs = ["x"]\n': 'dofs belong to type = "dof"',
        '[[spring]]\ntype = "dof"\nnodes = ["bar.p", "bar.q"]\nstiffness = 1.0\ndofs = ["x"]\n':
            "must be an array of 2 component(s)",
        '[[spring]]\ntype = "dof"\nnodes = ["bar.p"]\nstiffness = 1.0\ndofs = ["x"]\nanchor = [0.0, 0.0, 9.0]\n':
            'an anchor belongs to type = "axial"',
        '[[spring]]\nnodes = ["bar.p"]\nstiffness = 1.0\nanchor = [0.0, 0.0, 4.0]\n': "the anchor lies on a node",
        '[[spring]]\nnodes = ["bar.nope"]\nstiffness = 1.0\n': "has no node set 'nope'",
        '[[spring]]\ntype = "axle"\nnodes = ["bar.p"]\nstiffness = 1.0\n': "is not one of axial, dof",
        '[[dashpot]]\nnodes = ["bar.p", "bar.q"]\ncoefficient = 1.0\n': "dashpots act in dynamic stages only",
    }
    path = tmp_path / "bad.toml"
    for text, words in cases.items():
        path.write_text(base.replace("SPRING", text))
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))


def test_deck_spring_errors_and_unsupported(tmp_path):
    """Deck mistakes (one line naming the line, exit 2) and what covcontact does not read (listed, exit 2): a *SPRING
    over a solid element, a spring element without its constant, a dofs line on a SPRINGA, a spring to a free node of
    no solid element, *MPC MEANROT and DIST, a B32R beam element."""
    good = DASH_DECK
    cases = {
        good.replace("*SPRING, ELSET=ESPRING", "*SPRING, ELSET=MASS"): ("element 1 is no spring or dashpot element",),
        good.replace("*SPRING, ELSET=ESPRING\n\n9.869604401089358\n", ""): ("SPRINGA element 21 has no *SPRING",),
        good.replace("*SPRING, ELSET=ESPRING\n\n", "*SPRING, ELSET=ESPRING\n3\n"): ("a dofs line for the SPRINGA",),
        good.replace("GROUND, 1, 3", "GROUND, 1, 2"): ("its node 11 belongs to no solid element and is not held",),
        good.replace("*STEP, NLGEOM", "*MPC\nMEANROT, 1, 1, 1, 2, 2, 2, 5\n*MPC\nDIST, 6, 6, 6, 7, 7, 7, 5\n"
                                      "*STEP, NLGEOM"):
            ("*MPC MEANROT (a mean rotation", "*MPC DIST (a maximum distance"),
        good.replace("*NSET, NSET=BLOCK", "*ELEMENT, TYPE=B32R, ELSET=BEAM\n40, 1, 2, 3\n*NSET, NSET=BLOCK"):
            ("*ELEMENT, TYPE=B32R is not supported (3-node beam): CalculiX expands it into C3D20R bricks, covcontact "
             "does not",),
    }
    for k, (text, words) in enumerate(cases.items()):
        deck = tmp_path / f"bad{k}.inp"
        deck.write_text(text)
        code, err = _run_deck(deck, tmp_path / f"o{k}")
        assert code == 2, (words, err)
        for w in words:
            assert w in err, (w, err)
