"""Rubber: the hyperelastic models of the Abaqus and CalculiX manuals (docs/theory.md, section 26).

Every model splits the strain energy density per unit reference volume into a deviatoric and a volumetric part,

    W = W_dev(I1bar, I2bar) + U(J)      or      W = W_dev(lambda1bar, lambda2bar, lambda3bar) + U(J),

with C = F^T F, J = det F, I1bar = J^(-2/3) I1, I2bar = J^(-4/3) I2 (I1 = tr C, I2 = ((tr C)^2 - tr C^2) / 2) and the
deviatoric principal stretches lambdabar_a = J^(-1/3) lambda_a:

- polynomial (N <= 6): W_dev = sum_{1 <= i + j <= N} C_ij (I1bar - 3)^i (I2bar - 3)^j; Mooney-Rivlin (N = 1, C10 and
  C01), Neo-Hooke (C10 alone), the reduced polynomial (C_i0 alone; Yeoh: N = 3);
- Arruda-Boyce: W_dev = mu sum_{i=1}^{5} c_i / lambda_m^(2i - 2) (I1bar^i - 3^i), c = 1/2, 1/20, 11/1050, 19/7000,
  519/673750 (the five-term series of the manuals);
- Gent: W_dev = -mu J_m / 2 ln(1 - (I1bar - 3) / J_m) (defined for I1bar - 3 < J_m);
- Ogden (N <= 6): W_dev = sum_p 2 mu_p / alpha_p^2 (lambda1bar^alpha_p + lambda2bar^alpha_p + lambda3bar^alpha_p - 3).

The volumetric part is Abaqus's U(J) = sum_i (J - 1)^(2i) / D_i (the polynomial family, Gent and Ogden; a D_i of 0
beyond the first drops its term), and for Arruda-Boyce, as in both manuals, U(J) = ((J^2 - 1) / 2 - ln J) / D. The
initial moduli: mu0 = 2 (C10 + C01), mu for Gent, mu (1 + 3 / (5 lambda_m^2) + 99 / (175 lambda_m^4) + 513 / (875
lambda_m^6) + 42039 / (67375 lambda_m^8)) for Arruda-Boyce, sum mu_p for Ogden; K0 = 2 / D1 (2 / D).

The kernels take the params array laid out below; its first four entries are the equivalent initial linear constants
[E0, nu0, lambda0, mu0] like every other material's [E, nu, lambda, mu] (the automatic contact penalty reads E).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from .logstrain import _eigh3

#: kind code of the rubber models (SVK = 0, NEO_HOOKE = 1 in hyperelastic, J2 = 2 in plasticity_kernels)
RUBBER = 3

# params layout
P_E0, P_NU0, P_LAM0, P_MU0, P_K0 = 0, 1, 2, 3, 4
P_TYPE = 5      # the deviatoric part: T_POLY, T_ARRUDA, T_GENT, T_OGDEN
P_VOL = 6       # the volumetric part: 0 sum_i (J - 1)^(2i) / D_i, 1 ((J^2 - 1) / 2 - ln J) / D
P_INVD = 7      # 1 / D_i, i = 1..6 (0: no term)
P_N = 13        # the order N (number of Ogden terms)
P_DATA = 14     # polynomial: C_ij at P_DATA + 7 i + j; Arruda-Boyce: mu, lambda_m; Gent: mu, J_m;
                # Ogden: mu_p at P_DATA + p, alpha_p at P_DATA + 6 + p
NPARAMS = P_DATA + 49
T_POLY, T_ARRUDA, T_GENT, T_OGDEN = 0, 1, 2, 3
NMAX = 6

#: the Arruda-Boyce series coefficients c_1..c_5
AB_COEF = (0.5, 1.0 / 20.0, 11.0 / 1050.0, 19.0 / 7000.0, 519.0 / 673750.0)

_PAIRS = np.array([[0, 0], [1, 1], [2, 2], [0, 1], [1, 2], [0, 2]], dtype=np.int64)
_VOIGT = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2]], dtype=np.int64)


# ----------------------------------------------------------------------------------------------
# the models on the Python side

MODELS = ("neo-hooke", "mooney-rivlin", "polynomial", "reduced-polynomial", "yeoh", "arruda-boyce", "gent", "ogden")


class RubberError(ValueError):
    """Bad constants; ``key`` names the input key the message is about."""

    def __init__(self, msg: str, key: str | None = None):
        super().__init__(msg)
        self.key = key


@dataclass(frozen=True)
class Rubber:
    """A rubber model (``model`` one of MODELS) with its constants as the manuals name them.

    ``c``: the polynomial family's ((i, j, C_ij), ...); ``d``: D_1..D_N (the first > 0; 0 beyond it drops the term);
    ``mu``, ``alpha``: Ogden's mu_p, alpha_p, or (mu,) for Arruda-Boyce and Gent; ``lambda_m`` (Arruda-Boyce),
    ``jm`` (Gent). Checked on construction (RubberError naming the key)."""

    model: str
    c: tuple = ()
    d: tuple = ()
    mu: tuple = ()
    alpha: tuple = ()
    lambda_m: float = 0.0
    jm: float = 0.0
    density: float | None = None
    kind: int = field(init=False, default=RUBBER)

    def __post_init__(self) -> None:
        from .common import check_density

        _check(self)
        check_density(self.density)

    @property
    def name(self) -> str:
        return self.model

    @property
    def order(self) -> int:
        """N: the polynomial order or the number of Ogden terms (1 for Arruda-Boyce and Gent)."""
        if self.model == "ogden":
            return len(self.mu)
        if self.model in ("arruda-boyce", "gent"):
            return 1
        return max([i + j for i, j, _ in self.c] + [len(self.d)])

    @property
    def mu0(self) -> float:
        """The initial shear modulus."""
        return initial_moduli(self)[0]

    @property
    def K0(self) -> float:
        """The initial bulk modulus 2 / D1."""
        return initial_moduli(self)[1]

    @property
    def E(self) -> float:
        """The initial Young's modulus 9 K0 mu0 / (3 K0 + mu0)."""
        mu, K = initial_moduli(self)
        return 9.0 * K * mu / (3.0 * K + mu)

    @property
    def nu(self) -> float:
        """The initial Poisson's ratio (3 K0 - 2 mu0) / (2 (3 K0 + mu0))."""
        mu, K = initial_moduli(self)
        return (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))

    @property
    def lam(self) -> float:
        mu, K = initial_moduli(self)
        return K - 2.0 * mu / 3.0

    @property
    def params(self) -> np.ndarray:
        """float64 array handed to the kernels (layout: P_* of this module)."""
        p = np.zeros(NPARAMS)
        mu, K = initial_moduli(self)
        p[P_E0], p[P_NU0], p[P_LAM0], p[P_MU0], p[P_K0] = self.E, self.nu, K - 2.0 * mu / 3.0, mu, K
        p[P_N] = self.order
        for i, D in enumerate(self.d):
            p[P_INVD + i] = 0.0 if D == 0.0 else 1.0 / D
        if self.model == "arruda-boyce":
            p[P_TYPE], p[P_VOL] = T_ARRUDA, 1
            p[P_DATA], p[P_DATA + 1] = self.mu[0], self.lambda_m
        elif self.model == "gent":
            p[P_TYPE] = T_GENT
            p[P_DATA], p[P_DATA + 1] = self.mu[0], self.jm
        elif self.model == "ogden":
            p[P_TYPE] = T_OGDEN
            for k, (m, a) in enumerate(zip(self.mu, self.alpha)):
                p[P_DATA + k], p[P_DATA + 6 + k] = m, a
        else:
            p[P_TYPE] = T_POLY
            for i, j, v in self.c:
                p[P_DATA + 7 * i + j] = v
        return p

    def describe(self) -> str:
        """'mooney-rivlin: initial shear modulus mu0 = 2 (c10 + c01) = 1.2, bulk modulus K0 = 2 / d1 = 1200 (K0 / mu0
        = 1000, initial Poisson's ratio 0.4995)'."""
        mu, K = initial_moduli(self)
        how = {"arruda-boyce": "mu (1 + 3 / (5 lambda_m^2) + ...)", "gent": "mu", "ogden": "sum of mu_i",
               "neo-hooke": "2 c10", "reduced-polynomial": "2 c10", "yeoh": "2 c10"}.get(self.model, "2 (c10 + c01)")
        dname = "d" if self.model == "arruda-boyce" else "d1"
        return (f"{self.model}: initial shear modulus mu0 = {how} = {mu:.6g}, bulk modulus K0 = 2 / {dname} = {K:.6g} "
                f"(K0 / mu0 = {K / mu:.4g}, initial Poisson's ratio {self.nu:.6g})")


def initial_moduli(m: Rubber) -> tuple[float, float]:
    """(mu0, K0) of a rubber model."""
    if m.model == "ogden":
        mu0 = float(sum(m.mu))
    elif m.model == "gent":
        mu0 = float(m.mu[0])
    elif m.model == "arruda-boyce":
        L2 = 1.0 / m.lambda_m ** 2
        mu0 = 2.0 * m.mu[0] * sum((i + 1) * c * 3.0 ** i * L2 ** i for i, c in enumerate(AB_COEF))
    else:
        cc = {(i, j): v for i, j, v in m.c}
        mu0 = 2.0 * (cc.get((1, 0), 0.0) + cc.get((0, 1), 0.0))
    D1 = m.d[0] if m.d else 0.0
    return mu0, (2.0 / D1 if D1 != 0.0 else math.inf)


def _check(m: Rubber) -> None:
    if m.model not in MODELS:
        raise RubberError(f"unknown rubber model {m.model!r} (known: {', '.join(MODELS)})", "model")
    dname = "d" if m.model in ("arruda-boyce", "ogden") else "d1"
    if not all(math.isfinite(float(v)) for v in (*[x[2] for x in m.c], *m.d, *m.mu, *m.alpha, m.lambda_m, m.jm)):
        raise RubberError("the constants must be finite")
    N = m.order
    if N > NMAX:
        key = "mu" if m.model == "ogden" else next(f"c{i}{j}" for i, j, _ in m.c if i + j == N) \
            if any(i + j == N for i, j, _ in m.c) else f"d{len(m.d)}"
        raise RubberError(f"order N = {N} is above {NMAX}", key)
    if m.model == "ogden":
        if len(m.mu) != len(m.alpha) or not m.mu:
            raise RubberError(f"mu has {len(m.mu)} entries and alpha {len(m.alpha)}: give one alpha per mu "
                              f"(1 to {NMAX} terms)", "alpha")
        if len(m.d) > len(m.mu):
            raise RubberError(f"d has {len(m.d)} entries for {len(m.mu)} Ogden terms: D_1..D_N at most", "d")
        for k, a in enumerate(m.alpha):
            if a == 0.0:
                raise RubberError(f"alpha[{k}] = 0: an Ogden exponent must not be 0", "alpha")
    if m.model == "arruda-boyce" and not m.lambda_m > 0.0:
        raise RubberError(f"the locking stretch must be > 0, got {m.lambda_m}", "lambda_m")
    if m.model == "gent" and not m.jm > 0.0:
        raise RubberError(f"the limit of I1bar - 3 must be > 0, got {m.jm}", "jm")
    if not m.d:
        raise RubberError("missing the compressibility D1", dname)
    if len(m.d) > max(N, 1):
        raise RubberError(f"D{len(m.d)} needs order N >= {len(m.d)} (the model's order is {N})", f"d{len(m.d)}")
    mu0, K0 = initial_moduli(m)
    if not mu0 > 0.0:
        how = {"ogden": ("mu", "sum of mu_i"), "gent": ("mu", "mu"), "arruda-boyce": ("mu", "mu (1 + ...)")}.get(
            m.model, ("c10", "2 (c10 + c01)"))
        raise RubberError(f"the initial shear modulus {how[1]} = {mu0:g} must be > 0", how[0])
    if m.d[0] < 0.0:
        raise RubberError(f"the initial bulk modulus 2 / {dname} = {K0:g} must be > 0", dname)
    if m.d[0] == 0.0:
        raise RubberError(f"{dname} = 0 makes the material fully incompressible, which needs a mixed (hybrid) "
                          f"formulation: give {dname} > 0 (the initial bulk modulus is 2 / {dname}; e.g. "
                          f"{dname} = {2.0 / (1000.0 * mu0):.3g} for K0 = 1000 mu0)", dname)
    for k, D in enumerate(m.d[1:], start=2):
        if D < 0.0:
            raise RubberError(f"must be >= 0 (0: no term), got {D}", f"d{k}" if m.model != "ogden" else "d")


_CKEY = re.compile(r"^c(\d)(\d)$")
_DKEY = re.compile(r"^d(\d+)$")


def _number(key: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise RubberError("must be a number", key)
    if not math.isfinite(v):
        raise RubberError("must be finite", key)
    return float(v)


def _numbers(key: str, v) -> tuple:
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        v = [v]
    if not isinstance(v, list) or not v:
        raise RubberError("must be an array of numbers", key)
    return tuple(_number(key, x) for x in v)


def model_keys(model: str) -> tuple[str, ...]:
    """The keys of a model (the polynomial family's c_ij and d_i in their fixed form)."""
    return {"neo-hooke": ("c10", "d1"), "mooney-rivlin": ("c10", "c01", "d1"),
            "yeoh": ("c10", "c20", "c30", "d1", "d2", "d3"), "arruda-boyce": ("mu", "lambda_m", "d"),
            "gent": ("mu", "jm", "d1"), "ogden": ("mu", "alpha", "d"),
            "reduced-polynomial": ("c10", "c20", "...", "cN0", "d1", "...", "dN", "n"),
            "polynomial": ("c10", "c01", "c20", "c11", "c02", "...", "d1", "...", "dN", "n")}[model]


def rubber_from_keys(model: str, keys: dict, density: float | None = None) -> Rubber:
    """A Rubber from the keys of a problem file's material table (everything but ``model`` and ``density``)."""
    model = model.strip().lower().replace("_", "-").replace(" ", "-")
    if model == "neohooke":
        model = "neo-hooke"
    if model not in MODELS:
        raise RubberError(f"unknown rubber model {model!r} (known: {', '.join(MODELS)})", "model")
    keys = dict(keys)
    if model in ("arruda-boyce", "gent", "ogden"):
        names = model_keys(model)
        for k in keys:
            if k not in names:
                from ..words import suggest

                raise RubberError(f"unknown key{suggest(k, names)} ({model}: {', '.join(names)})", k)
        for k in names:
            if k not in keys:
                raise RubberError("missing required key", k)
        if model == "ogden":
            return Rubber(model, mu=_numbers("mu", keys["mu"]), alpha=_numbers("alpha", keys["alpha"]),
                          d=_numbers("d", keys["d"]), density=density)
        if model == "arruda-boyce":
            return Rubber(model, mu=(_number("mu", keys["mu"]),), lambda_m=_number("lambda_m", keys["lambda_m"]),
                          d=(_number("d", keys["d"]),), density=density)
        return Rubber(model, mu=(_number("mu", keys["mu"]),), jm=_number("jm", keys["jm"]),
                      d=(_number("d1", keys["d1"]),), density=density)
    # the polynomial family
    n = keys.pop("n", None)
    if n is not None and (isinstance(n, bool) or not isinstance(n, int) or not 1 <= n):
        raise RubberError(f"must be an integer from 1 to {NMAX}", "n")
    if n is not None and model not in ("polynomial", "reduced-polynomial"):
        raise RubberError(f"{model} has a fixed order", "n")
    if n is not None and n > NMAX:
        raise RubberError(f"order N = {n} is above {NMAX}", "n")
    c, d = {}, {}
    for k, v in keys.items():
        mc, md = _CKEY.match(k), _DKEY.match(k)
        if mc:
            i, j = int(mc.group(1)), int(mc.group(2))
            if i + j == 0:
                raise RubberError("c00 is not a constant of the model (i + j >= 1)", k)
            if i + j > NMAX:
                raise RubberError(f"order i + j = {i + j} is above {NMAX}", k)
            c[(i, j)] = _number(k, v)
        elif md:
            i = int(md.group(1))
            if not 1 <= i:
                raise RubberError("the compressibilities are d1..dN", k)
            if i > NMAX:
                raise RubberError(f"order N = {i} is above {NMAX}", k)
            d[i] = _number(k, v)
        else:
            from ..words import suggest

            raise RubberError(f"unknown key{suggest(k, ['c10', 'c01', 'd1', 'n'])} ({model}: "
                              f"{', '.join(model_keys(model))})", k)
    allowed = {"neo-hooke": {(1, 0)}, "mooney-rivlin": {(1, 0), (0, 1)}, "yeoh": {(1, 0), (2, 0), (3, 0)}}
    for (i, j) in c:
        key = f"c{i}{j}"
        if model in allowed and (i, j) not in allowed[model]:
            raise RubberError(f"not a constant of {model} ({', '.join(model_keys(model))})", key)
        if model == "reduced-polynomial" and j != 0:
            raise RubberError("the reduced polynomial has the c_i0 alone (I1bar only): use model = \"polynomial\"",
                              key)
        if n is not None and i + j > n:
            raise RubberError(f"order i + j = {i + j} is above the model's n = {n}", key)
    top = {"neo-hooke": 1, "mooney-rivlin": 1, "yeoh": 3}.get(model, n if n is not None else
                                                           max([i + j for i, j in c] + [max(d, default=1)]))
    for i in d:
        if i > top:
            raise RubberError(f"d{i} needs order N >= {i} (the model's order is {top})", f"d{i}")
    if 1 not in d:
        raise RubberError("missing required key", "d1")
    if model in ("neo-hooke", "mooney-rivlin", "reduced-polynomial", "yeoh") and (1, 0) not in c:
        raise RubberError("missing required key", "c10")
    dd = tuple(d.get(i, 0.0) for i in range(1, max(d) + 1))
    cc = tuple((i, j, v) for (i, j), v in sorted(c.items()))
    if model == "polynomial" and n is not None and (not cc or max(i + j for i, j, _ in cc) < n):
        cc = cc + ((n, 0, 0.0),)  # (an explicit order with zero top constants)
    return Rubber(model, c=cc, d=dd, density=density)


def moduli_notes(bodies) -> list[str]:
    """'body 'seal': mooney-rivlin: initial shear modulus ...' for every rubber material of the bodies (the run's
    log says them once, so that users can check their constants)."""
    out = []
    for b in bodies:
        mats = [("", getattr(b, "material", None)), *getattr(b, "materials", {}).items()]
        for name, mat in mats:
            if isinstance(mat, Rubber):
                where = f"body {b.name!r}" + (f", element set {name!r}" if name else "")
                out.append(f"{where}: {mat.describe()}")
    return out


# ----------------------------------------------------------------------------------------------
# kernels


@njit(cache=True)
def _volumetric(params, J, Jm1, lnJ):
    """U(J), U'(J), U''(J)."""
    if params[P_VOL] == 1.0:
        iD = params[P_INVD]
        # (J^2 - 1) / 2 - ln J = (J - 1)^2 / 2 + (J - 1) - ln J
        return (iD * (0.5 * Jm1 * Jm1 + (Jm1 - lnJ)), iD * Jm1 * (J + 1.0) / J, iD * (1.0 + 1.0 / (J * J)))
    U = 0.0
    up = 0.0
    upp = 0.0
    p = 1.0  # (J - 1)^(2i - 2)
    for i in range(1, NMAX + 1):
        iD = params[P_INVD + i - 1]
        if iD != 0.0:
            U += iD * p * Jm1 * Jm1
            up += 2.0 * i * iD * p * Jm1
            upp += 2.0 * i * (2.0 * i - 1.0) * iD * p
        p *= Jm1 * Jm1
    return U, up, upp


@njit(cache=True)
def _dev_invariants(params, x, y):
    """W_dev and its derivatives W1, W2, W11, W12, W22 in I1bar, I2bar at x = I1bar - 3, y = I2bar - 3; status 1
    beyond Gent's limit."""
    typ = int(params[P_TYPE])
    W = 0.0
    W1 = 0.0
    W2 = 0.0
    W11 = 0.0
    W12 = 0.0
    W22 = 0.0
    if typ == T_ARRUDA:
        mu = params[P_DATA]
        L2 = 1.0 / (params[P_DATA + 1] * params[P_DATA + 1])
        I = 3.0 + x
        f = mu  # mu / lambda_m^(2i - 2)
        for k in range(5):
            i = k + 1
            ci = f * AB_COEF[k]
            # I^i - 3^i = 3^i expm1(i log1p(x / 3))
            W += ci * 3.0 ** i * math.expm1(i * math.log1p(x / 3.0))
            W1 += ci * i * I ** (i - 1)
            if i > 1:
                W11 += ci * i * (i - 1) * I ** (i - 2)
            f *= L2
        return 0, W, W1, W2, W11, W12, W22
    if typ == T_GENT:
        mu = params[P_DATA]
        Jm = params[P_DATA + 1]
        r = 1.0 - x / Jm
        if not (r > 0.0):
            return 1, np.inf, 0.0, 0.0, 0.0, 0.0, 0.0
        W = -0.5 * mu * Jm * math.log1p(-x / Jm)
        W1 = 0.5 * mu / r
        W11 = 0.5 * mu / (Jm * r * r)
        return 0, W, W1, W2, W11, W12, W22
    xp = np.ones(NMAX + 1)
    yp = np.ones(NMAX + 1)
    for i in range(1, NMAX + 1):
        xp[i] = xp[i - 1] * x
        yp[i] = yp[i - 1] * y
    for i in range(NMAX + 1):
        for j in range(NMAX + 1 - i):
            c = params[P_DATA + 7 * i + j]
            if c == 0.0:
                continue
            W += c * xp[i] * yp[j]
            if i >= 1:
                W1 += i * c * xp[i - 1] * yp[j]
            if j >= 1:
                W2 += j * c * xp[i] * yp[j - 1]
            if i >= 2:
                W11 += i * (i - 1) * c * xp[i - 2] * yp[j]
            if i >= 1 and j >= 1:
                W12 += i * j * c * xp[i - 1] * yp[j - 1]
            if j >= 2:
                W22 += j * (j - 1) * c * xp[i] * yp[j - 2]
    return 0, W, W1, W2, W11, W12, W22


@njit(cache=True, inline="always")
def _mm(A, B):
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]
    return out


@njit(cache=True)
def _zero(S, D):
    for I in range(6):
        S[I] = 0.0
        for K in range(6):
            D[I, K] = 0.0


@njit(cache=True)
def rubber_response(params, J, cm, lnJ, S, D):
    """S (6,) and D = dS/dE (6, 6) of a rubber model from J = det F, C - I in Voigt order (``cm``) and ln J (Voigt
    order 11, 22, 33, 12, 23, 13, engineering shears). Returns 0, or 1 (S = D = 0) when J <= 0 or beyond Gent's
    limit."""
    if not (J > 0.0):
        _zero(S, D)
        return 1
    Jm1 = math.expm1(lnJ)
    _, up, upp = _volumetric(params, J, Jm1, lnJ)
    if int(params[P_TYPE]) == T_OGDEN:
        return _ogden_response(params, J, cm, lnJ, up, upp, S, D)
    c = np.empty((3, 3))
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        c[i, j] = cm[I]
        c[j, i] = cm[I]
    t = c[0, 0] + c[1, 1] + c[2, 2]
    c2 = _mm(c, c)
    i2c = 0.5 * (t * t - (c2[0, 0] + c2[1, 1] + c2[2, 2]))
    I1 = 3.0 + t
    I2 = 3.0 + 2.0 * t + i2c
    a = math.exp(-2.0 / 3.0 * lnJ)
    b = a * a
    x = a * t + 3.0 * math.expm1(-2.0 / 3.0 * lnJ)
    y = b * (2.0 * t + i2c) + 3.0 * math.expm1(-4.0 / 3.0 * lnJ)
    status, W, W1, W2, W11, W12, W22 = _dev_invariants(params, x, y)
    if status != 0:
        _zero(S, D)
        return status
    C = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            C[i, j] = c[i, j] + (1.0 if i == j else 0.0)
    detC = J * J
    Ci = np.empty((3, 3))
    Ci[0, 0] = (C[1, 1] * C[2, 2] - C[1, 2] * C[1, 2]) / detC
    Ci[1, 1] = (C[0, 0] * C[2, 2] - C[0, 2] * C[0, 2]) / detC
    Ci[2, 2] = (C[0, 0] * C[1, 1] - C[0, 1] * C[0, 1]) / detC
    Ci[0, 1] = (C[0, 2] * C[1, 2] - C[0, 1] * C[2, 2]) / detC
    Ci[1, 2] = (C[0, 1] * C[0, 2] - C[0, 0] * C[1, 2]) / detC
    Ci[0, 2] = (C[0, 1] * C[1, 2] - C[0, 2] * C[1, 1]) / detC
    Ci[1, 0] = Ci[0, 1]
    Ci[2, 1] = Ci[1, 2]
    Ci[2, 0] = Ci[0, 2]
    # dI1bar/dC = a C^-1 dev(c), dI2bar/dC = b C^-1 ((1 + t) c - c^2 - (t / 3 + 2 i2(c) / 3) I): formed from c = C - I,
    # without the cancellation of a (I - I1 / 3 C^-1) at small strains
    M1 = np.empty((3, 3))
    M2 = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            M1[i, j] = c[i, j] - (t / 3.0 if i == j else 0.0)
            M2[i, j] = (1.0 + t) * c[i, j] - c2[i, j] - ((t / 3.0 + 2.0 * i2c / 3.0) if i == j else 0.0)
    P1 = _mm(Ci, M1)
    P2 = _mm(Ci, M2)
    A1 = np.empty((3, 3))
    A2 = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            A1[i, j] = 0.5 * a * (P1[i, j] + P1[j, i])
            A2[i, j] = 0.5 * b * (P2[i, j] + P2[j, i])
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        S[I] = 2.0 * (W1 * A1[i, j] + W2 * A2[i, j] + up * 0.5 * J * Ci[i, j])
    # D = 4 d2W/dC2 (minor symmetric components)
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        dij = 1.0 if i == j else 0.0
        for K in range(I, 6):
            k = _PAIRS[K, 0]
            l = _PAIRS[K, 1]
            dkl = 1.0 if k == l else 0.0
            cc = Ci[i, j] * Ci[k, l]
            cs = 0.5 * (Ci[i, k] * Ci[j, l] + Ci[i, l] * Ci[j, k])
            ii = 0.5 * ((1.0 if i == k else 0.0) * (1.0 if j == l else 0.0)
                        + (1.0 if i == l else 0.0) * (1.0 if j == k else 0.0))
            d1 = a / 3.0 * (-dij * Ci[k, l] - Ci[i, j] * dkl + I1 / 3.0 * cc + I1 * cs)
            v = W11 * A1[i, j] * A1[k, l] + W1 * d1
            if W2 != 0.0 or W12 != 0.0 or W22 != 0.0:
                d2 = b * (-2.0 / 3.0 * (I1 * dij - C[i, j]) * Ci[k, l] + 4.0 / 9.0 * I2 * cc + dij * dkl - ii
                          - 2.0 / 3.0 * Ci[i, j] * (I1 * dkl - C[k, l]) + 2.0 / 3.0 * I2 * cs)
                v += (W12 * (A1[i, j] * A2[k, l] + A2[i, j] * A1[k, l]) + W22 * A2[i, j] * A2[k, l] + W2 * d2)
            v += upp * 0.25 * J * J * cc + up * (0.25 * J * cc - 0.5 * J * cs)
            D[I, K] = 4.0 * v
            D[K, I] = 4.0 * v
    return 0


@njit(cache=True, inline="always")
def _power_dd(beta, la, lb):
    """(x^beta - y^beta) / (x - y) at x = exp(la), y = exp(lb): y^(beta - 1) expm1(beta d) / expm1(d) with d = la - lb
    (both expm1 keep their relative precision at any small d), beta y^(beta - 1) at d = 0."""
    d = la - lb
    f = math.exp((beta - 1.0) * lb)
    if d == 0.0:
        return beta * f
    return f * math.expm1(beta * d) / math.expm1(d)


@njit(cache=True)
def _ogden_response(params, J, cm, lnJ, up, upp, S, D):
    """Ogden in the principal directions of C: S = sum_a 2 W_a N_a, D = 4 sum_ab W_ab N_a (x) N_b + 2 sum_{a<b} G_ab
    M_ab (x) M_ab with W_a = dW/dc_a (c_a the eigenvalues of C, N_a = n_a n_a, M_ab = n_a n_b + n_b n_a) and G_ab =
    (W_a - W_b) / (c_a - c_b) formed as a divided difference that stays exact for equal and nearly equal c_a."""
    e = np.empty(3)
    V = np.empty((3, 3))
    _eigh3(cm[0], cm[1], cm[2], cm[3], cm[4], cm[5], e, V)
    lc = np.empty(3)
    ca = np.empty(3)
    for q in range(3):
        lc[q] = math.log1p(e[q])
        ca[q] = 1.0 + e[q]
    Wa = np.zeros(3)
    Wab = np.zeros((3, 3))
    G = np.zeros((3, 3))  # the pairs' (W_a - W_b) / (c_a - c_b)
    psi = 0.0  # the coefficient of 1 / c_a in W_a common to a = 1, 2, 3
    n = int(params[P_N])
    r = np.empty(3)
    q_ = np.empty(3)
    for p in range(n):
        mu = params[P_DATA + p]
        al = params[P_DATA + 6 + p]
        k = 2.0 * mu / (al * al)
        m = math.exp(-al / 3.0 * lnJ)
        for a in range(3):
            r[a] = math.expm1(0.5 * al * lc[a])
            q_[a] = 1.0 + r[a]
        rbar = (r[0] + r[1] + r[2]) / 3.0
        s = q_[0] + q_[1] + q_[2]
        km = k * m
        for a in range(3):
            Wa[a] += km * al / (2.0 * ca[a]) * (r[a] - rbar)
            for b in range(3):
                v = -al / 6.0 * (q_[a] + q_[b]) + al * s / 18.0
                if a == b:
                    v += (0.5 * al - 1.0) * q_[a] + s / 3.0
                Wab[a, b] += km * al / (2.0 * ca[a] * ca[b]) * v
        psi += -km * al * s / 6.0
        for a in range(3):
            for b in range(a + 1, 3):
                G[a, b] += 0.5 * km * al * _power_dd(0.5 * al - 1.0, lc[a], lc[b])
    for a in range(3):
        Wa[a] += up * J / (2.0 * ca[a])
        for b in range(3):
            v = (upp * J * J + up * J) / (4.0 * ca[a] * ca[b])
            if a == b:
                v -= up * J / (2.0 * ca[a] * ca[a])
            Wab[a, b] += v
    psi += 0.5 * up * J
    for a in range(3):
        for b in range(a + 1, 3):
            G[a, b] -= psi / (ca[a] * ca[b])
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        v = 0.0
        for a in range(3):
            v += 2.0 * Wa[a] * V[i, a] * V[j, a]
        S[I] = v
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        for K in range(I, 6):
            k = _PAIRS[K, 0]
            l = _PAIRS[K, 1]
            v = 0.0
            for a in range(3):
                Na = V[i, a] * V[j, a]
                for b in range(3):
                    v += 4.0 * Wab[a, b] * Na * V[k, b] * V[l, b]
            for a in range(3):
                for b in range(a + 1, 3):
                    Mij = V[i, a] * V[j, b] + V[i, b] * V[j, a]
                    Mkl = V[k, a] * V[l, b] + V[k, b] * V[l, a]
                    v += 2.0 * G[a, b] * Mij * Mkl
            D[I, K] = v
            D[K, I] = v
    return 0


@njit(cache=True)
def rubber_energy(params, F):
    """W per unit reference volume at F (inf when det F <= 0 or beyond Gent's limit)."""
    J = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1]) - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
         + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    if not (J > 0.0):
        return np.inf
    lnJ = math.log(J)
    cm = np.empty(6)
    for I in range(6):
        i = _PAIRS[I, 0]
        j = _PAIRS[I, 1]
        cm[I] = F[0, i] * F[0, j] + F[1, i] * F[1, j] + F[2, i] * F[2, j] - (1.0 if I < 3 else 0.0)
    U, _, _ = _volumetric(params, J, math.expm1(lnJ), lnJ)
    if int(params[P_TYPE]) == T_OGDEN:
        e = np.empty(3)
        V = np.empty((3, 3))
        _eigh3(cm[0], cm[1], cm[2], cm[3], cm[4], cm[5], e, V)
        W = 0.0
        for p in range(int(params[P_N])):
            mu = params[P_DATA + p]
            al = params[P_DATA + 6 + p]
            for a in range(3):
                W += 2.0 * mu / (al * al) * math.expm1(al * (0.5 * math.log1p(e[a]) - lnJ / 3.0))
        return W + U
    t = cm[0] + cm[1] + cm[2]
    tc2 = (cm[0] * cm[0] + cm[1] * cm[1] + cm[2] * cm[2]
           + 2.0 * (cm[3] * cm[3] + cm[4] * cm[4] + cm[5] * cm[5]))
    i2c = 0.5 * (t * t - tc2)
    a = math.exp(-2.0 / 3.0 * lnJ)
    x = a * t + 3.0 * math.expm1(-2.0 / 3.0 * lnJ)
    y = a * a * (2.0 * t + i2c) + 3.0 * math.expm1(-4.0 / 3.0 * lnJ)
    status, W, _, _, _, _, _ = _dev_invariants(params, x, y)
    if status != 0:
        return np.inf
    return W + U
