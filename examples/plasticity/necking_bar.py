"""Necking of a circular bar in tension (Simo 1988; Simo 1992; Simo & Armero 1992; ANSYS VM318).

A steel bar of length 53.334 mm and radius 6.413 mm whose radius is reduced linearly to 0.982 x 6.413 in the
middle (a 1.8 % imperfection that fixes where the neck forms), pulled by 7 mm at each end (14 mm in all).
J2 plasticity at finite strain with F-bar hex8: E = 206.9 GPa, nu = 0.29 (units mm, N, MPa) and the
saturation + linear hardening of Simo,

    sigma_y(eps_p) = 450 + (715 - 450) (1 - exp(-16.93 eps_p)) + 129.24 eps_p   [MPa],

which is covcontact's Voce law with yield_stress = 450, sigma_inf = 715 (the saturation stress itself, not
the increment 265), delta = 16.93 and the optional linear term modulus = 129.24.

One eighth of the bar by symmetry: x, y >= 0 (a quarter of the cross-section, a square of n x n elements
mapped onto the quarter disc) and 0 <= z <= L/2 (nz elements, twice as fine at the neck z = 0 as at the
pulled end); u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on z = 0 (the middle section), u_z = 7 mm on the end
z = L/2 (free in x and y). The generator is the block mesh of covcontact.mesh.generators; its node
coordinates are moved onto the bar, so the sets xmin, ymin, zmin, zmax keep their meaning.

    python examples/plasticity/necking_bar.py                      # 4 x 12 elements, 56 steps, results/necking-bar
    python examples/plasticity/necking_bar.py --n 8 --nz 24 --steps 112 --out results/necking-fine

Prints, per step, the total elongation, the force on the whole bar (4 x the reaction on the eighth's pulled
end) and the neck radius ratio (current radius in the middle over 6.413); the VTU files in the output
directory show the neck (cell field equivalent_plastic_strain). Reference: the neck radius ratio 0.399 at
14 mm (ANSYS Verification Manual VM318, target radial displacement -3.740 mm of the neck surface, after
Simo 1992); docs/verification.md, "Necking of a circular bar".
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from covcontact.io.loader import problem_from_dict

RADIUS, HALF_LENGTH, IMPERFECTION = 6.413, 53.334 / 2.0, 0.982
E, NU, SIGMA_0, SIGMA_INF, DELTA, H = 206900.0, 0.29, 450.0, 715.0, 16.93, 129.24


def build(n: int = 4, nz: int = 12, steps: int = 56, half_elongation: float = 7.0, vtu: bool = True):
    """The eighth of the bar with n x n elements over the quarter section and nz along the half length."""
    raw = {"problem": {"name": "necking-bar", "units": "mm, N, MPa",
                       "description": "necking of a circular bar (Simo 1988), one eighth, F-bar hex8, J2"},
           "bodies": [{"name": "bar", "formulation": "fbar",
                       "material": {"model": "j2", "E": E, "nu": NU, "yield_stress": SIGMA_0,
                                    "hardening": {"law": "voce", "sigma_inf": SIGMA_INF, "delta": DELTA,
                                                  "modulus": H}},
                       "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": n, "ny": n,
                                "nz": nz}}],
           "dirichlet": [{"set": "bar.xmin", "components": "x"}, {"set": "bar.ymin", "components": "y"},
                         {"set": "bar.zmin", "components": "z"},
                         {"name": "pull", "set": "bar.zmax", "components": "z", "value": half_elongation}],
           "steps": {"count": steps}, "solver": {"line_search": True}, "output": {"vtu": vtu}}
    problem = problem_from_dict(raw, Path("necking_bar.toml"))
    X = problem.bodies[0].mesh.points          # the unit cube, moved onto the bar in place
    x, y, s = X[:, 0].copy(), X[:, 1].copy(), X[:, 2].copy()
    z = HALF_LENGTH * s * (0.5 + 0.5 * s)      # element length at the neck half that at the end
    r = RADIUS * (IMPERFECTION + (1.0 - IMPERFECTION) * z / HALF_LENGTH)
    X[:, 0] = r * x * np.sqrt(1.0 - 0.5 * y * y)   # the unit square onto the quarter disc (x = 0, y = 0 kept)
    X[:, 1] = r * y * np.sqrt(1.0 - 0.5 * x * x)
    X[:, 2] = z
    return problem


def neck_node(problem) -> int:
    """The surface node of the middle section on the plane y = 0."""
    X = problem.bodies[0].mesh.points
    ring = np.flatnonzero((np.abs(X[:, 2]) < 1e-9) & (np.abs(X[:, 1]) < 1e-9))
    return int(ring[np.argmax(X[ring, 0])])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=4, help="elements along each side of the quarter section")
    ap.add_argument("--nz", type=int, default=12, help="elements along the half length")
    ap.add_argument("--steps", type=int, default=56, help="equal load steps to 14 mm")
    ap.add_argument("--out", default="results/necking-bar")
    args = ap.parse_args()
    import meshio

    problem = build(args.n, args.nz, args.steps)
    res = problem.run(out=args.out, quiet=False)
    X = problem.bodies[0].mesh.points
    k = neck_node(problem)
    files = sorted(Path(args.out).glob("step_*.vtu"))[1:]     # step_0000 is the initial state
    print(" step  elongation [mm]  force [kN]  neck radius / 6.413")
    for entry, f in zip(res.summary["steps"], files):
        u = meshio.read(f).point_data["displacement"]
        print(f"{entry['step']:5d}  {2.0 * 7.0 * entry['load_factor']:15.3f}  "
              f"{4.0 * entry['reactions']['bar.zmax'][2] / 1e3:10.2f}  {(X[k, 0] + u[k, 0]) / RADIUS:19.4f}")
    raise SystemExit(res.exit_code)


if __name__ == "__main__":
    main()
