"""The near-null space handed to PETSc's GAMG (solvers/linear.py rigid_body_basis): an orthonormal basis
of the six rigid-body modes whose bits do not depend on where the coordinates lie in memory (PETSc's own
construction sums with BLAS, whose rounding does: its modes differed in the last bit from run to run)."""

import numpy as np

from covcontact.solvers.linear import rigid_body_basis


def _modes(X):
    B = np.zeros((3 * X.shape[0], 6))
    for d in range(3):
        B[d::3, d] = 1.0
    x, y, z = X.T
    B[0::3, 3], B[1::3, 3] = -y, x
    B[1::3, 4], B[2::3, 4] = -z, y
    B[0::3, 5], B[2::3, 5] = z, -x
    return B


def test_orthonormal_basis_of_the_rigid_body_modes():
    X = np.random.default_rng(3).uniform(-1.0, 4.0, size=(500, 3))
    Q = rigid_body_basis(X)
    assert Q.shape == (1500, 6)
    np.testing.assert_allclose(Q.T @ Q, np.eye(6), atol=1e-13)
    B = _modes(X)  # the modes about the origin: the same span
    assert np.linalg.norm(B - Q @ (Q.T @ B)) <= 1e-12 * np.linalg.norm(B)


def test_same_bits_wherever_the_coordinates_lie():
    X = np.random.default_rng(4).uniform(0.0, 1.0, size=(3001, 3))
    ref = rigid_body_basis(X)
    for offset in range(1, 8):  # copies at other alignments (offsets of 8 to 56 bytes)
        buf = np.empty(X.size + offset)
        moved = buf[offset:].reshape(X.shape)
        moved[...] = X
        np.testing.assert_array_equal(rigid_body_basis(moved), ref)
    F = np.asfortranarray(X)  # another layout too
    np.testing.assert_array_equal(rigid_body_basis(F), ref)
