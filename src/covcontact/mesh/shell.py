"""Solid-shell meshes from mid-surface meshes (docs/theory.md, section 25).

A shell as users have it is a surface mesh (Gmsh quadrilaterals or triangles, an Abaqus/CalculiX deck's S4 or S8R
elements) and a thickness. covcontact's shells are solid-shells, one element through the thickness with both faces
real surfaces; :func:`extrude_surface` makes them:

- the surface's cells are oriented consistently (each cell's normal by the right-hand rule of its corner order;
  across every edge that two cells share, they run through it in opposite directions; the first cell of each
  connected part keeps its orientation, so the surface's normal is that of its first cell); a surface that no
  orientation makes consistent (a Moebius strip) is an error naming two cells that disagree;
- every node gets a director, the unit mean of the normals x_xi x x_eta of the cells around it evaluated at the
  node (each weighted by its size there); on a smooth surface meshed finely it is the surface's normal;
- the reference surface is moved along the directors by the offset (Abaqus's OFFSET: the mid-surface lies at
  -offset t from the given surface along the normal; "middle" 0, "top" +1/2: the given surface is the shell's top,
  SPOS, "bottom" -1/2), and the bottom and top nodes are mid -+ t/2 d;
- quad4 cells become hex8 (the four bottom nodes, then the four top nodes), quad9 cells hex18 (a quad9 at the
  bottom, then one at the top); a quad8 gets its centre node (the serendipity surface's point at the cell centre,
  -1/4 of the corners plus 1/2 of the mid-side nodes) and becomes a quad9; a tri3 is split into three quad4 (its
  corners, the mid-points of its edges, shared with the neighbours, and its centroid); a tri6 likewise, into three
  quad4 of its corners, its mid-side nodes and the point of its quadratic surface at the centroid (-1/9 of the
  corners plus 4/9 of the mid-side nodes).

Sets: the surface's element sets (a split triangle's three quads in its sets); each node set of the surface holds
its nodes of both layers; node and face sets "top" and "bottom" (outward: the top's along the directors, the
bottom's against them) and "edges" (the lateral faces along the surface's free edges); a node set of the surface
whose nodes include whole free edges also becomes the face set of those lateral faces (a clamped edge, an edge load).
"""

from __future__ import annotations

from collections import deque

import numpy as np

from .mesh import Mesh

#: the solid-shell cell of each surface cell type (after quad8 -> quad9 and tri3, tri6 -> quad4)
SOLID_OF = {"quad4": "hex8", "quad9": "hex18"}
#: the surface cell types :func:`extrude_surface` takes
SURFACE_CELLS = ("quad4", "quad8", "quad9", "tri3", "tri6")
#: offsets by name (the given surface's place in the shell, Abaqus's OFFSET)
OFFSETS = {"middle": 0.0, "top": 0.5, "bottom": -0.5}

_CORNERS = {"quad4": 4, "quad9": 4}
#: a quad9 cell's nodes in reversed orientation (corners 0 3 2 1, edge mid-nodes 3-0 2-3 1-2 0-1, centre)
_REVERSE = {"quad4": np.array([0, 3, 2, 1]), "quad9": np.array([0, 3, 2, 1, 7, 6, 5, 4, 8]),
            "quad8": np.array([0, 3, 2, 1, 7, 6, 5, 4]), "tri3": np.array([0, 2, 1]),
            "tri6": np.array([0, 2, 1, 5, 4, 3])}
#: natural coordinates of a quad9's nodes (the quad4's are its first four)
_Q9_NAT = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0], [0, 0]], dtype=float)


class ShellMeshError(ValueError):
    """A surface mesh that cannot be made into solid-shells (the message names the cells)."""


def _quad8_to_quad9(points: np.ndarray, t: np.ndarray, cells: np.ndarray):
    """Each quad8 with its centre node (the serendipity surface's centre: -1/4 of the corners + 1/2 of the
    mid-side nodes); the points, the thicknesses (the centre's interpolated alike) and the quad9 cells."""
    def centre(v):
        return -0.25 * v[cells[:, :4]].sum(axis=1) + 0.5 * v[cells[:, 4:8]].sum(axis=1)

    ids = points.shape[0] + np.arange(cells.shape[0])
    return np.vstack([points, centre(points)]), np.concatenate([t, centre(t)]), np.hstack([cells, ids[:, None]])


def _three_quads(corners: np.ndarray, mids: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """The three quad4 of each triangle (``corners`` (n, 3), ``mids`` (n, 3) the mid-points of its edges 0-1, 1-2,
    2-0, ``centre`` (n,)): corner, mid-point of the next edge, centre, mid-point of the previous edge; (3 n, 4)."""
    return np.stack([np.stack([corners[:, k], mids[:, k], centre, mids[:, (k + 2) % 3]], axis=1) for k in range(3)],
                    axis=1).reshape(-1, 4)


def _split_triangles(points: np.ndarray, t: np.ndarray, cells: np.ndarray):
    """Each tri3 into three quad4 (corner, mid-point of the next edge, centroid, mid-point of the previous edge);
    the points, the thicknesses (interpolated linearly), the quads and the triangle of each quad."""
    edges = np.sort(np.stack([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]], axis=1).reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    mid = points.shape[0] + inverse.reshape(-1, 3)  # (ntri, 3): mid-points of edges 0-1, 1-2, 2-0
    centre = points.shape[0] + unique.shape[0] + np.arange(cells.shape[0])

    def new(v):
        return np.concatenate([v, 0.5 * (v[unique[:, 0]] + v[unique[:, 1]]), v[cells].mean(axis=1)])

    return new(points), new(t), _three_quads(cells, mid, centre), np.repeat(np.arange(cells.shape[0]), 3)


def _split_tri6(points: np.ndarray, t: np.ndarray, cells: np.ndarray):
    """Each tri6 (corners, then the mid-side nodes of edges 0-1, 1-2, 2-0) into three quad4 (corner, mid-side node of
    the next edge, centre, mid-side node of the previous edge), the centre the point of the quadratic triangle at its
    centroid (shape functions -1/9 at the corners, 4/9 at the mid-side nodes); the points, the thicknesses
    (interpolated alike), the quads and the triangle of each quad."""
    def centre(v):
        return -v[cells[:, :3]].sum(axis=1) / 9.0 + 4.0 * v[cells[:, 3:6]].sum(axis=1) / 9.0

    quads = _three_quads(cells[:, :3], cells[:, 3:6], points.shape[0] + np.arange(cells.shape[0]))
    return (np.vstack([points, centre(points)]), np.concatenate([t, centre(t)]), quads,
            np.repeat(np.arange(cells.shape[0]), 3))


def _orient(cells: np.ndarray, cell_type: str) -> np.ndarray:
    """The cells oriented consistently over every edge two of them share (breadth first from the first cell of each
    connected part); ShellMeshError where the surface cannot be."""
    n = cells.shape[0]
    corners = cells[:, :4]
    directed = np.stack([corners, np.roll(corners, -1, axis=1)], axis=2).reshape(-1, 2)  # (4 n, 2) a -> b
    key = np.sort(directed, axis=1)
    _, edge, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    edge = edge.ravel()
    owner = np.repeat(np.arange(n), 4)
    forward = directed[:, 0] < directed[:, 1]
    by_edge: dict[int, list[int]] = {}
    for k in np.flatnonzero(counts[edge] == 2):
        by_edge.setdefault(int(edge[k]), []).append(int(k))
    neighbours: list[list[tuple[int, bool]]] = [[] for _ in range(n)]
    for a, b in by_edge.values():  # (same: the two cells run through the edge in the same direction)
        same = bool(forward[a] == forward[b])
        neighbours[owner[a]].append((int(owner[b]), same))
        neighbours[owner[b]].append((int(owner[a]), same))
    flip = np.full(n, -1, dtype=np.int64)
    for start in range(n):
        if flip[start] >= 0:
            continue
        flip[start] = 0
        queue = deque([start])
        while queue:
            c = queue.popleft()
            for d, same in neighbours[c]:
                want = flip[c] ^ int(same)
                if flip[d] < 0:
                    flip[d] = want
                    queue.append(d)
                elif flip[d] != want:
                    raise ShellMeshError(f"the surface cannot be oriented: cells {c} and {d} (0-based) disagree "
                                         f"whichever way they are turned (a Moebius strip?)")
    out = cells.copy()
    turned = flip == 1
    out[turned] = cells[turned][:, _REVERSE[cell_type]]
    return out


def _cell_normals(points: np.ndarray, cells: np.ndarray, cell_type: str) -> np.ndarray:
    """(ne, nen, 3): the normals x_xi x x_eta of the cells (quad4, quad9) at each of their nodes."""
    from ..fem.shapes import shape_functions

    _, dN, _ = shape_functions(cell_type, _Q9_NAT[: cells.shape[1]])  # (nnodes, nen, 2): at the cell's nodes
    x = points[cells]  # (ne, nen, 3)
    return np.cross(np.einsum("ebi,ab->eai", x, dN[:, :, 0]), np.einsum("ebi,ab->eai", x, dN[:, :, 1]))


def _directors(points: np.ndarray, cells: np.ndarray, cell_type: str) -> np.ndarray:
    """The unit mean at every node of the normals x_xi x x_eta of its cells there."""
    normal = _cell_normals(points, cells, cell_type)
    acc = np.zeros_like(points)
    np.add.at(acc, cells.ravel(), normal.reshape(-1, 3))
    size = np.linalg.norm(acc, axis=1)
    used = np.unique(cells)
    if np.any(size[used] <= 1e-300):
        bad = used[size[used] <= 1e-300][0]
        raise ShellMeshError(f"node {bad} (0-based) has no direction: the normals of its cells cancel (a fold of "
                             f"the surface onto itself?)")
    return acc / np.where(size > 0.0, size, 1.0)[:, None]


def _node_normals(points: np.ndarray, cells: np.ndarray, cell_type: str) -> np.ndarray:
    """(ne, nen, 3): the unit normals of the cells at each of their nodes (x_xi x x_eta; a quad8 by its serendipity
    surface, a triangle by the plane of its corners)."""
    if cell_type == "quad8":  # (its serendipity surface, as quad9 with the centre node)
        p9, _, c9 = _quad8_to_quad9(points, np.zeros(points.shape[0]), cells)
        normal = _cell_normals(p9, c9, "quad9")[:, :8]
    elif cell_type.startswith("tri"):  # (the plane of the corners)
        x = points[cells]
        flat = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
        normal = np.repeat(flat[:, None, :], cells.shape[1], axis=1)
    else:
        normal = _cell_normals(points, cells, cell_type)
    return normal / np.maximum(np.linalg.norm(normal, axis=2, keepdims=True), 1e-300)


def knots(points: np.ndarray, cells: np.ndarray, cell_type: str, limit: float = 20.0) -> list[tuple[int, int, int,
                                                                                                     float]]:
    """The nodes where CalculiX's shell expansion makes a knot because the normals of the cells there spread: per
    node, the normals x_xi x x_eta of its cells at it (``cells`` oriented consistently), and a knot where one of them
    makes more than ``limit`` degrees with the first cell's (CalculiX's reference normal: the cells within 20 degrees
    of it share one normal, the others another). Returns (node, first cell, other cell, angle) per such node."""
    normal = _node_normals(points, cells, cell_type)
    node, cell = cells.ravel(), np.repeat(np.arange(len(cells)), cells.shape[1])
    first = np.full(points.shape[0], -1, dtype=np.int64)
    order = np.argsort(cell, kind="stable")
    for k in order[::-1]:  # (the lowest cell at each node last, so it stays)
        first[node[k]] = k
    cos = np.einsum("ki,ki->k", normal.reshape(-1, 3), normal.reshape(-1, 3)[first[node]])
    bad = np.flatnonzero(cos < np.cos(np.radians(limit)))
    out, seen = [], set()
    for k in bad[np.argsort(cos[bad])]:
        if int(node[k]) not in seen:
            seen.add(int(node[k]))
            out.append((int(node[k]), int(cell[first[node[k]]]), int(cell[k]),
                        float(np.degrees(np.arccos(np.clip(cos[k], -1.0, 1.0))))))
    return out


def normal_clusters(points: np.ndarray, cells: np.ndarray, cell_type: str, rank=None, key=None,
                    limit: float = 20.0) -> np.ndarray:
    """CalculiX's subsets of the cells at each node (its shell expansion, gen3delem): the cell of lowest ``rank``
    (its element label; default the cell's place) among those left is the reference, and the cells left whose normal
    at the node lies within ``limit`` degrees of the reference's and whose ``key`` there (thickness, (ne, nen)) is the
    same join its subset; repeated until no cell is left. ``cells`` oriented consistently. Returns (ne, nen): the
    subset of each cell at each of its nodes, 0 the reference cell's; a node in more than one subset is a knot."""
    ne, nen = cells.shape
    rank = np.arange(ne) if rank is None else np.asarray(rank)
    key = np.zeros((ne, nen)) if key is None else np.asarray(key, dtype=float)
    normal = _node_normals(points, cells, cell_type).reshape(-1, 3)
    node, flat_key = cells.ravel(), key.ravel()
    occ = np.lexsort((np.repeat(rank, nen), node))  # (occurrences by node, then by the cell's rank)
    starts = np.flatnonzero(np.r_[True, node[occ][1:] != node[occ][:-1]])
    first = np.repeat(occ[starts], np.diff(np.r_[starts, occ.size]))  # (each occurrence's node's reference)
    cos_limit = np.cos(np.radians(limit))
    same = (np.einsum("ki,ki->k", normal[occ], normal[first]) >= cos_limit) & (flat_key[occ] == flat_key[first])
    out = np.zeros(ne * nen, dtype=np.int64)
    bad_nodes = np.unique(node[occ[~same]])
    for v in bad_nodes:  # (only where one subset does not hold them all)
        mine = occ[node[occ] == v]   # (by rank)
        left = list(mine)
        c = 0
        while left:
            ref = left[0]
            take = [k for k in left if normal[k] @ normal[ref] >= cos_limit and flat_key[k] == flat_key[ref]]
            out[take] = c
            left = [k for k in left if k not in take]
            c += 1
    return out.reshape(ne, nen)


def split_at_knots(points: np.ndarray, cells: np.ndarray, cell_type: str, rank=None, key=None,
                   forced: np.ndarray | None = None, limit: float = 20.0):
    """The surface with every knot node expanded once per subset of its cells (normal_clusters of the consistently
    oriented cells, ``key`` (ne, nen) a value the cells of a subset share, e.g. the thickness), and once at the nodes
    ``forced`` (a mask: a node of one subset made a knot). Returns (points, cells, source: the given node of each node,
    knots: [(given node, its expansions' indices)]): the nodes that are no knot first, in their order, then each
    knot's expansions, subset by subset. The cells keep their node order as given. ShellMeshError where the surface
    cannot be oriented."""
    oriented = _orient(cells, cell_type)
    turned = np.flatnonzero(np.any(oriented != cells, axis=1))
    perm = _REVERSE[cell_type]
    ordered = None
    if key is not None:
        ordered = np.array(key, dtype=float)
        ordered[turned] = np.asarray(key, dtype=float)[turned][:, perm]
    sub = normal_clusters(points, oriented, cell_type, rank=rank, key=ordered, limit=limit)
    given = sub.copy()
    given[np.ix_(turned, perm)] = sub[turned]
    n = points.shape[0]
    knot = np.zeros(n, dtype=bool)
    knot[cells[given > 0]] = True
    if forced is not None:
        knot |= forced
    kept = np.flatnonzero(~knot)
    node, subset = cells.ravel(), given.ravel()
    at_knot = knot[node]
    S = int(given.max()) + 1
    pairs, inverse = np.unique(node[at_knot] * S + subset[at_knot], return_inverse=True)
    new = np.full(n, -1, dtype=np.int64)
    new[kept] = np.arange(kept.size)
    flat = new[node]
    flat[at_knot] = kept.size + inverse.ravel()
    source = np.concatenate([kept, pairs // S])
    found = [(int(i), kept.size + np.flatnonzero(pairs // S == i)) for i in np.flatnonzero(knot)]
    return points[source], flat.reshape(cells.shape), source, found


def extrude_surface(points: np.ndarray, cell_type: str, cells: np.ndarray, thickness, offset="middle",
                    node_sets: dict | None = None, element_sets: dict | None = None,
                    face_sets: dict | None = None, knot_angle: float | None = None) -> Mesh:
    """The solid-shell mesh (hex8 or hex18, one element through the thickness) of the surface mesh (``points``,
    ``cell_type`` in SURFACE_CELLS, ``cells``) with ``thickness`` (a number, or one per surface node) and ``offset``
    ("middle", "top", "bottom" or a number in [-1/2, 1/2], or one number per surface node); the module docstring
    says how. ``face_sets``: name -> [(surface cells, "top" or "bottom")], the face set (and node set, unless one of that name exists) of those cells'
    faces on that side of each cell's own normal (by its corner order as given, whichever way the orientation turned
    it: a deck's SPOS and SNEG). ``knot_angle`` (degrees): the surface split at its knots first (split_at_knots:
    the nodes whose cells' normals differ by more than that), each expansion with its own director; then
    ``mesh.shell_knots`` lists (the node's point, the mesh nodes of its expansions), each also the node set "_knotK"
    (K from 1) that a rigid body joins. ShellMeshError (a ValueError) for a surface that cannot be made into one."""
    points = np.asarray(points, dtype=np.float64)
    cells = np.asarray(cells, dtype=np.int64)
    if cell_type not in SURFACE_CELLS:
        raise ShellMeshError(f"surface cells {cell_type!r} cannot be made into solid-shells (they can: "
                             f"{', '.join(SURFACE_CELLS)})")
    if points.ndim != 2 or points.shape[1] != 3:
        raise ShellMeshError("the surface's points must be (n, 3)")
    n_surface = points.shape[0]
    t = np.broadcast_to(np.asarray(thickness, dtype=np.float64), (n_surface,)).copy()
    if not np.all(np.isfinite(t)) or np.any(t <= 0.0):
        bad = int(np.flatnonzero(~(t > 0.0))[0])
        raise ShellMeshError(f"the thickness must be positive, got {t[bad]:g} at node {bad} (0-based)")
    if isinstance(offset, str):
        o = OFFSETS.get(offset)
        if o is None:
            raise ShellMeshError(f"offset must be 'middle', 'top', 'bottom' or a number in [-0.5, 0.5], got "
                                 f"{offset!r}")
    o = np.broadcast_to(np.asarray(o if isinstance(offset, str) else offset, dtype=np.float64),
                        (n_surface,)).copy()  # (one per node: a deck's sections of different OFFSET meet at knots)
    if not np.all((o >= -0.5) & (o <= 0.5)):
        bad = int(np.flatnonzero(~((o >= -0.5) & (o <= 0.5)))[0])
        raise ShellMeshError(f"offset must be 'middle', 'top', 'bottom' or a number in [-0.5, 0.5], got {o[bad]:g}"
                             + (f" at node {bad} (0-based)" if np.ndim(offset) else ""))
    knot_groups, given_points = [], points
    if knot_angle is not None:
        points, cells, source, knot_groups = split_at_knots(points, cells, cell_type, limit=float(knot_angle))
        t, o = t[source], o[source]
        n_surface = points.shape[0]
        node_sets = {name: np.flatnonzero(np.isin(source, np.asarray(ids, dtype=np.int64)))
                     for name, ids in (node_sets or {}).items()}
    cell_of = np.arange(cells.shape[0])  # the surface cell each new cell comes from
    surface_type = cell_type
    if cell_type == "quad8":  # (the offsets of new points interpolated as the thicknesses: a cell's are alike)
        o = _quad8_to_quad9(points, o, cells)[1]
        points, t, cells = _quad8_to_quad9(points, t, cells)
        cell_type = "quad9"
    elif cell_type == "tri3":
        o = _split_triangles(points, o, cells)[1]
        points, t, cells, cell_of = _split_triangles(points, t, cells)
        cell_type = "quad4"
    elif cell_type == "tri6":
        o = _split_tri6(points, o, cells)[1]
        points, t, cells, cell_of = _split_tri6(points, t, cells)
        cell_type = "quad4"
    given = cells
    cells = _orient(cells, cell_type)
    turned = np.any(cells != given, axis=1)  # (cells whose top is the side against their own normal)
    d = _directors(points, cells, cell_type)
    # (nodes where the cells' normals spread beyond 45 degrees: a junction or a crease, where the mean director bends
    # the shell; said as a warning at the start of a run, covcontact.solvers.model)
    creases = [(int(cell_of[a]), int(cell_of[b]), n, angle) for n, a, b, angle in knots(points, cells, cell_type, 45.0)
               if n < n_surface]
    mid = points - (o * t)[:, None] * d
    bottom = mid - 0.5 * t[:, None] * d
    top = mid + 0.5 * t[:, None] * d
    n = points.shape[0]
    solid = SOLID_OF[cell_type]
    mesh = Mesh(np.vstack([bottom, top]), solid, np.hstack([cells, cells + n]))
    # sets
    top_faces = cells + n
    bottom_faces = cells[:, _REVERSE[cell_type]]
    mesh.add_face_set("top", top_faces)
    mesh.add_face_set("bottom", bottom_faces)
    mesh.add_node_set("top", np.unique(top_faces))
    mesh.add_node_set("bottom", np.unique(bottom_faces))
    mesh.add_node_set("all", np.arange(2 * n))
    from .faces import boundary_faces

    faces, _, _ = boundary_faces(mesh)
    in_plane = np.zeros(2 * n, dtype=bool)
    lateral = faces[~(np.all(faces < n, axis=1) | np.all(faces >= n, axis=1))]
    if cell_type == "quad9":  # (hex18: the six-node side faces as their 4-node halves, _edge_faces)
        lateral = _side_halves(cells, mesh.points)
    if lateral.shape[0]:
        mesh.add_face_set("edges", lateral)
        mesh.add_node_set("edges", np.unique(lateral))
    for name, ids in (node_sets or {}).items():
        ids = np.asarray(ids, dtype=np.int64)
        both = np.concatenate([ids, ids + n])
        mesh.add_node_set(name, both)
        in_plane[:] = False
        in_plane[both] = True
        f = lateral[np.all(in_plane[lateral], axis=1)] if lateral.shape[0] else lateral
        if f.shape[0]:
            mesh.add_face_set(name, f)
    for name, ids in (element_sets or {}).items():
        mesh.element_sets[name] = np.flatnonzero(np.isin(cell_of, np.asarray(ids, dtype=np.int64)))
    for name, rows in (face_sets or {}).items():
        chosen = []
        for ids, side in rows:
            if side in EDGE_SIDES:
                chosen.append(_edge_faces(name, side, given, surface_type, cell_of, ids, mesh.points))
                continue
            if side not in ("top", "bottom"):
                raise ShellMeshError(f"face set {name!r}: side must be 'top', 'bottom' or 'edge1'..'edge4', got "
                                     f"{side!r}")
            sel = np.flatnonzero(np.isin(cell_of, np.asarray(ids, dtype=np.int64)))
            up = turned[sel] != (side == "top")  # (the mesh's top face)
            if np.any(up):
                chosen.append(top_faces[sel[up]])
            if np.any(~up):
                chosen.append(bottom_faces[sel[~up]])
        if chosen:
            pieces = surface_type == "quad8" and any(side in EDGE_SIDES for _, side in rows)
            weights = []
            if len({c.shape[1] for c in chosen}) > 1:  # (hex18 faces beside edge halves: each as its four quarters)
                weights = [_QUARTER_WEIGHT * (_quarters(c) == np.repeat(c[:, 8], 4)[:, None]) if c.shape[1] == 9
                           else None for c in chosen]
                chosen = [_quarters(c) if c.shape[1] == 9 else c for c in chosen]
            f = np.vstack(chosen)
            mesh.add_face_set(name, f)
            if pieces:  # (a uniform pressure on the pieces: the consistent forces of the six-node side faces)
                mid = np.zeros(2 * n, dtype=bool)
                mid[np.concatenate([given[:, 4:8].ravel(), given[:, 4:8].ravel() + n])] = True
                weights = weights or [None] * len(chosen)
                mesh.face_weights[name] = np.vstack([2.0 * mid[c] if w is None else w
                                                     for c, w in zip(chosen, weights)])
            if name not in mesh.node_sets:
                mesh.add_node_set(name, np.unique(f))
    mesh.shell_creases = creases  # (surface cells a, b, surface node, angle in degrees) per such node
    mesh.shell_knots = []
    for k, (i, places) in enumerate(knot_groups):
        nodes = np.concatenate([places, places + n])
        mesh.add_node_set(f"_knot{k + 1}", nodes)
        mesh.shell_knots.append((given_points[i], nodes))
    return mesh


#: the nodal weight of the centre of each quarter of a 9-node face (_quarters; 0 at its other nodes) under which a
#: uniform pressure gives the 9-node face's consistent nodal forces (corners 1/36, mid-sides 1/9, centre 4/9 of the
#: force on a flat face)
_QUARTER_WEIGHT = 4.0


def _quarters(faces: np.ndarray) -> np.ndarray:
    """Each 9-node face (corners, mid-side nodes, centre) as its four 4-node quarters, in its orientation: a face set
    that also holds the 4-node halves of hex18 side faces (_edge_faces) is of one face type."""
    q = np.array([[0, 4, 8, 7], [4, 1, 5, 8], [8, 5, 2, 6], [7, 8, 6, 3]])
    return faces[:, q].reshape(-1, 4)


#: the sides of a face set row that name a quad4 cell's edge k (from its corner k to corner k + 1, in the cell's node
#: order as given): the lateral face of the solid-shell along it (a deck's S3..S6 of an S4 element)
EDGE_SIDES = ("edge1", "edge2", "edge3", "edge4")


def _edge_faces(name, side, given, surface_type, cell_of, ids, points) -> np.ndarray:
    """The side faces (outward) along edge ``side`` of the quad4 or quad8 surface cells ``ids``: (bottom a, bottom b,
    top b, top a) of the cell's edge from corner a to corner b; along a quad8 cell's edge (whose hex18 side face has
    six nodes, no facet type) its two halves, from a and from b to the edge's mid-node m, 4-node faces whose nodes
    are the side face's and whose areas add up to it (a slave surface's nodes and weights; as a master their chords
    would not be the edge's curve). ShellMeshError for other cells or an edge of two cells."""
    if surface_type not in ("quad4", "quad8"):
        raise ShellMeshError(f"face set {name!r}: {side} names an edge of a quad4 or quad8 shell cell (a deck's S4, "
                             f"S4R, S8, S8R); these cells are {surface_type}")
    k = EDGE_SIDES.index(side)
    corners = given[:, :4]
    count: dict = {}
    for c in corners:
        for e in range(4):
            key = frozenset((int(c[e]), int(c[(e + 1) % 4])))
            count[key] = count.get(key, 0) + 1
    out = []
    for c in np.flatnonzero(np.isin(cell_of, np.asarray(ids, dtype=np.int64))):
        a, b = int(given[c, k]), int(given[c, (k + 1) % 4])
        if count[frozenset((a, b))] > 1:
            raise ShellMeshError(f"face set {name!r}: {side} of surface cell {c} (0-based) is shared with another cell, "
                                 f"not an edge of the shell: it has no side face")
        pieces = [(a, b)] if surface_type == "quad4" else [(a, int(given[c, 4 + k])), (int(given[c, 4 + k]), b)]
        out += _side_faces(pieces, given[c], points)
    return np.array(out, dtype=np.int64).reshape(-1, 4)


def _side_faces(pieces, cell: np.ndarray, points: np.ndarray) -> list[np.ndarray]:
    """The side faces (bottom p, bottom q, top q, top p) of the edge pieces (p, q) of surface ``cell``, each turned
    outward (away from the centre of the cell's solid-shell)."""
    n = points.shape[0] // 2
    centre = points[np.concatenate([cell, cell + n])].mean(axis=0)
    out = []
    for p, q in pieces:
        face = np.array([p, q, q + n, p + n], dtype=np.int64)
        x = points[face]
        out.append(face if np.cross(x[1] - x[0], x[3] - x[0]) @ (x.mean(axis=0) - centre) >= 0.0 else face[::-1])
    return out


def _side_halves(cells: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The side faces along the free edges of quad9 surface ``cells`` (their hex18 solid-shells' six-node side faces)
    as 4-node halves, corner to mid-node, outward (:func:`_edge_faces`)."""
    corners = cells[:, :4]
    pairs = np.sort(np.stack([corners, np.roll(corners, -1, axis=1)], axis=2).reshape(-1, 2), axis=1)
    _, inverse, counts = np.unique(pairs, axis=0, return_inverse=True, return_counts=True)
    out = []
    for j in np.flatnonzero(counts[inverse.ravel()] == 1):
        c, k = divmod(int(j), 4)
        a, b, m = int(cells[c, k]), int(cells[c, (k + 1) % 4]), int(cells[c, 4 + k])
        out += _side_faces(((a, m), (m, b)), cells[c], points)
    return np.array(out, dtype=np.int64).reshape(-1, 4)


#: meshio's surface cell types and ours
_FROM_MESHIO = {"quad": "quad4", "quad8": "quad8", "quad9": "quad9", "triangle": "tri3", "triangle6": "tri6"}


def read_surface(path) -> tuple[np.ndarray, str, np.ndarray, dict, dict]:
    """A surface mesh file read through meshio (Gmsh, VTU, ...): (points, cell type, cells, node sets, element
    sets). The surface cells must be of one type of SURFACE_CELLS; named groups (Gmsh physical groups, cell sets) of
    surface cells become element sets, those of lines and points node sets (a physical curve: the nodes of its
    lines). ShellMeshError where the file holds no surface cells, cells of several types, or volume cells."""
    from pathlib import Path

    from meshio._mesh import topological_dimension

    from .io import MeshError, _groups, read_meshio

    p = Path(path)
    try:
        m = read_meshio(p)
    except MeshError as exc:
        raise ShellMeshError(str(exc)) from exc
    volume = sorted({b.type for b in m.cells if topological_dimension.get(b.type) == 3})
    if volume:
        raise ShellMeshError(f"{p}: holds volume cells ({', '.join(volume)}); a shell body's mesh is its surface")
    kinds = sorted({_FROM_MESHIO[b.type] for b in m.cells if b.type in _FROM_MESHIO})
    other = sorted({b.type for b in m.cells if topological_dimension.get(b.type) == 2 and b.type not in _FROM_MESHIO})
    if other or len(kinds) != 1:
        found = ", ".join(sorted({b.type for b in m.cells})) or "none"
        raise ShellMeshError(f"{p}: a shell body needs surface cells of one type of {', '.join(SURFACE_CELLS)} "
                             f"(meshio: quad, quad8, quad9, triangle); found: {found}")
    blocks = [b for b, blk in enumerate(m.cells) if blk.type in _FROM_MESHIO]
    first = np.cumsum([0] + [len(m.cells[b].data) for b in blocks])
    cells = np.concatenate([np.asarray(m.cells[b].data, dtype=np.int64) for b in blocks])
    used = np.unique(cells)
    renumber = -np.ones(len(m.points), dtype=np.int64)
    renumber[used] = np.arange(used.size)
    points = np.zeros((used.size, 3))
    pts = np.asarray(m.points, dtype=np.float64)
    points[:, : pts.shape[1]] = pts[used]
    node_sets: dict[str, np.ndarray] = {}
    element_sets: dict[str, np.ndarray] = {}
    for name, ids in m.point_sets.items():  # (an Abaqus file's *NSET)
        nodes = renumber[np.asarray(ids, dtype=np.int64)]
        if np.any(nodes >= 0):
            node_sets[name] = np.unique(nodes[nodes >= 0])
    for name, parts in _groups(m).items():
        for b, ids in parts:
            if b in blocks:
                k = blocks.index(b)
                element_sets[name] = np.union1d(element_sets.get(name, np.zeros(0, np.int64)), first[k] + ids)
            else:
                nodes = renumber[np.asarray(m.cells[b].data)[ids].ravel()]
                node_sets[name] = np.union1d(node_sets.get(name, np.zeros(0, np.int64)), nodes[nodes >= 0])
    return points, kinds[0], renumber[cells], node_sets, element_sets
