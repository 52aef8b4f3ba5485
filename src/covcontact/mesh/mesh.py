"""The Mesh: node coordinates, one volume cell type, named node sets and face sets."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: volume cell type -> the type of its contact faces
FACE_TYPE = {"hex8": "quad4", "hex18": "quad9", "hex27": "quad9", "tet4": "tri3", "tet10": "tri6", "hex20": "quad8"}
#: the face types of wedges (a face set holds one of them)
WEDGE_FACE_TYPES = ("tri3", "quad4")
#: nodes per face of each face type
FACE_NODES = {"quad4": 4, "quad9": 9, "tri3": 3, "tri6": 6, "quad8": 8}


@dataclass
class Mesh:
    """A mesh of one body.

    Attributes:
        points: (nnode, 3) float64 reference coordinates.
        cell_type: "hex8", "hex18" or "hex27" (node order as in ``covcontact.fem.shapes``).
        cells: (nelem, nen) int64 connectivity.
        node_sets: name -> sorted unique int64 node indices.
        face_sets: name -> (nface, 4 or 9) int64 face connectivity, quad4 for hex8 and quad9 for
            hex18/hex27, ordered so that the normal rho_1 x rho_2 points out of the body.
        element_sets: name -> sorted unique int64 element indices.
    """

    points: np.ndarray
    cell_type: str
    cells: np.ndarray
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    face_sets: dict[str, np.ndarray] = field(default_factory=dict)
    element_sets: dict[str, np.ndarray] = field(default_factory=dict)
    #: the face groups of a mesh file as read (name -> (nface, >= 4) corner nodes), to be matched again against
    #: the boundary of a part of the mesh (``select``), where faces between parts become boundary faces
    face_groups: dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.points = np.ascontiguousarray(self.points, dtype=np.float64)
        self.cells = np.ascontiguousarray(self.cells, dtype=np.int64)

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_cells(self) -> int:
        return int(self.cells.shape[0])

    @property
    def face_type(self) -> str:
        if self.cell_type not in FACE_TYPE:
            raise ValueError(f"{self.cell_type} cells have faces of two types (triangles and quadrilaterals): each "
                             f"face set is of one of them")
        return FACE_TYPE[self.cell_type]

    @property
    def face_types(self) -> tuple[str, ...]:
        """The face types a face set of this mesh may have: one, or for wedges tri3 and quad4 (a set of one)."""
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
