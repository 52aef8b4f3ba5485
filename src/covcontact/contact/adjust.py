"""Slave nodes moved onto their master before the first step (``[[contact]] adjust``; docs/input.md): a mesh whose
contact surfaces were meshed apart (a small gap or overlap from the geometry or the mesher) starts touching, stress
free, as Abaqus' and CalculiX' ADJUST do."""

from __future__ import annotations

import numpy as np

from .driver import project_slaves
from .search import candidates
from .surface import facet_frame, facet_sizes


def adjust_slaves(problem) -> list[str]:
    """Move the slave nodes of every pair with ``adjust`` onto its meshed master, in the bodies' meshes (in place):
    the nodes whose gap is below ``adjust`` (a distance; overlapping ones included), or the nodes of the slave body's
    node set ``adjust`` (a name) that have a contact point. Each goes to its closest point on the master. Returns one
    line per pair (how many nodes, how far at most) for the start of the run."""
    from ..assembly.system import System
    from .manager import ContactManager

    pairs = [c for c in problem.contacts if getattr(c, "adjust", None) is not None]
    if not pairs:
        return []
    system = System(problem.bodies, problem.rigid)
    manager = ContactManager(problem, system)
    xe = manager.extended(system.X.copy(), 0.0)
    bodies = {b.name: b for b in problem.bodies}
    out = []
    for pair in pairs:
        p = next(q for q in manager.passes if q.name == pair.name)
        body = bodies[pair.slave[0]]
        mesh = body.mesh
        if isinstance(pair.adjust, str):
            local = np.asarray(mesh.node_sets[pair.adjust], dtype=np.int64)
        elif pair.slave[1] in mesh.face_sets:
            local = np.unique(mesh.face_sets[pair.slave[1]])
        else:
            local = np.asarray(mesh.node_sets[pair.slave[1]], dtype=np.int64)
        nodes = local + system.offset(body.name)
        xs = np.ascontiguousarray(xe[nodes])
        sizes = facet_sizes(xe, p.surface.faces)
        reach = max(float(sizes.max()) if len(sizes) else 0.0, 0.0 if isinstance(pair.adjust, str) else pair.adjust)
        cand = candidates(xe, p.surface, xs, reach)
        res = project_slaves(xe, p.surface, xs, cand[0], cand[1])
        move = res.kind != 0
        if not isinstance(pair.adjust, str):
            move &= res.g < pair.adjust
        rho, t1, t2, n = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
        far = 0.0
        for j in np.flatnonzero(move):
            xyz = np.ascontiguousarray(xe[p.surface.faces[res.facet[j]]])
            facet_frame(xyz, float(res.xi[j, 0]), float(res.xi[j, 1]), rho, t1, t2, n)
            far = max(far, float(np.linalg.norm(rho - xs[j])))
            mesh.points[local[j]] = rho
        out.append(f"contact pair {pair.name!r}: {int(move.sum())} slave node(s) moved onto the master before the "
                   f"first step (adjust), by {far:.3g} at most")
    return out
