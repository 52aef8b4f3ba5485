"""Meshes: the Mesh container, structured generators, boundary faces, file I/O."""

from .faces import (
    FACE_LABELS,
    FACES,
    boundary_faces,
    check_orientation,
    face_normals,
    faces_on_nodes,
    jacobian_determinants,
    match_boundary_faces,
)
from .generators import CELLS, block, cylinder_patch, hemisphere_solid, plate, sphere_patch
from .generators_solid import half_cylinder_solid
from .io import MeshError, read_mesh, to_meshio, write_vtu
from .mesh import FACE_TYPE, Mesh

__all__ = [
    "CELLS", "FACES", "FACE_LABELS", "FACE_TYPE", "Mesh", "MeshError", "block", "boundary_faces",
    "check_orientation", "cylinder_patch", "face_normals", "faces_on_nodes", "half_cylinder_solid", "hemisphere_solid",
    "jacobian_determinants", "match_boundary_faces", "plate", "read_mesh", "sphere_patch",
    "to_meshio", "write_vtu",
]
