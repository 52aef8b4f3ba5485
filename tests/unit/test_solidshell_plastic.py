"""Plastic solid-shells (hex8, hex18 with J2): options, tangent against finite differences in elastic,
plastic and unloading states, state semantics, agreement with the plain solid and with St. Venant-Kirchhoff
where they must agree, and verification against closed forms (docs/theory.md "Plastic solid-shells").

Closed forms:

- uniaxial tension of a plate (the program from the problem file on): the log-strain solution of
  tests/verification/test_plasticity_problems.py, tau = E (sigma_y0 + H eps) / (E + H) beyond yield;
- plane-strain pure bending, elastic-perfectly plastic: M = M_p (1 - (kappa_y / kappa)^2 / 3) with the
  fully plastic moment M_p = sigma_0' t^2 / 4 per unit width, sigma_0' = 2 sigma_y / sqrt(3),
  kappa_y = 2 sigma_0' / (E' t), E' = E / (1 - nu^2); with n thickness points the moment tends to
  M_p sum_i w_i |zeta_i| (the rule, weights summing to 2, applied to |zeta|), and for every curvature it
  is the rule applied to the material-point response in plane strain with zero thickness stress
  ("discrete closed form", computed here with the same return mapping and the same steps).
"""

from __future__ import annotations

import json

import meshio
import numpy as np
import pytest

from covcontact.assembly import Pattern
from covcontact.elements import SolidBody
from covcontact.elements.solidshell import (
    EAS_MODES, SolidShellBody, check_options, gauss_rule, lobatto_1d, normalize_options, resolve_thickness,
)
from covcontact.fem.shapes import NODES
from covcontact.io.loader import load_problem
from covcontact.materials import J2Plasticity, SaintVenantKirchhoff, j2_point
from covcontact.materials.plasticity import (
    H_ALPHA, H_FLAG, Hill48, LinearHardening, SwiftHardening, VoceHardening,
)
from covcontact.mesh.generators import plate

E, NU = 200.0, 0.3

HARDENING = {
    "linear": dict(yield_stress=0.5, hardening=LinearHardening(modulus=20.0)),
    "swift": dict(hardening=SwiftHardening(K=2.0, eps0=0.01, n=0.2)),
    "voce": dict(yield_stress=0.5, hardening=VoceHardening(sigma_inf=1.0, delta=20.0, modulus=2.0)),
    "kinematic": dict(yield_stress=0.5, hardening=LinearHardening(modulus=5.0), kinematic_modulus=10.0),
}


def j2(law: str = "linear", **kw) -> J2Plasticity:
    return J2Plasticity(E=E, nu=NU, **{**HARDENING[law], **kw})


def shell_pair(cell: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Two distorted, curved shell-like elements (thickness 0.2 against 1 in-plane) sharing a side."""
    rng = np.random.default_rng(seed)
    ref = NODES[cell]
    pts = np.vstack([ref, ref + [2.0, 0.0, 0.0]])
    X, inv = np.unique(np.round(pts, 12), axis=0, return_inverse=True)
    cells = inv.reshape(2, -1).astype(np.int64)
    X = X * [0.5, 0.5, 0.1]
    X[:, 2] += 0.15 * X[:, 0] ** 2 - 0.1 * X[:, 1] ** 2
    X += 0.04 * rng.uniform(-1.0, 1.0, X.shape) * [1.0, 1.0, 0.2]
    return np.ascontiguousarray(X), cells


def rotation(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * W + (1.0 - np.cos(angle)) * W @ W


def residual(body, u, state) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, np.zeros(0), r, None, want_K=False, state=state) == -1
    return r


def tangent(body, u, state) -> tuple[np.ndarray, np.ndarray]:
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P, state=state) == -1
    return P.csr(data).toarray(), r


def commit(body, committed, u):
    """The trial state at u from ``committed`` (a converged step in a test without equilibrium)."""
    st = body.kernel_state(committed, committed)
    residual(body, u, st)
    return body.trial_of(st)


# ----------------------------------------------------------------------------- options


def test_thickness_options_and_defaults():
    mesh = plate(1.0, 1.0, 0.1, 2, 2, "hex8")
    # no thickness keys unless given: the elastic defaults (and the problem fingerprint) are unchanged
    assert check_options(mesh, {}) == normalize_options("hex8", None)
    assert "thickness_points" not in check_options(mesh, {})
    o = check_options(mesh, {"thickness_points": 7, "thickness_rule": "lobatto", "eas_thickness": False})
    assert (o["thickness_points"], o["thickness_rule"], o["eas_thickness"]) == (7, "lobatto", False)
    assert resolve_thickness({}, 0) == ("gauss", 2, 0)
    assert resolve_thickness({"thickness_rule": "lobatto"}, 0) == ("lobatto", 3, 0)
    assert resolve_thickness({}, 15) == ("gauss", 5, 3)
    assert resolve_thickness({"thickness_points": 9, "eas_thickness": False}, 15) == ("gauss", 9, 0)
    assert resolve_thickness({"thickness_points": 4, "eas_thickness": True}, 0) == ("gauss", 4, 2)
    X, cells = shell_pair("hex8")
    el = SolidShellBody("hex8", X, cells, SaintVenantKirchhoff(E=E, nu=NU))
    pl = SolidShellBody("hex8", X, cells, j2())
    assert (el.thickness_rule, el.thickness_points, el.weights.size, el.neas) == ("gauss", 2, 8, 7)
    assert (pl.thickness_rule, pl.thickness_points, pl.weights.size, pl.neas) == ("gauss", 5, 20, 10)
    assert set(el.new_state()) == {"alpha"}
    assert pl.new_state()["hist"].shape == (2, 20, pl.material.n_hist)
    X18, c18 = shell_pair("hex18")
    b18 = SolidShellBody("hex18", X18, c18, j2(), thickness_points=3, thickness_rule="lobatto")
    assert b18.weights.size == 27 and b18.neas == 4 + 1
    assert np.isclose(b18.weights.sum(), 8.0)
    bad = [
        {"thickness_points": 1}, {"thickness_points": 10}, {"thickness_points": 2.5},
        {"thickness_points": True}, {"thickness_points": "5"}, {"thickness_rule": "simpson"},
        {"thickness_rule": 3},
        {"thickness_rule": "lobatto", "thickness_points": 2}, {"eas_thickness": 1},
        {"eas_thickness": True, "thickness_points": 2}, {"thickness_point": 5},
    ]
    for opts in bad:
        with pytest.raises(ValueError) as err:
            check_options(mesh, opts)
        assert "\n" not in str(err.value) and "solid-shell" in str(err.value)
    assert resolve_thickness({"eas_thickness": True}, 0) == ("gauss", 5, 3)
    with pytest.raises(ValueError, match="eas_thickness needs thickness_points >= 3"):
        resolve_thickness({"eas_thickness": True, "thickness_points": 2}, 0)


@pytest.mark.parametrize("n", range(2, 10))
def test_lobatto_rule(n):
    x, w = lobatto_1d(n)
    assert x[0] == -1.0 and x[-1] == 1.0 and np.all(np.diff(x) > 0) and np.all(w > 0)
    for k in range(2 * n - 2):  # exact for degree 2n - 3
        assert abs(w @ x**k - (2.0 / (k + 1) if k % 2 == 0 else 0.0)) <= 1e-14
    pts, wt = gauss_rule("hex18", "lobatto", n)
    assert pts.shape == (9 * n, 3) and np.isclose(wt.sum(), 8.0)


def test_default_rule_is_the_original_rule():
    pts, w = gauss_rule("hex8")
    X, cells = shell_pair("hex8")
    body = SolidShellBody("hex8", X, cells, SaintVenantKirchhoff(E=E, nu=NU), thickness_points=2,
                          thickness_rule="gauss")
    ref = SolidShellBody("hex8", X, cells, SaintVenantKirchhoff(E=E, nu=NU))
    assert np.array_equal(body.points, ref.points) and np.array_equal(body.weights, w)
    assert len(EAS_MODES["hex8"]) == ref.neas
    u = 0.01 * np.random.default_rng(0).standard_normal(X.shape)
    assert np.array_equal(tangent(body, u, body.new_state())[0], tangent(ref, u, ref.new_state())[0])


# ----------------------------------------------------------------------------- tangent


def _states(body, X, d, R):
    """(name, committed state, u): elastic (virgin, small strain), plastic loading (virgin), elastic
    unloading from a plastic committed state."""
    big = X @ R.T - X + 0.02 * d
    committed = commit(body, body.new_state(), big)
    return [("elastic", body.new_state(), X @ R.T - X + 0.0002 * d),
            ("plastic", body.new_state(), big),
            ("unloading", committed, X @ R.T - X + 0.0195 * d)]


def fd_error(body, u, committed) -> tuple[float, np.ndarray]:
    st = body.kernel_state(committed, committed)
    K, r = tangent(body, u, st)
    trial = body.trial_of(st)
    h = 1e-7
    n = 3 * body.n_nodes
    Kfd = np.empty((n, n))
    for j in range(n):
        up = u.ravel().copy()
        um = u.ravel().copy()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up, body.kernel_state(committed, trial))
                     - residual(body, um, body.kernel_state(committed, trial))) / (2.0 * h)
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    return float(np.abs(K - Kfd).max() / np.abs(K).max()), trial["hist"]


@pytest.mark.parametrize("cell", ["hex8", "hex18"])
@pytest.mark.parametrize("law", list(HARDENING))
def test_tangent_matches_central_differences(cell, law):
    X, cells = shell_pair(cell, seed=1)
    body = SolidShellBody(cell, X, cells, j2(law))
    rng = np.random.default_rng(2)
    d = rng.uniform(-1.0, 1.0, X.shape)
    R = rotation([0.3, 1.0, 0.2], 0.9)  # 52 degrees
    for name, committed, u in _states(body, X, d, R):
        err, hist = fd_error(body, u, committed)
        flags = hist[:, :, H_FLAG]
        if name == "plastic":
            assert flags.all()
        else:
            assert not flags.any()
        if name == "unloading":
            assert committed["hist"][:, :, H_ALPHA].min() > 0.0
        assert err <= 1e-8, (name, err)


@pytest.mark.parametrize("cell,opts,mat,scale", [
    ("hex8", {"thickness_points": 3, "thickness_rule": "lobatto"}, "linear", 0.0011),
    ("hex8", {"thickness_points": 9, "eas_thickness": False, "eas": 3}, "voce", 0.0011),
    ("hex18", {"thickness_points": 7, "thickness_rule": "lobatto", "eas": 9}, "swift", 0.0011),
    ("hex18", {"thickness_points": 4, "ans_membrane": False}, "hill", 0.0005),
])
def test_tangent_mixed_states_other_rules_and_hill(cell, opts, mat, scale):
    """Loading from a partly plastic committed state: some points yield, the others stay elastic (the
    yield surface crosses the element; the scales keep every point away from it by more than the
    difference step)."""
    material = (j2("linear", hill48=Hill48(r0=1.8, r45=1.2, r90=2.2)) if mat == "hill" else j2(mat))
    X, cells = shell_pair(cell, seed=5)
    body = SolidShellBody(cell, X, cells, material, **opts)
    rng = np.random.default_rng(6)
    d = rng.uniform(-1.0, 1.0, X.shape)
    committed = commit(body, body.new_state(), scale * d)
    err, hist = fd_error(body, 1.2 * scale * d, committed)
    flags = hist[:, :, H_FLAG]
    assert 0 < flags.sum() < flags.size and committed["hist"][:, :, H_ALPHA].max() > 0
    assert err <= 1e-8


# ----------------------------------------------------------------------------- state


def test_evaluation_leaves_the_committed_state_alone():
    X, cells = shell_pair("hex8", seed=7)
    body = SolidShellBody("hex8", X, cells, j2())
    d = np.random.default_rng(8).uniform(-1.0, 1.0, X.shape)
    committed = commit(body, body.new_state(), 0.01 * d)
    assert committed["hist"][:, :, H_ALPHA].max() > 0
    saved = {k: v.copy() for k, v in committed.items()}
    u = 0.012 * d
    st1 = body.kernel_state(committed, committed)
    K1, r1 = tangent(body, u, st1)
    st2 = body.kernel_state(committed, body.trial_of(st1))  # another start of the local Newton
    r2 = residual(body, u, st2)
    st3 = body.kernel_state(committed, committed)
    K3, r3 = tangent(body, u, st3)
    # the history is read from hist_n only; with ``hist`` alone it is both (copied per element first)
    only = {"alpha": committed["alpha"].copy(), "hist": committed["hist"].copy()}
    r4 = residual(body, u, only)
    body.stress(u, committed)
    body.energy(u, committed)
    body.plastic_fields(committed)
    body.plastic_work(committed)
    for k in ("hist",):
        assert np.array_equal(committed[k], saved[k])
    assert np.array_equal(r1, r3) and np.array_equal(K1, K3)
    assert np.array_equal(st1["hist"], st3["hist"]) and np.array_equal(r4, r1)
    assert np.array_equal(only["hist"], st1["hist"])
    assert np.abs(r2 - r1).max() <= 1e-9 * np.abs(r1).max()
    assert np.abs(st2["hist"] - st1["hist"]).max() <= 1e-9
    # the trial carries more plastic strain than the committed state
    assert (st1["hist"][:, :, H_ALPHA] >= committed["hist"][:, :, H_ALPHA]).all()
    f = body.plastic_fields(body.trial_of(st1))
    assert set(f) == {"equivalent_plastic_strain", "yield_flag"} and f["yield_flag"].shape == (2,)
    vol = body.gauss_volumes()
    assert np.isclose(vol.sum(), np.abs(np.linalg.det(np.einsum(
        "eai,gak->egik", X[cells], body.dNp[: body.weights.size]))).dot(body.weights).sum())
    assert body.plastic_work(body.trial_of(st1)) > body.plastic_work(committed) > 0.0


# ----------------------------------------------------------------------------- agreement


@pytest.mark.parametrize("cell", ["hex8", "hex18"])
def test_homogeneous_deformation_matches_the_solid_element(cell):
    """A homogeneous deformation of a box is represented exactly (alpha = 0): the solid-shell gives the
    forces and the history of the plain solid element, elastic and plastic, over several steps."""
    mesh = plate(1.0, 0.5, 0.1, 2, 1, cell)
    X = mesh.points
    mat = j2("kinematic")
    shell = SolidShellBody(cell, X, mesh.cells, mat, thickness_points=3)
    m = 3 if cell == "hex18" else 2
    solid = SolidBody(cell, X, mesh.cells, mat, rule=(m, m, 3))
    F = np.array([[0.02, 0.004, 0.001], [0.003, -0.006, 0.002], [-0.001, 0.002, -0.01]])
    cs, cb = shell.new_state(), solid.new_state()
    for lam in (0.1, 0.5, 1.0, 1.6, 1.5):  # elastic, plastic, plastic, plastic, unloading
        u = lam * X @ F.T
        ks, kb = shell.kernel_state(cs, cs), solid.kernel_state(cb, cb)
        rs = residual(shell, u, ks)
        rb = residual(solid, u, kb)
        cs, cb = shell.trial_of(ks), solid.trial_of(kb)
        assert np.abs(rs - rb).max() <= 1e-11 * np.abs(rb).max()
        assert np.abs(cs["alpha"]).max() <= 1e-10
        assert np.abs(cs["hist"] - cb["hist"]).max() <= 1e-12
    assert cs["hist"][:, :, H_ALPHA].min() > 0 and not cs["hist"][:, :, H_FLAG].any()


@pytest.mark.parametrize("cell", ["hex8", "hex18"])
def test_elastic_j2_agrees_with_saint_venant_kirchhoff_at_small_strain(cell):
    """Below yield J2 is Hencky elasticity: at u = 0 its tangent is Hooke's (the SVK tangent, to
    round-off) and at a strain of 1e-5 the forces agree with SVK to O(strain)."""
    X, cells = shell_pair(cell, seed=9)
    mat = J2Plasticity(E=E, nu=NU, yield_stress=1e6)
    svk = SaintVenantKirchhoff(E=E, nu=NU)
    a = SolidShellBody(cell, X, cells, mat)
    b = SolidShellBody(cell, X, cells, svk, thickness_points=5, eas_thickness=True)
    K0a = tangent(a, np.zeros_like(X), a.new_state())[0]
    K0b = tangent(b, np.zeros_like(X), b.new_state())[0]
    assert np.abs(K0a - K0b).max() <= 1e-11 * np.abs(K0b).max()
    u = 1e-6 * np.random.default_rng(10).uniform(-1.0, 1.0, X.shape)
    ra, rb = residual(a, u, a.new_state()), residual(b, u, b.new_state())
    assert np.abs(ra - rb).max() <= 1e-4 * np.abs(rb).max()


# ----------------------------------------------------------------------------- verification: tension

SY0, HLIN = 0.4, 2.0
STRETCH = 0.2
FACTORS = [0.05 * (k + 1) for k in range(20)]

PROBLEM = f"""
[problem]
name = "uniaxial-j2-shell"

[[bodies]]
name = "sheet"
element = "CELL"
formulation = "solid-shell"
material = {{ model = "j2", E = {E}, nu = {NU}, yield_stress = {SY0}, \
             hardening = {{ law = "linear", modulus = {HLIN} }} }}
mesh = {{ generator = "plate", lx = 1.0, ly = 1.0, t = 0.1, nx = NX, ny = NX }}
OPTIONS

[[dirichlet]]
set = "sheet.xmin"
components = "x"

[[dirichlet]]
set = "sheet.ymin"
components = "y"

[[dirichlet]]
set = "sheet.bottom"
components = "z"

[[dirichlet]]
set = "sheet.xmax"
components = "x"
value = {STRETCH}

[solver]
rtol = 1.0e-12

[steps]
factors = [{", ".join(f"{f:.10g}" for f in FACTORS)}]
"""


def tension_closed_form(factors):
    """(tau, alpha, plastic work) after each step of a monotonic uniaxial loading (log strain)."""
    taus, alphas, works = [], [], []
    alpha, work = 0.0, 0.0
    for lam in factors:
        eps = np.log(1.0 + STRETCH * lam)
        trial = E * (eps - alpha)
        if trial > SY0 + HLIN * alpha:
            tau = E * (SY0 + HLIN * eps) / (E + HLIN)
            new = eps - tau / E
            work += tau * (new - alpha)
            alpha = new
        else:
            tau = trial
        taus.append(tau)
        alphas.append(alpha)
        works.append(work)
    return np.array(taus), np.array(alphas), np.array(works)


@pytest.mark.parametrize("cell,nx,options", [
    ("hex8", 2, ""), ("hex18", 1, 'options = { thickness_points = 3, thickness_rule = "lobatto" }'),
])
def test_uniaxial_tension_of_a_plate(tmp_path, cell, nx, options):
    path = tmp_path / "tension.toml"
    path.write_text(PROBLEM.replace("CELL", cell).replace("NX", str(nx)).replace("OPTIONS", options))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    tau, alpha, work = tension_closed_form(FACTORS)
    lam = 1.0 + STRETCH * np.array(FACTORS)
    area = 1.0 * 0.1
    reaction = np.array([-s["reactions"]["sheet.xmin"][0] for s in summary["steps"]])
    assert np.allclose(reaction, area * tau / lam, rtol=1e-8, atol=1e-12)
    wp = np.array([s["plastic_work"] for s in summary["steps"]])
    assert np.allclose(wp, 0.1 * work, rtol=1e-8, atol=1e-12)  # volume 0.1
    vtu = meshio.read(tmp_path / "out" / f"step_{len(FACTORS):04d}.vtu")
    eqp = np.concatenate(vtu.cell_data["equivalent_plastic_strain"])
    assert np.allclose(eqp, alpha[-1], rtol=1e-8)
    assert np.all(np.concatenate(vtu.cell_data["yield_flag"]) == 1.0)
    hist = res.state.elements[0]["hist"]
    assert np.allclose(hist[:, :, H_ALPHA], alpha[-1], rtol=1e-8)


# ----------------------------------------------------------------------------- verification: bending

T, L, B, SY = 0.1, 1.0, 0.1, 0.02
SIG0 = 2.0 * SY / np.sqrt(3.0)  # plane-strain yield stress
KAPPA_Y = 2.0 * SIG0 / (E / (1.0 - NU**2) * T)
M_P = SIG0 * T**2 / 4.0


def bend(cell: str, nx: int, kappas, H: float = 0.0, length: float = L, **opts):
    """Plane-strain pure bending of a strip (``length``, width B, thickness T) under end rotation
    theta = kappa length about the mid-thickness point of the end section, whose translation is free (no axial
    or shear force); the other end is a symmetry plane. Returns the moment per unit width, the
    body and Newton iterations of every step."""
    mesh = plate(length, B, T, nx, 1, cell)
    X = mesh.points
    body = SolidShellBody(cell, X, mesh.cells, J2Plasticity(E=E, nu=NU, yield_stress=SY,
                                                             hardening=LinearHardening(modulus=H)), **opts)
    n = X.shape[0]
    x0 = np.isclose(X[:, 0], 0.0)
    xL = np.isclose(X[:, 0], length)
    cols = [3 * a for a in range(n) if not (x0[a] or xL[a])]
    cols += [3 * a + 2 for a in range(n) if not (xL[a] or (x0[a] and X[a, 2] == 0.0))]
    Tm = np.zeros((3 * n, len(cols) + 2))  # u = Tm q + u_p: free dofs, then the end translation
    Tm[cols, np.arange(len(cols))] = 1.0
    Tm[3 * np.flatnonzero(xL), -2] = 1.0
    Tm[3 * np.flatnonzero(xL) + 2, -1] = 1.0
    Xc = np.array([length, 0.0, T / 2])

    def prescribed(theta):
        c, s = np.cos(theta), np.sin(theta)
        u = np.zeros((n, 3))
        du = np.zeros((n, 3))
        u[xL] = (X[xL] - Xc) @ np.array([[c - 1.0, 0, -s], [0, 0, 0], [s, 0, c - 1.0]]).T
        du[xL] = (X[xL] - Xc) @ np.array([[-s, 0, -c], [0, 0, 0], [c, 0, -s]]).T
        return u.ravel(), du.ravel()

    P = Pattern(n, [body.cells])

    def evaluate(u, committed, guess):
        st = body.kernel_state(committed, guess)
        data = P.zeros()
        r = np.zeros(3 * n)
        assert body.assemble(u, data, r, P, state=st) == -1
        return P.csr(data).toarray(), r, body.trial_of(st)

    committed = body.new_state()
    q = np.zeros(Tm.shape[1])
    u_old = np.zeros(3 * n)
    K = evaluate(u_old, committed, committed)[0]
    moments, iterations = [], []
    for kappa in kappas:
        u_p, du_p = prescribed(kappa * length)
        q -= np.linalg.solve(Tm.T @ K @ Tm, Tm.T @ K @ (u_p - u_old))  # predictor
        u_old = u_p
        trial = committed
        for it in range(25):
            K, r, trial = evaluate(Tm @ q + u_p, committed, trial)
            R = Tm.T @ r
            if it == 0:
                r0 = np.abs(R).max()
            if np.abs(R).max() <= max(1e-11 * r0, 1e-12 * SY * T * B):  # relative, or round-off
                break
            q -= np.linalg.solve(Tm.T @ K @ Tm, R)
        else:
            raise AssertionError(f"no convergence at kappa = {kappa}")
        committed = trial
        moments.append(r @ du_p / B)
        iterations.append(it)
    return np.array(moments), body, iterations


def thickness_levels(body):
    pts, w = body.points[: body.weights.size], body.weights
    zeta = np.unique(np.round(pts[:, 2], 13))
    wz = np.array([w[np.isclose(pts[:, 2], z)].sum() for z in zeta])
    return zeta, 2.0 * wz / wz.sum()


def discrete_moment(kappas, zeta, wz, H: float = 0.0):
    """The thickness rule applied to the material-point response: fibre stretch 1 + kappa z, plane strain,
    the thickness stretch iterated to zero S_33; M = sum_i w_i (T/2) P_11 z_i per unit width."""
    mat = J2Plasticity(E=E, nu=NU, yield_stress=SY, hardening=LinearHardening(modulus=H))
    M = np.zeros(len(kappas))
    for zi, wi in zip(zeta, wz):
        z = zi * T / 2
        hist, l3 = np.zeros(mat.n_hist), 1.0
        for k, kappa in enumerate(kappas):
            l1 = 1.0 + kappa * z
            for _ in range(50):
                S, D, new, status = j2_point(mat, np.diag([l1, 1.0, l3]), hist)
                assert status == 0
                if abs(S[2]) <= 1e-14 * SY:
                    break
                l3 -= S[2] / (D[2, 2] * l3)
            hist = new
            M[k] += wi * T / 2 * S[0] * l1 * z
    return M


@pytest.mark.parametrize("cell,nx", [("hex8", 4), ("hex18", 2)])
def test_bending_moment_follows_the_discrete_closed_form(cell, nx):
    """Elastic, elastic-plastic and plastic plane-strain bending (5 Gauss points, the default; hardening
    E/1000) up to 50 kappa_y (outer fibre strain 0.5 %): the moment is the thickness rule applied to the
    material point (zero thickness stress at every thickness level) to 1e-4."""
    H = E / 1000.0
    kappas = KAPPA_Y * np.array([0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0])
    M, body, its = bend(cell, nx, kappas, H=H)
    assert body.thickness_points == 5 and body.n_eas_thickness == 3
    zeta, wz = thickness_levels(body)
    Mh = discrete_moment(kappas, zeta, wz, H=H)
    assert np.abs(M / Mh - 1.0).max() <= 1e-4
    # first step elastic: E' kappa t^3 / 12
    assert abs(M[0] / (E / (1 - NU**2) * kappas[0] * T**3 / 12) - 1.0) <= 1e-4
    assert max(its) <= 6


@pytest.mark.parametrize("points,rule", [(5, "gauss"), (9, "gauss"), (7, "lobatto")])
def test_fully_plastic_moment(points, rule):
    """Elastic-perfectly plastic bending (one hex8 along the strip, which carries the uniform curvature
    alone): the moment follows the discrete closed form and tends to the fully plastic moment of the
    rule, M_p sum_i w_i |zeta_i| (weights summing to 2), which approaches M_p as the thickness points
    increase."""
    kappas = KAPPA_Y * np.array([0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 40.0, 50.0])
    M, body, its = bend("hex8", 1, kappas, length=0.5, thickness_points=points, thickness_rule=rule)
    zeta, wz = thickness_levels(body)
    limit = M_P * (wz @ np.abs(zeta))
    Mh = discrete_moment(kappas, zeta, wz)
    closed = np.where(kappas > KAPPA_Y, M_P * (1.0 - (KAPPA_Y / np.maximum(kappas, KAPPA_Y)) ** 2 / 3.0),
                      E / (1 - NU**2) * kappas * T**3 / 12)
    assert abs(M[0] / closed[0] - 1.0) <= 1e-4
    assert np.abs(M / Mh - 1.0).max() <= 5e-4  # one element: chord of the arc, O(theta^2)
    assert abs(M[-1] / limit - 1.0) <= 5e-4
    assert max(its) <= 6
    assert abs(M[-1] / closed[-1] - 1.0) <= {5: 0.06, 9: 0.02, 7: 0.045}[points]
