"""Piecewise-linear (tabular) isotropic hardening of the J2 plasticity, as an Abaqus or CalculiX *PLASTIC
table: sigma_y and its slope against hand values (beyond the last point constant, slope 0); the material
tangent against central differences in an elastic state, within a segment, across kinks, into and within
the perfectly plastic range beyond the last point and on elastic unloading; a two-point table against the
linear law; uniaxial stress (material point and a one-element problem) against the closed form
tau = sigma_y(alpha), eps = tau / E + alpha; one-line errors for impossible tables, from Python and from a
problem file. Every reference value is a hand value or a closed form."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from test_plasticity import (
    E_MOD,
    HILL_R,
    NU,
    commit,
    expm_sym,
    fd_tangent,
    hencky_T,
    hill_coef,
    hill_eq,
    rotation,
    tensor,
    uniaxial_diag,
)

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.materials import NHIST, J2Plasticity, j2_point
from covcontact.materials.plasticity import TableHardening, hardening_from_dict
from covcontact.materials.plasticity_kernels import NPARAMS, _hardening

# slopes 2000, 2500/3, 300, 50, then 0 (perfect plasticity from alpha = 0.2 on)
STRESS = [200.0, 240.0, 265.0, 280.0, 285.0]
STRAIN = [0.0, 0.02, 0.05, 0.1, 0.2]
TABLE = {"law": "table", "stress": STRESS, "strain": STRAIN}


def make(kin: float = 0.0, hill=None, table=TABLE) -> J2Plasticity:
    return J2Plasticity(E=E_MOD, nu=NU, hardening=table, kinematic_modulus=kin, hill48=hill)


# ----------------------------------------------------------------------------------------------
# 1. sigma_y and slope


# alpha, sigma_y, slope (by hand from STRESS, STRAIN; at a point the slope of the segment to its right)
HAND = [
    (0.0, 200.0, 2000.0),
    (0.01, 220.0, 2000.0),
    (0.02, 240.0, 25.0 / 0.03),
    (0.035, 252.5, 25.0 / 0.03),
    (0.05, 265.0, 300.0),
    (0.075, 272.5, 300.0),
    (0.15, 282.5, 50.0),
    (0.2, 285.0, 0.0),
    (0.2 + 1e-12, 285.0, 0.0),
    (3.0, 285.0, 0.0),
]


def test_sigma_y_and_slope_hand_values():
    mat = make()
    h = mat.hardening
    assert isinstance(h, TableHardening) and h.law == "table"
    assert mat.yield_stress == 200.0
    p = mat.params
    assert p.size == NPARAMS + 1 + 2 * len(STRESS)
    for alpha, sy, slope in HAND:
        assert h.sigma_y(alpha) == pytest.approx(sy, rel=1e-14)
        assert mat.yield_stress_at(alpha) == h.sigma_y(alpha)
        assert h.slope(alpha) == pytest.approx(slope, rel=1e-14)
        ks, kh = _hardening(p, alpha)  # the compiled law: the same numbers as the Python reference
        assert ks == h.sigma_y(alpha) and kh == h.slope(alpha)
    # one point: perfect plasticity at its stress
    one = make(table={"law": "table", "stress": [150.0], "strain": [0.0]})
    for alpha in (0.0, 0.1, 10.0):
        assert one.hardening.sigma_y(alpha) == 150.0 and one.hardening.slope(alpha) == 0.0
        assert _hardening(one.params, alpha) == (150.0, 0.0)


def test_fixed_params_part_unchanged():
    """The table is appended after the fixed part: its head is laid out as for the other laws."""
    lin = J2Plasticity(E=E_MOD, nu=NU, yield_stress=200.0, hardening={"law": "linear", "modulus": 0.0})
    p, q = make().params, lin.params
    assert q.size == NPARAMS
    same = [k for k in range(NPARAMS) if k not in (5,)]  # all but the law code
    np.testing.assert_array_equal(p[same], q[same])
    assert p[5] == 3.0 and p[NPARAMS] == len(STRESS)
    np.testing.assert_array_equal(p[NPARAMS + 1:], STRAIN + STRESS)


# ----------------------------------------------------------------------------------------------
# 2. tangent against central differences

ROT = rotation([1.0, -2.0, 0.5], 0.7)
G = np.array([[1.0, 0.3, -0.2], [0.3, -0.45, 0.25], [-0.2, 0.25, -0.35]])  # distinct eigenvalues


def F_at(t: float) -> np.ndarray:
    """A rotated stretch with log strain t G (mostly deviatoric, distinct eigenvalues)."""
    return ROT @ expm_sym(t * G)


def t_for(mat: J2Plasticity, alpha: float, hist_n: np.ndarray, t0: float) -> float:
    """The t > t0 at which one step from hist_n to F_at(t) ends at the equivalent plastic strain alpha
    (bisection; alpha grows monotonically with t on this path)."""
    lo, hi = t0, t0 + 1.0
    while j2_point(mat, F_at(hi), hist_n)[2][6] < alpha:
        hi *= 2.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if j2_point(mat, F_at(mid), hist_n)[2][6] < alpha:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


# state: (committed alpha_n or None for the virgin state, alpha of the step or None for an elastic step)
STATES = {
    "elastic": (None, None),
    "segment": (0.03, 0.04),  # within [0.02, 0.05)
    "kinks": (0.01, 0.075),  # from the first segment across two points into the third
    "beyond": (0.01, 0.3),  # across every point into the perfectly plastic range
    "perfect": (0.25, 0.3),  # within the perfectly plastic range
    "unloading": (0.075, None),  # elastic unloading after plastic flow
}


def segment(alpha: float) -> int:
    return int(np.searchsorted(STRAIN, alpha, side="right")) - 1


def on_the_table(mat: J2Plasticity, F: np.ndarray, hist: np.ndarray) -> None:
    """The yield condition of the returned state, T recomputed by numpy: sigma_bar(T - beta) = sigma_y(alpha)."""
    xi = hencky_T(mat, F, hist) - tensor(hist[7:13])
    assert hill_eq(xi, hill_coef(mat)) == pytest.approx(mat.yield_stress_at(hist[6]), rel=1e-11)


def _tangent_error(kin: float, hill, state: str) -> float:
    mat = make(kin, hill)
    alpha_n, alpha = STATES[state]
    if alpha_n is None:
        F, hist_n = F_at(1e-4), np.zeros(NHIST)
    else:
        t_n = t_for(mat, alpha_n, np.zeros(NHIST), 0.0)
        hist_n = commit(mat, F_at(t_n))
        assert hist_n[6] == pytest.approx(alpha_n, rel=1e-9)
        F = F_at(0.98 * t_n) if alpha is None else F_at(t_for(mat, alpha, hist_n, t_n))
    _, D, hist, status = j2_point(mat, F, hist_n)
    assert status == 0
    if alpha is None:
        assert hist[14] == 0.0 and hist[6] == hist_n[6]
    else:
        assert hist[14] == 1.0 and hist[6] == pytest.approx(alpha, rel=1e-9)
        on_the_table(mat, F, hist)
        # the converged alpha lies well inside its segment (FD steps of 1e-6 stay in it)
        assert min(abs(hist[6] - e) for e in STRAIN) > 1e-3
        crossed = segment(hist[6]) - segment(hist_n[6])
        assert crossed == {"segment": 0, "kinks": 2, "beyond": 4, "perfect": 0}[state]
    Dfd = fd_tangent(mat, F, hist_n)
    return float(np.max(np.abs(Dfd - D)) / np.max(np.abs(D)))


@pytest.mark.parametrize("state", sorted(STATES))
@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
@pytest.mark.parametrize("kin", [0.0, 1500.0], ids=["iso", "kin"])
def test_tangent_matches_central_differences(kin, hill, state):
    err = _tangent_error(kin, hill, state)
    assert err <= 1e-6, f"relative FD error {err:.2e}"


@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
def test_return_mapping_across_kinks_of_a_convex_table(hill):
    """Slopes growing from segment to segment (the radial-return residual concave, where Newton steps
    overshoot): one step from the virgin state across every point, and one across two points, converge onto
    the table, and the tangent still matches differences."""
    table = {"law": "table", "stress": [200.0, 205.0, 230.0, 300.0], "strain": [0.0, 0.05, 0.1, 0.13]}
    mat = make(0.0, hill, table)
    F = F_at(t_for(mat, 0.2, np.zeros(NHIST), 0.0))
    hist = commit(mat, F)  # status 0
    assert hist[6] == pytest.approx(0.2, rel=1e-9)
    on_the_table(mat, F, hist)
    t_n = t_for(mat, 0.02, np.zeros(NHIST), 0.0)
    hist_n = commit(mat, F_at(t_n))
    F = F_at(t_for(mat, 0.115, hist_n, t_n))
    _, D, hist, status = j2_point(mat, F, hist_n)
    assert status == 0 and segment_of(table, hist[6]) == 2
    on_the_table(mat, F, hist)
    Dfd = fd_tangent(mat, F, hist_n)
    assert np.max(np.abs(Dfd - D)) <= 1e-6 * np.max(np.abs(D))


def segment_of(table: dict, alpha: float) -> int:
    return int(np.searchsorted(table["strain"], alpha, side="right")) - 1


# ----------------------------------------------------------------------------------------------
# 3. the linear law and uniaxial stress


@pytest.mark.parametrize("hill", [None, HILL_R], ids=["mises", "hill"])
@pytest.mark.parametrize("kin", [0.0, 1500.0], ids=["iso", "kin"])
def test_two_points_reproduce_the_linear_law(kin, hill):
    lin = J2Plasticity(E=E_MOD, nu=NU, yield_stress=200.0, hardening={"law": "linear", "modulus": 2000.0},
                       kinematic_modulus=kin, hill48=hill)
    tab = make(kin, hill, {"law": "table", "stress": [200.0, 2200.0], "strain": [0.0, 1.0]})
    ha, hb = np.zeros(NHIST), np.zeros(NHIST)
    for t in (0.001, 0.02, 0.05, 0.04, 0.1, 0.3):  # elastic, plastic, unloading, plastic again
        Sa, Da, ha, sa = j2_point(lin, F_at(t), ha)
        Sb, Db, hb, sb = j2_point(tab, F_at(t), hb)
        assert sa == sb == 0 and ha[14] == hb[14]
        np.testing.assert_allclose(Sb, Sa, rtol=0, atol=1e-12 * np.max(np.abs(Sa)))
        np.testing.assert_allclose(Db, Da, rtol=0, atol=1e-12 * np.max(np.abs(Da)))
        np.testing.assert_allclose(hb, ha, rtol=0, atol=1e-12 * max(1.0, np.max(np.abs(ha))))
    assert ha[6] > 0.1


def uniaxial_closed_form(eps: float, alpha_n: float = 0.0) -> tuple[float, float]:
    """(tau, alpha) of uniaxial stress at log strain eps on monotonic loading, von Mises, isotropic
    hardening: elastic tau = E (eps - alpha_n) up to sigma_y(alpha_n); plastic tau = sigma_y(alpha) with
    eps = tau / E + alpha, i.e. on the segment i: alpha = (E eps - s_i + H_i e_i) / (E + H_i); beyond the
    last point tau = s_last."""
    e, s = STRAIN, STRESS
    if E_MOD * (eps - alpha_n) <= np.interp(alpha_n, e, s):
        return E_MOD * (eps - alpha_n), alpha_n
    for i in range(len(e) - 1):
        H = (s[i + 1] - s[i]) / (e[i + 1] - e[i])
        a = (E_MOD * eps - s[i] + H * e[i]) / (E_MOD + H)
        if e[i] <= a < e[i + 1]:
            return s[i] + H * (a - e[i]), a
    return s[-1], eps - s[-1] / E_MOD


def test_uniaxial_material_point_follows_the_table():
    """Large steps, several crossing points, the last ones beyond the table: tau = sigma_y(alpha) and the
    closed form, lateral log strain -nu tau / E - alpha / 2."""
    mat = make()
    path = [0.0005, 0.005, 0.03, 0.031, 0.09, 0.2, 0.35, 0.5]
    for eps, (tau, lat, hist) in zip(path, uniaxial_diag(mat, path), strict=True):
        tau_ref, alpha_ref = uniaxial_closed_form(eps)
        assert hist[14] == (1.0 if alpha_ref > 0.0 else 0.0)
        assert tau == pytest.approx(tau_ref, rel=1e-10)
        assert hist[6] == pytest.approx(alpha_ref, rel=1e-9, abs=1e-15)
        if alpha_ref > 0.0:
            assert tau == pytest.approx(mat.yield_stress_at(hist[6]), rel=1e-10)
        np.testing.assert_allclose(lat, -NU * tau_ref / E_MOD - 0.5 * alpha_ref, rtol=1e-9, atol=1e-15)


# one hex8 element, unit cube, symmetry conditions, the face x = 1 pulled: homogeneous uniaxial stress
FACTORS = [0.001, 0.01, 0.04, 0.1, 0.2, 0.35, 0.5]  # log strains up to ln 1.5, crossing every point
STRETCH = 0.5
PROBLEM = f"""
[problem]
name = "table-hardening"

[[bodies]]
name = "bar"
element = "hex8"
material = {{ model = "j2", E = {E_MOD}, nu = {NU}, hardening = {{ law = "table", stress = {STRESS}, \
strain = {STRAIN} }} }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }}

[[dirichlet]]
set = "bar.xmin"
components = "x"

[[dirichlet]]
set = "bar.ymin"
components = "y"

[[dirichlet]]
set = "bar.zmin"
components = "z"

[[dirichlet]]
set = "bar.xmax"
components = "x"
value = {STRETCH}

[solver]
rtol = 1.0e-12

[steps]
factors = {FACTORS}

[output]
vtu = false
"""


def test_one_element_uniaxial_tension_follows_the_table(tmp_path):
    """Reaction A0 tau / lambda of a one-element bar against the closed form, step by step (each step
    from the committed state: the closed form of monotonic loading does not depend on the steps)."""
    path = tmp_path / "bar.toml"
    path.write_text(PROBLEM)
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    lam = 1.0 + STRETCH * np.array(FACTORS)
    tau = np.array([-s["reactions"]["bar.xmin"][0] for s in summary["steps"]]) * lam
    ref = np.array([uniaxial_closed_form(math.log(v))[0] for v in lam])
    np.testing.assert_allclose(tau, ref, rtol=1e-8)
    assert ref[-1] == STRESS[-1] and ref[0] < STRESS[0]  # elastic first step, perfectly plastic last
    alpha = res.state.elements[0]["hist"][:, :, 6]
    np.testing.assert_allclose(alpha, uniaxial_closed_form(math.log(lam[-1]))[1], rtol=1e-8)


# ----------------------------------------------------------------------------------------------
# 4. impossible tables


BAD = [
    ({"strain": [0.0, 0.1, 0.05]}, "table hardening strain must be strictly increasing"),
    ({"strain": [0.0, 0.1, 0.1]}, "table hardening strain must be strictly increasing"),
    ({"strain": [0.01, 0.05, 0.1]}, "table hardening strain must start at 0"),
    ({"strain": [0.0, 0.1]}, "table hardening stress and strain must have the same length"),
    ({"stress": [200.0, -250.0, 280.0]}, "table hardening stress must be > 0"),
    ({"stress": [0.0, 250.0, 280.0]}, "table hardening stress must be > 0"),
    ({"stress": [], "strain": []}, "table hardening needs at least one point"),
]


@pytest.mark.parametrize("change, message", BAD)
def test_bad_table(change, message):
    spec = {"law": "table", "stress": [200.0, 250.0, 280.0], "strain": [0.0, 0.05, 0.2], **change}
    for build in (lambda: hardening_from_dict(spec), lambda: make(table=spec),
                  lambda: TableHardening(spec["stress"], spec["strain"])):
        with pytest.raises(ValueError, match=message) as err:
            build()
        assert "\n" not in str(err.value)


@pytest.mark.parametrize("spec, message", [
    ({"law": "table", "stress": [200.0]}, "hardening law 'table' needs"),
    ({"law": "table", "stress": 200.0, "strain": 0.0}, "table hardening stress must be a list of numbers"),
    ({"law": "table", "stress": [200.0], "strain": ["x"]}, "table hardening strain must be a list of numbers"),
    ({"law": "table", "stress": [200.0], "strain": [0.0], "modulus": 1.0}, "unknown parameter"),
])
def test_bad_table_dict(spec, message):
    with pytest.raises(ValueError, match=message) as err:
        hardening_from_dict(spec)
    assert "\n" not in str(err.value)


def test_yield_stress_must_match_the_first_point():
    assert make(table=TABLE).yield_stress == 200.0
    ok = J2Plasticity(E=E_MOD, nu=NU, yield_stress=200.0 * (1.0 + 5e-7), hardening=TABLE)
    assert ok.yield_stress == pytest.approx(200.0, rel=1e-6)
    with pytest.raises(ValueError, match="does not match the table's first stress"):
        J2Plasticity(E=E_MOD, nu=NU, yield_stress=210.0, hardening=TABLE)


@pytest.mark.parametrize("old, new, message", [
    (f"strain = {STRAIN}", "strain = [0.0, 0.05, 0.02, 0.1, 0.2]", "strain must be strictly increasing"),
    (f"strain = {STRAIN}", "strain = [0.001, 0.02, 0.05, 0.1, 0.2]", "strain must start at 0"),
    (f"strain = {STRAIN}", "strain = [0.0, 0.02, 0.05, 0.1]", "stress and strain must have the same length"),
    (f"stress = {STRESS}", "stress = [200.0, 240.0, -265.0, 280.0, 285.0]", "stress must be > 0"),
    (f"stress = {STRESS}", "stress = 200.0", "stress: must be an array of numbers"),
    (f", strain = {STRAIN}", "", "strain: missing required key"),
    (f"strain = {STRAIN}", "strain = [0.0, 0.02, 0.05, 0.1, 0.2], modulus = 1.0", "modulus: unknown key"),
    ("E = ", "yield_stress = 250.0, E = ", "does not match the table's first stress"),
])
def test_bad_table_in_a_problem_file(tmp_path, old, new, message):
    assert old in PROBLEM
    path = tmp_path / "bad.toml"
    path.write_text(PROBLEM.replace(old, new))
    with pytest.raises(InputError) as err:
        load_problem(path)
    msg = str(err.value)
    assert message in msg and "bad.toml" in msg and "bodies[0].material" in msg and "\n" not in msg
