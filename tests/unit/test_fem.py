"""Shape functions and Gauss rules: partition of unity, Kronecker property, derivatives against
finite differences, polynomial completeness, quadrature exactness."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from covcontact.fem.quadrature import default_rule, gauss_1d, gauss_hex, gauss_quad, gauss_tensor
from covcontact.fem.shapes import DIM, NNODES, NODES, ORDER, shape_functions

CELLS = ["quad4", "quad9", "hex8", "hex18", "hex27"]


def random_points(dim: int, n: int = 7, seed: int = 0) -> np.ndarray:
    """Random points strictly inside the reference cell [-1, 1]^dim."""
    return np.random.default_rng(seed).uniform(-0.95, 0.95, size=(n, dim))


def interpolate(cell: str, f, pts: np.ndarray) -> np.ndarray:
    """sum_a N_a(pts) f(x_a): the interpolant of f through the nodes of ``cell``."""
    N, _, _ = shape_functions(cell, pts)
    return N @ np.array([f(x) for x in NODES[cell]])


@pytest.mark.parametrize("cell", CELLS)
def test_table_consistency(cell):
    idx_nodes = NODES[cell]
    assert idx_nodes.shape == (NNODES[cell], DIM[cell])
    # nodes are distinct
    assert len({tuple(p) for p in idx_nodes}) == NNODES[cell]
    # number of nodes = product of (order + 1)
    assert NNODES[cell] == np.prod(ORDER[cell] + 1)


@pytest.mark.parametrize("cell", CELLS)
def test_partition_of_unity(cell):
    N, dN, ddN = shape_functions(cell, random_points(DIM[cell]))
    np.testing.assert_allclose(N.sum(axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(dN.sum(axis=1), 0.0, atol=1e-13)
    np.testing.assert_allclose(ddN.sum(axis=1), 0.0, atol=1e-13)


@pytest.mark.parametrize("cell", CELLS)
def test_kronecker_property(cell):
    N, _, _ = shape_functions(cell, NODES[cell])
    np.testing.assert_allclose(N, np.eye(NNODES[cell]), atol=1e-15)


@pytest.mark.parametrize("cell", CELLS)
def test_first_derivatives_fd(cell):
    dim = DIM[cell]
    pts = random_points(dim, seed=1)
    _, dN, _ = shape_functions(cell, pts)
    h = 1e-6
    for d in range(dim):
        e = np.zeros(dim)
        e[d] = h
        Np, _, _ = shape_functions(cell, pts + e)
        Nm, _, _ = shape_functions(cell, pts - e)
        # central differences of a polynomial of degree <= 2 per direction: truncation error is
        # only round-off, O(eps / h) ~ 1e-10
        np.testing.assert_allclose(dN[:, :, d], (Np - Nm) / (2 * h), rtol=0, atol=1e-8)


@pytest.mark.parametrize("cell", CELLS)
def test_second_derivatives_fd(cell):
    dim = DIM[cell]
    pts = random_points(dim, seed=2)
    _, _, ddN = shape_functions(cell, pts)
    h = 1e-6
    for d in range(dim):
        e = np.zeros(dim)
        e[d] = h
        _, dNp, _ = shape_functions(cell, pts + e)
        _, dNm, _ = shape_functions(cell, pts - e)
        # ddN[p, a, i, d] = d/dx_d of dN[p, a, i]
        np.testing.assert_allclose(ddN[:, :, :, d], (dNp - dNm) / (2 * h), rtol=0, atol=1e-8)
    # symmetry of the Hessian
    np.testing.assert_allclose(ddN, np.swapaxes(ddN, 2, 3), atol=1e-15)


@pytest.mark.parametrize("cell", CELLS)
def test_reproduces_coordinates(cell):
    """Isoparametric completeness: sum_a N_a x_a = x, sum_a dN_a/dxi_j x_a,i = delta_ij."""
    dim = DIM[cell]
    pts = random_points(dim, seed=3)
    N, dN, ddN = shape_functions(cell, pts)
    X = NODES[cell]
    np.testing.assert_allclose(N @ X, pts, atol=1e-14)
    jac = np.einsum("pai,aj->pji", dN, X)
    np.testing.assert_allclose(jac, np.broadcast_to(np.eye(dim), jac.shape), atol=1e-13)
    np.testing.assert_allclose(np.einsum("paij,ak->pkij", ddN, X), 0.0, atol=1e-13)


def _reproduced(cell: str, f) -> bool:
    pts = random_points(DIM[cell], n=11, seed=4)
    exact = np.array([f(x) for x in pts])
    return bool(np.allclose(interpolate(cell, f, pts), exact, rtol=0, atol=1e-12))


# (cell, polynomial, reproduced?) : the span of a tensor Lagrange basis holds exactly the
# monomials x^i y^j z^k with i <= order_x, j <= order_y, k <= order_z
SPAN_CASES = [
    ("quad4", lambda x: 1.0 + 2 * x[0] - 3 * x[1] + 0.5 * x[0] * x[1], True),
    ("quad4", lambda x: x[0] ** 2, False),
    ("quad9", lambda x: x[0] ** 2 * x[1] ** 2 - x[0] * x[1] ** 2 + 3 * x[0] ** 2, True),
    ("quad9", lambda x: x[0] ** 3, False),
    ("hex8", lambda x: x[0] * x[1] * x[2] - 2 * x[0] * x[2] + x[1] + 1.0, True),
    ("hex8", lambda x: x[1] ** 2, False),
    ("hex18", lambda x: x[0] ** 2 * x[1] ** 2 * x[2] + x[0] * x[1] ** 2 - x[2], True),
    ("hex18", lambda x: x[2] ** 2, False),
    ("hex18", lambda x: x[0] ** 3, False),
    ("hex27", lambda x: x[0] ** 2 * x[1] ** 2 * x[2] ** 2 + x[0] * x[2] ** 2 - x[1] ** 2, True),
    ("hex27", lambda x: x[2] ** 3, False),
]


@pytest.mark.parametrize("cell,f,expected", SPAN_CASES)
def test_polynomial_span(cell, f, expected):
    assert _reproduced(cell, f) is expected


@pytest.mark.parametrize("cell", CELLS)
def test_full_span_monomials(cell):
    """Every monomial of the tensor span is reproduced; raising any exponent by one is not."""
    order = ORDER[cell]
    dim = DIM[cell]
    for exps in itertools.product(*[range(o + 2) for o in order]):
        inside = all(e <= o for e, o in zip(exps, order))

        def mono(x, exps=exps):
            return float(np.prod([x[d] ** exps[d] for d in range(dim)]))

        assert _reproduced(cell, mono) is inside, (cell, exps)


def _int_1d(k: int) -> float:
    """Exact integral of (1 + x)^k over [-1, 1]."""
    return 2.0 ** (k + 1) / (k + 1)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_gauss_1d_exactness(n):
    x, w = gauss_1d(n)
    assert x.shape == w.shape == (n,)
    np.testing.assert_allclose(w.sum(), 2.0, rtol=1e-14)
    assert np.all(w > 0) and np.all(np.abs(x) < 1)
    # every monomial of degree <= 2n - 1 is exact (odd ones vanish by symmetry, so test the
    # shifted (1 + x)^k, which has all lower-degree terms too)
    for k in range(2 * n):
        assert w @ (1 + x) ** k == pytest.approx(_int_1d(k), rel=1e-13), k
        assert w @ x**k == pytest.approx((1 + (-1) ** k) / (k + 1), abs=1e-14), k
    # degree 2n is not: Gauss error constant is nonzero for x^(2n)
    assert abs(w @ x ** (2 * n) - 2.0 / (2 * n + 1)) > 1e-4
    assert abs(w @ (1 + x) ** (2 * n) - _int_1d(2 * n)) > 1e-4


def test_gauss_1d_rejects_zero_points():
    with pytest.raises(ValueError):
        gauss_1d(0)


@pytest.mark.parametrize("orders", [(1, 1), (2, 3), (3, 3), (2, 2, 2), (3, 3, 2), (1, 2, 4)])
def test_tensor_rule_exactness(orders):
    pts, w = gauss_tensor(orders)
    dim = len(orders)
    assert pts.shape == (int(np.prod(orders)), dim) and w.shape == (pts.shape[0],)
    np.testing.assert_allclose(w.sum(), 2.0**dim, rtol=1e-14)
    maxdeg = [2 * n - 1 for n in orders]
    for exps in itertools.product(*[range(m + 1) for m in maxdeg]):
        vals = np.prod([(1 + pts[:, d]) ** exps[d] for d in range(dim)], axis=0)
        exact = np.prod([_int_1d(e) for e in exps])
        assert w @ vals == pytest.approx(exact, rel=1e-13), exps
    # one degree too many in any direction is not exact
    for d in range(dim):
        exps = [0] * dim
        exps[d] = 2 * orders[d]
        vals = np.prod([pts[:, k] ** exps[k] for k in range(dim)], axis=0)
        exact = 2.0 ** (dim - 1) * 2.0 / (exps[d] + 1)
        assert abs(w @ vals - exact) > 1e-4, (orders, d)


def test_tensor_rule_ordering():
    """First direction runs fastest."""
    pts, _ = gauss_tensor((2, 3))
    x, _ = gauss_1d(2)
    y, _ = gauss_1d(3)
    np.testing.assert_allclose(pts[:2, 0], x)
    np.testing.assert_allclose(pts[:2, 1], y[0])
    np.testing.assert_allclose(pts[::2, 1], y)


def test_named_rules():
    p, w = gauss_quad(3)
    assert p.shape == (9, 2) and w.sum() == pytest.approx(4.0)
    p, w = gauss_hex(2, 3)
    assert p.shape == (12, 3) and w.sum() == pytest.approx(8.0)
    np.testing.assert_allclose(np.unique(p[:, 2]), np.sort(gauss_1d(3)[0]))
    for cell in CELLS:
        p, w = default_rule(cell)
        assert p.shape[1] == DIM[cell]
        assert w.sum() == pytest.approx(2.0 ** DIM[cell], rel=1e-14)


@pytest.mark.parametrize("cell", CELLS)
def test_default_rule_integrates_mass_matrix(cell):
    """The full rule integrates N_a N_b exactly (degree 2 * order per direction <= 2n - 1)."""
    p, w = default_rule(cell)
    N, _, _ = shape_functions(cell, p)
    M = np.einsum("p,pa,pb->ab", w, N, N)
    # compare with a rule of one more point per direction
    orders = tuple(int(o) + 2 for o in ORDER[cell])
    p2, w2 = gauss_tensor(orders)
    N2, _, _ = shape_functions(cell, p2)
    M2 = np.einsum("p,pa,pb->ab", w2, N2, N2)
    np.testing.assert_allclose(M, M2, rtol=1e-12, atol=1e-15)
    assert M.sum() == pytest.approx(2.0 ** DIM[cell], rel=1e-13)
