"""Partition of a distributed run (no MPI needed): balanced RCB parts, node owners, PETSc numbering."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.parallel.partition import DofLayout, node_owners, rcb


@pytest.mark.parametrize("nparts", [1, 2, 3, 5])
def test_rcb_balances_weights(nparts):
    rng = np.random.default_rng(1)
    pts = rng.random((600, 3)) * [4.0, 1.0, 1.0]
    w = rng.integers(1, 4, size=600).astype(float)
    part = rcb(pts, w, nparts)
    assert set(np.unique(part)) == set(range(nparts))
    load = np.bincount(part, weights=w, minlength=nparts)
    assert load.max() - load.min() <= 2 * 3.0 * np.ceil(np.log2(max(nparts, 2)))  # a few elements off
    if nparts == 2:  # the first cut is across the longest extent (x)
        assert pts[part == 0, 0].max() <= pts[part == 1, 0].min()


def test_layout_numbers_ranks_contiguously():
    cells = [np.array([[0, 1, 4, 3], [1, 2, 5, 4]])]
    parts = [np.array([1, 0])]
    owner = node_owners(6, cells, parts)
    np.testing.assert_array_equal(owner, [1, 0, 0, 1, 0, 0])  # shared nodes go to the lower rank
    X = np.arange(18, dtype=float).reshape(6, 3)
    for rank in (0, 1):
        lay = DofLayout.from_owners(owner, rank, 2, X)
        np.testing.assert_array_equal(lay.node_ranges, [0, 4, 6])
        np.testing.assert_array_equal(lay.to_petsc[lay.from_petsc], np.arange(18))
        nodes = lay.owned[::3] // 3
        assert np.all(owner[nodes] == rank)
        assert (lay.lo, lay.hi) == ((0, 12) if rank == 0 else (12, 18))
        np.testing.assert_array_equal(lay.owned_coordinates(), X[nodes])
    lay = DofLayout.from_owners(owner, 0, 2, X)
    np.testing.assert_array_equal(lay.owned[::3] // 3, [1, 2, 4, 5])  # natural order inside a rank
