"""Nonlinear multi-point constraints (``[[mpc]]``, a deck's *MPC PLANE, STRAIGHT, BEAM; docs/theory.md, "Nonlinear
multi-point constraints"): the constraint functions' derivatives and the reduced tangent against differences, the
constraints held exactly under large rigid rotations and in a homogeneous stretch (closed form), equilibrium, input
errors, and decks (CalculiX's dependent dofs, its order of a set's nodes, its skipped clashes; against CalculiX where
it is installed)."""

from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.motion import rotation_matrix
from covcontact.solvers.mpc import beam_constraint, line_constraint, plane_constraint

from reduced_fd import column_errors
from test_coupling import dat_blocks

# a 1 x 1 x 4 block of 2 x 2 x 4 hex8: node i + 3 j + 9 k at (i/2, j/2, k)
BLOCK = """
[problem]
name = "mpc"
[[bodies]]
name = "bar"
element = "hex8"
material = MATERIAL
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 4.0, nx = 2, ny = 2, nz = 4 }
sets = { a = { nodes = [36] }, b = { nodes = [38] }, c = { nodes = [42] }, p = { nodes = [9] }, q = { nodes = [27] }, m = { nodes = [18] }, tip = { nodes = [31] }, foot = { nodes = [4] } }
CONDITIONS
[[mpc]]
type = "plane"
nodes = ["bar.a", "bar.b", "bar.c", "bar.zmax"]
[[mpc]]
type = "straight"
nodes = ["bar.p", "bar.q", "bar.m"]
[[mpc]]
type = "beam"
nodes = ["bar.tip", "bar.foot"]
[steps]
count = STEPS
"""
NEO = '{ model = "neo-hooke", E = 100.0, nu = 0.3 }'
SVK0 = '{ model = "svk", E = 100.0, nu = 0.0 }'
CLAMP = '[[dirichlet]]\nset = "bar.zmin"\ncomponents = "xyz"\n'


def _path(tmp_path, conditions: str = CLAMP, material: str = NEO, steps: int = 2, name: str = "mpc.toml"):
    path = tmp_path / name
    path.write_text(BLOCK.replace("MATERIAL", material).replace("CONDITIONS", conditions)
                    .replace("STEPS", str(steps)))
    return path


@pytest.mark.parametrize("which", ["plane", "straight", "beam"])
def test_constraint_derivatives_match_differences(which):
    """g, dg/dy and d2g/dy2 of each constraint at random positions: the gradient and the Hessian against central
    differences of g and of the gradient (1e-7; g is a polynomial of degree <= 3, so differences of 1e-6 are exact
    to round-off), the Hessian symmetric."""
    rng = np.random.default_rng(7)
    n, extra = {"plane": (12, ()), "straight": (9, (np.array([0, 1, 2]),)), "beam": (6, (np.full(3, 0.7),))}[which]
    fun = {"plane": plane_constraint, "straight": line_constraint, "beam": beam_constraint}[which]
    y = rng.standard_normal((3, n))
    g, G, H = fun(y, *extra)
    h = 1e-6
    for j in range(n):
        yp, ym = y.copy(), y.copy()
        yp[:, j] += h
        ym[:, j] -= h
        gp, Gp, _ = fun(yp, *extra)
        gm, Gm, _ = fun(ym, *extra)
        np.testing.assert_allclose((gp - gm) / (2 * h), G[:, :, j], atol=1e-7)
        np.testing.assert_allclose((Gp - Gm) / (2 * h), H[:, :, :, j], atol=1e-7)
    np.testing.assert_allclose(H, np.swapaxes(H, 2, 3), atol=1e-14)


def test_reduced_tangent_matches_differences(tmp_path):
    """P^T K P plus the constraints' second-order part against central differences of the reduced residual in every
    independent dof, at a random deformed state with loads (so the dependent dofs carry forces): <= 1e-6 of max |K|;
    symmetric (the elimination keeps K's symmetry); the dependent dofs have zero rows and residuals; every constraint
    holds at the evaluated state to round-off."""
    from covcontact.solvers.model import Model

    force = '[[force]]\nset = "bar.zmax"\nvalue = [0.3, -0.2, 0.4]\n'
    model = Model(load_problem(_path(tmp_path, CLAMP + force)))
    committed = model.initial_state()
    rng = np.random.default_rng(3)
    u = 0.05 * rng.standard_normal(model.n_dofs)
    R, K, _ = model.evaluate(u, 0.5, committed)
    K = K.toarray()
    dep = model.constraints.mask
    assert dep.sum() == 9 + 2 + 1 - 3 and model.symmetric   # (zmax less the plane's three defining nodes)
    errors = column_errors(model, u, 0.5, committed, K, np.flatnonzero(~dep))
    assert max(errors.values()) <= 1e-6 * np.abs(K).max(), max(errors, key=errors.get)
    np.testing.assert_allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    assert np.all(R[dep] == 0.0) and np.allclose(K[np.ix_(dep, ~dep)], 0.0)
    _assert_constraints_hold(model.system.X + u.reshape(-1, 3), 1e-12)


def _assert_constraints_hold(x: np.ndarray, tol: float) -> None:
    """The three constraints of BLOCK at positions x: zmax in the plane of nodes 36, 38, 42; node 18 on the line of
    9 and 27; nodes 31 and 4 at distance 3."""
    n = np.cross(x[38] - x[36], x[42] - x[36])
    n /= np.linalg.norm(n)
    zmax = [i + 3 * j + 36 for j in range(3) for i in range(3)]
    assert np.abs((x[zmax] - x[36]) @ n).max() <= tol
    d = (x[27] - x[9]) / np.linalg.norm(x[27] - x[9])
    assert np.linalg.norm(np.cross(x[18] - x[9], d)) <= tol
    assert abs(np.linalg.norm(x[31] - x[4]) - 3.0) <= tol


def test_rigid_rotation_stays_unstrained(tmp_path):
    """The block turned as a whole by 120 degrees about an oblique axis (the foot's nodes moved there, the rest
    free): every node at c + R (X - c) (Rodrigues, closed form) to 1e-9 and the constraints hold to 1e-12; the
    constraints' exact elimination makes no force (the foot's reaction below 1e-8 of E A)."""
    theta = np.array([1.0, 2.0, 2.0]) / 3.0 * (2.0 * np.pi / 3.0)
    c = np.array([0.5, 0.5, 0.0])
    cond = (f'[[dirichlet]]\nset = "bar.zmin"\ncomponents = "xyz"\n'
            f'motion = {{ rotation = {theta.tolist()}, center = {c.tolist()} }}\n')
    path = _path(tmp_path, cond, steps=3)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    X = load_problem(path).bodies[0].mesh.points
    x = X + res.u.reshape(-1, 3)[: len(X)]
    np.testing.assert_allclose(x, c + (X - c) @ rotation_matrix(theta).T, atol=1e-9)
    _assert_constraints_hold(x, 1e-12)
    assert np.abs(res.summary["steps"][-1]["reactions"]["bar.zmin"]).max() < 1e-8 * 100.0


def test_homogeneous_stretch_is_not_disturbed(tmp_path):
    """A St. Venant-Kirchhoff bar (nu = 0: no lateral contraction, so the clamp is compatible) stretched by 1 along z
    through the plane's three defining nodes alone, the rest of the end face held in their plane and node 18 on its
    line (the beam constraint, which would forbid the stretch, left out): the homogeneous stretch is the solution,
    u_z = 0.25 Z at every node (1e-9), and the clamp's reaction is E/2 (l^3 - l) A with l = 1.25 (1e-9): the
    constraints carry the load to the end face's other nodes and add no force where the stretch satisfies them."""
    cond = CLAMP + "".join(f'[[dirichlet]]\nset = "bar.{s}"\ncomponents = "z"\nvalue = 1.0\n' for s in "abc")
    text = BLOCK.replace("MATERIAL", SVK0).replace("CONDITIONS", cond).replace("STEPS", "2")
    text = text[: text.index('[[mpc]]\ntype = "beam"')] + text[text.index("[steps]"):]
    path = tmp_path / "stretch.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    X = load_problem(path).bodies[0].mesh.points
    u = res.u.reshape(-1, 3)[: len(X)]
    np.testing.assert_allclose(u[:, 2], 0.25 * X[:, 2], atol=1e-9)
    np.testing.assert_allclose(u[:, :2], 0.0, atol=1e-9)
    force = 50.0 * (1.25 ** 3 - 1.25)   # E/2 (l^3 - l) on the unit section
    assert res.summary["steps"][-1]["reactions"]["bar.zmin"][2] == pytest.approx(-force, rel=1e-9)


def test_bent_bar_holds_its_constraints_in_equilibrium(tmp_path):
    """The clamped Neo-Hooke bar bent and twisted by end forces with all three constraints: each holds to 1e-12 at
    the end, the clamp's reaction balances the applied force (1e-8: the constraints' forces are internal), Newton
    converges quadratically (at most 6 iterations a step)."""
    force = '[[force]]\nset = "bar.zmax"\nvalue = [0.05, 0.02, 0.1]\n'
    path = _path(tmp_path, CLAMP + force, steps=2)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0 and max(s["iterations"] for s in res.summary["steps"]) <= 6
    X = load_problem(path).bodies[0].mesh.points
    x = X + res.u.reshape(-1, 3)[: len(X)]
    _assert_constraints_hold(x, 1e-12)
    assert np.linalg.norm(x[40] - X[40]) > 0.1
    reaction = np.array(res.summary["steps"][-1]["reactions"]["bar.zmin"])
    np.testing.assert_allclose(reaction, -9 * np.array([0.05, 0.02, 0.1]), atol=1e-8)


def test_mpc_input_errors(tmp_path):
    """One line each, naming the entry: an unknown type (with the closest), a defining set of several nodes, three
    defining nodes on a line, a dependent dof eliminated twice, a chain, a Dirichlet condition on a dependent dof, a
    beam of three sets."""
    good = BLOCK.replace("MATERIAL", NEO).replace("CONDITIONS", CLAMP).replace("STEPS", "1")
    cases = {
        good.replace('type = "plane"', 'type = "plain"'): "unknown type 'plain'; did you mean 'plane'",
        good.replace('nodes = ["bar.a", "bar.b"', 'nodes = ["bar.zmax", "bar.b"'):
            "'bar.zmax' holds 9 nodes; the defining nodes are sets of one node each",
        good.replace('sets = { a = { nodes = [36] }', 'sets = { a = { nodes = [37] }').replace(
            'c = { nodes = [42] }', 'c = { nodes = [38] }'): "lie on a line",
        good + '[[mpc]]\ntype = "straight"\nnodes = ["bar.p", "bar.q", "bar.m"]\n': "is eliminated by mpc[1] already",
        good + '[[mpc]]\ntype = "beam"\nnodes = ["bar.m", "bar.tip"]\n': "constraints may not chain",
        good.replace(CLAMP, CLAMP + '[[dirichlet]]\nset = "bar.m"\ncomponents = "x"\n'):
            "is eliminated by mpc[1] and held by this condition",
        good.replace('nodes = ["bar.tip", "bar.foot"]', 'nodes = ["bar.tip", "bar.foot", "bar.m"]'):
            "exactly two sets of one node each",
    }
    path = tmp_path / "bad.toml"
    for text, words in cases.items():
        path.write_text(text)
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))


def _deck(mpc: str) -> str:
    """A C3D20 cantilever 1 x 1 x 8 (1 x 1 x 4 elements) clamped at z = 0, pulled sideways at the far end, with
    the *MPC lines ``mpc``; node sets TOP (the far face, its corners at (0, 0, 8), (1, 0, 8), (0, 1, 8) written first) and MID (the
    line x = 0.5, y = 1, its ends left out)."""
    nodes, index = [], {}
    # 20-node bricks on a grid with half-steps: every grid point (i, j, k) of a 3 x 3 x 9 lattice except the
    # centres of faces and cells (the points with two or three odd indices)
    for k in range(9):
        for j in range(3):
            for i in range(3):
                if (i % 2) + (j % 2) + (k % 2) >= 2:
                    continue
                index[i, j, k] = len(nodes) + 1
                nodes.append(f"{len(nodes) + 1}, {0.5 * i}, {0.5 * j}, {k}")
    corners = [(0, 0, 0), (2, 0, 0), (2, 2, 0), (0, 2, 0), (0, 0, 2), (2, 0, 2), (2, 2, 2), (0, 2, 2)]
    mids = [(1, 0, 0), (2, 1, 0), (1, 2, 0), (0, 1, 0), (1, 0, 2), (2, 1, 2), (1, 2, 2), (0, 1, 2),
            (0, 0, 1), (2, 0, 1), (2, 2, 1), (0, 2, 1)]
    els = [[str(index[i, j, 2 * e + k]) for i, j, k in corners + mids] for e in range(4)]  # (15 nodes a line)
    top = [index[p] for p in [(0, 0, 8), (2, 0, 8), (0, 2, 8)]]
    top += [index[i, j, 8] for j in range(3) for i in range(3) if (i, j, 8) in index and index[i, j, 8] not in top]
    base = [index[i, j, 0] for j in range(3) for i in range(3) if (i, j, 0) in index]
    mid = [index[1, 2, k] for k in range(1, 8) if (1, 2, k) in index]
    return ("*NODE\n" + "\n".join(nodes) + "\n*ELEMENT, TYPE=C3D20, ELSET=EALL\n"
            + "\n".join(f"{e + 1}, {', '.join(els[e][:15])},\n{', '.join(els[e][15:])}" for e in range(4)) + "\n"
            + "*NSET, NSET=TOP\n" + ",\n".join(map(str, top)) + "\n"
            + "*NSET, NSET=BASE\n" + ", ".join(map(str, base)) + "\n"
            + "*NSET, NSET=MID\n" + ", ".join(map(str, mid)) + "\n"
            + "*NSET, NSET=NALL, GENERATE\n1, " + str(len(nodes)) + "\n"
            + "*MATERIAL, NAME=EL\n*ELASTIC\n210000., 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=EL\n"
            + mpc + "*BOUNDARY\nBASE, 1, 3\n*STEP, NLGEOM, INC=100\n*STATIC\n0.25, 1.\n*CLOAD\n"
            + f"{index[1, 2, 8]}, 2, 20000.\n*NODE PRINT, NSET=NALL\nU\n*END STEP\n"), index


def _dat_u(path) -> dict[int, np.ndarray]:
    """The last displacement block of a .dat."""
    blocks = dat_blocks(path)
    return blocks[[k for k in blocks if k[0] == "displacements"][-1]]


@pytest.mark.parametrize("kind", ["PLANE", "STRAIGHT"])
def test_deck_mpc_keeps_calculix_meaning(tmp_path, kind):
    """*MPC PLANE over a set whose three first-written nodes define the plane (CalculiX reads the set in the order
    written) and STRAIGHT over two nodes and the rest of a line: the constrained nodes stay in the plane of the
    deformed defining nodes (on their line) to 1e-6 of the tip's motion (the .dat's six digits); where CalculiX is
    installed, every displacement agrees with its run of the same deck within 1e-4 of the largest (measured 2.9e-5
    and 1.9e-5, where the MPC moves the nodes by 0.7 % and 3.5 % of it)."""
    from covcontact.cli import main

    mpc = "*MPC\nPLANE, TOP\n" if kind == "PLANE" else None
    text, index = _deck("")
    if mpc is None:
        mid = [index[1, 2, k] for k in range(9) if (1, 2, k) in index]
        mpc = f"*MPC\nSTRAIGHT, {mid[-1]}, {mid[0]}, MID\n"
    text, index = _deck(mpc)
    deck = tmp_path / "bar.inp"
    deck.write_text(text)
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    u = _dat_u(tmp_path / "o" / "bar.dat")
    X = {v: np.array([0.5 * i, 0.5 * j, float(k)]) for (i, j, k), v in index.items()}
    x = {v: X[v] + u[v] for v in u}
    scale = np.linalg.norm(u[index[1, 2, 8]])
    assert scale > 0.1
    if kind == "PLANE":
        a, b, c = (x[index[p]] for p in [(0, 0, 8), (2, 0, 8), (0, 2, 8)])
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        top = [v for (i, j, k), v in index.items() if k == 8]
        assert np.abs([(x[v] - a) @ n for v in top]).max() <= 1e-6 * scale
    else:
        line = [index[1, 2, k] for k in range(9) if (1, 2, k) in index]
        d = (x[line[0]] - x[line[-1]]) / np.linalg.norm(x[line[0]] - x[line[-1]])
        assert max(np.linalg.norm(np.cross(x[v] - x[line[-1]], d)) for v in line) <= 1e-6 * scale
    if not shutil.which("ccx"):
        return
    (tmp_path / "ccx").mkdir()
    (tmp_path / "ccx" / "bar.inp").write_text(text)
    subprocess.run(["ccx", "-i", "bar"], cwd=tmp_path / "ccx", capture_output=True, timeout=120, check=True)
    ref = _dat_u(tmp_path / "ccx" / "bar.dat")
    big = max(np.abs(r).max() for r in ref.values())
    assert max(np.abs(u[v] - ref[v]).max() for v in ref) <= 1e-4 * big


def test_deck_mpc_clash_unsupported_and_errors(tmp_path):
    """A node whose dependent dof an earlier *MPC has taken: its constraint left out with a note, as CalculiX leaves
    it out; MEANROT (also by its old name 1, as cgx writes it under *MPC, USER) and DIST listed as unsupported
    (exit 2, each named); a *MPC naming an undefined set or node, or
    a PLANE of three nodes: one line with the deck's line (exit 2)."""
    from covcontact.io.deck_import import import_deck

    text, index = _deck("*MPC\nPLANE, TOP\n*MPC\nPLANE, TOP\n")
    deck = tmp_path / "twice.inp"
    deck.write_text(text)
    imp = import_deck(deck, tmp_path / "twice" / "twice.toml")
    assert not imp.unsupported
    assert sum("is the dependent dof of an earlier MPC: this node's constraint is left out" in n
               for n in imp.notes) == 5
    problem = load_problem(imp.problem)
    assert [m.kind for m in problem.mpcs] == ["plane"]
    for mpc, words in [("*MPC\nMEANROT, 1, 1, 1, 2, 2, 2, 3\n", "*MPC MEANROT (a mean rotation"),
                       ("*MPC\nDIST, 1, 1, 1, 2, 2, 2, 3\n", "*MPC DIST (a maximum distance"),
                       ("*MPC, USER\n1, 1, 1, 1, 2, 2, 2, 3\n", "*MPC MEANROT (a mean rotation"),
                       ("*MPC\nPLANE, TOPS\n", "*MPC PLANE: no node set TOPS"),
                       ("*MPC\nPLANE, 1, 2, 99999\n", "node 99999 is not defined"),
                       ("*MPC\nPLANE, 1, 2, 3\n", "needs 3 defining nodes and at least one more")]:
        text, _ = _deck(mpc)
        deck = tmp_path / "bad.inp"
        deck.write_text(text)
        proc = subprocess.run(["covcontact", "run", str(deck), "--out", str(tmp_path / "ob")], capture_output=True,
                              text=True, timeout=120)
        assert proc.returncode == 2 and words in proc.stderr and "Traceback" not in proc.stderr, (words, proc.stderr)
