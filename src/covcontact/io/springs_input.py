"""The ``[[spring]]`` and ``[[dashpot]]`` sections (docs/input.md): springs and dashpots between two nodes or from the
nodes of a set to ground (``covcontact.elements.springs``)."""

from __future__ import annotations

import numpy as np

from ..description import COMPONENTS
from ..elements.springs import KINDS, Dashpot, Spring
from .validate import Section


def _ends(sec: Section, sets, kind: str) -> tuple[tuple, tuple | None, tuple]:
    """(the node sets, the anchor or None, the dofs) of a spring or dashpot entry."""
    raw = sec.get("nodes", "any")
    if not (isinstance(raw, list) and 1 <= len(raw) <= 2 and all(isinstance(r, str) for r in raw)):
        sec.fail('must be an array of one or two node sets ["body.set"] or ["body.set", "body.set"]', "nodes")
    ends = []
    for j, ref in enumerate(raw):
        key = f"nodes[{j}]"
        bname, sname = sets.body_set(Section({"set": ref}, sec.key_path(key), sec.file), "set", "node")
        sets.deformable(sec, key, bname)
        n = len(sets.mesh(bname).node_sets[sname])
        if len(raw) == 2 and n != 1:
            sec.fail(f"{ref!r} holds {n} nodes; the ends of a two-node {sec.path.split('[')[0]} are sets of one node "
                     f"each (a set of many nodes goes alone, each node to ground)", key)
        ends.append((bname, sname))
    if len(ends) == 2 and ends[0][0] == ends[1][0] and \
            sets.mesh(ends[0][0]).node_sets[ends[0][1]][0] == sets.mesh(ends[1][0]).node_sets[ends[1][1]][0]:
        sec.fail("both ends are the same node", "nodes")
    anchor = None
    dofs: tuple = ()
    if kind == "axial":
        if sec.has("dofs"):
            sec.fail('dofs belong to type = "dof" (an axial member acts along the line between its ends)', "dofs")
        if len(ends) == 1:
            if not sec.has("anchor"):
                sec.fail('missing: an axial member with one node set goes to a fixed point: give its anchor = '
                         '[x, y, z] (or a second node set, or type = "dof" for a spring to ground in one component)',
                         "anchor")
            anchor = sec.get("anchor", "vector")
            pts = sets.mesh(ends[0][0]).points[sets.mesh(ends[0][0]).node_sets[ends[0][1]]]
            if np.any(np.linalg.norm(pts - np.asarray(anchor), axis=1) <= 1e-12 * max(1.0, np.abs(pts).max())):
                sec.fail("the anchor lies on a node of the set: an axial member needs a direction (a length)", "anchor")
        else:
            if sec.has("anchor"):
                sec.fail("an anchor is the other end of a member with one node set; this one has two", "anchor")
            p = [sets.mesh(b).points[sets.mesh(b).node_sets[s][0]] for b, s in ends]
            if np.linalg.norm(p[1] - p[0]) <= 1e-12 * max(1.0, np.abs(p).max()):
                sec.fail("the two nodes lie at the same place: an axial member needs a direction (a length); use "
                         'type = "dof"', "nodes")
    else:
        if sec.has("anchor"):
            sec.fail('an anchor belongs to type = "axial" (a "dof" member with one node set goes to ground)', "anchor")
        raw_dofs = sec.get("dofs", "any")
        if not (isinstance(raw_dofs, list) and len(raw_dofs) == len(ends)
                and all(isinstance(c, str) and c in COMPONENTS for c in raw_dofs)):
            sec.fail(f'must be an array of {len(ends)} component(s), one per node set, each "x", "y" or "z"', "dofs")
        dofs = tuple(COMPONENTS[c] for c in raw_dofs)
    return tuple(ends), anchor, dofs


def _table(sec: Section) -> tuple:
    raw = sec.get("table", "any")
    ok = isinstance(raw, list) and len(raw) >= 2 and all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                    and np.isfinite(v) for v in p) for p in raw)
    if not ok:
        sec.fail("must be an array of at least two [elongation, force] points", "table")
    x = [float(p[0]) for p in raw]
    if any(b <= a for a, b in zip(x, x[1:])):
        sec.fail("the elongations must increase strictly", "table")
    return tuple((float(p[0]), float(p[1])) for p in raw)


def read_springs(top: Section, sets) -> tuple[list[Spring], list[Dashpot]]:
    """Every ``[[spring]]`` and ``[[dashpot]]`` entry."""
    springs = []
    for s in top.get("spring", "array", []):
        kind = s.get("type", "str", "axial", choices=KINDS)
        ends, anchor, dofs = _ends(s, sets, kind)
        if s.has("stiffness") == s.has("table"):
            s.fail("give exactly one of 'stiffness' (a linear spring) or 'table' ([elongation, force] points)")
        stiffness = s.get("stiffness", "float", None, positive=True)
        table = _table(s) if s.has("table") else None
        name = s.get("name", "str", "")
        s.done()
        springs.append(Spring(ends, kind, stiffness, table, dofs, anchor, name))
    dashpots = []
    for d in top.get("dashpot", "array", []):
        kind = d.get("type", "str", "axial", choices=KINDS)
        ends, anchor, dofs = _ends(d, sets, kind)
        c = d.get("coefficient", "float", positive=True)
        name = d.get("name", "str", "")
        d.done()
        dashpots.append(Dashpot(ends, c, kind, dofs, anchor, name))
    return springs, dashpots
