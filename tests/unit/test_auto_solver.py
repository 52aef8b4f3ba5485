"""``linear = "auto"``: the direct default, except for large frictionless problems of compressible solid bodies,
which go to petsc-gamg where it is installed (covcontact.solvers.run.auto_amg; docs/input.md, [solver])."""

from __future__ import annotations

import dataclasses

import pytest

from covcontact.materials import NeoHooke, SaintVenantKirchhoff
from covcontact.mesh.generators import block, plate
from covcontact.problem import Body, ContactPair, Problem, RigidBody, SolverOptions
from covcontact.solvers.choice import AUTO_AMG_DOFS, auto_amg, resolve_linear
from covcontact.solvers.linear import available


def problem(n: int, **body) -> Problem:
    """Two n x n x n hex8 blocks in frictionless contact (nothing is solved: only the choice is tested)."""
    material = body.pop("material", SaintVenantKirchhoff(E=200.0, nu=0.3))
    lower = Body("lower", block(1.0, 1.0, 1.0, n, n, n), material, **body)
    upper = Body("upper", block(1.0, 1.0, 1.0, n, n, n), material, **body)
    pair = ContactPair("pair", ("upper", "zmin"), ("lower", "zmax"), penalty=1e3)
    return Problem(name="blocks", bodies=[lower, upper], contacts=[pair])


BIG = 25  # 2 x 26^3 nodes = 105,456 dofs; n = 24 gives 93,750
SMALL = 5


def test_the_size_threshold():
    assert 3 * 2 * (BIG + 1) ** 3 >= AUTO_AMG_DOFS > 3 * 2 * BIG**3
    assert auto_amg(problem(BIG))
    assert not auto_amg(problem(BIG - 1)) and not auto_amg(problem(SMALL))


@pytest.mark.parametrize("change", ["friction", "solid-shell", "fbar", "nearly incompressible", "free rigid body",
                                    "plate"])
def test_what_keeps_the_direct_default(change):
    p = problem(BIG)
    if change == "plate":  # two 92 x 92 hex8 plates, one element through the thickness: 103,788 dofs
        p.bodies = [dataclasses.replace(b, mesh=plate(1.0, 1.0, 0.01, 92, 92)) for b in p.bodies]
        assert 3 * sum(b.mesh.n_nodes for b in p.bodies) >= AUTO_AMG_DOFS
    elif change == "friction":
        p.contacts = [dataclasses.replace(p.contacts[0], friction=0.2)]
    elif change in ("solid-shell", "fbar"):
        p.bodies[0] = dataclasses.replace(p.bodies[0], formulation=change)
    elif change == "nearly incompressible":
        p.bodies[1] = dataclasses.replace(p.bodies[1], material=NeoHooke(E=1.0, nu=0.49))
    else:
        p.rigid = [RigidBody("tool", shape="plane", free=(2,))]
    assert not auto_amg(p)
    assert resolve_linear(p, None) == "auto"


def test_resolution():
    big, small = problem(BIG), problem(SMALL)
    gamg = "petsc-gamg" in available()
    assert resolve_linear(big, None) == ("petsc-gamg" if gamg else "auto")
    assert resolve_linear(small, None) == "auto"
    big.solver = SolverOptions(linear="superlu")  # a choice in the input is kept
    assert resolve_linear(big, None) == "superlu"
    assert resolve_linear(big, "Auto ") == ("petsc-gamg" if gamg else "auto")  # the command line's wins
    assert resolve_linear(small, "cg-amg") == "cg-amg"
