"""The necking bar of Simo (1988) and Simo & Armero (1992): one eighth of a circular bar, F-bar hex8, J2 with
saturation and linear hardening (docs/verification.md, "Necking of a circular bar"). Used by
tests/verification/test_necking.py and benchmarks/necking.py."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

# the bar itself is the stand-alone example's (geometry, material, mesh, supports): one definition for the
# example, this test set-up and benchmarks/necking.py
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples" / "plasticity"))
from necking_bar import DELTA, HALF_LENGTH, IMPERFECTION, NU, RADIUS, SIGMA_0, SIGMA_INF, E, H, build

__all__ = ["HALF_LENGTH", "IMPERFECTION", "NU", "RADIUS", "VM318_NECK_RATIO", "VM318_U", "E", "considere_peak",
           "necking_problem", "results"]

#: the published neck: ANSYS Verification Manual VM318 (after Simo 1992, CMAME 99, 61-112), radial displacement
#: of the neck surface node (initial radius 0.982 x 6.413) at 7 mm per end, and the radius ratio it gives (0.3988)
VM318_U = -3.740
VM318_NECK_RATIO = (IMPERFECTION * RADIUS + VM318_U) / RADIUS


def necking_problem(n: int, nz: int, steps: int, half_elongation: float = 7.0):
    """The eighth of the bar (x, y >= 0, 0 <= z <= L/2; symmetry on x = 0, y = 0, z = 0) with n x n elements
    over the quarter cross-section (a square mapped onto the quarter disc) and nz along the half length,
    twice as fine at the neck (z = 0) as at the pulled end; the end moves by ``half_elongation`` along z
    (free in x and y). The radius grows linearly from 0.982 R in the middle to R at the end. No VTU output."""
    return build(n, nz, steps, half_elongation, vtu=False)


def results(problem, res) -> dict:
    """Force on the whole bar (4 x the eighth's reaction) against the total elongation, and the current
    radius over 6.413 at the neck (z = 0) and at the pulled end, at the last step."""
    X = problem.bodies[0].mesh.points
    u = np.asarray(res.u).reshape(-1, 3)
    steps = res.summary["steps"]
    force = [4.0 * s["reactions"]["bar.zmax"][2] for s in steps]
    elong = [2.0 * problem.dirichlet[-1].values[0] * s["load_factor"] for s in steps]

    def ratio(z0: float) -> float:
        ring = np.flatnonzero((np.abs(X[:, 2] - z0) < 1e-9) & (np.abs(X[:, 1]) < 1e-9))
        k = ring[np.argmax(X[ring, 0])]
        return float((X[k, 0] + u[k, 0]) / RADIUS)

    k = int(np.argmax(force))
    return {"force": force, "elongation": elong, "peak_force": force[k], "peak_elongation": elong[k],
            "neck_ratio": ratio(0.0), "end_ratio": ratio(HALF_LENGTH),
            "iterations": res.summary["total_iterations"]}


def considere_peak(radius: float) -> float:
    """Largest force of a uniform bar of this radius (Considere 1885: d sigma / d eps = sigma in true stress
    and logarithmic strain), with the hardening law above; elastic strain sigma / E added to the plastic
    one, volume constant."""
    def sig(ep):
        return SIGMA_0 + (SIGMA_INF - SIGMA_0) * (1.0 - np.exp(-DELTA * ep)) + H * ep

    def slope(ep):  # d sigma / d eps_total
        d = (SIGMA_INF - SIGMA_0) * DELTA * np.exp(-DELTA * ep) + H
        return d / (1.0 + d / E)

    ep = brentq(lambda e: slope(e) - sig(e), 1e-8, 2.0)
    return float(sig(ep) * np.pi * radius**2 * np.exp(-(ep + sig(ep) / E)))
