"""What every material shares: the check of its mass density."""

from __future__ import annotations

import math


def check_density(density) -> None:
    """A mass density is None (a static analysis needs none) or finite and > 0."""
    if density is not None and not (math.isfinite(float(density)) and float(density) > 0.0):
        raise ValueError(f"density must be finite and > 0, got density={density}")
