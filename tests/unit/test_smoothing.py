"""The smoothed normal law (``[[contact]] smoothing = width``, docs/theory.md section 5): the penalty law
rounded over a band of gaps, C1 where the plain law has a kink; the penalty law itself beyond the band. Its
tangents (facet pairs, analytic surfaces, friction) against finite differences."""

from __future__ import annotations

import numpy as np
import pytest
from profile_cases import profiles

from covcontact.contact import Plane, RigidMotion, Sphere
from covcontact.contact.friction import SLIP, STICK, surface_friction
from covcontact.contact.laws import is_active, smooth_law
from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

EPS, BAND = 100.0, 0.1


def test_law_is_c1_and_the_penalty_beyond_the_band():
    g = np.linspace(-0.3, 0.2, 5001)
    sig = np.array([smooth_law(x, 0.0, EPS, BAND) for x in g])
    beyond = g <= -BAND / 2
    np.testing.assert_allclose(sig[beyond, 0], EPS * g[beyond], rtol=1e-15)
    assert np.all(sig[g >= BAND / 2] == 0.0)
    # C1: traction and slope continuous (no jump larger than the slope times the step)
    h = g[1] - g[0]
    assert np.abs(np.diff(sig[:, 0])).max() <= EPS * h * (1 + 1e-9)
    assert np.abs(np.diff(sig[:, 1])).max() <= EPS / BAND * h * (1 + 1e-9)
    # the slope is the derivative of the traction (central differences)
    np.testing.assert_allclose(np.gradient(sig[:, 0], h)[1:-1], sig[1:-1, 1], atol=EPS * 1e-3)
    # the band's middle: traction eps b / 4, half the slope; active strictly below b / 2
    assert smooth_law(0.0, 0.0, EPS, BAND) == pytest.approx((-EPS * BAND / 8, EPS / 2))
    assert is_active(0.0499, 0.0, EPS, BAND) and not is_active(0.05, 0.0, EPS, BAND)
    # an Uzawa multiplier shifts the law like the plain one's
    assert smooth_law(0.01, -2.0, EPS, BAND) == smooth_law(0.01 - 0.02, 0.0, EPS, BAND)


def _fd(fun, x, h=1e-7):
    K = np.zeros((3, 3))
    for j in range(3):
        xp, xm = x.copy(), x.copy()
        xp[j] += h
        xm[j] -= h
        K[:, j] = (fun(xp) - fun(xm)) / (2 * h)
    return K


SURFACES = {"plane": Plane((0.0, 0.0, 0.0), (0.2, 0.1, 1.0)), "sphere": Sphere((0.0, 0.0, 0.0), 2.0),
            **{k: v for k, v in profiles(RigidMotion()).items() if k in ("ext_ridge", "rev_die")}}


@pytest.mark.parametrize("name", sorted(SURFACES))
@pytest.mark.parametrize("g", [-0.2, -0.04, 0.0, 0.03, 0.049])
def test_analytic_tangent_in_and_beyond_the_band(name, g):
    surf = SURFACES[name]
    pr = surf.project(np.array([0.3, 0.4, 1.9]))
    x = pr.rho + g * pr.normal
    for case in ("exact", "a"):
        r = surf.contact(x, EPS, case, band=BAND)
        assert np.linalg.norm(r.residual) == pytest.approx(-smooth_law(g, 0.0, EPS, BAND)[0], rel=1e-6)
        if case == "exact":
            K = _fd(lambda y: surf.contact(y, EPS, "exact", band=BAND).residual, x)
            assert np.linalg.norm(r.tangent - K) <= 1e-6 * np.linalg.norm(K)


@pytest.mark.parametrize("name", sorted(SURFACES))
@pytest.mark.parametrize("mu,state", [(0.3, SLIP), (50.0, STICK)])
def test_analytic_friction_tangent_in_the_band(name, mu, state):
    surf = SURFACES[name]
    pr = surf.project(np.array([0.3, 0.4, 1.9]))
    x = pr.rho + 0.01 * pr.normal  # inside the band, on its open side
    t1 = pr.rho_cov[0] / np.linalg.norm(pr.rho_cov[0])
    hist = surface_friction(surf, x + 0.02 * t1, EPS, 50.0, mu, band=BAND).history
    r = surface_friction(surf, x, EPS, 50.0, mu, hist, band=BAND)
    assert r.state == state
    K = _fd(lambda y: surface_friction(surf, y, EPS, 50.0, mu, hist, band=BAND).residual, x)
    assert np.linalg.norm(r.tangent - K) <= 1e-6 * np.linalg.norm(K)


TWO_BLOCKS = """
[problem]
name = "two-blocks"
[[bodies]]
name = "base"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 4, ny = 4, nz = 2, origin = [-1.0, -1.0, -0.5] }
[[bodies]]
name = "punch"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 3, ny = 3, nz = 2, origin = [-0.5, -0.5, 0.0] }
[[contact]]
slave = "punch.zmin"
master = "base.zmax"
penalty = 2.0e4
weighting = "area"
smoothing = 0.004
tangent = "exact"
FRICTION
[[dirichlet]]
set = "base.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.02, 0.01, -0.01]
[steps]
count = 3
"""


def _checked_gaps(tmp_path, text: str) -> np.ndarray:
    """check-tangent at steps 1 and 3 of the problem ``text`` (exact tangent within 1e-6), then the whole run;
    the gaps of its slave nodes at the end."""
    path = tmp_path / "p.toml"
    path.write_text(text)
    prob = load_problem(path)
    for step in (1, 3):
        rep = check_tangent(prob, step=step, columns=None)
        assert rep["converged"] and rep["judged"] > 0, rep.get("reason")
        assert rep["relative_error"] <= 1e-6, (step, rep["relative_error"])
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    return res.state.contact.passes[0].gap


@pytest.mark.parametrize("friction", ["", "friction = 0.2"], ids=["frictionless", "coulomb"])
def test_facet_pair_tangent_with_smoothing(tmp_path, friction):
    """A block pressed and pulled across another (facet master, area weighting): the penetration is of the
    order of the band, so slave nodes lie inside it; the exact tangent passes check-tangent at 1e-6."""
    g = _checked_gaps(tmp_path, TWO_BLOCKS.replace("FRICTION", friction))
    band = g[np.abs(g) < 0.002]
    assert band.size > 0  # some slaves sit inside the band: the smoothed part of the law is exercised


# ------------------------------------------------------------------ exponential pressure-overclosure law

C0, P0 = 0.05, 20.0


def test_exponential_law_shape():
    """p(0) = p0, p(c0) = 0, convex and C1 on the whole range (its linear continuation beyond an overclosure of
    2 c0 included); the slope is the derivative of the force."""
    from covcontact.contact.laws import exponential_law

    assert exponential_law(0.0, P0, C0)[0] == pytest.approx(-P0)
    assert exponential_law(C0, P0, C0) == (0.0, 0.0) and exponential_law(2 * C0, P0, C0) == (0.0, 0.0)
    g = np.linspace(-4 * C0, 1.5 * C0, 20001)
    s = np.array([exponential_law(x, P0, C0) for x in g])
    h = g[1] - g[0]
    np.testing.assert_allclose(np.gradient(s[:, 0], h)[1:-1], s[1:-1, 1], rtol=2e-3, atol=1e-4 * P0 / C0)
    assert np.abs(np.diff(s[:, 1])).max() < 1e-2 * s[:, 1].max()  # no jump in the slope
    assert np.all(np.diff(s[:, 1]) <= 1e-12)  # the stiffness only grows with the overclosure


@pytest.mark.parametrize("name", sorted(SURFACES))
@pytest.mark.parametrize("g", [-0.15, -0.05, 0.0, 0.03])
def test_exponential_analytic_tangent(name, g):
    surf = SURFACES[name]
    pr = surf.project(np.array([0.3, 0.4, 1.9]))
    x = pr.rho + g * pr.normal
    r = surf.contact(x, P0, "exact", band=-C0)
    from covcontact.contact.laws import exponential_law

    assert np.linalg.norm(r.residual) == pytest.approx(-exponential_law(g, P0, C0)[0], rel=1e-6)
    K = _fd(lambda y: surf.contact(y, P0, "exact", band=-C0).residual, x)
    assert np.linalg.norm(r.tangent - K) <= 1e-6 * np.linalg.norm(K)
    hist = surface_friction(surf, x + 0.01 * pr.rho_cov[0] / np.linalg.norm(pr.rho_cov[0]), P0, P0 / C0, 0.3,
                            band=-C0).history
    f = surface_friction(surf, x, P0, P0 / C0, 0.3, hist, band=-C0)
    K = _fd(lambda y: surface_friction(surf, y, P0, P0 / C0, 0.3, hist, band=-C0).residual, x)
    assert np.linalg.norm(f.tangent - K) <= 1e-6 * np.linalg.norm(K)


EXPONENTIAL = TWO_BLOCKS.replace('penalty = 2.0e4\nweighting = "area"\nsmoothing = 0.004',
                                 'law = "exponential"\nclearance = 0.004\npressure = 20.0\nweighting = "area"')


@pytest.mark.parametrize("friction", ["", "friction = 0.2"], ids=["frictionless", "coulomb"])
def test_exponential_facet_pair(tmp_path, friction):
    """The pressed and pulled block on a facet master with the exponential law: check-tangent passes at 1e-6;
    slave nodes carry force at positive gaps and none sinks in by more than 0.02."""
    g = _checked_gaps(tmp_path, EXPONENTIAL.replace("FRICTION", friction))
    assert np.any(g > 0.0) and np.all(g[np.isfinite(g)] > -0.02)  # contact before touching: soft law


@pytest.mark.parametrize("extra, message", [
    ('law = "exponential"\nclearance = 0.01\npressure = 10.0\npenalty = 1.0', "contact[0].penalty: not used"),
    ('law = "exponential"\npressure = 10.0', "contact[0].clearance: missing"),
    ('law = "exponential"\nclearance = -0.01\npressure = 10.0', "contact[0].clearance: must be > 0"),
    ('penalty = 1.0\nsmoothing = -0.1', "contact[0].smoothing: must be >= 0"),
    ('penalty = 1.0\nlaw = "hard"', "contact[0].law: 'hard' is not one of"),
])
def test_bad_laws(tmp_path, extra, message):
    from covcontact.io.validate import InputError

    text = TWO_BLOCKS.replace('penalty = 2.0e4\nweighting = "area"\nsmoothing = 0.004', extra).replace("FRICTION", "")
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)
