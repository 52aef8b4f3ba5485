"""Covariant Coulomb friction element (docs/theory.md section 7; Konyukhov & Schweizerhof, Comput Mech 35
(2005)). Every tangent is checked against central differences of the residual with re-projection
(docs/verification.md "Contact element and contact problems"); the stick residual against the gradient
of the stick energy 1/2 eps_N g^2 + 1/2 eps_T a_ij dxi^i dxi^j (the sign reference).
"""

import numpy as np
import pytest

from covcontact.contact import CASES, Cylinder, Plane, RigidMotion, Sphere
from covcontact.contact.element import contact_element
from covcontact.contact.friction import (
    HIST_SIZE,
    NEW,
    OPEN,
    SLIP,
    STICK,
    analytic_friction_batch,
    friction_batch,
    friction_element,
    make_history,
    node_to_surface_friction,
    surface_friction,
    transfer_history,
)
from covcontact.contact.geometry import facet_geometry
from covcontact.contact.projection import project_on_facet
from covcontact.motion import rotation_matrix
from profile_cases import profiles
from covcontact.fem.shapes import NODES

EPS_N = 7.0
EPS_T = 11.0
MU = {STICK: 5.0, SLIP: 0.2}  # with |dxi| ~ 0.06 and g = -0.03: ||T^tr|| ~ 0.6, mu eps_N |g| = 1.05 / 0.04
T_OLD = np.array([0.3, -0.2])
FACETS = [(4, False), (4, True), (9, False), (9, True)]
XI_N = np.array([0.1, -0.2])
DXI = np.array([0.05, -0.03])
GAP = -0.03


def rel(A, B):
    return np.linalg.norm(A - B) / np.linalg.norm(B)


def asym(K):
    return np.linalg.norm(K - K.T) / np.linalg.norm(K)


def make_facet(nen, curved, seed):
    """A valid perturbed quad4/quad9 facet of size ~2, rotated and shifted; curved: a convex dome."""
    rng = np.random.default_rng(seed)
    P = NODES["quad4" if nen == 4 else "quad9"].astype(float)
    xyz = np.column_stack([P, np.zeros(nen)])
    xyz[:, :2] += 0.08 * rng.standard_normal((nen, 2))
    if curved:
        x, y = xyz[:, 0], xyz[:, 1]
        xyz[:, 2] = -(x**2 + 0.5 * y**2 + 0.3 * x * y) / 3.0 + 0.03 * rng.standard_normal(nen)
    return xyz @ rotation_matrix(rng.uniform(-1, 1, 3)).T + rng.uniform(-1, 1, 3)


def frame_at(xyz, xi):
    nen = xyz.shape[0]
    rho, rc, a, n = np.zeros(3), np.zeros((2, 3)), np.zeros((2, 2)), np.zeros(3)
    facet_geometry(xyz, xi[0], xi[1], np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2)), rho, rc, a,
                   np.empty((2, 2)), n, np.empty((2, 2)))
    return rho, rc, a, n


def facet_case(nen, curved, state, with_t, seed=3):
    xyz = make_facet(nen, curved, seed + nen + 10 * curved)
    hist = make_history(XI_N, T_OLD if with_t else (0.0, 0.0))
    rho, _, _, n = frame_at(xyz, XI_N + DXI)
    return xyz, rho + GAP * n, hist, MU[state]


def facet_eval(x, nen, xi0, hist, mu, lam_k=0.0):
    """Residual with re-projection for the dof vector x (master nodes first, slave last)."""
    xyz, xs, xi = x[:-3].reshape(nen, 3).copy(), x[-3:].copy(), xi0.copy()
    assert project_on_facet(xyz, xs, xi)[0] == 0
    m = 3 * (nen + 1)
    R, K, ho = np.zeros(m), np.zeros((m, m)), np.zeros(HIST_SIZE)
    g, state = friction_element(xyz, xs, xi, EPS_N, EPS_T, mu, hist, R, K, ho, lam_k)
    return R, K, state, xi, g


def fd_check(fun, x, h=1e-6):
    """Central-difference Jacobian of fun(x) -> (R, state); also returns the set of states met."""
    cols, states = [], set()
    for k in range(x.size):
        e = np.zeros(x.size)
        e[k] = h
        Rp, sp = fun(x + e)
        Rm, sm = fun(x - e)
        states |= {sp, sm}
        cols.append((Rp - Rm) / (2 * h))
    return np.array(cols).T, states


# ---------------------------------------------------------------------------------------- facets


@pytest.mark.parametrize("nen,curved", FACETS)
@pytest.mark.parametrize("state", [STICK, SLIP])
@pytest.mark.parametrize("with_t", [False, True])
def test_facet_tangent_matches_fd(nen, curved, state, with_t):
    xyz, xs, hist, mu = facet_case(nen, curved, state, with_t)
    r = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, mu, hist, xi0=XI_N)
    assert r.state == state and r.inside and r.gap == pytest.approx(GAP, rel=1e-9)
    x = np.concatenate([xyz.ravel(), xs])
    def fun(y):
        R, _, st, _, _ = facet_eval(y, nen, r.xi, hist, mu)
        return R, st

    Kfd, states = fd_check(fun, x)
    assert states == {state}
    assert rel(r.tangent, Kfd) < 1e-6
    if state == STICK and not with_t:
        assert asym(r.tangent) < 1e-12  # the Hessian of the stick energy
    if state == SLIP:
        assert asym(r.tangent) > 0.05  # normal-to-tangential coupling (measured ~0.27)
    np.testing.assert_allclose(r.parts["normal"] + r.parts["friction"], r.tangent, atol=1e-13)


@pytest.mark.parametrize("nen,curved", FACETS)
def test_stick_residual_is_gradient_of_stick_energy(nen, curved):
    xyz, xs, hist, mu = facet_case(nen, curved, STICK, False)
    r = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, mu, hist, xi0=XI_N)

    def energy(y):
        _, _, _, xi, g = facet_eval(y, nen, r.xi, hist, mu)
        a = frame_at(y[:-3].reshape(nen, 3), xi)[2]
        d = xi - XI_N
        return 0.5 * EPS_N * min(g, 0.0) ** 2 + 0.5 * EPS_T * d @ a @ d

    x = np.concatenate([xyz.ravel(), xs])
    grad, _ = fd_check(lambda y: (np.array([energy(y)]), 0), x)
    assert rel(r.residual, grad[0]) < 1e-7
    # the friction force on the slave opposes the slip: -R_T(slave) . (rho(xi) - rho(xi_n)) < 0
    R_t = r.residual - node_to_surface_friction(xyz, xs, EPS_N, EPS_T, 0.0, hist, xi0=XI_N).residual
    slip = frame_at(xyz, r.xi)[0] - frame_at(xyz, XI_N)[0]
    assert -R_t[-3:] @ slip < -0.9 * np.linalg.norm(R_t[-3:]) * np.linalg.norm(slip)
    assert np.abs(R_t.reshape(-1, 3).sum(axis=0)).max() < 1e-13  # action = reaction


@pytest.mark.parametrize("nen,curved", FACETS)
def test_slip_traction_on_the_cone(nen, curved):
    xyz, xs, hist, mu = facet_case(nen, curved, SLIP, True)
    r = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, mu, hist, xi0=XI_N)
    a = frame_at(xyz, r.xi)[2]
    norm = np.sqrt(r.traction @ np.linalg.solve(a, r.traction))
    assert norm == pytest.approx(mu * EPS_N * abs(r.gap), rel=1e-12)
    stick = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, 1e6, hist, xi0=XI_N)  # the trial traction
    assert stick.state == STICK
    cosine = r.traction @ np.linalg.solve(a, stick.traction)
    assert cosine == pytest.approx(np.linalg.norm(r.traction_vector) * np.linalg.norm(stick.traction_vector))


@pytest.mark.parametrize("nen", [4, 9])
@pytest.mark.parametrize("state", [STICK, SLIP])
def test_facet_objectivity(nen, state):
    xyz, xs, hist, mu = facet_case(nen, True, state, True)
    r1 = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, mu, hist, xi0=XI_N)
    Q = rotation_matrix([0.9, -1.3, 0.4])
    c = np.array([2.0, -1.0, 0.5])
    r2 = node_to_surface_friction(xyz @ Q.T + c, Q @ xs + c, EPS_N, EPS_T, mu, hist, xi0=XI_N)
    assert r2.state == state
    np.testing.assert_allclose(r2.traction, r1.traction, rtol=1e-10, atol=1e-12)
    QQ = np.kron(np.eye(nen + 1), Q)
    np.testing.assert_allclose(r2.residual, QQ @ r1.residual, atol=1e-11)
    np.testing.assert_allclose(r2.tangent, QQ @ r1.tangent @ QQ.T, atol=1e-10 * np.abs(r1.tangent).max())
    # zero relative slip: the transported traction is the old one (same magnitude)
    rho, _, _, n = frame_at(xyz @ Q.T + c, XI_N)
    r3 = node_to_surface_friction(xyz @ Q.T + c, rho + GAP * n, EPS_N, EPS_T, 5.0, hist, xi0=XI_N)
    assert r3.state == STICK
    np.testing.assert_allclose(r3.traction, T_OLD, rtol=1e-10)


@pytest.mark.parametrize("nen,curved", FACETS)
def test_mu_zero_and_no_history_are_frictionless(nen, curved):
    xyz, xs, hist, _ = facet_case(nen, curved, SLIP, True)
    xi = XI_N + DXI
    r0 = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, 0.0, hist, xi0=xi)
    rn = node_to_surface_friction(xyz, xs, EPS_N, EPS_T, 0.4, None, xi0=xi)
    m = 3 * (nen + 1)
    RN, KN = np.zeros(m), np.zeros((m, m))
    assert np.array_equal(r0.xi, rn.xi)
    contact_element(xyz, xs, r0.xi, EPS_N, CASES["exact"], False, RN, KN, np.zeros((1, 1, 1)))
    assert r0.state == SLIP and rn.state == NEW
    for r in (r0, rn):
        np.testing.assert_array_equal(r.residual, RN)
        np.testing.assert_array_equal(r.tangent, KN)
        assert not np.any(r.traction)
        assert r.history[-1] == 1.0 and np.allclose(r.history[:2], r.xi)


def test_open_gives_zeros_and_a_fresh_history():
    xyz = make_facet(9, True, 7)
    rho, _, _, n = frame_at(xyz, XI_N)
    r = node_to_surface_friction(xyz, rho + 0.02 * n, EPS_N, EPS_T, 0.3, make_history(XI_N, T_OLD))
    assert r.state == OPEN and not np.any(r.residual) and not np.any(r.tangent)
    assert not np.any(r.history[11:13]) and r.history[13] == 1.0
    np.testing.assert_allclose(r.history[2:5], rho, atol=1e-12)


def test_sliding_sequence_sticks_then_slides():
    # drag a slave node along a flat facet at constant depth, committing the history each step:
    # it sticks until ||T|| reaches mu eps_N |g|, then slides with the traction opposing the motion
    xyz = make_facet(4, False, 11)
    _, rc, _, n = frame_at(xyz, np.zeros(2))
    e = rc[0] / np.linalg.norm(rc[0])
    x0 = frame_at(xyz, np.array([-0.5, 0.0]))[0] + GAP * n
    hist, states, mu = None, [], 1.0
    for k in range(10):
        r = node_to_surface_friction(xyz, x0 + 0.005 * k * e, EPS_N, EPS_T, mu, hist)
        hist = r.history
        states.append(r.state)
    assert states[0] == NEW and states[1] == STICK and states[-1] == SLIP
    assert states[1:].index(SLIP) > 1 and all(s == SLIP for s in states[1 + states[1:].index(SLIP):])
    t = r.traction_vector
    assert np.linalg.norm(t) == pytest.approx(mu * EPS_N * abs(GAP), rel=1e-9)
    assert t @ e == pytest.approx(-np.linalg.norm(t), rel=1e-9)


def test_transfer_history_keeps_the_traction_vector():
    # two quad9 facets of one curved strip sharing the edge x = 1 (VTK order, outward normal +z)
    P = NODES["quad9"].astype(float)

    def lift(p):
        return np.column_stack([p, -(p[:, 0] ** 2 + 0.3 * p[:, 1] ** 2) / 8.0])

    A, B = lift(P), lift(P + [2.0, 0.0])
    xi_n = np.array([0.9, 0.2])
    rho, rc, _, _ = frame_at(A, xi_n)
    h = make_history(xi_n, T_OLD, rho, rc)
    h2 = transfer_history(h, B, xi0=[-1.0, 0.0])
    assert h2[0] == pytest.approx(-1.1, abs=0.02) and h2[1] == pytest.approx(0.2, abs=1e-9)
    np.testing.assert_allclose(h2[2:5], rho, atol=1e-3)
    t_old = np.linalg.solve(rc @ rc.T, T_OLD) @ rc
    rc2 = h2[5:11].reshape(2, 3)
    t_new = np.linalg.solve(rc2 @ rc2.T, h2[11:13]) @ rc2
    np.testing.assert_allclose(t_new, t_old, atol=2e-3 * np.linalg.norm(t_old))
    assert transfer_history(np.zeros(HIST_SIZE), B)[-1] == 0.0


def test_input_validation():
    xyz = make_facet(4, False, 1)
    with pytest.raises(ValueError, match="eps_t"):
        node_to_surface_friction(xyz, np.zeros(3), 1.0, 0.0, 0.3)
    with pytest.raises(ValueError, match="mu"):
        node_to_surface_friction(xyz, np.zeros(3), 1.0, 1.0, -0.1)
    with pytest.raises(ValueError, match="history"):
        node_to_surface_friction(xyz, np.zeros(3), 1.0, 1.0, 0.3, history=np.zeros(13))
    with pytest.raises(ValueError, match="eps_n"):
        surface_friction(Plane(), np.zeros(3), -1.0, 1.0, 0.3)


@pytest.mark.parametrize("nen", [4, 9])
def test_friction_batch_matches_single_element(nen):
    rng = np.random.default_rng(nen)
    xyz = make_facet(nen, True, 100 + nen)
    npair = 37  # not a multiple of the chunk size
    xi_n = rng.uniform(-0.8, 0.8, (npair, 2))
    xs, hist, xi = [], np.zeros((npair, HIST_SIZE)), np.zeros((npair, 2))
    for k in range(npair):
        rho, _, _, n = frame_at(xyz, xi_n[k] + rng.uniform(-0.03, 0.03, 2))
        xs.append(rho + rng.uniform(-0.08, 0.01) * n)
        hist[k] = make_history(xi_n[k], rng.uniform(-0.3, 0.3, 2)) if k % 5 else np.zeros(HIST_SIZE)
    X = np.vstack([xyz, xs])
    conn = np.tile(np.arange(nen, dtype=np.int64), (npair, 1))
    sid = np.arange(nen, nen + npair, dtype=np.int64)
    eps_n, eps_t, mu = rng.uniform(1, 5, npair), rng.uniform(1, 5, npair), rng.uniform(0, 3, npair)
    singles = [
        node_to_surface_friction(xyz, xs[k], eps_n[k], eps_t[k], mu[k], hist[k], xi_n[k])
        for k in range(npair)
    ]
    for k in range(npair):
        xi[k] = singles[k].xi
    m = 3 * (nen + 1)
    R, K, H = np.zeros((npair, m)), np.zeros((npair, m, m)), np.zeros((npair, HIST_SIZE))
    g, st = np.zeros(npair), np.zeros(npair, dtype=np.int64)
    friction_batch(X, conn, sid, xi, eps_n, eps_t, mu, hist, R, K, H, g, st, np.zeros(npair))
    for k, s in enumerate(singles):
        assert st[k] == s.state and g[k] == pytest.approx(s.gap, abs=1e-14)
        np.testing.assert_allclose(R[k], s.residual, atol=1e-13)
        np.testing.assert_allclose(K[k], s.tangent, atol=1e-12)
        np.testing.assert_allclose(H[k], s.history, atol=1e-14)
    assert {OPEN, STICK, SLIP, NEW} <= set(st.tolist())


# ------------------------------------------------------------------------------ analytic surfaces

MOTION = RigidMotion(translation=(0.1, 0.2, -0.3), rotation=(0.2, -0.4, 0.3), center=(1.0, 0.0, 0.0))
LAM = 0.7


def surfaces(motion=MOTION):
    return {
        "plane": Plane((0.1, 0.2, 0.3), (1.0, 2.0, 3.0), motion),
        "cyl_out": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, True, motion),
        "cyl_in": Cylinder((0.0, 0.5, 0.0), (1.0, 1.0, 0.3), 2.0, False, motion),
        "sph_out": Sphere((0.3, 0.0, 0.0), 1.5, True, motion),
        "sph_in": Sphere((0.3, 0.0, 0.0), 1.5, False, motion),
        **profiles(motion),
    }


NAMES = list(surfaces())
POINT = np.array([0.7, -0.4, 0.9])


def surface_case(surf, with_t, lam=LAM):
    """History committed at depth GAP below POINT's projection, and a slave moved tangentially."""
    pr = surf.project(POINT, lam)
    xs0 = pr.rho + GAP * pr.normal
    hist = surface_friction(surf, xs0, EPS_N, EPS_T, 1.0, None, lam).history
    if with_t:
        hist[11:13] = T_OLD
    t1, t2 = (v / np.linalg.norm(v) for v in pr.rho_cov)
    return xs0, xs0 + 0.04 * t1 + 0.03 * t2, hist


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("state", [STICK, SLIP])
@pytest.mark.parametrize("with_t", [False, True])
def test_surface_tangent_matches_fd(name, state, with_t):
    surf = surfaces()[name]
    _, xs, hist = surface_case(surf, with_t)
    mu = MU[state]
    r = surface_friction(surf, xs, EPS_N, EPS_T, mu, hist, LAM)
    assert r.state == state and r.gap < 0

    def fun(y):
        s = surface_friction(surf, y, EPS_N, EPS_T, mu, hist, LAM)
        return s.residual, s.state

    Kfd, states = fd_check(fun, xs)
    assert states == {state}
    assert rel(r.tangent, Kfd) < 1e-6
    if state == STICK and not with_t:
        assert asym(r.tangent) < 1e-12
    if state == SLIP:
        assert asym(r.tangent) > 0.05
        a = r.history[5:11].reshape(2, 3) @ r.history[5:11].reshape(2, 3).T  # body-frame metric = current
        assert np.sqrt(r.traction @ np.linalg.solve(a, r.traction)) == pytest.approx(
            mu * EPS_N * abs(r.gap), rel=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_surface_stick_energy_and_mu_zero(name):
    surf = surfaces()[name]
    _, xs, hist = surface_case(surf, False)
    r = surface_friction(surf, xs, EPS_N, EPS_T, MU[STICK], hist, LAM)

    def energy(y):
        pr = surf.project(y, LAM)
        d = pr.xi - hist[:2]
        return np.array([0.5 * EPS_N * min(pr.gap, 0.0) ** 2 + 0.5 * EPS_T * d @ pr.a_cov @ d]), 0

    grad, _ = fd_check(energy, xs)
    assert rel(r.residual, grad[0]) < 1e-7
    r0 = surface_friction(surf, xs, EPS_N, EPS_T, 0.0, hist, LAM)
    ref = surf.contact(xs, EPS_N, "exact", LAM)
    np.testing.assert_array_equal(r0.residual, ref.residual)
    np.testing.assert_array_equal(r0.tangent, ref.tangent)


@pytest.mark.parametrize("name", NAMES)
def test_surface_objectivity(name):
    # history and slave at lam = 0, then the surface and the slave moved together by a rigid motion
    motion = RigidMotion(translation=(0.4, -0.2, 0.3), rotation=(0.5, -0.7, 0.4), center=(0.2, 0.1, 0.0))
    surf = surfaces(motion)[name]
    xs0, xs, hist = surface_case(surf, True, lam=0.0)
    Q = motion.matrix(1.0)
    for mu, y in ((MU[SLIP], xs), (MU[STICK], xs), (MU[STICK], xs0)):
        r1 = surface_friction(surf, y, EPS_N, EPS_T, mu, hist, 0.0)
        r2 = surface_friction(surf, motion.apply(y, 1.0), EPS_N, EPS_T, mu, hist, 1.0)
        assert r1.state == r2.state
        np.testing.assert_allclose(r2.traction, r1.traction, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(r2.residual, Q @ r1.residual, atol=1e-12)
        np.testing.assert_allclose(r2.tangent, Q @ r1.tangent @ Q.T, atol=1e-10 * np.abs(r1.tangent).max())
    np.testing.assert_allclose(r2.traction, T_OLD, rtol=1e-10)  # zero slip: the old traction


def test_analytic_batch_matches_single():
    rng = np.random.default_rng(5)
    for surf in surfaces().values():
        ns = 21
        xs, hist = np.zeros((ns, 3)), np.zeros((ns, HIST_SIZE))
        for k in range(ns):
            pr = surf.project(POINT + rng.uniform(-0.3, 0.3, 3), LAM)
            hist[k] = surface_friction(surf, pr.rho - 0.01 * pr.normal, EPS_N, EPS_T, 1.0, None, LAM).history
            hist[k, 11:13] = rng.uniform(-0.1, 0.1, 2) if k % 4 else 0.0
            hist[k, 13] = 1.0 if k % 7 else 0.0
            xs[k] = pr.rho + rng.uniform(-0.1, 0.02) * pr.normal + rng.uniform(-0.05, 0.05, 3)
        eps_n, eps_t, mu = rng.uniform(1, 5, ns), rng.uniform(1, 5, ns), rng.uniform(0, 3, ns)
        origin, frame = surf.placement(LAM)
        R, K, H = np.zeros((ns, 3)), np.zeros((ns, 3, 3)), np.zeros((ns, HIST_SIZE))
        g, xi, st = np.zeros(ns), np.zeros((ns, 2)), np.zeros(ns, dtype=np.int64)
        analytic_friction_batch(surf.kind, origin, frame, float(surf.radius), float(surf.sigma), surf.prof, xs, eps_n,
                                eps_t, mu, hist, R, K, H, g, xi, st, np.zeros(ns))
        for k in range(ns):
            s = surface_friction(surf, xs[k], eps_n[k], eps_t[k], mu[k], hist[k], LAM)
            assert st[k] == s.state and g[k] == s.gap
            np.testing.assert_array_equal(R[k], s.residual)
            np.testing.assert_array_equal(K[k], s.tangent)
            np.testing.assert_array_equal(H[k], s.history)
        assert {STICK, SLIP} <= set(st.tolist())


# ------------------------------------------------------------------ augmented Lagrangian multiplier


@pytest.mark.parametrize("nen,curved", FACETS)
@pytest.mark.parametrize("state", [STICK, SLIP])
def test_facet_tangent_with_multiplier_matches_fd(nen, curved, state):
    """Friction under the augmented normal law: the normal pressure and the Coulomb limit are
    mu |lam_k + eps_N g|, lam_k fixed during Newton; the tangent stays exact."""
    xyz, xs, hist, mu = facet_case(nen, curved, state, True)
    lam_k = -0.5 * EPS_N * abs(GAP)
    x = np.concatenate([xyz.ravel(), xs])
    R, K, st, xi, g = facet_eval(x, nen, XI_N, hist, mu, lam_k)
    R0, _, _, _, _ = facet_eval(x, nen, XI_N, hist, mu, 0.0)
    assert st == state and g == pytest.approx(GAP, rel=1e-9)
    assert np.abs(R - R0).max() > 1e-3 * np.abs(R0).max()  # the multiplier acts

    def fun(y):
        Ry, _, sy, _, _ = facet_eval(y, nen, xi, hist, mu, lam_k)
        return Ry, sy

    Kfd, states = fd_check(fun, x)
    assert states == {state}
    assert rel(K, Kfd) < 1e-6


def analytic_eval(surf, y, mu, hist, lam_k):
    origin, frame = surf.placement(LAM)
    R, K, H = np.zeros((1, 3)), np.zeros((1, 3, 3)), np.zeros((1, HIST_SIZE))
    g, xi, st = np.zeros(1), np.zeros((1, 2)), np.zeros(1, dtype=np.int64)
    analytic_friction_batch(surf.kind, origin, frame, float(surf.radius), float(surf.sigma), surf.prof, y[None, :],
                            np.array([EPS_N]), np.array([EPS_T]), np.array([mu]), hist[None, :], R, K, H, g,
                            xi, st, np.array([lam_k]))
    return R[0], K[0], int(st[0]), float(g[0])


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("state", [STICK, SLIP])
def test_surface_tangent_with_multiplier_matches_fd(name, state):
    surf = surfaces()[name]
    _, xs, hist = surface_case(surf, True)
    mu = MU[state]
    lam_k = -0.02 * EPS_N
    R, K, st, g = analytic_eval(surf, xs, mu, hist, lam_k)
    assert st == state and g < 0
    R0 = analytic_eval(surf, xs, mu, hist, 0.0)[0]
    assert np.abs(R - R0).max() > 1e-3 * np.abs(R0).max()

    def fun(y):
        Ry, _, sy, _ = analytic_eval(surf, y, mu, hist, lam_k)
        return Ry, sy

    Kfd, states = fd_check(fun, xs)
    assert states == {state}
    assert rel(K, Kfd) < 1e-6
