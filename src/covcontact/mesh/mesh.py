"""The Mesh: node coordinates, volume cells of one type or of several (a mixed mesh), named node, face and element
sets."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

#: volume cell type -> the type of its contact faces
FACE_TYPE = {"hex8": "quad4", "hex18": "quad9", "hex27": "quad9", "tet4": "tri3", "tet10": "tri6", "hex20": "quad8",
             # the planar cells (plane strain, plane stress, axisymmetric bodies in the x-y plane): their edges
             "quad4": "line2", "tri3": "line2", "quad8": "line3", "quad9": "line3", "tri6": "line3"}
#: the face types of wedges (a face set holds one of them)
WEDGE_FACE_TYPES = ("tri3", "quad4")
#: nodes per face of each face type
FACE_NODES = {"quad4": 4, "quad9": 9, "tri3": 3, "tri6": 6, "quad8": 8, "line2": 2, "line3": 3}
#: the cell types one mesh may mix: the linear cells, whose triangular and quadrilateral faces meet conformingly
MIXABLE = ("hex8", "wedge6", "tet4")
#: the planar cell types (x-y plane) and those one planar mesh may mix (edges of one type)
PLANAR_CELLS = ("quad4", "quad8", "quad9", "tri3", "tri6")
PLANAR_MIXABLE = (("quad4", "tri3"), ("quad8", "tri6"))


class CellBlock(NamedTuple):
    """The cells of one type in a mesh: element indices ``first`` .. ``first + len(cells) - 1``."""

    cell_type: str
    cells: np.ndarray
    first: int


@dataclass
class Mesh:
    """A mesh of one body.

    Attributes:
        points: (nnode, 3) float64 reference coordinates.
        cell_type: the volume cell type ("hex8", "hex18", "hex27", "hex20", "tet4", "tet10", "wedge6"; node order as
            in ``covcontact.fem``), or "mixed" for a mesh of several (``Mesh.mixed``).
        cells: (nelem, nen) int64 connectivity (a mixed mesh has none: its :attr:`blocks`).
        node_sets: name -> sorted unique int64 node indices.
        face_sets: name -> (nface, nodes per face) int64 face connectivity of one face type, ordered so that the
            normal rho_1 x rho_2 points out of the body.
        element_sets: name -> sorted unique int64 element indices.
    """

    points: np.ndarray
    cell_type: str
    cells: np.ndarray | None
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    face_sets: dict[str, np.ndarray] = field(default_factory=dict)
    element_sets: dict[str, np.ndarray] = field(default_factory=dict)
    #: the face groups of a mesh file as read (name -> (nface, >= 4) corner nodes), to be matched again against
    #: the boundary of a part of the mesh (``select``), where faces between parts become boundary faces
    face_groups: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    #: the cell blocks of a mixed mesh (``cell_type == "mixed"``): (cell type, cells) in element order
    mixed_blocks: list[tuple[str, np.ndarray]] = field(default_factory=list, repr=False)
    #: nodal weights (nface, nodes per face) of a pressure on face sets whose faces are pieces of larger faces
    #: (mesh.shell: the 4-node halves of a hex18's six-node side face, the quarters of a 9-node face), so that a
    #: uniform pressure on the pieces gives the whole face's consistent nodal forces
    face_weights: dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.points = np.ascontiguousarray(self.points, dtype=np.float64)
        if self.cell_type == "mixed":
            if self.cells is not None:
                raise ValueError("a mixed mesh has its cells in mixed_blocks, not cells")
            self.mixed_blocks = [(t, np.ascontiguousarray(c, dtype=np.int64)) for t, c in self.mixed_blocks]
            kinds = sorted({t for t, _ in self.mixed_blocks})
            if len(kinds) < 2:
                raise ValueError("a mixed mesh needs cells of at least two types; a mesh of one type is Mesh(points, "
                                 "cell_type, cells)")
            if any(set(kinds) <= set(pair) for pair in PLANAR_MIXABLE):
                pass
            elif any(t not in MIXABLE for t in kinds):
                raise ValueError(f"a mesh mixes only {', '.join(MIXABLE)} cells (their faces meet conformingly), "
                                 f"got {', '.join(kinds)}")
        else:
            if self.mixed_blocks:
                raise ValueError("mixed_blocks are for cell_type = 'mixed'")
            self.cells = np.ascontiguousarray(self.cells, dtype=np.int64)

    @classmethod
    def of_blocks(cls, points: np.ndarray, blocks: list[tuple[str, np.ndarray]]) -> Mesh:
        """A mesh of the cell ``blocks`` [(cell type, cells), ...] in element order: of one type, or mixed. Adjacent
        blocks of one type are joined."""
        joined: list[tuple[str, np.ndarray]] = []
        for t, c in blocks:
            c = np.asarray(c, dtype=np.int64)
            if joined and joined[-1][0] == t:
                joined[-1] = (t, np.concatenate([joined[-1][1], c]))
            elif len(c) or not joined:
                joined.append((t, c))
        if len({t for t, _ in joined}) == 1:
            return cls(points, joined[0][0], np.concatenate([c for _, c in joined]))
        return cls(points, "mixed", None, mixed_blocks=joined)

    @property
    def is_planar(self) -> bool:
        """Whether the cells are planar (quad4, quad8, quad9, tri3, tri6 in the x-y plane; their faces are edges)."""
        return all(t in PLANAR_CELLS for t in self.cell_types)

    @property
    def is_mixed(self) -> bool:
        return self.cell_type == "mixed"

    @property
    def blocks(self) -> list[CellBlock]:
        """The cells by type, in element order (one block unless the mesh is mixed)."""
        if not self.is_mixed:
            return [CellBlock(self.cell_type, self.cells, 0)]
        out, first = [], 0
        for t, c in self.mixed_blocks:
            out.append(CellBlock(t, c, first))
            first += len(c)
        return out

    @property
    def cell_types(self) -> tuple[str, ...]:
        """The distinct cell types, in the order of their first block."""
        return tuple(dict.fromkeys(b.cell_type for b in self.blocks))

    def connectivity(self) -> np.ndarray:
        """(nelem, nen) cells of a mesh of one cell type; a ValueError for a mixed mesh (use :attr:`blocks`)."""
        if self.is_mixed:
            raise ValueError(f"a mesh of {' and '.join(self.cell_types)} cells has no single connectivity table")
        return self.cells

    def pieces(self) -> list[tuple[int, Mesh]]:
        """(first element index, a mesh of one cell type over all the points) per block (sets not carried)."""
        if not self.is_mixed:
            return [(0, self)]
        return [(b.first, Mesh(self.points, b.cell_type, b.cells)) for b in self.blocks]

    def cells_of(self, elements: np.ndarray) -> tuple[str, np.ndarray]:
        """(cell type, (n, nen) cells) of ``elements``, all of one block's type (a ValueError otherwise)."""
        elements = np.asarray(elements, dtype=np.int64)
        for b in self.blocks:
            local = elements - b.first
            if np.all((local >= 0) & (local < len(b.cells))):
                return b.cell_type, b.cells[local]
        raise ValueError("these elements are of several cell types")

    def type_parts(self, elements: np.ndarray | None = None) -> list[tuple[str, np.ndarray]]:
        """(cell type, indices into ``elements`` (default: all cells)) per block that has cells among them."""
        elements = np.arange(self.n_cells) if elements is None else np.asarray(elements, dtype=np.int64)
        out = []
        for b in self.blocks:
            idx = np.flatnonzero((elements >= b.first) & (elements < b.first + len(b.cells)))
            if idx.size:
                out.append((b.cell_type, idx))
        return out

    def incidence(self) -> tuple[np.ndarray, np.ndarray]:
        """(element, node) of every node of every cell, flat (element-node incidence of any mesh)."""
        els, nodes = [], []
        for b in self.blocks:
            els.append(np.repeat(np.arange(b.first, b.first + len(b.cells)), b.cells.shape[1]))
            nodes.append(b.cells.ravel())
        return np.concatenate(els), np.concatenate(nodes)

    def centroids(self) -> np.ndarray:
        """(nelem, 3) mean of each cell's nodes."""
        return np.concatenate([self.points[b.cells].mean(axis=1) for b in self.blocks])

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_cells(self) -> int:
        return int(sum(len(b.cells) for b in self.blocks))

    @property
    def face_type(self) -> str:
        if self.cell_type not in FACE_TYPE:
            raise ValueError(f"{self.cell_type} cells have faces of two types (triangles and quadrilaterals): each "
                             f"face set is of one of them")
        return FACE_TYPE[self.cell_type]

    @property
    def face_types(self) -> tuple[str, ...]:
        """The face types a face set of this mesh may have: one, or for wedges and mixed meshes tri3 and quad4 (a set
        of one); hex18 solid-shells quad9 (top and bottom) and quad4 (the halves of their six-node side faces,
        covcontact.mesh.shell)."""
        if self.cell_type == "hex18":
            return ("quad9", "quad4")
        if self.is_mixed:
            made = {t for c in self.cell_types for t in (WEDGE_FACE_TYPES if c == "wedge6" else (FACE_TYPE[c],))}
            return tuple(t for t in WEDGE_FACE_TYPES if t in made)
        return WEDGE_FACE_TYPES if self.cell_type == "wedge6" else (self.face_type,)

    def node_set(self, name: str) -> np.ndarray:
        """Node indices of set ``name``; a KeyError lists the known names."""
        return _lookup(self.node_sets, name, "node set")

    def face_set(self, name: str) -> np.ndarray:
        """Outward-ordered faces of set ``name``; a KeyError lists the known names."""
        return _lookup(self.face_sets, name, "face set")

    def element_set(self, name: str) -> np.ndarray:
        """Element indices of set ``name``; a KeyError lists the known names."""
        return _lookup(self.element_sets, name, "element set")

    def add_node_set(self, name: str, nodes: np.ndarray) -> None:
        """Store ``nodes`` (any order, repeats allowed) as sorted unique indices."""
        self.node_sets[name] = np.unique(np.asarray(nodes, dtype=np.int64))

    def add_face_set(self, name: str, faces: np.ndarray) -> None:
        """Store outward-ordered faces (nface, 4 or 9) under ``name``."""
        f = np.ascontiguousarray(faces, dtype=np.int64)
        nfn = [FACE_NODES[t] for t in self.face_types]
        if f.ndim != 2 or f.shape[1] not in nfn:
            raise ValueError(f"face set {name!r} needs shape (nface, {' or '.join(map(str, nfn))}), got {f.shape}")
        self.face_sets[name] = f


def _lookup(sets: dict[str, np.ndarray], name: str, kind: str) -> np.ndarray:
    try:
        return sets[name]
    except KeyError:
        known = ", ".join(sorted(sets)) or "none"
        raise KeyError(f"no {kind} named {name!r}; known: {known}") from None
