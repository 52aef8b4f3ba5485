"""Hertz contact set-up shared by the tests (test_hertz.py) and the benchmarks (benchmarks/hertz.py, the
races in benchmarks/peers): the graded quarter ball, the problem, and the measures against Hertz's solution.
No test framework is imported, so that a timed run pays only for covcontact.

Set-up, reference and the meaning of the measures: test_hertz.py.
"""

from __future__ import annotations

import math

import numpy as np

from covcontact.contact.surface import tributary_area
from covcontact.materials import NeoHooke, SaintVenantKirchhoff
from covcontact.mesh import Mesh, faces_on_nodes, hemisphere_solid
from covcontact.problem import (
    Body,
    ContactPair,
    Dirichlet,
    OutputOptions,
    Problem,
    RigidBody,
    Steps,
)

R, E, NU = 1.0, 1.0, 0.3
E_STAR = E / (1.0 - NU**2)
C_HERTZ = 4.0 / 3.0 * E_STAR * math.sqrt(R)
D_MAX = 0.01 * R
MATERIALS = {"svk": SaintVenantKirchhoff, "neo-hooke": NeoHooke}


def grade_to_pole(mesh: Mesh, beta: float = 4.5, gamma: float = 4.0) -> Mesh:
    """Move the nodes of a ``hemisphere_solid`` (focus = 1) toward the pole; the surfaces stay exact.

    In spherical coordinates about the ball centre (rho, polar angle theta from the pole, azimuth):
    the depth s = 1 - rho/R becomes sinh(gamma s)/sinh(gamma) and theta/(pi/2) = x becomes
    x + w (sinh(beta x)/sinh(beta) - x) with w = rho'/R. Element sizes at the pole shrink by
    beta/sinh(beta) in the surface and gamma/sinh(gamma) in depth; the sphere and the flat face
    map onto themselves.
    """
    c = np.array([0.0, 0.0, R])
    v = mesh.points - c
    rho = np.linalg.norm(v, axis=1)
    theta = np.arccos(np.clip(-v[:, 2] / np.maximum(rho, 1e-300), -1.0, 1.0))
    phi = np.arctan2(v[:, 1], v[:, 0])
    rho_new = R * (1.0 - np.sinh(gamma * (1.0 - rho / R)) / math.sinh(gamma))
    x = theta / (0.5 * math.pi)
    theta_new = 0.5 * math.pi * (x + rho_new / R * (np.sinh(beta * x) / math.sinh(beta) - x))
    st = np.sin(theta_new)
    X = c + rho_new[:, None] * np.stack([st * np.cos(phi), st * np.sin(phi), -np.cos(theta_new)], axis=1)
    X[rho < 1e-14 * R] = c
    mesh.points = np.ascontiguousarray(X)
    return mesh


def quarter(mesh: Mesh) -> Mesh:
    """The elements of a half-ball with x >= 0 and y >= 0; adds node sets "symx" and "symy"."""
    tol = 1e-9 * R
    P = mesh.points
    keep = np.all((P[mesh.cells, 0] > -tol) & (P[mesh.cells, 1] > -tol), axis=1)
    cells = mesh.cells[keep]
    used = np.unique(cells)
    new = np.full(mesh.n_nodes, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    q = Mesh(P[used], mesh.cell_type, new[cells])
    for name in ("flat", "curved", "pole"):
        ids = new[mesh.node_sets[name]]
        q.add_node_set(name, ids[ids >= 0])
    q.add_node_set("symx", np.flatnonzero(np.abs(q.points[:, 0]) < tol))
    q.add_node_set("symy", np.flatnonzero(np.abs(q.points[:, 1]) < tol))
    for name in ("flat", "curved"):
        q.add_face_set(name, faces_on_nodes(q, q.node_sets[name]))
    q.add_node_set("all", np.arange(q.n_nodes))
    return q


def hertz_mesh(n: int = 16, nr: int = 8, cell: str = "hex8", beta: float = 4.5, gamma: float = 4.0) -> Mesh:
    """Quarter of a half-ball of radius R graded toward the pole (element size ~ 0.01 R there for n = 16)."""
    return quarter(grade_to_pole(hemisphere_solid(R, n=n, nr=nr, cell=cell, focus=1.0), beta, gamma))


def hertz_problem(mesh: Mesh, material: str, steps: int | tuple[float, ...] = 10, d_max: float = D_MAX,
                  penalty: float = 1e4, clamp: bool = False, vtu: bool = True) -> Problem:
    """The flat face moved down by d_max onto the rigid plane z = 0 in ``steps`` equal steps (or at
    the given load factors)."""
    flat = Dirichlet("ball", "flat", (0, 1, 2), (0.0, 0.0, -d_max)) if clamp else \
        Dirichlet("ball", "flat", (2,), (-d_max,))
    return Problem(
        name="hertz",
        bodies=[Body("ball", mesh, MATERIALS[material](E=E, nu=NU))],
        dirichlet=[flat, Dirichlet("ball", "symx", (0,), (0.0,)), Dirichlet("ball", "symy", (1,), (0.0,))],
        rigid=[RigidBody("floor", shape="plane",
                         params={"point": (0.0, 0.0, 0.0), "normal": (0.0, 0.0, 1.0)})],
        contacts=[ContactPair("floor", ("ball", "curved"), ("floor", ""), penalty=penalty, weighting="area")],
        steps=Steps.equal(steps) if isinstance(steps, int) else Steps(tuple(steps)),
        output=OutputOptions(vtu=vtu),
    )


def fit_hertz(d: np.ndarray, F: np.ndarray) -> tuple[float, float, float]:
    """Least squares: C1 of F = C1 d^1.5, and (C2, B) of F = C2 d^1.5 + B d^2."""
    C1 = float(np.sum(F * d**1.5) / np.sum(d**3))
    C2, B = np.linalg.lstsq(np.stack([d**1.5, d**2], axis=1), F, rcond=None)[0]
    return C1, float(C2), float(B)


def hertz_measures(result, mesh: Mesh, d_max: float = D_MAX, pressure: bool = True) -> dict:
    """Force-indentation of the whole ball and, per step, the contact radius and the central pressure.

    Contact radius: a_m = sqrt(5/2 sum f r^2 / sum f) over the nodal contact forces f at the deformed
    radii r (for the Hertz pressure sum f r^2 / sum f = 2/5 a^2). Central pressure: the largest
    deviation of the VTU ``contact_pressure`` from Hertz's p(r) (a = sqrt(R d)) over r < a/2,
    relative to p0.
    """
    steps = [s for s in result.summary["steps"] if s["converged"]]
    d = np.array([d_max * s["load_factor"] for s in steps])
    F = 4.0 * np.array([s["contact_force"][2] for s in steps])
    C1, C2, B = fit_hertz(d, F)
    out = {"d": d, "F": F, "ratio": F / (C_HERTZ * d**1.5), "C1": C1 / C_HERTZ, "C2": C2 / C_HERTZ, "B": B,
           "active": np.array([s["active_contacts"] for s in steps])}
    if not pressure:
        return out
    import meshio

    area = tributary_area(mesh.points, mesh.face_sets["curved"])
    a_m, p_err = [], []
    for s, dk in zip(steps, d, strict=True):
        vtu = meshio.read(result.out / f"step_{s['step']:04d}.vtu")
        n = mesh.n_nodes
        x = mesh.points + vtu.point_data["displacement"][:n]
        p = vtu.point_data["contact_pressure"][:n]
        act = vtu.point_data["contact_status"][:n] > 0.5
        r = np.hypot(x[:, 0], x[:, 1])
        f = p * area
        a_m.append(math.sqrt(2.5 * np.sum(f[act] * r[act] ** 2) / np.sum(f[act])))
        a = math.sqrt(R * dk)
        p0 = 2.0 * E_STAR * a / (math.pi * R)
        inner = (vtu.point_data["contact_status"][:n] >= 0) & (r < 0.5 * a)
        p_err.append(float(np.max(np.abs(p[inner] - p0 * np.sqrt(1.0 - (r[inner] / a) ** 2))) / p0))
    out["a_ratio"] = np.array(a_m) / np.sqrt(R * d)
    out["p_center_error"] = np.array(p_err)
    return out


def impact_problem(mesh: Mesh, v: float, steps: int = 100, mass: str = "redistributed", density: float = 1.0,
                   span: float = 1.2) -> Problem:
    """The quarter half-ball ``mesh`` (St. Venant-Kirchhoff) touching the rigid plane z = 0 at t = 0 with speed v
    downward, Newmark's trapezoidal rule, ``steps`` steps over ``span`` times Hertz's contact duration t_c
    (:func:`impact_reference`) (tests/verification/test_hertz_impact.py)."""
    from covcontact.problem import Dynamics, InitialVelocity

    t_c = impact_reference(v, density)[0]
    dyn = Dynamics(dt=span * t_c / steps, t_end=span * t_c, method="newmark", mass=mass)
    return Problem(
        name="hertz-impact",
        bodies=[Body("ball", mesh, SaintVenantKirchhoff(E=E, nu=NU, density=density))],
        dirichlet=[Dirichlet("ball", "symx", (0,), (0.0,)), Dirichlet("ball", "symy", (1,), (0.0,))],
        rigid=[RigidBody("floor", shape="plane", params={"point": (0.0, 0.0, 0.0), "normal": (0.0, 0.0, 1.0)})],
        contacts=[ContactPair("floor", ("ball", "curved"), ("floor", ""), penalty=1e4, weighting="area")],
        steps=dyn.steps(), output=OutputOptions(vtu=False), dynamics=dyn,
        initial_velocity=[InitialVelocity("ball", "", (0.0, 0.0, -v))],
    )


def impact_reference(v: float, density: float = 1.0) -> tuple[float, float, float]:
    """Hertz's impact of the half-ball (mass rho 2 pi R^3 / 3) at speed v (Johnson, Contact Mechanics, section
    11.4): (contact duration t_c, peak force F_max, largest indentation)."""
    m = density * 2.0 / 3.0 * math.pi * R ** 3
    t_c = 2.868 * (m ** 2 / (R * E_STAR ** 2 * v)) ** 0.2
    f_max = (5.0 / 4.0) ** 0.6 * (m * v * v) ** 0.6 * (4.0 / 3.0 * E_STAR * math.sqrt(R)) ** 0.4
    depth = (15.0 * m * v * v / (16.0 * E_STAR * math.sqrt(R))) ** 0.4
    return t_c, f_max, depth
