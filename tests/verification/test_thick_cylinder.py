"""Thick-walled cylinder under internal pressure, plane strain, elastic-perfectly plastic J2.

Reference: Hill R. (1950) The Mathematical Theory of Plasticity, Oxford, ch. 5 (the expansion of a
cylindrical tube, plane strain). For an incompressible material (nu = 1/2: the axial stress is the mean of
the radial and hoop stresses everywhere) the von Mises condition in plane strain is
sigma_theta - sigma_r = 2 k with k = sigma_y / sqrt(3). With inner radius a, outer radius b and the
plastic front at radius c (a <= c <= b), the internal pressure is

    p(c) = k (2 ln(c / a) + 1 - c^2 / b^2),

so the bore first yields at p_y = k (1 - a^2 / b^2) and the tube collapses at p_lim = 2 k ln(b / a).
Before yield the Lame solution (plane strain) gives the bore displacement

    u(a) = (1 + nu) / E (a^2 p / (b^2 - a^2)) ((1 - 2 nu) a + b^2 / a).

Set-up: a = 1, b = 2, E = 210000, sigma_y = 240 (sigma_y / E ~ 1e-3: small strain, so the finite-strain
J2 model and the dead pressure stay within ~1e-3 of the small-strain theory), hardening modulus 0. We use
nu = 0.49, nearly incompressible, because Hill's closed form for the plastic range assumes
incompressibility: with nu = 0.3 the elastic axial stress nu (sigma_r + sigma_theta) is not the mean
stress and the front position departs slightly from p(c). F-bar hex8 (no volumetric locking under the
isochoric plastic flow).

Mesh: a quarter of the cross-section (theta in [0, pi/2]), a (r, theta, z) block mapped to
x = r cos theta, y = r sin theta, graded geometrically toward the bore, one element layer in z with
u_z = 0 on both z faces (plane strain), symmetry u_y = 0 on theta = 0 and u_x = 0 on theta = pi/2. The
pressure acts on the block's "xmin" face (r = a); the mapping keeps the orientation (its Jacobian
determinant is r > 0), so the face stays outward-ordered (checked below).

Checks, per load step read from the step VTU files (cell fields ``yield_flag`` and
``equivalent_plastic_strain``, point field ``displacement``):
1. the bore displacement at an elastic step against Lame to 1 %;
2. the step at which the innermost ring first yields: nothing yields before, and the bracketing steps (1 %
   apart) lie within 3 % of p_y;
3. at pressures between first yield and ~90 % of p_lim, the plastic front (outermost ring of elements with
   alpha > 0) against c(p) from inverting p(c), within one radial element size.
"""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest

from covcontact.materials import J2Plasticity
from covcontact.mesh.generators import block
from covcontact.problem import Body, Dirichlet, OutputOptions, Pressure, Problem, SolverOptions, Steps

A, B = 1.0, 2.0
E, NU, SY = 210000.0, 0.49, 240.0
K = SY / math.sqrt(3.0)
N_R, N_T = 24, 8  # radial and circumferential elements
GRADING = 1.05  # ratio of successive radial element sizes (smallest at the bore)

P_YIELD = K * (1.0 - A**2 / B**2)
P_LIMIT = 2.0 * K * math.log(B / A)

ELASTIC = 0.5  # load factors are p / p_y
NEAR_YIELD = (0.995, 1.005, 1.015, 1.025)  # 1 % apart, straddling p_y
FRONT_PRESSURES = (0.80, 0.85, 0.90)  # fractions of p_lim for the front check (last one ~90 %)
FACTORS = (ELASTIC, 0.9, *NEAR_YIELD, *(f * P_LIMIT / P_YIELD for f in FRONT_PRESSURES))


def hill_pressure(c: float) -> float:
    return K * (2.0 * math.log(c / A) + 1.0 - c**2 / B**2)


def hill_front(p: float) -> float:
    """Invert p(c) (monotonic on [a, b]) by bisection."""
    lo, hi = A, B
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if hill_pressure(mid) < p else (lo, mid)
    return 0.5 * (lo + hi)


def lame_bore_displacement(p: float) -> float:
    return (1.0 + NU) / E * (A**2 * p / (B**2 - A**2)) * ((1.0 - 2.0 * NU) * A + B**2 / A)


def radial_nodes() -> np.ndarray:
    s = np.arange(N_R + 1) / N_R
    return A + (B - A) * (GRADING ** (N_R * s) - 1.0) / (GRADING**N_R - 1.0)


def quarter_cylinder():
    m = block(1.0, 1.0, 0.1, N_R, N_T, 1, "hex8")
    U = m.points
    ir = np.rint(U[:, 0] * N_R).astype(int)
    r = radial_nodes()[ir]
    theta = 0.5 * math.pi * U[:, 1]
    m.points = np.stack([r * np.cos(theta), r * np.sin(theta), U[:, 2]], axis=1)
    return m


def test_mesh_bore_faces_point_out_of_the_body():
    m = quarter_cylinder()
    X = m.points
    for f in m.face_set("xmin"):
        n = np.cross(X[f[1]] - X[f[0]], X[f[3]] - X[f[0]])
        centre = X[f].mean(axis=0)
        radial = np.array([centre[0], centre[1], 0.0])
        assert n @ radial < 0.0  # outward of the body = toward the axis
    assert np.allclose(np.hypot(X[m.node_set("xmin"), 0], X[m.node_set("xmin"), 1]), A)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    mesh = quarter_cylinder()
    body = Body("tube", mesh, J2Plasticity(E=E, nu=NU, yield_stress=SY,
                                           hardening={"law": "linear", "modulus": 0.0}), formulation="fbar")
    problem = Problem(
        name="thick-cylinder",
        bodies=[body],
        dirichlet=[Dirichlet("tube", "ymin", (1,), (0.0,)),  # theta = 0
                   Dirichlet("tube", "ymax", (0,), (0.0,)),  # theta = pi/2
                   Dirichlet("tube", "zmin", (2,), (0.0,)),
                   Dirichlet("tube", "zmax", (2,), (0.0,))],
        pressures=[Pressure("tube", "xmin", P_YIELD)],
        steps=Steps(factors=FACTORS),
        solver=SolverOptions(rtol=1e-10),
        output=OutputOptions(vtu=True, checkpoint_every=1000),
    )
    out = tmp_path_factory.mktemp("thick_cylinder")
    result = problem.run(out=out, quiet=True)
    assert result.summary["converged"]
    assert np.allclose([e["load_factor"] for e in result.summary["steps"]], FACTORS)
    steps = []
    for k in range(1, len(FACTORS) + 1):
        vtu = meshio.read(out / f"step_{k:04d}.vtu")
        steps.append({"alpha": np.concatenate(vtu.cell_data["equivalent_plastic_strain"]),
                      "flag": np.concatenate(vtu.cell_data["yield_flag"]),
                      "u": vtu.point_data["displacement"]})
    return mesh, steps, result


def _rings(mesh):
    """Radial index of every element (block lattice: x is the radial direction)."""
    X = mesh.points[mesh.cells]
    rc = np.hypot(X[:, :, 0], X[:, :, 1]).mean(axis=1)
    edges = radial_nodes()
    ring = np.searchsorted(edges, rc) - 1
    return ring, edges


def test_elastic_bore_displacement(run):
    mesh, steps, _ = run
    k = FACTORS.index(ELASTIC)
    p = ELASTIC * P_YIELD
    bore = mesh.node_set("xmin")
    X, U = mesh.points[bore], steps[k]["u"][bore]
    ur = (X[:, 0] * U[:, 0] + X[:, 1] * U[:, 1]) / np.hypot(X[:, 0], X[:, 1])
    ref = lame_bore_displacement(p)
    print(f"bore u_r = {ur.mean():.6e} (spread {np.ptp(ur):.1e}), Lame {ref:.6e}, "
          f"error {ur.mean() / ref - 1:+.2%}")
    assert np.all(steps[k]["alpha"] == 0.0)
    assert np.allclose(ur, ref, rtol=1e-2)


def test_first_yield_pressure(run):
    mesh, steps, _ = run
    ring, _ = _rings(mesh)
    inner = ring == 0
    first = next(k for k, s in enumerate(steps) if s["flag"][inner].max() > 0.0)
    assert first > 0
    p_before, p_first = FACTORS[first - 1] * P_YIELD, FACTORS[first] * P_YIELD
    print(f"first yield between p = {p_before:.3f} and {p_first:.3f}; Hill p_y = {P_YIELD:.3f}")
    # nothing yields anywhere before (the bore is the most stressed point)
    assert all(np.all(s["alpha"] == 0.0) for s in steps[:first])
    # The first Gauss points sit at r_g = a + 0.211 h_0 (h_0 = 0.022: the first radial element), where the
    # elastic solution reaches the yield condition at p_y (r_g / a)^2 = 1.0095 p_y: the FE first yield
    # lies a little above p_y; we ask for it within 3 % of p_y. Measured: between 1.015 and 1.025 p_y (48
    # radial elements, h_0 = 0.005: between 1.005 and 1.01 p_y).
    assert P_YIELD * 0.99 <= p_before < p_first <= P_YIELD * 1.03


def test_plastic_front_radius(run):
    mesh, steps, _ = run
    ring, edges = _rings(mesh)
    for frac in FRONT_PRESSURES:
        k = len(FACTORS) - len(FRONT_PRESSURES) + FRONT_PRESSURES.index(frac)
        p = FACTORS[k] * P_YIELD
        c = hill_front(p)
        plastic = steps[k]["alpha"] > 0.0
        rings_plastic = np.unique(ring[plastic])
        # the plastic zone is a full annulus from the bore: rings 0..m, every element in them
        m = rings_plastic.max()
        assert np.array_equal(rings_plastic, np.arange(m + 1))
        assert np.array_equal(plastic, ring <= m)
        c_fe = edges[m + 1]  # outer radius of the outermost plastic ring
        h = edges[m + 1] - edges[m]
        print(f"p = {p:.2f} ({frac:.0%} p_lim): front FE {c_fe:.4f} (ring {m}, h {h:.4f}), "
              f"Hill c = {c:.4f}, diff {c_fe - c:+.4f}")
        assert abs(c_fe - c) <= h
