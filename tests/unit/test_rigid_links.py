"""Node sets of deformable bodies attached to rigid bodies (``[[rigid]]`` ``attach``, a deck's *RIGID BODY): the
nonlinear elimination u_i = t + (R(theta) - I)(X_i - X_ref) (docs/theory.md, "Multi-point constraints"): closed forms,
large rotations, the reduced tangent against differences, equilibrium of the reported forces, input errors."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.motion import rotation_matrix

from reduced_fd import column_errors

BAR = """
[problem]
name = "links"
[[bodies]]
name = "bar"
element = "hex8"
material = MATERIAL
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 2.0, nx = 2, ny = 2, nz = 3 }
[[dirichlet]]
set = "bar.zmin"
components = "xyz"
[[rigid]]
name = "cap"
attach = ["bar.zmax"]
reference = [0.5, 0.5, 2.0]
RIGID
[steps]
count = 2
"""
SVK = '{ model = "svk", E = 100.0, nu = 0.0 }'
NEO = '{ model = "neo-hooke", E = 100.0, nu = 0.3 }'


def _problem(tmp_path, rigid: str, material: str = SVK, extra: str = ""):
    path = tmp_path / "links.toml"
    path.write_text(BAR.replace("MATERIAL", material).replace("RIGID", rigid) + extra)
    return path


def _stretch(force: float) -> float:
    """St. Venant-Kirchhoff (nu = 0) uniaxial stretch of the unit section under ``force``: E/2 (l^3 - l) = F."""
    roots = np.roots([50.0, 0.0, -50.0, -force])
    return float(roots[np.isreal(roots) & (roots.real > 1.0)].real[0])


@pytest.mark.parametrize("driven", ["motion", "force"])
def test_attached_cap_stretches_the_bar_homogeneously(tmp_path, driven):
    """A rigid cap moved by 0.5 (or pulled by the force that stretch needs) with its other components free: the
    homogeneous stretch (nu = 0 keeps the section), so the support's reaction and the cap's pull are
    E/2 (l^3 - l) A, l = 1.25, to 1e-10 (the force case: the cap's displacement 0.5 to Newton's tolerance)."""
    force = 50.0 * (1.25 ** 3 - 1.25)
    rigid = ('motion = { translation = [0.0, 0.0, 0.5] }\nfree = ["x", "y", "rx", "ry", "rz"]' if driven == "motion"
             else f'free = ["x", "y", "z", "rx", "ry", "rz"]\nforce = [0.0, 0.0, {force!r}]')
    res = load_problem(_problem(tmp_path, rigid)).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    step = res.summary["steps"][-1]
    cap = step["rigid_bodies"]["cap"]
    assert _stretch(force) == pytest.approx(1.25, rel=1e-14)
    assert cap["displacement"][2] == pytest.approx(0.5, rel=1e-9)
    assert step["reactions"]["bar.zmin"][2] == pytest.approx(-force, rel=1e-9)
    assert cap["attached_force"][2] == pytest.approx(-force, rel=1e-9)
    if driven == "force":  # equilibrium of the free body: applied + attached = 0
        assert cap["applied_force"][2] + cap["attached_force"][2] == pytest.approx(0.0, abs=1e-8 * force)
    X = load_problem(_problem(tmp_path, rigid)).bodies[0].mesh.points
    z = res.u.reshape(-1, 3)[: len(X), 2]
    np.testing.assert_allclose(z, 0.25 * X[:, 2], atol=1e-9)   # every node: u_z = (l - 1) Z


def test_a_body_turned_by_two_attached_caps_stays_unstrained(tmp_path):
    """Both ends attached to rigid bodies that turn by 120 degrees about an oblique axis through the base centre (the
    support replaced by the second body): every node at c + R (X - c) to 1e-12, no force on the caps (1e-10 of E A) (a large rotation
    carried exactly, no strain from the elimination)."""
    theta = np.array([1.0, 2.0, 2.0]) / 3.0 * (2.0 * np.pi / 3.0)
    c = [0.5, 0.5, 0.0]
    motion = f"motion = {{ rotation = {theta.tolist()}, center = {c} }}"
    text = BAR.replace("MATERIAL", NEO).replace("RIGID", motion).replace(
        '[[dirichlet]]\nset = "bar.zmin"\ncomponents = "xyz"\n',
        f'[[rigid]]\nname = "base"\nattach = ["bar.zmin"]\nreference = {c}\n{motion}\n')
    path = tmp_path / "turn.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    X = load_problem(path).bodies[0].mesh.points
    x = X + res.u.reshape(-1, 3)[: len(X)]
    np.testing.assert_allclose(x, c + (X - c) @ rotation_matrix(theta).T, atol=1e-12)
    cap = res.summary["steps"][-1]["rigid_bodies"]["cap"]
    # (E A = 100: forces below 1e-10 of it, the interior nodes are found to Newton's tolerance)
    assert np.abs(cap["attached_force"]).max() < 1e-8 and np.abs(cap["attached_moment"]).max() < 1e-8


def test_twisted_cap_balances_the_support(tmp_path):
    """A Neo-Hooke bar twisted by 0.8 rad through a cap free in its translations and tilts: quadratic convergence
    (at most 5 iterations a step), the cap's free components in equilibrium (its pull sums to zero there) and the
    support's reaction moment about the bar's axis equal to the cap's (1e-9)."""
    from covcontact.solvers.model import Model

    rigid = ('motion = { rotation = [0.0, 0.0, 0.8], center = [0.5, 0.5, 2.0] }\n'
             'free = ["x", "y", "z", "rx", "ry"]')
    path = _problem(tmp_path, rigid, NEO)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0 and max(s["iterations"] for s in res.summary["steps"]) <= 5
    cap = res.summary["steps"][-1]["rigid_bodies"]["cap"]
    torque = cap["attached_moment"][2]
    assert abs(torque) > 1.0
    scale = abs(torque)
    assert np.abs(cap["attached_force"]).max() < 1e-8 * scale and np.abs(cap["attached_moment"][:2]).max() < 1e-8 * scale
    model = Model(load_problem(path))
    u = res.u.copy()
    R = model.evaluate(u, 1.0, res.state, want_K=False, raw=True)[0].reshape(-1, 3)
    base = model.system.global_nodes("bar", "zmin")
    x = model.positions(u)
    reaction = np.cross(x[base] - [0.5, 0.5, 0.0], R[base]).sum(axis=0)
    assert reaction[2] == pytest.approx(torque, rel=1e-9)


def test_reduced_tangent_matches_differences(tmp_path):
    """P^T K P plus the rotation's second-order part against central differences of P^T R in the independent dofs
    (the cap's six included), at a deformed state with a rotation of 0.8 rad and forces at the attached nodes:
    <= 1e-6 of max |K|; the attached dofs have zero rows and residuals."""
    from covcontact.solvers.model import Model

    model = Model(load_problem(_problem(tmp_path, 'free = ["x", "y", "z", "rx", "ry", "rz"]', NEO)))
    committed = model.initial_state()
    rng = np.random.default_rng(3)
    u = 0.05 * rng.standard_normal(model.n_dofs)
    ref = model.system.reference[0]
    u[3 * ref.B: 3 * ref.B + 3] = [0.3, -0.2, 0.7]
    R, K, _ = model.evaluate(u, 0.5, committed)
    K = K.toarray()
    dep = model.constraints.mask
    assert model.symmetric is False
    cols = list(range(3 * ref.A, 3 * ref.A + 6)) + list(rng.choice(np.flatnonzero(~dep[: 3 * ref.A]), 10,
                                                                   replace=False))
    errors = column_errors(model, u, 0.5, committed, K, cols)
    assert max(errors.values()) <= 1e-6 * np.abs(K).max(), max(errors, key=errors.get)
    assert np.all(R[dep] == 0.0) and np.allclose(K[np.ix_(dep, ~dep)], 0.0)


def test_attached_input_errors(tmp_path):
    good = 'free = ["x", "y", "z", "rx", "ry", "rz"]'
    base = BAR.replace("MATERIAL", SVK).replace("RIGID", good)
    cases = {
        base.replace('attach = ["bar.zmax"]', 'attach = ["bra.zmax"]'): "no deformable body named 'bra'; did you mean",
        base.replace('attach = ["bar.zmax"]', 'attach = ["bar.zmx"]'): "has no node set 'zmx'; did you mean 'zmax'",
        base.replace('reference = [0.5, 0.5, 2.0]\n', ''): "needs its reference point",
        base.replace('attach = ["bar.zmax"]', 'attach = ["bar.zmin"]'): "attached to rigid body 'cap'",
        base + '[[rigid]]\nname = "cap2"\nattach = ["bar.zmax"]\nreference = [0.0, 0.0, 0.0]\n':
            "is attached to rigid bodies 'cap' and 'cap2'",
        base.replace(good, good + "\nmass = 1.0"): "takes its mass and inertia from their elements",
    }
    path = tmp_path / "bad.toml"
    for text, words in cases.items():
        path.write_text(text)
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))


def test_total_stage_motion_turns_to_the_total_rotation_vector(tmp_path):
    """A stage motion with ``total = true``: its rotation is the body's total rotation vector, reached linearly from
    the one the stage starts with (CalculiX's rotational node), where the default composes the stage's rotation onto
    the pose reached. A free bar hanging from the cap turned to 1.0 e_z, then (total) to 0.8 (1, 1, 1): every node at
    c + R(theta)(X - c) (closed form, Rodrigues) to 1e-8, the cap's rotation vector 0.8 (1, 1, 1) to 1e-12; halfway
    through the stage the motion's vector is the mean of the two. ``total`` with ``path`` is a one-line error."""
    from covcontact.motion import RigidMotion, StagedMotion

    c = [0.5, 0.5, 2.0]
    theta1, theta2 = np.array([0.0, 0.0, 1.0]), np.array([0.8, 0.8, 0.8])
    text = BAR.replace("MATERIAL", SVK).replace("RIGID", f"motion = {{ rotation = {theta1.tolist()}, center = {c} }}")
    text = text.replace('[[dirichlet]]\nset = "bar.zmin"\ncomponents = "xyz"\n', "")
    text += (f'[[stages]]\nname = "turn"\nsteps = {{ count = 4 }}\n'
             f'motions = {{ cap = {{ rotation = {theta2.tolist()}, center = {c}, total = true }} }}\n')
    path = tmp_path / "total.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    X = load_problem(path).bodies[0].mesh.points
    x = X + res.u.reshape(-1, 3)[: len(X)]
    np.testing.assert_allclose(x, c + (X - c) @ rotation_matrix(theta2).T, rtol=0.0, atol=1e-8)
    np.testing.assert_allclose(res.summary["steps"][-1]["rigid_bodies"]["cap"]["rotation"], theta2, atol=1e-12)
    first = RigidMotion(rotation=theta1, center=c)
    staged = StagedMotion(RigidMotion(rotation=theta2, center=c, total=True), *first.state(1.0))
    np.testing.assert_allclose(staged.rotation_vector(0.5), 0.5 * (theta1 + theta2), rtol=0.0, atol=1e-15)
    np.testing.assert_allclose(staged.matrix(0.5), rotation_matrix(0.5 * (theta1 + theta2)), atol=1e-15)
    composed = StagedMotion(RigidMotion(rotation=theta2 - theta1, center=c), *first.state(1.0))
    assert np.abs(composed.matrix(1.0) - rotation_matrix(theta2)).max() > 0.1   # (the default: not the same)
    path.write_text(text.replace("total = true", "total = true, path = [[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 1.0]]"))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "not as a path" in str(err.value) and "\n" not in str(err.value)


# ------------------------------------------------------------------------------------------------ decks

def _bar_deck(path, steps: str, rigid: str = "*RIGID BODY, NSET=TOP, REF NODE=1000, ROT NODE=1001") -> None:
    """A C3D8 bar 1 x 1 x 2 (2 x 2 x 3 elements), E = 100, nu = 0, its base held; its top a rigid body whose REF
    NODE (1000) sits at the top's centre and whose ROT NODE (1001) is a free-standing node."""
    from covcontact.mesh.generators import block

    m = block(1.0, 1.0, 2.0, 2, 2, 3, "hex8")
    lines = [f"{i + 1}, {x:.17g}, {y:.17g}, {z:.17g}" for i, (x, y, z) in enumerate(m.points)]
    els = [", ".join(map(str, [e + 1, *(c + 1)])) for e, c in enumerate(m.cells)]
    top = np.flatnonzero(np.isclose(m.points[:, 2], 2.0)) + 1
    base = np.flatnonzero(np.isclose(m.points[:, 2], 0.0)) + 1
    path.write_text(f"""*NODE, NSET=NALL
{chr(10).join(lines)}
1000, 0.5, 0.5, 2.0
1001, 0.0, 0.0, 0.0
*ELEMENT, TYPE=C3D8, ELSET=BAR
{chr(10).join(els)}
*NSET, NSET=TOP
{", ".join(map(str, top))}
*NSET, NSET=BASE
{", ".join(map(str, base))}
*NSET, NSET=PILOT
1000, 1001
*MATERIAL, NAME=M
*ELASTIC
100.0, 0.0
*SOLID SECTION, ELSET=BAR, MATERIAL=M
*BOUNDARY
BASE, 1, 3
{rigid}
{steps}""")


def _dat_block(text: str, kind: str, nset: str, time: str) -> dict:
    lines = text.splitlines()
    at = lines.index(f" {kind} for set {nset} and time  {time}")
    out = {}
    for ln in lines[at + 2:]:
        if not ln.strip():
            break
        f = ln.split()
        out[int(f[0])] = np.array([float(v) for v in f[1:4]])
    return out


def test_deck_rigid_body_stretches_and_turns_the_bar(tmp_path):
    """*RIGID BODY on the bar's top: step 1 moves the REF NODE up by 0.5 (the St. Venant-Kirchhoff stretch: the
    .dat's force at the REF NODE and the base's reaction E/2 (l^3 - l) A, l = 1.25, to 1e-8); step 2 turns the ROT
    NODE's z component to 0.3 rad with its x and y free (and *EL PRINT's S after step 1: the Cauchy stress F / A
    at all 96 Gauss points in CalculiX's numbering): the top turned by 0.3 about the bar's axis (its nodes at
    c + R (X - c) to the table's seven digits), the ROT NODE's displacement printed as the rotation vector."""
    from covcontact.cli import main
    from covcontact.motion import rotation_matrix

    deck = tmp_path / "rb.inp"
    step = "*STEP, NLGEOM\n*STATIC\n0.5, 1.0\n*BOUNDARY\n{bc}\n*NODE PRINT, NSET=PILOT\nU, RF\n" \
           "*NODE PRINT, NSET=TOP\nU\n*NODE PRINT, NSET=BASE\nRF\n*EL PRINT, ELSET=BAR\nS\n*END STEP\n"
    _bar_deck(deck, step.format(bc="1000, 1, 2, 0.0\n1000, 3, 3, 0.5\n1001, 3, 3, 0.0")
              + step.format(bc="1001, 3, 3, 0.3"))
    assert main(["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    text = (tmp_path / "out" / "rb.dat").read_text()
    force = 50.0 * (1.25 ** 3 - 1.25)
    pilot = _dat_block(text, "forces (fx,fy,fz)", "PILOT", "0.1000000E+01")
    base = _dat_block(text, "forces (fx,fy,fz)", "BASE", "0.1000000E+01")
    assert pilot[1000][2] == pytest.approx(force, rel=1e-8)
    assert sum(v[2] for v in base.values()) == pytest.approx(-force, rel=1e-8)
    lines = text.splitlines()
    at = lines.index(" stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz) for set BAR and time  0.1000000E+01")
    rows = [[float(v) for v in ln.split()] for ln in lines[at + 2: at + 2 + 96]]
    assert [r[:2] for r in rows] == [[e, g] for e in range(1, 13) for g in range(1, 9)]  # 12 C3D8, 8 points each
    stress = np.array([r[2:] for r in rows])
    np.testing.assert_allclose(stress[:, 2], force, rtol=1e-6)   # sigma_zz = F / A (nu = 0 keeps the section)
    assert np.abs(stress[:, [0, 1, 3, 4, 5]]).max() < 1e-6 * force
    u = _dat_block(text, "displacements (vx,vy,vz)", "PILOT", "0.2000000E+01")
    np.testing.assert_allclose(u[1000], [0.0, 0.0, 0.5], atol=1e-8)
    np.testing.assert_allclose(u[1001], [0.0, 0.0, 0.3], atol=1e-8)
    top = _dat_block(text, "displacements (vx,vy,vz)", "TOP", "0.2000000E+01")
    from covcontact.mesh.generators import block

    X = block(1.0, 1.0, 2.0, 2, 2, 3, "hex8").points
    c = np.array([0.5, 0.5, 2.0])
    for lab, disp in top.items():
        want = c + [0.0, 0.0, 0.5] + rotation_matrix([0.0, 0.0, 0.3]) @ (X[lab - 1] - c) - X[lab - 1]
        np.testing.assert_allclose(disp, want, atol=1e-6)  # (the table's seven digits)


def test_deck_rigid_body_errors_and_unsupported(tmp_path):
    """A REF NODE no *NODE defines, NSET and ELSET together, a rigid body's node in a *BOUNDARY (one line each, exit
    2); a *BOUNDARY on the ROT NODE that starts in the second step is listed as unsupported."""
    import contextlib
    import io

    from covcontact.cli import main

    step = "*STEP, NLGEOM\n*STATIC\n*BOUNDARY\n{bc}\n*END STEP\n"
    cases = {
        ("*RIGID BODY, NSET=TOP, REF NODE=1002", step.format(bc="1000, 3, 3, 0.1")): "REF NODE=1002: no *NODE defines",
        ("*RIGID BODY, NSET=TOP, ELSET=BAR, REF NODE=1000", step.format(bc="1000, 3, 3, 0.1")):
            "takes one of NSET= and ELSET=",
        ("*RIGID BODY, NSET=TOP, REF NODE=1000", step.format(bc="TOP, 3, 3, 0.1")): "attached to rigid body",
        ("*RIGID BODY, NSET=TOP, REF NODE=1000, ROT NODE=1001",
         step.format(bc="1000, 3, 3, 0.1") + step.format(bc="1001, 3, 3, 0.2")): "starts after the first step",
    }
    for k, ((rigid, steps), words) in enumerate(cases.items()):
        deck = tmp_path / f"bad{k}.inp"
        _bar_deck(deck, steps, rigid)
        buf = io.StringIO()
        with contextlib.redirect_stderr(buf):
            code = main(["run", str(deck), "--out", str(tmp_path / f"o{k}"), "--quiet"])
        assert code == 2 and words in buf.getvalue(), (words, buf.getvalue())


# ------------------------------------------------------------------------------------------------ dynamics

FALL = """
[problem]
name = "drop"
procedure = "dynamic"
dt = 0.05
t_end = 0.5
method = "newmark"
ramp = false
[[bodies]]
name = "col"
element = "hex8"
material = { model = "svk", E = 1.0e5, nu = 0.3, density = 2.0 }
mesh = { generator = "block", lx = 1.0, ly = 0.5, lz = 2.0, nx = 2, ny = 1, nz = 4 }
[bodies.sets]
corner = { closest = [0.0, 0.0, 2.0] }
other = { closest = [1.0, 0.5, 2.0] }
[[body_force]]
body = "col"
value = [0.0, 0.0, -4.0]
CONSTRAINT
"""
CAP = """[[rigid]]
name = "cap"
attach = ["col.zmax"]
reference = [0.5, 0.25, 2.0]
free = ["x", "y", "z", "rx", "ry", "rz"]
"""
TIE = """[[equation]]
terms = [["col.other", "z", 1.0], ["col.corner", "z", -1.0]]
[[equation]]
terms = [["col.other", "x", 1.0], ["col.corner", "x", -1.0]]
"""


@pytest.mark.parametrize("constraint", [CAP, TIE, CAP.replace("col.zmax", "col.zmin").replace("2.0]", "0.0]") + TIE],
                         ids=["cap", "equations", "both"])
def test_constraints_in_a_dynamic_stage_fall_freely(tmp_path, constraint):
    """An unsupported column under a body force applied at once, its top held by a massless rigid cap with every
    component free, or two of its top corners tied by equations, or both (the cap on the bottom): the constraints
    hold what the free fall does anyway, so every node falls -b t^2 / (2 rho) exactly (1e-10; the trapezoidal rule
    integrates a constant acceleration exactly), from the initial acceleration of the reduced mass P^T M P on, and
    the energy balances (1e-9)."""
    path = tmp_path / "fall.toml"
    path.write_text(FALL.replace("CONSTRAINT", constraint))
    problem = load_problem(path)
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    n = problem.bodies[0].mesh.n_nodes
    np.testing.assert_allclose(res.u.reshape(-1, 3)[:n, 2], -0.5 * (4.0 / 2.0) * 0.5 ** 2, rtol=1e-10)
    assert max(abs(s["energy"]["balance_error"]) for s in res.summary["steps"]) < 1e-9


PENDULUM = """
[problem]
name = "pendulum"
procedure = "dynamic"
dt = 0.022972
t_end = 2.2972
method = "newmark"
gravity = [0.0, 0.49979, -9.98750]
[[bodies]]
name = "bar"
element = "hex8"
material = { model = "svk", E = 1.0e7, nu = 0.3, density = 1.0 }
mesh = { generator = "block", lx = 0.2, ly = 0.2, lz = 2.0, nx = 1, ny = 1, nz = 4, origin = [-0.1, -0.1, -2.0] }
[[rigid]]
name = "pivot"
attach = ["bar.zmax"]
reference = [0.0, 0.0, 0.0]
free = ["rx"]
"""


def test_pendulum_through_an_attached_pivot():
    """A stiff bar 0.2 x 0.2 x 2 hanging from a pivot (its top face attached to a rigid body free to turn about x
    only), gravity g = 10 tilted by theta0 = 0.05 from the bar: it swings as the rigid physical pendulum,
    theta(t) = theta0 (1 - cos(2 pi t / T)) with T = 2 pi sqrt((L^2/3 + b^2/12) / (g L / 2)) = 2.2972 (the step is
    T / 100): theta(T/2) = 2 theta0 to 1e-4, theta(T) = 0 to 1e-4 theta0 (finite amplitude shifts the period by
    theta0^2/16 = 1.6e-4 of it), the kinetic energy at the bottom (T/4) m g (L/2)(1 - cos theta0) to 1e-2 (the
    bar's own ringing), the energy account closed to 3e-3 of that (the trapezoidal rule conserves the energy of a
    linear system only; on this rotation its error is of order (2 pi dt / T)^2 = 4e-3)."""
    import math
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "p.toml"
        path.write_text(PENDULUM)
        res = load_problem(path).run(out=Path(tmp) / "out", quiet=True)
    assert res.exit_code == 0 and max(s["iterations"] for s in res.summary["steps"]) <= 4
    steps = res.summary["steps"]
    theta = np.array([s["rigid_bodies"]["pivot"]["rotation"][0] for s in steps])
    th0 = math.atan2(0.49979, 9.98750)
    assert theta[49] == pytest.approx(2.0 * th0, rel=1e-4) and abs(theta[-1]) < 1e-4 * th0
    peak = 0.08 * 10.0 * 1.0 * (1.0 - math.cos(th0))
    assert steps[24]["energy"]["kinetic"] == pytest.approx(peak, rel=1e-2)
    err = max(abs(s["energy"]["balance_error"]) * max(s["energy"]["kinetic"] + s["energy"]["strain"],
                                                       abs(s["energy"]["external_work"])) for s in steps)
    assert err < 3e-3 * peak


def test_deck_el_print_peeq(tmp_path):
    """*EL PRINT PEEQ: the equivalent plastic strain at every Gauss point in CalculiX's layout (its header has no space
    before "for"): the bar of J2 perfect plasticity (yield 5 against E = 100) stretched by 25 % through its rigid
    top yields everywhere, PEEQ > 0 at all 96 points and below the stretch's ln 1.25 on average (the clamped ends
    concentrate it); the elastic bar prints zeros."""
    from covcontact.cli import main

    step = "*STEP, NLGEOM\n*STATIC\n0.25, 1.0\n*BOUNDARY\n1000, 1, 2, 0.0\n1000, 3, 3, 0.5\n" \
           "*EL PRINT, ELSET=BAR\nPEEQ\n*END STEP\n"
    for plastic in (True, False):
        deck = tmp_path / f"p{plastic}.inp"
        _bar_deck(deck, step)
        if plastic:
            deck.write_text(deck.read_text().replace("100.0, 0.0\n", "100.0, 0.0\n*PLASTIC\n5.0, 0.0\n"))
        assert main(["run", str(deck), "--out", str(tmp_path / f"o{plastic}"), "--quiet"]) == 0
        lines = (tmp_path / f"o{plastic}" / f"p{plastic}.dat").read_text().splitlines()
        at = lines.index(" equivalent plastic strain (elem, integ.pnt.,pe)for set BAR and time  0.1000000E+01")
        rows = np.array([[float(v) for v in ln.split()] for ln in lines[at + 2: at + 2 + 96]])
        assert rows[:, :2].tolist() == [[e, g] for e in range(1, 13) for g in range(1, 9)]
        if plastic:
            assert np.all(rows[:, 2] > 0.0) and 0.0 < rows[:, 2].mean() < np.log(1.25)
        else:
            assert np.all(rows[:, 2] == 0.0)


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
def test_planar_body_pulled_through_an_attached_cap(tmp_path, form):
    """A planar block (St. Venant-Kirchhoff, nu = 0) whose top edge is attached to a rigid cap moved up by 0.25 (a
    deck's *RIGID BODY on CPE or CAX elements): the homogeneous stretch, u_y = 0.25 Y at every node (1e-9), and the
    base's reaction E/2 (l^3 - l) times the section (1e-9; the thickness 1, or pi (2^2 - 1) about the axis). (The
    held z-dofs of the planar body kept their diagonal through the attached nodes' reduction: before, the reduced
    tangent had empty rows there.)"""
    ox = 1.0 if form == "axisymmetric" else 0.0
    text = f"""
[problem]
name = "cap"
[[bodies]]
name = "b"
formulation = "{form}"
element = "quad4"
material = {{ model = "svk", E = 100.0, nu = 0.0 }}
mesh = {{ generator = "rectangle", lx = 1.0, ly = 1.0, nx = 2, ny = 3, origin = [{ox}, 0.0] }}
[[dirichlet]]
set = "b.ymin"
components = "y"
[[dirichlet]]
set = "b.xmin"
components = "x"
[[rigid]]
name = "cap"
attach = ["b.ymax"]
attach_components = ["y"]
reference = [{ox + 0.5}, 1.0, 0.0]
motion = {{ translation = [0.0, 0.25, 0.0] }}
[steps]
count = 2
"""
    path = tmp_path / "cap.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    X = load_problem(path).bodies[0].mesh.points
    u = res.u.reshape(-1, 3)[: len(X)]
    np.testing.assert_allclose(u[:, 1], 0.25 * X[:, 1], atol=1e-9)
    area = np.pi * (2.0 ** 2 - 1.0 ** 2) if form == "axisymmetric" else 1.0
    assert res.summary["steps"][-1]["reactions"]["b.ymin"][1] == pytest.approx(-50.0 * (1.25 ** 3 - 1.25) * area,
                                                                               rel=1e-9)
