"""Finite-strain J2 plasticity (log-strain space): tangent against central finite differences, material-point
closed forms (uniaxial stress, simple shear, unloading), the discrete return-mapping equations (yield
condition, normality, Prager back stress, plastic work), Hill r-values, objectivity, isochoric flow and
validation. Every reference value is a closed form or an independent numpy evaluation, never a stored
output of the code under test."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import root

from covcontact.materials import (
    J2,
    NEO_HOOKE,
    NHIST,
    SVK,
    Hill48,
    J2Plasticity,
    LinearHardening,
    NeoHooke,
    SaintVenantKirchhoff,
    SwiftHardening,
    VoceHardening,
    j2_point,
    material_response,
    material_update,
)

PAIRS = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
E_MOD, NU, SY0 = 200e3, 0.3, 200.0
HILL_R = (1.8, 1.2, 2.2)  # r0, r45, r90

LAWS = {
    "linear": lambda: ({"law": "linear", "modulus": 2000.0}, SY0),
    "swift": lambda: ({"law": "swift", "K": 500.0, "eps0": 0.01, "n": 0.2}, None),
    "voce": lambda: ({"law": "voce", "sigma_inf": 400.0, "delta": 20.0, "modulus": 300.0}, SY0),
}


def sigma_y_ref(law: str, alpha: float) -> float:
    """The hardening laws in closed form with the parameters of LAWS (independent of the module)."""
    if law == "linear":
        return SY0 + 2000.0 * alpha
    if law == "swift":
        return 500.0 * (0.01 + alpha) ** 0.2
    return SY0 + (400.0 - SY0) * (1.0 - math.exp(-20.0 * alpha)) + 300.0 * alpha


def make(law: str, kin: float = 0.0, hill=None) -> J2Plasticity:
    hard, sy = LAWS[law]()
    return J2Plasticity(E=E_MOD, nu=NU, yield_stress=sy, hardening=hard, kinematic_modulus=kin, hill48=hill)


# ----------------------------------------------------------------------------------------------
# independent references (numpy)


def voigt(A: np.ndarray) -> np.ndarray:
    """Tensor components (11, 22, 33, 12, 23, 13) of a symmetric 3x3 tensor."""
    return np.array([A[i, j] for i, j in PAIRS])


def tensor(v: np.ndarray) -> np.ndarray:
    """Symmetric 3x3 tensor from its components (11, 22, 33, 12, 23, 13)."""
    A = np.empty((3, 3))
    for k, (i, j) in enumerate(PAIRS):
        A[i, j] = A[j, i] = v[k]
    return A


def log_strain(F: np.ndarray) -> np.ndarray:
    """E_log = 1/2 ln(F^T F) by numpy's eigh."""
    lam, V = np.linalg.eigh(F.T @ F)
    return (V * (0.5 * np.log(lam))) @ V.T


def expm_sym(A: np.ndarray) -> np.ndarray:
    lam, V = np.linalg.eigh(A)
    return (V * np.exp(lam)) @ V.T


def F_of_E(E: np.ndarray) -> np.ndarray:
    """Symmetric stretch U = sqrt(I + 2E): a deformation gradient with Green-Lagrange strain E."""
    lam, V = np.linalg.eigh(np.eye(3) + 2.0 * E)
    return (V * np.sqrt(lam)) @ V.T


def green_lagrange(F: np.ndarray) -> np.ndarray:
    return 0.5 * (F.T @ F - np.eye(3))


def hencky_T(mat: J2Plasticity, F: np.ndarray, hist: np.ndarray) -> np.ndarray:
    """T = lambda tr(E_e) I + 2 mu E_e with E_e = E_log(F) - E_p (E_p from the history)."""
    Ee = log_strain(F) - tensor(hist[0:6])
    return mat.lam * np.trace(Ee) * np.eye(3) + 2.0 * mat.mu * Ee


def hill_coef(mat: J2Plasticity) -> tuple[float, ...]:
    return (0.5, 0.5, 0.5, 1.5, 1.5, 1.5) if mat.hill48 is None else mat.hill48.coefficients


def hill_eq(xi: np.ndarray, coef) -> float:
    """Hill 1948 equivalent stress of the symmetric tensor xi (von Mises for the isotropic coefficients)."""
    Fh, Gh, Hh, Lh, Mh, Nh = coef
    return math.sqrt(Fh * (xi[1, 1] - xi[2, 2]) ** 2 + Gh * (xi[2, 2] - xi[0, 0]) ** 2
                     + Hh * (xi[0, 0] - xi[1, 1]) ** 2 + 2.0 * Lh * xi[1, 2] ** 2 + 2.0 * Mh * xi[0, 2] ** 2
                     + 2.0 * Nh * xi[0, 1] ** 2)


def hill_grad(xi: np.ndarray, coef) -> np.ndarray:
    """Tensor gradient of sigma_bar^2 / 2 (so that d sigma_bar / d xi = hill_grad / sigma_bar)."""
    Fh, Gh, Hh, Lh, Mh, Nh = coef
    g = np.empty((3, 3))
    g[0, 0] = Gh * (xi[0, 0] - xi[2, 2]) + Hh * (xi[0, 0] - xi[1, 1])
    g[1, 1] = Fh * (xi[1, 1] - xi[2, 2]) + Hh * (xi[1, 1] - xi[0, 0])
    g[2, 2] = Fh * (xi[2, 2] - xi[1, 1]) + Gh * (xi[2, 2] - xi[0, 0])
    g[0, 1] = g[1, 0] = Nh * xi[0, 1]
    g[1, 2] = g[2, 1] = Lh * xi[1, 2]
    g[0, 2] = g[2, 0] = Mh * xi[0, 2]
    return g


def hooke(E: float, nu: float) -> np.ndarray:
    """Isotropic linear elasticity in Voigt form with engineering shear (textbook matrix)."""
    c = E / ((1.0 + nu) * (1.0 - 2.0 * nu))
    D = np.zeros((6, 6))
    D[:3, :3] = c * nu
    D[np.arange(3), np.arange(3)] = c * (1.0 - nu)
    D[np.arange(3, 6), np.arange(3, 6)] = E / (2.0 * (1.0 + nu))
    return D


def fd_tangent(mat: J2Plasticity, F: np.ndarray, hist_n: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central differences of S w.r.t. the Green-Lagrange strain (engineering shear), perturbing C
    symmetrically (F -> sqrt(C), S depends on C only)."""
    E = green_lagrange(F)
    Dfd = np.empty((6, 6))
    for J, (i, j) in enumerate(PAIRS):
        dE = np.zeros((3, 3))
        if i == j:
            dE[i, i] = h
        else:
            dE[i, j] = dE[j, i] = 0.5 * h
        Sp = j2_point(mat, F_of_E(E + dE), hist_n)[0]
        Sm = j2_point(mat, F_of_E(E - dE), hist_n)[0]
        Dfd[:, J] = (Sp - Sm) / (2.0 * h)
    return Dfd


def commit(mat: J2Plasticity, F: np.ndarray, hist_n: np.ndarray | None = None) -> np.ndarray:
    S, D, hist, status = j2_point(mat, F, hist_n)
    assert status == 0
    return hist


# ----------------------------------------------------------------------------------------------
# 1. tangent against finite differences

F_GENERAL = np.array([[1.03, 0.02, -0.01], [0.015, 0.985, 0.012], [-0.008, 0.01, 0.99]])  # with rotation
F_UNIAXIAL = np.diag([1.03, 0.99, 0.99])  # two coincident eigenvalues of C
F_VOLUMETRIC = 0.99 * np.eye(3)  # three coincident eigenvalues of C
SHEAR = np.eye(3) + np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


def _state(mat: J2Plasticity, Fname: str, state: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(F, committed history, expected yield flag) of a tangent case."""
    F = {"general": F_GENERAL, "uniaxial": F_UNIAXIAL, "volumetric": F_VOLUMETRIC}[Fname]
    I = np.eye(3)
    if Fname == "volumetric":
        # deviatoric history from a shear step: large (reverse plastic flow) or just past yield (elastic)
        if state == "elastic":
            return F, np.zeros(NHIST), 0.0
        gamma = 0.05 if state == "plastic" else 2.5e-3
        hist_n = commit(mat, F @ (I + gamma * (SHEAR - I)))
        assert hist_n[14] == 1.0
        return F, hist_n, 1.0 if state == "plastic" else 0.0
    if state == "elastic":
        return I + 0.01 * (F - I), np.zeros(NHIST), 0.0
    if state == "plastic":
        return F, commit(mat, I + 0.5 * (F - I)), 1.0
    hist_n = commit(mat, I + 1.02 * (F - I))
    assert hist_n[14] == 1.0
    return F, hist_n, 0.0


def _distinct(F: np.ndarray) -> float:
    """Smallest gap between the eigenvalues of C, relative to the largest |eigenvalue of C - I|."""
    lam = np.linalg.eigvalsh(F.T @ F)
    return float(np.min(np.diff(lam)) / np.max(np.abs(lam - 1.0)))


@pytest.mark.parametrize("Fname", ["general", "uniaxial", "volumetric"])
@pytest.mark.parametrize("state", ["elastic", "plastic", "unloading"])
@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
@pytest.mark.parametrize("kin", [0.0, 1500.0], ids=["iso", "kin"])
@pytest.mark.parametrize("law", sorted(LAWS))
def test_tangent_matches_central_differences(law, kin, hill, state, Fname):
    mat = make(law, kin, hill)
    F, hist_n, flag = _state(mat, Fname, state)
    if Fname == "general":
        assert _distinct(F) > 0.1
    else:
        assert _distinct(F) == 0.0  # exactly coincident eigenvalues at the evaluation point
    S, D, hist, status = j2_point(mat, F, hist_n)
    assert status == 0
    assert hist[14] == flag
    if flag == 1.0:
        assert hist[6] > hist_n[6]
    else:
        assert hist[6] == hist_n[6]
    Dfd = fd_tangent(mat, F, hist_n)
    err = np.max(np.abs(Dfd - D)) / np.max(np.abs(D))
    assert err <= 1e-6, f"relative FD error {err:.2e}"


def _dd_reference(*x: float) -> float:
    """Divided difference of f = ln/2 at 2 or 3 points from the integral representation
    ln x = int_0^inf (1/(1+t) - 1/(x+t)) dt: f[a,b] = 1/2 int dt/((a+t)(b+t)),
    f[a,b,c] = -1/2 int dt/((a+t)(b+t)(c+t)); mapped to [0, 1] by t = u/(1-u) and integrated by quad."""
    from scipy.integrate import quad

    def g(u):
        v = 1.0 - u
        return v ** (len(x) - 2) / np.prod([xi * v + u for xi in x])

    val = quad(g, 0.0, 1.0, epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return 0.5 * val if len(x) == 2 else -0.5 * val


@pytest.mark.parametrize("base", [0.3, 1.0, 4.0])
def test_divided_differences_of_the_logarithm(base):
    """First and second divided differences (with their Taylor limits for close arguments) against an
    independent quadrature, across the switch-over thresholds."""
    from covcontact.materials.plasticity import _dd1, _dd2

    def t(a, b):
        return _dd1(a, b, 0.5 * math.log(a), 0.5 * math.log(b))

    for d in (0.0, 1e-13, 1e-9, 1e-6, 4.9e-4, 5.1e-4, 9.9e-4, 1.01e-3, 3e-3, 0.1, 1.0, 30.0):
        a, b, c = base, base * (1.0 + d), base * (1.0 + 2.0 * d)
        assert t(a, b) == pytest.approx(_dd_reference(a, b), rel=1e-12)
        for x0, x1, x2 in ((a, b, c), (a, a, b), (b, a, b), (a, b, 5.0 * a), (c, a, 0.2 * b)):
            got = _dd2(x0, x1, x2, t(x0, x1), t(x1, x2), t(x0, x2))
            assert got == pytest.approx(_dd_reference(x0, x1, x2), rel=1e-10)


def test_reference_state_is_hooke():
    """At F = I from the virgin state: S = 0 and D = isotropic Hooke (log strain = Green-Lagrange to first
    order), no NaN."""
    for mat in (make("linear"), make("swift", 1000.0, HILL_R)):
        S, D, hist, status = j2_point(mat, np.eye(3))
        assert status == 0
        assert np.all(S == 0.0)
        np.testing.assert_allclose(D, hooke(E_MOD, NU), rtol=1e-13, atol=1e-9)


def test_residual_stress_at_identity_is_finite_and_tangent_fd():
    mat = make("voce", 1000.0, HILL_R)
    hist_n = commit(mat, np.eye(3) + 0.05 * (SHEAR - np.eye(3)))
    S, D, hist, status = j2_point(mat, np.eye(3), hist_n)
    assert status == 0 and np.all(np.isfinite(S)) and np.all(np.isfinite(D))
    Dfd = fd_tangent(mat, np.eye(3), hist_n)
    assert np.max(np.abs(Dfd - D)) <= 1e-6 * np.max(np.abs(D))


def test_pure_volumetric_closed_form():
    """F = J^(1/3) I: T = K ln J I (Hencky), S = T C^-1 = K ln J / J^(2/3) I; elastic for any J."""
    mat = make("linear", 0.0, HILL_R)
    K = mat.lam + 2.0 * mat.mu / 3.0
    for J in (0.8, 1.0, 1.25):
        S, D, hist, status = j2_point(mat, J ** (1.0 / 3.0) * np.eye(3))
        assert status == 0 and hist[14] == 0.0
        np.testing.assert_allclose(S[:3], K * math.log(J) / J ** (2.0 / 3.0), rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(S[3:], 0.0, atol=1e-9)


# ----------------------------------------------------------------------------------------------
# 2. material point closed forms


def uniaxial_diag(mat, eps_path, hist_n=None, axis=0):
    """Uniaxial stress along a material axis: F = diag with ln F_aa = eps, the two lateral stretches
    iterated (Newton with D) to zero lateral stress. Returns per step (tau_aa, ln lateral stretches,
    history), committing each step."""
    hist_n = np.zeros(NHIST) if hist_n is None else hist_n
    lat = [k for k in range(3) if k != axis]
    stretch = np.ones(3)
    out = []
    for eps in eps_path:
        stretch[axis] = math.exp(eps)
        for _ in range(50):
            S, D, hist, status = j2_point(mat, np.diag(stretch), hist_n)
            assert status == 0
            r = S[lat]
            if np.max(np.abs(r)) <= 1e-11 * max(1.0, abs(S[axis])):
                break
            Jm = D[np.ix_(lat, lat)] * stretch[lat][None, :]  # dE_kk = stretch_k d stretch_k
            stretch[lat] -= np.linalg.solve(Jm, r)
        else:
            raise AssertionError("lateral stress iteration did not converge")
        tau = stretch[axis] ** 2 * S[axis]  # Kirchhoff tau = F S F^T
        out.append((tau, np.log(stretch[lat]), hist))
        hist_n = hist
    return out


@pytest.mark.parametrize("kin", [0.0, 1500.0])
def test_uniaxial_linear_hardening_closed_form(kin):
    """Log-strain closed form of uniaxial stress with linear (isotropic + kinematic) hardening:
    elastic tau = E eps; plastic tau = sigma_y0 + H_eff alpha, eps = tau/E + alpha, H_eff = H + H_kin,
    so tau = E (H_eff eps + sigma_y0) / (E + H_eff); lateral log strain -nu tau/E - alpha/2."""
    H = 2000.0
    mat = J2Plasticity(E=E_MOD, nu=NU, yield_stress=SY0, hardening={"law": "linear", "modulus": H},
                       kinematic_modulus=kin)
    Heff = H + kin
    eps_y = SY0 / E_MOD
    path = np.concatenate([np.linspace(0.2, 0.9, 3) * eps_y, np.linspace(1.5 * eps_y, 0.08, 8)])
    for eps, (tau, lat, hist) in zip(path, uniaxial_diag(mat, path)):
        if eps < eps_y:
            tau_ref, alpha_ref = E_MOD * eps, 0.0
            assert hist[14] == 0.0
        else:
            tau_ref = E_MOD * (Heff * eps + SY0) / (E_MOD + Heff)
            alpha_ref = (tau_ref - SY0) / Heff
            assert hist[14] == 1.0
        assert tau == pytest.approx(tau_ref, rel=1e-10)
        assert hist[6] == pytest.approx(alpha_ref, rel=1e-9, abs=1e-15)
        np.testing.assert_allclose(lat, -NU * tau_ref / E_MOD - 0.5 * alpha_ref, rtol=1e-9, atol=1e-15)


def test_loading_unloading_cycle():
    """Load past yield, unload elastically: slope d tau / d eps = E exactly (Hencky), yield flag 0,
    alpha and E_p frozen; reloading yields again at the previous stress."""
    mat = make("linear", 1500.0)
    load = list(np.linspace(0.002, 0.03, 6))
    unload = list(0.03 - np.linspace(2e-4, 1.6e-3, 5))
    res = uniaxial_diag(mat, load + unload + [0.0305])
    tau_max, _, hist_max = res[len(load) - 1]
    assert hist_max[14] == 1.0
    for k, eps in enumerate(unload):
        tau, _, hist = res[len(load) + k]
        assert hist[14] == 0.0
        assert hist[6] == hist_max[6]
        np.testing.assert_array_equal(hist[0:6], hist_max[0:6])
        assert (tau_max - tau) / (0.03 - eps) == pytest.approx(E_MOD, rel=1e-9)
    assert res[-1][2][14] == 1.0
    assert res[-1][2][6] > hist_max[6]


@pytest.mark.parametrize("kin", [0.0, 1500.0])
def test_simple_shear_small_strain(kin):
    """Simple shear F = I + gamma e1 x e2 at small strain against small-strain J2: elastic tau = mu gamma;
    plastic tau = [sigma_y0/sqrt 3 + (H_eff/3) gamma] / (1 + H_eff/(3 mu)) (from sqrt 3 (tau - H_kin
    gamma_p/3) = sigma_y0 + H gamma_p/sqrt 3, gamma = tau/mu + gamma_p). Finite-strain deviation
    O(gamma^2)."""
    H = 2000.0
    mat = J2Plasticity(E=E_MOD, nu=NU, yield_stress=SY0, hardening={"law": "linear", "modulus": H},
                       kinematic_modulus=kin)
    mu = mat.mu
    Heff = H + kin
    gamma_y = SY0 / (math.sqrt(3.0) * mu)
    hist_n = np.zeros(NHIST)
    for gamma in np.linspace(0.25 * gamma_y, 5e-3, 12):
        F = np.eye(3) + gamma * (SHEAR - np.eye(3))
        S, D, hist, status = j2_point(mat, F, hist_n)
        assert status == 0
        sigma = F @ tensor(S) @ F.T / np.linalg.det(F)
        if gamma < gamma_y:
            ref = mu * gamma
        else:
            ref = (SY0 / math.sqrt(3.0) + Heff / 3.0 * gamma) / (1.0 + Heff / (3.0 * mu))
            assert hist[6] == pytest.approx((gamma - ref / mu) / math.sqrt(3.0), rel=1e-3)
        assert sigma[0, 1] == pytest.approx(ref, rel=1e-4)
        hist_n = hist


@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
@pytest.mark.parametrize("kin", [0.0, 1500.0], ids=["iso", "kin"])
@pytest.mark.parametrize("law", sorted(LAWS))
def test_return_mapping_equations(law, kin, hill):
    """At a plastic point the trial history satisfies, with T from Hencky elasticity (numpy E_log):
    the yield condition sigma_bar(T - beta) = sigma_y(alpha) of the law; normality
    delta E_p = delta alpha grad sigma_bar(T - beta); Prager delta beta = 2/3 H_kin delta E_p;
    delta w_p = T : delta E_p."""
    mat = make(law, kin, hill)
    coef = hill_coef(mat)
    hist_n = commit(mat, np.eye(3) + 0.5 * (F_GENERAL - np.eye(3)))
    for F in (F_GENERAL, F_GENERAL @ F_GENERAL):
        S, D, hist, status = j2_point(mat, F, hist_n)
        assert status == 0 and hist[14] == 1.0
        T = hencky_T(mat, F, hist)
        xi = T - tensor(hist[7:13])
        alpha = hist[6]
        sbar = hill_eq(xi, coef)
        assert sbar == pytest.approx(sigma_y_ref(law, alpha), rel=1e-11)
        dEp = tensor(hist[0:6] - hist_n[0:6])
        dalpha = alpha - hist_n[6]
        np.testing.assert_allclose(dEp, dalpha * hill_grad(xi, coef) / sbar, rtol=0,
                                   atol=1e-11 * np.max(np.abs(dEp)))
        np.testing.assert_allclose(hist[7:13] - hist_n[7:13], 2.0 / 3.0 * kin * voigt(dEp), rtol=0,
                                   atol=1e-10 * max(1.0, kin) * np.max(np.abs(dEp)))
        assert hist[13] - hist_n[13] == pytest.approx(np.sum(T * dEp), rel=1e-10)
        # S = T : dE_log/dE, checked through the work identity S : dE = T : dE_log (central difference)
        E = green_lagrange(F)
        dE = 1e-7 * np.array([[1.0, 0.3, -0.2], [0.3, -0.5, 0.4], [-0.2, 0.4, 0.8]])
        dElog = log_strain(F_of_E(E + dE)) - log_strain(F_of_E(E - dE))
        assert np.sum(tensor(S) * 2.0 * dE) == pytest.approx(np.sum(T * dElog), rel=1e-7)
        hist_n = hist


def test_swift_and_voce_yield_on_uniaxial_path():
    """Swift and Voce along uniaxial stress: at every plastic step tau = sigma_y(alpha) of the law
    (von Mises, no kinematic hardening: the uniaxial Kirchhoff stress is the equivalent stress)."""
    for law in ("swift", "voce"):
        mat = make(law)
        path = np.linspace(0.002, 0.2, 12)
        for tau, lat, hist in uniaxial_diag(mat, path):
            assert hist[14] == 1.0
            assert tau == pytest.approx(sigma_y_ref(law, hist[6]), rel=1e-10)


def test_hardening_laws_python_reference():
    """yield_stress (Swift: derived K eps0^n) and the Python yield_stress_at agree with the closed forms."""
    assert make("swift").yield_stress == pytest.approx(500.0 * 0.01 ** 0.2, rel=1e-15)
    for law in sorted(LAWS):
        mat = make(law)
        for alpha in (0.0, 0.01, 0.3):
            assert mat.yield_stress_at(alpha) == pytest.approx(sigma_y_ref(law, alpha), rel=1e-14)


# ----------------------------------------------------------------------------------------------
# Hill: r-values from the material point


def uniaxial_T(mat: J2Plasticity, theta: float, eps: float, hist_n: np.ndarray) -> np.ndarray:
    """Uniaxial T along d = (cos theta, sin theta, 0) at log strain eps along d: the other five log-strain
    components (frame d, w, z) solved so that T (Hencky, from the returned history) is uniaxial."""
    c, s = math.cos(theta), math.sin(theta)
    Q = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # columns d, w, z

    def F_of(x):
        Er = tensor(np.array([eps, x[0], x[1], x[2], x[3], x[4]]))
        return expm_sym(Q @ Er @ Q.T)

    def resid(x):
        F = F_of(x)
        hist = j2_point(mat, F, hist_n)[2]
        Tr = Q.T @ hencky_T(mat, F, hist) @ Q
        return np.array([Tr[1, 1], Tr[2, 2], Tr[0, 1], Tr[1, 2], Tr[0, 2]]) / mat.E

    sol = root(resid, np.array([-0.5 * eps, -0.5 * eps, 0.0, 0.0, 0.0]), method="hybr", tol=1e-15)
    assert np.max(np.abs(resid(sol.x))) < 1e-13
    return j2_point(mat, F_of(sol.x), hist_n)[2], Q


@pytest.mark.parametrize("theta_deg, which", [(0.0, 0), (45.0, 1), (90.0, 2)])
def test_hill_r_values(theta_deg, which):
    """Lankford r = width / thickness plastic strain increment under uniaxial stress at theta from the
    rolling direction reproduces the r-value the Hill coefficients were built from."""
    mat = make("linear", 0.0, HILL_R)
    theta = math.radians(theta_deg)
    h1, Q = uniaxial_T(mat, theta, 0.004, np.zeros(NHIST))
    h2, _ = uniaxial_T(mat, theta, 0.01, h1)
    assert h1[14] == 1.0 and h2[14] == 1.0
    dEp = Q.T @ tensor(h2[0:6] - h1[0:6]) @ Q
    assert dEp[1, 1] / dEp[2, 2] == pytest.approx(HILL_R[which], rel=1e-8)


def test_hill_isotropic_r_values_match_von_mises():
    """r0 = r45 = r90 = 1 gives the von Mises coefficients; the Hill return mapping (Newton in s) and the
    radial return agree."""
    assert Hill48(1.0, 1.0, 1.0).coefficients == pytest.approx((0.5, 0.5, 0.5, 1.5, 1.5, 1.5), rel=1e-15)
    for law in sorted(LAWS):
        vm, hill = make(law, 1500.0), make(law, 1500.0, (1.0, 1.0, 1.0))
        hist_n = commit(vm, np.eye(3) + 0.5 * (F_GENERAL - np.eye(3)))
        a = j2_point(vm, F_GENERAL, hist_n)
        b = j2_point(hill, F_GENERAL, hist_n)
        np.testing.assert_allclose(b[0], a[0], rtol=1e-10, atol=1e-10 * np.max(np.abs(a[0])))
        np.testing.assert_allclose(b[1], a[1], rtol=1e-9, atol=1e-9 * np.max(np.abs(a[1])))
        np.testing.assert_allclose(b[2], a[2], rtol=1e-9, atol=1e-14)


# ----------------------------------------------------------------------------------------------
# 3. objectivity, 4. isochoric flow


def rotation(axis, angle) -> np.ndarray:
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
def test_superposed_rotation_leaves_S_and_history(hill):
    mat = make("voce", 1500.0, hill)
    Rq = rotation([1.0, -2.0, 0.5], 0.7)
    hist_n = commit(mat, np.eye(3) + 0.5 * (F_GENERAL - np.eye(3)))
    for F in (F_GENERAL, F_UNIAXIAL):
        S, D, hist, _ = j2_point(mat, F, hist_n)
        Sr, Dr, histr, _ = j2_point(mat, Rq @ F, hist_n)
        assert hist[14] == 1.0
        np.testing.assert_allclose(Sr, S, rtol=0, atol=1e-11 * np.max(np.abs(S)))
        np.testing.assert_allclose(Dr, D, rtol=0, atol=1e-11 * np.max(np.abs(D)))
        np.testing.assert_allclose(histr, hist, rtol=0, atol=1e-13 * max(1.0, np.max(np.abs(hist))))


@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
@pytest.mark.parametrize("law", sorted(LAWS))
def test_plastic_flow_is_isochoric(law, hill):
    mat = make(law, 1500.0, hill)
    hist = np.zeros(NHIST)
    for k in range(1, 6):
        F = np.eye(3) + 0.2 * k * (F_GENERAL - np.eye(3)) + 0.01 * k * (SHEAR - np.eye(3))
        hist = commit(mat, F, hist)
        assert hist[6] > 0.0
        assert abs(hist[0] + hist[1] + hist[2]) <= 1e-14 * np.max(np.abs(hist[0:6]))
        assert abs(hist[7] + hist[8] + hist[9]) <= 1e-12 * np.max(np.abs(hist[7:13]))


# ----------------------------------------------------------------------------------------------
# status codes and the material_update entry point


def test_inverted_element_status():
    mat = make("linear")
    S, D, hist, status = j2_point(mat, np.diag([1.0, 1.0, -1.0]), np.full(NHIST, 0.5))
    assert status == 1
    assert np.all(S == 0.0) and np.all(D == 0.0)
    assert np.all(hist == 0.5)


def test_material_update_dispatch():
    mat = make("swift", 1500.0, HILL_R)
    assert mat.kind == J2 == 2 and mat.n_hist == NHIST
    hist_n = commit(mat, np.eye(3) + 0.5 * (F_GENERAL - np.eye(3)))
    S, D, hist = np.empty(6), np.empty((6, 6)), np.empty(NHIST)
    assert material_update(mat.kind, mat.params, F_GENERAL, hist_n, hist, S, D) == 0
    ref = j2_point(mat, F_GENERAL, hist_n)
    np.testing.assert_array_equal(S, ref[0])
    np.testing.assert_array_equal(D, ref[1])
    np.testing.assert_array_equal(hist, ref[2])
    for m in (SaintVenantKirchhoff(E=210.0, nu=0.3), NeoHooke(E=210.0, nu=0.3)):
        assert m.kind in (SVK, NEO_HOOKE)
        S2, D2 = np.empty(6), np.empty((6, 6))
        e = np.empty(0)
        assert material_update(m.kind, m.params, F_GENERAL, e, e, S, D) == 0
        material_response(m.kind, m.params, F_GENERAL, S2, D2)
        np.testing.assert_array_equal(S, S2)
        np.testing.assert_array_equal(D, D2)


def test_params_layout_head():
    mat = make("voce", 1500.0, HILL_R)
    p = mat.params
    assert p.dtype == np.float64
    np.testing.assert_allclose(p[:4], [E_MOD, NU, mat.lam, mat.mu], rtol=1e-15)
    assert mat.lam == pytest.approx(E_MOD * NU / ((1 + NU) * (1 - 2 * NU)), rel=1e-15)


# ----------------------------------------------------------------------------------------------
# 5. validation


SWIFT = {"law": "swift", "K": 500.0, "eps0": 0.01, "n": 0.2}


@pytest.mark.parametrize("kwargs, match", [
    (dict(E=0.0), "Young's modulus"),
    (dict(E=-1.0), "Young's modulus"),
    (dict(nu=0.5), "Poisson's ratio"),
    (dict(nu=-1.0), "Poisson's ratio"),
    (dict(yield_stress=0.0), "yield stress must be > 0"),
    (dict(yield_stress=-5.0), "yield stress must be > 0"),
    (dict(yield_stress=None), "yield_stress is required"),
    (dict(hardening={"law": "linear", "modulus": -1.0}), "hardening modulus must be >= 0"),
    (dict(hardening={"law": "bilinear", "modulus": 1.0}), "unknown hardening law"),
    (dict(hardening={"law": "linear", "slope": 1.0}), "unknown parameter"),
    (dict(yield_stress=None, hardening={**SWIFT, "n": 1.0}), "Swift exponent n"),
    (dict(yield_stress=None, hardening={**SWIFT, "n": 0.0}), "Swift exponent n"),
    (dict(yield_stress=None, hardening={**SWIFT, "eps0": 0.0}), "Swift eps0"),
    (dict(yield_stress=None, hardening={**SWIFT, "eps0": -0.01}), "Swift eps0"),
    (dict(yield_stress=None, hardening={**SWIFT, "K": 0.0}), "Swift K"),
    (dict(yield_stress=200.0, hardening=SWIFT), "does not match the Swift law"),
    (dict(hardening={"law": "voce", "sigma_inf": 150.0, "delta": 10.0}), "Voce sigma_inf"),
    (dict(hardening={"law": "voce", "sigma_inf": 300.0, "delta": 0.0}), "Voce delta"),
    (dict(hardening={"law": "voce", "sigma_inf": 300.0, "delta": 10.0, "modulus": -2.0}),
     "Voce linear modulus"),
    (dict(kinematic_modulus=-1.0), "kinematic_modulus"),
    (dict(hill48=(1.0, 0.0, 1.0)), "r-value r45"),
    (dict(hill48=(-1.0, 1.0, 1.0)), "r-value r0"),
    (dict(hill48={"r0": 1.0, "r45": 1.0, "r90": -0.5}), "r-value r90"),
])
def test_validation(kwargs, match):
    args = dict(E=E_MOD, nu=NU, yield_stress=SY0, hardening={"law": "linear", "modulus": 100.0})
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        J2Plasticity(**args)


def test_swift_given_yield_stress_accepted_within_tolerance():
    sy = 500.0 * 0.01 ** 0.2
    mat = J2Plasticity(E=E_MOD, nu=NU, yield_stress=sy * (1.0 + 5e-7),
                       hardening=SwiftHardening(K=500.0, eps0=0.01, n=0.2))
    assert mat.yield_stress == pytest.approx(sy, rel=1e-6)
    with pytest.raises(ValueError, match="does not match"):
        J2Plasticity(E=E_MOD, nu=NU, yield_stress=sy * (1.0 + 2e-6),
                     hardening=SwiftHardening(K=500.0, eps0=0.01, n=0.2))


def test_hardening_dataclasses_accepted():
    a = J2Plasticity(E=E_MOD, nu=NU, yield_stress=SY0, hardening=VoceHardening(400.0, 20.0, 300.0))
    b = make("voce")
    np.testing.assert_array_equal(a.params, b.params)
    c = J2Plasticity(E=E_MOD, nu=NU, yield_stress=SY0, hardening=LinearHardening(2000.0),
                     hill48=Hill48(*HILL_R))
    d = make("linear", 0.0, {"r0": HILL_R[0], "r45": HILL_R[1], "r90": HILL_R[2]})
    np.testing.assert_array_equal(c.params, d.params)
