"""Covariant node-to-surface contact element: one slave node against one master facet.

Implements docs/theory.md sections 5 and 8 (penalty or augmented Lagrangian normal law,
internal-force convention). Dof order: the n master nodes first, the slave node last (paper eq. 14);
dof of block b, direction p is 3 b + p.

Normal law: with the multiplier lam_k <= 0 of the last Uzawa update (0 for pure penalty) the
effective gap is g_e = g + lam_k / eps, the traction lam_N = eps <g_e> = <lam_k + eps g> and the
energy W = eps/2 <g_e>^2 = 1/(2 eps) <lam_k + eps g>^2; the pair is active when g_e <= 0 (also at a
small positive geometric gap g when lam_k < 0).

With alpha_b = -N_b (master), 1 (slave) and beta_ib = -N_b,i (master), 0 (slave), the position
matrices are A = [alpha_b I] and A_,i = [beta_ib I], and every tangent part has the block form

    K_bc = eps H [ alpha_b alpha_c (c_nn n(x)n + M^ij rho_i(x)rho_j)
                   + g_e (alpha_c n(x)u_b + alpha_b u_c(x)n) - g_e g s_bc n(x)n ],
    u_b = beta_ib W^ij rho_j,   s_bc = beta_ib S^ij beta_jc

with (c_nn, M, W, S) = main (1, 0, 0, 0), rotational (0, 0, a^ij, 0), curvature (0, -g_e h^ij, 0, 0),
second order (0, g_e/g (a^ij - c^ij + g h^ij), c^ij - a^ij, c^ij); their sum is the exact Hessian
eps H grad g (x) grad g + lam_N hess g of W (c_ij = a_ij - g h_ij with the geometric g). For lam_k = 0,
g_e = g and this is the penalty element of 1/2 eps <g>^2, bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from covcontact.contact.geometry import facet_geometry
from covcontact.contact.laws import c_inverse, effective_gap, is_active
from covcontact.contact.projection import DEGENERATE, project_on_facet
from covcontact.fem.shapes import NODES

#: tangent case codes (paper's cases a-d and the exact Hessian)
CASE_A = 0  # main + rotational + curvature (paper eq. 20)
CASE_B = 1  # main + rotational
CASE_C = 2  # main + curvature
CASE_D = 3  # main only
CASE_EXACT = 4  # exact Hessian of the penalty energy
CASES = {"a": CASE_A, "b": CASE_B, "c": CASE_C, "d": CASE_D, "exact": CASE_EXACT}

#: order of the parts in the ``parts_out`` array
PART_NAMES = ("main", "rotational", "curvature", "second_order")

#: tolerance on |xi^i| - 1 for ``inside``
INSIDE_TOL = 1e-8

_NMAX = 9


@njit(cache=True)
def new_work():
    """Scratch arrays of one contact element evaluation (sized for quad9)."""
    nb = _NMAX + 1
    return (
        np.empty(_NMAX),  # 0 N
        np.empty((_NMAX, 2)),  # 1 dN
        np.empty((_NMAX, 2, 2)),  # 2 ddN
        np.empty(3),  # 3 rho
        np.empty((2, 3)),  # 4 rho_cov
        np.empty((2, 2)),  # 5 a_cov
        np.empty((2, 2)),  # 6 a_con
        np.empty(3),  # 7 n
        np.empty((2, 2)),  # 8 h_cov
        np.empty((2, 2)),  # 9 h_con
        np.empty((2, 2)),  # 10 c_con
        np.empty((2, 2)),  # 11 D1 = c^ij - a^ij
        np.empty((2, 2)),  # 12 D2 = a^ij - c^ij + g h^ij
        np.empty(nb),  # 13 alpha
        np.empty((2, nb)),  # 14 beta
        np.empty((nb, 3)),  # 15 u
        np.empty((3, 3)),  # 16 M
        np.empty((2, 2)),  # 17 Mc
        np.empty((2, 2)),  # 18 Wc
        np.empty((2, 2)),  # 19 Sc
        np.empty((2, 2)),  # 20 D1 with the effective gap, g_e a^ik h_kl c^lj
    )


@njit(cache=True)
def add_terms(nb, alpha, beta, n, rho_cov, g, ge, c_nn, Mc, Wc, Sc, use_w, use_s, scale, K, u, M):
    """K += scale * (block form of the module docstring) for coefficient tensors Mc, Wc, Sc.

    g: geometric gap; ge: effective gap g + lam_k / eps (ge = g for pure penalty).
    """
    for p in range(3):
        for q in range(3):
            M[p, q] = c_nn * n[p] * n[q]
            for i in range(2):
                for j in range(2):
                    M[p, q] += Mc[i, j] * rho_cov[i, p] * rho_cov[j, q]
    if use_w:
        for b in range(nb):
            for q in range(3):
                s = 0.0
                for i in range(2):
                    for j in range(2):
                        s += beta[i, b] * Wc[i, j] * rho_cov[j, q]
                u[b, q] = s
    for b in range(nb):
        for c in range(nb):
            ab = alpha[b] * alpha[c]
            sbc = 0.0
            if use_s:
                for i in range(2):
                    for j in range(2):
                        sbc += beta[i, b] * Sc[i, j] * beta[j, c]
            for p in range(3):
                for q in range(3):
                    v = ab * M[p, q]
                    if use_w:
                        v += ge * (alpha[c] * n[p] * u[b, q] + alpha[b] * u[c, p] * n[q])
                    if use_s:
                        v -= ge * g * sbc * n[p] * n[q]
                    K[3 * b + p, 3 * c + q] += scale * v


@njit(cache=True)
def _set_coeffs(which, ge, a_con, h_con, c_con, D1, D1e, D2, Mc, Wc, Sc):
    """Coefficients (c_nn, use_w, use_s) and Mc, Wc, Sc of a case (0-4) or a part (10 + index).

    ge: effective gap; D1 = c^ij - a^ij, D1e = ge/g D1, D2 = ge/g (a^ij - c^ij + g h^ij).
    """
    c_nn = 0.0
    use_w = False
    use_s = False
    for i in range(2):
        for j in range(2):
            Mc[i, j] = 0.0
            Wc[i, j] = 0.0
            Sc[i, j] = 0.0
    main = which in (CASE_A, CASE_B, CASE_C, CASE_D, CASE_EXACT, 10)
    rot = which in (CASE_A, CASE_B, 11)
    curv = which in (CASE_A, CASE_C, 12)
    if main:
        c_nn = 1.0
    if which == CASE_EXACT:
        use_w = True
        use_s = True
        for i in range(2):
            for j in range(2):
                Mc[i, j] = -D1e[i, j]
                Wc[i, j] = c_con[i, j]
                Sc[i, j] = c_con[i, j]
    if rot:
        use_w = True
        for i in range(2):
            for j in range(2):
                Wc[i, j] = a_con[i, j]
    if curv:
        for i in range(2):
            for j in range(2):
                Mc[i, j] = -ge * h_con[i, j]
    if which == 13:
        use_w = True
        use_s = True
        for i in range(2):
            for j in range(2):
                Mc[i, j] = D2[i, j]
                Wc[i, j] = D1[i, j]
                Sc[i, j] = c_con[i, j]
    return c_nn, use_w, use_s


@njit(cache=True)
def _mat2_prod3(A, B, C, out, fac):
    """out = fac * A B C for 2x2 matrices, symmetrised."""
    for i in range(2):
        for j in range(2):
            s = 0.0
            for k in range(2):
                for m in range(2):
                    s += A[i, k] * B[k, m] * C[m, j]
            out[i, j] = fac * s
    v = 0.5 * (out[0, 1] + out[1, 0])
    out[0, 1] = v
    out[1, 0] = v


@njit(cache=True)
def element_core(xyz, xs, xi1, xi2, eps_n, case, want_parts, R_out, K_out, P_out, work, lam_k=0.0):
    """Residual and tangent of one slave node against one facet at the converged projection.

    Args:
        xyz: (n, 3) facet nodes (n = 4 or 9). xs: (3,) slave position.
        xi1, xi2: converged projection (from ``project_on_facet``).
        eps_n: penalty (already weighted). case: CASE_A ... CASE_EXACT.
        want_parts: also fill P_out[0..3] with main, rotational, curvature, second order.
        R_out: (3(n+1),) out. K_out: (3(n+1), 3(n+1)) out. P_out: (4, 3(n+1), 3(n+1)) out, or any
            array when ``want_parts`` is False. work: tuple from ``new_work``.
        lam_k: normal multiplier (<= 0) of the last Uzawa update, fixed during Newton; 0 = penalty.

    Returns:
        g = (r_s - rho) . n (geometric); +inf at a degenerate facet point. Outputs are zero when
        lam_k + eps_n g > 0.
    """
    (
        N,
        dN,
        ddN,
        rho,
        rho_cov,
        a_cov,
        a_con,
        n,
        h_cov,
        h_con,
        c_con,
        D1,
        D2,
        alpha,
        beta,
        u,
        M,
        Mc,
        Wc,
        Sc,
        D1e,
    ) = work
    nen = xyz.shape[0]
    nb = nen + 1
    m = 3 * nb
    for r in range(m):
        R_out[r] = 0.0
        for s in range(m):
            K_out[r, s] = 0.0
    if want_parts:
        for k in range(4):
            for r in range(m):
                for s in range(m):
                    P_out[k, r, s] = 0.0
    area = facet_geometry(xyz, xi1, xi2, N[:nen], dN[:nen], ddN[:nen], rho, rho_cov, a_cov, a_con, n, h_cov)
    if area == 0.0:
        return np.inf
    g = (xs[0] - rho[0]) * n[0] + (xs[1] - rho[1]) * n[1] + (xs[2] - rho[2]) * n[2]
    ge = effective_gap(g, lam_k, eps_n)  # lam_N = eps_n ge
    if not is_active(g, lam_k, eps_n):
        return g
    for k in range(nen):
        alpha[k] = -N[k]
        beta[0, k] = -dN[k, 0]
        beta[1, k] = -dN[k, 1]
    alpha[nen] = 1.0
    beta[0, nen] = 0.0
    beta[1, nen] = 0.0
    for b in range(nb):
        for p in range(3):
            R_out[3 * b + p] = eps_n * ge * alpha[b] * n[p]
    # h^ij, c^ij = (a_ij - g h_ij)^-1, D1 = c^ij - a^ij = g a^ik h_kl c^lj, D1e = ge a^ik h_kl c^lj,
    # D2 = -g a^ik h_kl D1e^lj
    for i in range(2):
        for j in range(2):
            s = 0.0
            for k in range(2):
                for l in range(2):
                    s += a_con[i, k] * h_cov[k, l] * a_con[l, j]
            h_con[i, j] = s
    c_inverse(a_cov, a_con, h_cov, g, c_con)  # a^ij on the focal surface (no exact Hessian)
    _mat2_prod3(a_con, h_cov, c_con, D1, g)
    _mat2_prod3(a_con, h_cov, c_con, D1e, ge)
    _mat2_prod3(a_con, h_cov, D1e, D2, -g)
    c_nn, use_w, use_s = _set_coeffs(case, ge, a_con, h_con, c_con, D1, D1e, D2, Mc, Wc, Sc)
    add_terms(nb, alpha, beta, n, rho_cov, g, ge, c_nn, Mc, Wc, Sc, use_w, use_s, eps_n, K_out, u, M)
    if want_parts:
        for k in range(4):
            c_nn, use_w, use_s = _set_coeffs(10 + k, ge, a_con, h_con, c_con, D1, D1e, D2, Mc, Wc, Sc)
            add_terms(
                nb, alpha, beta, n, rho_cov, g, ge, c_nn, Mc, Wc, Sc, use_w, use_s, eps_n, P_out[k], u, M
            )
    return g


@njit(cache=True)
def contact_element(xyz, xs, xi, eps_n, case, want_parts, R_out, K_out, P_out, lam_k=0.0):
    """Compiled single-pair entry point: ``element_core`` with its own scratch arrays.

    xi: (2,) converged projection. lam_k: Uzawa multiplier (0 = penalty). Returns g (see
    ``element_core``).
    """
    work = new_work()
    return element_core(xyz, xs, xi[0], xi[1], eps_n, case, want_parts, R_out, K_out, P_out, work, lam_k)


@dataclass
class ContactResult:
    """Result of one contact element evaluation (docs/theory.md section 9).

    Attributes:
        gap: signed normal gap g (negative: penetration).
        xi: (2,) projection in the master's coordinates.
        normal: (3,) unit outward normal of the master at xi.
        inside: whether the projection lies on the facet (|xi^i| <= 1 + INSIDE_TOL).
        residual: (m,) lam_N A^T n, lam_N = <lam_k + eps_N g> (eps_N <g> for pure penalty),
            internal-force convention.
        tangent: (m, m) tangent of the requested case.
        parts: "main", "rotational", "curvature", "second_order" matrices.
        status: projection status (0 converged, 1 not converged).
    """

    gap: float
    xi: np.ndarray
    normal: np.ndarray
    inside: bool
    residual: np.ndarray
    tangent: np.ndarray
    parts: dict = field(default_factory=dict)
    status: int = 0


def _as_points(arr, shape_ok, what):
    a = np.asarray(arr, dtype=np.float64)
    if not shape_ok(a.shape):
        raise ValueError(f"{what} has shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{what} contains non-finite values")
    return np.ascontiguousarray(a)


def check_inputs(slave_xyz, eps_n, parts, xi0):
    """Validate the arguments common to facet and analytic contact; returns (xs, eps, case, xi0)."""
    xs = _as_points(slave_xyz, lambda s: s == (3,), "slave_xyz (expected (3,))")
    if parts not in CASES:
        raise ValueError(f"unknown parts {parts!r}; choose one of {', '.join(CASES)}")
    eps = float(eps_n)
    if not np.isfinite(eps) or eps <= 0.0:
        raise ValueError(f"eps_n must be a positive finite number, got {eps_n!r}")
    if xi0 is not None:
        xi0 = _as_points(xi0, lambda s: s == (2,), "xi0 (expected (2,))").copy()
    return xs, eps, CASES[parts], xi0


def check_multiplier(multiplier):
    """Validate a Uzawa multiplier (finite, <= 0); returns it as float."""
    lk = float(multiplier)
    if not np.isfinite(lk) or lk > 0.0:
        raise ValueError(f"multiplier must be a finite number <= 0, got {multiplier!r}")
    return lk


def node_to_surface(master_xyz, slave_xyz, eps_n, parts="a", xi0=None, multiplier=0.0) -> ContactResult:
    """Contact of one slave node against one quad4/quad9 master facet (docs/theory.md section 9).

    Args:
        master_xyz: (n, 3) current facet nodes, n = 4 or 9, VTK order, outward normal.
        slave_xyz: (3,) current slave position.
        eps_n: penalty parameter (> 0).
        parts: tangent case "a", "b", "c", "d" or "exact".
        xi0: (2,) projection start; default the natural coordinates of the nearest facet node.
        multiplier: augmented Lagrangian multiplier lam_k <= 0 of the last Uzawa update (0: penalty).

    Returns:
        ContactResult; residual and tangent are zero when multiplier + eps_n g > 0.
    """
    xyz = _as_points(master_xyz, lambda s: s in ((4, 3), (9, 3)), "master_xyz (expected (4, 3) or (9, 3))")
    xs, eps, case, xi = check_inputs(slave_xyz, eps_n, parts, xi0)
    lam_k = check_multiplier(multiplier)
    nen = xyz.shape[0]
    if xi is None:
        k = int(np.argmin(np.sum((xyz - xs) ** 2, axis=1)))
        xi = NODES["quad4" if nen == 4 else "quad9"][k].astype(np.float64).copy()
    status, g = project_on_facet(xyz, xs, xi)
    if status == DEGENERATE:
        raise ValueError("degenerate master facet (zero area element at the projection)")
    m = 3 * (nen + 1)
    R = np.zeros(m)
    K = np.zeros((m, m))
    P = np.zeros((4, m, m))
    g = contact_element(xyz, xs, xi, eps, case, True, R, K, P, lam_k)
    nrm = np.zeros(3)
    facet_geometry(
        xyz,
        xi[0],
        xi[1],
        np.empty(nen),
        np.empty((nen, 2)),
        np.empty((nen, 2, 2)),
        np.empty(3),
        np.empty((2, 3)),
        np.empty((2, 2)),
        np.empty((2, 2)),
        nrm,
        np.empty((2, 2)),
    )
    inside = bool(np.all(np.abs(xi) <= 1.0 + INSIDE_TOL))
    return ContactResult(
        gap=float(g),
        xi=xi,
        normal=nrm,
        inside=inside,
        residual=R,
        tangent=K,
        parts={name: P[k] for k, name in enumerate(PART_NAMES)},
        status=int(status),
    )
