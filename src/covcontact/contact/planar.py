"""Covariant node-to-segment contact in the plane: slave nodes of a planar body against master curves made of the
edges of a planar body (docs/theory.md section 28).

The master curve of a segment is x(xi) = N_b(xi) x_b, xi in [-1, 1], with 2 nodes (linear; edges of quad4 and
tri3) or 3 (quadratic: the two corners, then the mid-node; edges of quad8, quad9 and tri6). With the one convective
coordinate xi:

    rho = x,xi,  a = rho . rho (the metric a_11),  n = (rho_y, -rho_x) / sqrt(a)  (outward: the cells are
    counter-clockwise and an edge runs from its first to its second corner),
    h = x,xixi . n,  kappa = h / a (the curvature of the master curve),
    g = (x_s - x(xi)) . n at the closest point (x_s - x(xi)) . rho = 0 (Newton on xi: f' = -(a - g h) = -c).

Penalty (or augmented Lagrangian with the multiplier lam_k <= 0 held fixed): g_e = g + lam_k / eps,
p = eps <-g_e>, energy W = eps / 2 <g_e>^2. With alpha = (-N_b, 1) and beta = (-N_b,xi, 0) over the master nodes
and the slave (the slave last), the residual is R_b = eps g_e alpha_b n, and every tangent part has the block form

    K_bc = eps [ alpha_b alpha_c (c_nn n(x)n + M rho(x)rho) + g_e (alpha_c n(x)u_b + alpha_b u_c(x)n)
                 - g_e g s_bc n(x)n ],   u_b = beta_b W rho,   s_bc = beta_b S beta_c

with (c_nn, M, W, S) = main (1, 0, 0, 0), rotational (0, 0, 1/a, 0), curvature (0, -g_e h / a^2, 0, 0) and second
order (0, -g_e g h^2 / (a^2 c), 1/c - 1/a, 1/c), c = a - g h: the planar reduction of the 3D element
(:mod:`.element`, one index). Their sum is the exact Hessian of W. All vectors carry three components, the z one
zero: the planar bodies keep three dofs per node with u_z held at zero, and the contact does not see z.

A slave whose projection lies on no segment (the closest point of the curve is a vertex between two segments, in the
region behind a valley corner) is in contact with the vertex: g = s |x_s - x_v| with s the sign of
(x_s - x_v) . (n_1 + n_2) over the two segments' normals, n = (x_s - x_v) / g, and the exact tangent
eps [n(x)n + g_e / g (I - n(x)n)] (in-plane I) on the vertex-slave pair, for every tangent case (the 3D code's edge
and vertex points do the same). The open ends of a master curve take no vertex contact.
"""

from __future__ import annotations

import numpy as np

from .element import CASE_A, CASE_B, CASE_C, CASE_D, CASE_EXACT  # noqa: F401  (re-exported)

# the segment kernels (projection, the residual and tangent parts, the vertex) are planar_kernels's; planar_friction
# uses them too
from .planar_kernels import (INSIDE_TOL, MAX_ITER, project_on_segment, segment_core, segment_point,  # noqa: E402,F401
                             segment_shapes, vertex_core)
from .planar_search import FACET, VERTEX, closest_core  # noqa: E402
from .selfcontact import FRONT_COS, HOLD_COS  # noqa: E402


class Curve:
    """The master curve of a pass: segments (nseg, nen) of extended node ids, each corner's segments."""

    def __init__(self, segments: np.ndarray):
        self.segments = np.ascontiguousarray(segments, dtype=np.int64)
        self.nen = self.segments.shape[1]
        corners = self.segments[:, :2]
        self.corner_nodes = np.unique(corners)
        # each corner's segments, in increasing order, by its place in corner_nodes: node_segs[node_ptr[k]:
        # node_ptr[k + 1]] (the compiled search's arrays)
        pos = np.searchsorted(self.corner_nodes, corners.ravel())
        order = np.argsort(pos, kind="stable")
        self.node_segs = np.ascontiguousarray(np.repeat(np.arange(len(corners)), 2)[order], dtype=np.int64)
        self.node_ptr = np.concatenate([[0], np.cumsum(np.bincount(pos, minlength=len(self.corner_nodes)))]
                                       ).astype(np.int64)

    def normals(self, xe: np.ndarray) -> np.ndarray:
        """Unit chord normals of the segments (nseg, 2)."""
        t = xe[self.segments[:, 1], :2] - xe[self.segments[:, 0], :2]
        n = np.column_stack([t[:, 1], -t[:, 0]])
        return n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None]


#: self-contact: a projection counts as inside its segment up to this far beyond its ends in xi (a slave facing a node
#: of the other wall of a flattened surface otherwise flips between its two segments and the vertex on round-off)
SELF_TOL_INSIDE = 1e-4


def closest_points(curve: Curve, xe: np.ndarray, xs: np.ndarray, reach: float, keep: np.ndarray | None = None,
                   keep_band: float = 0.0, exclude: np.ndarray | None = None, own: np.ndarray | None = None,
                   cos_max: np.ndarray | None = None):
    """Closest points of slaves xs (ns, 3) on the curve at positions xe: per slave (kind 0 none, FACET on a segment,
    VERTEX at a vertex; segment (the vertex's first segment for VERTEX); xi (the vertex's xi there); g; vertex node
    id (-1); sign). Candidates: the segments with a corner within ``reach`` (a segment length or more) of the slave;
    among the projections inside their segment the one of smallest |g|; none inside: the nearest corner shared by
    two segments. ``keep`` (frictional passes): per slave the segment of the last iterate (-1 none), kept while the
    projection on it lies within ``keep_band`` of it (xi not clipped). Self-contact (``exclude``, (ns, k) segments
    each slave never touches, -1 padded; ``own`` (ns, 2) its own outward normal; ``cos_max`` (ns,)): a segment counts
    only if its normal makes a cosine below cos_max with the slave's own, a vertex only if the slave lies in front of
    it (within FRONT_COS of -own, seen from the vertex) and is not the slave's own node (docs/theory.md section 13)."""
    from scipy.spatial import cKDTree

    ns = len(xs)
    kind = np.zeros(ns, dtype=np.int64)
    seg = np.full(ns, -1, dtype=np.int64)
    xi = np.zeros(ns)
    g = np.full(ns, np.inf)
    vert = np.full(ns, -1, dtype=np.int64)
    sign = np.ones(ns)
    nodes = curve.corner_nodes
    tree = cKDTree(xe[nodes, :2])
    near = tree.query_ball_point(xs[:, :2], reach)
    sizes = np.fromiter(map(len, near), dtype=np.int64, count=ns)
    near_ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    near_k = np.fromiter((k for row in near for k in row), dtype=np.int64, count=int(near_ptr[-1]))
    self_mode = exclude is not None
    closest_core(np.ascontiguousarray(xe, dtype=np.float64), np.ascontiguousarray(xs, dtype=np.float64),
                 curve.segments, nodes.astype(np.int64), curve.node_ptr, curve.node_segs, near_ptr, near_k,
                 np.full(ns, -1, dtype=np.int64) if keep is None else np.ascontiguousarray(keep, dtype=np.int64),
                 float(keep_band), float(SELF_TOL_INSIDE if self_mode else INSIDE_TOL), self_mode,
                 np.ascontiguousarray(exclude, dtype=np.int64) if self_mode else np.full((ns, 1), -1, dtype=np.int64),
                 np.ascontiguousarray(own[:, :2], dtype=np.float64) if self_mode else np.zeros((ns, 2)),
                 np.ascontiguousarray(cos_max, dtype=np.float64) if self_mode else np.zeros(ns),
                 np.ascontiguousarray(curve.normals(xe), dtype=np.float64), float(FRONT_COS),
                 kind, seg, xi, g, vert, sign)
    return kind, seg, xi, g, vert, sign


# -- weights -----------------------------------------------------------------------------------------------------
def slave_weights(X: np.ndarray, edges: np.ndarray, formulation: str, thickness: float = 1.0) -> np.ndarray:
    """Per node of X, the consistent tributary measure of the edges (nf, 2 or 3) in the reference configuration:
    sum over the edges of int N_a t ds with t the thickness (plane strain, plane stress) or 2 pi R (axisymmetric,
    R = X_x the reference radius): what a uniform unit pressure on the edges gives the nodes (a quadratic edge:
    1/6, 2/3, 1/6 of its measure)."""
    out = np.zeros(len(X))
    if not len(edges):
        return out
    N, ds = edge_rule(X, edges, formulation, thickness, 5)
    np.add.at(out, edges.ravel(), np.einsum("fk,ka->fa", ds, N).ravel())
    return out


def edge_points(num, X: np.ndarray, parts: list, order: int | None):
    """The slave points of segment-to-segment contact in the plane: the Gauss points of the edges of ``parts``
    ((edges, formulation, thickness) each; ``order`` per edge, default 2 on linear and 3 on quadratic edges) as
    virtual points of ``num``. Returns (their ids, their measures w J t or w J 2 pi R, the index of each point's edge
    among all the parts' edges)."""
    ids, weight, own, first = [], [], [], 0
    for edges, formulation, thickness in parts:
        N, ds = edge_rule(X, edges, formulation, thickness, order or (2 if edges.shape[1] == 2 else 3))
        ids.append(num.points.add(np.repeat(edges, N.shape[0], axis=0), np.tile(N, (len(edges), 1))))
        weight.append(ds.ravel())
        own.append(first + np.repeat(np.arange(len(edges)), N.shape[0]))
        first += len(edges)
    return np.concatenate(ids), np.concatenate(weight), np.concatenate(own)


def edge_rule(X: np.ndarray, edges: np.ndarray, formulation: str, thickness: float, order: int):
    """The Gauss rule of ``order`` points on each edge (nf, 2 or 3) in the reference configuration: (N (k, nen) the
    shape values at the points, ds (nf, k) their measures w_k |dX/dxi| t, t the thickness or 2 pi R at the point)."""
    nen = edges.shape[1]
    pts, wts = np.polynomial.legendre.leggauss(order)
    N = np.zeros((len(pts), nen))
    dN = np.zeros((len(pts), nen))
    ddN = np.zeros(3)
    for k, z in enumerate(pts):
        n3, d3 = np.empty(3), np.empty(3)
        segment_shapes(nen, float(z), n3, d3, ddN)
        N[k], dN[k] = n3[:nen], d3[:nen]
    Xe = X[edges][:, :, :2]  # (nf, nen, 2)
    dx = np.einsum("ka,fai->fki", dN, Xe)
    ds = np.linalg.norm(dx, axis=2) * wts[None, :]
    if formulation == "axisymmetric":
        ds = ds * 2.0 * np.pi * np.einsum("ka,fa->fk", N, Xe[:, :, 0])
    else:
        ds = ds * float(thickness)
    return N, ds


# -- pairs on planar bodies ----------------------------------------------------------------------------------------
PLANAR_FORMULATIONS = ("plane_strain", "plane_stress", "axisymmetric")


def _body(bodies, name):
    return next((b for b in bodies if b.name == name), None)


def check_pair(pair, bodies, rigid) -> str | None:
    """Why the contact ``pair`` cannot run as planar contact (one line), or None. Called for pairs with a planar body
    on either side."""
    name = f"contact pair {pair.name!r}"
    if pair.self_surfaces:  # self-contact: edge sets of planar bodies of one formulation
        own = [_body(bodies, b) for b, _ in pair.self_surfaces]
        forms = {b.formulation if b is not None else "rigid" for b in own}
        if len(forms) > 1 or not forms <= set(PLANAR_FORMULATIONS):
            return (f"{name}: a self-contact surface in the plane is made of edge sets of planar bodies of one "
                    f"formulation (found {', '.join(sorted(forms))})")
        return None
    sb, mb = _body(bodies, pair.slave[0]), _body(bodies, pair.master[0])
    forms = {b.formulation for b in (sb, mb) if b is not None}
    planar = forms & set(PLANAR_FORMULATIONS)
    if forms - set(PLANAR_FORMULATIONS):
        return (f"{name}: body {(sb if sb.formulation not in PLANAR_FORMULATIONS else mb).name!r} is three-dimensional "
                f"and the other planar: a contact pair joins planar bodies only to planar bodies or rigid lines and "
                f"circles")
    if len(planar) > 1:
        return f"{name}: the bodies have different formulations ({' and '.join(sorted(planar))})"

    if pair.adjust is not None:
        return f"{name}: adjust is not available on planar bodies"
    if pair.weighting == "boundary":
        return f"{name}: weighting = \"boundary\" is not available on planar bodies (use \"area\" or \"nodal\")"
    if sb is None:
        return f"{name}: the slave of a planar pair is the edge set of a planar body, not the rigid body {pair.slave[0]!r}"
    if mb is None and pair.law == "tied":
        return f"{name}: a tied planar pair bonds to the edges of a planar body, not to the rigid body {pair.master[0]!r}"
    if mb is None:
        rb = next((r for r in rigid if r.name == pair.master[0]), None)
        if rb is not None and rb.mesh is not None:
            return _rigid_mesh_in_plane(name, rb, pair.master[1], sb.formulation)
        if rb is None or rb.shape not in ("plane", "cylinder", "profile"):
            return (f"{name}: the rigid master {pair.master[0]!r} of a planar pair must be an analytic line (shape = "
                    f"\"plane\" with a normal in the x-y plane), circle (shape = \"cylinder\" with its axis along z) "
                    f"or profile (shape = \"profile\" extruded along z; axisymmetric: revolved about the y axis)")
        if rb.shape == "profile":
            return _profile_in_plane(name, rb, sb.formulation)
        vec = np.asarray(rb.params["normal" if rb.shape == "plane" else "axis"], dtype=float)
        vec = vec / np.linalg.norm(vec)
        if rb.shape == "plane" and abs(vec[2]) > 1e-12:
            return f"{name}: the rigid plane {rb.name!r} of a planar pair needs a normal in the x-y plane (n_z = 0)"
        if rb.shape == "cylinder" and abs(abs(vec[2]) - 1.0) > 1e-12:
            return f"{name}: the rigid cylinder {rb.name!r} of a planar pair needs its axis along z ([0, 0, 1])"
        if rb.shape == "cylinder" and sb.formulation == "axisymmetric":
            return (f"{name}: a rigid circle in an axisymmetric model is a torus, not available; an axisymmetric "
                    f"pair takes a rigid line")
    return None


def _rigid_mesh_in_plane(name: str, rb, edges: str, formulation: str) -> str | None:
    """Why the meshed rigid body ``rb`` is no master of a planar pair (None when it is): its mesh is of planar cells
    in the x-y plane (x >= 0 in an axisymmetric model), ``edges`` one of its edge sets, and it moves in the plane."""
    from ..fem.planar_cells import EDGES

    mesh = rb.mesh
    if any(t not in EDGES for t in mesh.cell_types):
        return (f"{name}: the meshed rigid master {rb.name!r} of a planar pair must be a mesh of planar cells in the "
                f"x-y plane (quad4, quad8, quad9, tri3, tri6), got {' and '.join(mesh.cell_types)}")
    if np.abs(mesh.points[:, 2]).max() > 1e-9 * max(1.0, float(np.abs(mesh.points).max())):
        return f"{name}: the meshed rigid master {rb.name!r} of a planar pair has nodes off the x-y plane (z != 0)"
    if formulation == "axisymmetric" and mesh.points[:, 0].min() < 0.0:
        return f"{name}: the meshed rigid master {rb.name!r} of an axisymmetric pair has nodes at negative radius"
    if edges not in mesh.face_sets:
        known = ", ".join(sorted(mesh.face_sets)) or "none"
        return f"{name}: the meshed rigid master {rb.name!r} has no edge set {edges!r} (known: {known})"
    return _moves_in_plane(name, rb, formulation)


def _moves_in_plane(name: str, rb, formulation: str) -> str | None:
    """Why the rigid master ``rb``'s motion leaves the plane (None when it does not): it may translate in the x-y
    plane and turn about z (axisymmetric: translate along the axis y only)."""
    m = rb.motion
    t = np.asarray(getattr(m, "translation", np.zeros(3)), dtype=float)
    w = np.asarray(getattr(m, "rotation", np.zeros(3)), dtype=float)
    path = getattr(m, "path", None)
    if path is not None:
        path = np.asarray(path, dtype=float)
        t = np.array([path[:, 1].max() - path[:, 1].min() if formulation == "axisymmetric" else 0.0, 0.0,
                      np.abs(path[:, 3]).max()])
    if abs(t[2]) > 0.0 or np.any(w[:2] != 0.0) or (formulation == "axisymmetric" and (t[0] != 0.0 or w[2] != 0.0)):
        return (f"{name}: the rigid master {rb.name!r} of a planar pair moves out of its plane: it may translate in "
                f"the x-y plane and turn about z (axisymmetric: translate along the axis y only)")
    return None


def _profile_in_plane(name: str, rb, formulation: str) -> str | None:
    """Why the profile tool ``rb`` is no master curve of a planar pair (None when it is): in plane strain and plane
    stress a profile extruded along z (its drawing in the x-y plane), in an axisymmetric model one revolved about the
    y axis (x = 0: its drawing is the section's, p the radius); translations in the plane (along the axis in an
    axisymmetric model) and, in the plane, rotations about z."""
    ex, rv = rb.params.get("extrude"), rb.params.get("revolve")
    unit = (lambda v: np.asarray(v, dtype=float) / np.linalg.norm(v))
    if formulation == "axisymmetric":
        ok = rv is not None and abs(abs(unit(rv["axis"])[1]) - 1.0) <= 1e-12 and \
            abs(float(rv["center"][0])) <= 1e-12 and abs(float(rv["center"][2])) <= 1e-12
        want = "revolved about the model's axis (revolve = { axis = [0, 1, 0], center = [0, y, 0] })"
    else:
        ok = ex is not None and abs(abs(unit(ex["axis"])[2]) - 1.0) <= 1e-12 and abs(float(ex["origin"][2])) <= 1e-12
        want = "extruded along z from the x-y plane (extrude = { axis = [0, 0, 1], origin = [x, y, 0] })"
    if not ok:
        return f"{name}: the profile {rb.name!r} of a planar pair must be {want}"
    return _moves_in_plane(name, rb, formulation)


def planar_body(num, name):
    """The planar Body ``name`` of the problem, or None."""
    b = _body(num.problem.bodies, name)
    return b if b is not None and b.formulation in PLANAR_FORMULATIONS else None


def make_self_pass(num, name: str, pair, tangent: str | None, Pass, law_terms):
    """The self-contact pass of ``pair`` in the plane: its edge sets (``pair.self_surfaces``) are one curve, slave and
    master of itself; the slaves its nodes (or, ``type = "sts"``, the Gauss points of its edges), each excluding the
    segments around it (its own segment for a point) and meeting the rest face to face (docs/theory.md section 13)."""
    from .element import CASES
    from .selfcontact import excluded_facets

    X = num.reference()
    parts = []
    for b, f in pair.self_surfaces:
        mesh, off = num.mesh_of(b)
        if f not in mesh.face_sets:
            raise ValueError(f"contact {pair.name}: no edge set {f!r} on body {b!r}")
        body = planar_body(num, b)
        parts.append((mesh.face_sets[f] + off, body.formulation, float(body.options.get("thickness", 1.0))))
    segments = np.vstack([e for e, _, _ in parts])
    own = None
    if pair.type == "sts":
        slaves, weight, own = edge_points(num, X, parts, pair.order)
        exclude = own[:, None].copy()
    else:
        slaves = np.unique(segments.ravel())
        weight = sum(slave_weights(X, e, form, t) for e, form, t in parts)[slaves]
        if pair.weighting == "area" or pair.penalty == "auto":  # (no contact on the axis: see make_pass)
            slaves, weight = slaves[weight > 0.0], weight[weight > 0.0]
        exclude = excluded_facets(segments, num.n_ext, slave_nodes=slaves)
    h = float(np.mean(_chords(X, segments)))
    if pair.penalty == "auto":
        penalty = pair.penalty_factor() * max(num.material_E(b) for b, _ in pair.self_surfaces) / h
    else:
        penalty = float(pair.penalty)
    eps = penalty * weight if (pair.weighting == "area" or pair.penalty == "auto" or pair.type == "sts") else \
        np.full(len(slaves), penalty)
    eps, eps_t, band, law = law_terms(pair, eps, penalty)
    p = Pass(name, slaves, eps, weight, eps_t=eps_t, case=CASES[tangent or pair.tangent],
             mu=float(pair.friction or 0.0), augmented=pair.method == "augmented", max_aug=pair.max_augmentations,
             pair=pair.name, band=band, kind=pair.type, slave_faces=segments, slave_facet=own, law=law, exclude=exclude)
    p.curve = Curve(segments)
    if p.augmented:
        p.gap_tol = pair.gap_tolerance if pair.gap_tolerance is not None else pair.gap_tolerance_relative * h
    return p


def make_pass(num, name: str, slave, master, pair, tangent: str | None, Pass, analytic_surface, law_terms):
    """The node-to-segment pass of ``slave`` (body, edge set) against ``master`` (a planar body's edge set, or a
    rigid line or circle) of ``pair``: weights from :func:`slave_weights` (reference configuration), eps = penalty
    times the weight with weighting "area" or penalty "auto" (eps per unit length per thickness or circumference),
    the penalty itself per node with weighting "nodal"."""
    from .element import CASES

    X = num.reference()
    sb = planar_body(num, slave[0])
    smesh, soff = num.mesh_of(slave[0])
    thickness = float(sb.options.get("thickness", 1.0))
    if slave[1] not in smesh.node_sets:
        raise ValueError(f"contact {pair.name}: no node set {slave[1]!r} on body {slave[0]!r}")
    nodes = smesh.node_sets[slave[1]] + soff
    faces = smesh.face_sets[slave[1]] + soff if slave[1] in smesh.face_sets else None
    own = None
    if pair.type == "sts":  # segment-to-segment: the Gauss points of the slave edges as slaves (virtual points)
        if faces is None:
            raise ValueError(f"contact {pair.name}: segment-to-segment contact needs an edge set named {slave[1]!r}")
        nodes, weight, own = edge_points(num, X, [(faces, sb.formulation, thickness)], pair.order)
    elif faces is not None:
        weight = slave_weights(X, faces, sb.formulation, thickness)[nodes]
    else:
        weight = np.ones(len(nodes))
    mb = planar_body(num, master[0])
    segments = None
    rigid_mesh = mb is None and num.mesh_of(master[0])[0] is not None   # (a meshed rigid body's edges)
    if mb is not None or rigid_mesh:
        mmesh, moff = num.mesh_of(master[0])
        if master[1] not in mmesh.face_sets:
            raise ValueError(f"contact {pair.name}: no edge set {master[1]!r} on body {master[0]!r}")
        segments = mmesh.face_sets[master[1]] + moff
    ref = segments if segments is not None else faces
    h = float(np.mean(_chords(X, ref))) if ref is not None else 1.0
    if pair.penalty == "auto" and pair.law == "tied":  # the stiffer body over the shorter of both sides' segments
        sides = [e for e in (faces, segments) if e is not None and len(e)]
        penalty = (pair.penalty_factor() * max(num.material_E(b.name) for b in (sb, mb))
                   / min(float(np.mean(_chords(X, e))) for e in sides))
    elif pair.penalty == "auto":
        penalty = pair.penalty_factor() * num.material_E((mb if mb is not None else sb).name) / h
    else:
        penalty = float(pair.penalty)
    if pair.weighting == "area" or pair.penalty == "auto" or pair.type == "sts":
        if faces is None:
            raise ValueError(f"contact {pair.name}: area weighting needs an edge set named {slave[1]!r}")
        if pair.type != "sts" and np.any(weight <= 0.0):  # (the corner on the axis of a quadratic edge of an
            keep = weight > 0.0                              # axisymmetric body: no circumference, no contact)
            nodes, weight = nodes[keep], weight[keep]
        eps = penalty * weight
    else:
        eps = np.full(len(nodes), penalty)
    eps, eps_t, band, law = law_terms(pair, eps, penalty)   # (the pressure-overclosure laws as in 3D)
    kw = {"eps_t": eps_t, "case": CASES[tangent or pair.tangent], "mu": float(pair.friction or 0.0),
          "augmented": pair.method == "augmented", "max_aug": pair.max_augmentations, "pair": pair.name,
          "slave_body": slave[0], "master_body": master[0], "band": band, "kind": pair.type, "slave_faces": faces,
          "slave_facet": own, "law": law}
    if segments is not None:
        p = Pass(name, nodes, eps, weight, **kw)
        p.curve = Curve(segments)
    else:
        rb = next(r for r in num.problem.rigid if r.name == master[0])
        p = Pass(name, nodes, eps, weight, analytic=analytic_surface(rb), rigid=rb.name, **kw)
    if pair.law == "tied":
        xs = np.vstack([X, num.points.positions(X)])[nodes] if pair.type == "sts" else X[nodes]
        p.tie_facet, p.tie_N = tie(p.curve, X, xs, pair.tie_tolerance)
        if not (p.tie_facet >= 0).any():
            raise ValueError(f"contact {pair.name}: no slave node lies within the tie tolerance of the master edges; "
                             f"the edges do not meet: check the geometry or raise tie_tolerance")
    if p.augmented:
        p.gap_tol = pair.gap_tolerance if pair.gap_tolerance is not None else pair.gap_tolerance_relative * h
    return p


def _chords(X: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Per edge (nf, 2 or 3), its corner-to-corner length."""
    return np.linalg.norm(X[edges[:, 1], :2] - X[edges[:, 0], :2], axis=1)


def tie(curve: Curve, X: np.ndarray, xs: np.ndarray, tolerance: float | None):
    """Tie slave nodes at reference positions xs (ns, 3) to the master ``curve`` at reference nodes X (a tied pair,
    docs/theory.md section 14, in the plane): each to its closest point on the curve (a vertex between two segments
    included), if that lies within the tolerance (None: 5 % of the mean segment length). Returns (segment (ns,), -1
    where none lies within it; N (ns, nen) the segment's shape values at the tie point)."""
    lengths = _chords(X, curve.segments)
    tol = 0.05 * float(lengths.mean()) if tolerance is None else float(tolerance)
    kind, seg, xi, g, _, _ = closest_points(curve, X, xs, 1.5 * float(lengths.max()))
    ok = (kind != 0) & (np.abs(g) <= tol)
    N = np.zeros((len(xs), curve.nen))
    n3, d3, dd3 = np.empty(3), np.empty(3), np.empty(3)
    for i in np.flatnonzero(ok):
        segment_shapes(curve.nen, float(xi[i]), n3, d3, dd3)
        N[i] = n3[:curve.nen]
    return np.where(ok, seg, -1).astype(np.int64), N


# -- the pass -------------------------------------------------------------------------------------------------------
def segment_pass(manager, p, xe: np.ndarray, case: int, t, want_K: bool, want_parts: bool, ev, c=None, g0=None,
                 x_commit=None) -> None:
    """Evaluate the node-to-segment pass ``p`` (its ``curve``) at extended positions xe into ``ev`` (element blocks,
    the parts) and the trial pass state ``t`` (facet: the segment, xi, gap, force). A frictional pass (p.mu > 0)
    reads the committed pass state ``c`` (its friction history, on the segments ``c.hist_facet``) and the
    configuration ``x_commit`` of the last commit, keeps the segment of the last iterate ``g0`` up to KEEP_BAND
    outside it, and writes the history to commit and the friction state into ``t`` (:mod:`.planar_friction`);
    the committed state is only read."""
    from .laws import is_active, linear_equivalents

    curve: Curve = p.curve
    xs = xe[p.slaves]
    lengths = np.linalg.norm(xe[curve.segments[:, 1], :2] - xe[curve.segments[:, 0], :2], axis=1)
    reach = 1.5 * float(lengths.max()) if len(lengths) else 0.0
    friction = p.mu > 0.0 and c is not None
    # every slave keeps its segment of the last iterate up to KEEP_BAND beyond it: a frictional one has its history
    # there, and a slave at a vertex between two segments (a node facing a node of the other surface, as non-matching
    # meshes of flat walls and flattened self-contact have them) otherwise flips between them, or falls into the
    # valley between them, on round-off, and Newton cycles or diverges
    keep = g0.facet if g0 is not None else None
    own = cos_max = None
    if p.exclude is not None:  # self-contact: each slave's own outward normal, the facing test's hysteresis
        normals = curve.normals(xe)
        if p.slave_facet is not None:
            own = normals[p.slave_facet]
        else:
            own = np.where(p.exclude[:, :, None] >= 0, normals[np.maximum(p.exclude, 0)], 0.0).sum(axis=1)
            own /= np.maximum(np.linalg.norm(own, axis=1), 1e-300)[:, None]
        cos_max = np.where(g0.facet >= 0, HOLD_COS, 0.0) if g0 is not None else np.zeros(len(xs))
    kind, seg, xi, g, vert, sign = closest_points(curve, xe, xs, reach, keep, KEEP_BAND, p.exclude, own, cos_max)
    ok = kind != 0
    t.facet = np.where(ok, seg, -1).astype(np.int64)
    t.xi = np.column_stack([np.where(ok, xi, 0.0), np.zeros(len(xi))])
    t.gap = np.where(ok, g, np.inf)
    t.hist_facet = t.facet.copy()
    pull = np.zeros(len(ok), dtype=bool)
    if p.law is not None:  # a pressure-overclosure curve: the linear law with its traction and slope at each gap
        on, eps_s, lam_s = p.law.equivalents(t.gap, p.area)
        active = ok & on
        pull = active & (lam_s + eps_s * np.where(ok, g, 0.0) > 0.0)   # (a tension at a clearance: split below)
    else:
        if p.band != 0.0:
            eps_s, lam_s = linear_equivalents(t.gap, t.multiplier, p.eps, p.band)
        else:
            eps_s, lam_s = p.eps, t.multiplier
        active = ok & is_active(t.gap, t.multiplier, p.eps, p.band)
    nen = curve.nen
    nd = 3 * (nen + 1)
    idx = np.flatnonzero(active & (kind == FACET))
    if idx.size:
        conn = np.hstack([curve.segments[seg[idx]], p.slaves[idx][:, None]])
        R = np.zeros((idx.size, nd))
        K = np.zeros((idx.size, nd, nd))
        P = np.zeros((idx.size, 4, nd, nd)) if want_parts else np.zeros((1, 4, nd, nd))
        for j, s in enumerate(idx):
            xseg = np.ascontiguousarray(xe[conn[j, :nen]])
            if friction and pull[s]:  # (a pull carries no friction: the history is dropped, as in 3D)
                t.hist[s] = 0.0
                t.status[s] = 0
            elif friction:
                from .planar_friction import segment_friction_core

                hist = _segment_history(p, c, s, int(seg[s]), float(xi[s]), x_commit)
                t.gap[s], t.status[s] = segment_friction_core(
                    xseg, np.ascontiguousarray(xs[s]), float(xi[s]), float(eps_s[s]), float(p.eps_t[s]), float(p.mu),
                    float(lam_s[s]), hist, R[j], K[j], t.hist[s])
                if want_parts:
                    segment_core(xseg, np.ascontiguousarray(xs[s]), float(xi[s]), float(eps_s[s]), float(lam_s[s]),
                                 case, True, np.zeros(nd), np.zeros((nd, nd)), P[j])
                continue
            for e_j, l_j in _laws(float(eps_s[s]), float(lam_s[s]), float(g[s]), bool(pull[s])):
                Rj, Kj, Pj = np.zeros(nd), np.zeros((nd, nd)), np.zeros((4, nd, nd))
                t.gap[s] = segment_core(xseg, np.ascontiguousarray(xs[s]), float(xi[s]), e_j, l_j, case, want_parts,
                                        Rj, Kj, Pj)
                R[j] += Rj
                K[j] += Kj
                if want_parts:
                    P[j] += Pj
        t.force[idx] = -R[:, -3:]
        manager._add(ev.blocks, conn, R, K if want_K else None, xe)
        if want_parts:
            for k in range(4):
                ev.parts[k].add(conn, np.zeros_like(R), P[:, k])
    idx = np.flatnonzero(active & (kind == VERTEX))
    if idx.size:
        conn = np.column_stack([vert[idx], p.slaves[idx]])
        R = np.zeros((idx.size, 6))
        K = np.zeros((idx.size, 6, 6))
        for j, s in enumerate(idx):
            for e_j, l_j in _laws(float(eps_s[s]), float(lam_s[s]), float(g[s]), bool(pull[s])):
                Rj, Kj = np.zeros(6), np.zeros((6, 6))
                t.gap[s] = vertex_core(np.ascontiguousarray(xe[vert[s]]), np.ascontiguousarray(xs[s]),
                                       float(sign[s]), e_j, l_j, Rj, Kj)
                R[j] += Rj
                K[j] += Kj
            if friction:
                Rf, Kf = _vertex_friction(p, c, s, int(seg[s]), float(xi[s]), int(vert[s]), float(sign[s]),
                                          float(eps_s[s]), float(lam_s[s]), bool(pull[s]), xe, x_commit, t)
                R[j] += Rf
                K[j] += Kf
        t.force[idx] = -R[:, -3:]
        manager._add(ev.blocks, conn, R, K if want_K else None, xe)
        if want_parts:
            ev.parts[0].add(conn, np.zeros_like(R), K)


def _laws(eps: float, lam: float, g: float, pull: bool) -> tuple:
    """The linear laws (eps', lam') the kernels evaluate for one slave: its own, or where a curve pulls (lam + eps g >
    0: a tension at a clearance, where the kernels, written for a pushing law, act not at all) two pushing laws with
    the same g whose sum is it, (2 eps, -2 eps g - c) and (-eps, lam + 2 eps g + c) with c = eps |g| + |lam| > 0
    (the kernels' residual and every tangent part are linear in (eps', lam'))."""
    if not pull:
        return ((eps, lam),)
    c = eps * abs(g) + abs(lam) + 1e-300
    return ((2.0 * eps, -2.0 * eps * g - c), (-eps, lam + 2.0 * eps * g + c))


#: frictional passes: how far outside its segment of the last Newton iterate (in xi) a slave keeps it (a slave
#: resting on the node between two segments would otherwise cycle between them, its history moving each time)
KEEP_BAND = 0.02


def _vertex_friction(p, c, s: int, segment: int, xi: float, v: int, sign: float, eps: float, lam: float, pull: bool,
                     xe, x_commit, t):
    """The friction part (R, K on (vertex, slave)) of slave ``s`` at vertex node ``v`` (:func:`.planar_friction.
    vertex_friction`): its committed traction vector (from its history on whichever segment it was), its displacement
    relative to the vertex since the last commit; writes the history to commit (on the vertex's ``segment`` at its end
    ``xi``) and the friction state into ``t``."""
    from .planar_friction import NEW, traction_vector, vertex_friction, vertex_history

    t.hist_facet[s] = segment
    if pull or x_commit is None:  # (a pull carries no friction; no commit yet: frictionless, as a segment's NEW)
        t.hist[s] = 0.0
        t.status[s] = 0 if pull else NEW
        return np.zeros(6), np.zeros((6, 6))
    slave = p.slaves[s]
    du = (xe[slave] - x_commit[slave]) - (xe[v] - x_commit[v])
    R, K, T, tau, t.status[s] = vertex_friction(xe[v], xe[slave], du, traction_vector(c.hist[s]), sign, eps,
                                                float(p.eps_t[s]), float(p.mu), lam)
    t.hist[s] = vertex_history(np.ascontiguousarray(xe[p.curve.segments[segment]]), xi, T * tau)
    return R, K



def _segment_history(p, c, s: int, segment: int, xi: float, x_commit) -> np.ndarray:
    """The committed friction history of slave ``s`` on ``segment``: moved there from its committed segment
    (:func:`.planar_friction.transfer_history`), or started at its projection in the committed configuration for a
    slave new to contact (:func:`.planar_friction.start_history`); none (frictionless: NEW) without a committed
    configuration."""
    from .planar_friction import start_history, transfer_history

    hist = c.hist[s]
    if x_commit is None:
        return hist.copy() if hist[-1] > 0.0 and c.hist_facet[s] == segment else np.zeros_like(hist)
    xseg = np.ascontiguousarray(x_commit[p.curve.segments[segment]])
    eps_t = float(p.eps_t[s])
    if hist[-1] == 0.0:
        return start_history(xseg, x_commit[p.slaves[s]], xi, eps_t)
    if c.hist_facet[s] == segment:
        return hist.copy()
    try:
        return transfer_history(hist, xseg, xi, eps_t)
    except ValueError:
        return np.zeros_like(hist)


__all__ = ["CASE_A", "CASE_B", "CASE_C", "CASE_D", "CASE_EXACT", "Curve", "closest_points", "project_on_segment",
           "segment_core", "segment_pass", "slave_weights", "vertex_core", "check_pair", "make_pass", "tie"]
