"""Free vibration of a cantilever: the first period against Euler-Bernoulli, and the period elongation and
amplitude decay of generalized-alpha against the method's own amplification matrix (docs/verification.md,
"Dynamics").

Reference: Euler-Bernoulli, omega_1 = 1.8751^2 sqrt(E I / (rho A L^4)) (e.g. Meirovitch, Fundamentals of Vibrations,
2001, section 8.7). Set-up: the elastica cantilever of test_cantilever.py (L = 10, b = 1, h = 0.2, E = 1.5e6, nu = 0,
rho = 1: T_1 = 2.5272), hex27, clamped at x = 0. Three stages: a static tip force (1e-3 of E I / L^2: a linear
deflection), a short dynamic stage (T_1 / 50) that removes it, then free vibration; the first mode dominates the
tip's motion (the deflected shape of a tip force is close to it).
"""

from __future__ import annotations

import math
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict
from covcontact.observer import Observer
from covcontact.solvers.dynamics import Integrator
from covcontact.solvers.run import solve_problem

L, B, H, E, RHO = 10.0, 1.0, 0.2, 1.5e6, 1.0
EI = E * B * H ** 3 / 12.0
T1 = 2.0 * math.pi / (1.8751040687 ** 2 * math.sqrt(EI / (RHO * B * H * L ** 4)))


def _raw(nx: int, dt: float, method: str, rho_inf: float, periods: float) -> dict:
    swing = {"name": "swing", "procedure": "dynamic", "dt": dt, "t_end": periods * T1, "method": method}
    if method != "newmark":
        swing["rho_inf"] = rho_inf
    return {
        "problem": {"name": "cantilever-vibration"},
        "bodies": [{"name": "beam", "element": "hex27",
                    "material": {"model": "svk", "E": E, "nu": 0.0, "density": RHO},
                    "mesh": {"generator": "block", "lx": L, "ly": B, "lz": H, "nx": nx, "ny": 1, "nz": 1}}],
        "dirichlet": [{"set": "beam.xmin"}],
        "force": [{"name": "tip", "set": "beam.xmax", "value": [0.0, 0.0, -1e-3 * EI / L ** 2],
                   "distribution": "total"}],
        "stages": [{"name": "release", "remove": ["tip"], "procedure": "dynamic", "dt": T1 / 400, "t_end": T1 / 50,
                    "method": "newmark"}, swing],
        "output": {"vtu": False},
    }


class _Tip(Observer):
    """The tip's mean deflection at every converged time step."""

    def __init__(self):
        self.t, self.w = [], []

    def increment_converged(self, run, inc):
        d = inc.state.dynamics
        if d:
            nodes = run.problem.bodies[0].mesh.node_sets["xmax"]
            self.t.append(float(d["time"]))
            self.w.append(float(d["u"].reshape(-1, 3)[nodes, 2].mean()))


def _swing(tmp_path, nx, dt, method, rho_inf=1.0, periods=2.0):
    """(periods between upward zero crossings, the deflection's minimum in each) of the free vibration."""
    prob = problem_from_dict(_raw(nx, dt, method, rho_inf, periods), Path(tmp_path) / "p.toml")
    tip = _Tip()
    res = solve_problem(prob, out=tmp_path / method, observers=[tip])
    assert res.exit_code == 0
    t, w = np.array(tip.t), np.array(tip.w)
    s = np.sign(w)
    k = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    tz = t[k] - w[k] * (t[k + 1] - t[k]) / (w[k + 1] - w[k])
    lows = np.array([w[(t >= a) & (t < b)].min() for a, b in pairwise(tz)])
    return np.diff(tz), lows


def test_first_period_against_euler_bernoulli(tmp_path):
    """Newmark's trapezoidal rule, dt = T_1 / 50, 8 hex27 along: the period within 1 % of Euler-Bernoulli's
    (measured +0.37 % on 8 and 16 elements with dt = T_1 / 100; shear and rotary inertia of the 3D beam make it a
    little longer), the amplitude kept (no numerical damping; within 3 %: the second mode beats on it)."""
    periods, lows = _swing(tmp_path, 8, T1 / 50, "newmark", periods=2.2)
    assert len(periods) >= 1
    assert np.all(np.abs(periods / T1 - 1.0) < 0.01), periods / T1
    assert len(lows) < 2 or abs(lows[-1] / lows[0] - 1.0) < 0.03


def _amplification(g: Integrator, wdt: float) -> complex:
    """The principal (oscillating) eigenvalue of the method's amplification matrix at w dt."""
    A = np.empty((3, 3))
    c0, c1 = 1.0 / g.beta, 0.5 / g.beta - 1.0
    for j in range(3):
        x, v, a = np.eye(3)[j]
        lhs = (1.0 - g.alpha_m) * c0 + wdt ** 2 * (1.0 - g.alpha_f)
        x1 = ((1.0 - g.alpha_m) * (c0 * (x + v) + c1 * a) - g.alpha_m * a - wdt ** 2 * g.alpha_f * x) / lhs
        a1 = g.acceleration(x1, x, v, a, 1.0)
        A[:, j] = (x1, g.velocity(a1, v, a, 1.0), a1)
    lam = np.linalg.eigvals(A)
    return lam[np.argmax(np.abs(lam.imag))]


def test_generalized_alpha_damping_as_the_theory_predicts(tmp_path):
    """Generalized-alpha with rho_inf = 0, dt = T_1 / 8 (w dt = 0.785): the first mode's period lengthens and its
    amplitude decays as the method's amplification matrix says, 2 pi / arg(lambda) = 1.173 T_1 and |lambda|^(steps
    per period) = 0.594 per period. Measured on the beam: 1.177 and 1.172 T_1 (within 0.5 %), decay 0.570 (within
    5 %: the higher modes in the tip's motion die faster)."""
    lam = _amplification(Integrator.of("generalized-alpha", 0.0), 2.0 * math.pi / 8.0)
    theta = abs(np.angle(lam))
    period = 2.0 * math.pi / 8.0 / theta
    decay = abs(lam) ** (2.0 * math.pi / theta)
    assert period == pytest.approx(1.173, abs=1e-3) and decay == pytest.approx(0.594, abs=1e-3)
    periods, lows = _swing(tmp_path, 8, T1 / 8, "generalized-alpha", 0.0, periods=3.6)
    assert np.all(np.abs(periods / T1 / period - 1.0) < 0.01), periods / T1
    assert lows[1] / lows[0] == pytest.approx(decay, rel=0.08)


@pytest.mark.parametrize("cell, nx", [("hex8", 16), ("hex18", 8)])
def test_solid_shell_first_period(tmp_path, cell, nx):
    """The same beam as solid-shells (one element through the thickness, its third direction; the mass of the
    isoparametric brick integrated over the thickness): the first period within 1 % of Euler-Bernoulli (measured
    +0.15 % for hex8 on 16 and hex18 on 8 elements along, dt = T_1 / 50)."""
    raw = _raw(nx, T1 / 50, "newmark", 1.0, 2.2)
    raw["bodies"][0].update({"element": cell, "formulation": "solid-shell",
                             "mesh": {"generator": "plate", "lx": L, "ly": B, "t": H, "nx": nx, "ny": 1}})
    prob = problem_from_dict(raw, Path(tmp_path) / "p.toml")
    tip = _Tip()
    assert solve_problem(prob, out=tmp_path / cell, observers=[tip]).exit_code == 0
    t, w = np.array(tip.t), np.array(tip.w)
    s = np.sign(w)
    k = np.flatnonzero((s[:-1] < 0) & (s[1:] >= 0))
    tz = t[k] - w[k] * (t[k + 1] - t[k]) / (w[k + 1] - w[k])
    assert len(tz) >= 2
    assert np.all(np.abs(np.diff(tz) / T1 - 1.0) < 0.01), np.diff(tz) / T1
