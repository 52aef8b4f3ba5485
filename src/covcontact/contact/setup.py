"""Contact passes of a problem: node numbering, penalties and the static data of each pass.

Node numbering: the deformable nodes 0..N-1 of the global system come first, then the nodes of rigid meshed
bodies (no unknowns; positions from their prescribed motion). A master facet or slave node of a rigid body
contributes to the residual and tangent only through the deformable dofs of its pair.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..mesh.faces import all_boundary_faces
from . import planar
from .analytic import Cylinder, Plane, Sphere
from .element import CASES
from .facets import patch_count, quad_patches
from .points import VirtualPoints, gauss_points
from .selfcontact import excluded_facets
from .surface import MeshSurface, facet_sizes, slave_area
from .laws import PressureLaw
from .tied import tie
from .tool_profile import Profile


@dataclass
class Pass:
    """One slave set against one master surface (a pair, or one direction of a two-pass pair).

    The slaves are nodes (node-to-surface) or the Gauss points of the slave facets (segment-to-surface: ids after
    the extended nodes, :mod:`.points`). Static data only; what changes during a run lives in
    :class:`covcontact.contact.state.PassState`. The per-slave arrays are cut together by :meth:`subset`.
    """

    name: str
    slaves: np.ndarray                 # node ids in the extended numbering
    eps: np.ndarray                    # (ns,) weighted penalty per slave
    area: np.ndarray                   # (ns,) tributary area per slave (for the pressure output)
    eps_t: np.ndarray                  # (ns,) tangential penalty per slave
    case: int = 0                      # tangent case code (element.CASES)
    surface: MeshSurface | None = None
    analytic: object = None
    mu: float = 0.0                    # Coulomb coefficient (0: frictionless)
    augmented: bool = False            # augmented Lagrangian (Uzawa) instead of pure penalty
    gap_tol: float = 0.0               # largest accepted penetration of the augmented method
    max_aug: int = 20
    band: float = 0.0                  # normal law: 0 penalty, > 0 penalty smoothed over band, -c0 exponential
    global_index: np.ndarray | None = None  # distributed runs: positions of these slaves in the whole pass
    pair: str = ""                     # the contact pair this pass belongs to
    rigid: str = ""                    # the rigid body of an analytic master surface
    slave_body: str = ""               # the body that carries the slave nodes
    master_body: str = ""              # the body of the master surface
    kind: str = "nts"                  # "nts" (slave nodes) or "sts" (Gauss points of the slave facets)
    slave_faces: np.ndarray | None = None  # the slave face set (extended node ids), for the pressure output
    tie_facet: np.ndarray | None = None    # law "tied": (ns,) the master facet of each slave, -1 not tied
    tie_N: np.ndarray | None = None        # law "tied": (ns, nen) master shape values at the tie point
    exclude: np.ndarray | None = None      # self-contact: (ns, k) facets each slave never touches, -1 padded
    slave_facet: np.ndarray | None = None  # sts: (ns,) each point's facet in slave_faces
    own_patch: np.ndarray | None = None    # sts self-contact: (ns,) each point's patch quadrilateral in surface
    law: object = None                     # a laws.PressureLaw evaluated in the Python layer (None: band's law)
    curve: object = None                   # planar bodies: the master curve of node-to-segment contact (.planar)
    nodal: bool = False                    # sts: the law on the nodes' weighted gaps (.nodal_gap)

    @property
    def ns(self) -> int:
        return len(self.slaves)

    @property
    def tied(self) -> bool:
        return self.tie_facet is not None

    @property
    def self_contact(self) -> bool:
        return self.exclude is not None

    def subset(self, keep: np.ndarray) -> Pass:
        """The pass over slaves ``keep`` only (a rank's share of a distributed run)."""
        cut = {name: getattr(self, name)[keep] for name in ("slaves", "eps", "area", "eps_t", "tie_facet", "tie_N",
                                                            "exclude", "slave_facet", "own_patch") if getattr(self, name) is not None}
        return dataclasses.replace(self, global_index=keep, **cut)


def analytic_surface(rb):
    """The analytic surface of a rigid body with ``shape`` plane, cylinder, sphere or profile."""
    p = rb.params
    if rb.shape == "profile":
        return Profile(points=p["points"], fillets=p["fillets"], extrude=p["extrude"], revolve=p["revolve"],
                       motion=rb.motion)
    if rb.shape == "plane":
        return Plane(point=p["point"], normal=p["normal"], motion=rb.motion)
    if rb.shape == "cylinder":
        return Cylinder(center=p["center"], axis=p["axis"], radius=p["radius"], outside=p["outside"],
                        motion=rb.motion)
    return Sphere(center=p["center"], radius=p["radius"], outside=p["outside"], motion=rb.motion)


class Numbering:
    """Deformable nodes of the system first, then the nodes of the rigid meshed bodies."""

    def __init__(self, problem, system):
        self.problem = problem
        self.system = system
        self.N = system.n_nodes
        self.rigid_offset: dict[str, int] = {}
        self.rigid_meshes = []
        self.motions = {rb.name: rb.motion for rb in problem.rigid}  # a stage replaces them
        n = self.N
        for rb in problem.rigid:
            if rb.mesh is not None:
                self.rigid_offset[rb.name] = n
                self.rigid_meshes.append(rb)
                n += rb.mesh.n_nodes
        self.n_ext = n
        self.X_rigid = (np.vstack([rb.mesh.points for rb in self.rigid_meshes]) if self.rigid_meshes
                        else np.zeros((0, 3)))
        self.points = VirtualPoints(n)  # segment-to-surface slave points, numbered after the extended nodes

    def mesh_of(self, body: str):
        for b in self.problem.bodies:
            if b.name == body:
                return b.mesh, self.system.offset(body)
        for rb in self.rigid_meshes:
            if rb.name == body:
                return rb.mesh, self.rigid_offset[body]
        return None, None

    def reference(self) -> np.ndarray:
        return np.vstack([self.system.X, self.X_rigid])

    def motion(self, name: str):
        """The motion of rigid body ``name`` in the current stage."""
        return self.motions[name]

    def rigid_positions(self, lam: float) -> np.ndarray:
        parts = [self.motions[rb.name].apply(rb.mesh.points, lam) for rb in self.rigid_meshes]
        return np.vstack(parts) if parts else np.zeros((0, 3))

    def material_E(self, body: str) -> float | None:
        for b in self.problem.bodies:
            if b.name == body:
                return float(b.material.params[0])
        return None


def _shortest_edges(X, faces: np.ndarray) -> np.ndarray:
    """Per facet, its shortest corner-to-corner edge."""
    nc = 3 if faces.shape[1] in (3, 6) else 4
    c = X[faces[:, :nc]]
    return np.linalg.norm(c - np.roll(c, -1, axis=1), axis=2).min(axis=1)


def _auto_penalty(num: Numbering, pair, slave, master) -> float:
    """eps_N per unit area: auto_factor * E / h of the master body (the slave body's if rigid). A tied pair takes the
    stiffer of its bodies and h the smaller of its surfaces' mean shortest facet edges: a tie is a constraint
    (CalculiX writes equations), and across a thin layer (a shell's edge face, whose short side is the thickness)
    the mean facet size would leave it soft in bending."""
    X = num.reference()
    if pair.law == "tied":
        found = []
        for body, sset in (master, slave):
            E = num.material_E(body)
            mesh, off = num.mesh_of(body)
            if mesh is not None and sset in mesh.face_sets and len(mesh.face_sets[sset]):
                found.append((E, float(np.mean(_shortest_edges(X, mesh.face_sets[sset] + off)))))
        moduli = [E for E, _ in found if E is not None]
        if moduli:
            return pair.penalty_factor() * max(moduli) / min(h for _, h in found)
    for body, sset in (master, slave):
        E = num.material_E(body)
        mesh, off = num.mesh_of(body)
        if E is None or mesh is None or sset not in mesh.face_sets:
            continue
        h = float(np.mean(facet_sizes(X, mesh.face_sets[sset] + off))) / np.sqrt(2.0)
        return pair.penalty_factor() * E / h
    raise ValueError(f"contact {pair.name}: penalty = \"auto\" needs a deformable body with a face set "
                     f"named like its contact set")


def _slaves(num: Numbering, pair, faces: np.ndarray | None, nodes: np.ndarray | None, X) -> tuple:
    """(slave ids, area per slave, each point's facet or None) of slave ``faces`` (extended ids, None for a node set)
    and ``nodes``: the nodes with their tributary areas (nts; ``slave_area``, positive on tri6 and quad8 faces too),
    or the faces' Gauss points with their weights (sts)."""
    if pair.type == "sts":
        conn, N, weight, facet = gauss_points(X, faces, pair.order)
        return num.points.add(conn, N), weight, facet
    area = slave_area(X, faces)[nodes] if faces is not None else np.ones(len(nodes))
    return nodes, area, None


def boundary_area(num: Numbering, body: str, nodes: np.ndarray) -> np.ndarray:
    """Per node of ``nodes`` (extended ids of ``body``), its area over all the boundary faces of its body around it
    (``slave_area`` of each face type): what CalculiX gives the nodes of a node surface (weighting "boundary")."""
    mesh, off = num.mesh_of(body)
    X = num.reference()
    area = np.zeros(len(X))
    for faces, _, _ in all_boundary_faces(mesh):
        area += slave_area(X, faces + off)
    return area[nodes]


def _pressure_law(pair) -> PressureLaw | None:
    """The pair's pressure-overclosure curve evaluated in the Python layer (CalculiX's laws), or None (the kernels'
    own: penalty, smoothed penalty, Abaqus' exponential)."""
    per_area = pair.weighting in ("area", "boundary") or pair.type == "sts" or pair.penalty == "auto"
    if pair.law == "arctan":
        return PressureLaw("arctan", per_area, slope=float(pair.penalty), tension=pair.tension, reach=pair.reach)
    if pair.law == "table":
        return PressureLaw("table", per_area, table=pair.table, reach=pair.reach)
    if pair.law == "exponential" and pair.form == "calculix":
        return PressureLaw("calculix_exponential", per_area, clearance=pair.clearance, pressure=pair.pressure)
    return None


def law_terms(pair, eps: np.ndarray, penalty: float) -> tuple[np.ndarray, np.ndarray, float, PressureLaw | None]:
    """(eps, eps_t, band, law) of a pass whose slaves have the normal stiffness ``eps`` (``penalty`` times each
    slave's weight): a pressure-overclosure curve evaluated in the Python layer (``law``) makes eps its reference
    stiffness per slave (the scale of the tangential penalty); Abaqus' exponential law is the kernels' own, eps the
    nodal force at zero gap and band = -c0; the tangential penalty ``eps_t`` is the pair's (per the same weight), or
    by default eps (p0 / c0 per weight for the exponential laws)."""
    law = _pressure_law(pair)
    if law is not None:
        w = eps / penalty
        penalty = law.stiffness
        eps = penalty * w
    ratio = (pair.tangential_penalty / penalty) if pair.tangential_penalty else 1.0
    band = float(pair.smoothing)
    if pair.law == "exponential" and law is None:
        band = -float(pair.clearance)
        if not pair.tangential_penalty:
            ratio = 1.0 / float(pair.clearance)  # the tangential stiffness p0 / c0 (per area)
    elif law is not None and law.kind == "calculix_exponential" and not pair.tangential_penalty:
        ratio = float(pair.pressure) / float(pair.clearance) / penalty  # p0 / c0 as for Abaqus' curve
    return eps, eps * ratio, band, law


def make_pass(num: Numbering, name: str, slave, master, pair, tangent: str | None, surfaces=None) -> Pass:
    """The pass of ``slave`` against ``master`` of ``pair``; ``tangent`` overrides the pair's case. ``surfaces``:
    the (body, face set) list of a self-contact, merged into one surface that is both slave and master."""
    if surfaces is None and planar.planar_body(num, slave[0]) is not None:  # contact in the plane (.planar)
        return planar.make_pass(num, name, slave, master, pair, tangent, Pass, analytic_surface, law_terms)
    if surfaces is not None and planar.planar_body(num, surfaces[0][0]) is not None:
        return planar.make_self_pass(num, name, pair, tangent, Pass, law_terms)
    X = num.reference()
    if surfaces is not None:
        slave_faces = np.vstack([num.mesh_of(b)[0].face_sets[f] + num.mesh_of(b)[1] for b, f in surfaces])
        nodes = np.unique(slave_faces)
    else:
        smesh, soff = num.mesh_of(slave[0])
        slave_faces = smesh.face_sets[slave[1]] + soff if slave[1] in smesh.face_sets else None
        nodes = smesh.node_sets[slave[1]] + soff if pair.type == "nts" else None
    slaves, area, own = _slaves(num, pair, slave_faces, nodes, X)
    if pair.weighting == "boundary":
        area = boundary_area(num, slave[0], slaves)
    penalty = _auto_penalty(num, pair, slave, master) if pair.penalty == "auto" else pair.penalty
    if pair.weighting == "boundary":
        keep = area > 0.0
        slaves, area = slaves[keep], area[keep]
        eps = penalty * area
    elif pair.weighting == "area" or pair.penalty == "auto" or pair.type == "sts":
        if slave_faces is None:
            raise ValueError(f"contact {pair.name}: area weighting needs a face set named {slave[1]!r}")
        if pair.type == "nts" and np.any(area <= 0.0):  # tri6 corner nodes (slave_area): no contact, as in CalculiX
            keep = area > 0.0
            slaves, area = slaves[keep], area[keep]
        eps = penalty * area
    else:
        eps = np.full(len(slaves), float(penalty))
    eps, eps_t, band, law = law_terms(pair, eps, penalty)
    kw = {"eps_t": eps_t, "case": CASES[tangent or pair.tangent], "mu": float(pair.friction or 0.0),
          "augmented": pair.method == "augmented", "max_aug": pair.max_augmentations, "pair": pair.name,
          "slave_body": slave[0] if surfaces is None else "", "master_body": master[0] if surfaces is None else "",
          "band": band, "kind": pair.type, "slave_faces": slave_faces, "slave_facet": own, "law": law,
          "nodal": pair.gap == "nodal"}
    if surfaces is not None:
        quads, _ = quad_patches(slave_faces, num.points)  # tri3, tri6, quad8 facets as quadrilaterals
        surface = MeshSurface(quads, n_nodes=num.n_ext + num.points.count)
        h = float(np.mean(facet_sizes(X, slave_faces))) / np.sqrt(2.0)
        exclude = excluded_facets(slave_faces, num.n_ext, slave_nodes=None if own is not None else slaves,
                                  slave_facets=own)
        nsub = patch_count(slave_faces.shape[1])  # a facet excluded: all its patch quadrilaterals
        exclude = np.where(exclude[:, :, None] >= 0, exclude[:, :, None] * nsub + np.arange(nsub),
                           -1).reshape(len(exclude), -1)
        p = Pass(name, slaves, eps, area, surface=surface, exclude=exclude, **kw)
        if own is not None:  # each point's own patch quadrilateral (its normal is the point's own)
            per = len(own) // max(len(slave_faces), 1)
            p.own_patch = own * nsub + np.arange(len(own)) % per // (per // nsub)
    else:
        mmesh, moff = num.mesh_of(master[0])
        if mmesh is None:
            rb = next(r for r in num.problem.rigid if r.name == master[0])
            h = float(np.mean(facet_sizes(X, slave_faces))) if slave_faces is not None else 1.0
            p = Pass(name, slaves, eps, area, analytic=analytic_surface(rb), rigid=rb.name, **kw)
        else:
            faces = mmesh.face_sets[master[1]] + moff
            h = float(np.mean(facet_sizes(X, faces))) / np.sqrt(2.0)
            quads, _ = quad_patches(faces, num.points)  # tri3, tri6, quad8 facets as quadrilaterals
            p = Pass(name, slaves, eps, area, surface=MeshSurface(quads, n_nodes=num.n_ext + num.points.count), **kw)
    if pair.law == "tied":
        Xe = np.vstack([X, num.points.positions(X)])
        xs = Xe[slaves] if pair.type == "sts" else X[slaves]
        p.tie_facet, p.tie_N = tie(Xe, p.surface, xs, pair.tie_tolerance)
        if not (p.tie_facet >= 0).any():
            raise ContactSetupError(f"contact {pair.name}: no slave point lies within the tie tolerance of the master "
                             f"surface; the surfaces do not meet: check the geometry or raise tie_tolerance")
    if p.augmented:
        p.gap_tol = pair.gap_tolerance if pair.gap_tolerance is not None else pair.gap_tolerance_relative * h
    return p


class ContactSetupError(ValueError):
    """A contact pair that cannot be set up as the input gives it (the model says it as an input error)."""


def make_passes(num: Numbering, problem, tangent: str | None = None) -> list[Pass]:
    """Every pass of the problem's contact pairs (two per two-pass pair, one per self-contact)."""
    out = []
    for pair in problem.contacts:
        if pair.self_surfaces:
            out.append(make_pass(num, pair.name, pair.slave, pair.master, pair, tangent,
                                 surfaces=pair.self_surfaces))
            continue
        out.append(make_pass(num, pair.name, pair.slave, pair.master, pair, tangent))
        if pair.two_pass:
            out.append(make_pass(num, pair.name + "/reverse", tuple(pair.master), tuple(pair.slave), pair,
                                 tangent))
    return out
