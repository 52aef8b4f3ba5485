"""The deck element types covcontact reads and their cells, and the names sets and conditions take: shared by the
deck modules (the reader, the couplings, the shells, the mesh files) without an import cycle between them."""

from __future__ import annotations

import re

from .deck_planar import PLANAR_ELEMENTS, PLANAR_NFACES, PLANAR_NNODE

#: Abaqus / CalculiX element type -> (covcontact cell type, options); C3D8R is the full-integration hex8 (there is
#: no hourglass-controlled hex8), C3D20R the reduced hex20
ELEMENTS = {"C3D8": ("hex8", {}), "C3D8R": ("hex8", {}), "C3D20": ("hex20", {}),
            "C3D8I": ("hex8", {"incompatible_modes": True}),
            "C3D20R": ("hex20", {"integration": "reduced"}), "C3D10": ("tet10", {}), "C3D4": ("tet4", {}),
            "C3D6": ("wedge6", {}),
            # hybrid elements (nearly incompressible materials): covcontact's F-bar (deck_import, a note)
            "C3D8H": ("hex8", {"hybrid": True}), "C3D8RH": ("hex8", {"hybrid": True}),
            "C3D20H": ("hex20", {"hybrid": True}), "C3D20RH": ("hex20", {"hybrid": True}),
            "C3D10H": ("tet10", {"hybrid": True}), "C3D4H": ("tet4", {"hybrid": True}),
            "C3D6H": ("wedge6", {"hybrid": True})}
#: nodes per cell (the deck's node order is covcontact's, VTK's, for every one of these cells)
NNODE = {"hex8": 8, "hex20": 20, "tet10": 10, "tet4": 4, "wedge6": 6}
#: faces per cell (S1..Sn, P1..Pn)
NFACES = {"hex8": 6, "hex20": 6, "tet10": 4, "tet4": 4, "wedge6": 5}
# plane strain, plane stress and axisymmetric elements (CPE, CPS, CAX): planar cells (deck_planar)
ELEMENTS.update(PLANAR_ELEMENTS)
NNODE.update(PLANAR_NNODE)
NFACES.update(PLANAR_NFACES)


def safe_name(text: str) -> str:
    """A set or condition name covcontact's input takes (letters, digits, '_', '-')."""
    return re.sub(r"[^A-Za-z0-9_-]", "_", text)
