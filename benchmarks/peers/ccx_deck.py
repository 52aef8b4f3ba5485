"""Write the Hertz problem of tests/verification/test_hertz.py as a CalculiX input deck.

The deck is built from covcontact's own hex8 mesh (node and element numbers are the covcontact
indices plus one, so results map back without a search). It holds:

- the ball: C3D8 elements (same node order as covcontact's hex8), the material as
  ``*ELASTIC`` (under NLGEOM a St. Venant-Kirchhoff law: second Piola-Kirchhoff stress linear in
  the Green-Lagrange strain, the same law as covcontact's "svk") or ``*HYPERELASTIC, NEO HOOKE``
  with the small-strain moduli of covcontact's "neo-hooke" (C10 = mu/2, D1 = 2/K), whose
  volumetric part differs at finite strain;
- the rigid plane z = 0: a slab of C3D8 elements below it with every node fixed, its top faces the
  master surface;
- node-to-surface penalty contact, slave = the element faces of the curved surface, with a linear
  pressure-overclosure law whose slope is covcontact's area-weighted penalty (pressure per
  penetration);
- symmetry x = 0 and y = 0, the flat face moved down by d_max in ``steps`` fixed increments of a
  single NLGEOM step (a ramp), every increment printed: the total reaction force of the flat face,
  the displacements of the curved surface and the contact stresses.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from covcontact.materials import lame
from covcontact.mesh import Mesh
from covcontact.mesh.faces import boundary_faces

#: corner nodes (0-based, local) of the faces S1..S6 of a C3D8 element
C3D8_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


@dataclass(frozen=True)
class DeckInfo:
    """Counts and numbering of a written deck."""

    n_nodes: int          # all nodes (deformable bodies + rigid plane)
    n_elements: int       # all elements (deformable bodies + rigid plane)
    body_nodes: int       # nodes of the deformable bodies (the ball; both blocks)
    body_elements: int    # elements of the deformable bodies
    slave_faces: int
    master_faces: int
    rigid_node0: int      # first node number of the rigid plane (1-based; n_nodes + 1 without one)


def face_numbers(mesh: Mesh, set_name: str) -> tuple[np.ndarray, np.ndarray]:
    """(element index 0-based, CalculiX face number 1..6) of every face of a face set of a hex8 mesh."""
    if mesh.cell_type != "hex8":
        raise ValueError(f"only hex8 (C3D8) is written, got {mesh.cell_type}")
    bf, elem, _ = boundary_faces(mesh)
    keys = {tuple(sorted(f[:4])): e for f, e in zip(bf.tolist(), elem.tolist(), strict=True)}
    local = [frozenset(f) for f in C3D8_FACES]
    elems, nums = [], []
    for f in mesh.face_sets[set_name].tolist():
        e = keys[tuple(sorted(f[:4]))]
        pos = {int(np.flatnonzero(mesh.cells[e] == a)[0]) for a in f[:4]}
        elems.append(e)
        nums.append(local.index(frozenset(pos)) + 1)
    return np.array(elems, dtype=np.int64), np.array(nums, dtype=np.int64)


def _ids(values, per_line: int = 12) -> str:
    v = [str(int(x)) for x in values]
    return "\n".join(", ".join(v[i:i + per_line]) for i in range(0, len(v), per_line))


def _node_block(nset: str, first: int, points) -> list[str]:
    """``*NODE`` lines of ``points`` numbered from ``first``."""
    return [f"*NODE, NSET={nset}"] + [f"{first + a}, {x:.12e}, {y:.12e}, {z:.12e}"
                                      for a, (x, y, z) in enumerate(np.asarray(points).tolist())]


def _element_block(elset: str, first: int, cells) -> list[str]:
    """``*ELEMENT`` lines (C3D8) of ``cells``, which hold node numbers, numbered from ``first``."""
    return [f"*ELEMENT, TYPE=C3D8, ELSET={elset}"] + [f"{first + e}, " + ", ".join(str(a) for a in c)
                                                      for e, c in enumerate(np.asarray(cells).tolist())]


def _plane(n0: int, e0: int, lo: float, hi: float, nxy: int, depth: float):
    """Nodes and C3D8 elements of a slab lo <= x, y <= hi, -depth <= z <= 0 (one layer)."""
    t = np.linspace(lo, hi, nxy + 1)
    nodes, idx = [], {}
    for k, z in enumerate((-depth, 0.0)):
        for j, y in enumerate(t):
            for i, x in enumerate(t):
                idx[i, j, k] = n0 + len(nodes)
                nodes.append((x, y, z))
    elems, top = [], []
    for j in range(nxy):
        for i in range(nxy):
            c = [idx[i, j, 0], idx[i + 1, j, 0], idx[i + 1, j + 1, 0], idx[i, j + 1, 0],
                 idx[i, j, 1], idx[i + 1, j, 1], idx[i + 1, j + 1, 1], idx[i, j + 1, 1]]
            top.append(e0 + len(elems))
            elems.append(c)
    return nodes, elems, top


def hertz_deck(mesh: Mesh, material: str, E: float, nu: float, d_max: float, steps: int,
               penalty: float, sigma_inf: float | None = None, plane_n: int = 4,
               stress_scale: float = 1.0, frd: bool = True) -> tuple[str, DeckInfo]:
    """The deck text and its counts.

    Args:
        mesh: hex8 quarter ball with node sets flat, symx, symy, curved and face set curved.
        material: "svk" (*ELASTIC under NLGEOM) or "neo-hooke" (*HYPERELASTIC, NEO HOOKE).
        steps: number of equal, fixed increments from 0 to d_max.
        penalty: slope of the linear pressure-overclosure law (pressure per penetration).
        sigma_inf: the tension of CalculiX's node-to-surface law at large clearance, which it requires
            to be positive (stress units of the problem, before ``stress_scale``); default 1e-9 * penalty,
            the pressure of a penetration of 1e-9 length units (1e-7 * penalty changes the force by
            1e-5 relative at d = 0.01 R, n = 12).
        plane_n: plane elements per side.
        stress_scale: unit of stress of the deck relative to the problem's (E, penalty and sigma_inf are
            multiplied by it; forces and pressures read back are divided by it). CalculiX's residual
            check compares forces with constants of its own, so E = 1 makes it accept iterates early.
        frd: also write displacements and contact stresses to the .frd result file (as covcontact
            writes a VTU per step).
    """
    if material not in ("svk", "neo-hooke"):
        raise ValueError(f"material must be 'svk' or 'neo-hooke', got {material!r}")
    sigma_inf = penalty * 1e-9 if sigma_inf is None else sigma_inf
    S = float(stress_scale)
    E, penalty, sigma_inf = E * S, penalty * S, sigma_inf * S
    nb, eb = mesh.n_nodes, mesh.n_cells
    P = mesh.points
    lines = ["*HEADING", f"Hertz quarter ball, {eb} C3D8, {material}, d = {d_max:g} in {steps} increments"]
    lines += _node_block("NBALL", 1, P) + _element_block("EBALL", 1, mesh.cells + 1)
    size = float(np.max(np.abs(P[:, :2]))) * 1.25
    pn, pe, ptop = _plane(nb + 1, eb + 1, -0.25 * size, size, plane_n, 0.1 * size)
    lines += _node_block("NPLANE", nb + 1, pn) + _element_block("EPLANE", eb + 1, pe)
    for name in ("flat", "symx", "symy", "curved"):
        lines.append(f"*NSET, NSET=N{name.upper()}")
        lines.append(_ids(mesh.node_sets[name] + 1))
    se, sf = face_numbers(mesh, "curved")
    lines.append("*SURFACE, NAME=SBALL, TYPE=ELEMENT")
    lines += [f"{e + 1}, S{f}" for e, f in zip(se.tolist(), sf.tolist(), strict=True)]
    lines.append("*SURFACE, NAME=MPLANE, TYPE=ELEMENT")
    lines += [f"{e}, S2" for e in ptop]
    lines += ["*MATERIAL, NAME=BALL"]
    if material == "svk":
        lines += ["*ELASTIC", f"{E:.12e}, {nu:.12e}"]
    else:
        C10, D1 = c10_d1(E, nu)
        lines += ["*HYPERELASTIC, NEO HOOKE", f"{C10:.12e}, {D1:.12e}"]
    # the plane's elements carry a material but all their nodes are fixed
    lines += ["*MATERIAL, NAME=PLANE", "*ELASTIC", f"{1000.0 * E:.12e}, 0.3",
              "*SOLID SECTION, ELSET=EBALL, MATERIAL=BALL",
              "*SOLID SECTION, ELSET=EPLANE, MATERIAL=PLANE",
              "*SURFACE INTERACTION, NAME=FLOOR",
              "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
              f"{penalty:.12e}, {sigma_inf:.12e}",
              "*CONTACT PAIR, INTERACTION=FLOOR, TYPE=NODE TO SURFACE",
              "SBALL, MPLANE",
              "*BOUNDARY",
              "NPLANE, 1, 3",
              "NSYMX, 1, 1",
              "NSYMY, 2, 2",
              f"*STEP, NLGEOM, INC={100 * steps}",
              "*STATIC, DIRECT",
              f"{1.0 / steps:.12e}, 1.0",
              "*BOUNDARY",
              f"NFLAT, 3, 3, {-d_max:.12e}",
              "*NODE PRINT, NSET=NFLAT, TOTALS=ONLY",
              "RF",
              "*NODE PRINT, NSET=NCURVED",
              "U",
              "*CONTACT PRINT",
              "CSTR"]
    if frd:
        lines += ["*NODE FILE", "U", "*CONTACT FILE", "CSTR"]
    lines += ["*END STEP", ""]
    info = DeckInfo(n_nodes=nb + len(pn), n_elements=eb + len(pe), body_nodes=nb, body_elements=eb,
                    slave_faces=len(se), master_faces=len(ptop), rigid_node0=nb + 1)
    return "\n".join(lines), info


def c10_d1(E: float, nu: float) -> tuple[float, float]:
    """NEO HOOKE constants with covcontact's small-strain shear and bulk moduli: C10 = mu/2, D1 = 2/K."""
    lam, mu = lame(E, nu)
    return mu / 2.0, 2.0 / (lam + 2.0 * mu / 3.0)


def bodies_deck(problem, penalty: float | None = None, sigma_inf: float | None = None,
                stress_scale: float = 1.0, report: tuple[str, str] = ("punch", "zmax")) -> tuple[str, DeckInfo]:
    """A covcontact problem of deformable hex8 bodies (St. Venant-Kirchhoff), constant Dirichlet conditions and
    one node-to-surface contact pair as a CalculiX deck (e.g. the two blocks of benchmarks/problems).

    Bodies are numbered in the problem's order: node and element numbers are covcontact's global indices plus
    one. Zero Dirichlet values are fixed in the model, non-zero ones ramped over one NLGEOM step of
    ``len(problem.steps.factors)`` fixed equal increments. ``penalty`` (default: the pair's) is covcontact's
    area-weighted penalty, the slope of CalculiX's linear pressure-overclosure law; ``sigma_inf`` and
    ``stress_scale`` as in :func:`hertz_deck`. The total reaction of node set ``report`` (body, set) is printed
    per increment.
    """
    from covcontact.materials import SaintVenantKirchhoff

    if len(problem.contacts) != 1 or problem.contacts[0].weighting != "area":
        raise ValueError("one contact pair with the area-weighted penalty is written")
    c = problem.contacts[0]
    k = float(c.penalty if penalty is None else penalty)
    sigma_inf = k * 1e-9 if sigma_inf is None else sigma_inf
    S = float(stress_scale)
    factors = problem.steps.factors
    steps = len(factors)
    if not np.allclose(factors, np.arange(1, steps + 1) / steps):
        raise ValueError("only equal load steps are written")
    lines = ["*HEADING", f"{problem.name}: {len(problem.bodies)} bodies, node-to-surface penalty, {steps} increments"]
    offset, e_offset, n_el = {}, {}, 0
    n_nodes = 0
    for b in problem.bodies:
        if b.mesh.cell_type != "hex8" or not isinstance(b.material, SaintVenantKirchhoff):
            raise ValueError(f"body {b.name!r}: only hex8 St. Venant-Kirchhoff bodies are written")
        offset[b.name], e_offset[b.name] = n_nodes, n_el
        lines += _node_block(f"N{b.name.upper()}", n_nodes + 1, b.mesh.points)
        lines += _element_block(f"E{b.name.upper()}", n_el + 1, b.mesh.cells + n_nodes + 1)
        n_nodes += b.mesh.n_nodes
        n_el += b.mesh.n_cells
    meshes = {b.name: b.mesh for b in problem.bodies}

    def nset(body: str, name: str) -> str:
        label = f"N{body.upper()}_{name.upper()}"
        if label not in written:
            written.add(label)
            lines.extend([f"*NSET, NSET={label}", _ids(meshes[body].node_sets[name] + offset[body] + 1)])
        return label

    def surface(body: str, name: str, label: str) -> int:
        elems, nums = face_numbers(meshes[body], name)
        lines.append(f"*SURFACE, NAME={label}, TYPE=ELEMENT")
        lines.extend(f"{e + e_offset[body] + 1}, S{f}" for e, f in zip(elems.tolist(), nums.tolist(), strict=True))
        return len(elems)

    written: set[str] = set()
    n_slave = surface(c.slave[0], c.slave[1], "SSLAVE")
    n_master = surface(c.master[0], c.master[1], "SMASTER")
    fixed, moved = [], []
    for d in problem.dirichlet:
        label = nset(d.body, d.set)
        for comp, value in zip(d.components, d.values, strict=True):
            (moved if value else fixed).append(f"{label}, {comp + 1}, {comp + 1}" + (f", {value:.12e}" if value else ""))
    report_set = nset(*report)
    for b in problem.bodies:
        lines += [f"*MATERIAL, NAME=M{b.name.upper()}", "*ELASTIC", f"{b.material.E * S:.12e}, {b.material.nu:.12e}",
                  f"*SOLID SECTION, ELSET=E{b.name.upper()}, MATERIAL=M{b.name.upper()}"]
    lines += ["*SURFACE INTERACTION, NAME=CONTACT",
              "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
              f"{k * S:.12e}, {sigma_inf * S:.12e}",
              "*CONTACT PAIR, INTERACTION=CONTACT, TYPE=NODE TO SURFACE",
              "SSLAVE, SMASTER",
              "*BOUNDARY", *fixed,
              f"*STEP, NLGEOM, INC={100 * steps}",
              "*STATIC, DIRECT",
              f"{1.0 / steps:.12e}, 1.0",
              "*BOUNDARY", *moved,
              f"*NODE PRINT, NSET={report_set}, TOTALS=ONLY",
              "RF",
              "*END STEP", ""]
    info = DeckInfo(n_nodes=n_nodes, n_elements=n_el, body_nodes=n_nodes, body_elements=n_el,
                    slave_faces=n_slave, master_faces=n_master, rigid_node0=n_nodes + 1)
    return "\n".join(lines), info
