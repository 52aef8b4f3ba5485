"""covcontact: covariant node-to-surface contact for large-deformation finite elements."""

__version__ = "0.1.0"
