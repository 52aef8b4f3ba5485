"""The ``[[dirichlet]]``, ``[[force]]``, ``[[pressure]]`` and ``[[traction]]`` sections, and the references
``"body.set"`` that they and the contact pairs make to the bodies' node and face sets (docs/input.md)."""

from __future__ import annotations

import numpy as np

from ..description import COMPONENTS
from ..loads import BodyForce, Dirichlet, Equation, NodalForce, Pressure, Traction
from .fields import dirichlet_values, read_motion, split_ref
from .validate import Section, suggest


class SetRefs:
    """Resolves ``"body.set"`` references against the bodies and the meshed rigid bodies."""

    def __init__(self, bodies: list, rigid: list):
        self.bodies, self.rigid = bodies, rigid

    def mesh(self, bname: str):
        """The mesh of body ``bname`` (deformable or rigid meshed), or None."""
        owner = next((b.mesh for b in self.bodies if b.name == bname), None)
        if owner is None:
            owner = next((r.mesh for r in self.rigid if r.name == bname and r.mesh is not None), None)
        return owner

    def body_set(self, sec: Section, key: str, kind: str) -> tuple[str, str]:
        ref = sec.get(key, "str")
        bname, sname = split_ref(sec, key, ref)
        owner = self.mesh(bname)
        if owner is None:
            names = [b.name for b in self.bodies] + [r.name for r in self.rigid if r.mesh is not None]
            sec.fail(f"{ref!r}: no body named {bname!r}{suggest(bname, names)} (bodies: {', '.join(names) or 'none'})",
                     key)
        sets = owner.node_sets if kind == "node" else owner.face_sets
        if sname not in sets:
            known = ", ".join(sorted(sets)) or "none"
            sec.fail(f"{ref!r}: body {bname!r} has no {kind} set {sname!r}{suggest(sname, sets)} (known: {known})",
                     key)
        if len(sets[sname]) == 0:
            sec.fail(f"{ref!r}: {kind} set is empty", key)
        return bname, sname

    def deformable(self, sec: Section, key: str, bname: str) -> None:
        if not any(b.name == bname for b in self.bodies):
            sec.fail(f"{bname!r} is not a deformable body", key)


def read_dirichlet(top: Section, sets: SetRefs) -> list[Dirichlet]:
    """Every ``[[dirichlet]]`` entry."""
    dirichlet = []
    for d in top.get("dirichlet", "array", []):
        bname, sname = sets.body_set(d, "set", "node")
        sets.deformable(d, "set", bname)
        comps = d.get("components", "str", "xyz")
        if not comps or any(c not in COMPONENTS for c in comps) or len(set(comps)) != len(comps):
            d.fail(f"must be a non-empty combination of x, y, z, got {comps!r}", "components")
        dname = d.get("name", "str", "")
        motion = None
        held = False
        if d.has("motion"):
            if d.has("value"):
                d.fail("give either 'value' or 'motion', not both", "motion")
            motion = read_motion(d.get("motion", "table"))
            values = (0.0,) * len(comps)
        else:
            held = d.has("value") and d.data.get("value") == "held"
            values = (0.0,) * len(comps) if held and d.get("value", "str") else \
                dirichlet_values(d, "value", len(comps))
        start = d.get("stage", "str", None)
        if held and start is None:
            d.fail('value = "held" (the displacement the dofs have when the condition starts) needs a later '
                   '\'stage\' to start in', "value")
        if start is not None and motion is not None:
            d.fail("a condition with a motion holds from the first stage: leave out 'stage'", "stage")
        d.done()
        dirichlet.append(Dirichlet(bname, sname, tuple(COMPONENTS[c] for c in comps), tuple(values), dname,
                                   motion, start, held))
    return dirichlet


def read_loads(top: Section, sets: SetRefs) -> tuple[list, list, list]:
    """(forces, pressures, tractions): every ``[[force]]``, ``[[pressure]]`` and ``[[traction]]`` entry."""
    forces = []
    for f in top.get("force", "array", []):
        bname, sname = sets.body_set(f, "set", "node")
        sets.deformable(f, "set", bname)
        value = f.get("value", "vector")
        dist = f.get("distribution", "str", "per_node", choices=("per_node", "total"))
        fname = f.get("name", "str", "")
        f.done()
        forces.append(NodalForce(bname, sname, value, dist, fname))

    pressures = []
    for p in top.get("pressure", "array", []):
        bname, sname = sets.body_set(p, "set", "face")
        sets.deformable(p, "set", bname)
        value = p.get("value", "float")
        pname = p.get("name", "str", "")
        follower = p.get("follower", "bool", False)
        profile = None
        if p.has("profile"):
            prof = p.get("profile", "table")
            profile = (prof.get("constant", "float", 1.0), *prof.get("gradient", "vector", (0.0, 0.0, 0.0)))
            prof.done()
        p.done()
        pressures.append(Pressure(bname, sname, value, pname, follower, profile))

    tractions = []
    for t in top.get("traction", "array", []):
        bname, sname = sets.body_set(t, "set", "face")
        sets.deformable(t, "set", bname)
        value = t.get("value", "vector")
        tname = t.get("name", "str", "")
        t.done()
        tractions.append(Traction(bname, sname, value, tname))
    return forces, pressures, tractions


def read_equations(top: Section, sets: SetRefs, dirichlet: list[Dirichlet]) -> list[Equation]:
    """Every ``[[equation]]`` entry: ``terms = [["body.set", "x", c], ...]``, each set one node; the first term's dof is
    eliminated: it may be the first term of no other equation, nor held by a Dirichlet condition, and eliminations
    may not form a cycle (they may chain: an eliminated dof is a term of another equation)."""
    out: list[Equation] = []
    dependent: dict[tuple, str] = {}   # (body, node, component) of each eliminated dof -> its equation
    refs: dict[tuple, list[tuple]] = {}  # eliminated dof -> the dofs of its other terms
    for e in top.get("equation", "array", []):
        raw = e.get("terms", "any")
        name = e.get("name", "str", "")
        value = e.get("value", "float", 0.0)
        e.done()
        if not isinstance(raw, list) or not raw:
            e.fail("must be a non-empty array of [\"body.set\", \"x\" | \"y\" | \"z\", coefficient]", "terms")
        terms = []
        for j, t in enumerate(raw):
            key = f"terms[{j}]"
            if not (isinstance(t, list) and len(t) == 3 and isinstance(t[0], str) and t[1] in COMPONENTS
                    and isinstance(t[2], (int, float)) and not isinstance(t[2], bool)):
                e.fail("must be [\"body.set\", \"x\" | \"y\" | \"z\", coefficient]", key)
            bname, sname = sets.body_set(Section({"set": t[0]}, e.key_path(key), e.file), "set", "node")
            sets.deformable(e, key, bname)
            nodes = sets.mesh(bname).node_sets[sname]
            if len(nodes) != 1:
                e.fail(f"{t[0]!r} holds {len(nodes)} nodes; each term names a set of one node", key)
            comp = COMPONENTS[t[1]]
            dof = (bname, int(nodes[0]), comp)
            if j == 0:
                if float(t[2]) == 0.0:
                    e.fail("the first coefficient (of the eliminated dof) must not be zero", key)
                if dof in dependent:
                    e.fail(f"{t[0]} {t[1]} is the eliminated (first) term of {dependent[dof]} already: put another "
                           f"dof of this equation first", key)
                dependent[dof] = e.path
                first = dof
            elif dof == first:
                e.fail(f"{t[0]} {t[1]} is this equation's eliminated (first) term: it appears once", key)
            terms.append((bname, sname, comp, float(t[2])))
        out.append(Equation(terms, name, value))
        refs[first] = [(b, int(sets.mesh(b).node_sets[sn][0]), c) for b, sn, c, _ in terms[1:]]
    state: dict[tuple, int] = {}  # a cycle of eliminations (u_a = u_b, u_b = u_a) has no solution for them

    def visit(d: tuple) -> None:
        state[d] = 1
        for r in refs.get(d, ()):
            if state.get(r) == 1:
                top.fail(f"the equations {dependent[d]} and {dependent[r]} eliminate each other's dofs in a cycle: "
                         f"put another dof first in one of them", "equation")
            if r in refs and r not in state:
                visit(r)
        state[d] = 2

    for d in refs:
        if d not in state:
            visit(d)
    for i, bc in enumerate(dirichlet):
        nodes = set(sets.mesh(bc.body).node_sets[bc.set].tolist())
        for (bname, node, comp), where in dependent.items():
            if bname == bc.body and node in nodes and comp in bc.components:
                top.fail(f"the dof {'xyz'[comp]} of node {node} of {bname!r} is the eliminated (first) term of "
                         f"{where} and held by this condition: put another dof of the equation first",
                         f"dirichlet[{i}]")
    return out


def read_body_forces(top: Section, bodies: list) -> list[BodyForce]:
    """Every ``[[body_force]]``: ``body``, optional ``cells`` (an element set of it), and ``value`` (force per unit
    reference volume) or ``acceleration`` (times the density)."""
    out = []
    names = [b.name for b in bodies]
    for b in top.get("body_force", "array", []):
        bname = b.get("body", "str")
        if bname not in names:
            b.fail(f"no deformable body named {bname!r}{suggest(bname, names)} (bodies: {', '.join(names) or 'none'})",
                   "body")
        body = bodies[names.index(bname)]
        cells = b.get("cells", "str", "")
        if cells and cells not in body.mesh.element_sets:
            known = ", ".join(sorted(body.mesh.element_sets)) or "none"
            b.fail(f"body {bname!r} has no element set {cells!r}{suggest(cells, body.mesh.element_sets)} (known: "
                   f"{known})", "cells")
        if b.has("value") + b.has("acceleration") + b.has("centrifugal") != 1:
            b.fail("give exactly one of 'value' (force per unit volume), 'acceleration' (times the density) or "
                   "'centrifugal' (a spin)")
        per_mass = b.has("acceleration") or b.has("centrifugal")
        axis, center = None, (0.0, 0.0, 0.0)
        if b.has("centrifugal"):
            c = b.get("centrifugal", "table")
            omega = c.get("omega", "float", nonnegative=True)
            axis = c.get("axis", "vector")
            center = c.get("center", "vector", (0.0, 0.0, 0.0))
            if not np.linalg.norm(axis) > 0.0:
                c.fail("must not be zero", "axis")
            c.done()
            value = (omega * omega, 0.0, 0.0)
        else:
            value = b.get("acceleration" if per_mass else "value", "vector")
        if per_mass:
            for _, _, material, _ in body.material_parts(body.mesh.element_sets[cells] if cells else None):
                if getattr(material, "density", None) is None:
                    b.fail(f"missing: an acceleration needs the density of the material of body {bname!r}",
                           "centrifugal" if axis is not None else "acceleration")
        name = b.get("name", "str", "")
        b.done()
        out.append(BodyForce(bname, cells, value, name, per_mass, axis, center))
    return out
