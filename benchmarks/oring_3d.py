"""The O-ring of examples/contact/oring_groove.toml (axisymmetric, Mooney-Rivlin, F-bar quad4, squeezed 25 % in its
groove in 20 steps) against the same seal as a 3D sector: its section revolved about the y axis by ``--angle``
degrees in ``--layers`` hex8 layers (F-bar), the cut at theta = 0 held along z, the one at theta = angle by the
equation u . n = 0 per node (n its normal), the groove's walls the rigid cylinders r = 16.4 (outside) and r = 23.6
(a hole), the lid and bottom the same planes. Per model: dofs, Newton iterations, seconds (each solve in this process
after a warm-up of each), and the lid force of the whole ring (the sector's times 360 / angle) at each step, the
largest difference over the steps relative to the section's force there.

    python benchmarks/oring_3d.py [--angle 2] [--layers 1] [--out oring_3d.json]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import emit  # noqa: E402

EXAMPLE = ROOT / "examples" / "contact" / "oring_groove.toml"


def revolve(section, angle: float, layers: int):
    """The hex8 sector (and its node and face sets) of the quad4 ``section`` (x the radius, y the axis) turned about
    the y axis by ``angle`` degrees in ``layers`` layers: node (r, y) of layer k at (r cos t, y, -r sin t),
    t = k angle / layers (the cells turned to a positive volume)."""
    from covcontact.mesh import Mesh
    from covcontact.mesh.faces import check_orientation, faces_on_nodes

    P, cells = section.points, section.cells
    n = P.shape[0]
    t = np.radians(angle) * np.arange(layers + 1) / layers
    X = np.vstack([np.column_stack([P[:, 0] * np.cos(a), P[:, 1], -P[:, 0] * np.sin(a)]) for a in t])
    hexes = np.vstack([np.hstack([cells + k * n, cells + (k + 1) * n]) for k in range(layers)])
    mesh = Mesh(X, "hex8", hexes)
    if check_orientation(mesh):
        hexes = np.hstack([hexes[:, 4:], hexes[:, :4]])
        mesh = Mesh(X, "hex8", hexes)
    assert not check_orientation(mesh)
    outer = np.concatenate([section.node_sets["outer"] + k * n for k in range(layers + 1)])
    mesh.add_face_set("outer", faces_on_nodes(mesh, outer))
    mesh.add_node_set("outer", np.unique(outer))
    mesh.add_node_set("equator", np.concatenate([section.node_sets["equator"] + k * n for k in range(layers + 1)]))
    mesh.add_node_set("cut0", np.arange(n))
    for i in range(n):  # (the far cut's nodes one by one: the equations' terms)
        mesh.add_node_set(f"c{i}", np.array([layers * n + i]))
    return mesh, n


def sector_problem(section_problem, angle: float, layers: int):
    from covcontact.loads import Equation
    from covcontact.problem import Body, ContactPair, Dirichlet, RigidBody

    sec = section_problem.bodies[0]
    mesh, n = revolve(sec.mesh, angle, layers)
    a = np.radians(angle)
    normal = (-np.sin(a), np.cos(a))  # (the far cut's normal in (x, z): u_x nx + u_z nz = 0)
    eqs = [Equation([("ring", f"c{i}", 2, normal[1]), ("ring", f"c{i}", 0, normal[0])]) for i in range(n)]
    rigid = {r.name: r for r in section_problem.rigid}
    walls = [RigidBody("wall_in", shape="cylinder", params={"center": (0.0, 0.0, 0.0), "axis": (0.0, 1.0, 0.0),
                                                            "radius": 16.4, "outside": True}),
             RigidBody("wall_out", shape="cylinder", params={"center": (0.0, 0.0, 0.0), "axis": (0.0, 1.0, 0.0),
                                                             "radius": 23.6, "outside": False})]
    contacts = [ContactPair(c.name, ("ring", "outer"), c.master, penalty=c.penalty, weighting="area")
                for c in section_problem.contacts]
    problem = type(section_problem)(
        name="oring-sector", bodies=[Body("ring", mesh, sec.material, formulation="fbar")],
        dirichlet=[Dirichlet("ring", "equator", (1,), (-0.625,)), Dirichlet("ring", "cut0", (2,), (0.0,))],
        equations=eqs, rigid=[rigid["bottom"], rigid["lid"]] + walls, contacts=contacts, steps=section_problem.steps)
    problem.output.vtu = False
    problem.output.pictures = False
    return problem


def _solve(problem, out: Path, scale: float) -> dict:
    t0 = time.perf_counter()
    res = problem.run(out=out, quiet=True)
    wall = time.perf_counter() - t0
    assert res.exit_code == 0, problem.name
    lid = [scale * abs(s["contact_force_on"]["lid"][1]) for s in res.summary["steps"] if s["converged"]]
    return {"dofs": res.summary["dofs"], "iterations": res.summary["total_iterations"], "wall_s": round(wall, 3),
            "lid_force": lid}


def main() -> None:
    from covcontact.io.loader import load_problem

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--angle", type=float, default=2.0, help="the sector's angle, degrees")
    ap.add_argument("--layers", type=int, default=1, help="hex8 layers across the sector")
    ap.add_argument("--out", default=None, help="JSON file (default: stdout)")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        section = load_problem(EXAMPLE)
        section.output.vtu = False
        section.output.pictures = False
        _solve(load_problem(EXAMPLE), work / "warm2d", 1.0)   # (warm-up: nothing compiled while timed)
        _solve(sector_problem(load_problem(EXAMPLE), args.angle, args.layers), work / "warm3d", 1.0)
        axi = _solve(section, work / "axi", 1.0)
        sector = _solve(sector_problem(load_problem(EXAMPLE), args.angle, args.layers), work / "sector",
                        360.0 / args.angle)
    fa, fs = np.array(axi["lid_force"]), np.array(sector["lid_force"])
    diff = np.abs(fs - fa) / np.maximum(np.abs(fa), 1e-300)
    rows = ["| model | dofs | Newton iterations | seconds | lid force at the end (N) |", "|---|---|---|---|---|",
            f"| axisymmetric section (quad4, F-bar) | {axi['dofs']} | {axi['iterations']} | {axi['wall_s']:.2f} | "
            f"{fa[-1]:.6g} |",
            f"| 3D sector {args.angle:g} deg, {args.layers} layer(s) (hex8, F-bar) | {sector['dofs']} | "
            f"{sector['iterations']} | {sector['wall_s']:.2f} | {fs[-1]:.6g} |",
            f"\nlid force, sector against section: largest relative difference over the 20 steps {diff.max():.2e} "
            f"(at the end {diff[-1]:.2e}); time ratio {axi['wall_s'] / sector['wall_s']:.3f}"]
    emit({"angle": args.angle, "layers": args.layers, "axisymmetric": axi, "sector": sector,
          "max_relative_difference": float(diff.max())}, args.out, "\n".join(rows))


if __name__ == "__main__":
    main()
