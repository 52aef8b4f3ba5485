"""The Mesh: node coordinates, one volume cell type, named node sets and face sets."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: volume cell type -> the type of its contact faces
FACE_TYPE = {"hex8": "quad4", "hex18": "quad9", "hex27": "quad9"}


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
        return FACE_TYPE[self.cell_type]
