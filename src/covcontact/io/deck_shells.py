"""Shell elements of a deck made into solid-shells (docs/input.md, "Abaqus and CalculiX decks"; docs/theory.md,
section 25).

CalculiX expands every node of an S3, S4, S4R, S6, S8 or S8R element into nodes on the element's normal (a brick
through the thickness) and ties the expansion to the shell node it stands for; covcontact makes each connected part
of shell elements a body of solid-shells from its mid-surface (``covcontact.mesh.shell.extrude_surface``): a shell
node becomes a bottom and a top node on its director. What the deck says of a shell node is said of those two:

- the reader's part (:func:`read_shell_elements`, :func:`read_shell_card`, :func:`shell_surface_row`): the elements
  (S4, S4R -> quad4, S8, S8R -> quad8, S3 -> tri3, S6 -> tri6), *SHELL SECTION (ELSET, MATERIAL, OFFSET, the
  thickness on its data line), *NODAL THICKNESS, and the shell faces of *SURFACE (SPOS and SNEG, CalculiX's S2 and
  S1 on shells);
- the import's part (:class:`DeckShells`): the bodies, their surface mesh files and ``shell = { ... }`` tables,
  the node labels, the *BOUNDARY mapping of shell nodes (CalculiX's gen3dboun: a translation of a shell node
  prescribes the mean of its expanded nodes, a rotation the mean rotation of the line of them), *CLOAD split
  between the layers, pressures and edge loads on shells, and the contact surfaces of shell faces;
- knots: a node whose elements make several subsets (normals more than 20 degrees apart, another thickness) or
  that carries a moment or a non-zero rotation is expanded once per subset, and the expansions are attached to a
  rigid body whose reference is the node (``DeckShells.knots``, made *RIGID BODY entries that ``deck_rigid`` writes).
"""

from __future__ import annotations

import numpy as np

from .deck import Card, DeckError, numbers
from .deck_knots import forced_knots, knot_note, register_knot, split_part
from .deck_shell_conditions import ShellConditions

#: the shell elements read: deck type -> the surface cell type of its mid-surface
SHELL_ELEMENTS = {"S3": "tri3", "S4": "quad4", "S4R": "quad4", "S6": "tri6", "S8": "quad8", "S8R": "quad8"}
#: the element type written in a shell body's surface mesh file (what the mesh reader's meshio takes)
#: the surface file's element type of each cell type (a six-node triangle as STRI65, the name meshio reads)
SURFACE_TYPE = {"tri3": "S3", "quad4": "S4", "quad8": "S8R", "tri6": "STRI65"}
_NNODE = {"tri3": 3, "quad4": 4, "quad8": 8, "tri6": 6}
SHELL_CARDS = ("SHELL SECTION", "NODAL THICKNESS")
#: the shells refused, with why
REFUSED = {k: "covcontact reads S3, S4, S4R, S6, S8, S8R" for k in ("S9R5", "S4R5", "S8R5", "S3R", "STRI65")}


# -- reading ---------------------------------------------------------------------------------------------------------
def read_shell_elements(reader, c: Card, etype: str) -> None:
    """*ELEMENT, TYPE=S3 / S4 / S4R / S6 / S8 / S8R: a shell block (its labels and nodes)."""
    cell = SHELL_ELEMENTS[etype]
    n = _NNODE[cell]
    a = numbers(c, 1 + n, f"a {etype} element (label and {n} nodes)", integer=True)
    if a.dtype != np.int64:
        if np.any(a != np.round(a)):
            raise c.fail("element and node labels are whole numbers")
        a = a.astype(np.int64)
    m = reader.m
    m.shell_blocks.append((etype, cell, a[:, 0], a[:, 1:]))
    m.shell_where.append(c.where())
    if "ELSET" in c.params:
        reader._add(m.elsets, c.params["ELSET"], a[:, 0])


def refuse_shell_type(c: Card, etype: str) -> None:
    """A shell element covcontact does not make into solid-shells: one line."""
    if etype in REFUSED:
        raise c.fail(f"TYPE={etype} is not supported: {REFUSED[etype]}")


def _offset(c: Card) -> float:
    text = c.param("OFFSET")
    if text is None:
        return 0.0
    named = {"SPOS": 0.5, "SNEG": -0.5, "MIDDLE": 0.0}
    if text.upper() in named:
        return named[text.upper()]
    try:
        v = float(text)
    except ValueError:
        raise c.fail(f"OFFSET must be a number (or SPOS, SNEG), got {text!r}") from None
    if not -0.5 <= v <= 0.5:
        raise c.fail(f"OFFSET={text}: the reference surface lies outside the shell (|offset| > 0.5); covcontact's "
                     f"solid-shells take offsets in [-0.5, 0.5]")
    return v


def read_shell_card(reader, c: Card) -> None:
    """*SHELL SECTION (ELSET, MATERIAL, OFFSET; the thickness on the data line) and *NODAL THICKNESS (lines: node or
    node set, thickness)."""
    m = reader.m
    if c.name == "NODAL THICKNESS":
        for k, row in enumerate(c.rows()):
            if len(row) < 2:
                raise c.fail("a line is 'node or node set, thickness'", k)
            t = c.number(k, 1, row, "the thickness")
            if not t > 0.0:
                raise c.fail(f"the thickness must be positive, got {row[1]}", k)
            for lab in reader._resolve_nodes(c, k, row[0]):
                m.nodal_thickness[int(lab)] = (t, c.where(k))
        return
    for p in c.params:
        if p not in ("ELSET", "MATERIAL", "OFFSET", "NODAL THICKNESS"):
            raise c.fail(f"{p}{'=' + c.params[p] if c.params[p] else ''} is not supported (ELSET, MATERIAL, OFFSET, "
                         f"NODAL THICKNESS are read; composite and oriented sections are not)")
    elset = c.param("ELSET", required=True).upper()
    material = c.param("MATERIAL", required=True).upper()
    rows = c.rows()
    thickness = None
    if rows and rows[0] and rows[0][0] != "":
        thickness = c.number(0, 0, rows[0], "the thickness")
        if not thickness > 0.0:
            raise c.fail(f"the thickness must be positive, got {rows[0][0]}", 0)
        if len(rows[0]) > 1 and rows[0][1]:
            m.notes.append(f"{c.where(0)}: *SHELL SECTION: {rows[0][1]} integration points through the thickness: "
                           f"a solid-shell integrates through its thickness with its own rule")
    elif "NODAL THICKNESS" not in c.params:
        raise c.fail("needs the thickness on its data line (or NODAL THICKNESS with *NODAL THICKNESS cards)")
    m.shell_sections.append((elset, material, thickness, _offset(c), c.where()))


def shell_surface_row(reader, c: Card, k: int, row: list[str], name: str) -> bool:
    """Whether line ``k`` of an element *SURFACE names a shell face (SPOS, SNEG; S1 = SNEG and S2 = SPOS of shell
    elements, as CalculiX numbers them), which is then kept in ``shell_surfaces``; an edge (S3..S6) of a shell
    element is refused."""
    if len(row) < 2:
        return False
    face = row[1].upper()
    ref = row[0].upper()
    m = reader.m
    shells = _shell_labels(m)
    if face in ("SPOS", "SNEG"):
        els = np.array([int(ref)]) if ref.isdigit() else m.element_set(ref)
        if els is None:
            raise c.fail(f"{row[0]!r} is neither an element label nor an *ELSET defined above", k)
        solid = [int(e) for e in els if int(e) not in shells]
        if solid and all(int(e) in m.skipped_elements for e in solid):  # (elements of a type not read: listed)
            m.unsupported.append(f"{c.where(k)}: *SURFACE {name}: {face} on element {solid[0]}, "
                                 f"{m.skipped(solid[0])}, a type covcontact does not read")
            return True
        if solid:
            raise c.fail(f"{face} is a face of shell elements; element {solid[0]} is no shell element", k)
        m.shell_surfaces.setdefault(name, []).append((np.asarray(els, dtype=np.int64), face, c.where(k)))
        return True
    if not (face.startswith("S") and face[1:].isdigit()):
        return False
    els = np.array([int(ref)]) if ref.isdigit() else m.element_set(ref)
    if els is None or not shells or not any(int(e) in shells for e in els):
        return False
    if any(int(e) not in shells for e in els):
        raise c.fail(f"{face} names shell and solid elements at once ({row[0]}): give them on separate lines", k)
    if face in ("S3", "S4", "S5", "S6"):  # (an edge: the solid-shell's lateral face along it, of 4-node shells)
        types = {t for t, _, labs, _ in m.shell_blocks if np.intersect1d(labs, np.asarray(els, dtype=np.int64)).size}
        other = sorted(types - {"S4", "S4R", "S8", "S8R"})
        if other:
            raise c.fail(f"{face} of an {other[0]} element is an edge: covcontact reads the edges of S4, S4R, S8 "
                         f"and S8R elements (their solid-shells' side faces), not of {other[0]}", k)
        m.shell_surfaces.setdefault(name, []).append((np.asarray(els, dtype=np.int64), f"EDGE{int(face[1:]) - 2}",
                                                      c.where(k)))
        return True
    if face not in ("S1", "S2"):
        raise c.fail(f"{face} is no face of a shell element (S1 and S2 its negative and positive faces, S3..S6 its "
                     f"edges)", k)
    m.shell_surfaces.setdefault(name, []).append((np.asarray(els, dtype=np.int64), "SNEG" if face == "S1" else "SPOS",
                                                  c.where(k)))
    return True


def _shell_labels(m) -> set:
    key = sum(len(b[2]) for b in m.shell_blocks)
    if getattr(m, "_shell_cache", (None,))[0] != key:
        m._shell_cache = (key, {int(e) for _, _, labels, _ in m.shell_blocks for e in labels})
    return m._shell_cache[1]


# -- importing -------------------------------------------------------------------------------------------------------
class DeckShells(ShellConditions):
    """The shell bodies of a deck: each connected part of its shell elements (elements joined through shared nodes),
    numbered after the solid bodies (``first``). A shell node is the bottom node i and the top node i + n of its
    body's solid-shell mesh (i its place among the part's node labels in increasing order)."""

    def __init__(self, m, parts, dialect: str = "calculix"):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        from ..mesh.shell import ShellMeshError, extrude_surface

        self.m, self.parts, self.first, self.dialect = m, parts, parts.n, dialect
        self.notes: list[str] = []
        self.unsupported: list[str] = []
        self.bodies: list[dict] = []
        self.label_body = np.full(int(m.node_labels.max()) + 1 if m.node_labels.size else 1, -1, dtype=np.int64)
        self.label_index = np.full(self.label_body.size, -1, dtype=np.int64)
        self.el_body: dict[int, int] = {}
        self.plan: dict[int, tuple] = {}
        self._drilled: set = set()
        self._unused: set = set()
        self.equation_nodes: dict[int, set] = {}
        self._thickness: dict[int, float | None] = {}
        self.shared: set[int] = set()
        #: (shell node label, component) -> the right-hand side 2 v of its mean's equation at the first stage's end
        self.sum_values: dict[tuple, float] = {}
        #: knots (covcontact.io.deck_rigid): rigid body (its place in m.rigid_bodies) -> (the shell node's label, the
        #: drilling component 0..2 held where the expansions lie on one line along a global axis, else None)
        self.knots: dict[int, tuple[int, int | None]] = {}
        #: the labels the knots' expansions get (after the deck's largest node label)
        self._next = int(m.node_labels.max()) + 1 if m.node_labels.size else 1
        if not m.shell_blocks:
            self.n = 0
            return
        index = m.node_index()
        labels = np.concatenate([b[2] for b in m.shell_blocks])
        types = np.concatenate([np.full(len(b[2]), b[1], dtype=object) for b in m.shell_blocks])
        where = np.concatenate([np.full(len(b[2]), w, dtype=object) for b, w in zip(m.shell_blocks, m.shell_where)])
        conn = [b[3] for b in m.shell_blocks]
        for (_, _, labs, c), w in zip(m.shell_blocks, m.shell_where):
            lab = c.ravel()
            bad = (lab < 0) | (lab >= index.size)
            bad[~bad] = index[lab[~bad]] < 0
            if bad.any():
                e = int(labs[np.flatnonzero(bad.reshape(c.shape).any(axis=1))[0]])
                raise DeckError(f"{w}: *ELEMENT: element {e} refers to node {int(lab[bad][0])}, which no *NODE "
                                f"defines")
        both = np.intersect1d(labels, parts.el_labels)
        if both.size or np.unique(labels).size != labels.size:
            dup = int(both[0]) if both.size else int(np.sort(labels)[1:][np.diff(np.sort(labels)) == 0][0])
            raise DeckError(f"*ELEMENT: element {dup} is defined twice (element labels are unique in a deck)")
        ne = labels.size
        rows = np.concatenate([np.repeat(np.arange(len(c)) + off, c.shape[1]) for c, off in
                               zip(conn, np.cumsum([0] + [len(c) for c in conn])[:-1])])
        cols = np.concatenate([index[c.ravel()] for c in conn])
        nn = m.node_labels.size
        # (shell nodes that solid elements share: CalculiX's hinge, the mean of the node's expansion following the
        # solid's node, its rotation free: equations, ``hinges``)
        self.shared = {int(v) for v in m.node_labels[np.unique(cols[parts.of_node[cols] >= 0])]}
        g = coo_matrix((np.ones(rows.size), (rows, ne + cols)), shape=(ne + nn, ne + nn))
        _, comp = connected_components(g, directed=False)
        kinds = np.unique(comp[:ne])
        of_element = np.searchsorted(kinds, comp[:ne])
        self.n = kinds.size
        sections = self._sections(labels)
        self._thickness = {e: sec[2] for e, sec in sections.items()}  # (element label -> its section's thickness)
        forced = forced_knots(m, np.unique(np.concatenate([c.ravel() for c in conn])))
        conn_rows = [row for c in conn for row in c]
        for j in range(self.n):
            mine = np.flatnonzero(of_element == j)
            cell_types = sorted(set(types[mine]))
            if len(cell_types) > 1:
                a = int(labels[mine][types[mine] == cell_types[0]][0])
                b = int(labels[mine][types[mine] == cell_types[1]][0])
                raise DeckError(f"{where[mine[0]]}: shell elements {a} ({cell_types[0]}) and {b} ({cell_types[1]}) "
                                f"meet in one part: a shell body's mid-surface is of one cell type here (S3, S4/S4R, S6 or "
                                f"S8/S8R); mesh the part with one of them")
            cell = cell_types[0]
            cmat = np.vstack([conn_rows[e] for e in mine])
            nodes = np.unique(cmat)
            cells = np.searchsorted(nodes, cmat)
            oc = np.repeat([[sections[int(labels[e])][3]] for e in mine], cells.shape[1], axis=1)  # (its OFFSET)
            tc = np.zeros(cells.shape)  # (the thickness of each element at each of its nodes)
            for r, (e, row) in enumerate(zip(mine, cells)):
                sec = sections[int(labels[e])]
                for q, i in enumerate(row):
                    lab = int(nodes[i])
                    if sec[2] is None:  # (NODAL THICKNESS on the section: the nodes' own, as CalculiX and Abaqus)
                        if lab not in m.nodal_thickness:
                            raise DeckError(f"{sec[4]}: *SHELL SECTION, NODAL THICKNESS: node {lab} of element "
                                            f"{int(labels[e])} has no *NODAL THICKNESS")
                        tc[r, q] = m.nodal_thickness[lab][0]
                        continue
                    if lab in m.nodal_thickness and sec[4] not in self._unused:
                        self._unused.add(sec[4])
                        self.notes.append(f"{m.nodal_thickness[lab][1]}: *NODAL THICKNESS of node {lab}: its "
                                          f"elements' *SHELL SECTION ({sec[4]}) has no NODAL THICKNESS parameter, so "
                                          f"its thickness {sec[2]:g} holds (as in CalculiX and Abaqus)")
                    tc[r, q] = sec[2]
            points = m.X[index[nodes]]
            nodes, cells, points, t, o, knots_here = split_part(self, nodes, cells, points, tc, oc, cell, labels[mine],
                                                                forced)
            offset = float(o[0]) if np.all(o == o[0]) else o
            try:
                mesh0 = extrude_surface(points, cell, cells, t, offset)
            except ShellMeshError as exc:
                raise DeckError(f"{where[mine[0]]}: the shell part of element {int(labels[mine[0]])}: {exc}") from None
            half = mesh0.points.shape[0] // 2
            d = mesh0.points[half: half + nodes.size] - mesh0.points[: nodes.size]
            d /= np.linalg.norm(d, axis=1)[:, None]
            for lab, copies in knots_here:
                register_knot(self, lab, nodes[copies], d[copies], forced.get(lab, where[mine[0]]))
            if knots_here:
                self.notes.append(knot_note(where[mine[0]], int(labels[mine[0]]), knots_here))
            flipped = self._flipped(cell, cells)
            if flipped.any():
                if np.any(oc != 0.0):
                    raise DeckError(f"{where[mine[0]]}: shell elements {int(labels[mine[0]])} and "
                                    f"{int(labels[mine[flipped]][0])} are numbered with opposite normals in a part "
                                    f"with an OFFSET: CalculiX makes knots there; number the elements of the part "
                                    f"consistently")
                self.notes.append(f"{where[mine[0]]}: {int(flipped.sum())} shell elements (the first "
                                  f"{int(labels[mine[flipped]][0])}) are numbered against their neighbours' normal "
                                  f"(CalculiX makes knots there): their solid-shells follow the part's first element; "
                                  f"their SPOS and SNEG faces stay their own")
            secs = []
            for s, mat, _, _, w in m.shell_sections:
                if np.intersect1d(m.elsets.get(s, np.zeros(0, np.int64)), labels[mine]).size:
                    secs.append((s, mat, w))
            self.bodies.append({"elements": labels[mine], "cell": cell, "cells": cells, "nodes": nodes,
                                "points": points, "t": t, "offset": offset,
                                "n": half, "d": d, "flipped": flipped, "sections": secs, "where": where[mine[0]]})
            self._grow(int(nodes.max()) + 1)
            self.label_body[nodes] = self.first + j
            self.label_index[nodes] = np.arange(nodes.size)
            for lab in self.shared.intersection(nodes.tolist()):
                self.equation_nodes.setdefault(self.first + j, set()).add(lab)
            for e in labels[mine]:
                self.el_body[int(e)] = self.first + j

    def _grow(self, size: int) -> None:
        """The label maps long enough for labels below ``size`` (the knots' expansions)."""
        if size > self.label_body.size:
            extra = size - self.label_body.size
            self.label_body = np.concatenate([self.label_body, np.full(extra, -1, dtype=np.int64)])
            self.label_index = np.concatenate([self.label_index, np.full(extra, -1, dtype=np.int64)])

    def _sections(self, labels: np.ndarray) -> dict:
        """element label -> its *SHELL SECTION (elset, material, thickness, offset, where); one line for an element
        without one."""
        m = self.m
        out = {}
        for sec in m.shell_sections:
            if sec[0] not in m.elsets:
                raise DeckError(f"{sec[4]}: *SHELL SECTION names the element set {sec[0]!r}, which no *ELSET defines")
            for e in m.elsets[sec[0]]:
                out.setdefault(int(e), sec)
        for e in labels:
            if int(e) not in out:
                solid = [w for s, _, w in m.sections if int(e) in set(m.elsets.get(s, np.zeros(0)).tolist())]
                why = f" (a *SOLID SECTION at {solid[0]} names it: shells take *SHELL SECTION)" if solid else ""
                raise DeckError(f"{self._card(int(e))}: shell element {int(e)} has no *SHELL SECTION{why}")
        return out

    def _card(self, label: int) -> str:
        for (_, _, labs, _), w in zip(self.m.shell_blocks, self.m.shell_where):
            if np.any(labs == label):
                return w
        return "?"

    @staticmethod
    def _flipped(cell: str, cells: np.ndarray) -> np.ndarray:
        """Which surface cells extrude_surface turns (their normal against the first cell's of their part)."""
        from ..mesh.shell import _orient, _quad8_to_quad9, _split_tri6, _split_triangles

        if cell in ("tri3", "tri6"):
            pts = np.zeros((int(cells.max()) + 1, 3))
            split = _split_triangles if cell == "tri3" else _split_tri6
            _, _, quads, of = split(pts, np.ones(pts.shape[0]), cells)
            turned = np.any(_orient(quads, "quad4") != quads, axis=1)
            return np.bincount(of, weights=turned, minlength=cells.shape[0]) > 0
        if cell == "quad8":
            pts = np.zeros((int(cells.max()) + 1, 3))
            _, _, q9 = _quad8_to_quad9(pts, np.ones(pts.shape[0]), cells)
            return np.any(_orient(q9, "quad9") != q9, axis=1)
        return np.any(_orient(cells, cell) != cells, axis=1)

    # -- labels ---------------------------------------------------------------------------------------------------
    def nodes_body(self, labels) -> np.ndarray:
        lab = np.asarray(labels, dtype=np.int64)
        ok = (lab >= 0) & (lab < self.label_body.size)
        out = np.full(lab.shape, -1, dtype=np.int64)
        out[ok] = self.label_body[lab[ok]]
        return out

    def elements_body(self, labels) -> np.ndarray:
        return np.array([self.el_body.get(int(e), -1) for e in np.asarray(labels).ravel()], dtype=np.int64)

    def is_shell(self, labels) -> np.ndarray:
        """Whether each label is a shell node whose conditions and loads are the shell's (a node shared with a solid
        element is the solid's: the shell's expansion follows it through the hinge equations)."""
        out = self.nodes_body(labels) >= 0
        if self.shared:
            out &= ~np.isin(np.asarray(labels, dtype=np.int64), list(self.shared))
        return out

    # -- pressures ------------------------------------------------------------------------------------------------
    def edge_thickness(self, elements: np.ndarray, where: str) -> np.ndarray:
        """The thickness of each shell element of an edge load (its section's; NODAL THICKNESS: one line)."""
        out = np.zeros(len(elements))
        for k, e in enumerate(np.asarray(elements).tolist()):
            t = self._thickness.get(int(e))
            if t is None:
                raise DeckError(f"{where}: *DLOAD EDNOR on shell element {e}, whose *SHELL SECTION has NODAL "
                                f"THICKNESS: an edge load needs the element's thickness; give the section one")
            out[k] = t
        return out

    def pressure_side(self, face: int, where: str) -> str:
        """The face of a *DLOAD Pn on shells: CalculiX's P and P1 the negative face (pushing along the normal), P2
        the positive one; Abaqus' P the positive face (positive against the normal)."""
        if face == 0:
            return "SPOS" if self.dialect == "abaqus" else "SNEG"
        if face in (1, 2):
            return "SNEG" if face == 1 else "SPOS"
        raise DeckError(f"{where}: *DLOAD P{face} on shell elements: their faces are P (P1, the negative side) and P2 "
                        f"(edge loads are not supported)")

    # -- files ----------------------------------------------------------------------------------------------------
    def surface_text(self, j: int, nsets: dict, elsets: dict, faces: dict) -> str:
        """Shell body j's surface mesh file (its nodes by the deck's labels, the shells as S4, S8R or S3, its node and
        element sets, and the element sets of its shell faces)."""
        info = self.bodies[j]

        def lines(values):
            v = np.asarray(values).tolist()
            return [", ".join(map(str, v[i:i + 16])) for i in range(0, len(v), 16)]

        out = ["*NODE"]
        out += [f"{lab}, {x!r}, {y!r}, {z!r}" for lab, (x, y, z) in zip(info["nodes"].tolist(),
                                                                         info["points"].tolist(), strict=True)]
        out.append(f"*ELEMENT, TYPE={SURFACE_TYPE[info['cell']]}")
        out += [", ".join(map(str, row)) for row in np.column_stack([info["elements"],
                                                                     info["nodes"][info["cells"]]]).tolist()]
        for name, labs in elsets.items():
            out.append(f"*ELSET, ELSET={name}")
            out += lines(labs)
        for name, labs in nsets.items():
            out.append(f"*NSET, NSET={name}")
            out += lines(labs)
        return "\n".join(out) + "\n"

    def sets(self, j: int, nsets: dict, elsets: dict, faces: dict):
        """Body j's node sets (surface node indices), element sets (element positions), face rows {name: [(element
        set, side)]} and the element sets those rows name, all from the deck's label sets."""
        from .deck_elements import safe_name

        info = self.bodies[j]
        nodes, elements = info["nodes"], info["elements"]
        ns, es, ns_lab, es_lab = {}, {}, {}, {}
        for name, labs in nsets.items():
            labs = np.intersect1d(np.asarray(labs, dtype=np.int64), nodes)
            if self.shared:  # (a node shared with a solid: the solid's; the shell's layers follow it)
                labs = labs[~np.isin(labs, list(self.shared))]
            if labs.size:
                ns[name], ns_lab[name] = np.searchsorted(nodes, labs), labs
        order = np.argsort(elements, kind="stable")
        for name, labs in elsets.items():
            labs = np.intersect1d(np.asarray(labs, dtype=np.int64), elements)
            if labs.size:
                es[name], es_lab[name] = np.sort(order[np.searchsorted(elements[order], labs)]), labs
        rows = {}
        for name, refs in faces.items():
            mine = []
            for r, (els, side) in enumerate(refs):
                labs = np.intersect1d(np.asarray(els, dtype=np.int64), elements)
                if labs.size:
                    es_name = f"__{safe_name(name)}_{r + 1}"
                    es[es_name] = np.sort(order[np.searchsorted(elements[order], labs)])
                    es_lab[es_name] = labs
                    mine.append([es_name, side.lower() if side.startswith("EDGE") else
                                 "top" if side == "SPOS" else "bottom"])
            if mine:
                rows[safe_name(name)] = mine
        return ns, es, rows, ns_lab, es_lab

    def build(self, j: int, nsets: dict, elsets: dict, faces: dict):
        """(the Mesh, the file's text, the shell table) of shell body j."""
        from ..mesh.shell import extrude_surface

        info = self.bodies[j]
        ns, es, rows, ns_lab, es_lab = self.sets(j, nsets, elsets, faces)
        face_sets = {name: [(es[e], side) for e, side in r] for name, r in rows.items()}
        mesh = extrude_surface(info["points"], info["cell"], info["cells"], info["t"], info["offset"], ns, es,
                               face_sets=face_sets)
        t = info["t"]
        o = info["offset"]
        table = {"thickness": float(t[0]) if np.all(t == t[0]) else [float(v) for v in t],
                 "offset": o if np.ndim(o) == 0 else [float(v) for v in o]}
        if rows:
            table["faces"] = rows
        return mesh, self.surface_text(j, ns_lab, es_lab, rows), table

    def frd_labels(self, start: int) -> list[np.ndarray]:
        """Labels of every shell body's mesh nodes in the .frd (CalculiX numbers its expanded nodes anew): from
        ``start`` on."""
        out = []
        start = max(start, self._next)  # (after the knots' expansions)
        for info in self.bodies:
            out.append(start + np.arange(2 * info["n"]))
            start += 2 * info["n"]
        return out
