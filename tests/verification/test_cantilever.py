"""Large deflection of a cantilever under a dead tip force against the elastica.

Reference: the elastica EI theta'' = -P cos(theta), theta(0) = 0, theta'(L) = 0, solved here by shooting;
it reproduces Mattiasson (1981), Int. J. Numer. Meth. Engng 17, table 1: for P L^2/EI = 2 the tip
deflection w/L = 0.49346 and the shortening u/L = 0.16064.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import block
from covcontact.problem import Body, Dirichlet, NodalForce, OutputOptions, Problem, SolverOptions, Steps

MATTIASSON = {1.0: (0.05643, 0.30174), 2.0: (0.16064, 0.49346), 4.0: (0.32894, 0.66996)}


def elastica(k2: float) -> tuple[float, float]:
    """(u/L, w/L) of a unit cantilever with P L^2/EI = k2, by shooting on theta'(0)."""

    def rhs(s, y):
        return [y[1], -k2 * np.cos(y[0]), np.cos(y[0]), np.sin(y[0])]

    def end_moment(kappa0):
        sol = solve_ivp(rhs, (0, 1), [0.0, kappa0, 0.0, 0.0], rtol=1e-12, atol=1e-12)
        return sol.y[1, -1]

    kappa0 = brentq(end_moment, 0.0, k2)
    sol = solve_ivp(rhs, (0, 1), [0.0, kappa0, 0.0, 0.0], rtol=1e-12, atol=1e-12)
    return 1.0 - sol.y[2, -1], sol.y[3, -1]


@pytest.mark.parametrize("k2", sorted(MATTIASSON))
def test_elastica_reference_matches_mattiasson(k2):
    u, w = elastica(k2)
    assert u == pytest.approx(MATTIASSON[k2][0], abs=2e-5)
    assert w == pytest.approx(MATTIASSON[k2][1], abs=2e-5)


def cantilever(nx: int, k2: float = 2.0, steps: int = 4) -> Problem:
    L, b, h, E = 10.0, 1.0, 0.2, 1.5e6
    EI = E * b * h**3 / 12.0
    P = k2 * EI / L**2
    mesh = block(L, b, h, nx, 1, 1, cell="hex27")
    return Problem(
        name=f"cantilever-{nx}",
        bodies=[Body("beam", mesh, SaintVenantKirchhoff(E=E, nu=0.0))],
        dirichlet=[Dirichlet("beam", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))],
        forces=[NodalForce("beam", "xmax", (0.0, 0.0, -P), "total")],
        steps=Steps.equal(steps),
        solver=SolverOptions(rtol=1e-10),
        output=OutputOptions(vtu=False),
    )


def tip(result, mesh) -> np.ndarray:
    U = result.u.reshape(-1, 3)
    return U[mesh.node_sets["xmax"]].mean(axis=0)


def test_cantilever_converges_to_elastica(tmp_path):
    u_ref, w_ref = elastica(2.0)
    errors = []
    for nx in (4, 8, 16):
        prob = cantilever(nx)
        res = prob.run(out=tmp_path / str(nx))
        assert res.exit_code == 0
        d = tip(res, prob.bodies[0].mesh) / 10.0
        errors.append(abs(-d[2] - w_ref) / w_ref)
        # every step converges (residual 1e-8 below the step's out-of-balance, or the round-off floor of this
        # slender beam, 2e-9 .. 1e-8 of the load increment) within 12 iterations
        for s in res.summary["steps"]:
            r = s["residual_norms"]
            assert r[-1] < max(3e-8, 1e-8 * max(r[:2])) and s["iterations"] <= 12
    assert errors[-1] < 0.01, errors
    assert errors[2] < errors[0], errors


def test_newton_converges_quadratically(tmp_path):
    """In the asymptotic range (r_k < 0.05, above the round-off floor near 3e-9) r_(k+1) <= C r_k^2 with
    C < 1 (measured: 0.003 and 1.3e-5)."""
    prob = cantilever(8, k2=2.0, steps=2)
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    pairs = []
    for s in res.summary["steps"]:
        r = s["residual_norms"]
        pairs += [(r[k], r[k + 1]) for k in range(len(r) - 1) if r[k] < 0.05 and r[k + 1] > 1e-8]
    assert pairs
    assert all(b <= 1.0 * a * a for a, b in pairs), pairs


@pytest.mark.parametrize("cell", ["tet10", "hex20"])
def test_tetrahedra_and_20_node_bricks_converge_to_elastica(tmp_path, cell):
    """The same cantilever meshed in tet10 (the bricks split into six tetrahedra) or hex20 (hex27 trimmed), one
    brick through the width and the depth: the tip deflection converges to the elastica. Measured w error on 8, 16,
    32 bricks along: tet10 1.27 %, 0.087 %, 0.019 %; hex20 2.02 %, 0.13 %, 0.022 % (hex27: docs/verification.md)."""
    from covcontact.mesh.convert import convert

    u_ref, w_ref = elastica(2.0)
    errors = []
    for nx in (8, 16, 32):
        prob = cantilever(nx)
        prob.bodies[0].mesh = convert(block(10.0, 1.0, 0.2, nx, 1, 1, cell="hex27" if cell == "hex20" else "hex8"),
                                      cell)
        res = prob.run(out=tmp_path / str(nx))
        assert res.exit_code == 0
        d = tip(res, prob.bodies[0].mesh) / 10.0
        errors.append(abs(-d[2] - w_ref) / w_ref)
        assert abs(-d[0] - u_ref) / u_ref < 2.5 * errors[-1] + 1e-4
    assert errors[0] > errors[1] > errors[2], errors
    assert errors[2] < 5e-4, errors
