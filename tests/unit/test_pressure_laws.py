"""CalculiX's pressure-overclosure laws (contact/laws.py ``PressureLaw``; docs/theory.md, "Pressure-overclosure
laws"): the curves against their closed forms (CalculiX's manual, *SURFACE BEHAVIOR), their slopes against central
differences, the exact tangent of whole contact problems with each law against differences of the residual
(1e-6), and the contact force of a rigidly pressed punch against the law summed over its nodes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.contact.laws import PressureLaw
from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

K, SIG_INF = 1.0e4, 2.0
TABLE = ((0.0, 0.0), (0.001, 5.0), (0.003, 30.0), (0.006, 40.0))
C0, P0 = 0.002, 3.0


def _laws():
    return {"arctan": PressureLaw("arctan", True, slope=K, tension=SIG_INF),
            "table": PressureLaw("table", True, table=TABLE),
            "calculix_exponential": PressureLaw("calculix_exponential", True, clearance=C0, pressure=P0)}


def test_curves_have_calculix_closed_forms():
    laws = _laws()
    # arctan: p = K d (1/2 + atan(d/e)/pi), e = pi sigma_inf / K; p -> -sigma_inf at large clearance, K d deep in
    a = laws["arctan"]
    e = np.pi * SIG_INF / K
    d = np.array([-1e3 * e, -e, 0.0, e, 1e3 * e])
    p, _ = a.pressure(-d)
    assert p == pytest.approx(K * d * (0.5 + np.arctan(d / e) / np.pi), rel=1e-14)
    assert p[0] == pytest.approx(-SIG_INF, rel=1e-5) and p[2] == 0.0
    assert p[-1] == pytest.approx(K * d[-1], rel=1e-3)
    # table: through its points, constant outside (the first pressure before, the last beyond)
    t = laws["table"]
    dd = np.array([-0.01, 0.0, 0.0005, 0.001, 0.002, 0.006, 0.02])
    p, dp = t.pressure(-dd)
    assert p == pytest.approx([0.0, 0.0, 2.5, 5.0, 17.5, 40.0, 40.0], abs=1e-12)
    assert dp[2] == pytest.approx(5000.0) and dp[4] == pytest.approx(12500.0) and dp[-1] == 0.0
    # CalculiX's exponential: p0 at zero gap, 1 % of p0 at the clearance c0; beyond c0 faded to nothing at 2 c0
    x = laws["calculix_exponential"]
    p, _ = x.pressure(np.array([0.0, C0, 0.5 * C0, 1.5 * C0]))
    assert p == pytest.approx([P0, 0.01 * P0, 0.1 * P0, 0.5 * P0 * 100.0 ** -1.5], rel=1e-12)
    act, sig, _ = x.traction(np.array([1.99 * C0, 2.01 * C0]), np.ones(2))
    assert act.tolist() == [True, False] and sig[1] == 0.0


@pytest.mark.parametrize("kind", ["arctan", "table", "calculix_exponential"])
def test_slopes_against_central_differences(kind):
    law = _laws()[kind]
    g = np.array([-0.004, -0.0025, -0.0015, -0.0007, -0.0002, 0.0003, 0.0011, 0.0031])
    area = np.full(g.size, 0.3)
    h = 1e-9
    act, sig, dsig = law.traction(g, area)
    _, sp, _ = law.traction(g + h, area)
    _, sm, _ = law.traction(g - h, area)
    fd = (sp - sm) / (2 * h)
    on = act & (np.abs(sig) > 0)
    assert on.any()
    assert np.allclose(dsig[on], fd[on], rtol=1e-6, atol=1e-9 * np.abs(dsig).max())
    # the linear equivalent reproduces traction and slope
    act2, eps, lam = law.equivalents(g, area)
    assert (act2 == act).all()
    assert np.allclose((lam + eps * g)[on], sig[on], rtol=1e-12, atol=1e-15)


PUNCH = """
[problem]
name = "punch"
[[bodies]]
name = "base"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 3, ny = 3, nz = 1, origin = [-1.0, -1.0, -0.5] }
[[bodies]]
name = "punch"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [-0.4, -0.45, 0.0] }
[[contact]]
slave = "punch.zmin"
master = "base.zmax"
weighting = "area"
LAW
[[dirichlet]]
set = "base.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.0, 0.0, -0.004]
[steps]
count = 2
"""
LAWS = {"arctan": 'law = "arctan"\npenalty = 1.0e4\ntension = 2.0',
        "table": 'law = "table"\ntable = [[0.0, 0.0], [0.001, 5.0], [0.003, 30.0], [0.006, 40.0]]',
        "calculix_exponential": 'law = "exponential"\nform = "calculix"\nclearance = 0.002\npressure = 3.0'}


#: the arctan law's tension: the punch pulled off the base by 0.002 (clearances within reach sqrt(area))
PULL = ('law = "arctan"\npenalty = 1.0e4\ntension = 2.0\nreach = 0.05', 0.002)


@pytest.mark.parametrize("kind", sorted(LAWS) + ["pull"])
def test_exact_tangent_of_each_law(tmp_path, kind):
    """Two deformable blocks pressed together (slave nodes on master facets, edges and vertices): the assembled
    exact tangent against central differences of the residual at 1e-6."""
    path = tmp_path / "p.toml"
    text = PUNCH.replace("LAW", LAWS[kind]) if kind != "pull" else \
        PUNCH.replace("LAW", PULL[0]).replace("value = [0.0, 0.0, -0.004]", "value = [0.0, 0.0, 0.002]")
    path.write_text(text)
    rep = check_tangent(load_problem(path), step=2, columns=None)
    assert rep["converged"], rep
    assert rep["relative_error"] <= 1e-6, rep["relative_error"]


@pytest.mark.parametrize("kind", sorted(LAWS) + ["pull"])
def test_rigidly_pressed_punch_carries_the_law(tmp_path, kind):
    """A punch moved down rigidly (every node prescribed) onto a base much stiffer than the contact: each slave
    node's overclosure is the punch's travel, so the reaction is sum_i A_i p(d) (A_i the nodes' tributary areas,
    summing to the punch's face)."""
    d = 0.004
    law = _laws()[kind] if kind != "pull" else PressureLaw("arctan", True, slope=K, tension=SIG_INF, reach=0.05)
    text = PUNCH.replace("LAW", LAWS[kind] if kind != "pull" else PULL[0]).replace('set = "punch.zmax"',
                                                                                  'set = "punch.all"')
    if kind == "pull":  # (lifted: every node at a clearance, pulled by the tension)
        d = -PULL[1]
        text = text.replace("value = [0.0, 0.0, -0.004]", "value = [0.0, 0.0, 0.002]")
    text = text.replace("E = 1000.0, nu = 0.3 }\nmesh = { generator = \"block\", lx = 2.0",
                        "E = 1.0e16, nu = 0.3 }\nmesh = { generator = \"block\", lx = 2.0")
    path = tmp_path / "p.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    for step, frac in zip(s["steps"], (0.5, 1.0)):
        p, _ = law.pressure(np.array([-frac * d]))
        force = step["contact_force"][2]  # (on the slave nodes: up where the curve pushes, down where it pulls)
        assert force == pytest.approx(1.0 * p[0], rel=1e-6), (kind, step["contact_force"])
        if kind == "pull":
            assert p[0] < 0.0 and step["active_contacts"] == 9


def test_boundary_weighting_takes_the_node_area_over_the_whole_boundary(tmp_path):
    """weighting = "boundary" (a deck's node surface, as CalculiX weights it): each slave node's penalty per area times
    its area over all the boundary faces of its body around it (a quarter of each quad4 face). The rigidly pressed
    punch (1 x 1 x 0.5, 2 x 2 x 1 cells, faces of 0.25 below and on the sides): its bottom corner nodes take 3 x 1/16
    (one bottom, two side faces), its edge nodes 4 x 1/16 (two bottom, two side faces), the centre 4 x 1/16: 2.0 in
    all, twice the bottom's area (CalculiX 2.20 gives such a corner node of a one-element punch 0.5: a quarter of each
    of its three faces, benchmarks/ccx_laws.py); the reaction is K d times 2.0."""
    base = PUNCH.replace('weighting = "area"', 'weighting = "boundary"').replace("LAW", "penalty = 1.0e4")
    text = base.replace('set = "punch.zmax"', 'set = "punch.all"').replace(
        "E = 1000.0, nu = 0.3 }\nmesh = { generator = \"block\", lx = 2.0",
        "E = 1.0e16, nu = 0.3 }\nmesh = { generator = \"block\", lx = 2.0")
    path = tmp_path / "p.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    for step, frac in zip(s["steps"], (0.5, 1.0)):
        assert step["contact_force"][2] == pytest.approx(2.0 * 1.0e4 * 0.004 * frac, rel=1e-6)
    path.write_text(base)
    rep = check_tangent(load_problem(path), step=2, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]
