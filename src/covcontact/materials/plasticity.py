"""Finite-strain J2 (von Mises or Hill 1948) elastoplasticity in the logarithmic strain space.

Formulation (docs/theory.md, section 12): the total-Lagrangian
logarithmic strain E_log = 1/2 ln C (spectral decomposition of C = F^T F) is split additively,
E_log = E_e + E_p, with the plastic log strain E_p as history. The stress T conjugate to E_log follows
from Hencky elasticity, T = lambda tr(E_e) I + 2 mu E_e, and a small-strain-like return mapping is done
in that space (backward Euler, associative flow, isotropic hardening sigma_y(alpha) (linear, Swift, Voce or
a piecewise-linear table), linear Prager kinematic hardening d beta = 2/3 H_kin d E_p, yield function
phi = sqrt((T - beta) : P_H : (T - beta)) - sigma_y(alpha), P_H the von Mises or Hill 1948 matrix). The
second Piola-Kirchhoff stress is S = T : P with P = 2 dE_log/dC, and the algorithmic tangent
dS/dE = P : C_alg : P + T : L with L = 4 d^2 E_log / dC dC, all from the spectral (divided-difference)
formulas of the matrix logarithm.

Return mapping. In Mandel coordinates (shear components times sqrt 2) the Hill matrix is
P_hat = Q diag(p) Q^T with a fixed orthogonal Q (first column the hydrostatic direction, p_0 = 0) and the
elasticity is diagonal in the same basis (3 K on the hydrostatic mode, 2 mu on the five others). With
z = Q^T (T - beta) the backward-Euler update is z_k = z_tr_k / (1 + kappa s p_k), kappa = 2 mu + 2/3 H_kin,
s = delta_gamma / sigma_bar, so the closest-point projection reduces to one scalar equation: in
delta_gamma for von Mises (radial return, sigma_bar = sigma_bar_tr - (3 mu + H_kin) delta_gamma) and in s
for Hill (1/sigma_bar(s) - 1/sigma_y(alpha_n + s sigma_bar(s)) = 0, nearly linear in s), each by a
bracketed Newton to |sigma_bar - sigma_y| <= RM_TOL sigma_bar_tr. The consistent tangent in z coordinates
is diag(ce_k (1 - s p_k a_k ce_k)) + c v v^T (a_k = 1/(1 + kappa s p_k), v_k = ce_k p_k a_k z_k,
c = (1 - h s) / (sigma_bar r_s), h = d sigma_y / d alpha, r_s = d(sigma_bar - sigma_y)/ds).

Spectral part. E = 1/2 (C - I) is formed from F - I (accurate at small strain) and diagonalised by cyclic
Jacobi; l_a = 1 + 2 w_a, e_a = 1/2 log1p(2 w_a). First divided differences of f(x) = 1/2 ln x:
(e_a - e_b)/(l_a - l_b), or g(d)/(2 sqrt(l_a l_b)) with d = e_a - e_b, g(d) = d/sinh d by its Taylor series
when |d| < 1e-3 (exact 1/(2 l_a) at d = 0). Second divided differences: divided by the largest separation
when that exceeds 1e-3 of the largest argument, else a Taylor series about the mean. Equal or nearly equal
eigenvalues (F = I, uniaxial, volumetric) therefore need no special case.

``params`` layout (float64, length NPARAMS, the table law NPARAMS + 1 + 2 n; P_* are the index constants
below):

    0  E        Young's modulus             1  nu      Poisson's ratio
    2  lambda   first Lame constant         3  mu      shear modulus
    4  K        bulk modulus lambda + 2/3 mu
    5  law      hardening law code: 0 linear, 1 Swift, 2 Voce, 3 table
    6  sigma_y0 initial yield stress (Swift: K eps0^n; table: its first stress)
    7  H        linear hardening modulus (linear law; the optional linear term of Voce; 0 for Swift)
    8  K_swift  9  eps0      10 n          (Swift: sigma_y = K (eps0 + alpha)^n)
    11 sigma_inf 12 delta                  (Voce: sigma_y0 + (sigma_inf - sigma_y0)(1 - exp(-delta alpha))
                                            + H alpha)
    13 H_kin    linear kinematic hardening modulus (d beta = 2/3 H_kin d E_p)
    14 hill     0: von Mises, 1: Hill 1948
    15..20      Hill coefficients F, G, H, L, M, N (von Mises: 1/2, 1/2, 1/2, 3/2, 3/2, 3/2)
    21..29      Q3, row-major 3x3: the normal block of Q (column 0 = (1, 1, 1)/sqrt 3)
    30..35      p: eigenvalues of P_hat in the order of z (0, p_1, p_2, N, L, M)
    table law only, after the fixed part (P_TAB_N = NPARAMS = 36, P_TAB = 37):
    36          n, the number of points (>= 1)
    37..36+n    equivalent plastic strains of the points (0 first, strictly increasing)
    37+n..36+2n yield stresses of the points (sigma_y piecewise linear between them, constant from the last)

History layout (float64, length NHIST = 15) per material point:

    0..5   E_p, plastic logarithmic strain, tensor components (11, 22, 33, 12, 23, 13)
    6      alpha, equivalent plastic strain
    7..12  beta, back stress, tensor components (11, 22, 33, 12, 23, 13)
    13     w_p, accumulated plastic work density sum of T : delta E_p (per unit reference volume)
    14     yield flag: 1.0 if the last update was plastic, else 0.0

Voigt order of S and D: 11, 22, 33, 12, 23, 13; D acts on engineering shear strains (dS_I = D_IJ dE_J).
"""


from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .hyperelastic import LameConstants, lame
from .logstrain import _dd1, _dd2
from .plasticity_kernels import (
    H_ALPHA,
    H_BETA,
    H_EP,
    H_FLAG,
    H_WP,
    J2,
    LAW_LINEAR,
    LAW_SWIFT,
    LAW_TABLE,
    LAW_VOCE,
    NHIST,
    NPARAMS,
    P_BULK,
    P_E,
    P_H,
    P_HILL,
    P_HILL_COEF,
    P_HKIN,
    P_LAMBDA,
    P_LAW,
    P_MU,
    P_NU,
    P_P,
    P_Q3,
    P_SWIFT_EPS0,
    P_SWIFT_K,
    P_SWIFT_N,
    P_SY0,
    P_TAB,
    P_TAB_N,
    P_VOCE_DELTA,
    P_VOCE_SINF,
    RM_MAXIT,
    RM_TOL,
    _hardening,
    j2_response,
)

_LAWS = {"linear": LAW_LINEAR, "swift": LAW_SWIFT, "voce": LAW_VOCE, "table": LAW_TABLE}

# ----------------------------------------------------------------------------------------------
# Python side: parameters and validation


def _finite(name: str, v: float) -> float:
    v = float(v)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {name}={v}")
    return v


@dataclass(frozen=True)
class LinearHardening:
    """sigma_y(alpha) = sigma_y0 + modulus alpha (modulus 0: perfect plasticity)."""

    modulus: float = 0.0
    law: str = field(init=False, default="linear")

    def __post_init__(self) -> None:
        if _finite("hardening modulus", self.modulus) < 0.0:
            raise ValueError(f"hardening modulus must be >= 0, got modulus={self.modulus}")


@dataclass(frozen=True)
class SwiftHardening:
    """sigma_y(alpha) = K (eps0 + alpha)^n, so sigma_y0 = K eps0^n."""

    K: float
    eps0: float
    n: float
    law: str = field(init=False, default="swift")

    def __post_init__(self) -> None:
        if not _finite("Swift K", self.K) > 0.0:
            raise ValueError(f"Swift K must be > 0, got K={self.K}")
        if not _finite("Swift eps0", self.eps0) > 0.0:
            raise ValueError(f"Swift eps0 must be > 0, got eps0={self.eps0}")
        if not 0.0 < _finite("Swift n", self.n) < 1.0:
            raise ValueError(f"Swift exponent n must satisfy 0 < n < 1, got n={self.n}")

    @property
    def initial_yield(self) -> float:
        return float(self.K) * float(self.eps0) ** float(self.n)


@dataclass(frozen=True)
class VoceHardening:
    """sigma_y(alpha) = sigma_y0 + (sigma_inf - sigma_y0)(1 - exp(-delta alpha)) + modulus alpha."""

    sigma_inf: float
    delta: float
    modulus: float = 0.0
    law: str = field(init=False, default="voce")

    def __post_init__(self) -> None:
        _finite("Voce sigma_inf", self.sigma_inf)
        if not _finite("Voce delta", self.delta) > 0.0:
            raise ValueError(f"Voce delta must be > 0, got delta={self.delta}")
        if _finite("Voce modulus", self.modulus) < 0.0:
            raise ValueError(f"Voce linear modulus must be >= 0, got modulus={self.modulus}")


def _numbers(name: str, values: Any) -> tuple[float, ...]:
    """A 1-D sequence of finite numbers as a tuple of floats; ValueError naming ``name`` otherwise."""
    if isinstance(values, (str, bytes, dict)) or np.ndim(values) != 1:
        raise ValueError(f"table hardening {name} must be a list of numbers, got {name}={values!r}")
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ValueError(f"table hardening {name} must be a list of numbers, got {name}={list(values)!r}"
                         ) from None
    if not all(math.isfinite(v) for v in out):
        raise ValueError(f"table hardening {name} must be finite, got {name}={list(out)}")
    return out


@dataclass(frozen=True)
class TableHardening:
    """Piecewise-linear sigma_y(alpha) through the points (strain[i], stress[i]), as an Abaqus or CalculiX
    *PLASTIC table (yield stress, equivalent plastic strain): strain[0] = 0, strains strictly increasing,
    stresses > 0; constant (slope 0, perfect plasticity) beyond the last point, as in Abaqus and CalculiX.
    One point is perfect plasticity at stress[0]."""

    stress: tuple[float, ...]
    strain: tuple[float, ...]
    law: str = field(init=False, default="table")

    def __post_init__(self) -> None:
        stress = _numbers("stress", self.stress)
        strain = _numbers("strain", self.strain)
        if len(stress) != len(strain):
            raise ValueError(f"table hardening stress and strain must have the same length, got "
                             f"{len(stress)} stress and {len(strain)} strain values")
        if len(stress) == 0:
            raise ValueError("table hardening needs at least one point, got stress=[] and strain=[]")
        if not all(v > 0.0 for v in stress):
            raise ValueError(f"table hardening stress must be > 0 at every point, got stress={list(stress)}")
        if strain[0] != 0.0:
            raise ValueError(f"table hardening strain must start at 0 (the initial yield stress), "
                             f"got strain[0]={strain[0]}")
        if not all(b > a for a, b in itertools.pairwise(strain)):
            raise ValueError(f"table hardening strain must be strictly increasing, got strain={list(strain)}")
        object.__setattr__(self, "stress", stress)
        object.__setattr__(self, "strain", strain)

    @property
    def initial_yield(self) -> float:
        return self.stress[0]

    def _segment(self, alpha: float) -> int | None:
        """Index i of the segment [strain[i], strain[i + 1]) holding alpha (the first one for alpha < 0),
        None from the last point on."""
        e = self.strain
        if len(e) == 1 or alpha >= e[-1]:
            return None
        return max(0, min(len(e) - 2, int(np.searchsorted(e, alpha, side="right")) - 1))

    def slope(self, alpha: float) -> float:
        """d sigma_y / d alpha: the slope of the segment holding alpha (the right one at a point), 0 from
        the last point on."""
        i = self._segment(float(alpha))
        if i is None:
            return 0.0
        return (self.stress[i + 1] - self.stress[i]) / (self.strain[i + 1] - self.strain[i])

    def sigma_y(self, alpha: float) -> float:
        """sigma_y(alpha), linear between the points, stress[-1] from the last point on."""
        a = float(alpha)
        i = self._segment(a)
        if i is None:
            return self.stress[-1]
        return self.stress[i] + self.slope(a) * (a - self.strain[i])


Hardening = LinearHardening | SwiftHardening | VoceHardening | TableHardening


def hardening_from_dict(spec: dict[str, Any]) -> Hardening:
    """A hardening law from {"law": "linear"|"swift"|"voce"|"table", ...parameters}."""
    spec = dict(spec)
    law = str(spec.pop("law", "linear")).strip().lower()
    cls = {"linear": LinearHardening, "swift": SwiftHardening, "voce": VoceHardening,
           "table": TableHardening}.get(law)
    if cls is None:
        raise ValueError(f"unknown hardening law {law!r}; known: {', '.join(sorted(_LAWS))}")
    allowed = {"linear": {"modulus"}, "swift": {"K", "eps0", "n"},
               "voce": {"sigma_inf", "delta", "modulus"}, "table": {"stress", "strain"}}[law]
    unknown = set(spec) - allowed
    if unknown:
        raise ValueError(f"unknown parameter(s) {sorted(unknown)} for hardening law {law!r}; "
                         f"expected {sorted(allowed)}")
    try:
        if law == "table":
            return cls(**{k: _numbers(k, v) for k, v in spec.items()})
        return cls(**{k: float(v) for k, v in spec.items()})
    except TypeError as exc:
        raise ValueError(f"hardening law {law!r} needs {sorted(allowed)}: {exc}") from None


@dataclass(frozen=True)
class Hill48:
    """Hill 1948 anisotropy from Lankford r-values (x rolling, y transverse, z normal direction).

    F = r0 / (r90 (1 + r0)), G = 1 / (1 + r0), H = r0 / (1 + r0),
    N = (r0 + r90)(1 + 2 r45) / (2 r90 (1 + r0)), L = M = 3/2 (isotropic out-of-plane shear).
    Normalised so that the equivalent stress is the uniaxial stress in the rolling direction.
    """

    r0: float
    r45: float
    r90: float

    def __post_init__(self) -> None:
        for name in ("r0", "r45", "r90"):
            v = _finite(f"Hill r-value {name}", getattr(self, name))
            if not v > 0.0:
                raise ValueError(f"Hill r-value {name} must be > 0, got {name}={v}")

    @property
    def coefficients(self) -> tuple[float, float, float, float, float, float]:
        """(F, G, H, L, M, N)."""
        r0, r45, r90 = float(self.r0), float(self.r45), float(self.r90)
        Fh = r0 / (r90 * (1.0 + r0))
        Gh = 1.0 / (1.0 + r0)
        Hh = r0 / (1.0 + r0)
        Nh = (r0 + r90) * (1.0 + 2.0 * r45) / (2.0 * r90 * (1.0 + r0))
        return Fh, Gh, Hh, 1.5, 1.5, Nh


def _hill_basis(coef: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Q3 (3x3, column 0 hydrostatic) and p (6,) with P_hat = Q diag(p) Q^T in Mandel coordinates."""
    Fh, Gh, Hh, Lh, Mh, Nh = coef
    Pn = np.array([[Gh + Hh, -Hh, -Gh], [-Hh, Fh + Hh, -Fh], [-Gh, -Fh, Fh + Gh]])
    U = np.array([[1.0 / math.sqrt(2.0), 1.0 / math.sqrt(6.0)],
                  [-1.0 / math.sqrt(2.0), 1.0 / math.sqrt(6.0)],
                  [0.0, -2.0 / math.sqrt(6.0)]])
    B = U.T @ Pn @ U
    B = 0.5 * (B + B.T)
    if abs(B[0, 1]) <= 1e-15 * (abs(B[0, 0]) + abs(B[1, 1])):
        pv, W = np.array([B[0, 0], B[1, 1]]), np.eye(2)
    else:
        pv, W = np.linalg.eigh(B)
    Q3 = np.empty((3, 3))
    Q3[:, 0] = 1.0 / math.sqrt(3.0)
    Q3[:, 1:] = U @ W
    p = np.array([0.0, pv[0], pv[1], Nh, Lh, Mh])
    if not np.all(p[1:] > 0.0):
        raise ValueError(f"Hill coefficients {coef} do not define a positive definite yield function")
    return Q3, p


def _as_hill(h) -> Hill48 | None:
    if h is None or isinstance(h, Hill48):
        return h
    if isinstance(h, dict):
        unknown = set(h) - {"r0", "r45", "r90"}
        if unknown or len(h) != 3:
            raise ValueError(f"hill48 needs exactly r0, r45, r90; got {sorted(h)}")
        return Hill48(**{k: float(v) for k, v in h.items()})
    r = tuple(h)
    if len(r) != 3:
        raise ValueError(f"hill48 needs three r-values (r0, r45, r90), got {len(r)}")
    return Hill48(*(float(v) for v in r))


@dataclass(frozen=True)
class J2Plasticity(LameConstants):
    """Finite-strain J2 plasticity (log-strain space, Hencky elasticity, isotropic + kinematic hardening,
    optional Hill 1948 anisotropy).

    Args:
        E, nu: Young's modulus and Poisson's ratio.
        yield_stress: initial yield stress sigma_y0 (derived as K eps0^n for Swift, as the first stress
            for the table, when None).
        hardening: LinearHardening / SwiftHardening / VoceHardening / TableHardening or a dict
            {"law": ..., ...}.
        kinematic_modulus: H_kin of linear (Prager) kinematic hardening, d beta = 2/3 H_kin d E_p.
        hill48: None (von Mises), Hill48, a dict {"r0", "r45", "r90"} or a tuple (r0, r45, r90).
        density: mass per unit reference volume (dynamics), or None.
    """

    E: float
    nu: float
    yield_stress: float | None = None
    hardening: Any = field(default_factory=LinearHardening)
    kinematic_modulus: float = 0.0
    hill48: Any = None
    kind: int = field(init=False, default=J2)
    name: str = field(init=False, default="j2")
    density: float | None = None  # mass per unit reference volume (dynamics)

    def __post_init__(self) -> None:
        from .common import check_density

        check_density(self.density)
        E, nu = float(self.E), float(self.nu)
        if not (math.isfinite(E) and E > 0.0):
            raise ValueError(f"Young's modulus E must be finite and > 0, got E={self.E}")
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise ValueError(f"Poisson's ratio nu must satisfy -1 < nu < 0.5, got nu={self.nu}")
        hard = self.hardening
        if isinstance(hard, dict):
            hard = hardening_from_dict(hard)
        elif not isinstance(hard, (LinearHardening, SwiftHardening, VoceHardening, TableHardening)):
            raise ValueError(f"hardening must be a dict or a hardening law, got {type(hard).__name__}")
        object.__setattr__(self, "hardening", hard)
        sy = self.yield_stress
        if isinstance(hard, SwiftHardening):
            derived = hard.initial_yield
            if sy is None:
                sy = derived
            elif not abs(float(sy) - derived) <= 1e-6 * abs(derived):
                raise ValueError(f"yield_stress={sy} does not match the Swift law's K eps0^n = {derived!r} "
                                 f"(relative tolerance 1e-6)")
        elif isinstance(hard, TableHardening):
            derived = hard.initial_yield
            if sy is None:
                sy = derived
            elif not abs(float(sy) - derived) <= 1e-6 * abs(derived):
                raise ValueError(f"yield_stress={sy} does not match the table's first stress {derived!r} "
                                 f"(relative tolerance 1e-6)")
        elif sy is None:
            raise ValueError(f"yield_stress is required for the {hard.law} hardening law")
        sy = _finite("yield_stress", sy)
        if not sy > 0.0:
            raise ValueError(f"yield stress must be > 0, got yield_stress={sy}")
        object.__setattr__(self, "yield_stress", sy)
        if isinstance(hard, VoceHardening) and not float(hard.sigma_inf) >= sy:
            raise ValueError(f"Voce sigma_inf must be >= the initial yield stress {sy}, "
                             f"got sigma_inf={hard.sigma_inf}")
        if _finite("kinematic_modulus", self.kinematic_modulus) < 0.0:
            raise ValueError(f"kinematic_modulus must be >= 0, got {self.kinematic_modulus}")
        object.__setattr__(self, "hill48", _as_hill(self.hill48))
        object.__setattr__(self, "_params", self._build_params())

    @property
    def n_hist(self) -> int:
        """History length per material point (NHIST)."""
        return NHIST

    @property
    def params(self) -> np.ndarray:
        """float64 array (NPARAMS,), (NPARAMS + 1 + 2 n) for a table of n points, handed to the kernels
        (layout in the module docstring)."""
        return self._params.copy()

    def yield_stress_at(self, alpha: float) -> float:
        """sigma_y(alpha) of the hardening law (Python reference, for tests and post-processing)."""
        h = self.hardening
        a = float(alpha)
        if isinstance(h, LinearHardening):
            return self.yield_stress + h.modulus * a
        if isinstance(h, SwiftHardening):
            return h.K * (h.eps0 + a) ** h.n
        if isinstance(h, TableHardening):
            return h.sigma_y(a)
        return (self.yield_stress + (h.sigma_inf - self.yield_stress) * (1.0 - math.exp(-h.delta * a))
                + h.modulus * a)

    def _build_params(self) -> np.ndarray:
        h = self.hardening
        n_tab = len(h.strain) if isinstance(h, TableHardening) else 0
        p = np.zeros(NPARAMS + (1 + 2 * n_tab if n_tab else 0))
        lam, mu = lame(float(self.E), float(self.nu))
        p[P_E], p[P_NU], p[P_LAMBDA], p[P_MU] = float(self.E), float(self.nu), lam, mu
        p[P_BULK] = lam + 2.0 * mu / 3.0
        p[P_LAW] = _LAWS[h.law]
        p[P_SY0] = self.yield_stress
        if isinstance(h, LinearHardening):
            p[P_H] = h.modulus
        elif isinstance(h, SwiftHardening):
            p[P_SWIFT_K], p[P_SWIFT_EPS0], p[P_SWIFT_N] = h.K, h.eps0, h.n
        elif isinstance(h, TableHardening):
            p[P_TAB_N] = n_tab
            p[P_TAB:P_TAB + n_tab] = h.strain
            p[P_TAB + n_tab:P_TAB + 2 * n_tab] = h.stress
        else:
            p[P_VOCE_SINF], p[P_VOCE_DELTA], p[P_H] = h.sigma_inf, h.delta, h.modulus
        p[P_HKIN] = float(self.kinematic_modulus)
        if self.hill48 is None:
            coef = (0.5, 0.5, 0.5, 1.5, 1.5, 1.5)
            p[P_HILL] = 0.0
        else:
            coef = self.hill48.coefficients
            p[P_HILL] = 1.0
        p[P_HILL_COEF:P_HILL_COEF + 6] = coef
        Q3, pv = _hill_basis(coef)
        if self.hill48 is None:  # exact von Mises values
            pv = np.array([0.0, 1.5, 1.5, 1.5, 1.5, 1.5])
        p[P_Q3:P_Q3 + 9] = Q3.ravel()
        p[P_P:P_P + 6] = pv
        return p


# ----------------------------------------------------------------------------------------------
# kernels


# ----------------------------------------------------------------------------------------------
# Python wrappers (tests, post-processing)


def j2_point(material: J2Plasticity, F: np.ndarray, hist_n: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """S (6,), D (6, 6), trial history (NHIST,) and status of ``material`` at F from the committed
    history ``hist_n`` (None: the virgin state)."""
    F = np.ascontiguousarray(F, dtype=np.float64).reshape(3, 3)
    hn = np.zeros(NHIST) if hist_n is None else np.ascontiguousarray(hist_n, dtype=np.float64)
    if hn.shape != (NHIST,):
        raise ValueError(f"hist_n must have shape ({NHIST},), got {hn.shape}")
    S = np.empty(6)
    D = np.empty((6, 6))
    hist = np.empty(NHIST)
    status = j2_response(material.params, F, hn, hist, S, D)
    return S, D, hist, int(status)
