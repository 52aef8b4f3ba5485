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
from covcontact.contact.planar import project_on_segment, segment_point
from covcontact.contact.planar_friction import (
    OPEN,
    SLIP,
    STICK,
    make_history,
    segment_friction,
    start_history,
    transfer_history,
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
