"""Mass matrices against exact integrals, HRZ lumping and the mass redistributed away from contact nodes
(docs/theory.md, section 20)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.elements.mass import MASS_RULE, element_masses, lump, redistribute
from covcontact.mesh.convert import SOURCE, convert
from covcontact.mesh.generators import block


def test_hex8_and_tet4_consistent_mass_closed_forms():
    """hex8 on a box a x b x c: M_ab = rho V / 216 * 2^(coordinates the two nodes share) (the product of the 1D
    matrices h/6 [[2, 1], [1, 2]]); tet4: M_ab = rho V / 20 (1 + delta_ab)."""
    m = block(2.0, 1.0, 0.5, 1, 1, 1, "hex8")
    Me = element_masses("hex8", m.points, m.cells, 3.0)[0]
    X = m.points[m.cells[0]]
    same = (np.abs(X[:, None, :] - X[None, :, :]) < 1e-12).sum(axis=2)
    np.testing.assert_allclose(Me, 3.0 * 1.0 / 216.0 * 2.0 ** same, rtol=1e-13)
    X = np.array([[0.0, 0.0, 0.0], [1.0, 0.2, 0.0], [0.3, 1.0, 0.1], [0.2, 0.3, 1.5]])
    V = abs(np.linalg.det(X[1:] - X[0])) / 6.0
    Me = element_masses("tet4", X, np.array([[0, 1, 2, 3]]), 2.0)[0]
    np.testing.assert_allclose(Me, 2.0 * V / 20.0 * (1.0 + np.eye(4)), rtol=1e-13)


@pytest.mark.parametrize("cell", sorted(c for c in MASS_RULE if c != "hex18"))
def test_mass_of_every_cell(cell):
    """On a distorted block of each cell type: the total is rho times the volume, a rigid translation's kinetic
    energy is m v^2 / 2 for the consistent and the lumped matrix alike, the consistent matrix is symmetric positive
    definite and the HRZ diagonal positive."""
    src = block(2.0, 1.0, 1.0, 2, 2, 2, SOURCE.get(cell, cell))
    inner = np.all((src.points > 1e-9) & (src.points < [2.0 - 1e-9, 1.0 - 1e-9, 1.0 - 1e-9]), axis=1)
    src.points[inner] += 0.05 * np.random.default_rng(1).uniform(-1.0, 1.0, (int(inner.sum()), 3))
    m = convert(src, cell) if cell in SOURCE else src
    Me = element_masses(cell, m.points, m.cells, 2.5)
    assert Me.sum() == pytest.approx(2.5 * 2.0, rel=1e-12)  # the moved interior nodes keep the volume
    np.testing.assert_allclose(Me, Me.transpose(0, 2, 1), atol=1e-15)
    assert np.all(np.linalg.eigvalsh(Me) > 0.0)
    d = lump(Me)
    assert np.all(d > 0.0)
    np.testing.assert_allclose(d.sum(axis=1), Me.sum(axis=(1, 2)), rtol=1e-12)


def test_redistribution_keeps_each_element_mass():
    m = block(2.0, 1.0, 1.0, 2, 1, 1, "hex8")
    d = lump(element_masses("hex8", m.points, m.cells, 1.0))
    massless = np.zeros(m.n_nodes, dtype=bool)
    massless[m.node_sets["xmax"]] = True
    r = redistribute(m.cells, d, massless)
    np.testing.assert_allclose(r.sum(axis=1), d.sum(axis=1), rtol=1e-14)
    assert np.all(r[massless[m.cells]] == 0.0)
    np.testing.assert_array_equal(r[0], d[0])  # the element without contact nodes is untouched


def test_consistent_redistributed_mass():
    """``consistent_interior``: the elements with a massless node lumped and redistributed, the others consistent;
    the body's mass kept (rho V = 3), the massless nodes' rows empty."""
    from covcontact.elements.mass import assemble_mass

    m = block(3.0, 1.0, 1.0, 3, 1, 1, "hex8")
    Me = element_masses("hex8", m.points, m.cells, 1.0)
    massless = np.zeros(m.n_nodes, dtype=bool)
    massless[m.node_sets["xmax"]] = True
    M = assemble_mass(m.n_nodes, [(m.cells, Me)], True, massless, consistent_interior=True).toarray()
    assert M.sum() == pytest.approx(3.0, rel=1e-14)
    assert np.all(M[massless] == 0.0) and np.all(M[:, massless] == 0.0)
    touch = massless[m.cells].any(axis=1)
    inner = np.flatnonzero(~touch)
    only = assemble_mass(m.n_nodes, [(m.cells[inner], Me[inner])], False).toarray()
    edge = assemble_mass(m.n_nodes, [(m.cells[touch], Me[touch])], True, massless).toarray()
    np.testing.assert_allclose(M, only + edge, rtol=1e-14)
    assert np.count_nonzero(only - np.diag(np.diag(only))) > 0  # (the interior is not lumped)
