"""tet4, tet10, wedge6 and hex20 against hex27 on Cook's membrane geometry (compressible, plane strain).

The tapered panel of test_cook.py (corners (0, 0), (48, 44), (48, 60), (0, 44)), clamped on the left edge, its
right edge moved up by 1 (every node of it), plane strain, linear step (K(0) u = f with Neo-Hooke's Lame
constants, E = 250, nu = 0.3). The measure is the vertical reaction on the right edge, the panel's shear
stiffness. No closed form: the reference is hex27 on 32 elements per side; the meshes are the generator's
bricks split (tetrahedra, wedges) or trimmed (hex20), so they converge to the same continuum limit. Numbers:
docs/verification.md, "Tetrahedra, wedges and 20-node bricks".
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from covcontact.assembly import Pattern
from covcontact.elements.fbar import FbarBody
from covcontact.elements.solid import SolidBody
from covcontact.materials import NeoHooke
from covcontact.mesh.convert import SOURCE, convert
from covcontact.mesh.generators import block

MAT = NeoHooke(E=250.0, nu=0.3)


def stiffness(n: int, cell: str, material=MAT, fbar: bool = False) -> float:
    m = block(48.0, 44.0, 1.0, n, n, 1, SOURCE.get(cell, cell))
    if cell in SOURCE:
        m = convert(m, cell)
    X = m.points.copy()
    X[:, 1] += X[:, 0] / 48.0 * (44.0 - 28.0 * X[:, 1] / 44.0)
    body = (FbarBody if fbar else SolidBody)(cell, X, m.cells, material)
    assert body.check_reference() == []
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(np.zeros_like(X), data, r, P) == -1
    K = P.csr(data)
    u = np.zeros((body.n_nodes, 3))
    fixed = np.zeros((body.n_nodes, 3), dtype=bool)
    left = np.abs(X[:, 0]) < 1e-9
    right = np.abs(X[:, 0] - 48.0) < 1e-9
    fixed[left] = True
    fixed[right, 1] = True
    fixed[:, 2] = True
    u[right, 1] = 1.0
    free = np.flatnonzero(~fixed.ravel())
    known = np.flatnonzero(fixed.ravel())
    U = u.ravel()
    U[free] = sla.spsolve(K[free][:, free].tocsc(), -K[free][:, known] @ U[known])
    f = (K @ U).reshape(-1, 3)
    return float(f[right, 1].sum())


@pytest.fixture(scope="module")
def reference() -> float:
    return stiffness(32, "hex27")


@pytest.mark.parametrize("cell, n_ok, tol", [("tet10", 16, 0.005), ("hex20", 16, 0.005), ("tet4", 32, 0.04),
                                             ("wedge6", 32, 0.01)])
def test_converges_to_hex27(reference, cell, n_ok, tol):
    """The reaction approaches the hex27 reference monotonically from above (stiffer coarse meshes), the error
    falling with each refinement, and is within ``tol`` on ``n_ok`` elements per side. Measured, relative to
    hex27 on 32 per side, on 4, 8, 16, 32 per side: tet10 +3.6 %, +0.87 %, +0.24 %, +0.055 %; hex20 +1.9 %, +0.56 %,
    +0.17 %, +0.035 %; wedge6 +30 %, +8.7 %, +2.5 %, +0.71 %; tet4 +114 %, +40 %, +12 %, +3.4 % (hex27 itself +1.1 %,
    +0.33 %, +0.086 %; hex8 +32 %, +9.3 %, +2.6 %, +0.73 %)."""
    errs = []
    for n in (4, 8, 16, 32):
        if n > n_ok:
            break
        errs.append(stiffness(n, cell) / reference - 1.0)
    assert all(e > -1e-4 for e in errs), errs
    assert all(b < a for a, b in pairwise(errs)), errs
    assert errs[-1] < tol, errs


@pytest.mark.parametrize("cell", ["tet10", "hex20"])
def test_fbar_relieves_volumetric_locking(cell):
    """Nearly incompressible (nu = 0.4999): plain tet10 and hex20 lock mildly (too stiff), F-bar does not (tet10:
    the element's mean volume change, hex20: J projected onto the linear functions). Reference: F-bar hex27 on 8 per
    side (0.20 % above 16 per side). Measured relative to F-bar hex27 on 16 per side, on 4, 8, 16 per side: tet10
    plain +27 %, +7.8 %, +2.5 %, F-bar +11 %, +2.5 %, +0.64 %; hex20 plain +18 %, +5.4 %, +1.9 %, F-bar +5.0 %,
    +1.6 %, +0.56 %."""
    mat = NeoHooke(E=250.0, nu=0.4999)
    ref = stiffness(8, "hex27", mat, fbar=True)
    for n in (4, 8):
        plain = stiffness(n, cell, mat) / ref - 1.0
        fbar = stiffness(n, cell, mat, fbar=True) / ref - 1.0
        assert 0.0 < fbar < 0.45 * plain, (n, fbar, plain)
    assert fbar < 0.03
