"""Covariant Coulomb friction in the plane against the edges of planar bodies (covcontact.contact.planar_friction;
docs/theory.md section 28, "Friction").

The kernel's exact (non-symmetric) tangent against central differences of its residual (projection redone at every
perturbed point, the committed history held) in stick and in slip on linear, straight quadratic and curved quadratic
segments; the return mapping (|T| / sqrt(a) = mu p in slip); the history moved across segments; problems: a block
sliding on a planar body's edge (mu N in slip, stick below it) and a belt over a deformable pulley against
Euler-Eytelwein.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from covcontact.contact.friction_kernels import H_FLAG, H_T, H_XI
from covcontact.contact.planar import project_on_segment, segment_point, vertex_core
from covcontact.contact.planar_friction import (
    OPEN,
    SLIP,
    STICK,
    make_history,
    segment_friction,
    start_history,
    transfer_history,
    vertex_friction,
    vertex_history,
)
from covcontact.io.loader import load_problem

EPS, EPS_T, MU = 1.0e3, 1.0e3, 0.3
H = 1e-6


def rel(A, B):
    return float(np.linalg.norm(A - B) / np.linalg.norm(B))


def segment(nen: int, curved: bool) -> np.ndarray:
    x = np.array([[-0.4, 0.1, 0.0], [0.7, 0.3, 0.0], [0.15, 0.2 + (0.12 if curved else 0.0), 0.0]])
    return x[:nen].copy()


def slave_at(xseg, xi, g):
    x, r, _ = segment_point(xseg, xi)
    n = np.array([r[1], -r[0]]) / np.linalg.norm(r)
    return np.array([*(x + g * n), 0.0])


def evaluate(xseg, xs, hist, mu=MU, lam=0.0):
    xseg, xs = np.ascontiguousarray(xseg), np.ascontiguousarray(xs)
    xi, _, ok = project_on_segment(xseg, xs, 0.0)
    assert ok
    return segment_friction(xseg, xs, xi, EPS, EPS_T, mu, hist, lam) + (xi,)


def split(y, nen):
    return y[:-3].reshape(nen, 3), y[-3:]


def fd_jacobian(fun, x):
    cols = []
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += H
        xm[k] -= H
        cols.append((np.asarray(fun(xp)) - np.asarray(fun(xm))) / (2 * H))
    return np.array(cols).T


SEGMENTS = [(2, False), (3, False), (3, True)]


@pytest.mark.parametrize("nen,curved", SEGMENTS)
@pytest.mark.parametrize("dxi,T_n,state", [(0.01, 0.0, STICK), (-0.004, 1.5, STICK), (0.12, 0.0, SLIP),
                                            (-0.1, 2.0, SLIP), (0.2, -3.0, SLIP)])
@pytest.mark.parametrize("lam", [0.0, -20.0])
def test_friction_tangent_against_central_differences(nen, curved, dxi, T_n, state, lam):
    xseg = segment(nen, curved)
    xi0 = 0.31
    xs = slave_at(xseg, xi0, -0.05)
    hist = make_history(xi0 - dxi, T_n)
    R, K, ho, g, st, xi = evaluate(xseg, xs, hist, lam=lam)
    assert st == state
    x = np.concatenate([xseg.ravel(), xs])
    Kfd = fd_jacobian(lambda y: evaluate(*split(y, nen), hist, lam=lam)[0], x)
    assert rel(K, Kfd) < 1e-6
    assert np.all(K[2::3] == 0.0) and np.all(K[:, 2::3] == 0.0) and np.all(R[2::3] == 0.0)
    # the return mapping: |T| / sqrt(a) = mu p in slip, the trial traction in stick
    _, r, _ = segment_point(xseg, xi)
    a = float(r @ r)
    p = -(lam + EPS * g)
    T = ho[H_T]
    if st == SLIP:
        assert abs(T) / math.sqrt(a) == pytest.approx(MU * p, rel=1e-12)
        assert np.abs(K - K.T).max() > 1e-6 * np.abs(K).max()  # slip: non-symmetric
    else:
        assert abs(T) / math.sqrt(a) < MU * p
    assert ho[H_XI] == xi and ho[H_FLAG] == 1.0
    # the force on the slave balances the master's; its tangential part is -(T / a) rho to leading order
    f = R.reshape(-1, 3)
    assert np.abs(f.sum(axis=0)).max() < 1e-9 * np.abs(f).max()


def test_stick_without_old_traction_is_symmetric():
    """In stick with T_n = 0 the friction is the gradient of eps_T a dxi^2 / 2: the tangent is symmetric."""
    for nen, curved in SEGMENTS:
        xseg = segment(nen, curved)
        xs = slave_at(xseg, 0.2, -0.03)
        R, K, ho, g, st, xi = evaluate(xseg, xs, make_history(0.19))
        assert st == STICK
        assert np.abs(K - K.T).max() < 1e-10 * np.abs(K).max()


def test_frictionless_open_and_new():
    xseg = segment(3, True)
    xs = slave_at(xseg, 0.2, 0.01)
    assert evaluate(xseg, xs, make_history(0.1))[4] == OPEN
    xs = slave_at(xseg, 0.2, -0.01)
    R0, K0, *_ = evaluate(xseg, xs, make_history(0.1), mu=0.0)
    Rn, Kn, _, _, st, _ = evaluate(xseg, xs, np.zeros(14))
    assert st == 3 and np.array_equal(R0, Rn) and np.array_equal(K0, Kn)


def test_history_across_segments():
    """Two collinear linear segments: a stick point on the first moved onto the second lands on its continuation
    (xi < -1) with the same traction vector, so the slave's trial traction is the same on either side of the shared
    node; far beyond the continuation's band the anchor is the second segment's end, the stretch in the traction."""
    s1 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    s2 = np.array([[1.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    x1, r1 = np.array([0.9, 0.0, 0.0]), np.array([0.5, 0.0, 0.0])
    h1 = make_history(0.8, 0.5 * 2.0, x1, r1)  # traction vector t = T rho / a = (2, 0)
    h2 = transfer_history(h1, s2, 0.0, EPS_T)
    assert h2[H_XI] == pytest.approx(-1.1, abs=1e-12)
    assert h2[H_T] / 1.0 == pytest.approx(2.0, rel=1e-12)  # rho = (1, 0) on s2
    xs = np.array([1.02, -0.01, 0.0])
    Ra = evaluate(s1, xs, h1)
    Rb = evaluate(s2, xs, h2)
    np.testing.assert_allclose(Ra[0][-3:], Rb[0][-3:], rtol=1e-10)
    # an old point far from the new segment: anchored at its end with the stretch
    h1 = make_history(-1.0, 0.0, np.array([-2.0, 0.0, 0.0]), r1)
    h3 = transfer_history(h1, s2, 0.0, EPS_T)
    assert h3[H_XI] == -1.0 and h3[H_T] == pytest.approx(-EPS_T * 3.0 * 1.0)
    # a new slave sticks at its projection
    h = start_history(s2, np.array([2.0, -0.01, 0.0]), 0.0, EPS_T)
    assert h[H_XI] == pytest.approx(0.0, abs=1e-14) and h[H_T] == 0.0 and h[H_FLAG] == 1.0


def vertex_residual(y, du0, t_n, sign, lam=0.0):
    """Normal and friction residual of a slave at a vertex; y = (x_v, x_s) (6,), the displacement since the commit
    du0 + (x_s - x_v) - (x_s0 - x_v0) follows the positions."""
    xv, xs = y[:3], y[3:]
    R = np.zeros(6)
    K = np.zeros((6, 6))
    vertex_core(xv, xs, sign, EPS, lam, R, K)
    Rf, Kf, T, _, st = vertex_friction(xv, xs, du0 + (xs - xv), t_n, sign, EPS, EPS_T, MU, lam)
    return R + Rf, K + Kf, T, st


@pytest.mark.parametrize("du,t_n,state", [((1e-5, 0.0), (0.0, 0.0), STICK), ((-2e-5, 1e-5), (0.004, -0.002), STICK),
                                          ((3e-3, 0.0), (0.0, 0.0), SLIP), ((-6e-3, 0.0), (0.05, 0.01), SLIP)])
@pytest.mark.parametrize("sign", [-1.0, 1.0])
def test_vertex_friction_tangent_against_central_differences(du, t_n, state, sign):
    """Friction at a vertex (a slave in the region of a convex corner, normal along x_s - x_v): the exact tangent
    against central differences, the return mapping (|T| = mu N in slip), the forces balanced."""
    xv = np.array([0.3, -0.2, 0.0])
    d = np.array([0.004, 0.007, 0.0])
    xs = xv + (d if sign > 0 else -d)
    lam = 0.0 if sign < 0 else -EPS * 0.016      # (g = |d| > 0: the multiplier makes it active)
    y = np.concatenate([xv, xs])
    du0 = np.array([*du, 0.0]) - (xs - xv)
    tn = np.array([*t_n, 0.0])
    R, K, T, st = vertex_residual(y, du0, tn, sign, lam)
    assert st == state
    Kfd = fd_jacobian(lambda z: vertex_residual(z, du0, tn, sign, lam)[0], y)
    assert rel(K, Kfd) < 1e-6
    N = -(lam + EPS * sign * np.linalg.norm(d))
    assert N > 0.0
    if st == SLIP:
        assert abs(T) == pytest.approx(MU * N, rel=1e-12)
    else:
        assert abs(T) < MU * N
    assert np.abs(R[:3] + R[3:]).max() < 1e-12 * np.abs(R).max()
    # the friction force is tangential (normal to x_s - x_v) and opposes the relative displacement in slip
    Rf = vertex_friction(xv, xs, du0 + (xs - xv), tn, sign, EPS, EPS_T, MU, lam)[0]
    assert abs(Rf[3:5] @ d[:2]) < 1e-12 * np.linalg.norm(Rf) * np.linalg.norm(d)
    if st == SLIP and not any(t_n):
        assert float(-Rf[3:5] @ np.array(du)) < 0.0


def test_vertex_history_moves_on_to_either_segment():
    """The history of a slave at a vertex holds its traction vector's component along the segment: moved on to the
    next segment (across the corner) it carries the same traction vector up to the corner's turn."""
    s1 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    s2 = np.array([[1.0, 0.0, 0.0], [2.0, -0.1, 0.0]])
    t_vec = np.array([0.3, 0.0, 0.0])
    h = vertex_history(s1, 1.0, t_vec)
    assert h[H_XI] == 1.0 and h[H_FLAG] == 1.0 and h[H_T] == pytest.approx(0.3 * 0.5)
    h2 = transfer_history(h, s2, 0.0, EPS_T)
    assert h2[H_XI] == pytest.approx(-1.0, abs=1e-12)
    r2 = (s2[1] - s2[0]) / 2.0
    assert h2[H_T] == pytest.approx(float(t_vec @ r2), rel=1e-12)


# -- problems ------------------------------------------------------------------------------------------------------
def run(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    res = load_problem(path).run(out=tmp_path / name)
    assert res.exit_code == 0
    return res


def block_text(cell: str, load: str) -> str:
    return f"""
[problem]
name = "slide"
[[bodies]]
name = "low"
formulation = "plane_strain"
element = "{cell}"
mesh = {{ generator = "rectangle", lx = 2.0, ly = 0.5, nx = 8, ny = 2, origin = [0.0, 0.0] }}
material = {{ model = "neo-hooke", E = 1000.0, nu = 0.3 }}
[[bodies]]
name = "up"
formulation = "plane_strain"
element = "{cell}"
mesh = {{ generator = "rectangle", lx = 0.5, ly = 0.25, nx = 3, ny = 2, origin = [0.75, 0.5] }}
material = {{ model = "neo-hooke", E = 1000.0, nu = 0.3 }}
[[dirichlet]]
set = "low.ymin"
components = "xy"
value = 0.0
[[pressure]]
set = "up.ymax"
value = 1.0
[[contact]]
name = "c"
slave = "up.ymin"
master = "low.ymax"
penalty = 1e5
weighting = "area"
friction = {MU}
[steps]
factors = [0.25, 0.5, 0.75, 1.0]
""" + load


SLIDE = """
[[dirichlet]]
set = "up.ymax"
components = "x"
value = 0.02
"""


def push(F: float) -> str:
    return f"""
[[traction]]
set = "up.xmin"
value = [{F / 0.25}, 0.0, 0.0]
"""


def local_forces(res):
    """Per active slave of the run's first pass: (normal, tangential) components of its contact force in the frame of
    its master segment at its contact point (current configuration), and the friction states."""
    st, p = res.state.contact.passes[0], res.model.contact.passes[0]
    x = res.model.system.X + np.asarray(res.u).reshape(-1, 3)
    on = np.flatnonzero(np.isfinite(st.gap) & (np.abs(st.force).sum(axis=1) > 0))
    fn, ft = [], []
    for s in on:
        _, r, _ = segment_point(np.ascontiguousarray(x[p.curve.segments[st.facet[s]]]), float(st.xi[s, 0]))
        t = r / np.linalg.norm(r)
        fn.append(st.force[s, 0] * t[1] - st.force[s, 1] * t[0])
        ft.append(st.force[s, :2] @ t)
    # the slip: the reference distance between a slave and the master's material point under it
    X = res.model.system.X
    slip = [abs(segment_point(np.ascontiguousarray(X[p.curve.segments[st.facet[s]]]), float(st.xi[s, 0]))[0][0]
                - X[p.slaves[s], 0]) for s in on]
    return np.array(fn), np.array(ft), st.status[on], st.force[on], np.array(slip)


@pytest.mark.parametrize("cell", ["quad4", "quad8"])
def test_block_sliding_on_an_edge(tmp_path, cell):
    """A block (0.5 x 0.25, plane strain) pressed onto a planar body's edge by a pressure (N = 0.5 per unit
    thickness) and dragged along it by its top (0.02, far beyond the stick limit): every slave slips, its tangential
    force mu times its normal force in the frame of its master segment (to round-off on linear segments, 2e-7 on
    quadratic ones: the residual's O(g) terms, where a varies along the segment), the block's friction force
    mu N to the tilt of the deformed master's segments (3e-4); pushed sideways by a traction F = 0.05 < mu N = 0.15
    instead, the block rests (its slaves stick but those at its ends, where the pressure
    falls off) and the friction force is F (non-matching edges: 3 cells on 8). ``force``: the
    contact force on the slave."""
    res = run(tmp_path, f"slide_{cell}", block_text(cell, SLIDE))
    fn, ft, status, f, slip = local_forces(res)
    N, Ft = f[:, 1].sum(), f[:, 0].sum()
    assert slip.min() > 0.9 * 0.02
    print(f"slide {cell}: N = {N:.6f}, Ft / (mu N) = {Ft / (MU * N):.8f}, states {np.bincount(status)}, "
          f"local |ft| / (mu fn) - 1 <= {np.abs(np.abs(ft) / (MU * fn) - 1).max():.1e}")
    assert N == pytest.approx(0.5, rel=1e-3)
    assert np.all(status == SLIP)
    np.testing.assert_allclose(np.abs(ft), MU * fn, rtol=1e-9 if cell == "quad4" else 1e-6)
    assert np.all(np.sign(ft) == np.sign(ft[0]))
    assert -Ft == pytest.approx(MU * N, rel=1e-3)  # against the block's motion (+x)
    res = run(tmp_path, f"stick_{cell}", block_text(cell, push(0.05)))
    fn, ft, status, f, slip = local_forces(res)
    N, Ft = f[:, 1].sum(), f[:, 0].sum()
    print(f"stick {cell}: N = {N:.6f}, Ft = {Ft:.8f}, states {np.bincount(status)}, "
          f"|ft| / (mu fn) {np.round(np.abs(ft / (MU * fn)), 3)}, "
          f"slip {slip.max():.1e}")
    # the slaves inside the contact stick; the outer ones, where the pressure falls off, may slip a little: the block
    # rests (the lateral expansions of the two bodies differ)
    assert np.all(status[1:-1] == STICK) and np.all(np.abs(ft[1:-1]) < MU * fn[1:-1])
    assert slip[1:-1].max() < 1e-3 * 0.02 and slip.max() < 5e-3 * 0.02
    assert -Ft == pytest.approx(0.05, rel=1e-6)
    assert N == pytest.approx(0.5, rel=1e-3)


def capstan_text(nt_belt, nt_pulley, mu=0.3, t=0.01, d=1e-4, penalty=1e7, steps=4, cell="quad8", two_pass=False):
    """A belt (plane stress, E = 1e8, nu = 0, thickness t = R / 100, one quadratic cell through it) lying on a deformable
    half-disc pulley (a half annulus r 0.5 .. 1 held at its bore), wrapped over theta = pi; its end at angle 0 hangs a
    dead load T1 = 1 (-y), its end at pi is pulled down by d = 1e-4 (about ten times the belt's elastic elongation),
    both ramped together: every slave slides from the first step."""
    f = ", ".join(str((k + 1) / steps) for k in range(steps))
    return f"""
[problem]
name = "capstan2d"
[[bodies]]
name = "pulley"
formulation = "plane_stress"
element = "{cell}"
mesh = {{ generator = "annulus", r_inner = 0.5, r_outer = 1.0, nr = 2, nt = {nt_pulley}, angle = 180.0 }}
material = {{ model = "svk", E = 1e8, nu = 0.3 }}
[[bodies]]
name = "belt"
formulation = "plane_stress"
element = "{cell}"
mesh = {{ generator = "annulus", r_inner = 1.0, r_outer = {1.0 + t}, nr = 1, nt = {nt_belt}, angle = 180.0 }}
material = {{ model = "svk", E = 1e8, nu = 0.0 }}
[[dirichlet]]
set = "pulley.inner"
components = "xy"
value = 0.0
[[dirichlet]]
name = "pull"
set = "belt.angle1"
components = "y"
value = {-d}
[[force]]
set = "belt.angle0"
value = [0.0, -1.0, 0.0]
distribution = "total"
[[contact]]
name = "belt"
slave = "belt.inner"
master = "pulley.outer"
penalty = {penalty}
weighting = "area"
friction = {mu}
two_pass = {str(two_pass).lower()}
[steps]
factors = [{f}]
[output]
vtu = false
"""



@pytest.mark.parametrize("nt_belt,nt_pulley", [(30, 20), (60, 40)])
def test_capstan_belt_over_a_pulley(tmp_path, nt_belt, nt_pulley):
    """Euler-Eytelwein: T2 / T1 = exp(mu theta) = 2.566 (mu = 0.3, theta = pi) for a belt sliding over a deformable
    pulley section (quad8 belt and pulley, non-matching edges). T2: the reaction of the pulled end. Measured 2.5695
    (+0.12 %; 43 of the 61 slaves in contact) at 30 / 20 cells, 2.5670 (+0.025 %; 118 of 121) at 60 / 40; within
    0.16 % of that in every step (sliding throughout)."""
    res = run(tmp_path, f"capstan_{nt_belt}", capstan_text(nt_belt, nt_pulley))
    exact = math.exp(MU * math.pi)
    for s in res.summary["steps"]:
        ratio = -s["reactions"]["belt.angle1"][1] / s["load_factor"]
        pair = s["pairs"]["belt"]
        print(f"capstan {nt_belt} / {nt_pulley} step {s['step']}: T2 / T1 = {ratio:.5f} "
              f"({ratio / exact - 1:+.2e}), slip {pair.get('slip')} of {pair['active_contacts']}")
        assert abs(ratio / exact - 1) < 5e-3
        assert pair.get("stick", 0) == 0


def test_capstan_on_a_polygon_with_two_passes(tmp_path):
    """quad4 belt and pulley (linear segments, the pulley a 40-gon), 97 belt cells so that no belt node starts on a
    corner, both passes: T2 / T1 within 1 % of exp(mu pi) (measured +0.80 %); one pass lets the pulley's corners
    through the belt's chords (docs/verification.md, "Contact in the plane")."""
    res = run(tmp_path, "capstan_q4", capstan_text(97, 40, cell="quad4", two_pass=True))
    s = res.summary["steps"][-1]
    ratio = -s["reactions"]["belt.angle1"][1] / s["load_factor"]
    assert abs(ratio / math.exp(MU * math.pi) - 1) < 1e-2
