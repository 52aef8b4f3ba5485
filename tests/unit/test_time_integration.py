"""The generalized-alpha family on a single degree of freedom m x'' + k x = 0 (docs/theory.md, section 20): the
spectral radius at infinite frequency is rho_inf, the methods are second order, the trapezoidal rule keeps the
energy exactly; the parameters are those of Chung and Hulbert (1993) and Hilber, Hughes and Taylor (1977)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.solvers.dynamics import Integrator


def _step(g: Integrator, x, v, a, dt, w2=1.0):
    """One step of the method on x'' + w2 x = 0 (m = 1), solved exactly: the dynamic residual of covcontact,
    (1 - am) a_(n+1) + am a_n + w2 ((1 - af) x_(n+1) + af x_n) = 0, with Newmark's a_(n+1)(x_(n+1))."""
    c0, c1 = 1.0 / (g.beta * dt * dt), 0.5 / g.beta - 1.0
    lhs = (1.0 - g.alpha_m) * c0 + w2 * (1.0 - g.alpha_f)
    rhs = (1.0 - g.alpha_m) * (c0 * (x + dt * v) + c1 * a) - g.alpha_m * a - w2 * g.alpha_f * x
    x1 = rhs / lhs
    a1 = g.acceleration(x1, x, v, a, dt)
    np.testing.assert_allclose((1.0 - g.alpha_m) * a1 + g.alpha_m * a + w2 * ((1.0 - g.alpha_f) * x1 + g.alpha_f * x),
                               0.0, atol=1e-9 * max(1.0, abs(lhs * x1)))
    return x1, g.velocity(a1, v, a, dt), a1


def _spectral_radius(g: Integrator, wdt: float) -> float:
    """Largest eigenvalue modulus of the amplification matrix of (x, dt v, dt^2 a) at w dt."""
    A = np.empty((3, 3))
    for j in range(3):
        e = np.eye(3)[j]
        x, v, a = _step(g, e[0], e[1] / 1.0, e[2], 1.0, wdt ** 2)
        A[:, j] = (x, v, a)
    return float(np.max(np.abs(np.linalg.eigvals(A))))


@pytest.mark.parametrize("method, rho", [("generalized-alpha", 0.0), ("generalized-alpha", 0.5),
                                         ("generalized-alpha", 0.8), ("generalized-alpha", 1.0), ("hht", 0.5),
                                         ("hht", 0.9), ("newmark", 1.0)])
def test_spectral_radius_at_infinite_frequency(method, rho):
    """rho(w dt -> inf) = rho_inf (measured at w dt = 1e5), and no amplification at any frequency."""
    g = Integrator.of(method, rho)
    assert _spectral_radius(g, 1e5) == pytest.approx(rho, abs=2e-3)
    assert all(_spectral_radius(g, w) <= 1.0 + 1e-12 for w in np.logspace(-2, 3, 26))


@pytest.mark.parametrize("method, rho", [("generalized-alpha", 0.6), ("hht", 0.7), ("newmark", 1.0)])
def test_second_order(method, rho):
    """x'' + x = 0 from x = 1 over t = 10: the error of x(10) falls by 4 per halving of dt (about: 3.6 to 4.4)."""
    g = Integrator.of(method, rho)
    errs = []
    for n in (200, 400, 800):
        dt = 10.0 / n
        x, v, a = 1.0, 0.0, -1.0
        for _ in range(n):
            x, v, a = _step(g, x, v, a, dt)
        errs.append(abs(x - np.cos(10.0)) + abs(v + np.sin(10.0)))
    rates = [errs[0] / errs[1], errs[1] / errs[2]]
    assert all(3.6 < r < 4.4 for r in rates), rates


def test_trapezoidal_rule_keeps_the_energy():
    """Newmark's trapezoidal rule: (v^2 + w^2 x^2) / 2 is constant to round-off, even at w dt = 10."""
    g = Integrator.of("newmark")
    x, v, a = 1.0, 0.3, -100.0
    e0 = 0.5 * (v * v + 100.0 * x * x)
    for _ in range(500):
        x, v, a = _step(g, x, v, a, 1.0, 100.0)
    assert 0.5 * (v * v + 100.0 * x * x) == pytest.approx(e0, rel=1e-10)


def test_parameters():
    g = Integrator.of("generalized-alpha", 1.0)
    assert (g.alpha_m, g.alpha_f, g.beta, g.gamma) == (0.5, 0.5, 0.25, 0.5)
    g = Integrator.of("hht", 0.5)
    assert g.alpha_m == 0.0 and g.alpha_f == pytest.approx(1.0 / 3.0)
    with pytest.raises(ValueError, match="HHT needs rho_inf"):
        Integrator.of("hht", 0.4)
