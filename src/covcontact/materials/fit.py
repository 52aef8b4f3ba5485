"""Fitting the rubber models to test data (docs/theory.md section 26, "Fitting to test data"; docs/input.md).

Test data are nominal stress against nominal strain of the three homogeneous tests of an incompressible solid, as
Abaqus takes them (*UNIAXIAL TEST DATA, *BIAXIAL TEST DATA, *PLANAR TEST DATA):

- uniaxial:    stretches (lam, lam^-1/2, lam^-1/2), P = dW/dlam;
- equibiaxial: (lam, lam, lam^-2), P = 1/2 dW/dlam (the nominal stress of either stretched direction);
- planar (pure shear): (lam, 1, lam^-1), P = dW/dlam;

with lam = 1 + strain. In the invariants (W1 = dW/dI1bar, W2 = dW/dI2bar at J = 1):

    uniaxial P = 2 (lam - lam^-2) (W1 + W2 / lam), equibiaxial P = 2 (lam - lam^-5) (W1 + lam^2 W2),
    planar P = 2 (lam - lam^-3) (W1 + W2),

and for Ogden P = sum_p 2 mu_p / alpha_p (lam^(alpha_p - 1) - lam^(-k alpha_p - 1)), k = 1/2, 2, 1 (Treloar; Ogden,
Non-linear elastic deformations, 1984, section 7.2).

Every model's nominal stress is linear in some of its constants (the C_ij; Ogden's mu_p given the alpha_p;
Arruda-Boyce's mu given lambda_m; Gent's mu given J_m). The fit minimises, as Abaqus does by default, the relative
error E = sum_i (1 - P_model(lam_i) / P_test_i)^2 over the points of every test together (the points of zero stress
left out), or the absolute error sum_i (P_model - P_test)^2 (``error = "absolute"``). The polynomial family is fitted
exactly by linear least squares; Ogden, Arruda-Boyce and Gent by variable projection: the linear constants by linear
least squares inside a nonlinear least-squares search (scipy.optimize.least_squares) over the others (the alpha_p
from many starts, bounded to |alpha_p| <= 20; lambda_m, J_m bounded by the data).

Drucker's stability of the fitted incompressible model: with log strains e1, e2 (e3 = -e1 - e2) the principal
Kirchhoff stress differences are t_a - t_3 = dW^/de_a of W^(e1, e2) = W(exp e1, exp e2, exp e3), and dt : de > 0 for
every isochoric de is the positive definiteness of the Hessian H = d2W^/de_a de_b (H11 + H22 > 0, H11 H22 - H12^2 >
0). It is checked, as Abaqus checks it, in uniaxial, equibiaxial and planar tension and compression: every mode over
the stretches the data tested (the tests map onto each other: uniaxial compression at lam is equibiaxial tension at
lam^-1/2, planar compression at lam is planar tension at 1 / lam) and over Abaqus's range of nominal strains, -0.9 to
9 (stretches 0.1 to 10). An instability within the tested strains is a warning; beyond them a note.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .rubber import AB_COEF, MODELS, NMAX, Rubber, RubberError, rubber_from_keys

KINDS = ("uniaxial", "equibiaxial", "planar")
#: accepted spellings of the test kinds
_KIND_ALIASES = {"uniaxial": "uniaxial", "biaxial": "equibiaxial", "equibiaxial": "equibiaxial",
                 "planar": "planar", "pure-shear": "planar", "pure_shear": "planar", "shear": "planar"}
ERRORS = ("relative", "absolute")
#: Abaqus's range of the stability check: nominal strains -0.9 to 9 (stretches 0.1 to 10)
ABAQUS_RANGE = (0.1, 10.0)
ALPHA_BOUND = 20.0


class FitError(ValueError):
    """Bad test data or a model that cannot be fitted; ``key`` names the input key the message is about."""

    def __init__(self, msg: str, key: str | None = None):
        super().__init__(msg)
        self.key = key


@dataclass(frozen=True)
class TestData:
    """One test: ``kind`` (uniaxial, equibiaxial, planar), nominal ``strain`` and nominal ``stress`` (same length),
    ``name`` saying where they come from (a file, or the kind)."""

    kind: str
    strain: np.ndarray
    stress: np.ndarray
    name: str = ""

    @property
    def stretch(self) -> np.ndarray:
        return 1.0 + self.strain

    __test__ = False  # (not a pytest class)


def make_test(kind: str, strain, stress, name: str = "") -> TestData:
    """A checked TestData: a known kind, numbers of equal counts (at least one point), finite, strains > -1 and
    strictly monotone (FitError naming the key: kind, strain, stress)."""
    k = _KIND_ALIASES.get(str(kind).strip().lower().replace(" ", "-"))
    if k is None:
        raise FitError(f"unknown test kind {kind!r} (uniaxial, equibiaxial, planar)", "kind")
    try:
        e = np.asarray(strain, dtype=float).ravel()
        s = np.asarray(stress, dtype=float).ravel()
    except (TypeError, ValueError):
        raise FitError("strain and stress must be arrays of numbers", "strain") from None
    where = f"{name}: " if name else ""
    if e.size == 0 or s.size == 0:
        raise FitError(f"{where}no data points", "strain" if e.size == 0 else "stress")
    if e.size != s.size:
        raise FitError(f"{where}{e.size} strains and {s.size} stresses: give one stress per strain", "stress")
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(s))):
        raise FitError(f"{where}the strains and stresses must be finite", "strain")
    if np.any(e <= -1.0):
        bad = int(np.flatnonzero(e <= -1.0)[0])
        raise FitError(f"{where}nominal strain {e[bad]:g} (point {bad + 1}) is not above -1 (the stretch 1 + strain "
                       f"must be > 0)", "strain")
    d = np.diff(e)
    if d.size and not (np.all(d > 0.0) or np.all(d < 0.0)):
        bad = int(np.flatnonzero(d <= 0.0)[0] if d[0] > 0.0 else np.flatnonzero(d >= 0.0)[0]) + 1
        raise FitError(f"{where}the strains are not monotone: point {bad + 1} ({e[bad]:g}) after {e[bad - 1]:g} "
                       f"(give one loading branch, strains strictly increasing or decreasing)", "strain")
    return TestData(k, e, s, name or k)


_NUM = re.compile(r"[,;\s]+")


def read_table(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(strain, stress) from a text file: two columns separated by commas, semicolons or blanks; '#' starts a
    comment; a first line of words is a header, and where it names 'stress' before 'strain' the columns are in that
    order (else nominal strain, then nominal stress). FitError naming the file and line."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as exc:
        raise FitError(f"cannot read {path}: {exc.strerror or exc}", "file") from None
    rows, stress_first, header_done = [], False, False
    for k, line in enumerate(text.splitlines(), start=1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        fields = [f for f in _NUM.split(line) if f]
        try:
            vals = [float(f) for f in fields]
        except ValueError:
            if not rows and not header_done:  # a header
                low = line.lower()
                stress_first = "stress" in low and "strain" in low and low.index("stress") < low.index("strain")
                header_done = True
                continue
            raise FitError(f"{path.name}, line {k}: {line!r} is not two numbers", "file") from None
        if len(vals) < 2:
            raise FitError(f"{path.name}, line {k}: {line!r} has {len(vals)} number: give strain and stress", "file")
        rows.append(vals[:2])
    if not rows:
        raise FitError(f"{path.name}: no data points", "file")
    a = np.asarray(rows)
    return (a[:, 1], a[:, 0]) if stress_first else (a[:, 0], a[:, 1])


# ----------------------------------------------------------------------------------------------
# the models' incompressible nominal stresses: P = Phi(lam; beta) theta


@dataclass(frozen=True)
class Form:
    """A model's constants split for the fit: ``terms`` name the linear constants theta (the polynomial family's
    (i, j); ('mu', p) for Ogden's mu_p; ('mu',) for Arruda-Boyce and Gent), ``beta`` the others (Ogden's alpha_p,
    Arruda-Boyce's lambda_m, Gent's J_m)."""

    model: str
    terms: tuple
    theta: np.ndarray
    beta: np.ndarray


def polynomial_terms(model: str, n: int | None) -> tuple:
    """The (i, j) of a polynomial-family model in Abaqus's order (C10, C01, C20, C11, C02, C30, ...)."""
    if model == "neo-hooke":
        return ((1, 0),)
    if model == "mooney-rivlin":
        return ((1, 0), (0, 1))
    if model == "yeoh":
        return ((1, 0), (2, 0), (3, 0))
    if model == "reduced-polynomial":
        return tuple((i, 0) for i in range(1, n + 1))
    return tuple((k - j, j) for k in range(1, n + 1) for j in range(k + 1))


def form_of(m: Rubber) -> Form:
    """A Rubber's constants as a Form."""
    if m.model == "ogden":
        return Form("ogden", tuple(("mu", p) for p in range(len(m.mu))), np.array(m.mu, float), np.array(m.alpha, float))
    if m.model == "arruda-boyce":
        return Form(m.model, (("mu",),), np.array([m.mu[0]]), np.array([m.lambda_m]))
    if m.model == "gent":
        return Form(m.model, (("mu",),), np.array([m.mu[0]]), np.array([m.jm]))
    return Form(m.model, tuple((i, j) for i, j, _ in m.c), np.array([v for _, _, v in m.c], float), np.zeros(0))


def _invariants(kind: str, lam: np.ndarray):
    """I1 - 3, I2 - 3 (formed without cancellation near lam = 1), the factor g and the weight a2 of W2 in P = g (W1
    + a2 W2)."""
    d = lam - 1.0
    if kind == "uniaxial":  # I1 = lam^2 + 2 / lam, I2 = 2 lam + lam^-2
        x = d * d * (lam + 2.0) / lam
        y = d * d * (2.0 * lam + 1.0) / (lam * lam)
        return x, y, 2.0 * (lam - lam ** -2), 1.0 / lam
    if kind == "equibiaxial":  # I1 = 2 lam^2 + lam^-4, I2 = lam^4 + 2 lam^-2
        x = d * d * (lam + 1.0) ** 2 * (2.0 * lam * lam + 1.0) / lam ** 4
        y = d * d * (lam + 1.0) ** 2 * (lam * lam + 2.0) / (lam * lam)
        return x, y, 2.0 * (lam - lam ** -5), lam * lam
    # planar: I1 = I2 = lam^2 + 1 + lam^-2
    x = d * d * (lam + 1.0) ** 2 / (lam * lam)
    return x, x, 2.0 * (lam - lam ** -3), 1.0


def _ab_w1(beta, I1):
    """Arruda-Boyce dW/dI1bar / mu and d2W/dI1bar2 / mu."""
    L2 = 1.0 / beta[0] ** 2
    w1 = sum((i + 1) * c * L2 ** i * I1 ** i for i, c in enumerate(AB_COEF))
    w11 = sum((i + 1) * i * c * L2 ** i * I1 ** (i - 1) for i, c in enumerate(AB_COEF) if i > 0)
    return w1, w11


def basis(form: Form, kind: str, lam: np.ndarray, beta: np.ndarray | None = None) -> np.ndarray:
    """Phi (npoints, nterms): the nominal stress of ``kind`` at stretches ``lam`` is Phi theta."""
    lam = np.asarray(lam, dtype=float)
    beta = form.beta if beta is None else beta
    if form.model == "ogden":
        k = {"uniaxial": 0.5, "equibiaxial": 2.0, "planar": 1.0}[kind]
        L = np.log(lam)[:, None]
        a = np.asarray(beta)[None, :]
        # 2 / a (lam^(a - 1) - lam^(-k a - 1)) = 2 / (a lam) (exp(a L) - exp(-k a L)), formed with expm1
        return 2.0 / (a * lam[:, None]) * (np.expm1(a * L) - np.expm1(-k * a * L))
    x, y, g, a2 = _invariants(kind, lam)
    if form.model == "arruda-boyce":
        return (g * _ab_w1(beta, 3.0 + x)[0])[:, None]
    if form.model == "gent":
        return (g * 0.5 / (1.0 - x / beta[0]))[:, None]
    cols = []
    for i, j in form.terms:
        w1 = i * x ** (i - 1) * y ** j if i > 0 else 0.0 * x
        w2 = j * x ** i * y ** (j - 1) if j > 0 else 0.0 * x
        cols.append(g * (w1 + a2 * w2))
    return np.stack(cols, axis=1)


def nominal_stress(model: Rubber | Form, kind: str, strain) -> np.ndarray:
    """The incompressible nominal stress of ``kind`` at nominal ``strain`` (closed form)."""
    form = model if isinstance(model, Form) else form_of(model)
    lam = 1.0 + np.atleast_1d(np.asarray(strain, dtype=float))
    return basis(form, kind, lam) @ form.theta


# ----------------------------------------------------------------------------------------------
# Drucker stability


def _derivatives(form: Form, x: float, y: float):
    """W1, W2, W11, W12, W22 at I1bar - 3 = x, I2bar - 3 = y."""
    if form.model == "arruda-boyce":
        w1, w11 = _ab_w1(form.beta, 3.0 + x)
        return form.theta[0] * w1, 0.0, form.theta[0] * w11, 0.0, 0.0
    if form.model == "gent":
        mu, jm = form.theta[0], form.beta[0]
        r = 1.0 - x / jm
        if r <= 0.0:
            return math.nan, 0.0, math.nan, 0.0, 0.0
        return 0.5 * mu / r, 0.0, 0.5 * mu / (jm * r * r), 0.0, 0.0
    W = [0.0] * 5
    for (i, j), c in zip(form.terms, form.theta):
        if i >= 1:
            W[0] += c * i * x ** (i - 1) * y ** j
        if j >= 1:
            W[1] += c * j * x ** i * y ** (j - 1)
        if i >= 2:
            W[2] += c * i * (i - 1) * x ** (i - 2) * y ** j
        if i >= 1 and j >= 1:
            W[3] += c * i * j * x ** (i - 1) * y ** (j - 1)
        if j >= 2:
            W[4] += c * j * (j - 1) * x ** i * y ** (j - 2)
    return tuple(W)


def log_hessian(model: Rubber | Form, e1: float, e2: float) -> np.ndarray:
    """H = d2W^/de_a de_b (2, 2) of the incompressible model at log strains e1, e2, e3 = -e1 - e2: the tangent of
    the principal Kirchhoff stress differences t_a - t_3 in the log strains (Drucker: stable where H is positive
    definite)."""
    form = model if isinstance(model, Form) else form_of(model)
    e3 = -e1 - e2
    if form.model == "ogden":
        H = np.zeros((2, 2))
        for mu, a in zip(form.theta, form.beta):
            E1, E2, E3 = math.exp(a * e1), math.exp(a * e2), math.exp(a * e3)
            H += 2.0 * mu * np.array([[E1 + E3, E3], [E3, E2 + E3]])
        return H
    p = [math.exp(2.0 * e) for e in (e1, e2, e3)]
    q = [1.0 / v for v in p]
    x = math.expm1(2.0 * e1) + math.expm1(2.0 * e2) + math.expm1(2.0 * e3)
    y = math.expm1(-2.0 * e1) + math.expm1(-2.0 * e2) + math.expm1(-2.0 * e3)
    W1, W2, W11, W12, W22 = _derivatives(form, x, y)
    g1 = np.array([2.0 * (p[0] - p[2]), 2.0 * (p[1] - p[2])])
    g2 = np.array([-2.0 * (q[0] - q[2]), -2.0 * (q[1] - q[2])])
    H1 = 4.0 * np.array([[p[0] + p[2], p[2]], [p[2], p[1] + p[2]]])
    H2 = 4.0 * np.array([[q[0] + q[2], q[2]], [q[2], q[1] + q[2]]])
    return (W1 * H1 + W2 * H2 + W11 * np.outer(g1, g1) + W12 * (np.outer(g1, g2) + np.outer(g2, g1))
            + W22 * np.outer(g2, g2))


#: the modes of the check: (name, log strains (e1, e2) at log stretch L)
MODES = {"uniaxial": lambda L: (L, -0.5 * L), "equibiaxial": lambda L: (L, L), "planar": lambda L: (L, 0.0)}


def stable_at(model: Rubber | Form, kind: str, lam: float) -> bool:
    """Drucker's condition at stretch ``lam`` of the mode ``kind``."""
    H = log_hessian(model, *MODES[kind](math.log(lam)))
    tr, det = H[0, 0] + H[1, 1], H[0, 0] * H[1, 1] - H[0, 1] * H[1, 0]
    return bool(tr > 0.0 and det > 0.0)


def _first_unstable(form: Form, kind: str, lam_end: float, n: int = 500) -> float | None:
    """The stretch, from 1 towards ``lam_end``, where the mode first becomes unstable (to 1e-10 in log stretch), or
    None."""
    L = np.linspace(0.0, math.log(lam_end), n + 1)[1:]
    prev = 0.0
    for v in L:
        if not stable_at(form, kind, math.exp(v)):
            lo, hi = prev, v
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if stable_at(form, kind, math.exp(mid)):
                    lo = mid
                else:
                    hi = mid
                if abs(hi - lo) < 1e-10:
                    break
            return math.exp(hi)
        prev = v
    return None


@dataclass
class ModeCheck:
    """One mode of the check: ``kind`` and ``sense`` (tension, compression), the stretch the data reach in it
    (``tested``, 1 where no test reaches it), the end of the check and the first unstable stretch (None: stable)."""

    kind: str
    sense: str
    tested: float
    end: float
    unstable: float | None

    @property
    def within_data(self) -> bool:
        return self.unstable is not None and (self.unstable <= self.tested if self.sense == "tension"
                                              else self.unstable >= self.tested)

    def describe(self) -> str:
        reach = (f"the data reach {self.tested - 1.0:.4g}" if self.tested != 1.0 else "no test reaches this mode")
        return (f"{self.kind} {self.sense} from nominal strain {self.unstable - 1.0:.4g} ({reach})")


def tested_stretches(tests: list[TestData]) -> dict:
    """The extreme stretch the data reach in each (kind, sense), the tests mapped onto each other (uniaxial
    compression at lam = equibiaxial tension at lam^-1/2, planar compression at lam = planar tension at 1 / lam)."""
    reach = {(k, s): 1.0 for k in KINDS for s in ("tension", "compression")}

    def add(kind, lam):
        key = (kind, "tension" if lam > 1.0 else "compression")
        reach[key] = max(reach[key], lam) if lam > 1.0 else min(reach[key], lam)

    for t in tests:
        for lam in t.stretch:
            if lam == 1.0:
                continue
            if t.kind == "uniaxial":
                add("uniaxial", lam)
                add("equibiaxial", lam ** -0.5)
            elif t.kind == "equibiaxial":
                add("equibiaxial", lam)
                add("uniaxial", lam ** -2.0)
            else:
                add("planar", lam)
                add("planar", 1.0 / lam)
    return reach


def stability(model: Rubber | Form, tests: list[TestData] = ()) -> list[ModeCheck]:
    """Drucker's check in the six modes over the tested stretches and Abaqus's range (0.1 to 10)."""
    form = model if isinstance(model, Form) else form_of(model)
    reach = tested_stretches(list(tests))
    out = []
    for kind in KINDS:
        for sense in ("tension", "compression"):
            tested = reach[(kind, sense)]
            end = max(tested, ABAQUS_RANGE[1]) if sense == "tension" else min(tested, ABAQUS_RANGE[0])
            out.append(ModeCheck(kind, sense, tested, end, _first_unstable(form, kind, end)))
    return out


def stability_verdict(checks: list[ModeCheck]) -> tuple[list[str], list[str]]:
    """(warnings, notes): an instability within the tested strains is a warning, beyond them a note."""
    warn = [c.describe() for c in checks if c.within_data]
    beyond = [c.describe() for c in checks if c.unstable is not None and not c.within_data]
    notes = []
    if not warn and not beyond:
        notes.append("Drucker-stable in uniaxial, equibiaxial and planar tension and compression at the tested strains "
                     "and over nominal strains -0.9 to 9")
    elif not warn:
        notes.append("Drucker-stable at the tested strains; unstable beyond them in " + "; ".join(beyond))
    warnings = (["unstable (Drucker) at the tested strains in " + "; ".join(warn)
                 + (" (and beyond them in " + "; ".join(beyond) + ")" if beyond else "")] if warn else [])
    return warnings, notes


# ----------------------------------------------------------------------------------------------
# the fit


@dataclass
class Fit:
    """A fitted model: ``keys`` are its constants as the problem file names them (rubber_from_keys), ``form`` the
    same as a Form; per test the RMS and largest relative errors and the RMS absolute error; the stability check."""

    model: str
    n: int | None
    error: str
    keys: dict
    form: Form
    tests: list[TestData]
    errors: list[dict]
    checks: list[ModeCheck]
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def mu0(self) -> float:
        f = self.form
        if f.model == "ogden":
            return float(np.sum(f.theta))
        if f.model == "gent":
            return float(f.theta[0])
        if f.model == "arruda-boyce":
            return float(2.0 * f.theta[0] * _ab_w1(f.beta, 3.0)[0])
        c = dict(zip(f.terms, f.theta))
        return float(2.0 * (c.get((1, 0), 0.0) + c.get((0, 1), 0.0)))

    def rubber(self, d, density=None) -> Rubber:
        """The Rubber with these constants and the compressibility keys ``d`` (a dict of d1.. or d)."""
        keys = dict(self.keys)
        keys.update(d)
        if self.model in ("polynomial", "reduced-polynomial"):
            keys["n"] = self.n
        return rubber_from_keys(self.model, keys, density)

    def constants_text(self) -> str:
        """'mu = [0.63, ...], alpha = [...]' (problem-file keys, 6 digits)."""
        parts = []
        for k, v in self.keys.items():
            parts.append(f"{k} = [{', '.join(f'{x:.6g}' for x in v)}]" if isinstance(v, list) else f"{k} = {v:.6g}")
        return ", ".join(parts)

    def lines(self) -> list[str]:
        """The report: the constants, the error per test, the stability verdict."""
        npts = sum(t.strain.size for t in self.tests)
        head = f"{self.model}" + (f", N = {self.n}" if self.n and self.model in ("polynomial", "reduced-polynomial",
                                                                                 "ogden") else "")
        out = [f"{head} fitted to {len(self.tests)} test{'s' * (len(self.tests) != 1)} ({npts} points; "
               f"{self.error} error): {self.constants_text()}; initial shear modulus mu0 = {self.mu0:.6g}"]
        for t, e in zip(self.tests, self.errors):
            out.append(f"  {t.kind:<11s} {t.name:<16s} {t.strain.size:3d} points, nominal strains "
                       f"{t.strain.min():.4g} to {t.strain.max():.4g}: RMS relative error {100 * e['rms_rel']:.2f} %, "
                       f"largest {100 * e['max_rel']:.2f} %, RMS error {e['rms_abs']:.4g}")
        return out


def _n_constants(model: str, n: int | None) -> int:
    if model == "ogden":
        return 2 * n
    if model in ("arruda-boyce", "gent"):
        return 2
    return len(polynomial_terms(model, n))


def fit(model: str, tests: list[TestData], n: int | None = None, error: str = "relative") -> Fit:
    """Fit ``model`` (one of rubber.MODELS; ``n`` the order of the polynomial and reduced polynomial, the number of
    Ogden terms) to ``tests`` together, minimising the ``error`` ("relative", Abaqus's default, or "absolute")."""
    model = model.strip().lower().replace("_", "-").replace(" ", "-")
    model = "neo-hooke" if model == "neohooke" else model
    if model not in MODELS:
        raise FitError(f"unknown rubber model {model!r} (known: {', '.join(MODELS)})", "model")
    if error not in ERRORS:
        raise FitError(f"error must be \"relative\" or \"absolute\", got {error!r}", "error")
    if model in ("polynomial", "reduced-polynomial", "ogden"):
        if n is None:
            n = 1 if model != "ogden" else 3
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= NMAX:
            raise FitError(f"must be an integer from 1 to {NMAX}, got {n!r}", "n")
    elif n is not None:
        raise FitError(f"{model} has a fixed number of constants: leave out n", "n")
    if not tests:
        raise FitError("no test data", "test_data")
    lam = [t.stretch for t in tests]
    y = [t.stress for t in tests]
    use = [np.ones(t.stress.size, bool) if error == "absolute" else t.stress != 0.0 for t in tests]
    npts = int(sum(u.sum() for u in use))
    nc = _n_constants(model, n)
    if nc > npts:
        zero = " (points of zero stress do not count for the relative error)" if error == "relative" else ""
        raise FitError(f"{model}{f' N = {n}' if model in ('polynomial', 'reduced-polynomial', 'ogden') else ''} has "
                       f"{nc} constants and the data {npts} points{zero}: give more points or take a model with fewer "
                       f"constants", "test_data")
    Y = np.concatenate([yi[u] for yi, u in zip(y, use)])
    w = np.ones_like(Y) if error == "absolute" else 1.0 / np.abs(Y)

    def solve(form: Form, beta) -> tuple[np.ndarray, np.ndarray]:
        A = np.concatenate([basis(form, t.kind, li[u], beta) for t, li, u in zip(tests, lam, use)]) * w[:, None]
        scale = np.linalg.norm(A, axis=0)
        scale[scale == 0.0] = 1.0
        theta = np.linalg.lstsq(A / scale, Y * w, rcond=None)[0] / scale
        return theta, A @ theta - Y * w

    if model in ("arruda-boyce", "gent", "ogden"):
        from scipy.optimize import least_squares

        terms = tuple(("mu", p) for p in range(n)) if model == "ogden" else (("mu",),)
        form0 = Form(model, terms, np.zeros(0), np.zeros(0))
        if model == "ogden":
            starts = _ogden_starts(n)
            lo, hi = -ALPHA_BOUND * np.ones(n), ALPHA_BOUND * np.ones(n)
            to_beta = (lambda z: z)
        else:
            xmax = max(float(np.max(_invariants(t.kind, li)[0])) for t, li in zip(tests, lam))
            if model == "gent":  # J_m = xmax (1 + exp z): above every tested I1bar - 3
                to_beta = (lambda z: np.array([max(xmax, 1e-12) * (1.0 + math.exp(z[0]))]))
                starts, lo, hi = [np.array([v]) for v in (-2.0, 0.0, 2.0, 5.0)], np.array([-25.0]), np.array([25.0])
            else:  # lambda_m = 1 + exp z
                to_beta = (lambda z: np.array([1.0 + math.exp(z[0])]))
                starts, lo, hi = [np.array([v]) for v in (-1.0, 0.5, 1.5, 3.0)], np.array([-10.0]), np.array([10.0])
        best = None
        for z0 in starts:
            try:
                r = least_squares(lambda z: solve(form0, to_beta(z))[1], z0, bounds=(lo, hi), x_scale=1.0,
                                  xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=400)
            except (ValueError, FloatingPointError, OverflowError):
                continue
            if np.isfinite(r.cost) and (best is None or r.cost < best.cost):
                best = r
        if best is None:
            raise FitError(f"the {model} fit failed from every start", "test_data")
        beta = to_beta(best.x)
        theta = solve(form0, beta)[0]
        if model == "ogden":  # (terms ordered by alpha)
            order = np.argsort(beta)
            beta, theta = beta[order], theta[order]
        form = Form(model, form0.terms, theta, beta)
    else:
        form0 = Form(model, polynomial_terms(model, n), np.zeros(0), np.zeros(0))
        theta = solve(form0, None)[0]
        form = Form(model, form0.terms, theta, np.zeros(0))
    keys = _keys(form)
    errors = []
    for t, li in zip(tests, lam):
        P = basis(form, t.kind, li) @ form.theta
        nz = t.stress != 0.0
        rel = (P[nz] - t.stress[nz]) / t.stress[nz] if nz.any() else np.zeros(1)
        errors.append({"rms_rel": float(np.sqrt(np.mean(rel ** 2))), "max_rel": float(np.max(np.abs(rel))),
                       "rms_abs": float(np.sqrt(np.mean((P - t.stress) ** 2)))})
    checks = stability(form, tests)
    warnings, notes = stability_verdict(checks)
    out = Fit(model, n, error, keys, form, list(tests), errors, checks, warnings, notes)
    if not out.mu0 > 0.0:
        raise FitError(f"the fitted {model} has the initial shear modulus mu0 = {out.mu0:.4g} <= 0 ({out.constants_text()}): "
                       f"the data do not determine this model; take fewer constants or add tests", "test_data")
    return out


def _ogden_starts(n: int) -> list[np.ndarray]:
    """Starting exponents: the distinct n-subsets of a spread of alphas (at most 20, deterministic)."""
    cand = [-6.0, -2.0, -1.0, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 8.0]
    combos = list(itertools.combinations(cand, n))
    if len(combos) > 20:
        idx = np.linspace(0, len(combos) - 1, 20).round().astype(int)
        combos = [combos[i] for i in idx]
    return [np.array(c) for c in combos]


def _keys(form: Form) -> dict:
    if form.model == "ogden":
        return {"mu": [float(v) for v in form.theta], "alpha": [float(v) for v in form.beta]}
    if form.model == "arruda-boyce":
        return {"mu": float(form.theta[0]), "lambda_m": float(form.beta[0])}
    if form.model == "gent":
        return {"mu": float(form.theta[0]), "jm": float(form.beta[0])}
    return {f"c{i}{j}": float(v) for (i, j), v in zip(form.terms, form.theta)}


# ----------------------------------------------------------------------------------------------
# input: a material table with test_data


def read_tests(entries, base: Path) -> list[TestData]:
    """The ``test_data`` array of a material table: each ``{ kind = "uniaxial", file = "uni.csv" }`` or ``{ kind =
    ..., strain = [...], stress = [...] }``. FitError with ``key`` the path below the material ('test_data[1].file')."""
    if not isinstance(entries, list) or not entries:
        raise FitError("must be an array of tests: [{ kind = \"uniaxial\", file = \"uni.csv\" }, ...]", "test_data")
    out = []
    for k, e in enumerate(entries):
        at = f"test_data[{k}]"
        if not isinstance(e, dict):
            raise FitError("must be a table { kind = ..., file = ... } or { kind = ..., strain = [...], stress = "
                           "[...] }", at)
        unknown = sorted(set(e) - {"kind", "file", "strain", "stress"})
        if unknown:
            raise FitError("unknown key (kind, file, strain, stress)", f"{at}.{unknown[0]}")
        if "kind" not in e:
            raise FitError("missing required key (uniaxial, equibiaxial, planar)", f"{at}.kind")
        if not isinstance(e["kind"], str):
            raise FitError("must be \"uniaxial\", \"equibiaxial\" or \"planar\"", f"{at}.kind")
        if "file" in e:
            if "strain" in e or "stress" in e:
                raise FitError("give file, or strain and stress, not both", f"{at}.file")
            if not isinstance(e["file"], str):
                raise FitError("must be a file name", f"{at}.file")
            p = Path(e["file"])
            p = p if p.is_absolute() else base / p
            if not p.is_file():
                raise FitError(f"no file {p}", f"{at}.file")
            try:
                strain, stress = read_table(p)
                out.append(make_test(e["kind"], strain, stress, p.name))
            except FitError as exc:
                raise FitError(str(exc), f"{at}.file" if exc.key in ("file", "strain", "stress") else f"{at}.kind") \
                    from None
            continue
        for key in ("strain", "stress"):
            if key not in e:
                raise FitError("missing required key (or give file)", f"{at}.{key}")
            v = e[key]
            if not isinstance(v, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
                raise FitError("must be an array of numbers", f"{at}.{key}")
        try:
            out.append(make_test(e["kind"], e["strain"], e["stress"], ""))
        except FitError as exc:
            raise FitError(str(exc), f"{at}.{exc.key}") from None
    return out


#: the compressibility keys of each model in a fitted material
def _d_keys(model: str) -> tuple:
    return ("d",) if model in ("arruda-boyce", "ogden") else tuple(f"d{i}" for i in range(1, NMAX + 1))


def fitted_material(model: str, keys: dict, base: Path, density: float | None = None, name: str = ""):
    """A Rubber fitted to the test data of a problem file's material table (``keys``: everything but ``model`` and
    ``density``: test_data, n, error and the compressibilities d1.. (d for Ogden and Arruda-Boyce), or ``poisson``, the
    initial Poisson's ratio they follow from with the fitted mu0, as Abaqus's POISSON=). The Rubber's
    ``fitted`` holds the report lines (the constants, the errors, the stability verdict; lines that begin with
    'warning: ' are warnings). Raises FitError or RubberError naming the key."""
    keys = dict(keys)
    model = model.strip().lower().replace("_", "-").replace(" ", "-")
    model = "neo-hooke" if model == "neohooke" else model
    tests = read_tests(keys.pop("test_data"), base)
    n = keys.pop("n", None)
    error = keys.pop("error", "relative")
    if not isinstance(error, str):
        raise FitError("must be \"relative\" or \"absolute\"", "error")
    dk = _d_keys(model)
    poisson = keys.pop("poisson", None)
    d = {}
    for k in list(keys):
        if k in dk:
            d[k] = keys.pop(k)
    if keys:
        k = sorted(keys)[0]
        raise FitError(f"with test_data the constants are fitted: give test_data, n, error and {', '.join(dk[:2])}"
                       f"{', ...' if len(dk) > 2 else ''} or poisson (the compressibility) only", k)
    if poisson is not None:
        if d:
            raise FitError(f"give the compressibility once: poisson or {dk[0]}", "poisson")
        if isinstance(poisson, bool) or not isinstance(poisson, (int, float)) or not -1.0 < poisson < 0.5:
            raise FitError(f"must be a number in (-1, 0.5) (0.5, incompressible, needs a mixed formulation covcontact "
                           f"does not have: e.g. 0.495), got {poisson!r}", "poisson")
    elif not d:
        raise FitError(f"missing required key: the fit is incompressible; give the compressibility ({dk[0]} > 0, e.g. "
                       f"{dk[0]} = 2 / (1000 mu0) for K0 = 1000 mu0, or poisson = 0.4995)", dk[0])
    f = fit(model, tests, n, error)
    notes = list(f.notes)
    if poisson is not None:  # (as Abaqus's POISSON=: D1 = 2 / K0 from the fitted mu0, the higher D_i zero)
        if not f.mu0 > 0.0:
            raise FitError(f"the fitted initial shear modulus mu0 = {f.mu0:.6g} is not positive: no compressibility "
                           f"follows from poisson (fit another model or order to these data)", "test_data")
        d1 = 3.0 * (1.0 - 2.0 * poisson) / (f.mu0 * (1.0 + poisson))
        d = {"d": [d1] if model == "ogden" else d1} if dk == ("d",) else {"d1": d1}
        notes.append(f"compressibility from Poisson's ratio {poisson:g}: D1 = 3 (1 - 2 nu) / (mu0 (1 + nu)) = "
                     f"{d1:.6g} (K0 = {2.0 / d1:.6g})")
    m = f.rubber(d, density)
    lines = [f"{name + ': ' if name else ''}{f.lines()[0]}", *f.lines()[1:]]
    lines += [f"warning: {name + ': ' if name else ''}{w}" for w in f.warnings]
    lines += [f"  {x}" for x in notes]
    object.__setattr__(m, "fitted", tuple(lines))
    object.__setattr__(m, "fit", f)
    return m


def fit_notes(bodies) -> list[str]:
    """The report of every material of the bodies whose constants were fitted to test data, 'body 'seal': ogden,
    N = 3 fitted to ...' (lines beginning 'warning: ' are warnings): the run's log says them once."""
    out = []
    for b in bodies:
        for name, mat in [("", getattr(b, "material", None)), *getattr(b, "materials", {}).items()]:
            where = f"body {b.name!r}" + (f", element set {name!r}" if name else "")
            for line in getattr(mat, "fitted", ()):
                out.append(f"warning: {where}: {line[9:]}" if line.startswith("warning: ") else f"{where}: {line}")
    return out


# ----------------------------------------------------------------------------------------------
# covcontact fit-material


def plot_fit(f: Fit, path: str | Path, title: str = "") -> None:
    """Data (markers) and fit (lines) of every test, nominal stress against nominal strain, to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    colors = {"uniaxial": "C0", "equibiaxial": "C3", "planar": "C2"}
    for t, e in zip(f.tests, f.errors):
        lo, hi = min(0.0, t.strain.min()), max(0.0, t.strain.max())
        s = np.linspace(lo, hi, 300)
        c = colors[t.kind]
        ax.plot(t.strain, t.stress, "o", color=c, ms=4, label=f"{t.kind} data ({t.name})" if t.name != t.kind
                else f"{t.kind} data")
        ax.plot(s, nominal_stress(f.form, t.kind, s), "-", color=c,
                label=f"{t.kind} fit (RMS relative error {100 * e['rms_rel']:.1f} %)")
    ax.set_xlabel("nominal strain")
    ax.set_ylabel("nominal stress")
    ax.grid(alpha=0.3)
    head = f"{f.model}" + (f" N = {f.n}" if f.model in ("polynomial", "reduced-polynomial", "ogden") else "")
    ax.set_title(f"{title}\n{head}, mu0 = {f.mu0:.4g}" if title else f"{head}, mu0 = {f.mu0:.4g}", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
