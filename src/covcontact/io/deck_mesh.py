"""The mesh side of an imported deck (docs/input.md, "Abaqus and CalculiX decks"): its connected parts (each a
body), and each body's mesh file (nodes, elements, sets, surfaces in the plain Abaqus form covcontact's mesh reader
takes) with the meshio mesh it reads as, built from the same content (``covcontact run DECK.inp`` hands it to the
loader instead of reading the file back)."""

from __future__ import annotations

import re

import numpy as np

from .deck import DeckError
from .deck_model import DeckModel


from .deck_elements import safe_name  # noqa: E402,F401  (re-exported: the import names sets through it)


class Parts:
    """The connected parts of the deck's mesh (elements joined through shared nodes): each is a body."""

    def __init__(self, m: DeckModel):
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components

        self.m = m
        self.index = m.node_index()
        self.el_labels = np.concatenate([b[2] for b in m.blocks]) if m.blocks else np.zeros(0, np.int64)
        conn = [b[3] for b in m.blocks]
        for (_, _, labels, c), where in zip(m.blocks, m.block_where):
            bad = self._lookup(c) < 0
            if bad.any():
                e = int(np.flatnonzero(bad.any(axis=1))[0])
                raise DeckError(f"{where}: *ELEMENT: element {int(labels[e])} refers to node {int(c[bad][0])}, which no "
                                f"*NODE defines")
        top = int(self.el_labels.max()) + 1 if self.el_labels.size else 1
        self.el_index = np.full(top, -1, dtype=np.int64)
        if np.unique(self.el_labels).size != self.el_labels.size:
            order = np.sort(self.el_labels)
            dup = int(order[1:][order[1:] == order[:-1]][0])
            where = [w for (_, _, labels, _), w in zip(m.blocks, m.block_where) if dup in labels][-1]
            raise DeckError(f"{where}: *ELEMENT: element {dup} is defined twice (element labels are unique in a deck)")
        self.el_index[self.el_labels] = np.arange(self.el_labels.size)
        rows = np.concatenate([np.repeat(np.arange(len(c)) + off, c.shape[1]) for c, off in
                               zip(conn, np.cumsum([0] + [len(c) for c in conn])[:-1])]) if conn else np.zeros(0, int)
        cols = np.concatenate([self.index[c.ravel()] for c in conn]) if conn else np.zeros(0, int)
        ne, nn = self.el_labels.size, m.node_labels.size
        g = coo_matrix((np.ones(rows.size), (rows, ne + cols)), shape=(ne + nn, ne + nn))
        _, comp = connected_components(g, directed=False)
        el_comp = comp[:ne]
        kinds = np.unique(el_comp)
        self.of_element = np.searchsorted(kinds, el_comp)      # body number of each element (deck order)
        self.n = kinds.size
        node_body = np.full(nn, -1, dtype=np.int64)
        if conn:  # (a deck of shells alone has no solid part)
            node_body[cols] = np.repeat(self.of_element, np.concatenate([np.full(len(c), c.shape[1]) for c in conn]))
        self.of_node = node_body                                # body of each node (-1: in no element)

    def _lookup(self, labels: np.ndarray) -> np.ndarray:
        lab = np.asarray(labels, dtype=np.int64)
        ok = (lab >= 0) & (lab < self.index.size)
        out = np.full(lab.shape, -1, dtype=np.int64)
        out[ok] = self.index[lab[ok]]
        return out

    def nodes_body(self, labels: np.ndarray) -> np.ndarray:
        idx = self._lookup(labels)
        out = np.full(idx.shape, -1, dtype=np.int64)
        out[idx >= 0] = self.of_node[idx[idx >= 0]]
        return out

    def elements_body(self, labels: np.ndarray) -> np.ndarray:
        lab = np.asarray(labels, dtype=np.int64)
        ok = (lab >= 0) & (lab < self.el_index.size)
        idx = np.full(lab.shape, -1, dtype=np.int64)
        idx[ok] = self.el_index[lab[ok]]
        out = np.full(idx.shape, -1, dtype=np.int64)
        out[idx >= 0] = self.of_element[idx[idx >= 0]]
        return out

    def block_range(self, j: int) -> slice:
        """The elements of the deck's element block ``j`` among all elements (deck order)."""
        start = sum(len(self.m.blocks[i][2]) for i in range(j))
        return slice(start, start + len(self.m.blocks[j][2]))


def body_content(m: DeckModel, parts: Parts, k: int, extra_nsets: dict, extra_elsets: dict,
                 extra_surfaces: dict) -> dict:
    """Body k's nodes, element blocks, element and node sets and element surfaces, by deck labels (with the sets and
    surfaces the import adds: single nodes, element labels, pressure faces); each surface row (its own element set,
    the face number, the elements)."""

    def own_elements(labels):
        return labels[parts.elements_body(labels) == k]

    def own_nodes(labels):
        return labels[parts.nodes_body(labels) == k]

    mine = parts.of_node == k
    blocks = []
    for j, (_, cell, labels, conn) in enumerate(m.blocks):
        sel = parts.of_element[parts.block_range(j)] == k
        if sel.any():
            blocks.append((cell, labels[sel], conn[sel]))
    elsets = {}
    for name, labels in {**m.elsets, **extra_elsets}.items():
        labels = own_elements(labels)  # (GENERATE ranges may name labels no element has)
        if labels.size:
            elsets[safe_name(name)] = labels
    node_sets = {**{safe_name(n): v for n, v in m.nsets.items()}, **extra_nsets}
    node_sets.update({safe_name(n): v for n, (kind, v) in m.surfaces.items()
                      if kind == "NODE" and safe_name(n) not in node_sets})
    nsets = {}
    for name, labels in node_sets.items():
        labels = own_nodes(labels)  # (nodes of no element carry no unknowns)
        if labels.size:
            nsets[name] = labels
    all_surfaces = {safe_name(n): [(els, face) for els, face, _ in refs]
                    for n, (kind, refs) in m.surfaces.items() if kind == "ELEMENT"}
    all_surfaces.update(extra_surfaces)
    surfaces = {}
    for name, refs in all_surfaces.items():
        rows = []
        for j, (els, face) in enumerate(refs):
            els = own_elements(els)
            if els.size:  # (an element set of its own per face number)
                rows.append((f"__{name}_{j + 1}", face, els))
        if rows:
            surfaces[name] = rows
    return {"labels": m.node_labels[mine], "X": m.X[mine], "blocks": blocks, "elsets": elsets, "nsets": nsets,
            "surfaces": surfaces}


def body_text(c: dict) -> str:
    """The body's mesh file: *NODE, *ELEMENT per block, *ELSET, *NSET, *SURFACE (Abaqus, as covcontact reads it)."""
    from .deck_planar import MESH_TYPE

    abaqus_type = {"hex8": "C3D8", "hex20": "C3D20", "tet10": "C3D10", "tet4": "C3D4", "wedge6": "C3D6", **MESH_TYPE}

    def label_lines(values) -> list[str]:
        v = np.asarray(values).tolist()
        return [", ".join(map(str, v[i:i + 16])) for i in range(0, len(v), 16)]

    lines = ["*NODE"]
    lines += [f"{lab}, {x!r}, {y!r}, {z!r}" for lab, (x, y, z) in zip(c["labels"].tolist(), c["X"].tolist(),
                                                                        strict=True)]
    for cell, labels, conn in c["blocks"]:
        lines.append(f"*ELEMENT, TYPE={abaqus_type[cell]}")
        lines += [", ".join(map(str, row)) for row in np.column_stack([labels, conn]).tolist()]
    for name, labels in c["elsets"].items():
        lines.append(f"*ELSET, ELSET={name}")
        lines += label_lines(labels)
    for name, labels in c["nsets"].items():
        lines.append(f"*NSET, NSET={name}")
        lines += label_lines(labels)
    for name, rows in c["surfaces"].items():
        for es, _, labels in rows:
            lines.append(f"*ELSET, ELSET={es}")
            lines += label_lines(labels)
        lines.append(f"*SURFACE, NAME={name}, TYPE=ELEMENT")
        lines += [f"{es}, S{face}" for es, face, _ in rows]
    return "\n".join(lines) + "\n"


def surface_refs(c: dict) -> dict:
    """The element surfaces of ``body_content`` as the mesh reader takes them: name -> [(element set, face)]."""
    return {name: [(es, face) for es, face, _ in rows] for name, rows in c["surfaces"].items()}


def body_meshio(c: dict):
    """The meshio mesh the body's file reads as (points in file order, a block per *ELEMENT card, the sets as
    indices), built without the text."""
    import meshio

    from ..mesh.io import _TO_MESHIO

    labels = c["labels"]
    cells = [(_TO_MESHIO[cell], np.searchsorted(labels, conn)) for cell, _, conn in c["blocks"]]
    el_labels = [lab for _, lab, _ in c["blocks"]]
    cell_sets = {}
    surface_sets = {es: labs for rows in c["surfaces"].values() for es, _, labs in rows}
    for name, labs in {**c["elsets"], **surface_sets}.items():
        per_block = []
        for lab in el_labels:
            order = np.argsort(lab, kind="stable")
            pos = np.searchsorted(lab[order], labs)
            pos = np.clip(pos, 0, max(lab.size - 1, 0))
            hit = lab[order][pos] == labs if lab.size else np.zeros(labs.size, dtype=bool)
            per_block.append(order[pos[hit]].astype(np.int64))
        cell_sets[name] = per_block
    point_sets = {name: np.searchsorted(labels, labs).astype(np.int32) for name, labs in c["nsets"].items()}
    return meshio.Mesh(c["X"].copy(), cells, point_sets=point_sets, cell_sets=cell_sets)
