"""A part of a mesh: the body of one volume of a mesh file that holds several (docs/input.md, "Several bodies
in one file")."""

from __future__ import annotations

import numpy as np

from .faces import match_boundary_faces
from .mesh import Mesh


def select(mesh: Mesh, elements: np.ndarray) -> Mesh:
    """The part of ``mesh`` made of ``elements``: its own node numbering (nodes shared with the rest are its
    own copies), the node sets restricted to its nodes, the element sets to its elements, and the face sets
    matched against its boundary (faces between this part and the rest are boundary faces of it)."""
    elements = np.unique(np.asarray(elements, dtype=np.int64))
    blocks = [(t, mesh.cells_of(elements[idx])[1]) for t, idx in mesh.type_parts(elements)]
    used = np.unique(np.concatenate([c.ravel() for _, c in blocks]))
    new = np.full(mesh.n_nodes, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    part = Mesh.of_blocks(mesh.points[used], [(t, new[c]) for t, c in blocks])
    for name, nodes in mesh.node_sets.items():
        k = new[nodes]
        if np.any(k >= 0):
            part.add_node_set(name, k[k >= 0])
    enew = np.full(mesh.n_cells, -1, dtype=np.int64)
    enew[elements] = np.arange(elements.size)
    for name, elems in mesh.element_sets.items():
        k = enew[elems]
        if np.any(k >= 0):
            part.element_sets[name] = np.unique(k[k >= 0])
    groups = mesh.face_groups or {name: f for name, f in mesh.face_sets.items()}
    for name, faces in groups.items():
        f = new[np.asarray(faces)[:, :4]]
        f = f[np.all(f >= 0, axis=1)]
        if len(f):
            matched, _ = match_boundary_faces(part, f)
            if matched.shape[0]:
                part.add_face_set(name, matched)
    return part
