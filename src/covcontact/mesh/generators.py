"""Structured hexahedral meshes with named node sets and face sets.

Every generator maps one or more structured lattices of parameters u in [0, 1]^3 through an exact
geometric map, so the mid-nodes of hex18 and hex27 lie on the curved geometry. For hex18 the third
lattice direction (the thickness of plates and shells) is the linear one. Blocks are joined by
merging coincident nodes; every element is then turned right-handed (positive Jacobian), and a
face set is made for every node set whose nodes carry boundary faces (for hex18 only the t = -1
and t = +1 faces are faces, so its side sets are node sets only).

Spherical patches with ``theta0 = 0`` are caps meshed without a collapsed pole: an O-grid (a
central square and four mapped blocks, or three for an azimuth sector) drawn on the unit disk and
mapped to the sphere by theta = theta1 * rho.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from scipy.sparse import coo_matrix

from ..fem.shapes import IDX, ORDER
from .faces import boundary_faces, jacobian_determinants
from .mesh import Mesh

CELLS = ("hex8", "hex18", "hex27")
_OFF = {1: np.array([0, 1]), 2: np.array([0, 2, 1])}
_TWO_PI = 2.0 * math.pi
_Block = tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]  # points, cells, set masks


def _check_cell(cell: str) -> None:
    if cell not in CELLS:
        raise ValueError(f"unknown cell type {cell!r}; use one of {', '.join(CELLS)}")


def _count(name: str, value: int) -> int:
    if int(value) != value or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _positive(name: str, value: float) -> float:
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be positive and finite, got {value!r}")
    return float(value)


def _lin(n: int) -> np.ndarray:
    return np.linspace(0.0, 1.0, n + 1)


def _refine(b: np.ndarray, order: int) -> np.ndarray:
    if order == 1:
        return b
    u = np.empty(2 * b.size - 1)
    u[0::2] = b
    u[1::2] = 0.5 * (b[:-1] + b[1:])
    return u


def _lattice(cell: str, bounds: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Lattice parameters U (m, 3) and connectivity for element boundaries ``bounds[d]``.

    Direction 0 runs fastest for nodes and elements; quadratic directions get mid-nodes at the
    parameter midpoints.
    """
    order, idx = ORDER[cell], IDX[cell]
    u = [_refine(np.asarray(b, dtype=np.float64), int(o)) for b, o in zip(bounds, order, strict=True)]
    m = [x.size for x in u]
    g = np.meshgrid(u[2], u[1], u[0], indexing="ij")
    U = np.stack([g[2].ravel(), g[1].ravel(), g[0].ravel()], axis=1)
    n = [len(b) - 1 for b in bounds]
    e = np.meshgrid(np.arange(n[2]), np.arange(n[1]), np.arange(n[0]), indexing="ij")
    E = np.stack([e[2].ravel(), e[1].ravel(), e[0].ravel()], axis=1)
    off = np.stack([_OFF[int(order[d])][idx[:, d]] for d in range(3)], axis=1)
    L = E[:, None, :] * order[None, None, :] + off[None]
    return U, L[..., 0] + m[0] * (L[..., 1] + m[1] * L[..., 2])


def _mirror_perm(cell: str) -> np.ndarray:
    """Node permutation mirroring a cell in its first natural direction."""
    idx = IDX[cell]
    target = idx.copy()
    target[:, 0] = np.array([1, 0, 2])[idx[:, 0]]
    return np.array([np.nonzero((idx == t).all(axis=1))[0][0] for t in target], dtype=np.int64)


def _assemble(blocks: list[_Block], cell: str, no_faces: Sequence[str] = ("all",), merge: bool = True) -> Mesh:
    """Join blocks, merge coincident nodes (``merge``: a lattice has none), orient elements, build node and
    face sets."""
    X = np.concatenate([b[0] for b in blocks])
    offsets = np.cumsum([0] + [b[0].shape[0] for b in blocks])
    cells = np.concatenate([b[1] + o for b, o in zip(blocks, offsets[:-1], strict=True)])
    names = list(dict.fromkeys(k for b in blocks for k in b[2]))
    masks = {
        k: np.concatenate([b[2].get(k, np.zeros(b[0].shape[0], dtype=bool)) for b in blocks])
        for k in names
    }
    n = X.shape[0]
    if merge:
        from scipy.sparse.csgraph import connected_components  # imported where used: start-up time
        from scipy.spatial import cKDTree

        tol = 1e-9 * float(np.ptp(X, axis=0).max())
        pairs = cKDTree(X).query_pairs(tol, output_type="ndarray")
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        _, first, inv = np.unique(label, return_index=True, return_inverse=True)
        order = np.argsort(first)
        rank = np.empty_like(order)
        rank[order] = np.arange(order.size)
        new = rank[inv.ravel()]
        kept = first[order]
    else:
        new = kept = np.arange(n)
    cells = new[cells]
    srt = np.sort(cells, axis=1)
    if np.any(srt[:, 1:] == srt[:, :-1]):
        raise ValueError("mesh generation produced collapsed elements (repeated nodes)")
    mesh = Mesh(X[kept], cell, cells)
    flip = jacobian_determinants(mesh, np.zeros((1, 3)))[:, 0] < 0.0
    mesh.cells[flip] = mesh.cells[flip][:, _mirror_perm(cell)]
    faces, _, _ = boundary_faces(mesh)
    for k in names:
        if not masks[k].any():
            continue
        mesh.add_node_set(k, new[masks[k]])
        if k in no_faces:
            continue
        on = np.zeros(mesh.n_nodes, dtype=bool)
        on[mesh.node_sets[k]] = True
        f = faces[np.all(on[faces], axis=1)]
        if f.shape[0]:
            mesh.add_face_set(k, f)
    return mesh


def _alias(mesh: Mesh, new: str, old: str) -> None:
    if old in mesh.node_sets:
        mesh.node_sets[new] = mesh.node_sets[old]
    if old in mesh.face_sets:
        mesh.face_sets[new] = mesh.face_sets[old]


def block(
    lx: float, ly: float, lz: float, nx: int, ny: int, nz: int, cell: str = "hex8",
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Box [0, lx] x [0, ly] x [0, lz] + origin with nx x ny x nz elements.

    Sets: node and face sets "xmin", "xmax", "ymin", "ymax", "zmin", "zmax"; node set "all".
    """
    _check_cell(cell)
    size = np.array([_positive(k, v) for k, v in (("lx", lx), ("ly", ly), ("lz", lz))])
    n = [_count(k, v) for k, v in (("nx", nx), ("ny", ny), ("nz", nz))]
    U, cells = _lattice(cell, [_lin(k) for k in n])
    sets = {"all": np.ones(U.shape[0], dtype=bool)}
    for d, ax in enumerate("xyz"):
        sets[ax + "min"] = U[:, d] == 0.0
        sets[ax + "max"] = U[:, d] == 1.0
    return _assemble([(np.asarray(origin, dtype=np.float64) + U * size, cells, sets)], cell, merge=False)


def plate(
    lx: float, ly: float, t: float, nx: int, ny: int, cell: str = "hex8",
    origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Plate [0, lx] x [0, ly] x [0, t] + origin, one element through the thickness (z).

    Sets: those of ``block`` plus the aliases "bottom" (= "zmin") and "top" (= "zmax").
    """
    mesh = block(lx, ly, t, nx, ny, 1, cell, origin)
    _alias(mesh, "bottom", "zmin")
    _alias(mesh, "top", "zmax")
    return mesh


_AXIS_PERM = {"z": [0, 1, 2], "x": [2, 0, 1], "y": [1, 2, 0]}


def _shell_radii(radius: float, t: float) -> tuple[float, float]:
    R, t = _positive("radius", radius), _positive("t", t)
    if t >= 2.0 * R:
        raise ValueError(f"thickness t = {t} must be below the diameter 2 R = {2 * R}")
    return R, t


def _span(a0: float, a1: float, what: str) -> tuple[float, bool]:
    span = float(a1) - float(a0)
    if not (0.0 < span <= _TWO_PI * (1.0 + 1e-12)):
        raise ValueError(f"{what}1 - {what}0 must lie in (0, 2 pi], got {span!r}")
    return span, abs(span - _TWO_PI) < 1e-9


def cylinder_patch(
    radius: float, length: float, angle0: float, angle1: float, t: float, n_circ: int,
    n_len: int, cell: str = "hex8", axis: str = "z", center: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Cylindrical shell patch of mid-surface radius R, one element through the thickness t.

    The axis ("x", "y" or "z") passes through ``center``; the patch spans axial coordinates
    [0, length] from ``center`` and angles [angle0, angle1] in radians, measured from +x towards
    +y about "z", from +y towards +z about "x", from +z towards +x about "y". A full turn is
    closed (seam nodes merged).

    Sets: node and face sets "inner", "outer" (radius R -+ t/2), "end0", "end1" (axial ends),
    "angle0", "angle1" (dropped for a full turn); node set "all".
    """
    _check_cell(cell)
    R, t = _shell_radii(radius, t)
    length = _positive("length", length)
    if axis not in _AXIS_PERM:
        raise ValueError(f"axis must be 'x', 'y' or 'z', got {axis!r}")
    span, full = _span(angle0, angle1, "angle")
    U, cells = _lattice(cell, [_lin(_count("n_circ", n_circ)), _lin(_count("n_len", n_len)), _lin(1)])
    phi = angle0 + span * U[:, 0]
    r = R - 0.5 * t + t * U[:, 2]
    local = np.stack([r * np.cos(phi), r * np.sin(phi), length * U[:, 1]], axis=1)
    X = np.asarray(center, dtype=np.float64) + local[:, _AXIS_PERM[axis]]
    sets = {
        "inner": U[:, 2] == 0.0, "outer": U[:, 2] == 1.0,
        "end0": U[:, 1] == 0.0, "end1": U[:, 1] == 1.0,
        "all": np.ones(U.shape[0], dtype=bool),
    }
    if not full:
        sets["angle0"], sets["angle1"] = U[:, 0] == 0.0, U[:, 0] == 1.0
    return _assemble([(X, cells, sets)], cell)


def _on_sphere(center: np.ndarray, r: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    st = np.sin(theta)
    xyz = np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=1)
    return np.asarray(center + r[:, None] * xyz)


def sphere_patch(
    radius: float, theta0: float, theta1: float, phi0: float, phi1: float, t: float,
    n_theta: int, n_phi: int, cell: str = "hex8", center: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Spherical shell patch of mid-surface radius R, one element through the thickness t.

    theta is the polar angle from +z, phi the azimuth from +x; 0 <= theta0 < theta1 < pi. For
    theta0 > 0 the lattice is n_theta x n_phi elements. For theta0 = 0 the patch is a cap meshed
    by an O-grid (no collapsed pole): n_phi elements along the rim (a multiple of 4 for a full
    turn, of 2 for a sector), a central square of n_phi/4 (n_phi/2 for a sector) elements a side,
    and n_theta elements across the ring between the square and the rim.

    Sets: node and face sets "inner", "outer" (radius R -+ t/2), "theta0", "theta1", "phi0",
    "phi1" (phi sets dropped for a full turn); node set "all". For a cap "theta0" (alias "pole")
    is a node set of the nodes on the pole line, present when a node sits there (always for
    hex18/hex27 and for sectors; for a full hex8 cap when n_phi / 4 is even).
    """
    _check_cell(cell)
    R, t = _shell_radii(radius, t)
    if not (0.0 <= theta0 < theta1 < math.pi):
        raise ValueError(f"need 0 <= theta0 < theta1 < pi, got theta0={theta0!r}, theta1={theta1!r}")
    span, full = _span(phi0, phi1, "phi")
    n_theta, n_phi = _count("n_theta", n_theta), _count("n_phi", n_phi)
    c0 = np.asarray(center, dtype=np.float64)
    if theta0 == 0.0:
        return _sphere_cap(R, theta1, phi0, span, full, t, n_theta, n_phi, cell, c0)
    U, cells = _lattice(cell, [_lin(n_theta), _lin(n_phi), _lin(1)])
    theta = theta0 + (theta1 - theta0) * U[:, 0]
    X = _on_sphere(c0, R - 0.5 * t + t * U[:, 2], theta, phi0 + span * U[:, 1])
    sets = {
        "inner": U[:, 2] == 0.0, "outer": U[:, 2] == 1.0,
        "theta0": U[:, 0] == 0.0, "theta1": U[:, 0] == 1.0,
        "all": np.ones(U.shape[0], dtype=bool),
    }
    if not full:
        sets["phi0"], sets["phi1"] = U[:, 1] == 0.0, U[:, 1] == 1.0
    return _assemble([(X, cells, sets)], cell)


_Map2 = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
_Side = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]


def _ring_block(rot: float, a0: float, a1: float, side: _Side) -> _Map2:
    """Disk block between a straight side of the central square and the rim arc [a0, a1]."""

    def f(u0: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sx, sy = side(u0)
        ang = rot + a0 + (a1 - a0) * u0
        return (1 - s) * sx + s * np.cos(ang), (1 - s) * sy + s * np.sin(ang)

    return f


def _sphere_cap(
    R: float, theta1: float, phi0: float, span: float, full: bool, t: float, n_theta: int,
    n_phi: int, cell: str, center: np.ndarray,
) -> Mesh:
    q = math.pi / 4
    if full:
        if n_phi % 4:
            raise ValueError(f"a full cap needs n_phi divisible by 4, got {n_phi}")
        m, c, k = n_phi // 4, 0.4, 1.0
        maps: list[tuple[_Map2, int, int, str]] = [
            (lambda u, v: (c * (2 * u - 1), c * (2 * v - 1)), m, m, "centre")
        ]
        for j in range(4):
            cr, sr = math.cos(j * 2 * q), math.sin(j * 2 * q)

            def side(u: np.ndarray, cr: float = cr, sr: float = sr) -> tuple[np.ndarray, np.ndarray]:
                x, y = c * np.ones_like(u), c * (2 * u - 1)
                return cr * x - sr * y, sr * x + cr * y

            maps.append((_ring_block(j * 2 * q, -q, q, side), m, n_theta, "ring"))
    else:
        if n_phi % 2:
            raise ValueError(f"a cap sector needs an even n_phi, got {n_phi}")
        m, c, k = n_phi // 2, 0.45, span / (2 * q)
        maps = [
            (lambda u, v: (c * u, c * v), m, m, "square"),
            (_ring_block(0.0, 0.0, q, lambda u: (c * np.ones_like(u), c * u)), m, n_theta, "A"),
            (_ring_block(0.0, 2 * q, q, lambda u: (c * u, c * np.ones_like(u))), m, n_theta, "B"),
        ]
    blocks: list[_Block] = []
    for f, na, nb, kind in maps:
        U, cells = _lattice(cell, [_lin(na), _lin(nb), _lin(1)])
        x, y = f(U[:, 0], U[:, 1])
        rho = np.hypot(x, y)
        psi = np.arctan2(y, x)
        X = _on_sphere(center, R - 0.5 * t + t * U[:, 2], theta1 * rho, phi0 + k * psi)
        sets = {
            "inner": U[:, 2] == 0.0, "outer": U[:, 2] == 1.0,
            "theta1": (U[:, 1] == 1.0) & (kind not in ("centre", "square")),
            "theta0": rho < 1e-12, "pole": rho < 1e-12,
            "all": np.ones(U.shape[0], dtype=bool),
        }
        if kind == "square":
            sets["phi0"], sets["phi1"] = U[:, 1] == 0.0, U[:, 0] == 0.0
        elif kind == "A":
            sets["phi0"] = U[:, 0] == 0.0
        elif kind == "B":
            sets["phi1"] = U[:, 0] == 0.0
        blocks.append((X, cells, sets))
    return _assemble(blocks, cell, no_faces=("all", "theta0", "pole"))


def hemisphere_solid(
    radius: float, n: int = 4, nr: int | None = None, cell: str = "hex8", core: float = 0.45,
    focus: float = 1.0, origin: Sequence[float] = (0.0, 0.0, 0.0),
) -> Mesh:
    """Solid half-ball of radius R: flat face up at z = R, pole (lowest point) at ``origin``.

    A cube-sphere mesh: an inner half-box [-a, a]^2 x [-a, 0] (a = core * R, relative to the
    ball centre origin + (0, 0, R)) with n x n x n/2 elements, plus five blocks (bottom and four
    sides) of nr layers between the box and the sphere, equiangular on the sphere. ``focus`` in
    (0, 1] shrinks the elements at the pole by that factor (a cubic grading of the box and the
    face coordinates) for Hertz-type contact. hex18 is rejected (its 3 x 2 side faces cannot
    join the blocks conformingly).

    Sets: node and face sets "flat" (z = R), "curved" (the sphere); node sets "pole" (the lowest
    node) and "all".
    """
    _check_cell(cell)
    if cell == "hex18":
        raise ValueError("hemisphere_solid needs hex8 or hex27: hex18 is a solid-shell cell")
    R = _positive("radius", radius)
    n = _count("n", n)
    if n % 2:
        raise ValueError(f"n must be even (a node at the pole), got {n}")
    nr = max(1, n // 2) if nr is None else _count("nr", nr)
    if not (0.0 < core < 1.0 / math.sqrt(3.0)):
        raise ValueError(f"core must lie in (0, 1/sqrt(3)), got {core!r}")
    if not (0.0 < focus <= 1.0):
        raise ValueError(f"focus must lie in (0, 1], got {focus!r}")
    a = core * R
    half = np.linspace(0.0, 1.0, n // 2 + 1)
    bx = np.concatenate([-half[::-1], half[1:]])
    bz = np.linspace(-1.0, 0.0, n // 2 + 1)
    bs = _lin(nr)

    def g(x: np.ndarray) -> np.ndarray:
        return np.asarray(x * (focus + (1.0 - focus) * x * x))

    def w(x: np.ndarray) -> np.ndarray:
        return np.tan(0.25 * math.pi * x)

    c = np.asarray(origin, dtype=np.float64) + np.array([0.0, 0.0, R])
    U, cells = _lattice(cell, [bx, bx, bz])
    blocks: list[_Block] = [
        (c + a * np.stack([g(U[:, 0]), g(U[:, 1]), U[:, 2]], 1), cells, {"flat": U[:, 2] == 0.0})
    ]
    # (fixed axis, sign): the bottom (z = -a) and the four sides
    for axis, sign in ((2, -1.0), (0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)):
        bottom = axis == 2
        U, cells = _lattice(cell, [bx, bx if bottom else bz, bs])
        p = np.empty((U.shape[0], 3))
        d = np.empty_like(p)
        free = [0, 1] if bottom else [k for k in (0, 1) if k != axis] + [2]
        p[:, axis], d[:, axis] = sign, sign
        p[:, free[0]] = g(U[:, 0])
        d[:, free[0]] = w(p[:, free[0]])
        p[:, free[1]] = g(U[:, 1]) if bottom else U[:, 1]
        d[:, free[1]] = w(p[:, free[1]])
        d /= np.linalg.norm(d, axis=1)[:, None]
        s = U[:, 2:3]
        X = c + (1.0 - s) * a * p + s * R * d
        sets = {"curved": U[:, 2] == 1.0, "flat": np.zeros(U.shape[0], bool) if bottom else U[:, 1] == 0.0}
        blocks.append((X, cells, sets))
    mesh = _assemble(blocks, cell)
    curved = mesh.node_sets["curved"]
    pole = curved[np.argmin(np.linalg.norm(mesh.points[curved] - c + [0.0, 0.0, R], axis=1))]
    mesh.add_node_set("pole", np.array([pole]))
    mesh.add_node_set("all", np.arange(mesh.n_nodes))
    return mesh
