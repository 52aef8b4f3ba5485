"""Springback of an elastic-perfectly plastic strip after pure bending in plane strain (docs/verification.md).

Closed form (Gardiner 1957, "The springback of metals", Trans. ASME 79; small strain, rectangular section,
elastic unloading): a strip of thickness t bent to the radius R and released keeps the radius R_f with

    R / R_f = 1 - 3 x + 4 x^3,   x = sigma_0' R / (E' t),

sigma_0' = 2 sigma_y / sqrt(3) and E' = E / (1 - nu^2) in plane strain (valid while the surface yields,
x < 1/2). Set-up: half of the strip (symmetry plane x = 0), one hex8 layer in z with u_z = 0 on both faces
(plane strain), n hex8 F-bar layers through the thickness. Stage 1 turns the end section x = L/2 as a plane
(the x components of its nodes follow the rigid motion of pure bending; the thickness may contract freely)
while its middle node follows in y; stage 2 releases the section (its reactions ramped to zero; the middle
node keeps its y, which removes the rigid translation and carries no load in pure bending). The
curvatures are measured away from the end: the rotation of the section x = L/4 over the arc length of the
middle surface up to it, loaded (R) and released (R_f).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict

E, NU, SY = 200.0e3, 0.3, 200.0  # MPa
T, RADIUS = 1.0, 100.0          # mm: x = 0.105, the surface strain 5 times the yield strain
HALF = 4.0                      # half-length of the strip, mm


def strip_problem(n: int, ratio: float = 2.0, steps: int = 10, release_steps: int = 2,
                  formulation: str = "fbar") -> dict:
    """The problem as a dict (n layers, elements ``ratio`` times longer than thick)."""
    nx = int(round(HALF / (T / n) / ratio))
    theta = HALF / RADIUS
    rows = [[0.0, 0.0, 0.0, 0.0]]
    for k in range(1, 41):  # the end's centre on the arc of radius R / lam: a polyline in lam
        lam = k / 40.0
        rho = RADIUS / lam
        rows.append([lam, rho * np.sin(lam * theta) - HALF, rho * (1.0 - np.cos(lam * theta)), 0.0])
    motion = {"rotation": [0.0, 0.0, theta], "center": [HALF, T / 2, 0.0], "path": rows}
    w = T / n
    return {
        "problem": {"name": "springback", "stage": "bend"},
        "bodies": [{
            "name": "strip", "formulation": formulation,
            "material": {"model": "j2", "E": E, "nu": NU, "yield_stress": SY,
                         "hardening": {"law": "linear", "modulus": 0.0}},
            "mesh": {"generator": "block", "lx": HALF, "ly": T, "lz": w, "nx": nx, "ny": n, "nz": 1},
            "sets": {"endmid": {"box": [[HALF, T / 2, 0.0], [HALF, T / 2, w]]}},
        }],
        "dirichlet": [
            {"set": "strip.xmin", "components": "x"},
            {"set": "strip.zmin", "components": "z"},
            {"set": "strip.zmax", "components": "z"},
            {"name": "turn", "set": "strip.xmax", "components": "x", "motion": motion},
            {"name": "middle", "set": "strip.endmid", "components": "y", "motion": motion},
        ],
        "solver": {"rtol": 1e-10},
        "output": {"vtu": False},
        "steps": {"count": steps},
        "stages": [{"name": "release", "steps": {"count": release_steps}, "release": ["turn"]}],
    }


def curvature(x: np.ndarray, X: np.ndarray, at: float) -> float:
    """Rotation of the section X = at over the arc length of the middle surface from X = 0 to it."""
    sec = np.isclose(X[:, 0], at) & np.isclose(X[:, 2], 0.0)
    s = x[sec][np.argsort(X[sec, 1])]
    d = s[-1] - s[0]
    phi = np.arctan2(-d[0], d[1])
    mid = np.isclose(X[:, 1], T / 2) & np.isclose(X[:, 2], 0.0) & (X[:, 0] <= at + 1e-9)
    pts = x[mid][np.argsort(X[mid, 0])]
    return phi / float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def springback(raw: dict, tmp: Path) -> tuple[float, float, dict]:
    """(loaded curvature, released curvature, summary) at the quarter section."""
    problem = problem_from_dict(raw, tmp / "springback.toml")
    res = problem.run(out=tmp / "out")
    assert res.exit_code == 0, res.summary.get("steps", [])[-1:]
    X = problem.bodies[0].mesh.points
    k_f = curvature(X + res.u.reshape(-1, 3), X, HALF / 2)
    loaded = dict(raw, stages=[])
    problem = problem_from_dict(loaded, tmp / "loaded.toml")
    res_l = problem.run(out=tmp / "out_loaded")
    k = curvature(X + res_l.u.reshape(-1, 3), X, HALF / 2)
    return k, k_f, res.summary


def gardiner(radius: float) -> float:
    x = (2.0 * SY / np.sqrt(3.0)) * radius / (E / (1.0 - NU ** 2) * T)
    return 1.0 - 3.0 * x + 4.0 * x ** 3


def test_springback_of_a_bent_strip_hex8(tmp_path):
    k, k_f, summary = springback(strip_problem(8), tmp_path)
    assert k * RADIUS == pytest.approx(1.0, abs=0.01)  # bent to R (the section stays plane)
    ratio = k_f / k
    expected = gardiner(1.0 / k)
    assert 0.6 < ratio < 0.8  # a large springback: x = 0.105
    assert ratio == pytest.approx(expected, rel=0.02)
    # the release stage unloads elastically: no plastic work in it
    stages = {s["name"]: s for s in summary["stages"]}
    assert stages["bend"]["plastic_dissipation"] > 0.0
    assert abs(stages["release"]["plastic_dissipation"]) < 1e-9 * stages["bend"]["plastic_dissipation"]


def shell_problem(n_points: int, rule: str = "gauss", cell: str = "hex8", nx: int = 8, steps: int = 10) -> dict:
    """The same strip as solid-shells: one element through the thickness (z) with ``n_points`` thickness
    points, plane strain by u_y = 0 on both sides. The end section x = L/2 turns as a plane (x components
    follow the motion, rotation about -y); the bottom node of the symmetry section is held in z (the
    rigid translation), which carries no load in pure bending."""
    theta = HALF / RADIUS
    rows = [[0.0, 0.0, 0.0, 0.0]]
    for k in range(1, 41):
        lam = k / 40.0
        rho = RADIUS / lam
        rows.append([lam, rho * np.sin(lam * theta) - HALF, 0.0, rho * (1.0 - np.cos(lam * theta))])
    motion = {"rotation": [0.0, -theta, 0.0], "center": [HALF, 0.0, T / 2], "path": rows}
    return {
        "problem": {"name": "springback-shell", "stage": "bend"},
        "bodies": [{"name": "strip", "formulation": "solid-shell", "element": cell,
                    "options": {"thickness_points": n_points, "thickness_rule": rule},
                    "material": {"model": "j2", "E": E, "nu": NU, "yield_stress": SY,
                                 "hardening": {"law": "linear", "modulus": 0.0}},
                    "mesh": {"generator": "block", "lx": HALF, "ly": 0.5, "lz": T, "nx": nx, "ny": 1, "nz": 1},
                    "sets": {"pin": {"box": [[0.0, 0.0, 0.0], [0.0, 0.5, 0.0]]}}}],
        "dirichlet": [
            {"set": "strip.xmin", "components": "x"},
            {"set": "strip.ymin", "components": "y"},
            {"set": "strip.ymax", "components": "y"},
            {"set": "strip.pin", "components": "z"},
            {"name": "turn", "set": "strip.xmax", "components": "x", "motion": motion},
        ],
        "solver": {"rtol": 1e-10},
        "output": {"vtu": False},
        "steps": {"count": steps},
        "stages": [{"name": "release", "steps": {"count": 2}, "release": ["turn"]}],
    }


def shell_curvature(x: np.ndarray, X: np.ndarray, at: float) -> float:
    """Rotation of the section X = at (bottom to top node) over the arc length of the middle surface."""
    sec = np.isclose(X[:, 0], at) & np.isclose(X[:, 1], 0.0)
    s = x[sec][np.argsort(X[sec, 2])]
    d = s[-1] - s[0]
    phi = -np.arctan2(d[0], d[2])
    xs = np.unique(np.round(X[X[:, 0] <= at + 1e-9, 0], 9))
    mids = np.array([x[np.isclose(X[:, 0], v) & np.isclose(X[:, 1], 0.0)].mean(axis=0) for v in xs])
    return phi / float(np.linalg.norm(np.diff(mids, axis=0), axis=1).sum())


@pytest.mark.parametrize("cell, nx", [("hex8", 8), ("hex18", 4)])
def test_springback_of_a_bent_strip_solid_shell(tmp_path, cell, nx):
    raw = shell_problem(9, cell=cell, nx=nx)
    problem = problem_from_dict(raw, tmp_path / "shell.toml")
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    X = problem.bodies[0].mesh.points
    k_f = shell_curvature(X + res.u.reshape(-1, 3), X, HALF / 2)
    loaded = problem_from_dict(dict(raw, stages=[]), tmp_path / "loaded.toml").run(out=tmp_path / "loaded")
    k = shell_curvature(X + loaded.u.reshape(-1, 3), X, HALF / 2)
    assert k * RADIUS == pytest.approx(1.0, abs=0.03)
    assert k_f / k == pytest.approx(gardiner(1.0 / k), rel=0.02)
    stages = {s["name"]: s for s in res.summary["stages"]}
    assert abs(stages["release"]["plastic_dissipation"]) < 1e-9 * stages["bend"]["plastic_dissipation"]
