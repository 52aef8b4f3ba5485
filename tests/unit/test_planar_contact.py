"""Covariant node-to-segment contact in the plane (covcontact.contact.planar; docs/theory.md section 28).

Kernels: the exact tangent against central differences of the residual (projection redone at every perturbed
point) on linear and quadratic segments and on a rigid circle, each tangent part against central differences of
the quantity it linearises (main: grad g; rotational: the normal at fixed xi; curvature: n,xi), a slave behind a
valley vertex; the consistent weights (thickness, 2 pi R); the contact patch test (plane strain and axisymmetric,
uniform pressure through a flat interface); Hertz line contact and a shrink fit against Lame.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from covcontact.contact import CASES, Cylinder, Plane, RigidMotion
from covcontact.contact.planar import (
    FACET,
    VERTEX,
    Curve,
    closest_points,
    project_on_segment,
    segment_core,
    segment_point,
    slave_weights,
    vertex_core,
)
from covcontact.io.loader import load_problem

from planar_blocks import two_blocks

EPS = 1.0e3
H = 1e-6


def rel(A, B):
    return float(np.linalg.norm(A - B) / np.linalg.norm(B))


def segment(nen: int, curved: bool) -> np.ndarray:
    """A master segment in the x-y plane (z = 0): 2 nodes, or 3 (corners, then the mid-node, off the chord when
    curved)."""
    x = np.array([[-0.4, 0.1, 0.0], [0.7, 0.3, 0.0], [0.15, 0.2 + (0.12 if curved else 0.0), 0.0]])
    return x[:nen].copy()


def slave_at(xseg: np.ndarray, xi: float, g: float) -> np.ndarray:
    x, r, _ = segment_point(xseg, xi)
    n = np.array([r[1], -r[0]]) / np.linalg.norm(r)
    return np.array([*(x + g * n), 0.0])


def evaluate(xseg, xs, case="exact", eps=EPS, lam=0.0, parts=True):
    """(R, K, P, g, xi) at the closest point (projection from scratch)."""
    nen = len(xseg)
    nd = 3 * (nen + 1)
    xi, _, ok = project_on_segment(np.ascontiguousarray(xseg), np.ascontiguousarray(xs), 0.0)
    assert ok
    R, K, P = np.zeros(nd), np.zeros((nd, nd)), np.zeros((4, nd, nd))
    g = segment_core(np.ascontiguousarray(xseg), np.ascontiguousarray(xs), xi, eps, lam, CASES[case], parts, R, K, P)
    return R, K, P, g, xi


def split(x, nen):
    return x[:-3].reshape(nen, 3), x[-3:]


def fd_jacobian(fun, x):
    """Central differences of fun (R^m -> R^k) at x, (k, m)."""
    cols = []
    for k in range(x.size):
        xp, xm = x.copy(), x.copy()
        xp[k] += H
        xm[k] -= H
        cols.append((np.asarray(fun(xp)) - np.asarray(fun(xm))) / (2 * H))
    return np.array(cols).T


SEGMENTS = [(2, False), (3, False), (3, True)]


@pytest.mark.parametrize("nen,curved", SEGMENTS)
@pytest.mark.parametrize("g", [-1e-1, -1e-2])
@pytest.mark.parametrize("lam", [0.0, -5.0])
def test_exact_tangent_matches_central_differences(nen, curved, g, lam):
    xseg = segment(nen, curved)
    xs = slave_at(xseg, 0.37, g)
    R, K, P, gap, xi = evaluate(xseg, xs, lam=lam)
    assert xi == pytest.approx(0.37, abs=1e-10) and gap == pytest.approx(g, rel=1e-9)
    x = np.concatenate([xseg.ravel(), xs])
    Kfd = fd_jacobian(lambda y: evaluate(*split(y, nen), lam=lam)[0], x)
    assert rel(K, Kfd) < 1e-6
    assert rel(P.sum(axis=0), K) < 1e-13
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    # the force on the slave pushes it out of the master: -R(slave) = eps |g_e| n
    _, r, _ = segment_point(xseg, xi)
    n = np.array([r[1], -r[0], 0.0]) / np.linalg.norm(r)
    np.testing.assert_allclose(-R[-3:], EPS * abs(g + lam / EPS) * n, rtol=1e-12, atol=1e-12)
    assert np.all(K[2::3] == 0.0) and np.all(K[:, 2::3] == 0.0)  # z is not seen


@pytest.mark.parametrize("nen,curved", SEGMENTS)
def test_each_part_against_central_differences(nen, curved):
    """main = eps grad g (x) grad g; rotational = eps g_e (D + D^T), D_bc = alpha_b dn/dx_c at fixed xi;
    curvature = eps g_e alpha_b alpha_c n,xi (x) rho / a; second order = the rest of the FD Hessian."""
    xseg = segment(nen, curved)
    g0 = -0.03
    xs = slave_at(xseg, -0.21, g0)
    R, K, P, g, xi = evaluate(xseg, xs)
    x = np.concatenate([xseg.ravel(), xs])
    grad = fd_jacobian(lambda y: [evaluate(*split(y, nen))[3]], x)[0]
    assert rel(P[0], EPS * np.outer(grad, grad)) < 1e-6

    def normal(y, z):
        _, r, _ = segment_point(split(y, nen)[0], z)
        return np.array([r[1], -r[0], 0.0]) / np.linalg.norm(r)

    xi_ = float(xi)
    from covcontact.contact.planar import segment_shapes
    Nv, dN, ddN = np.empty(3), np.empty(3), np.empty(3)
    segment_shapes(nen, xi_, Nv, dN, ddN)
    alpha = np.array([*(-Nv[:nen]), 1.0])
    dndx = fd_jacobian(lambda y: normal(y, xi_), x)  # (3, nd): the normal at fixed xi
    D = np.zeros_like(K)
    for b in range(nen + 1):
        D[3 * b: 3 * b + 3] = alpha[b] * dndx
    assert rel(P[1], EPS * g * (D + D.T)) < 1e-6
    dn_dxi = (normal(x, xi_ + H) - normal(x, xi_ - H)) / (2 * H)
    _, rho, _ = segment_point(xseg, xi_)
    rho = np.array([*rho, 0.0])
    curv = EPS * g * np.kron(np.outer(alpha, alpha), np.outer(dn_dxi, rho) / (rho @ rho))
    if curved:
        assert rel(P[2], curv) < 1e-6
    else:
        assert np.abs(P[2]).max() < 1e-12 * np.abs(P[0]).max()
    Kfd = fd_jacobian(lambda y: evaluate(*split(y, nen))[0], x)
    assert np.linalg.norm(P[3] - (Kfd - P[:3].sum(0))) < 1e-6 * np.linalg.norm(K)


@pytest.mark.parametrize("nen,curved", SEGMENTS)
def test_case_identities_and_second_order_in_g(nen, curved):
    xseg = segment(nen, curved)
    res = {c: evaluate(xseg, slave_at(xseg, 0.5, -0.02), c) for c in CASES}
    P = res["exact"][2]
    expect = {"a": (0, 1, 2), "b": (0, 1), "c": (0, 2), "d": (0,), "exact": (0, 1, 2, 3)}
    for c, parts in expect.items():
        assert np.abs(res[c][1] - P[list(parts)].sum(axis=0)).max() <= 1e-13 * np.abs(P[0]).max()
        np.testing.assert_array_equal(res[c][0], res["exact"][0])
    assert np.linalg.matrix_rank(P[0], tol=1e-10 * np.abs(P[0]).max()) == 1
    diffs = []
    for g in (-1e-2, -5e-3):
        _, K, P, _, _ = evaluate(xseg, slave_at(xseg, 0.5, g))
        diffs.append(np.linalg.norm(P[3]))
    assert 3.0 <= diffs[0] / diffs[1] <= 5.0  # the second-order part is O(g^2)


def test_positive_gap_is_inactive():
    xseg = segment(3, True)
    R, K, P, g, _ = evaluate(xseg, slave_at(xseg, 0.1, 0.01))
    assert g == pytest.approx(0.01) and not R.any() and not K.any()


@pytest.mark.parametrize("outside", [True, False])
@pytest.mark.parametrize("case", ["a", "exact"])
def test_rigid_circle_against_central_differences(outside, case):
    """The rigid circle (a cylinder with its axis along z) on an in-plane slave: residual eps g_e n, and the
    tangent of case a (main + curvature; no rotational part without master dofs) equal to the exact one up to
    the second-order part, the exact one against central differences."""
    cyl = Cylinder((0.3, -0.2, 0.0), (0.0, 0.0, 1.0), 1.5, outside, RigidMotion())
    r = 1.5 - 0.02 if outside else 1.5 + 0.02
    xs = np.array([[0.3 + r * math.cos(0.7), -0.2 + r * math.sin(0.7), 0.0]])
    out = cyl.evaluate(xs, EPS, parts=case, lam=0.0)
    assert out.gap[0] == pytest.approx(-0.02, rel=1e-9)

    def res(y):
        return cyl.evaluate(y.reshape(1, 3), EPS, parts=case, lam=0.0).residual[0]

    Kfd = fd_jacobian(res, xs[0])
    K = out.tangent[0]
    n = (xs[0] - [0.3, -0.2, 0.0]) / np.linalg.norm(xs[0] - [0.3, -0.2, 0.0]) * (1 if outside else -1)
    t = np.array([-n[1], n[0], 0.0])
    kappa = 1.0 / 1.5 * (-1 if outside else 1)  # kappa = h / a of the circle with its outward normal
    if case == "exact":
        assert rel(K, Kfd) < 1e-6
        assert K[0:2, 0:2] == pytest.approx(EPS * (np.outer(n, n) - (-0.02) * kappa / (1 - (-0.02) * kappa) * np.outer(t, t))[:2, :2])
    else:  # main + curvature: eps (n n - g kappa t t)
        assert rel(K, EPS * (np.outer(n, n) - (-0.02) * kappa * np.outer(t, t))) < 1e-12
    assert np.all(K[2] == 0.0) and np.all(K[:, 2] == 0.0)


def test_rigid_line():
    line = Plane((0.0, 1.0, 0.0), (0.0, 1.0, 0.0), RigidMotion())
    out = line.evaluate(np.array([[0.3, 0.98, 0.0]]), EPS, parts="exact", lam=0.0)
    assert out.gap[0] == pytest.approx(-0.02)
    np.testing.assert_allclose(out.residual[0], [0.0, EPS * -0.02, 0.0])
    np.testing.assert_allclose(out.tangent[0], np.diag([0.0, EPS, 0.0]))


def valley():
    """Two linear segments meeting at a valley vertex (node 1 at the origin), the body below them."""
    xe = np.array([[-1.0, 0.5, 0.0], [0.0, 0.0, 0.0], [1.0, 0.5, 0.0]])
    return xe, Curve(np.array([[2, 1], [1, 0]]))  # counter-clockwise body below: edges run right to left


def test_vertex_between_segments():
    xe, curve = valley()
    # behind the valley: neither projection lies on its segment; the closest point is the vertex
    xs = np.array([[0.02, -0.1, 0.0]])
    kind, seg, xi, g, vert, sign = closest_points(curve, xe, xs, 3.0)
    assert kind[0] == VERTEX and vert[0] == 1 and sign[0] == -1.0
    assert g[0] == pytest.approx(-math.hypot(0.02, 0.1))
    # in front of the valley: on the nearer segment
    kind, seg, xi, g, *_ = closest_points(curve, xe, np.array([[0.3, 0.1, 0.0]]), 3.0)
    assert kind[0] == FACET and seg[0] == 0
    # the vertex element: exact tangent against central differences, for penalty and an Uzawa multiplier
    x = np.concatenate([xe[1], xs[0]])
    for lam in (0.0, -20.0):
        def res(y):
            R, K = np.zeros(6), np.zeros((6, 6))
            vertex_core(y[:3], y[3:], -1.0, EPS, lam, R, K)
            return R

        R, K = np.zeros(6), np.zeros((6, 6))
        gap = vertex_core(xe[1], xs[0], -1.0, EPS, lam, R, K)
        assert gap == pytest.approx(-math.hypot(0.02, 0.1))
        assert rel(K, fd_jacobian(res, x)) < 1e-6
        np.testing.assert_allclose(-R[3:5], -EPS * (gap + lam / EPS) * (xs[0, :2] - xe[1, :2]) / gap)


def test_slave_at_a_segment_end():
    """A slave exactly above a vertex between two collinear segments: on either segment with the same gap, force
    and tangent (the patch test's matching nodes)."""
    xe = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    curve = Curve(np.array([[0, 1], [1, 2]]))
    xs = np.array([[0.0, -0.01, 0.0]])  # the body is below (edges run right to left): a penetration of 0.01
    kind, seg, xi, g, *_ = closest_points(curve, xe, xs, 3.0)
    assert kind[0] == FACET and g[0] == pytest.approx(-0.01) and abs(xi[0]) == pytest.approx(1.0)


def test_axisymmetric_and_plane_weights():
    """Consistent weights: int N_a t ds (t the thickness) and int N_a 2 pi R ds in the reference configuration."""
    X = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.5, 0.0, 0.0], [3.0, 0.0, 0.0]])
    w = slave_weights(X, np.array([[0, 1]]), "axisymmetric")
    np.testing.assert_allclose(w[:2], 2 * np.pi * np.array([(2 * 1 + 2) / 6, (1 + 2 * 2) / 6]))
    assert w.sum() == pytest.approx(2 * np.pi * 1.5)  # the area of the annulus pi (2^2 - 1^2)
    w = slave_weights(X, np.array([[0, 1, 2]]), "plane_strain", 0.5)
    np.testing.assert_allclose(w[:3], 0.5 * np.array([1 / 6, 1 / 6, 2 / 3]))
    w = slave_weights(X, np.array([[0, 1, 2], [1, 3, 2]][:1]), "axisymmetric")
    assert w.sum() == pytest.approx(np.pi * (2**2 - 1**2))


# -- problems ------------------------------------------------------------------------------------------------------
def run(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    prob = load_problem(path)
    res = prob.run(out=tmp_path / name)
    assert res.exit_code == 0
    return res


def blocks(form: str, cell: str, nx_up: int, origin_x: float, extra: str = "") -> str:
    """Two blocks of ``cell`` (the upper with ``nx_up`` cells), the upper pressed by 1 (``origin_x``: 1 in an
    axisymmetric model, 0 otherwise, as planar_blocks places them)."""
    assert origin_x == (1.0 if form == "axisymmetric" else 0.0)
    return two_blocks(form, '[[contact]]\nname = "c"\nslave = "up.ymin"\nmaster = "low.ymax"\npenalty = 1e7\n'
                      'weighting = "area"\n' + extra, cell=cell, upper=f"lx = 1.0, ly = 0.5, nx = {nx_up}", steps=1,
                      name="patch")


@pytest.mark.parametrize("form,cell", [("plane_strain", "quad4"), ("plane_stress", "quad8"),
                                       ("axisymmetric", "quad4"), ("axisymmetric", "quad8")])
def test_contact_patch_test(tmp_path, form, cell):
    """Two blocks with a flat interface (matching nodes), the upper one under a uniform pressure: both carry the
    same uniform stress to round-off (the slaves' weights are the consistent loads of a uniform pressure, per unit
    thickness or over the circumference), and the contact forces add up to the load."""
    ox = 1.0 if form == "axisymmetric" else 0.0
    res = run(tmp_path, f"patch_{form}_{cell}", blocks(form, cell, 4, ox))
    u = np.asarray(res.u).reshape(-1, 3)
    syy = []
    for blk in res.model.system.blocks:
        sig = blk.solid.gauss_cauchy(u[blk.offset: blk.offset + blk.n_nodes])
        syy.append(sig[..., 1])
        assert np.abs(sig[..., [0, 3] if form == "plane_strain" else [0, 2, 3]]).max() < 1e-6
    syy = np.concatenate([s.ravel() for s in syy])
    assert syy.max() - syy.min() < 1e-9
    assert syy.mean() == pytest.approx(-1.0, abs=2e-3)  # (finite strain: the load per reference area)
    state = res.state.contact.passes[0]
    total = -np.abs(state.force[:, 1]).sum()
    area = math.pi * (2.0**2 - 1.0**2) if form == "axisymmetric" else 1.0
    assert total == pytest.approx(-area, rel=1e-9)


E_, NU_ = 1000.0, 0.3


def hertz_text(nt: int, nr: int, d: float) -> str:
    return f"""
[problem]
name = "hertz"
[[bodies]]
name = "cyl"
formulation = "plane_strain"
element = "quad4"
mesh = {{ generator = "annulus", r_inner = 0.3, r_outer = 1.0, nr = {nr}, nt = {nt}, angle = 180.0, bias = 0.9 }}
material = {{ model = "neo-hooke", E = {E_}, nu = {NU_} }}
[[rigid]]
name = "floor"
shape = "plane"
point = [1.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[dirichlet]]
set = "cyl.angle0"
components = "y"
value = 0.0
[[dirichlet]]
set = "cyl.angle1"
components = "y"
value = 0.0
[[dirichlet]]
set = "cyl.inner"
components = "x"
value = {d}
[[contact]]
name = "c"
slave = "cyl.outer"
master = "floor"
penalty = 1e7
weighting = "area"
[steps]
factors = [0.25, 0.5, 0.75, 1.0]
"""


def test_hertz_line_contact(tmp_path):
    """A cylinder (R = 1, plane strain, the upper half of a ring r = 0.3 .. 1 of 360 x 24 quad4 cells graded to the
    surface) pressed by its bore onto a rigid line: half-width a = sqrt(4 P R / (pi E*)) and peak pressure
    p0 = 2 P / (pi a) (Johnson, Contact Mechanics, section 4.2), P the force per unit length (twice the half
    model's). a from the second moment of the nodal forces (sum f y^2 / sum f = a^2 / 4 for Hertz's pressure), p0
    the largest nodal pressure (force over weight). Neo-Hooke: p0 / E* = a / (2 R) = 2.3 %, where St. Venant-
    Kirchhoff would soften by about that much (docs/verification.md, Hertz 3D)."""
    res = run(tmp_path, "hertz", hertz_text(360, 24, 0.004))
    st, p = res.state.contact.passes[0], res.model.contact.passes[0]
    f = np.abs(st.force[:, 0])
    y = res.model.system.X[p.slaves, 1] + np.asarray(res.u).reshape(-1, 3)[p.slaves, 1]
    P = 2.0 * f.sum()
    Es = E_ / (1 - NU_**2)
    a = math.sqrt(4 * P / (math.pi * Es))
    p0 = 2 * P / (math.pi * a)
    a_m = 2.0 * math.sqrt((f * y**2).sum() / f.sum())
    p_max = (f / p.area).max()
    print(f"Hertz line contact: P = {P:.4f}, a = {a:.5f}, a_m / a - 1 = {a_m / a - 1:+.4f}, "
          f"p_max / p0 - 1 = {p_max / p0 - 1:+.4f}, contact nodes {np.count_nonzero(f)}")
    assert abs(a_m / a - 1) < 0.03
    assert abs(p_max / p0 - 1) < 0.03


def shrink_text(method: str, penalty: float) -> str:
    bodies = "".join(f"""
[[bodies]]
name = "{n}"
formulation = "plane_strain"
element = "quad8"
mesh = {{ generator = "annulus", r_inner = {ri}, r_outer = {ro}, nr = 4, nt = {nt} }}
material = {{ model = "neo-hooke", E = {E_}, nu = {NU_} }}
[[dirichlet]]
set = "{n}.angle0"
components = "y"
value = 0.0
[[dirichlet]]
set = "{n}.angle1"
components = "x"
value = 0.0
""" for n, ri, ro, nt in (("hub", 0.5, 1.001, 16), ("ring", 1.0, 1.5, 17)))
    return f"""
[problem]
name = "shrink"
{bodies}
[[contact]]
name = "fit"
slave = "hub.outer"
master = "ring.inner"
penalty = {penalty}
weighting = "area"
method = "{method}"
""" + ("gap_tolerance = 1e-7\n" if method == "augmented" else "")


@pytest.mark.parametrize("method,penalty", [("penalty", 1e8), ("augmented", 1e5)])
def test_shrink_fit_against_lame(tmp_path, method, penalty):
    """A hub (r 0.5 .. 1.001) shrunk into a ring (1 .. 1.5), plane strain, quarter models of quad8 with non-matching
    edges (16 and 17 cells around): the mean contact pressure against Lame's (Timoshenko and Goodier, section 33):
    p = delta / ((1 + nu) / E (b^2 / (c^2 - b^2) ((1 - 2 nu) b + c^2 / b) + b^2 / (b^2 - a^2) ((1 - 2 nu) b + a^2 / b)))."""
    a, b, c, dl = 0.5, 1.0, 1.5, 1e-3
    res = run(tmp_path, f"shrink_{method}", shrink_text(method, penalty))
    st, p = res.state.contact.passes[0], res.model.contact.passes[0]
    k = (1 + NU_) / E_
    exact = dl / (k * (b**2 / (c**2 - b**2) * ((1 - 2 * NU_) * b + c**2 / b)
                       + b**2 / (b**2 - a**2) * ((1 - 2 * NU_) * b + a**2 / b)))
    mean = np.linalg.norm(st.force, axis=1).sum() / p.area.sum()
    print(f"shrink fit ({method}): p / p_Lame - 1 = {mean / exact - 1:+.5f}, "
          f"largest penetration {-st.gap[np.isfinite(st.gap)].min():.2e}")
    assert abs(mean / exact - 1) < 0.01


def test_bad_planar_pairs(tmp_path):
    """A planar pair the code cannot take: one line naming the pair (exit 2 from the command line)."""
    text = blocks("plane_strain", "quad4", 4, 0.0, "").replace('weighting = "area"\n', 'weighting = "area"\nadjust = 0.01\n')
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(Exception, match="adjust is not available on planar bodies"):
        load_problem(path)
