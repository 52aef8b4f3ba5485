"""Tangent sweeps: the consistent tangents of the J2 material point and of the elements against central
finite differences over load paths, with the committed history of the previous increment.

1. Material point (log-strain J2, every hardening law, isotropic and kinematic, von Mises and Hill): the
   principal stretches are distinct, nearly equal (relative gaps 4e-4, at the Taylor switch-over of the
   divided differences, 1e-6 and 1e-9) or exactly equal pairs, in a random principal frame and under a
   random superposed rotation; the path loads elastically, just past yield (eps_p = 1e-6, 1e-4), to large
   plastic strain (eps_p = 0.3, 1.0), unloads elastically, reloads in reverse into reverse yield and ends
   at three (nearly) equal stretches (pure volume change: reverse plastic flow from the large E_p).
2. Elements on two randomly distorted elements along a random nodal displacement path with a growing
   rigid rotation (plastic loading, partial elastic unloading, reverse loading): hex8, F-bar hex8 (spatial
   and variational form), F-bar hex27, solid-shell hex8 and hex18 with 2 and 5 Gauss and 3 Lobatto points
   through the thickness (EAS on, the thickness EAS modes of plastic materials included), J2 and one
   hyperelastic material.

A state is checked only where no yield flag changes between the +h and -h evaluations, which is asserted:
a crossing of the yield surface within the difference step fails as such, never as a tangent error.
Measured errors (h = 1e-7): material point <= 2e-8, elements <= 5e-9 (relative to max |D| or max |K|).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from covcontact.assembly import Pattern
from covcontact.elements.fbar import FbarBody
from covcontact.elements.solid import SolidBody
from covcontact.elements.solidshell import SolidShellBody
from covcontact.fem.shapes import NODES
from covcontact.materials import NHIST, J2Plasticity, NeoHooke, j2_point
from covcontact.materials.plasticity import H_ALPHA, H_FLAG

PAIRS = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]
HILL_R = (1.8, 1.2, 2.2)  # r0, r45, r90
TOL = 1e-6  # relative FD error accepted (measured <= 2e-8)


def rotation(axis, angle: float) -> np.ndarray:
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * W + (1.0 - math.cos(angle)) * W @ W


def random_rotation(rng) -> np.ndarray:
    return rotation(rng.standard_normal(3), rng.uniform(0.3, 3.0))


# ----------------------------------------------------------------------------------------------
# 1. material point

E_MOD, NU, SY0, H_KIN = 200e3, 0.3, 200.0, 1500.0
#: hardening laws; Swift with a small eps0 (strongly curved near eps_p = 0), Voce with a fast saturation
LAWS = {
    "linear": ({"law": "linear", "modulus": 2000.0}, SY0),
    "perfect": ({"law": "linear", "modulus": 0.0}, SY0),
    "swift": ({"law": "swift", "K": 500.0, "eps0": 0.002, "n": 0.25}, None),
    "voce": ({"law": "voce", "sigma_inf": 400.0, "delta": 40.0, "modulus": 300.0}, SY0),
}
#: relative gap between two principal stretches (None: three distinct stretches)
GAPS = {"distinct": None, "near4": 4e-4, "near6": 1e-6, "near9": 1e-9, "pair": 0.0, "pair-rot": 0.0}
#: the increments of every path and their expected yield flag
STEPS = {"elastic": 0.0, "yield": 1.0, "early": 1.0, "large": 1.0, "larger": 1.0, "unload": 0.0,
         "reverse": 1.0, "volumetric": 1.0}
#: equivalent plastic strain reached by the loading increments (reverse: its increment)
ALPHA = {"yield": 1e-6, "early": 1e-4, "large": 0.3, "larger": 1.0, "reverse": 1e-3}
#: plastic strain increment taken as the yield onset (re-evaluating a converged plastic state may flow by
#: ~1e-13, round-off of the return mapping)
ONSET = 1e-12
H_MAT = 1e-7  # difference step in E (truncation 1e-7 h^-2 .. round-off 1e-15 / h: best near 1e-7)


def j2(law: str, kin: bool, hill: bool) -> J2Plasticity:
    hard, sy = LAWS[law]
    return J2Plasticity(E=E_MOD, nu=NU, yield_stress=sy, hardening=hard,
                        kinematic_modulus=H_KIN if kin else 0.0, hill48=HILL_R if hill else None)


def F_of_E(E: np.ndarray) -> np.ndarray:
    """Symmetric stretch U = sqrt(I + 2E)."""
    lam, V = np.linalg.eigh(np.eye(3) + 2.0 * E)
    return (V * np.sqrt(lam)) @ V.T


def stretch_F(e: np.ndarray, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    """F = R Q diag(exp e) Q^T: principal log stretches e in the principal frame Q, superposed rotation R."""
    return R @ (Q * np.exp(e)) @ Q.T


def fd_material(mat: J2Plasticity, F: np.ndarray, hist_n: np.ndarray, h: float = H_MAT):
    """Central differences of S w.r.t. the Green-Lagrange strain (engineering shears) at F from hist_n: C is
    perturbed symmetrically and the rotation of F kept (F' = R sqrt(C +- 2 dE), R of the polar decomposition
    of F). Also returns the yield flags of the 12 evaluations."""
    W, _, Vt = np.linalg.svd(F)
    R = W @ Vt
    E = 0.5 * (F.T @ F - np.eye(3))
    Dfd = np.empty((6, 6))
    flags = []
    for J, (i, j) in enumerate(PAIRS):
        dE = np.zeros((3, 3))
        if i == j:
            dE[i, i] = h
        else:
            dE[i, j] = dE[j, i] = 0.5 * h
        Sp, _, hp, sp = j2_point(mat, R @ F_of_E(E + dE), hist_n)
        Sm, _, hm, sm = j2_point(mat, R @ F_of_E(E - dE), hist_n)
        assert sp == 0 and sm == 0
        flags += [hp[H_FLAG], hm[H_FLAG]]
        Dfd[:, J] = (Sp - Sm) / (2.0 * h)
    return Dfd, flags


def _trial(mat: J2Plasticity, F: np.ndarray, hist_n: np.ndarray) -> np.ndarray:
    S, D, hist, status = j2_point(mat, F, hist_n)
    assert status == 0
    return hist


def _solve_load(mat, F_at, hist_n: np.ndarray, target: float, lo: float, hi: float) -> float:
    """The load parameter s in [lo, hi] at which the step from hist_n to F_at(s) adds ``target`` to the
    equivalent plastic strain (bisection; the increment grows with s there)."""
    def inc(s):
        return _trial(mat, F_at(s), hist_n)[H_ALPHA] - hist_n[H_ALPHA]

    assert inc(lo) <= target < inc(hi), "the bracket does not contain the target"
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if inc(mid) <= target:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * abs(hi):
            break
    return 0.5 * (lo + hi)


def stretch_pattern(pattern: str, rng):
    """Deviatoric principal log-strain direction n (equivalent strain 1), the constant offset g giving two
    stretches the relative gap of the pattern, the principal frame Q and whether the path is exact (F
    diagonal: the equal stretches of C are equal bit for bit)."""
    gap = GAPS[pattern]
    g = np.zeros(3)
    if gap is None:
        n = rng.uniform(-1.0, 1.0, 3)
    else:
        k = int(rng.integers(3))
        n = -np.ones(3)
        n[k] = 2.0
        n *= rng.choice([-1.0, 1.0])
        i, j = [m for m in range(3) if m != k]
        g[i], g[j] = 0.5 * gap, -0.5 * gap
    n -= n.mean()
    n /= math.sqrt(2.0 / 3.0 * (n @ n))
    if gap is None:
        assert np.min(np.diff(np.sort(n))) > 0.2  # clearly distinct
    exact = pattern == "pair"
    return n, g, (np.eye(3) if exact else random_rotation(rng)), exact


def load_path(mat: J2Plasticity, pattern: str, seed: int) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(label, F, committed history) of the increments of STEPS: principal log strains s n + v s / 3 + g
    with the load parameter s set (by bisection) for the targets of ALPHA, each increment committed."""
    rng = np.random.default_rng(seed)
    n, g, Q, exact = stretch_pattern(pattern, rng)
    vol = 0.1 * rng.uniform(-1.0, 1.0)  # volumetric log strain per unit s
    Rs = [np.eye(3) if exact else random_rotation(rng) for _ in STEPS]

    def at(k):
        return lambda s: stretch_F(s * n + vol * s / 3.0 + g, Q, Rs[k])

    path = []
    h = np.zeros(NHIST)

    def add(label, F, hist_n):
        path.append((label, F, hist_n))
        return _trial(mat, F, hist_n)

    s_y = _solve_load(mat, at(0), h, ONSET, 0.0, 0.1)
    add("elastic", at(0)(0.5 * s_y), h)
    s = _solve_load(mat, at(1), h, ALPHA["yield"], s_y, 2.0 * s_y)
    h = add("yield", at(1)(s), h)
    for k, label in ((2, "early"), (3, "large"), (4, "larger")):
        s = _solve_load(mat, at(k), h, ALPHA[label] - h[H_ALPHA], s, s + 3.0)
        h = add(label, at(k)(s), h)
    s_top = s
    t_rev = _solve_load(mat, lambda t: at(5)(s_top - t), h, ONSET, 0.0, 0.1)  # reverse yield onset
    h = add("unload", at(5)(s_top - 0.5 * t_rev), h)  # middle of the elastic range
    t = _solve_load(mat, lambda t: at(6)(s_top - t), h, ALPHA["reverse"], 0.5 * t_rev, 1.0)
    h = add("reverse", at(6)(s_top - t), h)
    spread = np.zeros(3) if not np.any(g) else np.array([0.5, 0.0, -0.5]) * GAPS[pattern]
    add("volumetric", stretch_F(0.05 * rng.uniform(-1.0, 1.0) + spread, Q, Rs[7]), h)
    assert [p[0] for p in path] == list(STEPS)
    return path


def _check_stretches(pattern: str, label: str, F: np.ndarray) -> None:
    """The principal stretches have the coincidences the pattern claims."""
    gap = GAPS[pattern]
    if pattern == "pair":  # F diagonal: C diagonal, equal entries equal bit for bit
        assert np.array_equal(F, np.diag(np.diag(F)))
        c = np.diag(F.T @ F)
        assert len(set(c.tolist())) == (1 if label == "volumetric" else 2)
        return
    ls = np.sort(0.5 * np.log(np.linalg.eigvalsh(F.T @ F)))
    diffs = np.array([ls[1] - ls[0], ls[2] - ls[1], ls[2] - ls[0]])
    if gap:
        assert np.min(np.abs(diffs - gap)) <= 1e-3 * gap
        if label == "volumetric":
            assert diffs[2] <= (1.0 + 1e-3) * gap
    elif gap == 0.0 or label == "volumetric":  # coincident to round-off
        assert np.min(diffs) <= 1e-13
        if label == "volumetric":
            assert diffs[2] <= 1e-13


@pytest.mark.parametrize("pattern", list(GAPS))
@pytest.mark.parametrize("hill", [False, True], ids=["mises", "hill"])
@pytest.mark.parametrize("kin", [False, True], ids=["iso", "kin"])
@pytest.mark.parametrize("law", list(LAWS))
def test_j2_tangent_along_load_path(law, kin, hill, pattern):
    mat = j2(law, kin, hill)
    path = load_path(mat, pattern, seed=17 + list(GAPS).index(pattern))
    for label, F, hist_n in path:
        _check_stretches(pattern, label, F)
        S, D, hist, status = j2_point(mat, F, hist_n)
        assert status == 0
        flag = STEPS[label]
        assert hist[H_FLAG] == flag, label
        if flag:
            assert hist[H_ALPHA] > hist_n[H_ALPHA], label
        else:
            assert hist[H_ALPHA] == hist_n[H_ALPHA] and np.array_equal(hist[:13], hist_n[:13]), label
        if label in ("yield", "early", "large", "larger"):
            assert hist[H_ALPHA] == pytest.approx(ALPHA[label], rel=1e-6)
        if label == "reverse":
            assert hist[H_ALPHA] - hist_n[H_ALPHA] == pytest.approx(ALPHA[label], rel=1e-6)
        Dfd, flags = fd_material(mat, F, hist_n)
        assert set(flags) == {flag}, f"{label}: a yield flag changes within +-h (a kink, not a tangent check)"
        err = np.abs(Dfd - D).max() / np.abs(D).max()
        assert err <= TOL, f"{label}: relative FD error {err:.2e}"


# ----------------------------------------------------------------------------------------------
# 2. elements

E_EL, NU_EL = 200.0, 0.3
EL_MATERIALS = {
    "lin-kin": lambda: J2Plasticity(E=E_EL, nu=NU_EL, yield_stress=0.5,
                                    hardening={"law": "linear", "modulus": 20.0}, kinematic_modulus=10.0),
    "swift-hill": lambda: J2Plasticity(E=E_EL, nu=NU_EL, hardening={"law": "swift", "K": 2.0, "eps0": 0.005,
                                                                    "n": 0.25}, hill48=HILL_R),
    "voce-kin-hill": lambda: J2Plasticity(E=E_EL, nu=NU_EL, yield_stress=0.5,
                                          hardening={"law": "voce", "sigma_inf": 1.0, "delta": 30.0,
                                                     "modulus": 2.0}, kinematic_modulus=5.0, hill48=HILL_R),
    "neo-hooke": lambda: NeoHooke(E=E_EL, nu=0.45),
}
#: solid-shell thickness rules: (rule, points)
THICKNESS = {"g2": ("gauss", 2), "g5": ("gauss", 5), "l3": ("lobatto", 3)}
ELEMENTS = ["hex8", "fbar8-spatial", "fbar8-variational", "fbar27"] + [
    f"shell{c}-{t}" for c in (8, 18) for t in THICKNESS]
#: displacement path: (label, load factor); the rigid rotation grows with every increment
EL_PATH = [("load", 0.5), ("load", 1.0), ("load", 2.0), ("unload", 1.8), ("reverse", 0.6)]
EL_SEED = 3
H_EL = 1e-7  # difference step in u (element size 0.5..1, shell thickness 0.2)


def solid_pair(cell: str, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Two distorted hexahedra (hex8 or hex27) sharing a face, nodes merged."""
    rng = np.random.default_rng(seed)
    ref = NODES[cell]
    X, inv = np.unique(np.round(np.vstack([ref, ref + [2.0, 0.0, 0.0]]), 12), axis=0, return_inverse=True)
    cells = inv.reshape(2, -1).astype(np.int64)
    X = 0.5 * X * [1.0, 0.8, 1.3] + 0.08 * rng.uniform(-1.0, 1.0, X.shape)
    return np.ascontiguousarray(X), cells


def shell_pair(cell: str, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Two distorted, curved shell-like elements (thickness 0.2 against 1 in-plane) sharing a side."""
    rng = np.random.default_rng(seed)
    ref = NODES[cell]
    X, inv = np.unique(np.round(np.vstack([ref, ref + [2.0, 0.0, 0.0]]), 12), axis=0, return_inverse=True)
    cells = inv.reshape(2, -1).astype(np.int64)
    X = X * [0.5, 0.5, 0.1]
    X[:, 2] += 0.15 * X[:, 0] ** 2 - 0.1 * X[:, 1] ** 2
    X += 0.04 * rng.uniform(-1.0, 1.0, X.shape) * [1.0, 1.0, 0.2]
    return np.ascontiguousarray(X), cells


def element_body(name: str, material):
    if name.startswith("shell"):
        cell, t = name[5:].split("-")
        rule, points = THICKNESS[t]
        X, cells = shell_pair(f"hex{cell}", EL_SEED)
        body = SolidShellBody(f"hex{cell}", X, cells, material, thickness_rule=rule, thickness_points=points)
        assert body.thickness_points == points and body.neas > 0
        if getattr(material, "n_hist", 0):
            assert body.n_eas_thickness == points - 2  # the thickness EAS modes of plastic materials
        return body
    if name == "hex8":
        return SolidBody("hex8", *solid_pair("hex8", EL_SEED), material)
    if name == "fbar27":
        return FbarBody("hex27", *solid_pair("hex27", EL_SEED), material)
    return FbarBody("hex8", *solid_pair("hex8", EL_SEED), material, form=name.split("-")[1])


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


def yield_flags(state) -> np.ndarray | None:
    hist = state.get("hist")
    return None if hist is None or hist.shape[-1] == 0 else hist[..., H_FLAG].copy()


def fd_element(body, u: np.ndarray, committed: dict, h: float = H_EL):
    """(K, central differences of the residual, trial state) at u from the committed state; every evaluation
    starts the local EAS Newton (solid-shells) from the trial at u. Asserts that no Gauss point changes
    its yield flag between the evaluations."""
    st = body.kernel_state(committed, committed)
    K, r = tangent(body, u, st)
    trial = body.trial_of(st)
    assert np.abs(residual(body, u, body.kernel_state(committed, trial)) - r).max() <= 1e-12 * np.abs(r).max()
    flags = yield_flags(trial)
    Kfd = np.empty_like(K)
    for j in range(u.size):
        cols = []
        for sign in (1.0, -1.0):
            up = u.ravel().copy()
            up[j] += sign * h
            s = body.kernel_state(committed, trial)
            cols.append(residual(body, up, s))
            if flags is not None:
                assert np.array_equal(yield_flags(s), flags), \
                    f"dof {j}: a yield flag changes within +-h (a kink, not a tangent check)"
        Kfd[:, j] = (cols[0] - cols[1]) / (2.0 * h)
    return K, Kfd, trial


@pytest.mark.parametrize("mat", list(EL_MATERIALS))
@pytest.mark.parametrize("element", ELEMENTS)
def test_element_tangent_along_load_path(element, mat):
    """Plastic loading (the first increment from the virgin state), partial elastic unloading, reverse
    loading; the tangent of every increment from the history committed by the previous one."""
    body = element_body(element, EL_MATERIALS[mat]())
    X = body.X
    plastic = isinstance(body.material, J2Plasticity)
    rng = np.random.default_rng(EL_SEED + 100)
    d = rng.uniform(-1.0, 1.0, X.shape)
    axis = rng.standard_normal(3)
    amp = 0.01 if element.startswith("shell") else 0.02
    committed = body.new_state()
    for k, (label, lam) in enumerate(EL_PATH):
        u = X @ rotation(axis, 0.6 * (k + 1) / len(EL_PATH)).T - X + lam * amp * d
        K, Kfd, trial = fd_element(body, u, committed)
        err = np.abs(K - Kfd).max() / np.abs(K).max()
        assert err <= TOL, f"increment {k} ({label}): relative FD error {err:.2e}"
        if body.symmetric_tangent:
            assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
        if isinstance(body, SolidShellBody):
            assert np.abs(trial["alpha"]).max() > 0.0  # EAS active
        if plastic:
            flags = yield_flags(trial)
            grew = trial["hist"][..., H_ALPHA] > committed["hist"][..., H_ALPHA]
            assert np.array_equal(grew, flags == 1.0)
            if label == "unload":  # partly: some points unload elastically, others still flow
                assert 0 < flags.sum() < flags.size, flags
            elif k in (1, 2):
                assert flags.all()
            else:
                assert flags.any()
        committed = trial
    if plastic:
        assert committed["hist"][..., H_ALPHA].min() > 0.0
