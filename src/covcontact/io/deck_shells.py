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


def quadratic_edges(m, name: str) -> str | None:
    """Whether the shell surface ``name`` holds edges (S3..S6) of S8 or S8R elements: the side faces of their 18-node
    solid-shells have six nodes, each taken as its two 4-node halves (mesh.shell), which serve slave surfaces (nodes
    and their tributary areas). As a master they are exact where the edge is straight (its mid-side node on the chord
    of its corners: "straight", the halves then are the side face's two halves, their displacement linear along the
    edge where the element's is quadratic) and chords of a curved edge ("curved"); None: no such edges."""
    rows = m.shell_surfaces.get(name, [])
    eight = [(labs, c) for t, _, labs, c in m.shell_blocks if t in ("S8", "S8R")]
    out = None
    index = m.node_index()
    for els, side, _ in rows:
        if not side.startswith("EDGE"):
            continue
        k = int(side[4:]) - 1
        for labs, conn in eight:
            rows_here = conn[np.isin(labs, els)]
            if not rows_here.size:
                continue
            out = "straight"
            x = m.X[index[rows_here[:, [k, (k + 1) % 4, 4 + k]]]]   # (corner a, corner b, the mid-side node)
            chord = x[:, 1] - x[:, 0]
            off = np.cross(x[:, 2] - x[:, 0], chord)
            if np.any(np.linalg.norm(off, axis=1) > 1e-6 * np.einsum("ij,ij->i", chord, chord)):
                return "curved"
    return out


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
class DeckShells:
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
        forced = self._forced_knots(np.unique(np.concatenate([c.ravel() for c in conn])))
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
            offs = {sections[int(labels[e])][3] for e in mine}
            if len(offs) > 1:
                raise DeckError(f"{where[mine[0]]}: the shell part of element {int(labels[mine[0]])} has sections of "
                                f"different OFFSETs ({', '.join(f'{o:g}' for o in sorted(offs))}): CalculiX makes knots "
                                f"where they meet, covcontact's shell bodies have one offset")
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
            nodes, cells, points, t, knots_here = self._split_knots(nodes, cells, points, tc, cell, labels[mine],
                                                                    forced)
            try:
                mesh0 = extrude_surface(points, cell, cells, t, offs.pop())
            except ShellMeshError as exc:
                raise DeckError(f"{where[mine[0]]}: the shell part of element {int(labels[mine[0]])}: {exc}") from None
            half = mesh0.points.shape[0] // 2
            d = mesh0.points[half: half + nodes.size] - mesh0.points[: nodes.size]
            d /= np.linalg.norm(d, axis=1)[:, None]
            for lab, copies in knots_here:
                self._knot(lab, nodes[copies], d[copies], forced.get(lab, where[mine[0]]))
            if knots_here:
                spread = sum(1 for lab, c in knots_here if c.size > 1)
                why = [f"{spread} where its elements' normals differ by more than 20 degrees or their thicknesses "
                       f"differ"] if spread else []
                why += [f"{len(knots_here) - spread} for a moment or a non-zero rotation"] if spread < len(knots_here) \
                    else []
                self.notes.append(
                    f"{where[mine[0]]}: {len(knots_here)} knot{'s' if len(knots_here) > 1 else ''} in the shell part "
                    f"of element {int(labels[mine[0]])} ({', '.join(why)}): as in CalculiX each such node is expanded "
                    f"once per normal and the expansions are joined by a rigid body whose reference is the node (its "
                    f"dofs 1-6 the body's translation and rotation); CalculiX's knot may also expand uniformly, "
                    f"covcontact's holds the thickness there")
            flipped = self._flipped(cell, cells)
            if flipped.any():
                if sections[int(labels[mine[0]])][3] != 0.0:
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
                                "points": points, "t": t, "offset": sections[int(labels[mine[0]])][3],
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

    def _forced_knots(self, shell_nodes: np.ndarray) -> dict[int, str]:
        """Shell node label -> the card that gives it a non-zero rotation (*BOUNDARY, dofs 4-6) or a moment (*CLOAD,
        dofs 4-6) in some step: a knot (CalculiX's dynamic steps make one; its static ones a mean rotation, which
        leaves the thickness there free)."""
        m = self.m
        out: dict[int, str] = {}
        for b in list(m.model_boundary) + [b for st in m.steps for b in st.boundary]:
            if b.value not in (None, 0.0) and any(d >= 4 for d in b.dofs):
                for lab in np.intersect1d(b.nodes, shell_nodes).tolist():
                    out.setdefault(int(lab), b.where)
        for st in m.steps:
            for ld in st.loads:
                if ld.kind == "cload" and ld.dof >= 4 and ld.value != 0.0:
                    for lab in np.intersect1d(ld.nodes, shell_nodes).tolist():
                        out.setdefault(int(lab), ld.where)
        return out

    def _split_knots(self, nodes, cells, points, tc, cell, rank, forced):
        """The part's surface split at its knots (mesh.shell.split_at_knots: subsets by normal within 20 degrees and
        by thickness, and the nodes of ``forced``): (its node labels, the expansions after the deck's with labels of
        their own; cells; points; thicknesses; [(knot label, its expansions' places)])."""
        from ..mesh.shell import ShellMeshError, split_at_knots

        try:
            points, cells_new, source, found = split_at_knots(points, cells, cell, rank=rank, key=tc,
                                                              forced=np.isin(nodes, list(forced)))
        except ShellMeshError:  # (extrude_surface says so)
            t = np.zeros(nodes.size)
            t[cells.ravel()] = tc.ravel()
            return nodes, cells, points, t, []
        copies = source.size - (nodes.size - len(found))
        labels = np.concatenate([nodes[source[: source.size - copies]], self._next + np.arange(copies)])
        self._next += copies
        t = np.zeros(source.size)
        t[cells_new.ravel()] = tc.ravel()
        return labels, cells_new, points, t, [(int(nodes[i]), places) for i, places in found]

    def _knot(self, lab: int, copies: np.ndarray, d: np.ndarray, where: str) -> None:
        """Shell node ``lab`` as a knot: a rigid body (appended to the deck's *RIGID BODYs) of its expansions
        ``copies`` (labels; ``d`` their directors) with the node as REF NODE. Expansions on one line leave the
        rotation about it to nothing: held where the line is a global axis, else listed."""
        if lab in self.shared:
            raise DeckError(f"{where}: shell node {lab} is a knot of the shell expansion and a node of a solid element: "
                            f"not supported (tie the shell to the solid with *TIE there)")
        drill = None
        if np.all(np.linalg.norm(np.cross(d, d[0]), axis=1) < 1e-6):
            k = int(np.argmax(np.abs(d[0])))
            if abs(d[0][k]) < 1.0 - 1e-9:
                self.unsupported.append(f"{where}: a moment or a non-zero rotation on shell node {lab}, whose normal "
                                        f"{_vec(d[0])} is no global axis: its knot (a rigid body of the node's "
                                        f"expansion along the normal) cannot hold the rotation about the normal; "
                                        f"not supported")
            drill = k
        self.knots[len(self.m.rigid_bodies)] = (lab, drill)
        self.m.rigid_bodies.append((np.asarray(copies, dtype=np.int64), lab, None, where))

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

    def hinges(self, ref, solid_ref) -> list[dict]:
        """The [[equation]] entries of the nodes shared with solid elements (CalculiX: a hinge): per component the
        mean of the shell node's two layers equals the solid node's displacement, u_b + u_t - 2 u_s = 0
        (``solid_ref(label)``: the solid node's single-node set reference)."""
        out = []
        for lab in sorted(self.shared):
            body = int(self.label_body[lab])
            if body < 0:
                continue
            b, t, s = ref(body, f"_SN{lab}_b"), ref(body, f"_SN{lab}_t"), solid_ref(lab)
            out += [{"name": f"hinge{lab}_{c}", "terms": [[b, c, 1.0], [t, c, 1.0], [s, c, -2.0]]} for c in "xyz"]
        return out

    # -- boundary conditions --------------------------------------------------------------------------------------
    def plan_boundaries(self) -> None:
        """The mapping of every shell node's *BOUNDARY dofs (those of the model data and the first step, which hold
        over the run) onto its two layers, after CalculiX's gen3dboun (static steps, no knot):

        - a translation c of the shell node prescribes the mean of its expanded nodes (u_1 + u_3 = 2 u(n)): the mean
          of the bottom and top node, an equation u_b,c + u_t,c = 2 v whose right-hand side follows the deck's values
          over the steps (``sum_values``: its first stage's, the later ones as stage targets);
        - a rotation about a tangent axis a fixes the mean rotation of the line of expanded nodes about a; with both
          tangent rotations fixed (a clamp) the line keeps its direction: the tangential components of u_t - u_b
          vanish (exact at any rotation), its thickness change stays free as in CalculiX; the drilling rotation
          (an axis within 0.999 of the normal) is dropped, as CalculiX drops it;
        - a single tangent rotation is kept where it makes a symmetry plane: the shell's normal and the rotation axis
          along global axes and the translation normal to the plane fixed: then both layers hold that translation.

        Where the pair's component is held alike (a clamped or symmetric tangential component) both layers get the
        *BOUNDARY (any value, amplitudes, later steps); the rest are [[equation]]s holding from the first step on:
        the means with the deck's values, the rotations' differences at zero. Everything else is one line
        (DeckError)."""
        m = self.m
        first = list(m.model_boundary) + (list(m.steps[0].boundary) if m.steps else [])
        dofs: dict[int, set] = {}
        wh: dict[int, str] = {}
        nonzero: dict[tuple, str] = {}
        for b in first:
            shell = b.nodes[self.is_shell(b.nodes)]
            if shell.size and b.fixed:
                raise DeckError(f"{b.where}: *BOUNDARY, FIXED on shell node {int(shell[0])}: not supported on shells")
            for lab in shell.tolist():
                dofs.setdefault(lab, set()).update(b.dofs)
                wh.setdefault(lab, b.where)
                if b.value not in (None, 0.0):
                    for d in b.dofs:
                        nonzero.setdefault((lab, d), b.where)
        for lab, D in dofs.items():
            self.plan[lab] = self._classify(lab, D, wh[lab], nonzero)
        for st in m.steps[1:]:
            for b in st.boundary:
                for lab in b.nodes[self.is_shell(b.nodes)].tolist():
                    both, sums = self.plan.get(lab, (set(), []))[:2]
                    extra = [d for d in b.dofs if d > 3 or d - 1 not in both]
                    valued = [d for d in extra if d > 3 or d - 1 not in sums]  # (a mean takes any value)
                    if extra and (set(b.dofs) - dofs.get(lab, set()) or b.fixed
                                  or (valued and b.value not in (None, 0.0))):
                        raise DeckError(f"{b.where}: *BOUNDARY on dof {extra[0]} of shell node {lab} in a later step: "
                                        f"a shell node's rotations and the translations its two layers share through "
                                        f"an equation are held from the first step on (model data or the first step), "
                                        f"at zero")
            if st.boundary_new and any(self.plan[lab][1] or self.plan[lab][2] for lab in self.plan):
                raise DeckError(f"{st.where}: *BOUNDARY, OP=NEW in a step of a deck with shell nodes held through "
                                f"equations (their conditions hold over the whole run here)")

    def _classify(self, lab: int, D: set, where: str, nonzero: dict):
        body = self.bodies[self.label_body[lab] - self.first]
        d = body["d"][self.label_index[lab]]
        T = sorted(c - 1 for c in D if c <= 3)
        R = sorted(c - 4 for c in D if c >= 4)
        rot = [c for c in D if c >= 4 and (lab, c) in nonzero]
        if rot:
            raise DeckError(f"{nonzero[(lab, rot[0])]}: *BOUNDARY: a rotation (dof {rot[0]}) prescribed non-zero on "
                            f"shell node {lab}: not supported (a rotation of the line of its two layers)")
        drill = [r for r in R if abs(d[r]) > 0.999]
        if drill and where not in self._drilled:
            self._drilled.add(where)
            self.notes.append(f"{where}: *BOUNDARY: dof {drill[0] + 4} of shell node {lab} (and of the others there "
                              f"whose normal it is) is a drilling rotation (about the normal): dropped, as CalculiX "
                              f"drops it")
        R = [r for r in R if r not in drill]
        P = np.array([np.eye(3)[r] - d[r] * d for r in R]).reshape(-1, 3)
        rank = int(np.linalg.matrix_rank(P, tol=1e-6)) if R else 0
        k = int(np.argmax(np.abs(d))) if np.max(np.abs(d)) > 1.0 - 1e-9 else None
        both: set = set()
        sums: list = []
        diffs: list = []
        if rank == 2:
            if k is not None:
                for c in range(3):
                    if c == k:
                        continue
                    if c in T:
                        both.add(c)
                    else:
                        diffs.append(np.eye(3)[c])
                sums = [k] if k in T else []
            else:
                sums = list(T)
                e1 = P[0] / np.linalg.norm(P[0])
                e2 = np.cross(d, e1)
                diffs = [e1, e2]
        elif rank == 1:
            if k is None or len(R) != 1:
                raise DeckError(f"{where}: *BOUNDARY: rotation dof {R[0] + 4} of shell node {lab} alone (its other "
                                f"tangent rotation free) on a shell whose normal {_vec(d)} is no global axis: only "
                                f"symmetry planes (e.g. XSYMM: 1, 5, 6 on a flat shell) map exactly; not supported")
            i = 3 - k - R[0]
            if i not in T:
                raise DeckError(f"{where}: *BOUNDARY: rotation dof {R[0] + 4} of shell node {lab} without the "
                                f"translation {i + 1} normal to its symmetry plane: only symmetry planes (e.g. XSYMM: "
                                f"1, 5, 6 on a flat shell) map exactly; not supported")
            both.add(i)
            sums = [c for c in T if c != i]
        else:
            sums = list(T)
        for row in diffs:
            if np.count_nonzero(np.abs(row) > 1e-14) > 1 and any((lab, c + 1) in nonzero for c in T):
                raise DeckError(f"{where}: *BOUNDARY: non-zero values on shell node {lab} of a curved shell: not "
                                f"supported")
        if sums or diffs:
            self.equation_nodes.setdefault(int(self.label_body[lab]), set()).add(lab)
        return both, sums, diffs

    def boundary_split(self, labels: np.ndarray, dofs) -> tuple[np.ndarray, dict[int, np.ndarray]]:
        """(the labels that are no shell nodes, {component: the shell labels whose two layers both take it})."""
        shell = self.is_shell(labels)
        out = {}
        for d in dofs:
            if d <= 3:
                labs = [lab for lab in labels[shell].tolist() if d - 1 in self.plan.get(lab, (set(),))[0]]
                if labs:
                    out[d - 1] = np.asarray(labs, dtype=np.int64)
        return labels[~shell], out

    def equations(self, ref) -> list[dict]:
        """The [[equation]] entries of the plan (``ref(body, set)``: the set's reference in the problem file)."""
        out = []
        comps = "xyz"
        for lab, (_, sums, diffs) in sorted(self.plan.items()):
            body = int(self.label_body[lab])
            b, t = ref(body, f"_SN{lab}_b"), ref(body, f"_SN{lab}_t")
            for c in sums:
                value = self.sum_values.get((lab, c), 0.0)
                out.append({"name": f"shell{lab}_{comps[c]}", "terms": [[t, comps[c], 1.0], [b, comps[c], 1.0]]}
                           | ({"value": value} if value else {}))
            rows = [np.asarray(r, dtype=float) for r in diffs]
            if len(rows) == 2:  # (two rows, their dependents distinct: eliminated with pivoting)
                c1 = int(np.argmax(np.abs(rows[0])))
                rows[1] = rows[1] - rows[1][c1] / rows[0][c1] * rows[0]
            for j, r in enumerate(rows):
                c1 = int(np.argmax(np.abs(r)))
                terms = [[b, comps[c1], -float(r[c1])], [t, comps[c1], float(r[c1])]]
                terms += [[x, comps[c], s * float(r[c])] for c in range(3) if c != c1 and abs(r[c]) > 1e-14
                          for x, s in ((t, 1.0), (b, -1.0))]
                out.append({"name": f"shell{lab}_r{j + 1}", "terms": terms})
        return out

    def layer_sets(self, body: int) -> dict:
        """The single-node sets of the equations' nodes of shell body ``body`` (its ``sets`` table)."""
        info = self.bodies[body - self.first]
        out = {}
        for lab in sorted(self.equation_nodes.get(body, ())):
            i = int(self.label_index[lab])
            out[f"_SN{lab}_b"] = {"nodes": [i]}
            out[f"_SN{lab}_t"] = {"nodes": [i + info["n"]]}
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
        table = {"thickness": float(t[0]) if np.all(t == t[0]) else [float(v) for v in t],
                 "offset": info["offset"]}
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


def _vec(v) -> str:
    return "(" + ", ".join(f"{x:.3g}" for x in v) + ")"
