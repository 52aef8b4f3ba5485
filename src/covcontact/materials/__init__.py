"""Materials: St. Venant-Kirchhoff, compressible Neo-Hooke and finite-strain J2 plasticity (parameters array +
compiled response)."""

from .hyperelastic import (
    NEO_HOOKE,
    SVK,
    VOIGT,
    Material,
    NeoHooke,
    SaintVenantKirchhoff,
    lame,
    material_energy,
    material_from_name,
    material_response,
    strain_energy,
    stress_tangent,
    voigt_to_tensor,
)
from .plasticity import (
    J2,
    NHIST,
    Hill48,
    J2Plasticity,
    LinearHardening,
    SwiftHardening,
    TableHardening,
    VoceHardening,
    j2_point,
    j2_response,
)
from .update import material_update

__all__ = [
    "NEO_HOOKE", "SVK", "VOIGT", "Material", "NeoHooke", "SaintVenantKirchhoff", "lame",
    "material_energy", "material_from_name", "material_response", "strain_energy", "stress_tangent",
    "voigt_to_tensor", "J2", "NHIST", "Hill48", "J2Plasticity", "LinearHardening", "SwiftHardening",
    "TableHardening", "VoceHardening", "j2_point", "j2_response", "material_update",
]
