"""Contact laws, each written once: the normal law (penalty or augmented Lagrangian, optionally smoothed over
a band of gaps) and the inverse of
c_ij = a_ij - g h_ij that the exact tangents and the friction kernels share (docs/theory.md section 3).

The kernels take the law as (eps_N, lam_k, band): band = 0 the penalty law, band > 0 the penalty law
smoothed over that width, band = -c0 < 0 the exponential pressure-overclosure law with clearance c0 (eps_N
then the nodal force at zero gap).

Normal law: with the Uzawa multiplier lam_k <= 0 of the last update (0 for pure penalty) the effective
gap is g_e = g + lam_k / eps_N, the normal traction lam_N = eps_N <g_e> = <lam_k + eps_N g> and the pair
is *active* when g_e <= 0 (also at a small positive geometric gap g when lam_k < 0). The functions are
compiled and accept scalars (inside kernels) or arrays (in the Python layer) alike.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def effective_gap(g, lam_k, eps_n):
    """g_e = g + lam_k / eps_N (scalars or arrays)."""
    return g + lam_k / eps_n


@njit(cache=True)
def is_active(g, lam_k, eps_n, band=0.0):
    """The activity test g + lam_k / eps_N <= 0, or < band / 2 with a smoothing band, or g < c0 for the
    exponential law (band = -c0) (scalars or arrays; +inf gaps are inactive)."""
    if band > 0.0:
        return effective_gap(g, lam_k, eps_n) < 0.5 * band
    if band < 0.0:
        return g < -band
    return effective_gap(g, lam_k, eps_n) <= 0.0


#: the exponential law continues linearly beyond this value of t = 1 - g / c0 (an overclosure of 2 c0)
EXP_T_MAX = 3.0


@njit(cache=True)
def exponential_law(g, eps_n, c0):
    """The exponential pressure-overclosure law (scalars): (sigma, dsigma). eps_n is the nodal force at zero
    gap (p0 times the node's area), c0 the clearance at which the force starts; with t = 1 - g / c0:
    sigma = -eps_n t (e^t - 1) / (e - 1) for 0 < t <= EXP_T_MAX, continued linearly beyond."""
    t = 1.0 - g / c0
    if t <= 0.0:
        return 0.0, 0.0
    scale = eps_n / (np.e - 1.0)
    if t <= EXP_T_MAX:
        et = np.exp(t)
        return -scale * t * (et - 1.0), scale * (et - 1.0 + t * et) / c0
    et = np.exp(EXP_T_MAX)
    slope = scale * (et - 1.0 + EXP_T_MAX * et) / c0
    return -scale * EXP_T_MAX * (et - 1.0) - slope * (t - EXP_T_MAX) * c0, slope


@njit(cache=True)
def smooth_law(g, lam_k, eps_n, band):
    """The smoothed normal law (scalars): (sigma, dsigma), sigma = -lam_N <= 0 the signed normal traction and
    dsigma its derivative by g. With b = band / 2 and g_e = g + lam_k / eps_N: sigma = eps_N g_e for
    g_e <= -b (the penalty law itself), -eps_N (b - g_e)^2 / (4 b) for |g_e| < b, 0 beyond: C1 at the
    band's ends."""
    ge = effective_gap(g, lam_k, eps_n)
    b = 0.5 * band
    if ge <= -b:
        return eps_n * ge, eps_n
    if ge >= b:
        return 0.0, 0.0
    t = b - ge
    return -eps_n * t * t / (4.0 * b), eps_n * t / (2.0 * b)


@njit(cache=True)
def linear_equivalent(g, lam_k, eps_n, band):
    """(eps', lam_k') of the linear law lam_k' + eps' g that has the smoothed law's traction and slope at this
    g (an active g: g_e < band / 2): the kernels, written for the linear law, then evaluate the smoothed one
    exactly (residual sigma n, tangent dsigma n n + sigma hess g)."""
    if band == 0.0:
        return eps_n, lam_k
    if band > 0.0:
        sig, dsig = smooth_law(g, lam_k, eps_n, band)
    else:
        sig, dsig = exponential_law(g, eps_n, -band)
    return dsig, sig - dsig * g


def linear_equivalents(g: np.ndarray, lam_k: np.ndarray, eps_n: np.ndarray, band: float):
    """``linear_equivalent`` over arrays of active slaves."""
    if band == 0.0:
        return eps_n, lam_k
    e = np.empty_like(eps_n)
    m = np.empty_like(lam_k)
    for k in range(len(g)):
        e[k], m[k] = linear_equivalent(g[k], lam_k[k], eps_n[k], band)
    return e, m


@njit(cache=True)
def normal_pressure(g, lam_k, eps_n):
    """lam_k + eps_N g: minus the normal traction of an active pair (negative in contact)."""
    return lam_k + eps_n * g


def uzawa_update(lam_k: np.ndarray, g: np.ndarray, eps_n: np.ndarray, band: float = 0.0) -> np.ndarray:
    """The augmented-Lagrangian update lam_k <- min(lam_k + eps_N g, 0) (gaps without contact point: 0); with
    a smoothing band lam_k <- sigma(g), the smoothed traction."""
    gg = np.where(np.isfinite(g), g, 0.0)
    if band > 0.0:
        return np.array([min(smooth_law(gg[k], lam_k[k], eps_n[k], band)[0], 0.0) for k in range(len(gg))])
    return np.minimum(normal_pressure(gg, lam_k, eps_n), 0.0)


@njit(cache=True)
def c_inverse(a_cov, a_con, h_cov, g, out):
    """out = c^ij, the inverse of c_ij = a_ij - g h_ij; a^ij where c_ij is singular (the slave on the focal
    surface of the master, where the exact Hessian does not exist). Returns True when c_ij was invertible."""
    c00 = a_cov[0, 0] - g * h_cov[0, 0]
    c01 = a_cov[0, 1] - g * h_cov[0, 1]
    c11 = a_cov[1, 1] - g * h_cov[1, 1]
    detc = c00 * c11 - c01 * c01
    if abs(detc) > 1e-14 * abs(a_cov[0, 0] * a_cov[1, 1]):
        out[0, 0] = c11 / detc
        out[1, 1] = c00 / detc
        out[0, 1] = -c01 / detc
        out[1, 0] = -c01 / detc
        return True
    for i in range(2):
        for j in range(2):
            out[i, j] = a_con[i, j]
    return False


# -- pressure-overclosure curves evaluated in the Python layer (meshed masters) -----------------------------------
#: the largest clearance a tabular or arctan law reaches, over the square root of the slave's area (CalculiX's c0)
DEFAULT_REACH = 1e-3
#: the slope handed to the kernels is at least this fraction of the law's reference stiffness (a flat piece of a
#: table has none, and the kernels divide by the slope)
SLOPE_FLOOR = 1e-12


class PressureLaw:
    """A pressure-overclosure curve p(d) of the overclosure d = -g (docs/theory.md, "Pressure-overclosure laws"):

    - ``arctan``: p = K d (1/2 + atan(d / e) / pi), e = pi sigma_inf / K (CalculiX's node-to-face LINEAR law with
      its tension, tending to sigma_inf at large clearance, up to the clearance ``reach`` sqrt(area));
    - ``table``: piecewise linear through (d_i, p_i), constant outside the table (CalculiX's TABULAR), felt up to
      the clearance ``reach`` sqrt(area) where p > 0;
    - ``calculix_exponential``: p = p0 exp(-ln(100) g / c0) for g < c0 (CalculiX's EXPONENTIAL), faded linearly to
      zero between c0 and 2 c0 (CalculiX cuts it off at c0, a jump of 0.01 p0 that its frozen contact elements get
      over; covcontact keeps the curve continuous instead).

    p is a pressure (times the slave's area, ``per_area``) or a force per slave node. The kernels are written for the
    linear law; :meth:`equivalents` gives, at each gap, the linear law with this curve's traction and slope there.
    ``stiffness`` is the law's reference slope (K, the table's largest, p0 ln(100) / c0): the scale of its
    tangential penalty and of the slope floor."""

    def __init__(self, kind: str, per_area: bool, slope: float = 0.0, tension: float = 0.0, reach: float | None = None,
                 table: tuple = (), clearance: float = 0.0, pressure: float = 0.0):
        self.kind, self.per_area = kind, per_area
        self.reach = DEFAULT_REACH if reach is None else float(reach)
        if kind == "arctan":
            self.K = float(slope)
            self.e = np.pi * float(tension) / self.K
            self.stiffness = self.K
        elif kind == "table":
            d = np.array([t[0] for t in table], dtype=float)
            p = np.array([t[1] for t in table], dtype=float)
            self.d, self.p = d, p
            self.stiffness = float(np.max(np.abs(np.diff(p) / np.diff(d)))) if len(d) > 1 else 1.0
            self.stiffness = self.stiffness or 1.0
        elif kind == "calculix_exponential":
            self.c0, self.p0 = float(clearance), float(pressure)
            self.beta = np.log(100.0) / self.c0
            self.stiffness = self.p0 * self.beta
        else:
            raise ValueError(f"unknown pressure-overclosure law {kind!r}")

    def pressure(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(p, dp/dd) per unit weight at the gaps ``g`` (finite)."""
        d = -np.asarray(g, dtype=float)
        if self.kind == "arctan":
            x = d / self.e
            s = 0.5 + np.arctan(x) / np.pi
            return self.K * d * s, self.K * (s + x / (np.pi * (1.0 + x * x)))
        if self.kind == "table":
            k = np.clip(np.searchsorted(self.d, d, side="right") - 1, 0, len(self.d) - 2) if len(self.d) > 1 else \
                np.zeros(d.shape, dtype=np.int64)
            if len(self.d) == 1:
                return np.full(d.shape, self.p[0]), np.zeros(d.shape)
            slope = (self.p[k + 1] - self.p[k]) / (self.d[k + 1] - self.d[k])
            inside = (d >= self.d[0]) & (d <= self.d[-1])
            p = np.where(d < self.d[0], self.p[0], np.where(d > self.d[-1], self.p[-1],
                                                             self.p[k] + slope * (d - self.d[k])))
            return p, np.where(inside, slope, 0.0)
        p = self.p0 * np.exp(self.beta * d)
        # beyond c0 (d < -c0) faded linearly to zero at 2 c0: CalculiX's jump from 0.01 p0 to nothing at c0 leaves
        # no equilibrium for a slave at c0 (CalculiX gets through by freezing its contact elements, which then act
        # beyond c0 with the curve itself); the fade lies between the two and is continuous
        fade = np.clip(2.0 + d / self.c0, 0.0, 1.0)
        dfade = np.where((d < -self.c0) & (d > -2.0 * self.c0), 1.0 / self.c0, 0.0)
        return p * fade, self.beta * p * fade + p * dfade

    def limit(self, area: np.ndarray) -> np.ndarray:
        """The largest clearance at which the law acts on each slave: reach sqrt(area), or 1e-10 where a slave has
        no area (CalculiX's rule)."""
        if self.kind == "calculix_exponential":
            return np.full(np.shape(area), 2.0 * self.c0)
        a = np.asarray(area, dtype=float)
        return np.where(a > 0.0, self.reach * np.sqrt(np.maximum(a, 0.0)), 1e-10)  # (CalculiX: 1e-10 without area)

    def traction(self, g: np.ndarray, area: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(active, sigma, dsigma/dg) per slave: sigma = -w p(-g) the signed normal force (negative in compression),
        w the area or 1; active where g is below the law's limit and the force is not zero (or, touching or
        overclosed, is zero: the slope there starts Newton from a touching state). A positive sigma pulls
        (the arctan law's tension at a clearance)."""
        g = np.asarray(g, dtype=float)
        w = area if self.per_area else np.ones_like(g)
        gg = np.where(np.isfinite(g), g, 0.0)
        p, dp = self.pressure(gg)
        active = np.isfinite(g) & (g < self.limit(area)) & ((p != 0.0) | (gg <= 0.0))
        return active, np.where(active, -w * p, 0.0), np.where(active, w * dp, 0.0)

    def equivalents(self, g: np.ndarray, area: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(active, eps', lam') of the linear law lam' + eps' g with this law's traction and slope at each gap (the
        slope at least SLOPE_FLOOR times the reference stiffness times the weight)."""
        active, sig, dsig = self.traction(g, area)
        w = area if self.per_area else np.ones_like(sig)
        eps = np.maximum(dsig, SLOPE_FLOOR * self.stiffness * np.maximum(w, 1e-300))
        gg = np.where(np.isfinite(g), g, 0.0)
        return active, eps, sig - eps * gg
