"""Capstan (Euler-Eytelwein): a thin strip sliding over a rough rigid cylinder.

Reference: L. Euler (1762), J. A. Eytelwein (1808), the belt-friction formula of statics texts: a flexible
band wrapped over an angle theta on a cylinder with Coulomb friction mu, sliding everywhere, carries
T_high / T_low = exp(mu theta) (mu = 0.3: theta = pi/2 -> 1.602, pi -> 2.566).

Set-up: the strip is a ``cylinder_patch`` (hex8 solid-shell, one element through the thickness t = R/100,
width b = R/10, St. Venant-Kirchhoff, nu = 0) of mid radius R + t/2 spanning the angles
[pi/2 - theta, pi/2] about z, so its inner face lies on the rigid cylinder of radius R (analytic master,
inner face nodes the slaves, area-weighted penalties). The end at pi/2 - theta carries a dead tangential
force T_low; the end at pi/2 is pulled along the cylinder: its nodes get the x-displacement of a rotation
by ``delta`` about the axis (-r sin delta, r the node's radius, so the end face turns with the strip), the
axial displacement 0 and the radial (y) displacement free. Loads and displacement grow together
(proportional loading); the pull (delta R = 1e-3) is about ten times the strip's elastic elongation, so
every slave node slides from the second step on, and the ratio is the same at every sliding step.

Measured: T_high = the tangential (-x) reaction of the pulled end, over the applied T_low.

The finite thickness lowers the ratio by 0.2 to 1.4 % here: the tension acts at the mid-surface R + t/2 while
friction acts on the inner face at R, and the shear that balances the friction's moment about the
mid-surface takes a little of the normal force (``exp_strip``). The converged meshes lie within 0.05 % of
exp_strip, and halving t halves the deviation from exp(mu theta) (benchmarks/capstan.py,
docs/verification.md).
"""

from __future__ import annotations

import math
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from covcontact.motion import RigidMotion
from covcontact.elements.solidshell import check_options
from covcontact.io.loader import load_problem
from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import cylinder_patch
from covcontact.problem import (
    Body,
    ContactPair,
    Dirichlet,
    NodalForce,
    OutputOptions,
    Problem,
    RigidBody,
    Steps,
)

ROOT = Path(__file__).resolve().parents[2]
R, T_STRIP, WIDTH, E = 1.0, 0.01, 0.1, 1.0e8
T_LOW = 1.0
A1 = 0.5 * math.pi  # the pulled end; its tangent (direction of increasing angle) is -x


def capstan_problem(theta: float, mu: float, n_circ: int, delta: float = 1.0e-3, penalty: float = 1.0e6,
                    tangential_penalty: float | None = None, steps: int = 4, mode: str = "pull",
                    t: float = T_STRIP) -> Problem:
    """The capstan strip (thickness ``t``) over ``theta`` with friction ``mu``, ``n_circ`` elements around.

    mode "pull": the end at pi/2 is pulled along the cylinder by the angle ``delta``; mode "drum": that
    end is held (x, z) and the cylinder turns by -delta about its axis instead (the strip stays put).
    """
    a0 = A1 - theta
    mesh = cylinder_patch(R + 0.5 * t, WIDTH, a0, A1, t, n_circ, 1, cell="hex8", axis="z")
    body = Body("strip", mesh, SaintVenantKirchhoff(E=E, nu=0.0), "solid-shell", check_options(mesh, {}))
    dirichlet = []
    if mode == "pull":
        for layer, r in (("inner", R), ("outer", R + t)):
            name = f"pull_{layer}"
            mesh.node_sets[name] = np.intersect1d(mesh.node_sets["angle1"], mesh.node_sets[layer])
            dirichlet.append(Dirichlet("strip", name, (0, 2), (-r * math.sin(delta), 0.0)))
        motion = RigidMotion()
    elif mode == "drum":
        dirichlet.append(Dirichlet("strip", "angle1", (0, 2), (0.0, 0.0)))
        motion = RigidMotion(rotation=(0.0, 0.0, -delta))
    else:
        raise ValueError(f"mode must be 'pull' or 'drum', got {mode!r}")
    drum = RigidBody("drum", motion=motion, shape="cylinder",
                     params={"center": (0.0, 0.0, 0.0), "axis": (0.0, 0.0, 1.0), "radius": R, "outside": True})
    # dead force along -t(a0), t(phi) = (-sin phi, cos phi, 0): pulls the low end off along its tangent
    f_low = (T_LOW * math.sin(a0), -T_LOW * math.cos(a0), 0.0)
    return Problem(
        name="capstan",
        description=f"capstan: strip over a rigid cylinder, theta = {theta:.4g}, mu = {mu:g}",
        bodies=[body],
        rigid=[drum],
        contacts=[ContactPair("contact1", slave=("strip", "inner"), master=("drum", ""), penalty=penalty,
                              weighting="area", friction=mu, tangential_penalty=tangential_penalty)],
        dirichlet=dirichlet,
        forces=[NodalForce("strip", "angle0", f_low, "total")],
        steps=Steps.equal(steps),
        output=OutputOptions(vtu=False),
    )


def capstan_measures(summary: dict, f_low) -> list[dict]:
    """Per converged step: T_high / T_low, the pair's stick/slip counts and the force balance residual."""
    out = []
    for s in summary["steps"]:
        if not s["converged"]:
            continue
        lam = s["load_factor"]
        react = np.sum([np.asarray(v) for v in s["reactions"].values()], axis=0)
        pair = s["pairs"]["contact1"]
        contact = np.asarray(pair["contact_force"])  # force of the drum on the strip
        out.append({
            "step": s["step"], "load_factor": lam, "iterations": s["iterations"],
            "ratio": float(-react[0] / (lam * T_LOW)),
            "active": pair["active_contacts"], "slip": pair.get("slip", 0), "stick": pair.get("stick", 0),
            "min_gap": pair["min_gap"],
            "balance": float(np.linalg.norm(react + contact + lam * np.asarray(f_low)) / (lam * T_LOW)),
        })
    return out


def run_capstan(problem: Problem, out) -> tuple[dict, list[dict]]:
    """Run ``problem`` and return (summary, per-step measures)."""
    summary = problem.run(out=out).summary
    return summary, capstan_measures(summary, problem.forces[0].value)


def exp_strip(theta: float, mu: float, t: float = T_STRIP) -> float:
    """The capstan of a curved strip of thickness t: exp(mu theta R / r_m (1 - mu^2 t / (2 r_m))).

    Curved-beam equilibrium with the membrane force T at the mid-surface r_m = R + t/2, contact pressure and
    friction on the inner face at R, constant bending moment: T' = -Q - f, N = T - Q', and the moment of the
    friction about the mid-surface balanced by the shear, Q = -f t / (2 r_m), with f = -mu N. Both
    corrections to exp(mu theta) vanish as t/R -> 0.
    """
    r_m = R + 0.5 * t
    return math.exp(mu * theta * R / r_m * (1.0 - mu * mu * t / (2.0 * r_m)))


@cache
def _measures(theta: float, mu: float, n_circ: int, mode: str = "pull", delta: float = 1.0e-3,
              steps: int = 4) -> tuple:
    with tempfile.TemporaryDirectory() as tmp:
        _, ms = run_capstan(capstan_problem(theta, mu, n_circ, delta=delta, steps=steps, mode=mode), tmp)
    return tuple(ms)


CASES = [(0.5 * math.pi, 0.3), (math.pi, 0.3), (0.5 * math.pi, 0.5), (math.pi, 0.5)]


@pytest.mark.parametrize("theta, mu", CASES)
def test_full_sliding_ratio_is_exp_mu_theta(theta, mu):
    n_circ = round(32 * theta / math.pi)  # 16 elements per quarter turn
    ms = _measures(theta, mu, n_circ)
    n_slaves = 2 * (n_circ + 1)
    assert len(ms) == 4
    for m in ms[1:]:
        # every inner-face node touches and slides at every measured step; the forces balance (to Newton's
        # residual tolerance, 1e-8 of the step's out-of-balance)
        assert m["active"] == m["slip"] == n_slaves and m["stick"] == 0, m
        assert m["balance"] < 1e-8, m
        # penetration: the largest pressure T_high / (R b) over eps_N
        p_max = m["load_factor"] * T_LOW * math.exp(mu * theta) / (R * WIDTH)
        assert -1.1 * p_max / 1.0e6 < m["min_gap"] < 0.0, m
    ratio = ms[-1]["ratio"]
    # docs/verification.md "Capstan": within 2 % of exp(mu theta) (mu = 0.3: 1.602 at pi/2, 2.566 at pi)
    assert ratio == pytest.approx(math.exp(mu * theta), rel=0.02)
    # and within 0.25 % of the thick-strip capstan (measured: -0.21 %, -0.42 %, -0.40 %, -0.80 % from
    # exp(mu theta); +0.05 %, +0.09 %, +0.09 %, +0.18 % from exp_strip, O(h^2) under refinement)
    assert ratio == pytest.approx(exp_strip(theta, mu), rel=2.5e-3)
    # proportional loading at full sliding: the ratio does not depend on the load factor
    assert np.ptp([m["ratio"] for m in ms[1:]]) < 1e-4 * ratio


def test_ratio_converges_under_refinement():
    """Nodes every pi/16, pi/32, pi/64 on a quarter turn: the error falls by about 4 per halving."""
    theta, mu = 0.5 * math.pi, 0.3
    err = [abs(_measures(theta, mu, n)[-1]["ratio"] / exp_strip(theta, mu) - 1.0) for n in (8, 16, 32)]
    # measured: 1.7e-3, 4.6e-4, 1.6e-4
    assert err[1] < err[0] / 3 and err[2] < err[1] / 2 and err[2] < 3e-4, err


def test_turning_drum_gives_the_same_ratio():
    """The end held and the cylinder turned under the strip (a moving analytic master): the same capstan."""
    theta, mu = 0.5 * math.pi, 0.3
    drum = _measures(theta, mu, 16, mode="drum")
    for m in drum[1:]:
        assert m["active"] == m["slip"] == 34 and m["balance"] < 1e-8, m
    assert drum[-1]["ratio"] == pytest.approx(_measures(theta, mu, 16)[-1]["ratio"], rel=1e-4)


def test_frictionless_strip_transmits_the_load():
    ms = _measures(0.5 * math.pi, 0.0, 16)
    assert ms[-1]["ratio"] == pytest.approx(1.0, abs=2e-4)


def test_partial_sliding_stays_below_the_capstan():
    """A pull smaller than the elastic elongation: part of the strip sticks, the ratio is well below."""
    theta, mu = 0.5 * math.pi, 0.3
    last = _measures(theta, mu, 16, delta=5.0e-6)[-1]
    assert last["stick"] > 0 and last["stick"] + last["slip"] == last["active"] == 34, last
    assert last["ratio"] < 0.9 * math.exp(mu * theta)


def test_example_file(tmp_path):
    """examples/verification/capstan.toml: theta = pi, mu = 0.3, the end pulled without turning."""
    prob = load_problem(ROOT / "examples" / "verification" / "capstan.toml")
    _, ms = run_capstan(prob, tmp_path)
    last = ms[-1]
    assert last["slip"] == last["active"] >= 64 and last["stick"] == 0, last
    # measured 2.572 (+0.2 %)
    assert last["ratio"] == pytest.approx(math.exp(0.3 * math.pi), rel=0.01)
