"""Solid-shell elements (Hauptmann & Schweizerhof 1998; Hauptmann, Schweizerhof & Doll 2000).

Displacement-only hexahedra with one element through the thickness; the thickness direction is the
third natural coordinate t (bottom node layer t = -1, then top layer t = +1, as in
:mod:`covcontact.fem.shapes`). Total Lagrangian, with three locking cures on the covariant
Green-Lagrange strain:

- ANS transverse shear. hex8: Dvorkin-Bathe, E_rt tied at (0, -+1, t), E_st at (-+1, 0, t).
  hex18: MITC9-like, E_rt at (r, s) = (-+a, {-b, 0, b}) interpolated linearly in r and
  quadratically in s (E_st transposed), a = 1/sqrt(3), b = sqrt(3/5).
- ANS thickness strain (curvature-thickness locking): E_tt tied at the in-plane node positions,
  t = 0 (hex8 the four corners (-+1, -+1, 0), bilinear; hex18 the nine quad9 nodes, biquadratic).
- EAS (Poisson thickness locking, in-plane bending): enhanced natural strain modes M(xi) alpha mapped
  with the centre Jacobian (Simo-Rifai), alpha condensed per element after a local Newton solve.
- hex18 only, optional: MITC9-like membrane tying (E_rr like E_rt, E_ss like E_st, E_rs at (-+a, -+a)).

Materials: hyperelastic ones (no history) and J2 plasticity (``n_hist`` values per Gauss point, state key
``hist``). The material sees the enhanced strain E = E_ANS + Gamma alpha through C = I + 2 E (an F with
F^T F = C); with plasticity the return mapping runs from the committed history at every iterate of the
local EAS Newton, so the history, S and the consistent tangent D that condenses alpha are those of the
final alpha (docs/theory.md, "Plastic solid-shells"). Thickness integration: option ``thickness_points``
(2..9) and ``thickness_rule`` ("gauss" or "lobatto"); default 2 Gauss points for materials without
history (the original rule) and 5 Gauss points for plastic ones. Option ``eas_thickness`` (default on for
plastic materials) adds the EAS modes E_tt P_k(t), k = 2 .. points - 1, so that the thickness strain is
free at every thickness level (plastic incompressibility at finite strain asks for a thickness strain
that is not linear in t; without them plastic bending locks).

Kernels: :mod:`covcontact.elements.solidshell_kernels` (element routines; :mod:`.solidshell_dense` its small
dense factorisations) and
:mod:`covcontact.elements.solidshell_loops` (parallel loops over elements).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..fem.axes import calculix_axes
from ..fem.quadrature import DEFAULT_RULE, gauss_1d, gauss_tensor
from ..fem.shapes import NODES, shape_functions
from ..materials.hyperelastic import Material
from .base import ElementBody
from .solidshell_loops import solidshell_chunk, solidshell_fields

SHELL_CELLS = ("hex8", "hex18")

_A = 1.0 / math.sqrt(3.0)
_B = math.sqrt(0.6)


def _p2(x: float) -> float:
    return 0.5 * (3.0 * x * x - 1.0)


#: EAS modes in the order they are switched on by ``eas = n``: (Voigt component of the natural strain
#: (rr, ss, tt, rs, st, rt) = 0..5, the mode function of (r, s, t)); every mode has zero mean.
EAS_MODES: dict[str, list[tuple[int, Any]]] = {
    "hex8": [
        (2, lambda r, s, t: t), (0, lambda r, s, t: r), (1, lambda r, s, t: s),
        (3, lambda r, s, t: r), (3, lambda r, s, t: s),
        (2, lambda r, s, t: r * t), (2, lambda r, s, t: s * t),
    ],
    "hex18": [
        (2, lambda r, s, t: t), (2, lambda r, s, t: r * t), (2, lambda r, s, t: s * t),
        (2, lambda r, s, t: r * s * t), (2, lambda r, s, t: _p2(r) * t), (2, lambda r, s, t: _p2(s) * t),
        (2, lambda r, s, t: _p2(r) * s * t), (2, lambda r, s, t: r * _p2(s) * t),
        (2, lambda r, s, t: _p2(r) * _p2(s) * t),
    ],
}

#: default options per cell type (see docs/verification.md "Shells" for the benchmarks behind them)
DEFAULTS: dict[str, dict[str, Any]] = {
    "hex8": {"eas": 7, "ans_shear": True, "ans_thickness": True, "ans_membrane": False},
    "hex18": {"eas": 4, "ans_shear": True, "ans_thickness": True, "ans_membrane": True},
}
OPTION_KEYS = ("eas", "ans_shear", "ans_thickness", "ans_membrane", "thickness_points", "thickness_rule",
               "eas_thickness")
#: the boolean options
_BOOL_KEYS = ("ans_shear", "ans_thickness", "ans_membrane", "eas_thickness")
#: rules through the thickness and their admissible point counts (Lobatto with 2 points, t = -1 and 1,
#: integrates the bending stiffness three times too large)
THICKNESS_RULES = {"gauss": (2, 9), "lobatto": (3, 9)}
#: default number of thickness points: materials without history keep the original 2-point Gauss rule
#: (results unchanged); materials with history (plasticity) get 5, enough for the elastoplastic stress
#: profile of bending (docs/theory.md "Plastic solid-shells")
THICKNESS_DEFAULT_ELASTIC = {"gauss": 2, "lobatto": 3}
THICKNESS_DEFAULT_PLASTIC = 5


def normalize_options(cell_type: str, options: dict | None) -> dict:
    """Validated options with defaults filled in; ValueError with a one-line message otherwise.

    The thickness integration keys (``thickness_points`` 2..9, Lobatto 3..9; ``thickness_rule`` "gauss" or
    "lobatto"; ``eas_thickness`` true/false) are kept only when given: their defaults depend on the
    material (:func:`resolve_thickness`)."""
    if cell_type not in SHELL_CELLS:
        raise ValueError(f"solid-shell elements need cell type hex8 or hex18, got {cell_type!r}")
    options = dict(options or {})
    unknown = sorted(set(options) - set(OPTION_KEYS))
    if unknown:
        raise ValueError(f"unknown solid-shell option(s) {', '.join(unknown)}; known: {', '.join(OPTION_KEYS)}")
    out = dict(DEFAULTS[cell_type])
    nmax = len(EAS_MODES[cell_type])
    if "eas" in options:
        n = options["eas"]
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or not 0 <= n <= nmax:
            raise ValueError(f"solid-shell option eas must be an integer 0..{nmax} for {cell_type}, got {n!r}")
        out["eas"] = int(n)
    for key in _BOOL_KEYS:
        if key in options:
            v = options[key]
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"solid-shell option {key} must be true or false, got {v!r}")
            out[key] = bool(v)
    if cell_type == "hex8" and out["ans_membrane"]:
        raise ValueError("solid-shell option ans_membrane applies to hex18 only")
    # thickness integration: only the keys given are kept (the default depends on the material,
    # resolved by resolve_thickness())
    rule = options.get("thickness_rule", "gauss")
    if "thickness_rule" in options:
        if not isinstance(rule, str) or rule not in THICKNESS_RULES:
            raise ValueError(f"solid-shell option thickness_rule must be \"gauss\" or \"lobatto\", "
                             f"got {rule!r}")
        out["thickness_rule"] = rule
    if "thickness_points" in options:
        n = options["thickness_points"]
        lo, hi = THICKNESS_RULES[rule]
        if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or not 2 <= n <= 9:
            raise ValueError(f"solid-shell option thickness_points must be an integer 2..9, got {n!r}")
        if not lo <= n <= hi:
            raise ValueError(f"solid-shell option thickness_points must be {lo}..{hi} for the {rule} rule "
                             f"(2 Lobatto points under-integrate bending), got {n}")
        out["thickness_points"] = int(n)
    if out.get("eas_thickness") and out.get("thickness_points", 3) < 3:
        raise ValueError("solid-shell option eas_thickness needs thickness_points >= 3")
    return out


def lobatto_1d(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Lobatto rule on [-1, 1] (end points included; exact for degree 2n - 3), n >= 2."""
    if n < 2:
        raise ValueError("a Lobatto rule needs at least two points")
    P = np.polynomial.legendre.Legendre.basis(n - 1)
    inner = np.sort(np.real(P.deriv().roots())) if n > 2 else np.zeros(0)
    x = np.concatenate([[-1.0], inner, [1.0]])
    w = 2.0 / (n * (n - 1) * P(x) ** 2)
    x = 0.5 * (x - x[::-1])  # exactly symmetric
    w = 0.5 * (w + w[::-1])
    if n % 2:
        x[n // 2] = 0.0
    return x, w


def resolve_thickness(options: dict, n_hist: int = 0) -> tuple[str, int, int]:
    """(rule, points, extra EAS thickness modes) through the thickness for normalised ``options`` and a
    material with ``n_hist`` history values per point.

    Defaults: :data:`THICKNESS_DEFAULT_PLASTIC` points for materials with history or with
    ``eas_thickness = true``, else :data:`THICKNESS_DEFAULT_ELASTIC`; the thickness modes E_tt P_k(t),
    k = 2 .. points - 1 (:func:`thickness_modes`, option ``eas_thickness``) on for materials with history,
    off otherwise."""
    rule = options.get("thickness_rule", "gauss")
    on = options.get("eas_thickness")
    n = options.get("thickness_points")
    if n is None:
        n = THICKNESS_DEFAULT_PLASTIC if n_hist or on else THICKNESS_DEFAULT_ELASTIC[rule]
    if on is None:
        on = bool(n_hist)
    elif on and n < 3:
        raise ValueError("solid-shell option eas_thickness needs thickness_points >= 3")
    return rule, int(n), (int(n) - 2 if on else 0)


def thickness_modes(count: int) -> list[tuple[int, Any]]:
    """EAS modes E_tt P_k(t), k = 2 .. count + 1 (Legendre polynomials, zero mean through the thickness).

    With n thickness points and count = n - 2 they make, together with the compatible (constant in t) and
    the enhanced linear part, the thickness strain free at every thickness level: the thickness stress of
    each level vanishes on average over the element (no spurious pressure when plastic incompressibility
    asks for a thickness strain nonlinear in t, e.g. E_33 = ((1 + kappa z)^-2 - 1)/2 in bending)."""
    modes: list[tuple[int, Any]] = []
    for k in range(2, count + 2):
        Pk = np.polynomial.legendre.Legendre.basis(k)
        modes.append((2, lambda r, s, t, Pk=Pk: float(Pk(t))))
    return modes


def gauss_rule(cell_type: str, rule: str = "gauss", nt: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """In-plane Gauss points (2 x 2 hex8, 3 x 3 hex18) times ``nt`` points of ``rule`` in t (r fastest).

    ``nt = None`` or the Gauss rule with 2 points is the original rule of the element
    (:data:`covcontact.fem.quadrature.DEFAULT_RULE`), bit for bit."""
    order = DEFAULT_RULE[cell_type]
    if rule == "gauss":
        return gauss_tensor((order[0], order[1], order[2] if nt is None else int(nt)))
    xr, wr = gauss_1d(order[0])
    xt, wt = lobatto_1d(int(nt))
    pts = np.array([(r, s, t) for t in xt for s in xr for r in xr], dtype=np.float64)
    w = np.array([a * b * c for c in wt for b in wr for a in wr], dtype=np.float64)
    return np.ascontiguousarray(pts), w


def mesh_problem(cell_type: str, X: np.ndarray, cells: np.ndarray) -> str | None:
    """One-line description of the first badly oriented element, or None.

    Checks det J0 > 0 at the centre, the Gauss points and the corners of every element, and that no
    thickness fibre (bottom node a -> top node a + nen/2) runs opposite to a neighbour's.
    """
    cells = np.asarray(cells, dtype=np.int64)
    if cells.shape[0] == 0:
        return None
    corners = NODES["hex8"]
    pts = np.vstack([np.zeros((1, 3)), gauss_tensor(DEFAULT_RULE[cell_type])[0], corners])
    dN = shape_functions(cell_type, pts)[1]
    J = np.einsum("eai,paj->epij", X[cells], dN)
    det = np.linalg.det(J).min(axis=1)
    scale = np.abs(np.linalg.det(J[:, 0])) + 1e-300
    bad = np.flatnonzero(~(det > 1e-12 * scale))
    if bad.size:
        return f"solid-shell element {int(bad[0])} has det J <= 0 (inverted or degenerate cell, check node order)"
    half = cells.shape[1] // 2
    n = int(X.shape[0])
    keys = (cells[:, :half] * n + cells[:, half:]).ravel()
    rev = (cells[:, half:] * n + cells[:, :half]).ravel()
    clash = np.isin(rev, keys).reshape(-1, half).sum(axis=1)
    if clash.any():
        e = int(np.argmax(clash))  # the element with the most reversed fibres (a flipped one)
        return (f"solid-shell element {e} has its thickness direction opposite to a neighbour "
                f"(bottom nodes 0..{half - 1}, top nodes {half}..{2 * half - 1} must agree)")
    return None


def check_options(mesh, options: dict | None) -> dict:
    """Validate solid-shell ``options`` and the mesh orientation; return the normalised options."""
    out = normalize_options(mesh.cell_type, options)
    msg = mesh_problem(mesh.cell_type, mesh.points, mesh.cells)
    if msg is not None:
        raise ValueError(msg)
    return out


class _Points:
    """Evaluation points with de-duplication."""

    def __init__(self, first: np.ndarray) -> None:
        self.pts: list[tuple[float, float, float]] = []
        self.index: dict[tuple[float, float, float], int] = {}
        for p in first:
            self.add(p, unique=False)

    def add(self, p, unique: bool = True) -> int:
        key = (round(float(p[0]), 12), round(float(p[1]), 12), round(float(p[2]), 12))
        if unique and key in self.index:
            return self.index[key]
        self.index.setdefault(key, len(self.pts))
        self.pts.append((float(p[0]), float(p[1]), float(p[2])))
        return len(self.pts) - 1


def _lagrange(nodes: tuple[float, ...], x: float) -> list[float]:
    out = []
    for k, xk in enumerate(nodes):
        v = 1.0
        for m, xm in enumerate(nodes):
            if m != k:
                v *= (x - xm) / (xk - xm)
        out.append(v)
    return out


def tying_tables(cell_type: str, ans_shear: bool, ans_thickness: bool, ans_membrane: bool,
                 rule: tuple[np.ndarray, np.ndarray] | None = None):
    """Gauss rule and ANS interpolation of one cell type.

    Returns points (npt, 3) (the ng Gauss points first), weights (ng,), and the CSR tying table
    tie_ptr (6 ng + 1,), tie_pt, tie_w: component I of the natural strain at Gauss point g is
    sum_q tie_w[q] E_I(points[tie_pt[q]]) over q in tie_ptr[6 g + I] .. tie_ptr[6 g + I + 1].
    ``rule`` (points, weights): the integration rule (default :func:`gauss_rule` of the cell type);
    the shear and membrane tying points lie at the t of each Gauss point.
    """
    gp, w = gauss_rule(cell_type) if rule is None else rule
    P = _Points(gp)
    rows: list[list[tuple[int, float]]] = []
    for g, (r, s, t) in enumerate(gp):
        comp: list[list[tuple[int, float]]] = [[(g, 1.0)] for _ in range(6)]
        if cell_type == "hex8":
            if ans_shear:
                comp[5] = [(P.add((0.0, -1.0, t)), 0.5 * (1 - s)), (P.add((0.0, 1.0, t)), 0.5 * (1 + s))]
                comp[4] = [(P.add((-1.0, 0.0, t)), 0.5 * (1 - r)), (P.add((1.0, 0.0, t)), 0.5 * (1 + r))]
            if ans_thickness:
                lr, ls = _lagrange((-1.0, 1.0), r), _lagrange((-1.0, 1.0), s)
                comp[2] = [(P.add((x, y, 0.0)), lr[i] * ls[j])
                           for j, y in enumerate((-1.0, 1.0)) for i, x in enumerate((-1.0, 1.0))]
        else:
            lin, quad = (-_A, _A), (-_B, 0.0, _B)
            la_r, la_s = _lagrange(lin, r), _lagrange(lin, s)
            lq_r, lq_s = _lagrange(quad, r), _lagrange(quad, s)
            rows_r = [(P.add((x, y, t)), la_r[i] * lq_s[j]) for j, y in enumerate(quad) for i, x in enumerate(lin)]
            rows_s = [(P.add((x, y, t)), lq_r[i] * la_s[j]) for j, y in enumerate(lin) for i, x in enumerate(quad)]
            if ans_shear:
                comp[5] = rows_r
                comp[4] = rows_s
            if ans_membrane:
                comp[0] = rows_r
                comp[1] = rows_s
                comp[3] = [(P.add((x, y, t)), la_r[i] * la_s[j]) for j, y in enumerate(lin) for i, x in enumerate(lin)]
            if ans_thickness:
                nodes = (-1.0, 0.0, 1.0)
                l3r, l3s = _lagrange(nodes, r), _lagrange(nodes, s)
                comp[2] = [(P.add((x, y, 0.0)), l3r[i] * l3s[j]) for j, y in enumerate(nodes) for i, x in enumerate(nodes)]
        rows.extend(comp)
    tie_ptr = np.zeros(len(rows) + 1, dtype=np.int64)
    tie_ptr[1:] = np.cumsum([len(c) for c in rows])
    tie_pt = np.array([p for c in rows for p, _ in c], dtype=np.int64)
    tie_w = np.array([v for c in rows for _, v in c], dtype=np.float64)
    return np.array(P.pts), w, tie_ptr, tie_pt, tie_w


def eas_tables(cell_type: str, neas: int, gauss_points: np.ndarray, n_thickness: int = 0
               ) -> tuple[np.ndarray, np.ndarray]:
    """Natural component and values (ng, .) of the first ``neas`` EAS modes followed by ``n_thickness``
    thickness modes (:func:`thickness_modes`)."""
    modes = EAS_MODES[cell_type][:neas] + thickness_modes(n_thickness)
    neas = len(modes)
    comp = np.array([c for c, _ in modes], dtype=np.int64)
    val = np.array([[f(*p) for _, f in modes] for p in gauss_points], dtype=np.float64)
    val = val.reshape(len(gauss_points), neas)
    return comp, np.ascontiguousarray(val)


class SolidShellBody(ElementBody):
    """A solid-shell body (hex8 or hex18), the :class:`SolidBody` interface plus EAS history.

    ``check_reference`` tests the centre and every evaluation point; ``assemble`` and the fields solve
    the EAS parameters for u (local Newton from their last values) and return condensed tangents;
    ``stress`` pushes S forward with the compatible F and reports the assumed strain.

    State (:meth:`new_state`): ``alpha`` (a hint, the start of the local EAS Newton) and, for a material
    with history (J2), ``hist`` (nelem, ngp, n_hist). An assembly reads the committed history from
    ``state["hist_n"]`` when given (as :meth:`ElementBody.kernel_state` provides it), else from
    ``state["hist"]``, and writes the trial at the solved alpha into ``state["hist"]``; the fields
    (``stress``, ``energy``) read ``state["hist"]`` as the committed history and write nothing.

    Args:
        cell_type: "hex8" (quad4 faces) or "hex18" (quad9 faces).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, nen) connectivity, thickness = third natural direction.
        material: a :mod:`covcontact.materials` material.
        **options: eas (number of EAS modes), ans_shear, ans_thickness, ans_membrane (hex18),
            thickness_points, thickness_rule, eas_thickness; see :func:`normalize_options`, :data:`DEFAULTS`
            and :func:`resolve_thickness` (attributes ``thickness_rule``, ``thickness_points``,
            ``n_eas_thickness``; ``neas`` counts all EAS modes).
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 chunk_bytes: int = 32 * 2**20, **options: Any) -> None:
        self.options = normalize_options(cell_type, options)
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        msg = mesh_problem(cell_type, self.X, self.cells)
        if msg is not None:
            raise ValueError(msg)
        o = self.options
        self.thickness_rule, self.thickness_points, self.n_eas_thickness = resolve_thickness(o, self.n_hist)
        pts, self.weights, self.tie_ptr, self.tie_pt, self.tie_w = tying_tables(
            cell_type, o["ans_shear"], o["ans_thickness"], o["ans_membrane"],
            gauss_rule(cell_type, self.thickness_rule, self.thickness_points))
        self.points = pts
        self.dNp = np.ascontiguousarray(shape_functions(cell_type, pts)[1])
        self.dNc = np.ascontiguousarray(shape_functions(cell_type, np.zeros((1, 3)))[1][0])
        self.eas_comp, self.eas_val = eas_tables(cell_type, o["eas"], pts[: self.weights.size],
                                                 self.n_eas_thickness)
        self.neas = int(self.eas_comp.size)

    HINTS = ("alpha",)

    @property
    def n_hist(self) -> int:
        """Material history length per Gauss point (0 for hyperelastic materials)."""
        return int(getattr(self.material, "n_hist", 0))

    def new_state(self) -> dict[str, np.ndarray]:
        """EAS parameters alpha (nelem, neas), zero in the reference state (a hint: the start of the local
        EAS solve, whose result depends on u and the committed history only); for a material with history
        also ``hist`` (nelem, ngp, n_hist), the material history per Gauss point (committed / trial)."""
        st = {"alpha": np.zeros((self.n_elements, self.neas))}
        if self.n_hist:
            st["hist"] = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        return st

    def _hist(self, state) -> tuple[np.ndarray, np.ndarray]:
        """(committed, trial) history arrays of ``state``: ``hist_n`` if the caller passes it (read only),
        else ``hist`` itself (the kernels copy each element's committed values first)."""
        if self.n_hist == 0:
            h = np.zeros((self.n_elements, self.weights.size, 0))
            return h, h
        hist = state.get("hist")
        if hist is None:  # a state with the EAS start values only: virgin material
            hist = state["hist"] = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        return state.get("hist_n", hist), hist

    def gauss_volumes(self) -> np.ndarray:
        """(nelem, ngp) reference volume w_g det J0 of every Gauss point (computed once)."""
        if getattr(self, "_gauss_volumes", None) is None:
            dN = self.dNp[: self.weights.size]
            J0 = np.einsum("eai,gak->egik", self.X[self.cells], dN)
            self._gauss_volumes = np.linalg.det(J0) * self.weights[None, :]
        return self._gauss_volumes

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        hist_n, hist = self._hist(state)
        solidshell_chunk(self.material.kind, self.material.params, self.X, u, self.cells, e0, state["alpha"], self.dNp,
                         self.dNc, self.weights, self.tie_ptr, self.tie_pt, self.tie_w, self.eas_comp, self.eas_val,
                         want_K, Ke, fe, flags, nblocks, hist_n, hist)

    def point_stresses(self, u: np.ndarray, state: dict | None = None) -> np.ndarray:
        """(ne, ng, 6) Cauchy stress (xx, yy, zz, xy, yz, xz) at the Gauss points (r fastest, then s, then the
        thickness coordinate t: a hex8's eight in CalculiX's order of a C3D8), at the EAS parameters solved for ``u``
        and the history of ``state`` (read as the committed one)."""
        ng = self.weights.size
        return self._fields(u, 3, 7 * ng, state).reshape(self.n_elements, ng, 7)[..., :6]

    def shell_resultants(self, u: np.ndarray, state: dict | None = None) -> dict[str, np.ndarray]:
        """Per element, in the deformed configuration (docs/theory.md section 6, "Stress resultants"): ``frame``
        (ne, 3, 3) rows e1, e2, e3 (e3 the element's mean director, the bottom-to-top node vectors' mean; e1 the
        global x axis projected off e3, the z axis where e3 is nearly x; e2 = e3 x e1); ``thickness`` (ne,) the mean
        bottom-to-top distance; per unit length of the mid-surface the membrane forces ``N`` (N11, N22, N12), the
        bending moments ``M`` (M11, M22, M12: int sigma_ab z dz, z along e3 from the mid-surface, so M11 > 0
        stretches the top) and the transverse shear forces ``Q`` (Q1, Q2); the stresses on the ``bottom`` and
        ``top`` faces (ne, 6 in the frame: 11, 22, 33, 12, 23, 13), the least-squares line through the Gauss
        points' stresses over the thickness coordinate taken at -1 and +1."""
        ng = self.weights.size
        ne = self.n_elements
        f = self._fields(u, 3, 7 * ng, state).reshape(ne, ng, 7)
        sig, dv = f[..., :6], f[..., 6]
        zeta = self.points[:ng, 2]
        x = self.X + self._u(u)
        h = self.cells.shape[1] // 2
        d = x[self.cells[:, h:]] - x[self.cells[:, :h]]
        t = np.linalg.norm(d, axis=2).mean(axis=1)
        e3 = d.mean(axis=1)
        e3 /= np.linalg.norm(e3, axis=1)[:, None]
        frame = np.stack([*calculix_axes(e3), e3], axis=1)
        i, j = np.array([0, 1, 2, 0, 1, 0]), np.array([0, 1, 2, 1, 2, 2])
        S = np.empty((ne, ng, 3, 3))
        S[..., i, j] = sig
        S[..., j, i] = sig
        local = np.einsum("eai,egij,ebj->egab", frame, S, frame)[..., i, j]   # (ne, ng, 6) in the frame
        volume = dv.sum(axis=1)
        mean = np.einsum("eg,egk->ek", dv, local) / volume[:, None]     # the volume average: N / t
        N = mean * t[:, None]
        M = np.einsum("eg,egk->ek", dv * zeta[None, :], local) * (0.5 * t * t / volume)[:, None]
        zbar = (dv * zeta[None, :]).sum(axis=1) / volume
        zc = zeta[None, :] - zbar[:, None]
        slope = np.einsum("eg,egk->ek", dv * zc, local) / (dv * zc * zc).sum(axis=1)[:, None]
        return {"frame": frame, "thickness": t, "N": N[:, [0, 1, 3]], "M": M[:, [0, 1, 3]], "Q": N[:, [5, 4]],
                "bottom": mean + slope * (-1.0 - zbar)[:, None], "top": mean + slope * (1.0 - zbar)[:, None]}

    def _gauss_fields(self, u, mode, out, state) -> None:
        # the history of ``state`` is read as the committed one (never written)
        hist_n = state.get("hist") if self.n_hist else None
        if hist_n is None:
            hist_n = np.zeros((self.n_elements, self.weights.size, self.n_hist))
        alpha = state["alpha"].copy()  # the local EAS solve writes its result: not into the caller's state
        solidshell_fields(self.material.kind, self.material.params, self.X, u, self.cells, alpha, self.dNp,
                          self.dNc, self.weights, self.tie_ptr, self.tie_pt, self.tie_w, self.eas_comp, self.eas_val,
                          mode, out, hist_n)
