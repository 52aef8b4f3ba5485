"""A deck's *COUPLING (REF NODE=, SURFACE=, CONSTRAINT NAME=) with *KINEMATIC or *DISTRIBUTING, and the rotational
dofs 4-6 of reference nodes (docs/input.md, "Abaqus and CalculiX decks"; docs/theory.md, "Multi-point constraints").

*KINEMATIC holds the surface's nodes to the reference node's rigid motion: a ``[[rigid]]`` body with those nodes
attached (``covcontact.io.deck_rigid``), its reference point the REF NODE, whose dofs 1-3 are the body's translation
and 4-6 its rotation vector (CalculiX's coupling reference node; a *RIGID BODY's REF NODE reads dofs 4-6 so too, as
Abaqus does). Dofs 1-3 named on the *KINEMATIC lines are the components of the nodes that follow the body: all three
make a rigid attachment, some of them the nonlinear equations u_ik = [t + (R(theta) - I) Y_i]_k of those components
alone (``attach_components``), as CalculiX writes them; dofs 4-6 there (the rotations of coupling nodes that have
them) mean nothing for solid nodes.

*DISTRIBUTING is what CalculiX makes of it (couplings.f, cloaddistributing.f): no constraint, a load distribution.
The surface's nodes get the weights w_i = (int N_i dA) / A over its faces (CalculiX's Gauss rules per element type),
centre c = sum w_i X_i, arms r_i = X_i - c, and a force F and moment M at the REF NODE (position p) become the
nodal forces

    F_i = w_i F + w_i (J^-1 (M + (p - c) x F)) x r_i,     J = sum_i w_i (|r_i|^2 I - r_i r_i^T),

(CalculiX's principal-axis form of the same), which sum to F and whose moment about p is M. They are dead loads at
fixed nodes (a ``[[force]]`` per node), the moments only on the dofs 4-6 the *DISTRIBUTING lines name (the forces
always). The REF NODE carries no unknowns: a *BOUNDARY on it is refused (CalculiX ignores it; Abaqus' interpolation
constraint is not implemented). A step's first *CLOAD on the REF NODE replaces the distributed loads of earlier
steps (CalculiX: OP=NEW in effect for them).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..fem.planar_cells import EDGES
from .deck import Card, DeckError
from .deck_loads import Boundary, Load

#: the cards this module reads (deck_model dispatches them here)
COUPLING_CARDS = ("COUPLING", "KINEMATIC", "DISTRIBUTING")

#: the nodes (0-based, in the element's node order) of face Sn of each element type, CalculiX's tables (ifaceq,
#: ifacet, ifacew1): corners first, then the mid-side nodes of the edges between consecutive corners
_HEX20 = {1: (3, 2, 1, 0, 10, 9, 8, 11), 2: (4, 5, 6, 7, 12, 13, 14, 15), 3: (0, 1, 5, 4, 8, 17, 12, 16),
          4: (1, 2, 6, 5, 9, 18, 13, 17), 5: (2, 3, 7, 6, 10, 19, 14, 18), 6: (3, 0, 4, 7, 11, 16, 15, 19)}
_TET10 = {1: (0, 2, 1, 6, 5, 4), 2: (0, 1, 3, 4, 8, 7), 3: (1, 2, 3, 5, 9, 8), 4: (0, 3, 2, 7, 9, 6)}
_WEDGE6 = {1: (0, 2, 1), 2: (3, 4, 5), 3: (0, 1, 4, 3), 4: (1, 2, 5, 4), 5: (2, 0, 3, 5)}
FACE_NODES = {
    "hex8": {k: v[:4] for k, v in _HEX20.items()}, "hex20": _HEX20,
    "tet4": {k: v[:3] for k, v in _TET10.items()}, "tet10": _TET10, "wedge6": _WEDGE6,
}
#: the faces S1..Sn of planar elements: their edges, from corner k to corner k + 1 (then the edge's mid-node)
EDGE_NODES = {cell: {k + 1: tuple(int(i) for i in e) for k, e in enumerate(edges)} for cell, edges in EDGES.items()}

_G2 = 1.0 / np.sqrt(3.0)
_G3 = np.sqrt(0.6)
#: CalculiX's surface rules (gauss.f): points (xi, eta) and weights
_RULES = {
    "quad1": (np.array([[0.0, 0.0]]), np.array([4.0])),
    "quad2": (np.array([[-_G2, -_G2], [_G2, -_G2], [-_G2, _G2], [_G2, _G2]]), np.ones(4)),
    "quad3": (np.array([[a, b] for b in (-_G3, 0.0, _G3) for a in (-_G3, 0.0, _G3)]),
              np.array([wa * wb for wb in (5 / 9, 8 / 9, 5 / 9) for wa in (5 / 9, 8 / 9, 5 / 9)])),
    "tri1": (np.array([[1 / 3, 1 / 3]]), np.array([0.5])),
    "tri3": (np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]]), np.full(3, 1 / 6)),
}
#: the rule CalculiX integrates a face of each deck element type with (couplings.f: mint), per face node count
_RULE = {"C3D8": "quad2", "C3D8I": "quad2", "C3D8R": "quad1", "C3D20R": "quad2", "C3D20": "quad3", "C3D10": "tri3",
         "C3D4": "tri1", "C3D6": {3: "tri1", 4: "quad1"}}
_RULE.update({f"{t}H": _RULE[t] for t in ("C3D8", "C3D8R", "C3D20", "C3D20R", "C3D10", "C3D4", "C3D6")})


def _shape(n: int, xi: float, eta: float) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions (n,) and their derivatives (2, n) of a face of n nodes (quad4, quad8, tri3, tri6)."""
    if n in (4, 8):
        c = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
        if n == 4:
            N = 0.25 * (1 + c[:, 0] * xi) * (1 + c[:, 1] * eta)
            dN = 0.25 * np.array([c[:, 0] * (1 + c[:, 1] * eta), c[:, 1] * (1 + c[:, 0] * xi)])
            return N, dN
        a, b = c[:, 0], c[:, 1]
        Nc = 0.25 * (1 + a * xi) * (1 + b * eta) * (a * xi + b * eta - 1)
        dNc = 0.25 * np.array([a * (1 + b * eta) * (2 * a * xi + b * eta), b * (1 + a * xi) * (a * xi + 2 * b * eta)])
        Nm = np.array([0.5 * (1 - xi ** 2) * (1 - eta), 0.5 * (1 + xi) * (1 - eta ** 2),
                       0.5 * (1 - xi ** 2) * (1 + eta), 0.5 * (1 - xi) * (1 - eta ** 2)])
        dNm = np.array([[-xi * (1 - eta), 0.5 * (1 - eta ** 2), -xi * (1 + eta), -0.5 * (1 - eta ** 2)],
                        [-0.5 * (1 - xi ** 2), -eta * (1 + xi), 0.5 * (1 - xi ** 2), -eta * (1 - xi)]])
        return np.concatenate([Nc, Nm]), np.concatenate([dNc, dNm], axis=1)
    z = 1.0 - xi - eta
    if n == 3:
        return np.array([z, xi, eta]), np.array([[-1.0, 1.0, 0.0], [-1.0, 0.0, 1.0]])
    N = np.array([z * (2 * z - 1), xi * (2 * xi - 1), eta * (2 * eta - 1), 4 * xi * z, 4 * xi * eta, 4 * eta * z])
    dN = np.array([[1 - 4 * z, 4 * xi - 1, 0.0, 4 * (z - xi), 4 * eta, -4 * eta],
                   [1 - 4 * z, 0.0, 4 * eta - 1, -4 * xi, 4 * xi, 4 * (z - eta)]])
    return N, dN


@dataclass
class Coupling:
    """One *COUPLING with its *KINEMATIC or *DISTRIBUTING, in the deck's terms."""

    name: str                     # CONSTRAINT NAME
    ref: int                      # REF NODE label
    surface: str
    where: str
    kind: str = ""                # "kinematic" | "distributing" (empty until its card is read)
    dofs: tuple = ()              # the dofs of its lines (1..6)
    nodes: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))   # the surface's node labels
    faces: list = field(default_factory=list)    # (deck element type, node labels of the face) per face
    rigid: int = -1               # *KINEMATIC: its body in DeckModel.rigid_bodies
    kin_where: str = ""           # where its *KINEMATIC / *DISTRIBUTING card is


def read_coupling_card(reader, c: Card, following: Card | None) -> None:
    """*COUPLING (``following``: the card after it, which must be *KINEMATIC or *DISTRIBUTING), *KINEMATIC,
    *DISTRIBUTING: model data of ``reader`` (``covcontact.io.deck_model``), kept in its model's ``couplings``."""
    m = reader.m
    if c.name == "COUPLING":
        if reader.step is not None:
            raise c.fail("*COUPLING is model data: it belongs before the first *STEP")
        for p, v in c.params.items():
            if p not in ("REF NODE", "REFNODE", "SURFACE", "CONSTRAINT NAME", "CONSTRAINTNAME"):
                m.unsupported.append(f"{c.where()}: *COUPLING, {p}{'=' + v if v else ''} is not supported"
                                     + (" (the dofs in the global axes only)" if p == "ORIENTATION" else ""))
        ref = c.param("REF NODE", c.param("REFNODE"))
        if ref is None:
            raise c.fail("missing parameter REF NODE= (the reference node: a label or a node set of one node)")
        name = c.param("CONSTRAINT NAME", c.param("CONSTRAINTNAME"))
        if name is None:
            raise c.fail("missing parameter CONSTRAINT NAME= (e.g. *COUPLING, REF NODE=..., SURFACE=..., CONSTRAINT "
                         "NAME=C1)")
        if ref.strip().isdigit():
            label = int(ref)
        else:
            nodes = m.nsets.get(ref.upper())
            if nodes is None:
                raise c.fail(f"REF NODE={ref}: neither a node label nor a *NSET defined above")
            if nodes.size != 1:
                raise c.fail(f"REF NODE={ref}: the node set holds {nodes.size} nodes; the reference node is one")
            label = int(nodes[0])
        surface = c.param("SURFACE", required=True).upper()
        if surface not in m.surfaces:
            raise c.fail(f"SURFACE={c.params['SURFACE']}: no *SURFACE of that name above (defined: "
                         f"{', '.join(sorted(m.surfaces)) or 'none'})")
        if following is None or following.name not in ("KINEMATIC", "DISTRIBUTING"):
            raise c.fail("must be followed by *KINEMATIC or *DISTRIBUTING")
        cp = Coupling(name.upper(), label, surface, c.where())
        kind, refs = m.surfaces[surface]
        if kind == "NODE":
            cp.nodes = np.unique(refs)
        else:
            cp.faces = _faces(m, refs, surface, f", the surface of *COUPLING {name.upper()} at {c.where()}")
            cp.nodes = np.unique(np.concatenate([f for _, f in cp.faces]))
        _couplings(m).append(cp)
        return
    pending = _couplings(m)[-1] if _couplings(m) and not _couplings(m)[-1].kind else None
    if pending is None:
        raise c.fail(f"*{c.name} belongs right after a *COUPLING card")
    pending.kind, pending.kin_where = c.name.lower(), c.where()
    for p, v in c.params.items():
        m.unsupported.append(f"{c.where()}: *{c.name}, {p}{'=' + v if v else ''} is not supported")
    dofs = []
    for k, row in enumerate(c.rows()):
        first = c.number(k, 0, row, "the first dof")
        last = c.number(k, 1, row, "the last dof", first)
        if first != int(first) or last != int(last) or not 1 <= first <= last <= 6:
            raise c.fail(f"dofs are 'first dof[, last dof]' within 1..6, first <= last; got {', '.join(row)}", k)
        dofs += range(int(first), int(last) + 1)
    if c.name == "DISTRIBUTING":
        if not pending.faces:
            raise c.fail(f"the surface {pending.surface} of the *COUPLING is a node surface: *DISTRIBUTING needs an "
                         f"element (face) surface")
        planar = sorted({etype for etype, _ in pending.faces if etype[:3] in ("CPE", "CPS", "CAX")})
        if planar:
            raise c.fail(f"*DISTRIBUTING on the edges of planar elements ({', '.join(planar)}) is not supported "
                         f"(*KINEMATIC is)")
        pending.dofs = tuple(sorted(set(dofs)))
        return
    if not dofs:  # (Abaqus: all dofs; CalculiX couples none)
        dofs = [1, 2, 3]
        m.notes.append(f"{c.where()}: *KINEMATIC without dof lines: all of its nodes' dofs are coupled (as Abaqus "
                       f"reads it)")
    pending.dofs = tuple(sorted(set(dofs)))
    comps = [d for d in pending.dofs if d <= 3]
    if not comps:
        raise c.fail("dofs 4-6 alone couple nothing on solid nodes (they have no rotations); name some of 1-3")
    if len(comps) < len(pending.dofs):
        m.notes.append(f"{c.where()}: *KINEMATIC dofs 4-6 couple the nodes' rotations, which solid nodes do not "
                       f"have: only dofs {', '.join(map(str, comps))} are coupled")
    for other in _couplings(m)[:-1]:  # (several surfaces on one reference node: one rigid body)
        if other.kind == "kinematic" and other.ref == pending.ref:
            if [d for d in other.dofs if d <= 3] != comps:
                m.unsupported.append(f"{c.where()}: two *KINEMATIC couplings on REF NODE {pending.ref} with different "
                                     f"dofs; with --ignore-unsupported the second is left out")
                return
            nodes, ref, rot, where = m.rigid_bodies[other.rigid]
            m.rigid_bodies[other.rigid] = (np.union1d(nodes, pending.nodes), ref, rot, where)
            pending.rigid = other.rigid
            return
    pending.rigid = len(m.rigid_bodies)
    m.rigid_bodies.append((pending.nodes, pending.ref, None, pending.where))


def _couplings(m) -> list:
    if not hasattr(m, "couplings"):
        m.couplings = []
    return m.couplings


def _faces(m, refs, surface: str = "", owner: str = "") -> list:
    """(deck element type, node labels of the face) of every face of an element surface's lines (``surface``: its
    name, ``owner``: ', the surface of ...' for the messages)."""
    out = []
    for els, face, where in refs:
        found = np.zeros(els.size, dtype=bool)
        for etype, cell, labels, conn in m.blocks:
            hit = np.isin(els, labels)
            if not hit.any():
                continue
            table = FACE_NODES.get(cell, EDGE_NODES.get(cell))  # (planar elements' faces are edges)
            if table is None:
                raise DeckError(f"{where}: *SURFACE{' ' + surface if surface else ''}: {etype} elements: a coupling "
                                f"on them is not supported{owner}")
            if face not in table:
                raise DeckError(f"{where}: S{face}: {cell} elements have the faces S1..S{len(table)}")
            rows = conn[np.isin(labels, els)]
            out += [(etype, row[list(table[face])]) for row in rows]
            found |= hit
        if not found.all():  # (a type not read: named with its *ELEMENT line, else not defined)
            bad = int(els[~found][0])
            what = m.skipped(bad)
            if what is None:
                raise DeckError(f"{where}: *SURFACE{' ' + surface if surface else ''}: element {bad} is not "
                                f"defined{owner}")
            from .deck_elements import ELEMENTS
            from .deck_planar import element_names
            raise DeckError(f"{where}: *SURFACE{' ' + surface if surface else ''}: element {bad} is {what}, a type "
                            f"covcontact does not read (it reads {element_names(ELEMENTS)}){owner}")
    return out


def weights(m, cp: Coupling) -> tuple[np.ndarray, np.ndarray]:
    """(node labels, weights w_i = int N_i dA / A) of a *DISTRIBUTING coupling's surface, as CalculiX computes them
    (its Gauss rule per element type; quadratic faces give their corners their own, possibly negative, share)."""
    index = m.node_index()
    area = np.zeros(cp.nodes.size)
    pos = {int(lab): k for k, lab in enumerate(cp.nodes)}
    for etype, nodes in cp.faces:
        rule = _RULE[etype]
        rule = rule[len(nodes)] if isinstance(rule, dict) else rule
        X = m.X[index[nodes]]
        for (xi, eta), wt in zip(*_RULES[rule]):
            N, dN = _shape(len(nodes), xi, eta)
            a, b = dN @ X
            dA = wt * np.linalg.norm(np.cross(a, b))
            for lab, n in zip(nodes, N):
                area[pos[int(lab)]] += dA * n
    return cp.nodes, area / area.sum()


def distribution(X: np.ndarray, w: np.ndarray, p: np.ndarray) -> np.ndarray:
    """C (n, 3, 6): the nodal forces F_i = C_i [F, M] of a force F and moment M at ``p`` over the nodes at ``X`` with
    the weights ``w`` (see the module)."""
    c = w @ X
    r = X - c
    J = (w * (r * r).sum(axis=1)).sum() * np.eye(3) - (w[:, None] * r).T @ r
    Jinv = np.linalg.inv(J)
    d = p - c
    skew = lambda v: np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])  # noqa: E731
    C = np.zeros((len(w), 3, 6))
    for i, (wi, ri) in enumerate(zip(w, r)):
        arm = -wi * skew(ri) @ Jinv             # (J^-1 m) x r_i w_i = arm @ m
        C[i, :, :3] = wi * np.eye(3) + arm @ skew(d)
        C[i, :, 3:] = arm
    return C


class DeckCouplings:
    """The couplings of a deck at import: the *DISTRIBUTING loads as per-node forces per covcontact stage, the
    reference nodes' dofs (rigid bodies' and couplings') in *BOUNDARY and *CLOAD. ``unsupported`` and ``notes`` are
    the importer's lists (appended to)."""

    def __init__(self, m, parts, rigid, unsupported: list, notes: list, dialect: str = "calculix"):
        self.m, self.b, self.rigid = m, parts, rigid
        self.unsupported, self.notes, self.dialect = unsupported, notes, dialect
        index = m.node_index()
        self.dist: list[Coupling] = []
        self.by_label: dict[int, int] = {}
        for cp in _couplings(m):
            if cp.kind != "distributing":
                continue
            if cp.ref >= index.size or index[cp.ref] < 0:
                raise DeckError(f"{cp.where}: REF NODE={cp.ref}: no *NODE defines node {cp.ref}")
            if cp.ref in rigid.by_label or cp.ref in self.by_label:
                self.unsupported.append(f"{cp.where}: REF NODE {cp.ref} of a *DISTRIBUTING coupling is the reference "
                                        f"node of another coupling or rigid body; with --ignore-unsupported this "
                                        f"coupling is left out")
                continue
            if dialect == "abaqus":  # (the same card, another meaning: listed, CalculiX's used with the flag)
                self.unsupported.append(f"{cp.where}: *DISTRIBUTING in an Abaqus deck: Abaqus' distributing coupling "
                                        f"is a constraint (the REF NODE follows the surface's weighted mean motion, "
                                        f"the forces the deformed surface); covcontact has CalculiX's reading, dead "
                                        f"nodal loads on the reference configuration: with --ignore-unsupported "
                                        f"those are used (the same for small rotations)")
            self.by_label[cp.ref] = len(self.dist)
            self.dist.append(cp)
        self.coef, self.labels = [], []
        for cp in self.dist:
            labels, w = weights(m, cp)
            self.labels.append(labels)
            C = distribution(m.X[index[labels]], w, m.X[index[cp.ref]])
            C[:, :, [3 + d - 4 for d in (4, 5, 6) if d not in cp.dofs]] = 0.0  # (moments only on the dofs named)
            self.coef.append(C)
        self.stage_loads: list[dict] = []
        self._restate()
        kin = {int(cp.ref) for cp in _couplings(m) if cp.kind == "kinematic"}
        kin |= {lab for lab, _ in rigid.knots.values()}  # (a knot's dofs 4-6 are its rotation in CalculiX too)
        self.rigid_refs = {lab for lab, (_, off) in rigid.by_label.items() if off == 0 and lab not in kin}

    def _restate(self) -> None:
        """A step's first *CLOAD on a *DISTRIBUTING REF NODE (or a *CLOAD, OP=NEW) replaces the distributed loads of
        the steps before: the REF NODE's loads it does not restate go to zero (explicit zero loads)."""
        loaded: set[tuple[int, int]] = set()
        for s, step in enumerate(self.m.steps):
            mine = {(int(n), ld.dof) for ld in step.loads if ld.kind == "cload" for n in ld.nodes
                    if int(n) in self.by_label}
            touched = {n for n, _ in mine}
            if s > 0:
                for n, dof in sorted(loaded - mine):
                    if n in touched or "cload" in step.loads_new:
                        step.loads.append(Load("cload", str(n), dof, 0.0, step.where, nodes=np.array([n])))
            loaded |= mine

    # -- reference nodes in *BOUNDARY and *CLOAD ----------------------------------------------------------------
    def _rigid_component(self, r: int, off: int, lab: int, dof: int, where: str, what: str) -> int | None:
        """The rigid body's component (0..5) of ``dof`` on its REF (off 0) or ROT (off 3) node ``lab``; None (listed)
        for a dof that node does not have."""
        comp = off + dof - 1
        if comp > 5 or dof > 6:
            self.unsupported.append(f"{where}: {what} on dof {dof} of node {lab}, a rigid body's ROT NODE (its dofs "
                                    f"1-3 are the rotation vector)")
            return None
        if dof > 3 and lab in self.rigid_refs and self.dialect == "calculix":
            self.notes.append(f"{where}: {what} on dof {dof} of the *RIGID BODY's REF NODE {lab}: read as its "
                              f"rotation, as Abaqus reads it (CalculiX turns a rigid body through its ROT NODE and "
                              f"does not use the REF NODE's dofs 4-6)")
        return comp

    def _plain(self, labels: np.ndarray, dofs, where: str, what: str) -> None:
        """Dofs 4-6 on nodes that are no reference node: listed (solid nodes have dofs 1-3)."""
        bad = [d for d in dofs if d > 3]
        if bad and labels.size:
            self.unsupported.append(f"{where}: {what} on dof {bad[0]} of node {int(labels[0])}, which is no reference "
                                    f"node (solid nodes have the displacements 1..3)")

    def boundary_keys(self, b: Boundary) -> tuple[np.ndarray, list]:
        """(the labels of ``b`` that are no reference node, the ("rigid", body, component) keys of those that are);
        a *DISTRIBUTING REF NODE is refused (listed)."""
        labels, rigid = self.rigid.split(b.nodes)
        hit = np.isin(labels, list(self.by_label))
        if hit.any():
            self.unsupported.append(f"{b.where}: *BOUNDARY on the REF NODE {int(labels[hit][0])} of a *DISTRIBUTING "
                                    f"coupling (CalculiX ignores it, Abaqus prescribes the surface's mean motion: no "
                                    f"such constraint here); with --ignore-unsupported it is ignored, as CalculiX does")
            labels = labels[~hit]
        keys = []
        refs = b.nodes[np.isin(b.nodes, list(self.rigid.by_label))]
        for (r, off), lab in zip(rigid, refs):
            for d in b.dofs:
                comp = self._rigid_component(r, off, int(lab), d, b.where, "*BOUNDARY")
                if comp is not None:
                    keys.append(("rigid", r, comp))
        self._plain(labels, b.dofs, b.where, "*BOUNDARY")
        return labels, keys

    def load_keys(self, ld: Load) -> tuple[np.ndarray, list]:
        """(the labels of a *CLOAD that are no reference node, the keys of those that are: ("rforce", body,
        component) of rigid bodies, ("dforce", coupling, dof - 1) of *DISTRIBUTING couplings)."""
        labels, rigid = self.rigid.split(ld.nodes)
        keys = []
        refs = ld.nodes[np.isin(ld.nodes, list(self.rigid.by_label))]
        for (r, off), lab in zip(rigid, refs):
            comp = self._rigid_component(r, off, int(lab), ld.dof, ld.where, "*CLOAD")
            if comp is not None:
                keys.append(("rforce", r, comp))
        hit = np.isin(labels, list(self.by_label))
        for lab in labels[hit]:
            k = self.by_label[int(lab)]
            if ld.dof > 3 and ld.dof not in self.dist[k].dofs:
                self.unsupported.append(f"{ld.where}: *CLOAD on dof {ld.dof} of the REF NODE {int(lab)}: its "
                                        f"*DISTRIBUTING ({self.dist[k].kin_where}) does not name that dof, so the "
                                        f"moment is not distributed")
                continue
            if ld.dof > 6:
                continue
            keys.append(("dforce", k, ld.dof - 1))
        labels = labels[~hit]
        self._plain(labels, (ld.dof,), ld.where, "*CLOAD")
        return labels, keys

    # -- the distributed loads ----------------------------------------------------------------------------------------
    def stage(self, loads: dict) -> dict:
        """Record a stage's loads {(coupling, dof 0..5): value at its end}; the ``targets`` of the nodal forces that
        change over it (a stage after the first)."""
        self.stage_loads.append(loads)
        if len(self.stage_loads) == 1:
            return {}
        out = {}
        before, now = self._forces(self.stage_loads[-2]), self._forces(loads)
        for k, (f0, f1) in enumerate(zip(before, now)):
            for lab, a, b in zip(self.labels[k], f0, f1):
                if not np.array_equal(a, b):
                    out[self._name(k, lab)] = b.tolist()
        return out

    def _forces(self, loads: dict) -> list[np.ndarray]:
        out = []
        for k, C in enumerate(self.coef):
            v = np.array([loads.get((k, j), 0.0) for j in range(6)])
            out.append(C @ v)
        return out

    @staticmethod
    def _name(k: int, lab) -> str:
        return f"dc{k + 1}n{int(lab)}"

    def entries(self, node_sets: dict, ref) -> list[dict]:
        """The ``[[force]]`` tables of the couplings ever loaded (a node set of one node each, its force at the end of
        the first stage); ``node_sets`` receives the sets, ``ref(body, set)`` names them."""
        loaded = {k for loads in self.stage_loads for (k, _) in loads}
        first = self._forces(self.stage_loads[0] if self.stage_loads else {})
        out = []
        for k in sorted(loaded):
            bodies = self.b.nodes_body(self.labels[k])
            for lab, body, f in zip(self.labels[k], bodies, first[k]):
                if body < 0:
                    continue
                name = f"_N{int(lab)}"
                node_sets[name] = np.array([lab], dtype=np.int64)
                out.append({"name": self._name(k, lab), "set": ref(int(body), name), "value": f.tolist(),
                            "distribution": "per_node"})
        return out


from .deck_elements import safe_name  # noqa: E402  (the names of the sets it makes)


def coupling_names(m, names: list[str]) -> list[str]:
    """The rigid bodies' names with those of *KINEMATIC couplings after their CONSTRAINT NAME (unique)."""
    out, done = list(names), set()
    for cp in _couplings(m):
        if cp.kind == "kinematic" and cp.rigid >= 0 and cp.rigid not in done:  # (the first of those on one REF NODE)
            done.add(cp.rigid)
            name = safe_name(cp.name)
            taken = set(out) | {safe_name(s) for s, _, _ in m.sections}
            out[cp.rigid] = name if name not in taken else f"{name}_{cp.rigid + 1}"
    return out


def coupled_components(m) -> dict[int, list[int]]:
    """{rigid body: the components 0..2 its nodes follow} of the *KINEMATIC couplings that hold some of them only (on
    planar elements never z, which their bodies hold)."""
    out = {}
    planar = planar_couplings(m)
    for cp in _couplings(m):
        if cp.kind == "kinematic" and cp.rigid >= 0:
            comps = [d - 1 for d in cp.dofs if d <= 3 and not (d == 3 and cp.rigid in planar)]
            if len(comps) < 3:
                out[cp.rigid] = comps
    return out


def planar_couplings(m) -> set[int]:
    """The rigid bodies of *KINEMATIC couplings on the edges of planar elements (CPE, CPS, CAX): they move in the
    plane, so their translation along z and rotations about x and y are held."""
    return {cp.rigid for cp in _couplings(m) if cp.kind == "kinematic" and cp.rigid >= 0
            and any(etype[:3] in ("CPE", "CPS", "CAX") for etype, _ in cp.faces)}
