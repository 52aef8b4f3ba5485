"""Node-structured CSR pattern: layout, ranks, scatter against a scipy COO assembly."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from covcontact.assembly import Pattern


def random_block(rng, n_nodes: int, nelem: int, nen: int) -> np.ndarray:
    """Connectivity with distinct nodes inside each element."""
    return np.array([rng.choice(n_nodes, size=nen, replace=False) for _ in range(nelem)], dtype=np.int64)


def coo_matrix(n_dofs: int, conn: np.ndarray, Ke: np.ndarray, offset: int = 0) -> sp.csr_matrix:
    """Reference: the element matrices summed by scipy's COO -> CSR conversion."""
    dofs = (3 * (conn + offset)[:, :, None] + np.arange(3)).reshape(conn.shape[0], -1)
    rows = np.repeat(dofs[:, :, None], dofs.shape[1], axis=2).ravel()
    cols = np.repeat(dofs[:, None, :], dofs.shape[1], axis=1).ravel()
    return sp.coo_matrix((Ke.ravel(), (rows, cols)), shape=(n_dofs, n_dofs)).tocsr()


def test_layout_and_offsets():
    conn = np.array([[0, 1, 2, 3], [2, 3, 4, 5]])
    P = Pattern(7, [conn], extra_pairs=np.array([[0, 6]]))
    deg = P.node_deg
    # node 0: {0,1,2,3,6}; node 6 (only in the extra pair): {0, 6}; node 2: {0..5}
    assert list(P.node_adj[P.node_ptr[0]:P.node_ptr[1]]) == [0, 1, 2, 3, 6]
    assert list(P.node_adj[P.node_ptr[6]:P.node_ptr[7]]) == [0, 6]
    assert deg[2] == 6
    assert P.nnz == 9 * P.node_ptr[-1] and P.n_dofs == 21
    assert P.indptr.dtype == np.int32 and P.indices.dtype == np.int32
    # entry (3A+i, 3B+j) at 9 node_ptr[A] + 3 i deg(A) + 3 k + j
    for A in range(7):
        for k, B in enumerate(P.node_adj[P.node_ptr[A]:P.node_ptr[A + 1]]):
            for i in range(3):
                for j in range(3):
                    off = 9 * P.node_ptr[A] + 3 * i * deg[A] + 3 * k + j
                    assert P.indptr[3 * A + i] <= off < P.indptr[3 * A + i + 1]
                    assert P.indices[off] == 3 * B + j
    d = P.diag_offsets()
    assert np.array_equal(P.indices[d], np.arange(P.n_dofs))
    for row in range(P.n_dofs):
        assert P.indptr[row] <= d[row] < P.indptr[row + 1]
        cols = P.indices[P.indptr[row]:P.indptr[row + 1]]
        assert np.all(np.diff(cols) > 0)
    data = P.zeros()
    A = P.csr(data)
    assert np.shares_memory(A.data, data) and np.shares_memory(A.indices, P.indices)
    data[d] = 1.0
    assert np.array_equal(A.toarray(), np.eye(21))


def test_isolated_nodes_get_a_diagonal():
    P = Pattern(5, [np.array([[1, 2]])])
    assert np.array_equal(P.node_deg, [1, 2, 2, 1, 1])


@pytest.mark.parametrize("symmetric", [False, True])
def test_scatter_equals_coo_assembly(symmetric):
    rng = np.random.default_rng(1)
    n1, n2 = 30, 40
    c1 = random_block(rng, n1, 25, 8)
    c2 = random_block(rng, n2, 12, 27)
    pairs = np.array([[3, n1 + 5], [n1 + 7, 0]])
    P = Pattern(n1 + n2, [c1, c2 + n1], extra_pairs=pairs)
    K1 = rng.standard_normal((c1.shape[0], 24, 24))
    K2 = rng.standard_normal((c2.shape[0], 81, 81))
    Kp = rng.standard_normal((pairs.shape[0], 6, 6))
    if symmetric:
        K1 = K1 + K1.transpose(0, 2, 1)
        K2 = K2 + K2.transpose(0, 2, 1)
        Kp = Kp + Kp.transpose(0, 2, 1)
    data = P.zeros()
    P.scatter(data, c1, K1)
    P.scatter(data, c2, K2, node_offset=n1)
    P.scatter(data, pairs, Kp)
    ref = (coo_matrix(P.n_dofs, c1, K1) + coo_matrix(P.n_dofs, c2, K2, n1)
           + coo_matrix(P.n_dofs, pairs, Kp))
    A = P.csr(data)
    assert abs(A - ref).max() <= 1e-12 * abs(ref).max()
    # the pattern holds no entry the elements do not couple (apart from diagonals)
    assert ref.nnz <= A.nnz
    if symmetric:
        assert abs(A - A.T).max() <= 1e-12 * abs(A).max()
    # precomputed ranks give the same result
    data2 = P.zeros()
    P.scatter(data2, c1, K1, ranks=P.ranks(c1))
    P.scatter(data2, c2, K2, ranks=P.ranks(c2, node_offset=n1), node_offset=n1)
    P.scatter(data2, pairs, Kp)
    assert np.array_equal(data, data2)


def test_pattern_is_the_union_of_element_couplings():
    rng = np.random.default_rng(2)
    conn = random_block(rng, 50, 40, 8)
    P = Pattern(50, [conn])
    coupled = np.zeros((50, 50), dtype=bool)
    for e in conn:
        coupled[np.ix_(e, e)] = True
    coupled[np.arange(50), np.arange(50)] = True
    nodes = np.zeros((50, 50), dtype=bool)
    for A in range(50):
        nodes[A, P.node_adj[P.node_ptr[A]:P.node_ptr[A + 1]]] = True
    assert np.array_equal(coupled, nodes)


def test_ranks_reject_pairs_outside_the_pattern():
    P = Pattern(6, [np.array([[0, 1, 2], [3, 4, 5]])])
    r = P.ranks(np.array([[2, 0, 1]]))
    assert r.dtype == np.int32 and r.shape == (1, 3, 3)
    assert np.array_equal(r[0, 0], [2, 0, 1])
    with pytest.raises(ValueError, match="not in the pattern"):
        P.ranks(np.array([[0, 3]]))
    with pytest.raises(ValueError, match="outside"):
        Pattern(3, [np.array([[0, 3]])])
