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

Kernels: :mod:`covcontact.elements.solidshell_kernels` (element routines) and
:mod:`covcontact.elements.solidshell_loops` (parallel loops over elements).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import get_num_threads

from ..fem.quadrature import DEFAULT_RULE, gauss_tensor
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
OPTION_KEYS = ("eas", "ans_shear", "ans_thickness", "ans_membrane")


def normalize_options(cell_type: str, options: dict | None) -> dict:
    """Validated options with defaults filled in; ValueError with a one-line message otherwise."""
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
    for key in OPTION_KEYS[1:]:
        if key in options:
            v = options[key]
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"solid-shell option {key} must be true or false, got {v!r}")
            out[key] = bool(v)
    if cell_type == "hex8" and out["ans_membrane"]:
        raise ValueError("solid-shell option ans_membrane applies to hex18 only")
    return out


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


def tying_tables(cell_type: str, ans_shear: bool, ans_thickness: bool, ans_membrane: bool):
    """Gauss rule and ANS interpolation of one cell type.

    Returns points (npt, 3) (the ng Gauss points first), weights (ng,), and the CSR tying table
    tie_ptr (6 ng + 1,), tie_pt, tie_w: component I of the natural strain at Gauss point g is
    sum_q tie_w[q] E_I(points[tie_pt[q]]) over q in tie_ptr[6 g + I] .. tie_ptr[6 g + I + 1].
    """
    gp, w = gauss_tensor(DEFAULT_RULE[cell_type])
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


def eas_tables(cell_type: str, neas: int, gauss_points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Natural component (neas,) and values (ng, neas) of the first ``neas`` EAS modes."""
    modes = EAS_MODES[cell_type][:neas]
    comp = np.array([c for c, _ in modes], dtype=np.int64)
    val = np.array([[f(*p) for _, f in modes] for p in gauss_points], dtype=np.float64)
    val = val.reshape(len(gauss_points), neas)
    return comp, np.ascontiguousarray(val)


class SolidShellBody(ElementBody):
    """A solid-shell body (hex8 or hex18), the :class:`SolidBody` interface plus EAS history.

    ``check_reference`` tests the centre and every evaluation point; ``assemble`` and the fields solve
    the EAS parameters for u (local Newton from their last values) and return condensed tangents;
    ``stress`` pushes S forward with the compatible F and reports the assumed strain.

    Args:
        cell_type: "hex8" (quad4 faces) or "hex18" (quad9 faces).
        X: (nnode, 3) reference coordinates.
        cells: (nelem, nen) connectivity, thickness = third natural direction.
        material: a :mod:`covcontact.materials` material.
        **options: eas (number of EAS modes), ans_shear, ans_thickness, ans_membrane (hex18); see
            :func:`normalize_options` and :data:`DEFAULTS`.
    """

    def __init__(self, cell_type: str, X: np.ndarray, cells: np.ndarray, material: Material,
                 chunk_bytes: int = 32 * 2**20, **options: Any) -> None:
        if getattr(material, "n_hist", 0):
            raise ValueError("solid-shells take hyperelastic materials only (no material history yet)")
        self.options = normalize_options(cell_type, options)
        super().__init__(cell_type, X, cells, material, chunk_bytes)
        msg = mesh_problem(cell_type, self.X, self.cells)
        if msg is not None:
            raise ValueError(msg)
        o = self.options
        pts, self.weights, self.tie_ptr, self.tie_pt, self.tie_w = tying_tables(
            cell_type, o["ans_shear"], o["ans_thickness"], o["ans_membrane"])
        self.points = pts
        self.dNp = np.ascontiguousarray(shape_functions(cell_type, pts)[1])
        self.dNc = np.ascontiguousarray(shape_functions(cell_type, np.zeros((1, 3)))[1][0])
        self.neas = o["eas"]
        self.eas_comp, self.eas_val = eas_tables(cell_type, self.neas, pts[: self.weights.size])

    HINTS = ("alpha",)

    def new_state(self) -> dict[str, np.ndarray]:
        """EAS parameters alpha (nelem, neas), zero in the reference state (a hint: the start of the local
        EAS solve, whose result depends on u only)."""
        return {"alpha": np.zeros((self.n_elements, self.neas))}

    def _chunk(self, u, e0, want_K, Ke, fe, flags, nblocks, state) -> None:
        solidshell_chunk(self.material.kind, self.material.params, self.X, u, self.cells, e0, state["alpha"], self.dNp,
                         self.dNc, self.weights, self.tie_ptr, self.tie_pt, self.tie_w, self.eas_comp, self.eas_val,
                         want_K, Ke, fe, flags, nblocks)

    def _gauss_fields(self, u, mode, out, state) -> None:
        solidshell_fields(self.material.kind, self.material.params, self.X, u, self.cells, state["alpha"], self.dNp,
                          self.dNc, self.weights, self.tie_ptr, self.tie_pt, self.tie_w, self.eas_comp, self.eas_val,
                          mode, out, get_num_threads())
