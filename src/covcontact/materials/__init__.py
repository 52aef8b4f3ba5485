"""Materials: St. Venant-Kirchhoff and compressible Neo-Hooke (parameters array + compiled response)."""

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

__all__ = [
    "NEO_HOOKE", "SVK", "VOIGT", "Material", "NeoHooke", "SaintVenantKirchhoff", "lame",
    "material_energy", "material_from_name", "material_response", "strain_energy", "stress_tangent",
    "voigt_to_tensor",
]
