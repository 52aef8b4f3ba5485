"""Covariant node-to-surface contact: projection, search, contact element, analytic rigid surfaces."""

from covcontact.contact.analytic import Cylinder, Plane, Sphere
from covcontact.contact.driver import (
    EDGE,
    FACET,
    NO_CONTACT,
    VERTEX,
    ProjectionResult,
    closest_points,
    project_slaves,
)
from covcontact.contact.element import (
    CASE_A,
    CASE_B,
    CASE_C,
    CASE_D,
    CASE_EXACT,
    CASES,
    PART_NAMES,
    ContactResult,
    node_to_surface,
)
from covcontact.contact.friction import (
    HIST_SIZE,
    NEW,
    OPEN,
    SLIP,
    STICK,
    FrictionResult,
    analytic_friction_batch,
    friction_batch,
    make_history,
    new_history,
    node_to_surface_friction,
    surface_friction,
    transfer_history,
)
from covcontact.contact.kernels import contact_batch
from covcontact.contact.projection import project_on_facet
from covcontact.contact.search import candidates
from covcontact.contact.surface import MeshSurface, tributary_area
from covcontact.contact.tool_profile import Profile
from covcontact.motion import RigidMotion

__all__ = [
    "HIST_SIZE",
    "NEW",
    "OPEN",
    "SLIP",
    "STICK",
    "FrictionResult",
    "analytic_friction_batch",
    "friction_batch",
    "make_history",
    "new_history",
    "node_to_surface_friction",
    "surface_friction",
    "transfer_history",
    "EDGE",
    "FACET",
    "NO_CONTACT",
    "VERTEX",
    "MeshSurface",
    "ProjectionResult",
    "candidates",
    "closest_points",
    "project_slaves",
    "tributary_area",
    "CASES",
    "CASE_A",
    "CASE_B",
    "CASE_C",
    "CASE_D",
    "CASE_EXACT",
    "PART_NAMES",
    "ContactResult",
    "Cylinder",
    "Plane",
    "Profile",
    "RigidMotion",
    "Sphere",
    "contact_batch",
    "node_to_surface",
    "project_on_facet",
]
