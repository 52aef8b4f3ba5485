"""Master surface topology and the global contact search (exact box candidates)."""

import numpy as np
import pytest

from covcontact.contact.search import candidates, candidates_brute
from covcontact.contact.surface import MeshSurface, facet_boxes, tributary_area
from covcontact.fem.shapes import shape_functions


def wavy_grid(nx, ny, nen=4, amp=0.2, L=1.0):
    """Structured quad4/quad9 grid on z = amp sin(2 pi x) cos(2 pi y), outward normal +z."""
    p = 1 if nen == 4 else 2
    mx, my = p * nx + 1, p * ny + 1
    X, Y = np.meshgrid(np.linspace(0, L, mx), np.linspace(0, L, my), indexing="ij")
    Z = amp * np.sin(2 * np.pi * X / L) * np.cos(2 * np.pi * Y / L)
    x = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
    faces = []
    for i in range(nx):
        for j in range(ny):
            a, b = p * i, p * j
            c = [a * my + b, (a + p) * my + b, (a + p) * my + b + p, a * my + b + p]
            if nen == 9:
                c += [(a + 1) * my + b, (a + 2) * my + b + 1, (a + 1) * my + b + 2, a * my + b + 1]
                c += [(a + 1) * my + b + 1]
            faces.append(c)
    return x, np.array(faces, dtype=np.int64)


def test_adjacency_structured_grid():
    _, faces = wavy_grid(3, 2)
    s = MeshSurface(faces)
    # facet (i, j) has index 2 i + j; edge 1 (corners 1-2) of facet (0, 0) meets edge 3 of facet (1, 0)
    assert s.nbr_facet[0, 1] == 2 and s.nbr_edge[0, 1] == 3
    assert s.nbr_facet[0, 2] == 1 and s.nbr_edge[0, 2] == 0
    assert s.nbr_facet[0, 0] == -1 and s.nbr_facet[0, 3] == -1
    # symmetric pairing, and shared corners agree
    f, e = np.nonzero(s.nbr_facet >= 0)
    nb, ne = s.nbr_facet[f, e], s.nbr_edge[f, e]
    assert np.all(s.nbr_facet[nb, ne] == f) and np.all(s.nbr_edge[nb, ne] == e)
    assert np.all(faces[f, e] == faces[nb, (ne + 1) % 4])
    # 3 x 2 grid: 7 interior edges; 4 x 3 nodes of which the 2 inner ones are off the boundary
    assert len(f) == 2 * 7
    assert s.node_on_boundary.sum() == 10
    # node-to-facet incidence: the centre-row nodes belong to up to four facets
    counts = np.diff(s.node_ptr)
    assert counts.sum() == faces.size and counts.max() == 4
    assert set(s.facets_of_node(faces[0, 2])) == {0, 1, 2, 3}


def test_quad9_adjacency_and_interior_nodes():
    _, faces = wavy_grid(3, 3, nen=9)
    s = MeshSurface(faces)
    assert np.count_nonzero(s.nbr_facet >= 0) == 2 * 12
    # the centre node of the middle facet and its mid-edge nodes are interior
    assert not s.node_on_boundary[faces[4]].any()
    assert s.n_nonmanifold == 0


def test_vertex_normals_flat():
    x, faces = wavy_grid(2, 2, amp=0.0)
    n = MeshSurface(faces).vertex_normals(x)
    assert np.allclose(n, [0, 0, 1])


@pytest.mark.parametrize("nen", [4, 9])
def test_tributary_area_sums_to_area(nen):
    # flat: exact; the unit square area is 1 and corner nodes of the square get the smallest share
    x, faces = wavy_grid(4, 3, nen=nen, amp=0.0)
    a = tributary_area(x, faces)
    assert a.sum() == pytest.approx(1.0, rel=1e-13)
    assert np.all(a > 0)
    # cylinder quad9 patch, radius 2, 60 degrees, length 1.5: area R theta L
    R, th, L, n = 2.0, np.pi / 3, 1.5, 6
    phi = np.linspace(-th / 2, th / 2, 2 * n + 1)
    y = np.linspace(0, L, 5)
    P, Y = np.meshgrid(phi, y, indexing="ij")
    xc = np.c_[R * np.sin(P).ravel(), Y.ravel(), R * np.cos(P).ravel()]
    my = 5
    fc = []
    for i in range(n):
        for j in range(2):
            a0, b0 = 2 * i, 2 * j
            fc.append(
                [
                    a0 * my + b0,
                    (a0 + 2) * my + b0,
                    (a0 + 2) * my + b0 + 2,
                    a0 * my + b0 + 2,
                    (a0 + 1) * my + b0,
                    (a0 + 2) * my + b0 + 1,
                    (a0 + 1) * my + b0 + 2,
                    a0 * my + b0 + 1,
                    (a0 + 1) * my + b0 + 1,
                ]
            )
    ac = tributary_area(xc, np.array(fc))
    assert ac.sum() == pytest.approx(R * th * L, rel=1e-5)  # quad9 arc interpolation error ~1e-6


@pytest.mark.parametrize("nen", [4, 9])
def test_boxes_contain_facets(nen):
    # boxes bound the facet surface itself (quad9 bulges beyond its nodes)
    x, faces = wavy_grid(3, 3, nen=nen, amp=0.3)
    rng = np.random.default_rng(1)
    x = x + rng.normal(scale=0.05, size=x.shape)
    lo, hi = facet_boxes(x, faces)
    pts = rng.uniform(-1, 1, (400, 2))
    N, _, _ = shape_functions("quad4" if nen == 4 else "quad9", pts)
    r = np.einsum("pa,fai->fpi", N, x[faces])
    assert np.all(r >= lo[:, None, :] - 1e-14) and np.all(r <= hi[:, None, :] + 1e-14)
    if nen == 9:  # the node box alone would not be enough for this perturbed facet set
        node_hi = x[faces].max(axis=1)
        assert np.any(r > node_hi[:, None, :])


@pytest.mark.parametrize("nen", [4, 9])
@pytest.mark.parametrize("method", ["grid", "kdtree"])
def test_candidates_match_brute_force(nen, method):
    rng = np.random.default_rng(42 + nen)
    x, faces = wavy_grid(10, 7, nen=nen, amp=0.15)
    s = MeshSurface(faces)
    xs = rng.uniform([-0.2, -0.2, -0.4], [1.2, 1.2, 0.4], (1500, 3))
    for margin in (0.0, 0.02, 0.3):
        ptr, fac = candidates(x, s, xs, margin, method=method)
        ref = candidates_brute(x, s, xs, margin)
        lo, hi = facet_boxes(x, faces)
        total_ref = 0
        for i, r in enumerate(ref):
            got = fac[ptr[i] : ptr[i + 1]]
            # exact set (no superset: the box test is applied after the grid / tree lookup)
            assert sorted(got) == sorted(r)
            total_ref += len(r)
            # nearest box first
            d = np.linalg.norm(np.maximum(0, np.maximum(lo[got] - xs[i], xs[i] - hi[got])), axis=1)
            assert np.all(np.diff(d) >= 0)
        assert ptr[-1] == total_ref and total_ref > 0


def test_candidates_edge_cases():
    x, faces = wavy_grid(3, 3)
    s = MeshSurface(faces)
    xs = np.array([[0.5, 0.5, 100.0], [np.nan, 0.5, 0.0], [0.5, 0.5, 0.0]])
    ptr, _ = candidates(x, s, xs, 0.1)
    assert ptr[1] == 0 and ptr[2] == ptr[1] and ptr[3] > ptr[2]
    with pytest.raises(ValueError):
        candidates(x, s, xs, -1.0)


@pytest.mark.parametrize("case", ["hashed", "crowded"])
def test_candidates_exact_on_hashed_and_crowded_grids(case):
    # hashed: two patches far apart, far more cells than entries, so the cell table is a sorted hashed list;
    # crowded: one cell holding all 144 facets, past the first pass's 64-bit mask
    rng = np.random.default_rng(7)
    x, faces = wavy_grid(12, 12, amp=0.15)
    xs = rng.uniform([-0.1, -0.1, -0.3], [1.1, 1.1, 0.3], (800, 3))
    if case == "hashed":
        x, faces = np.vstack([x, x + 1e3]), np.vstack([faces, faces + len(x)])
        xs = np.vstack([xs, xs + 1e3])
    s = MeshSurface(faces)
    ptr, fac = candidates(x, s, xs, 0.05, cell_factor=40.0 if case == "crowded" else 1.0)
    ref = candidates_brute(x, s, xs, 0.05)
    assert ptr[-1] == sum(len(r) for r in ref) > 0
    for i, r in enumerate(ref):
        assert sorted(fac[ptr[i] : ptr[i + 1]]) == sorted(r)
