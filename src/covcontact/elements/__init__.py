"""Elements: total-Lagrangian solid hexahedra and the solid-shells (8-node and 18-node, ANS + EAS)."""

from .solid import SOLID_CELLS, SolidBody, SolidStress, solid_chunk, solid_gauss_fields
from .solidshell import SolidShellBody, check_options

__all__ = ["SOLID_CELLS", "SolidBody", "SolidShellBody", "SolidStress", "check_options", "solid_chunk",
           "solid_gauss_fields"]
