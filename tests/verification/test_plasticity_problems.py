"""J2 plasticity through the whole program: problem file, Newton, state, output.

Uniaxial tension of a block under symmetry conditions is a homogeneous state, so every element sees the
material-point closed form in logarithmic strain (docs/theory.md section 12): for a stretch lambda,
eps = ln lambda; with linear hardening the Kirchhoff stress is tau = E eps below yield and
tau = E (sigma_y0 + H eps) / (E + H) on monotonic loading beyond it, alpha = eps - tau / E. (Elastic
unloading is checked at the material point, tests/unit/test_plasticity.py: load factors only increase
within a stage.) The reaction on the loaded face is A0 tau / lambda (first Piola-Kirchhoff stress
P11 = tau / lambda). The plastic work of the backward-Euler update is the sum over the steps of
tau_(n+1) (alpha_(n+1) - alpha_n) per unit reference volume.
"""

from __future__ import annotations

import json

import meshio
import numpy as np
import pytest

from covcontact.io.loader import load_problem

E, NU, SY0, H = 200.0, 0.3, 0.4, 2.0
STRETCH = 0.2  # the loaded face moves by 0.2 (block length 1): lambda = 1.2 at the load factor 1
FACTORS = [0.05 * (k + 1) for k in range(20)]

PROBLEM = f"""
[problem]
name = "uniaxial-j2"

[[bodies]]
name = "bar"
element = "hex8"
formulation = "FORMULATION"
material = {{ model = "j2", E = {E}, nu = {NU}, yield_stress = {SY0}, hardening = {{ law = "linear", modulus = {H} }} }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }}

[[dirichlet]]
set = "bar.xmin"
components = "x"

[[dirichlet]]
set = "bar.ymin"
components = "y"

[[dirichlet]]
set = "bar.zmin"
components = "z"

[[dirichlet]]
set = "bar.xmax"
components = "x"
value = {STRETCH}

[solver]
rtol = 1.0e-12

[steps]
factors = [{", ".join(f"{f:.10g}" for f in FACTORS)}]
"""


def closed_form(factors):
    """(tau, alpha, plastic work) after each step of a monotonic loading."""
    taus, alphas, works = [], [], []
    alpha, work = 0.0, 0.0
    for lam in factors:
        eps = np.log(1.0 + STRETCH * lam)
        trial = E * (eps - alpha)
        if trial > SY0 + H * alpha:  # plastic (the trial stress is beyond the current yield stress)
            tau = E * (SY0 + H * eps) / (E + H)
            new = eps - tau / E
            work += tau * (new - alpha)
            alpha = new
        else:
            tau = trial
        taus.append(tau)
        alphas.append(alpha)
        works.append(work)
    return np.array(taus), np.array(alphas), np.array(works)


@pytest.mark.parametrize("formulation", ["solid", "fbar"])
def test_uniaxial_tension_and_unloading(tmp_path, formulation):
    path = tmp_path / "uniaxial.toml"
    path.write_text(PROBLEM.replace("FORMULATION", formulation))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    tau, alpha, work = closed_form(FACTORS)
    lam = 1.0 + STRETCH * np.array(FACTORS)
    reaction = np.array([-s["reactions"]["bar.xmin"][0] for s in summary["steps"]])
    assert np.allclose(reaction, tau / lam, rtol=1e-8, atol=1e-10)
    # plastic work and dissipation per step from the material history
    wp = np.array([s["plastic_work"] for s in summary["steps"]])
    assert np.allclose(wp, work, rtol=1e-8, atol=1e-12)
    dis = np.array([s["plastic_dissipation"] for s in summary["steps"]])
    assert np.allclose(dis, np.diff(np.concatenate([[0.0], work])), rtol=1e-7, atol=1e-12)
    assert np.all(dis > 0.0)  # every step yields (the first: eps = 0.0099 against sigma_y0 / E = 0.002)
    # cell fields of the last step: uniform equivalent plastic strain, every point yielding
    vtu = meshio.read(tmp_path / "out" / f"step_{len(FACTORS):04d}.vtu")
    eqp = np.concatenate(vtu.cell_data["equivalent_plastic_strain"])
    assert np.allclose(eqp, alpha[-1], rtol=1e-8)
    assert np.all(np.concatenate(vtu.cell_data["yield_flag"]) == 1.0)
    # the committed state carries the same history
    hist = res.state.elements[0]["hist"]
    assert np.allclose(hist[:, :, 6], alpha[-1], rtol=1e-8)


def test_plastic_input_errors(tmp_path):
    """Impossible plastic parameters stop the run with one line naming the file and the key."""
    from covcontact.io.validate import InputError

    bad = {
        'yield_stress = 0.4': 'yield_stress = -1.0',
        'law = "linear", modulus = 2.0': 'law = "swift", K = 1.0, eps0 = 0.01, n = 1.5',
    }
    base = PROBLEM.replace("FORMULATION", "solid")
    for old, new in bad.items():
        text = base.replace(old, new)
        assert text != base
        path = tmp_path / "bad.toml"
        path.write_text(text)
        with pytest.raises(InputError) as err:
            load_problem(path)
        msg = str(err.value)
        assert "bad.toml" in msg and "\n" not in msg
