"""The rubber models of the Abaqus / CalculiX manuals (covcontact.materials.rubber): stress and tangent against
central differences, the energy against independent formulas in the principal stretches (complex-step
derivatives), the homogeneous uniaxial, equibiaxial and pure-shear closed forms, the initial moduli, the input
keys and their errors, and a one-element run."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.materials.hyperelastic import material_response_h, strain_energy, stress_tangent
from covcontact.materials.rubber import Rubber, RubberError, moduli_notes, rubber_from_keys

PAIRS = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
AB = (0.5, 1.0 / 20.0, 11.0 / 1050.0, 19.0 / 7000.0, 519.0 / 673750.0)

MODELS = {
    "neo-hooke": Rubber("neo-hooke", c=((1, 0, 0.5),), d=(0.01,)),
    "mooney-rivlin": Rubber("mooney-rivlin", c=((1, 0, 0.4), (0, 1, 0.1)), d=(0.05,)),
    "polynomial-2": Rubber("polynomial", c=((1, 0, 0.4), (0, 1, 0.1), (2, 0, 0.02), (1, 1, -0.01), (0, 2, 0.005)),
                           d=(0.05, 0.1)),
    "reduced-6": Rubber("reduced-polynomial", c=tuple((i, 0, 0.5 * (-0.1) ** (i - 1)) for i in range(1, 7)),
                        d=(0.05, 0.1, 0.0, 0.0, 0.0, 0.3)),
    "yeoh": Rubber("yeoh", c=((1, 0, 0.5), (2, 0, -0.02), (3, 0, 0.003)), d=(0.02, 0.05, 0.1)),
    "arruda-boyce": Rubber("arruda-boyce", mu=(0.8,), lambda_m=2.5, d=(0.05,)),
    "gent": Rubber("gent", mu=(0.8,), jm=20.0, d=(0.05,)),
    "ogden-3": Rubber("ogden", mu=(0.6, 0.01, -0.02), alpha=(1.3, 5.0, -2.0), d=(0.05, 0.02, 0.01)),
    "ogden-6": Rubber("ogden", mu=(0.3, 0.2, 0.1, 0.05, -0.01, 0.02), alpha=(2.0, 1.0, 3.0, -1.5, -3.0, 0.5),
                      d=(0.05,)),
}


def _rotation(seed: int) -> np.ndarray:
    Q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    return Q * np.sign(np.linalg.det(Q))


def _stretched(lams, seed=3) -> np.ndarray:
    """F = Q diag(lams) Q^T (principal axes turned off the coordinate axes)."""
    Q = _rotation(seed)
    return Q @ np.diag(lams) @ Q.T


_F = {
    "random": np.eye(3) + 0.3 * np.random.default_rng(0).standard_normal((3, 3)),
    "uniaxial-3": np.diag([3.0, 3.0 ** -0.5, 3.0 ** -0.5]),
    "large-3": _stretched([3.0, 0.7, 0.45]),
    "two-equal": _stretched([1.2, 1.2, 0.8]),
    "nearly-equal-1e-4": _stretched([1.2, 1.2 * (1.0 + 1e-4), 0.8]),
    "nearly-equal-1e-7": _stretched([1.2, 1.2 * (1.0 + 1e-7), 0.8]),
    "nearly-equal-1e-11": _stretched([1.2, 1.2 * (1.0 + 1e-11), 0.8]),
    "three-equal": 1.05 * np.eye(3),
    "three-nearly-equal": _stretched([1.05, 1.05 * (1.0 + 3e-8), 1.05 * (1.0 - 2e-8)]),
    "J-near-1": np.eye(3) + 1e-4 * np.random.default_rng(1).standard_normal((3, 3)),
}


def _sqrtm(C):
    w, V = np.linalg.eigh(C)
    return (V * np.sqrt(w)) @ V.T


def _perturbed(F, J, h):
    """The symmetric stretch whose Green-Lagrange strain is E(F) plus h in Voigt component J (engineering shear)."""
    i, j = PAIRS[J]
    C = F.T @ F
    dC = np.zeros((3, 3))
    dC[i, j] += h
    dC[j, i] += h
    return _sqrtm(C + dC)  # (dE_ii = h: dC_ii = 2h; dgamma_ij = h: dC_ij = dC_ji = h)


@pytest.mark.parametrize("fname", list(_F))
@pytest.mark.parametrize("model", list(MODELS))
def test_stress_and_tangent_against_central_differences(model, fname):
    """S = dW/dE by central differences of material_energy and D = dS/dE by central differences of S (h = 1e-6
    in E), each to 1e-6 of its largest entry; D is symmetric."""
    mat, F = MODELS[model], _F[fname]
    S, D, status = stress_tangent(mat, F)
    assert status == 0
    h = 1e-6
    Sfd = np.empty(6)
    Dfd = np.empty((6, 6))
    for J in range(6):
        Fp, Fm = _perturbed(F, J, h), _perturbed(F, J, -h)
        Sfd[J] = (strain_energy(mat, Fp) - strain_energy(mat, Fm)) / (2.0 * h)
        Dfd[:, J] = (stress_tangent(mat, Fp)[0] - stress_tangent(mat, Fm)[0]) / (2.0 * h)
    assert np.abs(S - Sfd).max() <= 1e-6 * np.abs(S).max()
    assert np.abs(D - Dfd).max() <= 1e-6 * np.abs(D).max()
    assert np.abs(D - D.T).max() <= 1e-13 * np.abs(D).max()


# -- the manuals' energies, written in the principal stretches (independent of the kernels) ------------------


def _energy(mat: Rubber, l):
    """W(lambda_1, lambda_2, lambda_3) as the Abaqus / CalculiX manuals write it (complex-safe)."""
    l1, l2, l3 = l
    J = l1 * l2 * l3
    if mat.model == "ogden":
        lb = [x * J ** (-1.0 / 3.0) for x in l]
        W = sum(2.0 * m / a ** 2 * (lb[0] ** a + lb[1] ** a + lb[2] ** a - 3.0) for m, a in zip(mat.mu, mat.alpha))
    else:
        I1b = J ** (-2.0 / 3.0) * (l1 ** 2 + l2 ** 2 + l3 ** 2)
        I2b = J ** (-4.0 / 3.0) * ((l1 * l2) ** 2 + (l2 * l3) ** 2 + (l1 * l3) ** 2)
        if mat.model == "arruda-boyce":
            W = mat.mu[0] * sum(c / mat.lambda_m ** (2 * i) * (I1b ** (i + 1) - 3.0 ** (i + 1))
                                for i, c in enumerate(AB))
            return W + 1.0 / mat.d[0] * ((J ** 2 - 1.0) / 2.0 - np.log(J))
        if mat.model == "gent":
            W = -mat.mu[0] * mat.jm / 2.0 * np.log(1.0 - (I1b - 3.0) / mat.jm)
        else:
            W = sum(c * (I1b - 3.0) ** i * (I2b - 3.0) ** j for i, j, c in mat.c)
    return W + sum((J - 1.0) ** (2 * (i + 1)) / D for i, D in enumerate(mat.d) if D != 0.0)


def _dW(mat, l, a):
    """dW/dlambda_a by a complex step (exact to round-off)."""
    z = np.array(l, dtype=complex)
    z[a] += 1e-30j
    return _energy(mat, z).imag / 1e-30


@pytest.mark.parametrize("model", list(MODELS))
def test_energy_and_principal_stresses_are_the_manuals(model):
    """W and the principal nominal stresses dW/dlambda_a of the kernels equal the manuals' formulas written in the
    principal stretches (their derivatives by complex steps) to 1e-12, at stretches from 0.5 to 3 with J != 1."""
    mat = MODELS[model]
    Q = _rotation(5)
    for l in ([1.3, 0.9, 1.2], [3.0, 0.6, 0.5], [0.5, 1.4, 1.5], [1.1, 1.1, 0.95]):
        F = Q @ np.diag(l)
        assert strain_energy(mat, F) == pytest.approx(_energy(mat, np.array(l)), rel=1e-12)
        S = stress_tangent(mat, F)[0]
        Sm = np.array([[S[0], S[3], S[5]], [S[3], S[1], S[4]], [S[5], S[4], S[2]]])
        P = np.array([Sm[a, a] * l[a] for a in range(3)])  # (F = Q diag(l): the principal axes are the x, y, z axes)
        ref = np.array([_dW(mat, l, a) for a in range(3)])
        assert np.abs(P - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.abs(Sm - np.diag(np.diag(Sm))).max() <= 1e-12 * np.abs(ref).max()


# -- homogeneous incompressible tests --------------------------------------------------------------------------


def _invariant_derivatives(mat, I1b, I2b):
    """dW/dI1bar, dW/dI2bar of the invariant models (written out from the manuals' W)."""
    if mat.model == "arruda-boyce":
        return mat.mu[0] * sum((i + 1) * c / mat.lambda_m ** (2 * i) * I1b ** i for i, c in enumerate(AB)), 0.0
    if mat.model == "gent":
        return mat.mu[0] / 2.0 / (1.0 - (I1b - 3.0) / mat.jm), 0.0
    W1 = sum(i * c * (I1b - 3.0) ** (i - 1) * (I2b - 3.0) ** j for i, j, c in mat.c if i > 0)
    W2 = sum(j * c * (I1b - 3.0) ** i * (I2b - 3.0) ** (j - 1) for i, j, c in mat.c if j > 0)
    return W1, W2


def _closed_form(mat, test, lam):
    """The nominal stress of an incompressible solid (Treloar; Ogden, Non-linear elastic deformations, 1984,
    section 7.2; the Abaqus Theory Manual's hyperelastic test-data section): uniaxial
    P = 2 (lam - lam^-2) (W1 + W2 / lam), equibiaxial P = 2 (lam - lam^-5) (W1 + lam^2 W2), pure shear (planar)
    P = 2 (lam - lam^-3) (W1 + W2); Ogden sum 2 mu_p / alpha_p (lam^(alpha_p - 1) - lam^(-k alpha_p - 1)) with k =
    1/2, 2, 1."""
    if mat.model == "ogden":
        k = {"uniaxial": 0.5, "equibiaxial": 2.0, "planar": 1.0}[test]
        return sum(2.0 * m / a * (lam ** (a - 1.0) - lam ** (-k * a - 1.0)) for m, a in zip(mat.mu, mat.alpha))
    if test == "uniaxial":
        I1, I2 = lam ** 2 + 2.0 / lam, 2.0 * lam + lam ** -2
        W1, W2 = _invariant_derivatives(mat, I1, I2)
        return 2.0 * (lam - lam ** -2) * (W1 + W2 / lam)
    if test == "equibiaxial":
        I1, I2 = 2.0 * lam ** 2 + lam ** -4, lam ** 4 + 2.0 * lam ** -2
        W1, W2 = _invariant_derivatives(mat, I1, I2)
        return 2.0 * (lam - lam ** -5) * (W1 + lam ** 2 * W2)
    I1 = I2 = lam ** 2 + 1.0 + lam ** -2
    W1, W2 = _invariant_derivatives(mat, I1, I2)
    return 2.0 * (lam - lam ** -3) * (W1 + W2)


@pytest.mark.parametrize("test", ["uniaxial", "equibiaxial", "planar"])
@pytest.mark.parametrize("model", list(MODELS))
def test_homogeneous_tests_against_closed_forms(model, test):
    """At the isochoric stretch of each test (J = 1: the volumetric part adds only a pressure) the kernels' Kirchhoff
    stress difference (tau_11 - tau_33) / lam is the incompressible nominal stress of the closed form (the pressure,
    the Lagrange multiplier of incompressibility, drops out of the difference), to 1e-10 at lam = 0.5 ... 3."""
    mat = MODELS[model]
    for lam in (0.5, 0.8, 1.3, 2.0, 3.0):
        l = {"uniaxial": [lam, lam ** -0.5, lam ** -0.5], "equibiaxial": [lam, lam ** -2, lam],
             "planar": [lam, lam ** -1, 1.0]}[test]
        F = np.diag(l)
        S = stress_tangent(mat, F)[0]
        tau = np.array(l) ** 2 * S[:3]
        P = (tau[0] - tau[1]) / lam
        assert P == pytest.approx(_closed_form(mat, test, lam), rel=1e-10, abs=1e-12)


def test_equivalent_models():
    """Ogden with alpha = 2 is Neo-Hooke with C10 = mu / 2; with alpha = 2 and -2 it is Mooney-Rivlin (C10 = mu_1 / 2,
    C01 = mu_2 / 2); the reduced polynomial with N = 1 and Yeoh with C20 = C30 = 0 are Neo-Hooke; the polynomial
    with N = 1 is Mooney-Rivlin; Gent tends to Neo-Hooke (C10 = mu / 2) as J_m grows."""
    F = _F["random"]

    def same(a, b, rel=1e-12):
        Sa, Da, _ = stress_tangent(a, F)
        Sb, Db, _ = stress_tangent(b, F)
        assert np.abs(Sa - Sb).max() <= rel * np.abs(Sa).max() and np.abs(Da - Db).max() <= rel * np.abs(Da).max()

    nh = Rubber("neo-hooke", c=((1, 0, 0.35),), d=(0.04,))
    mr = Rubber("mooney-rivlin", c=((1, 0, 0.35), (0, 1, 0.12)), d=(0.04,))
    same(Rubber("ogden", mu=(0.7,), alpha=(2.0,), d=(0.04,)), nh)
    same(Rubber("ogden", mu=(0.7, 0.24), alpha=(2.0, -2.0), d=(0.04,)), mr)
    same(Rubber("reduced-polynomial", c=((1, 0, 0.35),), d=(0.04,)), nh)
    same(Rubber("yeoh", c=((1, 0, 0.35), (2, 0, 0.0), (3, 0, 0.0)), d=(0.04,)), nh)
    same(Rubber("polynomial", c=((1, 0, 0.35), (0, 1, 0.12)), d=(0.04,)), mr)
    same(Rubber("gent", mu=(0.7,), jm=1e9, d=(0.04,)), nh, rel=1e-8)


@pytest.mark.parametrize("model", list(MODELS))
def test_initial_moduli_and_small_strain_precision(model):
    """At F = I the tangent is Hooke's with the model's mu0 and K0 (mu0 = 2 (C10 + C01), Arruda-Boyce's series, Gent's
    mu, Ogden's sum of mu_i; K0 = 2 / D1) to 1e-12; at a strain of 1e-9 formed from the displacement gradient the
    stress is D0 : E to 1e-6 (every digit of a small strain kept)."""
    mat = MODELS[model]
    mu0, K0 = mat.mu0, mat.K0
    expected = {"neo-hooke": 1.0, "mooney-rivlin": 1.0, "polynomial-2": 1.0, "reduced-6": 1.0, "yeoh": 1.0,
                "gent": 0.8, "ogden-3": 0.59, "ogden-6": 0.66,
                "arruda-boyce": 0.8 * (1 + 3 / (5 * 2.5 ** 2) + 99 / (175 * 2.5 ** 4) + 513 / (875 * 2.5 ** 6)
                                       + 42039 / (67375 * 2.5 ** 8))}[model]
    assert mu0 == pytest.approx(expected, rel=1e-14)
    assert K0 == pytest.approx(2.0 / mat.d[0], rel=1e-14)
    S, D, _ = stress_tangent(mat, np.eye(3))
    lam = K0 - 2.0 * mu0 / 3.0
    D0 = np.zeros((6, 6))
    D0[:3, :3] = lam
    D0[range(3), range(3)] += 2.0 * mu0
    D0[range(3, 6), range(3, 6)] = mu0
    assert np.abs(S).max() <= 1e-14 * K0
    assert np.abs(D - D0).max() <= 1e-12 * K0
    assert mat.E == pytest.approx(9.0 * K0 * mu0 / (3.0 * K0 + mu0), rel=1e-14)
    assert mat.params[3] == mu0 and mat.params[2] == pytest.approx(lam, rel=1e-14)
    H = 1e-9 * np.array([[0.3, -0.7, 0.2], [0.4, 1.0, -0.5], [0.1, 0.6, -0.2]])
    S = np.empty(6)
    Dh = np.empty((6, 6))
    assert material_response_h(mat.kind, mat.params, np.eye(3) + H, H, S, Dh) == 0
    E = 0.5 * (H + H.T)
    e = np.array([E[0, 0], E[1, 1], E[2, 2], 2 * E[0, 1], 2 * E[1, 2], 2 * E[0, 2]])
    assert np.abs(S - D0 @ e).max() <= 1e-6 * np.abs(D0 @ e).max()


def test_inadmissible_points():
    """det F <= 0, and Gent beyond its limit I1bar - 3 = J_m: status 1, S = D = 0, W = inf."""
    F = np.diag([1.0, 1.0, -1.0])
    for mat in MODELS.values():
        S, D, status = stress_tangent(mat, F)
        assert status == 1 and not S.any() and not D.any() and strain_energy(mat, F) == np.inf
    gent = Rubber("gent", mu=(1.0,), jm=2.0, d=(0.1,))
    F = np.diag([2.5, 2.5 ** -0.5, 2.5 ** -0.5])  # I1bar - 3 = 3.05 > J_m
    assert stress_tangent(gent, F)[2] == 1 and strain_energy(gent, F) == np.inf


# -- input ------------------------------------------------------------------------------------------------


def test_keys_make_the_models():
    """Problem-file keys as Abaqus names the constants."""
    m = rubber_from_keys("mooney-rivlin", {"c10": 0.4, "c01": 0.1, "d1": 0.05})
    assert m.mu0 == pytest.approx(1.0) and m.K0 == pytest.approx(40.0)
    m = rubber_from_keys("polynomial", {"c10": 0.4, "c11": 0.01, "d1": 0.05, "d2": 0.1})
    assert m.order == 2 and m.d == (0.05, 0.1)
    m = rubber_from_keys("polynomial", {"c10": 0.4, "d1": 0.05, "n": 3})
    assert m.order == 3
    m = rubber_from_keys("reduced-polynomial", {"c10": 0.4, "c60": 1e-6, "d1": 0.05})
    assert m.order == 6
    m = rubber_from_keys("ogden", {"mu": [0.6, 0.01], "alpha": [1.3, 5.0], "d": [0.05]})
    assert m.mu0 == pytest.approx(0.61)
    m = rubber_from_keys("neo_hooke", {"c10": 0.5, "d1": 0.01})
    assert m.model == "neo-hooke" and m.kind == 3
    assert rubber_from_keys("arruda-boyce", {"mu": 1.0, "lambda_m": 3.0, "d": 0.01}).K0 == pytest.approx(200.0)
    assert rubber_from_keys("gent", {"mu": 1.0, "jm": 30.0, "d1": 0.01}).mu0 == 1.0


BAD = [
    ("mooney-rivlin", {"c10": -0.4, "c01": 0.1, "d1": 0.05}, "c10", "initial shear modulus"),
    ("neo-hooke", {"c10": 0.4, "d1": -0.05}, "d1", "initial bulk modulus"),
    ("neo-hooke", {"c10": 0.4, "d1": 0.0}, "d1", "incompressible"),
    ("ogden", {"mu": [1.0, 0.1], "alpha": [2.0, 0.0], "d": [0.1]}, "alpha", "alpha[1] = 0"),
    ("ogden", {"mu": [1.0, 0.1], "alpha": [2.0], "d": [0.1]}, "alpha", "one alpha per mu"),
    ("ogden", {"mu": [1.0], "alpha": [2.0], "d": [0.1, 0.2]}, "d", "D_1..D_N"),
    ("ogden", {"mu": [0.1] * 7, "alpha": [2.0] * 7, "d": [0.1]}, "mu", "above 6"),
    ("ogden", {"mu": [-1.0], "alpha": [2.0], "d": [0.1]}, "mu", "initial shear modulus"),
    ("reduced-polynomial", {"c10": 0.4, "c70": 0.1, "d1": 0.1}, "c70", "above 6"),
    ("polynomial", {"c10": 0.4, "d1": 0.1, "n": 7}, "n", "above 6"),
    ("polynomial", {"c10": 0.4, "c21": 0.1, "d1": 0.1, "n": 2}, "c21", "above the model's n"),
    ("mooney-rivlin", {"c10": 0.4, "c20": 0.1, "d1": 0.1}, "c20", "not a constant"),
    ("yeoh", {"c10": 0.4, "d1": 0.1, "d4": 0.1}, "d4", "order"),
    ("arruda-boyce", {"mu": 1.0, "lambda_m": 0.0, "d": 0.1}, "lambda_m", "> 0"),
    ("gent", {"mu": 1.0, "jm": 10.0}, "d1", "missing"),
    ("neo-hooke", {"c10": 0.4, "d1": 0.1, "c01": 0.1}, "c01", "not a constant"),
]


@pytest.mark.parametrize("model, keys, key, words", BAD, ids=[f"{b[0]}-{b[2]}-{i}" for i, b in enumerate(BAD)])
def test_bad_constants_name_the_key(tmp_path, model, keys, key, words):
    with pytest.raises(RubberError) as err:
        rubber_from_keys(model, keys)
    assert err.value.key == key and words in str(err.value)
    text = ", ".join(f"{k} = {v}" for k, v in keys.items())
    path = tmp_path / "p.toml"
    path.write_text(CUBE.replace("MATERIAL", f'{{ model = "{model}", {text} }}'))
    with pytest.raises(InputError) as err:
        load_problem(path)
    line = str(err.value)
    assert "\n" not in line and f"bodies[0].material.{key}:" in line and words in line


# -- a run ----------------------------------------------------------------------------------------------------

CUBE = """
[problem]
name = "cube"
[[bodies]]
name = "cube"
element = "hex8"
material = MATERIAL
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }
[[dirichlet]]
set = "cube.xmin"
components = "x"
[[dirichlet]]
set = "cube.ymin"
components = "y"
[[dirichlet]]
set = "cube.zmin"
components = "z"
[[dirichlet]]
set = "cube.xmax"
components = "x"
value = 1.0
[steps]
count = 4
[solver]
rtol = 1e-10
"""


@pytest.mark.parametrize("material, mat", [
    ('{ model = "mooney-rivlin", c10 = 0.4, c01 = 0.1, d1 = 0.05 }', MODELS["mooney-rivlin"]),
    ('{ model = "ogden", mu = [0.6, 0.01, -0.02], alpha = [1.3, 5.0, -2.0], d = [0.05, 0.02, 0.01] }',
     MODELS["ogden-3"]),
])
def test_one_element_uniaxial_stretch(tmp_path, capsys, material, mat):
    """A unit hex8 cube on symmetry planes stretched to twice its length: the reaction equals the compressible
    uniaxial closed form (the lateral stretch t from dW/dlambda_2 (2, t, t) = 0, the force dW/dlambda_1 (2, t, t),
    the manuals' W differentiated by complex steps) to 1e-10; the Newton iterations converge quadratically; the run
    says the initial moduli once."""
    path = tmp_path / "cube.toml"
    path.write_text(CUBE.replace("MATERIAL", material))
    prob = load_problem(path)
    notes = moduli_notes(prob.bodies)
    assert len(notes) == 1 and "initial shear modulus" in notes[0]
    res = prob.run(out=tmp_path / "out", quiet=False)
    assert res.exit_code == 0
    err = capsys.readouterr().err
    assert err.count("note: body 'cube': ") == 1 and f"mu0 = sum of mu_i = {mat.mu0:.6g}" in err \
        if mat.model == "ogden" else f"mu0 = 2 (c10 + c01) = {mat.mu0:.6g}" in err
    t = brentq(lambda t: _dW(mat, [2.0, t, t], 1), 0.3, 1.2, xtol=1e-15)
    reaction = res.summary["steps"][-1]["reactions"]["cube.xmax"][0]
    assert reaction == pytest.approx(_dW(mat, [2.0, t, t], 0), rel=1e-10)
    assert max(s["iterations"] for s in res.summary["steps"]) <= 6
