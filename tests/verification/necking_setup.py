"""The necking bar of Simo (1988) and Simo & Armero (1992): one eighth of a circular bar, F-bar hex8, J2 with
saturation and linear hardening (docs/verification.md, "Necking of a circular bar"). Used by
tests/verification/test_necking.py and benchmarks/necking.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from covcontact.io.loader import problem_from_dict

#: geometry (mm) and material (MPa) as published: length 53.334, radius 6.413, radius 0.982 R in the middle
RADIUS, HALF_LENGTH, IMPERFECTION = 6.413, 53.334 / 2.0, 0.982
E, NU, SIGMA_0, SIGMA_INF, DELTA, H = 206900.0, 0.29, 450.0, 715.0, 16.93, 129.24


def necking_problem(n: int, nz: int, steps: int, half_elongation: float = 7.0):
    """The eighth of the bar (x, y >= 0, 0 <= z <= L/2; symmetry on x = 0, y = 0, z = 0) with n x n elements
    over the quarter cross-section (a square mapped onto the quarter disc) and nz along the half length,
    twice as fine at the neck (z = 0) as at the pulled end; the end moves by ``half_elongation`` along z
    (free in x and y). The radius grows linearly from 0.982 R in the middle to R at the end."""
    raw = {"problem": {"name": "necking-bar", "units": "mm, N, MPa"},
           "bodies": [{"name": "bar", "formulation": "fbar",
                       "material": {"model": "j2", "E": E, "nu": NU, "yield_stress": SIGMA_0,
                                    "hardening": {"law": "voce", "sigma_inf": SIGMA_INF, "delta": DELTA,
                                                  "modulus": H}},
                       "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": n, "ny": n,
                                "nz": nz}}],
           "dirichlet": [{"set": "bar.xmin", "components": "x"}, {"set": "bar.ymin", "components": "y"},
                         {"set": "bar.zmin", "components": "z"},
                         {"name": "pull", "set": "bar.zmax", "components": "z", "value": half_elongation}],
           "steps": {"count": steps}, "solver": {"line_search": True}, "output": {"vtu": False}}
    problem = problem_from_dict(raw, Path("necking_bar.toml"))
    X = problem.bodies[0].mesh.points
    x, y, s = X[:, 0].copy(), X[:, 1].copy(), X[:, 2].copy()
    z = HALF_LENGTH * s * (0.5 + 0.5 * s)
    r = RADIUS * (IMPERFECTION + (1.0 - IMPERFECTION) * z / HALF_LENGTH)
    X[:, 0] = r * x * np.sqrt(1.0 - 0.5 * y * y)  # the square onto the quarter disc, x = 0 and y = 0 kept
    X[:, 1] = r * y * np.sqrt(1.0 - 0.5 * x * x)
    X[:, 2] = z
    return problem


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
