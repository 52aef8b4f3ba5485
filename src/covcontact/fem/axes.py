"""CalculiX's local axes of a unit normal (its contact output's tangential directions, and covcontact's shell frame):
t1 the global x axis projected off n (the z axis where n is nearly x), t2 = n x t1."""

from __future__ import annotations

import numpy as np


def calculix_axes(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t1, t2) of the unit normals ``n`` (..., 3): t1 = x - n_x n normalised, or z - n_z n where 1 - |n_x| <
    1.5231e-6 (CalculiX's bound), and t2 = n x t1."""
    n = np.asarray(n, dtype=np.float64)
    near_x = (1.0 - np.abs(n[..., 0]) < 1.5231e-6)[..., None]
    axis = np.where(near_x, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    t1 = axis - (axis * n).sum(axis=-1, keepdims=True) * n
    t1 = t1 / np.linalg.norm(t1, axis=-1, keepdims=True)
    return t1, np.cross(n, t1)
