"""Elements: total-Lagrangian solid hexahedra."""

from .solid import SOLID_CELLS, SolidBody, SolidStress, solid_chunk, solid_gauss_fields

__all__ = ["SOLID_CELLS", "SolidBody", "SolidStress", "solid_chunk", "solid_gauss_fields"]
