"""Python twin of sphere_q9.toml: the seed paper's Example 2 built with the covcontact API.

A steel-like plate (St. Venant-Kirchhoff, E = 210 GPa, nu = 0.3; units mm, N, MPa), 90 x 40 x 1 mm, clamped
along x = 0, bent over a rigid sphere (radius 30 mm, top at a third of the span) by non-symmetric dead loads:
1500 N on the free edge x = 90 and 1000 N on the long free edge y = 40. Biquadratic solid-shell elements
(hex18, quad9 master facets); the meshed rigid sphere cap carries the slave nodes.

    python examples/paper/sphere_q9.py                 # one run, tangent case a, into results/sphere-q9
    python examples/paper/sphere_q9.py --study         # cases a, b, c, d, exact (the paper's Table 1)
    python examples/paper/sphere_q9.py --steps 10 --nx 9 --ny 4

``build()`` returns the same Problem as ``load_problem("examples/paper/sphere_q9.toml")``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from covcontact.elements.solidshell import check_options
from covcontact.materials import SaintVenantKirchhoff
from covcontact.mesh.generators import plate, sphere_patch
from covcontact.problem import (
    Body,
    ContactPair,
    Dirichlet,
    NodalForce,
    OutputOptions,
    Problem,
    RigidBody,
    SolverOptions,
    Steps,
)

SPHERE_CENTRE = (30.3, 20.3, -30.001)   # top 1e-3 mm below the plate, off the plate's node grid


def build(nx: int = 18, ny: int = 8, n_phi: int = 48, n_theta: int = 12, penalty: float = 1.0e4,
          steps: int = 100, formulation: str = "solid-shell") -> Problem:
    """The sphere example with ``nx x ny`` hex18 plate elements and an ``n_phi``/``n_theta`` rigid cap."""
    mesh = plate(90.0, 40.0, 1.0, nx, ny, cell="hex18")
    options = check_options(mesh, {}) if formulation == "solid-shell" else {}
    shell = Body("plate", mesh, SaintVenantKirchhoff(E=2.1e5, nu=0.3), formulation, options)
    cap = sphere_patch(29.5, 0.0, 1.2, 0.0, 2.0 * math.pi, 1.0, n_theta, n_phi, cell="hex8",
                       center=SPHERE_CENTRE)
    sphere = RigidBody("sphere", mesh=cap, shape="mesh")
    return Problem(
        name="sphere-q9",
        description="shell (hex18 solid-shell, quad9 master) bent over a rigid meshed sphere (slave nodes) "
                    "by non-symmetric forces",
        bodies=[shell],
        rigid=[sphere],
        contacts=[ContactPair("contact1", slave=("sphere", "outer"), master=("plate", "bottom"),
                              penalty=penalty, weighting="area", tangent="a")],
        dirichlet=[Dirichlet("plate", "xmin", (0, 1, 2), (0.0, 0.0, 0.0))],
        forces=[NodalForce("plate", "xmax", (0.0, 0.0, -1500.0), "total"),
                NodalForce("plate", "ymax", (0.0, 0.0, -1000.0), "total")],
        steps=Steps.equal(steps),
        solver=SolverOptions(rtol=1e-8, etol=1e-16, max_iterations=25, predictor="tangent"),
        output=OutputOptions(vtu=True, every=10, pictures=True),
        source=Path(__file__),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", action="store_true", help="run the cases a, b, c, d, exact")
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--nx", type=int, default=18)
    ap.add_argument("--ny", type=int, default=8)
    ap.add_argument("--penalty", type=float, default=1.0e4)
    ap.add_argument("--out", default="results/sphere-q9")
    args = ap.parse_args()
    problem = build(nx=args.nx, ny=args.ny, penalty=args.penalty, steps=args.steps)
    if args.study:
        from covcontact.study import run_study

        raise SystemExit(run_study(problem, ["a", "b", "c", "d", "exact"], Path(args.out), quiet=False))
    result = problem.run(out=args.out, quiet=False)
    print(f"total iterations {result.summary['total_iterations']}, wall time {result.summary['wall_time_s']:.1f} s")
    raise SystemExit(result.exit_code)


if __name__ == "__main__":
    main()
