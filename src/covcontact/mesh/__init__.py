"""Meshes: the Mesh container, structured generators, boundary faces, file I/O."""

from .mesh import FACE_TYPE, Mesh

__all__ = ["FACE_TYPE", "Mesh"]
