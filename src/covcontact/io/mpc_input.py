"""The ``[[mpc]]`` section (docs/input.md): nonlinear multi-point constraints, a plane, a straight line or a beam's
fixed distance (``covcontact.solvers.mpc``)."""

from __future__ import annotations

import numpy as np

from ..loads import KINDS, MPC, degenerate, dependent_components
from .validate import Section, suggest

_WHAT = {"plane": "the first three nodes (sets of one node each) define the plane, the sets after them hold the nodes "
                  "kept in it",
         "straight": "the first two nodes (sets of one node each) define the line, the sets after them hold the nodes "
                     "kept on it",
         "beam": "exactly two sets of one node each, whose distance stays constant"}


def read_mpcs(top: Section, sets, bodies: list, dirichlet: list, equations: list, rigid: list) -> list[MPC]:
    """Every ``[[mpc]]`` entry: ``type`` and ``nodes = ["body.set", ...]``. One line each for: a defining set of more
    than one node, defining nodes that define nothing (collinear, coincident), no constrained node besides the defining
    ones (which the constrained sets may hold: they are left out), a dependent dof (``loads.dependent_components``) that
    is another constraint's dependent dof, is held by a Dirichlet condition, follows a rigid body or is an input of
    another constraint (no chains), and an equation's eliminated dof among a constraint's inputs."""
    out: list[MPC] = []
    planar = {b.name for b in bodies if b.formulation in ("plane_strain", "plane_stress", "axisymmetric")}
    entries = top.get("mpc", "array", [])
    dependent: dict[tuple, str] = {}    # (body, node, component) -> the constraint that eliminates it
    inputs: dict[tuple, str] = {}       # (body, node, component) of the other dofs -> a constraint that reads it
    for i, e in enumerate(entries):
        kind = e.get("type", "str")
        if kind not in KINDS:
            e.fail(f"unknown type {kind!r}{suggest(kind, KINDS)}: one of {', '.join(KINDS)}", "type")
        raw = e.get("nodes", "any")
        name = e.get("name", "str", "") or f"mpc[{i}]"
        e.done()
        nd = KINDS[kind]
        if not (isinstance(raw, list) and all(isinstance(r, str) for r in raw)
                and (len(raw) == 2 if kind == "beam" else len(raw) > nd)):
            e.fail(f"must be an array of node sets \"body.set\": {_WHAT[kind]}", "nodes")
        refs, node_lists = [], []
        for j, ref in enumerate(raw):
            key = f"nodes[{j}]"
            bname, sname = sets.body_set(Section({"set": ref}, e.key_path(key), e.file), "set", "node")
            sets.deformable(e, key, bname)
            if bname in planar:
                e.fail(f"{ref!r} is a set of the planar body {bname!r}: multi-point constraints act on 3D bodies",
                       key)
            nodes = sets.mesh(bname).node_sets[sname]
            if j < nd and len(nodes) != 1:
                e.fail(f"{ref!r} holds {len(nodes)} nodes; the {'nodes' if kind == 'beam' else 'defining nodes'} "
                       f"are sets of one node each", key)
            refs.append((bname, sname))
            node_lists.append([(bname, int(v)) for v in nodes])
        defining = [n[0] for n in node_lists[:nd]]
        X = np.array([sets.mesh(b).points[v] for b, v in defining], dtype=float)
        if len(set(defining)) < nd or degenerate(kind, X):
            e.fail({"plane": "the three defining nodes lie on a line (or two coincide): they define no plane",
                    "straight": "the two defining nodes coincide: they define no line",
                    "beam": "the two nodes coincide: a beam constraint needs a length"}[kind], "nodes")
        # (a defining node in a constrained set lies in its plane or on its line already: left out)
        constrained = [[]] if kind == "beam" else [[n] for lst in node_lists[nd:] for n in lst if n not in defining]
        if not constrained:
            e.fail("the constrained sets hold only defining nodes: nothing to constrain", "nodes")
        for extra in constrained:
            these = defining + extra
            Xs = np.array([sets.mesh(b).points[v] for b, v in these], dtype=float)
            dep = [(these[a][0], these[a][1], k) for a, k in dependent_components(kind, Xs)]
            for d in dep:
                if d in dependent:
                    e.fail(f"the dof {'xyz'[d[2]]} of node {d[1]} of body {d[0]!r} is eliminated by {dependent[d]} "
                           f"already (each constraint eliminates its own: the plane's normal component, the line's "
                           f"two across it, a beam's first node along it)", "nodes")
                if d in inputs:
                    e.fail(f"the dof {'xyz'[d[2]]} of node {d[1]} of body {d[0]!r} is eliminated here and read by "
                           f"{inputs[d]}: constraints may not chain", "nodes")
                dependent[d] = name
            for b, v in these:
                for k in range(3):
                    d = (b, v, k)
                    if d in dep:
                        continue
                    if d in dependent and dependent[d] != name:
                        e.fail(f"the dof {'xyz'[k]} of node {v} of body {b!r} is eliminated by {dependent[d]}: "
                               f"constraints may not chain", "nodes")
                    inputs.setdefault(d, name)
        out.append(MPC(kind, refs, name))
    if not out:
        return out
    for i, bc in enumerate(dirichlet):
        nodes = set(sets.mesh(bc.body).node_sets[bc.set].tolist())
        for (b, v, k), where in dependent.items():
            if b == bc.body and v in nodes and k in bc.components:
                top.fail(f"the dof {'xyz'[k]} of node {v} of body {b!r} is eliminated by {where} and held by this "
                         f"condition", f"dirichlet[{i}]")
    for i, eq in enumerate(equations):
        b, s, k, _ = eq.terms[0]
        v = int(sets.mesh(b).node_sets[s][0])
        if (b, v, k) in dependent or (b, v, k) in inputs:
            where = dependent.get((b, v, k)) or inputs[(b, v, k)]
            top.fail(f"its first (eliminated) term, the dof {'xyz'[k]} of node {v} of body {b!r}, is "
                     f"{'eliminated' if (b, v, k) in dependent else 'read'} by {where}; put another term first",
                     f"equation[{i}]")
    for r in rigid:
        for b, s in r.attach:
            for v in sets.mesh(b).node_sets[s]:
                for k in r.attach_components:
                    if (b, int(v), k) in dependent:
                        top.fail(f"the dof {'xyz'[k]} of node {int(v)} of body {b!r} follows rigid body {r.name!r} "
                                 f"and is eliminated by {dependent[(b, int(v), k)]}", "mpc")
    return out
