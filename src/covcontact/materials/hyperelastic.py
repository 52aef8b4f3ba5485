"""Hyperelastic materials: St. Venant-Kirchhoff and compressible Neo-Hooke (the rubber models of the manuals, kind
RUBBER: covcontact.materials.rubber).

A material is a small dataclass on the Python side and, for the kernels, a pair
``(kind, params)``: an int code and a float64 array ``[E, nu, lambda, mu]``. The compiled
:func:`material_response` returns the second Piola-Kirchhoff stress S and the material tangent
D = dS/dE in Voigt notation, order (11, 22, 33, 12, 23, 13), with engineering shear strains
(2 E_12, 2 E_23, 2 E_13), so that dS_I = D_IJ dE_J.

- St. Venant-Kirchhoff: W = lambda/2 (tr E)^2 + mu E:E, S = lambda tr(E) I + 2 mu E.
- Neo-Hooke: W = mu/2 (I_C - 3) - mu ln J + lambda/2 (ln J)^2,
  S = mu (I - C^-1) + lambda ln(J) C^-1,
  D_ijkl = lambda Ci_ij Ci_kl + (mu - lambda ln J) (Ci_ik Ci_jl + Ci_il Ci_jk).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from .common import check_density  # noqa: F401  (re-exported: the materials check their density through it)
from .rubber import RUBBER, Rubber, rubber_energy, rubber_response

#: kind codes understood by the kernels
SVK = 0
NEO_HOOKE = 1

#: Voigt index of the symmetric pair (i, j)
VOIGT = np.array([[0, 3, 5], [3, 1, 4], [5, 4, 2]], dtype=np.int64)
#: (i, j) pair of each Voigt index
VOIGT_PAIRS = np.array([[0, 0], [1, 1], [2, 2], [0, 1], [1, 2], [0, 2]], dtype=np.int64)


def lame(E: float, nu: float) -> tuple[float, float]:
    """Lame constants (lambda, mu) from Young's modulus and Poisson's ratio."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def _check(E: float, nu: float) -> None:
    if not (math.isfinite(E) and E > 0.0):
        raise ValueError(f"Young's modulus E must be finite and > 0, got E={E}")
    if not (math.isfinite(nu) and -1.0 < nu < 0.5):
        raise ValueError(f"Poisson's ratio nu must satisfy -1 < nu < 0.5, got nu={nu}")


class LameConstants:
    """lambda and mu from the attributes E and nu (isotropic elasticity of every material)."""

    E: float
    nu: float

    @property
    def lam(self) -> float:
        """First Lame constant lambda."""
        return lame(self.E, self.nu)[0]

    @property
    def mu(self) -> float:
        """Shear modulus mu."""
        return lame(self.E, self.nu)[1]


@dataclass(frozen=True)
class _Isotropic(LameConstants):
    E: float
    nu: float
    kind: int = field(init=False, default=-1)
    name: str = field(init=False, default="")
    density: float | None = None  # mass per unit reference volume (dynamics)

    def __post_init__(self) -> None:
        _check(float(self.E), float(self.nu))
        check_density(self.density)

    @property
    def params(self) -> np.ndarray:
        """float64 array [E, nu, lambda, mu] handed to the kernels."""
        lam, mu = lame(self.E, self.nu)
        return np.array([self.E, self.nu, lam, mu], dtype=np.float64)


@dataclass(frozen=True)
class SaintVenantKirchhoff(_Isotropic):
    """St. Venant-Kirchhoff: S = lambda tr(E) I + 2 mu E (unstable in strong compression)."""

    kind: int = field(init=False, default=SVK)
    name: str = field(init=False, default="svk")


@dataclass(frozen=True)
class NeoHooke(_Isotropic):
    """Compressible Neo-Hooke: W = mu/2 (I_C - 3) - mu ln J + lambda/2 (ln J)^2."""

    kind: int = field(init=False, default=NEO_HOOKE)
    name: str = field(init=False, default="neo-hooke")


Material = SaintVenantKirchhoff | NeoHooke | Rubber

_NAMES: dict[str, type[SaintVenantKirchhoff | NeoHooke]] = {
    "svk": SaintVenantKirchhoff,
    "saint-venant-kirchhoff": SaintVenantKirchhoff,
    "st-venant-kirchhoff": SaintVenantKirchhoff,
    "neo-hooke": NeoHooke,
    "neohooke": NeoHooke,
}


def material_from_name(name: str, **params: float) -> Material:
    """Material by name ("svk", "saint-venant-kirchhoff", "neo-hooke", "neohooke") with E and nu."""
    key = name.strip().lower().replace("_", "-").replace(" ", "-")
    if key not in _NAMES:
        raise ValueError(f"unknown material {name!r}; known: {', '.join(sorted(_NAMES))}")
    unknown = set(params) - {"E", "nu", "density"}
    if unknown:
        raise ValueError(f"unknown material parameter(s) {sorted(unknown)}; expected E and nu (and density)")
    for p in ("E", "nu"):
        if p not in params:
            raise ValueError(f"material {name!r} needs parameter {p}")
    density = params.get("density")
    return _NAMES[key](E=float(params["E"]), nu=float(params["nu"]),
                       density=None if density is None else float(density))


# ----------------------------------------------------------------------------------------------
# kernels


@njit(cache=True, inline="always")
def _det3(A):
    return (
        A[0, 0] * (A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1])
        - A[0, 1] * (A[1, 0] * A[2, 2] - A[1, 2] * A[2, 0])
        + A[0, 2] * (A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0])
    )


@njit(cache=True)
def material_response(kind, params, F, S, D):
    """Second Piola-Kirchhoff stress S (6,) and tangent D = dS/dE (6, 6) at deformation gradient F.

    Voigt order 11, 22, 33, 12, 23, 13; D acts on engineering shear strains. Returns 0, or 1 when
    det F <= 0 (then S and D are finite: computed for SVK, zero for Neo-Hooke).
    """
    J = _det3(F)
    cm = np.empty(6)  # C - I in Voigt order
    for I in range(6):
        i = VOIGT_PAIRS[I, 0]
        j = VOIGT_PAIRS[I, 1]
        cm[I] = F[0, i] * F[0, j] + F[1, i] * F[1, j] + F[2, i] * F[2, j] - (1.0 if I < 3 else 0.0)
    return _hyperelastic(kind, params, J, cm, math.log(J) if J > 0.0 else 0.0, S, D)


@njit(cache=True)
def material_response_h(kind, params, F, H, S, D):
    """``material_response`` from F and the displacement gradient H = F - I as the element forms it from the
    displacements: C - I = H + H^T + H^T H and ln J = log1p(det F - 1) keep every digit of a small strain (formed
    from F, a strain of 1e-8 keeps 8 digits, and the nodal forces of a stiff body under a small load cancel to a
    residual the convergence test cannot pass)."""
    J = _det3(F)
    cm = np.empty(6)
    for I in range(6):
        i = VOIGT_PAIRS[I, 0]
        j = VOIGT_PAIRS[I, 1]
        cm[I] = H[i, j] + H[j, i] + H[0, i] * H[0, j] + H[1, i] * H[1, j] + H[2, i] * H[2, j]
    # ln J from det(I + H) - 1 = tr H + (the second invariant) + det H
    i2 = (H[0, 0] * H[1, 1] - H[0, 1] * H[1, 0] + H[1, 1] * H[2, 2] - H[1, 2] * H[2, 1]
          + H[0, 0] * H[2, 2] - H[0, 2] * H[2, 0])
    lnJ = math.log1p(H[0, 0] + H[1, 1] + H[2, 2] + i2 + _det3(H)) if J > 0.0 else 0.0
    return _hyperelastic(kind, params, J, cm, lnJ, S, D)


@njit(cache=True, inline="always")
def _hyperelastic(kind, params, J, cm, lnJ, S, D):
    """S and D of St. Venant-Kirchhoff or Neo-Hooke from J = det F, C - I (``cm``, Voigt) and ln J."""
    if kind == RUBBER:
        return rubber_response(params, J, cm, lnJ, S, D)
    lam = params[2]
    mu = params[3]
    status = 0
    if not (J > 0.0):
        status = 1
    if kind == SVK:
        e0 = 0.5 * cm[0]
        e1 = 0.5 * cm[1]
        e2 = 0.5 * cm[2]
        tr = e0 + e1 + e2
        S[0] = lam * tr + 2.0 * mu * e0
        S[1] = lam * tr + 2.0 * mu * e1
        S[2] = lam * tr + 2.0 * mu * e2
        S[3] = mu * cm[3]
        S[4] = mu * cm[4]
        S[5] = mu * cm[5]
        for I in range(6):
            for K in range(6):
                D[I, K] = 0.0
        for I in range(3):
            for K in range(3):
                D[I, K] = lam
            D[I, I] += 2.0 * mu
            D[I + 3, I + 3] = mu
        return status
    # Neo-Hooke
    if status == 1:
        for I in range(6):
            S[I] = 0.0
            for K in range(6):
                D[I, K] = 0.0
        return status
    c = np.empty(6)
    for I in range(6):
        c[I] = cm[I] + (1.0 if I < 3 else 0.0)
    detC = J * J
    Ci = np.empty((3, 3))
    # inverse of the symmetric C by cofactors
    Ci[0, 0] = (c[1] * c[2] - c[4] * c[4]) / detC
    Ci[1, 1] = (c[0] * c[2] - c[5] * c[5]) / detC
    Ci[2, 2] = (c[0] * c[1] - c[3] * c[3]) / detC
    Ci[0, 1] = (c[5] * c[4] - c[3] * c[2]) / detC
    Ci[1, 2] = (c[3] * c[5] - c[0] * c[4]) / detC
    Ci[0, 2] = (c[3] * c[4] - c[5] * c[1]) / detC
    Ci[1, 0] = Ci[0, 1]
    Ci[2, 1] = Ci[1, 2]
    Ci[2, 0] = Ci[0, 2]
    # mu (I - C^-1) = mu C^-1 (C - I): no cancellation at small strain
    for I in range(6):
        i = VOIGT_PAIRS[I, 0]
        j = VOIGT_PAIRS[I, 1]
        S[I] = lam * lnJ * Ci[i, j] + mu * (Ci[i, 0] * cm[VOIGT[0, j]] + Ci[i, 1] * cm[VOIGT[1, j]]
                                            + Ci[i, 2] * cm[VOIGT[2, j]])
    m = mu - lam * lnJ
    for I in range(6):
        i = VOIGT_PAIRS[I, 0]
        j = VOIGT_PAIRS[I, 1]
        for K in range(I, 6):
            k = VOIGT_PAIRS[K, 0]
            l = VOIGT_PAIRS[K, 1]
            v = lam * Ci[i, j] * Ci[k, l] + m * (Ci[i, k] * Ci[j, l] + Ci[i, l] * Ci[j, k])
            D[I, K] = v
            D[K, I] = v
    return status


@njit(cache=True)
def material_energy(kind, params, F):
    """Strain energy density W per unit reference volume (inf for Neo-Hooke and rubber with det F <= 0)."""
    if kind == RUBBER:
        return rubber_energy(params, F)
    lam = params[2]
    mu = params[3]
    C = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            C[i, j] = F[0, i] * F[0, j] + F[1, i] * F[1, j] + F[2, i] * F[2, j]
    if kind == SVK:
        tr = 0.5 * (C[0, 0] + C[1, 1] + C[2, 2] - 3.0)
        ee = 0.0
        for i in range(3):
            for j in range(3):
                e = 0.5 * (C[i, j] - (1.0 if i == j else 0.0))
                ee += e * e
        return 0.5 * lam * tr * tr + mu * ee
    J = _det3(F)
    if not (J > 0.0):
        return np.inf
    lnJ = math.log(J)
    return 0.5 * mu * (C[0, 0] + C[1, 1] + C[2, 2] - 3.0) - mu * lnJ + 0.5 * lam * lnJ * lnJ


# ----------------------------------------------------------------------------------------------
# Python wrappers (tests, post-processing)


def stress_tangent(material: Material, F: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """S (6,), D (6, 6) and status (0 ok, 1 det F <= 0) of ``material`` at F (3, 3)."""
    F = np.ascontiguousarray(F, dtype=np.float64).reshape(3, 3)
    S = np.empty(6)
    D = np.empty((6, 6))
    status = material_response(material.kind, material.params, F, S, D)
    return S, D, int(status)


def strain_energy(material: Material, F: np.ndarray) -> float:
    """Strain energy density W(F) of ``material``."""
    F = np.ascontiguousarray(F, dtype=np.float64).reshape(3, 3)
    return float(material_energy(material.kind, material.params, F))


def voigt_to_tensor(v: np.ndarray) -> np.ndarray:
    """Symmetric (..., 3, 3) tensor from (..., 6) Voigt stress components."""
    v = np.asarray(v)
    return v[..., VOIGT]
