"""A rigid body with a reference node and a mass: a lid of mass m on an elastic block under gravity, the
mass-spring oscillator (docs/verification.md, "Dynamics").

Reference: m x'' + k x = m g from rest at the unloaded length: x oscillates between 0 and 2 m g / k with the period
2 pi sqrt(m / k). Set-up: a 1 x 1 x 1 block (E = 1e4, nu = 0: k = E A / H = 1e4; density 1e-3, its mass 1e-4 of the
lid's), held at its bottom, a rigid plane (free in z, mass 10) on its top, gravity 1 (static deflection 1e-3: a
linear spring), penalty 1e8 per area, Newmark's trapezoidal rule, dt = T / 50.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

LID = """
[problem]
name = "mass-on-spring"
gravity = [0.0, 0.0, -1.0]
procedure = "dynamic"
dt = 0.004
t_end = 0.6
method = "newmark"
mass = "redistributed"
[[bodies]]
name = "block"
material = { model = "svk", E = 1.0e4, nu = 0.0, density = 0.001 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }
[[rigid]]
name = "lid"
shape = "plane"
point = [0.5, 0.5, 1.0]
normal = [0.0, 0.0, -1.0]
free = ["z"]
mass = 10.0
[[contact]]
slave = "block.zmax"
master = "lid"
penalty = 1.0e8
weighting = "area"
[[dirichlet]]
set = "block.zmin"
[output]
vtu = false
"""
M, K, G = 10.0, 1.0e4, 1.0
T = 2.0 * math.pi * math.sqrt(M / K)
DEFLECTION = M * G / K


def test_lid_oscillates_on_the_block(tmp_path):
    """The lid swings between 0 and 2 m g / k (measured 2.004) with the period 2 pi sqrt(m / k) (measured 1.0029 T:
    the trapezoidal rule's 0.13 % at dt = T / 50 and the block's own compliance), the energy balance within 1e-3."""
    path = tmp_path / "lid.toml"
    path.write_text(LID)
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    z = np.array([s["rigid_bodies"]["lid"]["displacement"][2] for s in steps])
    t = np.array([s["time"] for s in steps])
    assert -z.min() == pytest.approx(2.0 * DEFLECTION, rel=0.01)
    w = z + DEFLECTION
    sg = np.sign(w)
    k = np.flatnonzero((sg[:-1] < 0) & (sg[1:] >= 0))
    tz = t[k] - w[k] * (t[k + 1] - t[k]) / (w[k + 1] - w[k])
    assert len(tz) >= 2
    np.testing.assert_allclose(np.diff(tz) / T, 1.0, atol=0.01)
    assert max(abs(s["energy"]["balance_error"]) for s in steps) < 1e-3


@pytest.mark.parametrize("change, key, message", [
    (("mass = 10.0\n", ""), "rigid[0].mass", "needs its mass"),
    (('free = ["z"]', 'free = ["z", "rx"]'), "rigid[0].inertia", "principal moments of inertia"),
    (('free = ["z"]\n', ""), "rigid[0].mass", "this one's motion is prescribed"),
])
def test_bad_input(tmp_path, change, key, message):
    path = tmp_path / "lid.toml"
    path.write_text(LID.replace(*change))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert key in str(err.value) and message in str(err.value), str(err.value)
