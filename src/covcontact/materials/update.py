"""One compiled entry point for every material, with or without history (docs/theory.md section 1).

``material_update(kind, params, F, hist_n, hist, S, D)`` returns the second Piola-Kirchhoff stress S (6,)
and the algorithmic tangent D = dS/dE (6, 6) (Voigt order 11, 22, 33, 12, 23, 13, engineering shears) at
the deformation gradient F. ``hist_n`` is the committed history of the material point (read only) and
``hist`` receives the trial history; hyperelastic materials have none (arrays of length 0), the J2
material (kind J2, covcontact.materials.plasticity) has NHIST values per point. Returns 0, or a non-zero
status when the point is inadmissible (1: det F <= 0; 2: the return mapping did not converge).
"""

from __future__ import annotations

from numba import njit

from .hyperelastic import material_response, material_response_h
from .plasticity_kernels import J2, j2_response, j2_response_h


@njit(cache=True)
def material_update(kind, params, F, hist_n, hist, S, D):
    if kind == J2:
        return j2_response(params, F, hist_n, hist, S, D)
    for k in range(hist.shape[0]):
        hist[k] = hist_n[k]
    return material_response(kind, params, F, S, D)


@njit(cache=True)
def material_update_h(kind, params, F, H, hist_n, hist, S, D):
    """``material_update`` with the displacement gradient H = F - I as the element formed it from the displacements
    (every digit of a small strain kept)."""
    if kind == J2:
        return j2_response_h(params, F, H, hist_n, hist, S, D)
    for k in range(hist.shape[0]):
        hist[k] = hist_n[k]
    return material_response_h(kind, params, F, H, S, D)
